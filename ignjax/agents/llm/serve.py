"""A scripted OpenAI-compatible chat server: a TEST DOUBLE, not a model.

It answers ``POST /v1/chat/completions`` with replies computed from the
request alone (never from simulator state), so the client, the agents built
on it and the benchmarks can be exercised end to end without a GPU:

* **Request checks** like a real server: a JSON object with ``model`` (an
  unknown model gets 404), a non-empty ``messages`` list whose contents are
  strings or parts of type ``text`` / ``image_url``; images must be
  ``data:<mime>;base64,...`` URLs whose base64 decodes. A bad shape gets 400
  ``{"error": {"message": ..., "type": "invalid_request_error"}}``.
  ``reject_response_format=True`` answers any request carrying
  ``response_format`` with a 400 naming it, as vLLM does without guided
  decoding.
* **Replies.** With a ``policy`` callable, ``policy(request_json) -> str``
  is the reply. Otherwise, with ``response_format`` of type
  ``json_schema``, an instance valid under the schema is generated
  (enum values, integers within bounds, every property, one ``anyOf`` /
  ``oneOf`` branch) by a ``random.Random`` seeded with the SHA-256 of the
  message texts, the SHA-256 of each image and the request's ``seed``;
  otherwise a small JSON object when the last user text contains the word
  JSON (or ``response_format`` is ``json_object``), else a short sentence.
  The server's own ``--seed`` drives latency and faults, not replies, so
  two servers answer the same request alike (like one model served twice).
  A reply longer than ``max_tokens`` (whitespace tokens) is cut there with
  ``finish_reason`` ``"length"``.
* **Usage** is an approximation: ``prompt_tokens`` = whitespace-separated
  words of all text parts + 256 per image; ``completion_tokens`` = words
  of the reply.
* **Load.** At most ``concurrency`` requests are served at once (an
  ``asyncio.Semaphore``); the rest queue. A served request sleeps
  ``latency * (1 + jitter * u)``, ``u`` uniform in [-1, 1] from a per-request
  RNG seeded by (server seed, SHA-256 of the body, how many times this
  body was received) — deterministic for the same request sequence, while a
  retried request draws anew. :meth:`ScriptedServer.stats` reports requests
  received, most served at once, queue high-water mark, faults by kind and
  responses by status; :attr:`ScriptedServer.arrivals` gives the time each
  recent request arrived, on the server's own ``time.monotonic`` clock (the
  wait a client let pass between two requests, as the server saw it).
* **Faults** (``--faults SPEC``), grammar::

      SPEC := ITEM ("," ITEM)*
      ITEM := KIND ":" PROBABILITY       e.g. 429:0.1  (per request, seeded)
            | KIND "@" N ["-" M]          e.g. 500@2, drop@3-5  (the N-th
                                          (to M-th) request received, from 1)
      KIND := slow | drop | malformed | truncated | an HTTP status 400-599

  Positional items win over probabilities; probabilities may sum to at
  most 1 and are tried in the order written against one uniform draw.
  ``429`` answers at once (before the queue) with ``Retry-After:
  <retry_after>`` — a float string such as ``0.05``, which is not
  standard HTTP (integer seconds or a date) but keeps tests fast; other
  statuses answer after the latency with an error body. ``slow`` sleeps
  ``slow_s`` (default 30 s) before answering, past a client's timeout;
  ``drop`` closes the connection without a response; ``malformed``
  answers 200 with a body that is not JSON; ``truncated`` answers 200 with
  a valid envelope whose content is cut in the middle and
  ``finish_reason`` ``"length"``.

Use it as ``with ScriptedServer(latency=0.0, faults="500@1") as srv:
srv.base_url`` (its own thread and event loop; port 0, the default, lets
the OS choose a free port as the server binds it, and ``srv.port`` is the
port it got), or from a shell: ``python -m ignjax.agents.llm.serve --port
0``, which prints ``... listening on http://127.0.0.1:PORT/v1 ...`` with the
bound port once it serves.
"""

from __future__ import annotations

import argparse
import asyncio
import base64
import binascii
import collections
import hashlib
import json
import random
import re
import signal
import sys
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable

