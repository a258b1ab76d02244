"""Async client for OpenAI-compatible chat-completions servers (vLLM, the
scripted test double of :mod:`ignjax.agents.llm.serve`, hosted APIs).

One :class:`ChatClient` holds one ``aiohttp.ClientSession`` and sends
:class:`ChatRequest` s (messages whose images are raw encoded bytes, an
optional reply schema, a ``tag`` naming the episode); it returns
:class:`ChatResult` s with the reply text, the parsed JSON object, token
counts and bookkeeping. Choices made here:

* **Load and concurrency.** At most ``concurrency`` requests are in flight
  per endpoint. A request takes a slot on the endpoint with the fewest in
  flight (ties: lowest index, and on a retry the endpoint that just failed
  goes last among equals); when every slot is taken, requests wait in FIFO
  order and a finished request hands its slot over directly. A request
  holds no slot while it sleeps between retries.
* **Retries.** 429, 408, 5xx, timeouts (``aiohttp.ClientTimeout(total=
  timeout_s)`` per attempt), connection errors, dropped connections and
  malformed JSON bodies are retried with exponential backoff and full
  jitter: wait ``U(0, 1) * min(backoff_max_s, backoff_base_s * 2**k)`` after
  the k-th failure, where ``U`` comes from a ``random.Random`` seeded from
  ``config.seed`` and the request hash (reproducible runs). A
  ``Retry-After`` header (seconds, a float string is accepted, or an HTTP
  date) replaces that wait, capped at ``backoff_max_s``. Caps:
  ``max_retries`` per request and ``max_retries_per_episode`` per non-empty
  tag; past either, :class:`LLMRequestError` names endpoint, last status,
  attempts and reason. Other 4xx are not retried; the error carries the
  server's message (``{"error": {"message"}}``, ``{"message"}`` or
  ``{"detail"}``).
* **Structured output.** With a schema and ``structured`` ``"json_schema"``
  or ``"auto"`` the body carries ``response_format={"type": "json_schema",
  "json_schema": {"name", "schema", "strict": true}}``. In ``"auto"`` a 400
  whose message names response_format / json_schema / guided decoding marks
  that endpoint as unstructured for the rest of the client's life and the
  request is sent again at once without it (not counted as a retry). The
  reply is always run through :func:`~ignjax.agents.llm.parse.parse_reply`
  (schema-checked when there is one); a reply cut at ``max_tokens``
  (``finish_reason == "length"``) is returned, not retried — a seeded,
  temperature-0 model would write the same again — with ``parsed=None``
  and a ``parse_error`` saying so, for the caller's correction prompt.
* **Cache and replay.** See :mod:`ignjax.agents.llm.cache`: the cache is
  read before sending and written after each successful reply (never after
  an error); with ``replay=True`` nothing is sent and a miss raises
  :class:`ReplayMissError` naming the hash and the cache file.
* **The API key** is read from ``os.environ[config.api_key_env]`` when the
  client is entered, kept in a private holder whose repr is ``<secret>``,
  and sent only as ``Authorization: Bearer``. Every message this module
  raises or logs, and every reply text it returns, passes through a
  scrubber that replaces the key's value with ``***`` (a server could echo
  headers back); aiohttp's exceptions are not chained, since they may hold
  the request headers.
* **Latency** of a result is the wall time of the attempt that succeeded
  (send to last byte), not counting queueing or earlier attempts; a cache
  hit reports the stored latency of the original reply.
"""

from __future__ import annotations

import asyncio
import dataclasses
import hashlib
import json
import logging
import math
import os
import random
import re
import time
from collections import defaultdict, deque
from dataclasses import dataclass
from email.utils import parsedate_to_datetime
from typing import Any, Sequence

from ignjax.agents.llm.cache import ResponseCache, request_hash
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.messages import (ChatRequest, ChatResult, ClientStats, ImagePart, LLMRequestError,
                                        ReplayMissError)
from ignjax.agents.llm.parse import parse_reply
from ignjax.errors import ConfigError
from ignjax.errors.extras import optional_module, require_extra

aiohttp = optional_module("aiohttp", "llm")  # the llm extra: pip install "ignjax[llm]"

log = logging.getLogger("ignjax.agents.llm")

RETRY_STATUSES = frozenset({408, 429})
_FALLBACK_HINT = re.compile(r"response_format|json_schema|guided", re.IGNORECASE)



# ---------------------------------------------------------------------------


