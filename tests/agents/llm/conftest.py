"""Fixtures of the LLM-client tests: real scripted servers on 127.0.0.1 and
real clients, nothing mocked.

``scripted_server(**options)`` starts a :class:`ScriptedServer` (stopped at
the end of the test); ``llm_config(*servers, **fields)`` builds an
:class:`LLMConfig` for them with test-speed retry settings;
``run_client(config, requests, cache=None)`` sends requests with one fresh
client and returns ``(results, client_stats, client_repr)``.
"""

from __future__ import annotations

import asyncio

import pytest

from ignjax.agents.llm.client import ChatClient
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.serve import DEFAULT_MODEL, ScriptedServer


@pytest.fixture
def scripted_server():
    started: list[ScriptedServer] = []

    def start(**options) -> ScriptedServer:
        srv = ScriptedServer(**options).start()
        started.append(srv)
        return srv

    yield start
    for srv in started:
        srv.stop()


@pytest.fixture
def llm_config():
    def make(*servers, **fields) -> LLMConfig:
        base = {"endpoints": tuple(s if isinstance(s, str) else s.base_url for s in servers),
                "model": DEFAULT_MODEL, "api_key_env": None, "timeout_s": 5.0, "backoff_base_s": 0.005,
                "backoff_max_s": 0.05, "max_tokens": 256}
        base.update(fields)
        return LLMConfig(**base)

    return make


@pytest.fixture
def run_client():
    def run(config, requests, cache=None, many=False):
        async def go():
            async with ChatClient(config, cache=cache) as client:
                if many:
                    results = await client.complete_many(requests)
                else:
                    results = [await client.complete(r) for r in requests]
                return results, client.stats(), repr(client)

        return asyncio.run(go())

    return run