from ignjax.agents.llm.scripted import DATA_URL, cut_words, scripted_reply, texts_and_images
from ignjax.errors import ConfigError
from ignjax.errors.extras import optional_module

web = optional_module("aiohttp.web", "llm")

DEFAULT_MODEL = "ignjax-scripted"
NAMED_FAULTS = ("slow", "drop", "malformed", "truncated")
TOKENS_PER_IMAGE = 256
ROLES = ("system", "user", "assistant", "tool", "developer")
DESCRIPTION = ("ignjax scripted test double: replies are computed from the request text by a script, "
               "not by a language model")


# ---------------------------------------------------------------------------
# faults
# ---------------------------------------------------------------------------


def _fault_kind(kind: str, item: str) -> str:
    if kind in NAMED_FAULTS:
        return kind
    if kind.isdigit() and 400 <= int(kind) <= 599:
        return kind
    raise ConfigError(None, "--faults", f"item {item!r}: unknown fault kind {kind!r}; use "
                      f"{', '.join(NAMED_FAULTS)} or an HTTP status 400-599")


@dataclass(frozen=True)
class FaultSpec:
    """Parsed ``--faults`` (see the module doc for the grammar).

    Attributes:
        rates: ``(kind, probability)`` in the order written.
        positions: ``(first, last, kind)`` request-number ranges (1-based).
    """

    rates: tuple[tuple[str, float], ...] = ()
    positions: tuple[tuple[int, int, str], ...] = ()

    @classmethod
    def parse(cls, spec: "str | FaultSpec | None") -> "FaultSpec":
        if spec is None or isinstance(spec, FaultSpec):
            return spec or cls()
        rates, positions = [], []
        for item in (s.strip() for s in spec.split(",")):
            if not item:
                continue
            if "@" in item:
                kind, _, where = item.partition("@")
                kind = _fault_kind(kind.strip(), item)
                m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", where)
                if not m or int(m.group(1)) < 1 or (m.group(2) and int(m.group(2)) < int(m.group(1))):
                    raise ConfigError(None, "--faults", f"item {item!r}: expected KIND@N or KIND@N-M with 1 <= N <= M")
                lo = int(m.group(1))
                hi = int(m.group(2)) if m.group(2) else lo
                for a, b, _k in positions:
                    if lo <= b and a <= hi:
                        raise ConfigError(None, "--faults", f"item {item!r}: overlaps request numbers {a}-{b}")
                positions.append((lo, hi, kind))
            elif ":" in item:
                kind, _, p = item.rpartition(":")
                kind = _fault_kind(kind.strip(), item)
                try:
                    prob = float(p)
                except ValueError:
                    prob = -1.0
                if not 0.0 <= prob <= 1.0:
                    raise ConfigError(None, "--faults", f"item {item!r}: probability must be a number in [0, 1]")
                rates.append((kind, prob))
            else:
                raise ConfigError(None, "--faults", f"item {item!r}: expected KIND:PROBABILITY or KIND@N")
        total = sum(p for _, p in rates)
        if total > 1.0 + 1e-9:
            raise ConfigError(None, "--faults", f"probabilities sum to {total:g}, more than 1")
        return cls(tuple(rates), tuple(positions))

    def choose(self, n: int, u: float) -> str | None:
        """The fault of the ``n``-th request received, given its uniform draw ``u``."""
        for lo, hi, kind in self.positions:
            if lo <= n <= hi:
                return kind
        acc = 0.0
        for kind, p in self.rates:
            acc += p
            if u < acc:
                return kind
        return None


# ---------------------------------------------------------------------------
# request checks
# ---------------------------------------------------------------------------


class _Reject(Exception):
    def __init__(self, status: int, message: str, kind: str = "invalid_request_error"):
        super().__init__(message)
        self.status, self.message, self.kind = status, message, kind