class _Secret:
    """Holds the API key; shows as ``<secret>``."""

    __slots__ = ("_value",)

    def __init__(self, value: str | None):
        self._value = value or None

    def reveal(self) -> str | None:
        return self._value

    def scrub(self, text: str) -> str:
        """``text`` with every occurrence of the key replaced by ``***``."""
        if self._value and isinstance(text, str):
            return text.replace(self._value, "***")
        return text

    def __repr__(self) -> str:
        return "<secret>" if self._value else "<no key>"

    __str__ = __repr__

    def __reduce__(self):
        raise TypeError("the API key holder cannot be pickled")


@dataclass
class _Attempt:
    kind: str  # "ok", "retry", "fatal"
    status: int | None = None
    reason: str = ""
    retry_after: float | None = None
    reply: dict | None = None
    latency_s: float = 0.0


def _retry_after(value: str | None) -> float | None:
    if not value:
        return None
    try:
        s = float(value)
        return s if math.isfinite(s) and s >= 0 else None
    except ValueError:
        pass
    try:
        return max(0.0, parsedate_to_datetime(value).timestamp() - time.time())
    except (TypeError, ValueError, IndexError, OverflowError):
        return None


def server_message(raw: bytes, limit: int = 500) -> str:
    """The error message in an error body: ``{"error": {"message"}}``,
    ``{"error": "..."}``, ``{"message"}``, ``{"detail"}`` (vLLM, OpenAI,
    FastAPI), else the start of the body."""
    text = raw.decode("utf-8", errors="replace").strip()
    try:
        j = json.loads(text)
    except ValueError:
        return text[:limit] or "(empty body)"
    msg = None
    if isinstance(j, dict):
        e = j.get("error")
        if isinstance(e, dict) and e.get("message"):
            msg = e["message"]
        elif isinstance(e, str) and e:
            msg = e
        elif j.get("message"):
            msg = j["message"]
        elif "detail" in j:
            msg = j["detail"]
    if msg is None:
        msg = j
    msg = msg if isinstance(msg, str) else json.dumps(msg)
    return msg[:limit]


def _rng_seed(seed: int | None, key: str) -> int:
    return int.from_bytes(hashlib.sha256(f"{seed}|{key}".encode()).digest()[:8], "big")


# ---------------------------------------------------------------------------
# the client
# ---------------------------------------------------------------------------


