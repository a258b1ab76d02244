"""What the MLLM client sends and returns, and how it fails: :class:`ChatRequest`
(messages whose images are :class:`ImagePart` s of raw encoded bytes, an
optional reply schema, a ``tag`` naming the episode), :class:`ChatResult`
(the reply text, the parsed object, token counts, bookkeeping),
:class:`ClientStats`, :func:`price`, and the errors (:class:`LLMError`,
:class:`LLMRequestError`, :class:`ReplayMissError`). Plain data with their
checks; the transport is :mod:`ignjax.agents.llm.client`, which needs the
``llm`` extra, so these import without it."""

from __future__ import annotations

import base64
import hashlib
import re
from dataclasses import dataclass
from typing import Sequence

from ignjax.errors import IgnjaxError, InputError

_MIME = re.compile(r"^image/[A-Za-z0-9.+-]+$")
_SCHEMA_NAME = re.compile(r"^[A-Za-z0-9_-]{1,64}$")


# ---------------------------------------------------------------------------
# errors
# ---------------------------------------------------------------------------


class LLMError(IgnjaxError):
    """Base of the errors of :mod:`ignjax.agents.llm`."""


class LLMRequestError(LLMError):
    """A request failed for good: a non-retryable status, or retries spent.

    Attributes:
        endpoint: the base URL of the last attempt (``None`` if none was made).
        status: HTTP status of the last attempt (``None``: no response, e.g.
            a timeout or dropped connection).
        attempts: HTTP attempts made for this request.
        reason: what went wrong, with the server's message when it sent one.
        request_hash: the request's cache key.
        tag: the request's tag (episode id).
    """

    def __init__(self, message: str, *, endpoint: str | None, status: int | None, attempts: int, reason: str,
                 request_hash: str = "", tag: str = ""):
        super().__init__(message)
        self.endpoint, self.status, self.attempts = endpoint, status, attempts
        self.reason, self.request_hash, self.tag = reason, request_hash, tag


class ReplayMissError(LLMError):
    """Replay mode met a request that is not in the cache.

    Attributes:
        request_hash: the missing key.
        cache_path: the cache file searched.
    """

    def __init__(self, request_hash: str, cache_path: str, tag: str = ""):
        self.request_hash, self.cache_path, self.tag = request_hash, cache_path, tag
        where = f" (tag {tag!r})" if tag else ""
        super().__init__(f"replay: no cached reply for request {request_hash}{where} in {cache_path}; "
                         "the prompt, images, model or generation settings differ from the recorded run")


# ---------------------------------------------------------------------------
# requests and results
# ---------------------------------------------------------------------------


@dataclass(frozen=True, repr=False)
class ImagePart:
    """One image of a message, as encoded bytes (JPEG, PNG, ...) and their
    mime type; turned into a ``data:`` URL only when sent."""

    data: bytes
    mime: str = "image/jpeg"

    def __post_init__(self):
        if not isinstance(self.data, (bytes, bytearray, memoryview)):
            raise InputError(None, "ImagePart.data", f"expected encoded image bytes, got {type(self.data).__name__}")
        object.__setattr__(self, "data", bytes(self.data))
        if not isinstance(self.mime, str) or not _MIME.match(self.mime):
            raise InputError(None, "ImagePart.mime", f"expected a mime type such as image/jpeg, got {self.mime!r}")

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.data).hexdigest()

    def data_url(self) -> str:
        return f"data:{self.mime};base64,{base64.b64encode(self.data).decode('ascii')}"

    def __repr__(self) -> str:
        return f"ImagePart({self.mime}, {len(self.data)} bytes, sha256={self.sha256[:12]})"


