"""Where a command's wall time goes: loading, compiling, running.

Two records, both cheap enough to stay on:

* :func:`phase` marks the spans of a named phase (``"load"``: reading an
  episode file, building its scenes' tables and goal fields, building a
  simulator world). Spans of the same phase may nest (``open_benchmark``
  inside ``load_benchmark``); only their union counts.
* :class:`CompileClock` listens to JAX's own compile events (tracing to a
  jaxpr, lowering to StableHLO, and the backend compile, which is a load
  from the persistent cache on a hit) and keeps their spans and counts.

:func:`split` turns both into disjoint seconds: ``compile`` is the union of
the compile spans; ``load`` the load spans outside them (a goal field's
program compiles while the benchmark loads: that time is compile); the rest
of a command's wall time is running (simulating, writing outputs, and the
interpreter's start and imports). ``python -m ignjax.bench`` reports it as
its ``time_to_result`` block (:mod:`ignjax.bench.time_to_result`).
"""

from __future__ import annotations

import functools
import threading
import time
from contextlib import contextmanager

_SPANS: dict[str, list[tuple[float, float]]] = {}
_DEPTH: dict[str, int] = {}
_LOCK = threading.Lock()

PROGRAM_LOAD_EVENT = "/ignjax/programs/load_duration"
"""The event of one program loaded whole from ignjax's program store (:mod:`ignjax.cache.programs`)."""
COMPILE_EVENTS = ("/jax/core/compile/jaxpr_trace_duration", "/jax/core/compile/jaxpr_to_mlir_module_duration",
                  "/jax/core/compile/backend_compile_duration", PROGRAM_LOAD_EVENT)
"""JAX's events for tracing, lowering and the backend compile (or cache load) of one program, and the program
store's load of one program."""


@contextmanager
def phase(name: str):
    """Record the wall-clock span of the body as phase ``name``; nested
    spans of the same phase count once (the outermost)."""
    with _LOCK:
        depth = _DEPTH.get(name, 0)
        _DEPTH[name] = depth + 1
    t0 = time.time()
    try:
        yield
    finally:
        with _LOCK:
            _DEPTH[name] -= 1
            if depth == 0:
                _SPANS.setdefault(name, []).append((t0, time.time()))


def in_phase(name: str):
    """Decorator: every call of the function is a span of phase ``name``."""
    def wrap(fn):
        @functools.wraps(fn)
        def inner(*args, **kwargs):
            with phase(name):
                return fn(*args, **kwargs)
        return inner
    return wrap


def phase_spans(name: str) -> list[tuple[float, float]]:
    """The recorded ``(start, end)`` spans of phase ``name`` (``time.time()`` seconds)."""
    with _LOCK:
        return list(_SPANS.get(name, ()))


class CompileClock:
    """JAX's compile events from the moment it is started: their spans and
    how many programs were obtained, compiled, or loaded (from JAX's
    persistent compilation cache or whole from ignjax's program store)."""

    def __init__(self):
        self.spans: list[tuple[float, float]] = []
        self.names: list[str] = []  # the programs obtained, in order (JAX's names, e.g. "jit(_run_sharded)")
        self.cache_hits = 0
        self.whole = 0  # of the hits, programs loaded whole from the program store (no tracing or lowering)
        self._on = False

    def start(self) -> "CompileClock":
        import jax  # only a process that measures pays for it here

        def span(event, start, end, **kw):
            if self._on and event in COMPILE_EVENTS:
                self.spans.append((start, end))
                if event in (COMPILE_EVENTS[2], PROGRAM_LOAD_EVENT):
                    self.names.append(str(kw.get("fun_name", "?")))
                if event == PROGRAM_LOAD_EVENT:
                    self.cache_hits += 1
                    self.whole += 1

        def count(event, **_):
            if self._on and event == "/jax/compilation_cache/cache_hits":
                self.cache_hits += 1

        jax.monitoring.register_event_time_span_listener(span)
        jax.monitoring.register_event_listener(count)
        self._on = True
        return self

    @property
    def programs(self) -> int:
        """Programs obtained (compiled or loaded from the cache) while started."""
        return len(self.names)

    def stop(self) -> None:
        self._on = False  # JAX keeps the listeners; they do nothing from now on


def union_seconds(spans) -> float:
    """Length of the union of ``(start, end)`` spans."""
    total, end = 0.0, -float("inf")
    for a, b in sorted(spans):
        if b <= end:
            continue
        total += b - max(a, end)
        end = b
    return total


def split(load_spans, compile_spans) -> dict:
    """Disjoint ``load_s`` and ``compile_s``: all compile time, and load time outside it."""
    compile_s = union_seconds(compile_spans)
    load_s = union_seconds(list(load_spans) + list(compile_spans)) - compile_s
    return {"load_s": load_s, "compile_s": compile_s}


__all__ = ["COMPILE_EVENTS", "PROGRAM_LOAD_EVENT", "CompileClock", "in_phase", "phase", "phase_spans", "split", "union_seconds"]