def _check_request(body: Any, model: str) -> None:
    if not isinstance(body, dict):
        raise _Reject(400, "request body must be a JSON object")
    if not isinstance(body.get("model"), str):
        raise _Reject(400, "field 'model' is required and must be a string")
    if body["model"] != model:
        raise _Reject(404, f"The model `{body['model']}` does not exist.", "NotFoundError")
    msgs = body.get("messages")
    if not isinstance(msgs, list) or not msgs:
        raise _Reject(400, "field 'messages' must be a non-empty list")
    for i, m in enumerate(msgs):
        if not isinstance(m, dict):
            raise _Reject(400, f"messages[{i}] must be an object")
        if m.get("role") not in ROLES:
            raise _Reject(400, f"messages[{i}].role must be one of {', '.join(ROLES)}; got {m.get('role')!r}")
        c = m.get("content")
        if isinstance(c, str) or (c is None and m["role"] == "assistant"):
            continue
        if not isinstance(c, list) or not c:
            raise _Reject(400, f"messages[{i}].content must be a string or a non-empty list of parts")
        for j, p in enumerate(c):
            where = f"messages[{i}].content[{j}]"
            if not isinstance(p, dict) or p.get("type") not in ("text", "image_url"):
                raise _Reject(400, f"{where} must be a part of type 'text' or 'image_url'")
            if p["type"] == "text":
                if not isinstance(p.get("text"), str):
                    raise _Reject(400, f"{where}.text must be a string")
                continue
            iu = p.get("image_url")
            url = iu.get("url") if isinstance(iu, dict) else None
            if not isinstance(url, str):
                raise _Reject(400, f"{where}.image_url.url must be a string")
            mm = DATA_URL.match(url)
            if not mm:
                raise _Reject(400, f"{where}.image_url.url must be a data:<mime>;base64,... URL "
                                   "(the scripted server fetches nothing)")
            try:
                data = base64.b64decode(mm.group("b64"), validate=True)
            except (binascii.Error, ValueError):
                raise _Reject(400, f"{where}.image_url.url: base64 data does not decode") from None
            if not data:
                raise _Reject(400, f"{where}.image_url.url: image is empty")
    for k, lo, hi in (("temperature", 0.0, 2.0), ("top_p", 0.0, 1.0)):
        v = body.get(k)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float)) or not lo <= v <= hi):
            raise _Reject(400, f"field '{k}' must be a number in [{lo}, {hi}]")
    mt = body.get("max_tokens")
    if mt is not None and (isinstance(mt, bool) or not isinstance(mt, int) or mt < 1):
        raise _Reject(400, "field 'max_tokens' must be a positive integer")
    seed = body.get("seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int)):
        raise _Reject(400, "field 'seed' must be an integer")
    if body.get("stream"):
        raise _Reject(400, "field 'stream': streaming is not supported by the scripted server")
    if body.get("n", 1) != 1:
        raise _Reject(400, "field 'n' must be 1")
    rf = body.get("response_format")
    if rf is not None:
        if not isinstance(rf, dict) or rf.get("type") not in ("text", "json_object", "json_schema"):
            raise _Reject(400, "field 'response_format.type' must be text, json_object or json_schema")
        if rf["type"] == "json_schema":
            js = rf.get("json_schema")
            if not isinstance(js, dict) or not isinstance(js.get("schema"), dict) or not isinstance(js.get("name"), str):
                raise _Reject(400, "field 'response_format.json_schema' needs a string 'name' and an object 'schema'")


def _error(status: int, message: str, kind: str = "invalid_request_error", headers=None) -> web.Response:
    return web.json_response({"error": {"message": message, "type": kind, "param": None, "code": status}},
                             status=status, headers=headers)


# ---------------------------------------------------------------------------
# the server
# ---------------------------------------------------------------------------


class ScriptedServer:
    """The test double on its own thread and event loop.

    Args:
        model: the one model id it serves.
        latency: seconds a served request sleeps (before jitter).
        jitter: relative jitter of that sleep (``latency * (1 + jitter*u)``).
        concurrency: requests served at once; more queue.
        faults: a fault SPEC string or :class:`FaultSpec` (module doc).
        seed: seeds latency jitter and faults.
        policy: ``policy(request_json) -> str`` scripts the reply text.
        reject_response_format: answer 400 to any ``response_format``.
        retry_after: ``Retry-After`` seconds sent with a 429 fault.
        slow_s: how long a ``slow`` fault sleeps.
        history: how many recent request bodies :attr:`requests` (and
            arrival times, :attr:`arrivals`) it keeps.
        host, port: where to listen (port 0: a free port, chosen as the
            server binds it; :attr:`port` is then the bound port).
    """

    def __init__(self, *, model: str = DEFAULT_MODEL, latency: float = 0.0, jitter: float = 0.0,
                 concurrency: int = 64, faults: "str | FaultSpec | None" = None, seed: int = 0,
                 policy: Callable[[dict], str] | None = None, reject_response_format: bool = False,
                 retry_after: float = 0.05, slow_s: float = 30.0, history: int = 64,
                 host: str = "127.0.0.1", port: int = 0):
        if latency < 0 or not 0 <= jitter <= 1:
            raise ConfigError(None, "--latency/--jitter", "latency must be >= 0 and jitter in [0, 1]")
        if concurrency < 1:
            raise ConfigError(None, "--concurrency", f"must be >= 1, got {concurrency}")
        self.model, self.latency, self.jitter, self.concurrency = model, float(latency), float(jitter), int(concurrency)
        self.faults = FaultSpec.parse(faults)
        self.seed, self.policy = int(seed), policy
        self.reject_response_format = reject_response_format
        self.retry_after, self.slow_s = float(retry_after), float(slow_s)
        self.host, self.port = host, int(port)
        self._history = collections.deque(maxlen=max(1, history))
        self._arrivals = collections.deque(maxlen=max(1, history))
        self._lock = threading.Lock()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._runner: web.AppRunner | None = None
        self._sem: asyncio.Semaphore | None = None
        self.reset_stats()

    # -- stats ------------------------------------------------------------

    def reset_stats(self) -> None:
        """Zero the counters (the request numbering of positional faults too)."""
        with self._lock:
            self._received = 0
            self._serving = self._max_serving = self._waiting = self._queue_hw = 0
            self._faults: collections.Counter = collections.Counter()
            self._statuses: collections.Counter = collections.Counter()
            self._attempts: collections.Counter = collections.Counter()
            self._last_request: dict | None = None
            self._last_headers: dict = {}
            self._last_images: list[tuple[str, bytes]] = []
            self._history.clear()
            self._arrivals.clear()

    def stats(self) -> dict:
        """``requests`` received, ``max_concurrent`` served at once,
        ``queue_high_water``, ``in_service`` now, ``faults`` by kind and
        ``statuses`` of the responses sent."""
        with self._lock:
            return {"requests": self._received, "max_concurrent": self._max_serving,
                    "queue_high_water": self._queue_hw, "in_service": self._serving,
                    "faults": dict(self._faults), "statuses": dict(self._statuses)}

    @property
    def last_request(self) -> dict | None:
        """The JSON body of the last chat request received."""
        with self._lock:
            return self._last_request

    @property
    def last_headers(self) -> dict:
        """The HTTP headers of the last chat request received."""
        with self._lock:
            return dict(self._last_headers)

    @property
    def last_images(self) -> list[tuple[str, bytes]]:
        """``(mime, decoded bytes)`` of each image of the last request."""
        with self._lock:
            return list(self._last_images)

    @property
    def requests(self) -> list[dict]:
        """The last ``history`` chat request bodies, oldest first."""
        with self._lock:
            return list(self._history)

    @property
    def arrivals(self) -> list[float]:
        """``time.monotonic()`` on the server when each of the last
        ``history`` chat requests arrived (every one received, rejected or
        not), oldest first."""
        with self._lock:
            return list(self._arrivals)

    @property
    def base_url(self) -> str:
        return f"http://{self.host}:{self.port}/v1"

    # -- handlers ---------------------------------------------------------

    def app(self) -> web.Application:
        app = web.Application(client_max_size=256 * 1024**2)
        app.router.add_get("/v1/models", self._models)
        app.router.add_get("/health", self._health)
        app.router.add_post("/v1/chat/completions", self._chat)
        return app

    async def _health(self, request: web.Request) -> web.Response:
        return web.Response(text="ok")

    async def _models(self, request: web.Request) -> web.Response:
        return web.json_response({"object": "list", "data": [{
            "id": self.model, "object": "model", "created": 0, "owned_by": "ignjax-scripted-test-double",
            "root": self.model, "description": DESCRIPTION}]})

    def _count(self, status: int) -> None:
        with self._lock:
            self._statuses[status] += 1

    async def _chat(self, request: web.Request) -> web.StreamResponse:
        arrived = time.monotonic()
        raw = await request.read()
        key = hashlib.sha256(raw).hexdigest()
        with self._lock:
            self._arrivals.append(arrived)
            self._received += 1
            n = self._received
            self._attempts[key] += 1
            attempt = self._attempts[key]
            self._last_headers = dict(request.headers)
        rng = random.Random(int.from_bytes(hashlib.sha256(f"{self.seed}|{key}|{attempt}".encode()).digest()[:8], "big"))
        fault = self.faults.choose(n, rng.random())
        sleep_s = self.latency * (1.0 + self.jitter * rng.uniform(-1.0, 1.0))
        try:
            body = json.loads(raw)
        except ValueError:
            self._count(400)
            return _error(400, "request body is not valid JSON")
        try:
            _check_request(body, self.model)
        except _Reject as e:
            self._count(e.status)
            return _error(e.status, e.message, e.kind)
        with self._lock:
            self._last_request = body
            self._last_images = texts_and_images(body)[1]
            self._history.append(body)
        if self.reject_response_format and "response_format" in body:
            self._count(400)
            return _error(400, "response_format (json_schema) is not supported by this server: "
                               "guided decoding is not available")
        if fault == "429":
            return self._fault_status(429)
        with self._lock:
            self._waiting += 1
            self._queue_hw = max(self._queue_hw, self._waiting)
        try:
            await self._sem.acquire()
        finally:
            with self._lock:
                self._waiting -= 1
        try:
            with self._lock:
                self._serving += 1
                self._max_serving = max(self._max_serving, self._serving)
            await asyncio.sleep(sleep_s)
            return await self._answer(request, body, fault)
        finally:
            with self._lock:
                self._serving -= 1
            self._sem.release()

    def _fault_status(self, status: int) -> web.Response:
        with self._lock:
            self._faults[str(status)] += 1
            self._statuses[status] += 1
        headers = {"Retry-After": f"{self.retry_after:g}"} if status == 429 else None
        msg = "rate limited (scripted fault)" if status == 429 else f"scripted fault: HTTP {status}"
        return _error(status, msg, "server_error" if status >= 500 else "invalid_request_error", headers)

    async def _answer(self, request: web.Request, body: dict, fault: str | None) -> web.StreamResponse:
        if fault and fault.isdigit():
            return self._fault_status(int(fault))
        if fault:
            with self._lock:
                self._faults[fault] += 1
        if fault == "slow":
            await asyncio.sleep(self.slow_s)
        if fault == "drop":
            request.transport.close()  # no response: the client sees the connection drop
            return web.Response(status=500)
        if fault == "malformed":
            self._count(200)
            return web.Response(status=200, text='{"id": "chatcmpl-scripted", "choices": [{"mess',
                                content_type="application/json")
        content = scripted_reply(body, self.policy)
        finish = "stop"
        mt = body.get("max_tokens")
        if mt is not None:
            cut = cut_words(content, int(mt))
            if cut != content:
                content, finish = cut, "length"
        if fault == "truncated":
            content, finish = content[: max(1, len(content) // 2)], "length"
        texts, images = texts_and_images(body)
        prompt_tokens = sum(len(t.split()) for t in texts) + TOKENS_PER_IMAGE * len(images)
        completion_tokens = len(content.split())
        digest = hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()
        self._count(200)
        return web.json_response({
            "id": f"chatcmpl-scripted-{digest[:16]}", "object": "chat.completion", "created": int(time.time()),
            "model": self.model, "system_fingerprint": "ignjax-scripted-test-double",
            "choices": [{"index": 0, "message": {"role": "assistant", "content": content},
                         "finish_reason": finish, "logprobs": None}],
            "usage": {"prompt_tokens": prompt_tokens, "completion_tokens": completion_tokens,
                      "total_tokens": prompt_tokens + completion_tokens}})

    # -- lifetime ---------------------------------------------------------

    async def _startup(self) -> None:
        self._sem = asyncio.Semaphore(self.concurrency)
        self._runner = web.AppRunner(self.app(), handler_cancellation=True, shutdown_timeout=0.5, access_log=None)
        await self._runner.setup()
        site = web.TCPSite(self._runner, self.host, self.port)
        await site.start()
        self.port = self._runner.addresses[0][1]

    def start(self) -> "ScriptedServer":
        """Start serving on a background thread; returns when it listens."""
        if self._thread is not None:
            raise RuntimeError("server already started")
        self._loop = asyncio.new_event_loop()
        ready = threading.Event()
        failure: list[BaseException] = []

        def run():
            asyncio.set_event_loop(self._loop)
            try:
                self._loop.run_until_complete(self._startup())
            except BaseException as e:  # reported to start()'s caller
                failure.append(e)
                ready.set()
                return
            ready.set()
            self._loop.run_forever()

        self._thread = threading.Thread(target=run, name=f"scripted-llm-server-{id(self):x}", daemon=True)
        self._thread.start()
        if not ready.wait(30) or failure:
            self._thread.join(1)
            self._thread = None
            raise RuntimeError(f"scripted server did not start on {self.host}:{self.port}: "
                               f"{failure[0] if failure else 'timed out'}")
        return self

    def stop(self) -> None:
        """Stop serving (cancelling requests in service) and join the thread."""
        if self._thread is None:
            return
        loop = self._loop
        if self._runner is not None:
            asyncio.run_coroutine_threadsafe(self._runner.cleanup(), loop).result(30)
        loop.call_soon_threadsafe(loop.stop)
        self._thread.join(30)
        loop.close()
        self._thread = self._loop = self._runner = None

    def __enter__(self) -> "ScriptedServer":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()


# ---------------------------------------------------------------------------
# command line
# ---------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    """The command line of :func:`main`."""
    ap = argparse.ArgumentParser(prog="python -m ignjax.agents.llm.serve",
                                 description="Scripted OpenAI-compatible chat server. A TEST DOUBLE: replies are "
                                             "computed from the request text by a script, not by a model.")
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, default=8000,
                    help="0: a free port, chosen as the server binds it (the ready line names it)")
    ap.add_argument("--model", default=DEFAULT_MODEL)
    ap.add_argument("--latency", type=float, default=0.0, help="seconds per served request")
    ap.add_argument("--jitter", type=float, default=0.0, help="relative latency jitter in [0, 1]")
    ap.add_argument("--concurrency", type=int, default=64, help="requests served at once; more queue")
    ap.add_argument("--faults", default=None, help="e.g. 429:0.1,500:0.05,drop:0.02 or 500@1,drop@3-4")
    ap.add_argument("--seed", type=int, default=0, help="seeds latency jitter and faults")
    ap.add_argument("--retry-after", type=float, default=0.05, help="Retry-After seconds of a 429 fault")
    ap.add_argument("--slow-s", type=float, default=30.0, help="how long a 'slow' fault sleeps")
    ap.add_argument("--reject-response-format", action="store_true",
                    help="answer 400 to requests with response_format (like vLLM without guided decoding)")
    return ap


def main(argv: list[str] | None = None) -> int:
    """``python -m ignjax.agents.llm.serve``: run the test double until
    SIGINT / SIGTERM."""
    ap = build_parser()
    args = ap.parse_args(argv)
    try:
        srv = ScriptedServer(model=args.model, latency=args.latency, jitter=args.jitter,
                             concurrency=args.concurrency, faults=args.faults, seed=args.seed,
                             reject_response_format=args.reject_response_format, retry_after=args.retry_after,
                             slow_s=args.slow_s, host=args.host, port=args.port)
    except ConfigError as e:
        ap.error(str(e))
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    with srv:
        print(f"scripted test-double chat server (not a model) listening on {srv.base_url} "
              f"serving model {srv.model!r}", flush=True)
        while not stop.wait(0.5):
            pass
    print("scripted server stopped", file=sys.stderr, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