@dataclass(frozen=True)
class ChatRequest:
    """One chat-completions request.

    Attributes:
        messages: ``{"role": str, "content": str | [part, ...]}`` dicts; a
            part is a string (text), ``{"type": "text", "text": ...}``, or
            an :class:`ImagePart`. Other message keys are sent as given.
        schema: JSON schema of the reply (``None``: free text).
        schema_name: its name in ``response_format`` (letters, digits,
            ``_``, ``-``; at most 64).
        tag: the episode id: per-episode retry cap, logs, transcripts.
    """

    messages: Sequence[dict]
    schema: dict | None = None
    schema_name: str = "decision"
    tag: str = ""

    def __post_init__(self):
        msgs = self.messages
        if not isinstance(msgs, (list, tuple)) or not msgs:
            raise InputError(None, "messages", "expected a non-empty list of messages")
        for i, m in enumerate(msgs):
            if not isinstance(m, dict):
                raise InputError(None, f"messages[{i}]", f"expected a dict with role and content, got {type(m).__name__}")
            if not isinstance(m.get("role"), str) or not m["role"]:
                raise InputError(None, f"messages[{i}].role", "expected a non-empty string")
            c = m.get("content")
            if isinstance(c, str):
                continue
            if not isinstance(c, (list, tuple)) or not c:
                raise InputError(None, f"messages[{i}].content", "expected a string or a non-empty list of parts")
            for j, p in enumerate(c):
                ok = isinstance(p, (str, ImagePart)) or (
                    isinstance(p, dict) and p.get("type") == "text" and isinstance(p.get("text"), str))
                if not ok:
                    raise InputError(None, f"messages[{i}].content[{j}]",
                                     "expected a string, {'type': 'text', 'text': ...} or an ImagePart")
        object.__setattr__(self, "messages", tuple(msgs))
        if self.schema is not None and not isinstance(self.schema, dict):
            raise InputError(None, "schema", f"expected a JSON schema dict or None, got {type(self.schema).__name__}")
        if not isinstance(self.schema_name, str) or not _SCHEMA_NAME.match(self.schema_name):
            raise InputError(None, "schema_name", f"expected 1-64 letters, digits, '_' or '-', got {self.schema_name!r}")
        if not isinstance(self.tag, str):
            raise InputError(None, "tag", f"expected a string, got {type(self.tag).__name__}")


@dataclass(frozen=True)
class ChatResult:
    """The reply to one :class:`ChatRequest`.

    Attributes:
        text: the reply's message content.
        parsed: the JSON object found in it (schema-checked when the request
            had a schema), or ``None``.
        prompt_tokens, completion_tokens: the server's ``usage`` (0 if absent).
        latency_s: wall time of the successful attempt (stored value on a
            cache hit).
        retries: retries this request needed (0 on a cache hit).
        cache_hit: whether the reply came from the cache.
        request_hash: the cache key (:func:`~ignjax.agents.llm.cache.request_hash`).
        endpoint: base URL that answered; ``None`` on a cache hit.
        finish_reason: the server's (``"stop"``, ``"length"``, ...).
        parse_error: why ``parsed`` is ``None`` (one sentence), else ``None``.
    """

    text: str
    parsed: dict | None
    prompt_tokens: int
    completion_tokens: int
    latency_s: float
    retries: int
    cache_hit: bool
    request_hash: str
    endpoint: str | None
    finish_reason: str | None
    parse_error: str | None = None


@dataclass(frozen=True)
class ClientStats:
    """A snapshot of a client's counters (:meth:`ChatClient.stats`).

    ``in_flight_seconds`` is the integral of requests in flight over time
    since the client was entered; two snapshots give the utilisation of the
    window between them (:meth:`utilisation_since`)."""

    t: float
    requests_sent: int
    replies_ok: int
    requests_failed: int
    cache_hits: int
    retries: int
    in_flight: int
    max_in_flight: int
    prompt_tokens: int
    completion_tokens: int
    in_flight_seconds: float
    capacity: int
    sent_per_endpoint: tuple[int, ...]
    unstructured_endpoints: tuple[str, ...]

    def utilisation_since(self, earlier: "ClientStats") -> float:
        """Mean requests in flight between ``earlier`` and this snapshot,
        divided by ``concurrency * n_endpoints`` (0 for an empty window)."""
        dt = self.t - earlier.t
        if dt <= 0 or self.capacity <= 0:
            return 0.0
        return (self.in_flight_seconds - earlier.in_flight_seconds) / dt / self.capacity


def price(prompt_tokens: int, completion_tokens: int, prices: dict | None) -> float | None:
    """Cost in USD of the tokens at ``prices`` (USD per 1M tokens,
    ``{"prompt": x, "completion": y}``); ``None`` when prices are unknown."""
    if not prices:
        return None
    return (prompt_tokens * float(prices.get("prompt", 0.0)) + completion_tokens * float(prices.get("completion", 0.0))) / 1e6


# ---------------------------------------------------------------------------
# the key and its scrubber


__all__ = ["ChatRequest", "ChatResult", "ClientStats", "ImagePart", "LLMError", "LLMRequestError", "ReplayMissError", "price"]
