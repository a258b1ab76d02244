"""Which models the servers serve, asked before any episode runs.

:func:`check_served` sends ``GET {endpoint}/models`` (the OpenAI API's model
list, which vLLM, SGLang, Ollama, hosted APIs and the scripted server of
:mod:`ignjax.agents.llm.serve` answer) to every endpoint of an
:class:`~ignjax.agents.llm.config.LLMConfig` at once, with the client's
timeout (``timeout_s``, total per endpoint) and its key (``Authorization:
Bearer``, only when the variable named by ``api_key_env`` is set), and raises
:class:`~ignjax.errors.ConfigError`:

* naming the endpoint, when it does not answer within ``timeout_s``, refuses
  the connection, answers with an error status (401 for a wrong key, 404
  where it has no model list) or with a body that is not a model list;
* naming the model asked for and the ones served, when an endpoint's list
  lacks ``model``.

So a misspelled ``--llm-model`` stops the command with exit status 2 before
any scene is loaded, rather than ending every episode as ``model_failure``.
Under ``replay`` nothing is asked: the cache answers and no server is
needed. Like the client's, every message passes through the key's scrubber,
and aiohttp's exceptions are not chained.
"""

from __future__ import annotations

import asyncio
import json
import os

from ignjax.agents.llm.client import _Secret, server_message
from ignjax.agents.llm.config import LLMConfig
from ignjax.errors import ConfigError
from ignjax.errors.extras import optional_module, require_extra

aiohttp = optional_module("aiohttp", "llm")  # the llm extra: pip install "ignjax[llm]"


class _Unanswered(Exception):
    """An endpoint gave no usable model list (the reason, in words)."""


async def _models_of(session: aiohttp.ClientSession, endpoint: str, key: _Secret, timeout_s: float) -> list[str]:
    """The model ids ``endpoint`` lists (``{"data": [{"id": ...}, ...]}``).

    Raises:
        _Unanswered: no answer in time, no connection, an error status or a body that is no model list.
    """
    headers = {"Authorization": f"Bearer {key.reveal()}"} if key.reveal() else {}
    try:
        async with session.get(f"{endpoint}/models", headers=headers,
                               timeout=aiohttp.ClientTimeout(total=timeout_s)) as resp:
            raw = await resp.read()
            status = resp.status
    except TimeoutError:
        raise _Unanswered(f"no answer within {timeout_s:g} s (llm.timeout_s)") from None
    except (aiohttp.ClientError, OSError) as e:
        raise _Unanswered(f"connection error: {type(e).__name__}: {e}") from None
    if status != 200:
        raise _Unanswered(f"HTTP {status}: {server_message(raw, 300)}")
    try:
        data = json.loads(raw)["data"]
        ids = [m["id"] for m in data]
        if not all(isinstance(i, str) for i in ids):
            raise TypeError("a model id is not a string")
    except (ValueError, KeyError, TypeError) as e:
        raise _Unanswered(f"the reply is not a model list ({type(e).__name__}): "
                          f"{raw[:120].decode('utf-8', 'replace')!r}") from None
    return ids


def _key(config: LLMConfig) -> _Secret:
    env = config.api_key_env
    return _Secret(os.environ.get(env) if env else None)


async def served_models(config: LLMConfig, key: _Secret | None = None) -> dict[str, list[str] | str]:
    """``endpoint -> the model ids it lists``, or ``endpoint -> why it gave none`` (one sentence,
    scrubbed of the key), asking every endpoint at once (``key``: the holder of the key to send;
    default: read from ``config.api_key_env``)."""
    key = _key(config) if key is None else key
    async with aiohttp.ClientSession() as session:
        answers = await asyncio.gather(*(_models_of(session, e, key, config.timeout_s) for e in config.endpoints),
                                       return_exceptions=True)
    out: dict[str, list[str] | str] = {}
    for endpoint, a in zip(config.endpoints, answers):
        if isinstance(a, _Unanswered):
            out[endpoint] = key.scrub(str(a))
        elif isinstance(a, BaseException):
            raise a
        else:
            out[endpoint] = a
    return out


def check_served(config: LLMConfig, model_setting: str = "llm.model", endpoints_setting: str = "llm.endpoints") -> None:
    """Stop before any work unless every endpoint of ``config`` answers and serves ``config.model``
    (module docstring); nothing is asked under ``config.replay``.

    Args:
        model_setting, endpoints_setting: how the command names the two settings in its errors
            (``--llm-model`` / ``--llm-endpoint`` for ``python -m ignjax.evaluate``).

    Raises:
        ConfigError: naming ``endpoints_setting`` and each endpoint that gave no model list, with why;
            else naming ``model_setting``, the model asked for and the models each endpoint serves.
        MissingExtra: the llm extra (aiohttp) is not installed.
    """
    require_extra("aiohttp", "llm")
    if config.replay or not config.endpoints:
        return
    key = _key(config)
    found = asyncio.run(served_models(config, key))
    silent = {e: why for e, why in found.items() if isinstance(why, str)}
    if silent:
        raise ConfigError(None, endpoints_setting, key.scrub("; ".join(
            f"{e} did not list its models (GET {e}/models): {why}" for e, why in silent.items())
            + " (is the server running, and is this its OpenAI-compatible base URL, such as http://HOST:8000/v1?)"))
    lacking = {e: ids for e, ids in found.items() if config.model not in ids}
    if lacking:
        served = "; ".join(f"{e} serves {', '.join(map(repr, ids)) if ids else 'no model'}" for e, ids in lacking.items())
        raise ConfigError(None, model_setting, key.scrub(f"model {config.model!r} is not served: {served}"))


__all__ = ["check_served", "served_models"]
