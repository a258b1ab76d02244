"""Ending a command's process without tearing it down.

Once a command's ``main`` has returned, everything it writes is written
(atomically, :func:`ignjax.fileio.atomic_write`). Python's own shutdown then
spends 0.3-0.5 s (2-core CPU, after a run that loaded the shipped benchmark)
freeing every module, every array and the XLA runtime's clients, thread
pools and loaded programs, memory the operating system takes back at once
anyway. :func:`exit_now` keeps the steps of that shutdown that can matter
and skips the teardown: it waits for the threads that Python would wait
for (non-daemon threads, including the executors' workers), runs the exit
handlers (``atexit``, e.g. logging's flush), flushes the standard streams
and ends the process with the command's exit status.

Used by the ``python -m ignjax.<command>`` entry points only: a ``main``
called from Python (a notebook, the tests) returns as usual.
"""

from __future__ import annotations

import atexit
import os
import sys
import threading
from typing import NoReturn


def exit_now(status: int | str | None) -> NoReturn:
    """End the process with ``status`` as ``sys.exit`` would (None: 0; a message: printed, 1), without the
    teardown (module docstring)."""
    if status is None or isinstance(status, int):
        code = status or 0
    else:
        print(status, file=sys.stderr)
        code = 1
    threading._shutdown()  # what the interpreter runs first at exit: joins non-daemon threads, executors' hooks
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):  # closed or replaced streams: nothing to flush
            pass
    os._exit(code)


__all__ = ["exit_now"]
