"""Helpers of the speed figures: one timed call, best-of-N rounds in which
several functions take turns, and progress lines on stderr."""

from __future__ import annotations

import math
import sys
import time
from typing import Sequence


def timed(fn) -> float:
    """Seconds one call of ``fn`` takes."""
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def time_interleaved(fns: Sequence, repeat: int = 3) -> list[float]:
    """Best-of-``repeat`` seconds of each function after a warm-up, the
    functions taking turns in every round, so that a machine whose speed
    drifts (a shared VM) slows each of them alike and their ratios hold."""
    for fn in fns:
        fn()
    best = [math.inf] * len(fns)
    for _ in range(repeat):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            best[i] = min(best[i], time.perf_counter() - t0)
    return best


def log(msg: str) -> None:
    """A progress line on stderr (stdout carries the figures)."""
    print(msg, file=sys.stderr, flush=True)