class ChatClient:
    """Async client; use as ``async with ChatClient(config) as client``.

    Args:
        config: the :class:`~ignjax.agents.llm.config.LLMConfig`.
        cache: a :class:`~ignjax.agents.llm.cache.ResponseCache` to use;
            by default one in ``config.cache_dir`` when that is set, opened
            when the client is entered and closed on exit.
    """

    def __init__(self, config: LLMConfig, cache: ResponseCache | None = None):
        if not isinstance(config, LLMConfig):
            raise TypeError(f"expected an LLMConfig, got {type(config).__name__}")
        require_extra("aiohttp", "llm")
        config.check_usable()
        self.config = config
        self._own_cache = cache is None and config.cache_dir is not None  # opened when entered
        self.cache = cache
        if config.replay and cache is None and config.cache_dir is None:
            raise ConfigError(None, "llm.replay", "replay needs a response cache: set cache_dir")
        n = len(config.endpoints)
        self._key = _Secret(None)
        self._session: aiohttp.ClientSession | None = None
        self._entered = False
        self._in_flight_ep = [0] * n
        self._sent_ep = [0] * n
        self._unstructured = [config.structured == "none"] * n
        self._waiters: deque[tuple[asyncio.Future, int | None]] = deque()
        self._episode_retries: dict[str, int] = defaultdict(int)
        self._requests_sent = self._replies_ok = self._failed = self._cache_hits = self._retries = 0
        self._in_flight = self._max_in_flight = 0
        self._prompt_tokens = self._completion_tokens = 0
        self._t_last = self._t_enter = time.monotonic()
        self._integral = 0.0

    # -- lifetime ---------------------------------------------------------

    async def __aenter__(self) -> "ChatClient":
        env = self.config.api_key_env
        self._key = _Secret(os.environ.get(env) if env else None)
        if self._own_cache and self.cache is None:
            self.cache = ResponseCache(self.config.cache_dir)
        if self.config.endpoints and not self.config.replay:
            self._session = aiohttp.ClientSession(connector=aiohttp.TCPConnector(limit=0))
        self._t_last = self._t_enter = time.monotonic()
        self._integral = 0.0
        self._entered = True
        return self

    async def __aexit__(self, *exc) -> None:
        await self.aclose()

    async def aclose(self) -> None:
        """Close the HTTP session and the cache the client opened itself."""
        if self._session is not None:
            await self._session.close()
            self._session = None
        if self._own_cache and self.cache is not None:
            self.cache.close()
            self.cache = None
        self._entered = False

    def __repr__(self) -> str:
        c = self.config
        return (f"ChatClient(model={c.model!r}, endpoints={list(c.endpoints)!r}, concurrency={c.concurrency}, "
                f"structured={c.structured!r}, cache={self.cache!r}, replay={c.replay}, key={self._key!r})")

    # -- public calls -----------------------------------------------------

    async def complete(self, request: ChatRequest) -> ChatResult:
        """The reply to ``request``, from the cache or a server.

        Raises:
            LLMRequestError: non-retryable status, or retries spent.
            ReplayMissError: replay mode and the request is not cached.
        """
        if not self._entered:
            raise RuntimeError("use the client as `async with ChatClient(config) as client:`")
        key = self.request_hash(request)
        if self.cache is not None:
            rec = self.cache.get(key)
            if rec is not None:
                self._cache_hits += 1
                return self._result(request, key, rec, retries=0, cache_hit=True, endpoint=None)
        if self.config.replay:
            raise ReplayMissError(key, str(getattr(self.cache, "path", self.cache)), request.tag)
        rec, endpoint, retries = await self._send(request, key)
        if self.cache is not None:
            self.cache.put(key, rec)
        return self._result(request, key, rec, retries=retries, cache_hit=False, endpoint=endpoint)

    async def complete_many(self, requests: Sequence[ChatRequest]) -> list[ChatResult | Exception]:
        """Replies to all ``requests`` at once (bounded by the concurrency),
        in order; a failed request gives its exception in its place."""
        return list(await asyncio.gather(*(self.complete(r) for r in requests), return_exceptions=True))

    def request_hash(self, request: ChatRequest) -> str:
        """The cache key of ``request`` under this client's config."""
        return request_hash(self.config.model, self.generation_params(request), request.messages, request.schema)

    def generation_params(self, request: ChatRequest) -> dict:
        """Generation settings that enter the request hash."""
        c = self.config
        return {"temperature": c.temperature, "seed": c.seed, "max_tokens": c.max_tokens,
                "structured": c.structured, "schema_name": request.schema_name if request.schema else None,
                "image_detail": c.image_detail, "extra_body": c.extra_body}

    def episode_retries(self, tag: str) -> int:
        """Retries spent so far by requests tagged ``tag``."""
        return self._episode_retries.get(tag, 0)

    def stats(self) -> ClientStats:
        """Snapshot of the counters (see :class:`ClientStats`)."""
        self._tick()
        return ClientStats(
            t=self._t_last, requests_sent=self._requests_sent, replies_ok=self._replies_ok,
            requests_failed=self._failed, cache_hits=self._cache_hits, retries=self._retries,
            in_flight=self._in_flight, max_in_flight=self._max_in_flight, prompt_tokens=self._prompt_tokens,
            completion_tokens=self._completion_tokens, in_flight_seconds=self._integral,
            capacity=self.config.concurrency * len(self.config.endpoints), sent_per_endpoint=tuple(self._sent_ep),
            unstructured_endpoints=tuple(e for e, u in zip(self.config.endpoints, self._unstructured) if u))

    def utilisation(self, since: ClientStats | None = None) -> float:
        """Mean in flight / (concurrency * n_endpoints) from ``since`` (a
        :meth:`stats` snapshot; default: since the client was entered)."""
        now = self.stats()
        if since is None:
            since = dataclasses.replace(now, t=self._t_enter, in_flight_seconds=0.0)
        return now.utilisation_since(since)

    # -- slots ------------------------------------------------------------

    def _tick(self) -> None:
        now = time.monotonic()
        self._integral += self._in_flight * (now - self._t_last)
        self._t_last = now

    def _pick(self, avoid: int | None) -> int | None:
        cap = self.config.concurrency
        free = [i for i, n in enumerate(self._in_flight_ep) if n < cap]
        if not free:
            return None
        return min(free, key=lambda i: (self._in_flight_ep[i], i == avoid, i))

    def _take(self, i: int) -> None:
        self._tick()
        self._in_flight_ep[i] += 1
        self._in_flight += 1
        self._max_in_flight = max(self._max_in_flight, self._in_flight)

    def _release(self, i: int) -> None:
        self._tick()
        self._in_flight_ep[i] -= 1
        self._in_flight -= 1
        while self._waiters:
            j = self._pick(self._waiters[0][1])
            if j is None:
                break
            fut, _ = self._waiters.popleft()
            if fut.done():  # its waiter was cancelled
                continue
            self._take(j)
            fut.set_result(j)

    async def _acquire(self, avoid: int | None) -> int:
        if not self._waiters:
            i = self._pick(avoid)
            if i is not None:
                self._take(i)
                return i
        fut = asyncio.get_running_loop().create_future()
        entry = (fut, avoid)
        self._waiters.append(entry)
        try:
            return await fut
        except asyncio.CancelledError:
            if fut.done() and not fut.cancelled():
                self._release(fut.result())
            elif entry in self._waiters:
                self._waiters.remove(entry)
            raise

    # -- sending ----------------------------------------------------------

    def _wire_messages(self, messages: Sequence[dict]) -> list[dict]:
        out = []
        for m in messages:
            c = m["content"]
            if not isinstance(c, str):
                parts = []
                for p in c:
                    if isinstance(p, str):
                        parts.append({"type": "text", "text": p})
                    elif isinstance(p, ImagePart):
                        url = {"url": p.data_url()}
                        if self.config.image_detail:
                            url["detail"] = self.config.image_detail
                        parts.append({"type": "image_url", "image_url": url})
                    else:
                        parts.append(p)
                c = parts
            out.append({**m, "content": c})
        return out

    def _body(self, request: ChatRequest, wire: list[dict], structured: bool) -> bytes:
        c = self.config
        body: dict[str, Any] = {"model": c.model, "messages": wire, "temperature": c.temperature,
                                "max_tokens": c.max_tokens}
        if c.seed is not None:
            body["seed"] = c.seed
        if structured:
            body["response_format"] = {"type": "json_schema", "json_schema": {
                "name": request.schema_name, "schema": request.schema, "strict": True}}
        if c.extra_body:
            body.update(c.extra_body)
        return json.dumps(body, ensure_ascii=False).encode("utf-8")

    def _fail(self, request: ChatRequest, key: str, *, endpoint: str | None, status: int | None, attempts: int,
              reason: str) -> LLMRequestError:
        s = self._key.scrub
        reason = s(reason)
        ep = s(endpoint) if endpoint else None
        where = f"{ep}/chat/completions" if ep else "chat/completions"
        st = f"HTTP {status}" if status is not None else "no HTTP response"
        tag = f", tag {s(request.tag)!r}" if request.tag else ""
        msg = f"{where}: {st} after {attempts} attempt{'s' if attempts != 1 else ''} (request {key[:12]}{tag}): {reason}"
        self._failed += 1
        log.warning("%s", s(msg))
        return LLMRequestError(s(msg), endpoint=ep, status=status, attempts=attempts, reason=reason,
                               request_hash=key, tag=request.tag)

    async def _send(self, request: ChatRequest, key: str) -> tuple[dict, str, int]:
        c = self.config
        rng = random.Random(_rng_seed(c.seed, key))
        wire = self._wire_messages(request.messages)
        bodies: dict[bool, bytes] = {}
        retries = attempts = 0
        avoid: int | None = None
        while True:
            i = await self._acquire(avoid)
            endpoint = c.endpoints[i]
            structured = request.schema is not None and not self._unstructured[i]
            if structured not in bodies:
                bodies[structured] = self._body(request, wire, structured)
            try:
                attempts += 1
                a = await self._attempt(i, bodies[structured])
            finally:
                self._release(i)
            if a.kind == "ok":
                return self._record(a), endpoint, retries
            if (a.kind == "fatal" and a.status == 400 and structured and c.structured == "auto"
                    and _FALLBACK_HINT.search(a.reason)):
                if not self._unstructured[i]:
                    self._unstructured[i] = True
                    log.warning("%s", self._key.scrub(
                        f"{endpoint}: rejected response_format ({a.reason}); sending requests with a schema "
                        "there without it from now on (structured='auto' fallback)"))
                continue
            if a.kind == "fatal":
                raise self._fail(request, key, endpoint=endpoint, status=a.status, attempts=attempts, reason=a.reason)
            avoid = i
            if retries >= c.max_retries:
                raise self._fail(request, key, endpoint=endpoint, status=a.status, attempts=attempts,
                                 reason=f"{a.reason}; gave up after max_retries={c.max_retries}")
            if request.tag and self._episode_retries[request.tag] >= c.max_retries_per_episode:
                raise self._fail(request, key, endpoint=endpoint, status=a.status, attempts=attempts,
                                 reason=f"{a.reason}; episode {request.tag!r} spent its "
                                        f"max_retries_per_episode={c.max_retries_per_episode}")
            retries += 1
            self._retries += 1
            if request.tag:
                self._episode_retries[request.tag] += 1
            delay = rng.random() * min(c.backoff_max_s, c.backoff_base_s * 2 ** (retries - 1))
            if a.retry_after is not None:
                delay = min(a.retry_after, c.backoff_max_s)
            log.info("%s", self._key.scrub(f"{endpoint}/chat/completions: {a.reason}; retry {retries} in {delay:.3f} s"
                                           f" (request {key[:12]}{', tag ' + repr(request.tag) if request.tag else ''})"))
            await asyncio.sleep(delay)

    async def _attempt(self, i: int, body: bytes) -> _Attempt:
        c = self.config
        url = f"{c.endpoints[i]}/chat/completions"
        headers = {"Content-Type": "application/json"}
        key = self._key.reveal()
        if key:
            headers["Authorization"] = f"Bearer {key}"
        self._requests_sent += 1
        self._sent_ep[i] += 1
        t0 = time.monotonic()
        try:
            async with self._session.post(url, data=body, headers=headers,
                                          timeout=aiohttp.ClientTimeout(total=c.timeout_s)) as resp:
                raw = await resp.read()
                status = resp.status
                retry_after = _retry_after(resp.headers.get("Retry-After"))
        except TimeoutError:
            return _Attempt("retry", None, f"timed out after {c.timeout_s:g} s")
        except (aiohttp.ClientError, OSError) as e:
            return _Attempt("retry", None, f"connection error: {type(e).__name__}: {e}")
        latency = time.monotonic() - t0
        if status == 200:
            try:
                j = json.loads(raw)
                choice = j["choices"][0]
                content = choice["message"].get("content") or ""
                if not isinstance(content, str):
                    raise TypeError("message content is not a string")
            except (ValueError, KeyError, IndexError, TypeError, AttributeError) as e:
                return _Attempt("retry", status, f"malformed reply body ({type(e).__name__}): "
                                                 f"{raw[:120].decode('utf-8', 'replace')!r}")
            usage = j.get("usage") if isinstance(j.get("usage"), dict) else {}
            return _Attempt("ok", status, reply={
                "text": content, "finish_reason": choice.get("finish_reason"),
                "prompt_tokens": int(usage.get("prompt_tokens") or 0),
                "completion_tokens": int(usage.get("completion_tokens") or 0)}, latency_s=latency)
        reason = f"HTTP {status}: {server_message(raw)}"
        if status in RETRY_STATUSES or status >= 500:
            return _Attempt("retry", status, reason, retry_after=retry_after)
        return _Attempt("fatal", status, reason)

    def _record(self, a: _Attempt) -> dict:
        self._replies_ok += 1
        r = dict(a.reply)
        r["text"] = self._key.scrub(r["text"])
        r["latency_s"] = a.latency_s
        r["model"] = self.config.model
        self._prompt_tokens += r["prompt_tokens"]
        self._completion_tokens += r["completion_tokens"]
        return r

    def _result(self, request: ChatRequest, key: str, rec: dict, *, retries: int, cache_hit: bool,
                endpoint: str | None) -> ChatResult:
        text = rec.get("text") or ""
        parsed, err = parse_reply(text, request.schema)
        finish = rec.get("finish_reason")
        if parsed is None and finish == "length":
            err = f"reply cut off at max_tokens={self.config.max_tokens} (finish_reason 'length'): {err}"
        return ChatResult(text=text, parsed=parsed, prompt_tokens=int(rec.get("prompt_tokens") or 0),
                          completion_tokens=int(rec.get("completion_tokens") or 0),
                          latency_s=float(rec.get("latency_s") or 0.0), retries=retries, cache_hit=cache_hit,
                          request_hash=key, endpoint=endpoint, finish_reason=finish, parse_error=err)


__all__ = ["ChatClient", "server_message"]
