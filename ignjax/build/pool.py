"""``--workers N`` of the build commands: per-scene work in worker processes.

:func:`resolve_workers` turns the option into a process count (0: one per
usable CPU core). :func:`ordered_map` yields a function ``map_(fn, items)``
that returns ``fn(item)`` for every item **in the order of the items**: the
built-in, lazy :func:`map` in this process for one worker, else a
:class:`~concurrent.futures.ProcessPoolExecutor` whose processes are started
with ``spawn`` (JAX and MuJoCo's OpenGL are not safe to fork). A worker's
exception is raised in this process when its item's turn comes, exactly as
the serial loop would raise it (errors of ignjax pickle by their fields); the
items not started yet are then cancelled and the pool shut down, so a failing
build ends instead of hanging. A worker process that dies (killed, out of
memory) ends the command with an error that says so.

Everything random in the build flows from (seed, scene), never from the order
in which scenes are processed, so N workers give the same bytes as one.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Callable, Iterable, Iterator

from ignjax.errors import ConfigError, IgnjaxError


class WorkerError(IgnjaxError):
    """A worker process ended without returning its result."""


def resolve_workers(workers, option: str = "--workers") -> int:
    """The number of processes ``--workers`` asks for: ``workers`` itself
    when >= 1, one per CPU core this process may run on when 0.

    Raises:
        ConfigError: ``workers`` is not an integer >= 0.
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 0:
        raise ConfigError(None, option, f"must be an integer >= 0 (0: one per CPU core), got {workers!r}")
    if workers == 0:
        return max(1, len(os.sched_getaffinity(0)))
    return workers


def _init_worker() -> None:
    # several processes may share one accelerator: none takes most of its memory up front
    os.environ.setdefault("XLA_PYTHON_CLIENT_PREALLOCATE", "false")


def _ordered(results: Iterator) -> Iterator:
    try:
        yield from results
    except BrokenProcessPool as e:
        raise WorkerError(f"a worker process ended abruptly (killed or out of memory?); try fewer --workers ({e})") from e


@contextlib.contextmanager
def ordered_map(workers: int, tasks: int | None = None):
    """Context giving ``map_(fn, items)``, results in item order (see the
    module docstring). ``fn`` must be a module-level function and the items
    picklable when ``workers > 1``. ``tasks`` (the most items one map gets)
    caps the number of processes started."""
    n = workers if tasks is None else min(workers, max(tasks, 1))
    if n <= 1:
        yield map
        return
    pool = ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"), initializer=_init_worker)

    def map_(fn: Callable, items: Iterable) -> Iterator:
        return _ordered(pool.map(fn, items))

    try:
        yield map_
    finally:
        # on an error: drop the items not started, wait for the running ones (no stray processes)
        pool.shutdown(wait=True, cancel_futures=True)


__all__ = ["WorkerError", "ordered_map", "resolve_workers"]
