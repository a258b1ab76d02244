"""Multimodal LLM access over an OpenAI-compatible HTTP API (layer 3; uses
only ``ignjax.protocol``, ``arrays``, ``errors``, ``fileio`` below it).

Modules:

* :mod:`~ignjax.agents.llm.config`: :class:`LLMConfig`, the checked settings
  (endpoints, model, retries, concurrency, cache, prices; the API key is
  never a field, only the name of its environment variable);
* :mod:`~ignjax.agents.llm.messages`: :class:`ChatRequest` /
  :class:`ImagePart` / :class:`ChatResult`, :class:`ClientStats`,
  :func:`price` and the errors (plain data, no extra needed);
* :mod:`~ignjax.agents.llm.client`: :class:`ChatClient` (aiohttp, the
  ``llm`` extra): least-loaded dispatch over endpoints, bounded concurrency, seeded retries
  with backoff, structured output with fallback, key scrubbing, stats;
* :mod:`~ignjax.agents.llm.cache`: :func:`request_hash` and the SQLite
  :class:`ResponseCache` (record / replay);
* :mod:`~ignjax.agents.llm.parse`: :func:`parse_reply`, the tolerant JSON
  reply parser and its JSON-schema subset check;
* :mod:`~ignjax.agents.llm.serve`: ``ScriptedServer``, a scripted
  OpenAI-compatible TEST DOUBLE with latency, queueing and fault
  injection, and ``python -m ignjax.agents.llm.serve``.
"""

from ignjax.agents.llm.cache import ResponseCache, request_hash
from ignjax.agents.llm.client import ChatClient
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.messages import (ChatRequest, ChatResult, ClientStats, ImagePart, LLMError, LLMRequestError,
                                        ReplayMissError, price)
from ignjax.agents.llm.parse import parse_reply, validate


def __getattr__(name: str):
    # deferred import: importing serve here would make
    # `python -m ignjax.agents.llm.serve` warn that the module was already
    # imported by its package before running as __main__
    if name == "ScriptedServer":
        from ignjax.agents.llm.serve import ScriptedServer

        return ScriptedServer
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["ChatClient", "ChatRequest", "ChatResult", "ClientStats", "ImagePart", "LLMConfig", "LLMError",
           "LLMRequestError", "ReplayMissError", "ResponseCache", "ScriptedServer", "parse_reply", "price",
           "request_hash", "validate"]
