"""Render worker processes: :class:`RenderPool`.

Why processes: MuJoCo Warp runs each kernel on a single thread when it runs
on the CPU (its CPU path is a sequential loop and not safe to launch from
several threads at once), and OpenGL renders one view at a time, so one
process renders on one core whatever the machine has. A pool of
``ViewConfig.workers`` processes, each holding its own
:class:`~ignjax.sim.views.contexts.SceneContexts`, renders that many calls
at once.

Protocol (one duplex pipe per worker, driven by one parent thread per
worker so a large reply never blocks the sending of the next job):

* ``("scene", s, compiled)``: the first time a worker needs scene ``s`` it
  receives its :class:`~ignjax.scenes.compile.CompiledScene` (a few MB,
  pickled once per worker and scene);
* ``("render", s, poses)`` -> ``("ok", (rgb, depth, instance))`` or
  ``("error", text)``;
* ``("close",)``.

Workers are fresh interpreters (``python -m ignjax.sim.views.pool``; JAX
and OpenGL do not survive a fork, and unlike ``multiprocessing``'s spawn
this never re-runs the caller's main script, so no ``__main__`` guard is
needed) connected over a socket pair they inherit. Each takes a few
seconds to start (imports, JIT); the pool is made once per
:class:`~ignjax.sim.views.renderer.ViewRenderer` and reused across steps. A
worker that dies (killed, out of memory) fails the call with a
:class:`RuntimeError` naming it; nothing waits forever.
"""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
import traceback
from concurrent.futures import ThreadPoolExecutor, wait
from multiprocessing.connection import Connection

import numpy as np


def _serve(conn) -> None:
    """A worker's loop: first message ``("init", backend, sim, config)``."""
    from ignjax.sim.views.contexts import SceneContexts

    _, backend, sim, config = conn.recv()
    compiled: dict = {}
    contexts = SceneContexts(compiled.__getitem__, backend, sim, config)
    try:
        while True:
            msg = conn.recv()
            if msg[0] == "close":
                break
            if msg[0] == "scene":
                compiled[msg[1]] = msg[2]
                continue
            try:
                conn.send(("ok", contexts.render(msg[1], msg[2])))
            except Exception:  # reported to the parent, which raises it
                conn.send(("error", traceback.format_exc()))
    except (EOFError, KeyboardInterrupt):
        pass
    finally:
        contexts.close()
        conn.close()


class RenderPool:
    """``n`` render processes.

    Args:
        compiled: ``compiled(s)`` gives scene ``s``'s compiled scene (parent side).
        backend: ``"warp"`` or ``"egl"`` (resolved).
        sim, config: as :class:`~ignjax.sim.views.renderer.ViewRenderer`'s.
        n: worker count (>= 2).
    """

    def __init__(self, compiled, backend: str, sim, config, n: int):
        self.compiled, self.n = compiled, n
        one = config.replace(workers=1)
        self._conns, self._procs, self._known = [], [], []
        for _ in range(n):
            mine, theirs = socket.socketpair()
            with theirs:
                self._procs.append(subprocess.Popen([sys.executable, "-m", "ignjax.sim.views.pool", str(theirs.fileno())],
                                                    pass_fds=[theirs.fileno()], stdin=subprocess.DEVNULL))
            conn = Connection(mine.detach())
            conn.send(("init", backend, sim, one))
            self._conns.append(conn)
            self._known.append(set())
        self._threads = ThreadPoolExecutor(n, thread_name_prefix="ignjax-render")
        self._lock = threading.Lock()
        self._closed = False

    def _run(self, w: int, jobs):
        conn, known, out = self._conns[w], self._known[w], []
        try:
            for s, poses in jobs:
                if s not in known:
                    conn.send(("scene", s, self.compiled(s)))
                    known.add(s)
                conn.send(("render", s, np.ascontiguousarray(poses, np.float32)))
                kind, value = conn.recv()
                if kind == "error":
                    raise RuntimeError(f"render worker {w} failed:\n{value}")
                out.append(value)
        except (EOFError, BrokenPipeError, ConnectionResetError, OSError) as e:
            p = self._procs[w]
            try:
                code = p.wait(timeout=1.0)
            except subprocess.TimeoutExpired:
                code = None
            raise RuntimeError(f"render worker {w} (pid {p.pid}) exited with code {code} "
                               f"while rendering: {type(e).__name__}") from None
        return out

    def render_many(self, calls):
        """Results of ``calls`` [(scene, poses), ...] in order; call i goes to
        worker i mod n."""
        if self._closed:
            raise RuntimeError("the render pool is closed")
        queues = [[] for _ in range(self.n)]
        for i, c in enumerate(calls):
            queues[i % self.n].append(c)
        with self._lock:
            futures = [self._threads.submit(self._run, w, q) for w, q in enumerate(queues)]
            wait(futures)  # every worker idle again before an error is raised
            per_worker = [f.result() for f in futures]
        return [per_worker[i % self.n][i // self.n] for i in range(len(calls))]

    def render(self, s: int, poses: np.ndarray):
        return self.render_many([(s, poses)])[0]

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        for conn in self._conns:
            try:
                conn.send(("close",))
            except (OSError, BrokenPipeError):
                pass
        for p in self._procs:
            try:
                p.wait(timeout=10.0)
            except subprocess.TimeoutExpired:
                pass
        self._kill()
        for conn in self._conns:
            conn.close()
        self._threads.shutdown(wait=False)

    def _kill(self) -> None:
        for p in self._procs:
            if p.poll() is None:
                p.kill()
                p.wait(timeout=5.0)

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass


def _main(argv) -> None:
    _serve(Connection(int(argv[0])))


if __name__ == "__main__":
    _main(sys.argv[1:])


__all__ = ["RenderPool"]
