"""``--processes N``: start N copies of a command line on this machine.

The launcher reserves a port on 127.0.0.1 for the coordinator
(:func:`reserved_port`, held for the whole run), starts N copies of
``python -m <module> <arguments>`` with ``--coordinator``,
``--num-processes`` and ``--process-id`` set (and, unless
``IGNJAX_CPU_DEVICES`` is set, each with its share of the cores as CPU
devices), and waits for them. The first process that exits non-zero ends
the run: the launcher stops the others (SIGTERM, then SIGKILL after a few
seconds), says which process failed and how, and exits non-zero (that
process's exit code, or 1 when a signal ended it). Nothing is left running.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator

from ignjax.devices import ENV_VAR, available_cores
from ignjax.devices.processes import local_cpu_devices

LAUNCHED_ENV = "IGNJAX_LAUNCHED"
"""Set in the processes a launcher starts (they never launch again)."""

KILL_GRACE_S = 5.0
"""Seconds between SIGTERM and SIGKILL when the launcher stops the others."""


@contextlib.contextmanager
def reserved_port(host: str = "127.0.0.1") -> Iterator[int]:
    """Hold a TCP port (the OS's choice) for the ``with`` block: yields its number.

    The port is held by a socket bound to ``host`` with ``SO_REUSEPORT`` and
    ``SO_REUSEADDR`` that never listens, so connections to the port are
    refused until a server takes it. The OS gives the port to no one who
    asks for port 0 while it is held, and a socket that sets neither option
    gets ``EADDRINUSE``, so no other program can come by the port between
    the choice and its use. The sockets that can bind it meanwhile are
    ``SO_REUSEPORT`` sockets of the same user, such as the gRPC server of
    JAX's coordination service (gRPC sets the option on Linux), and, while
    nothing listens on it, sockets that set ``SO_REUSEADDR``, such as the
    check process 0 makes that the coordinator's port is free
    (:mod:`ignjax.devices.processes`). Without ``SO_REUSEADDR`` here that
    check would fail; with it, a program that binds this very port number
    with ``SO_REUSEADDR`` before the coordinator listens could take it, but
    such a program must have been given the number, since no port-0 bind
    returns it.
    """
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        s.bind((host, 0))
        yield s.getsockname()[1]


def strip_processes(argv: list[str]) -> list[str]:
    """``argv`` without ``--processes N`` / ``--processes=N`` (or an abbreviation argparse accepts)."""
    out, skip = [], False
    for tok in argv:
        if skip:
            skip = False
            continue
        name = tok.split("=", 1)[0]
        if len(name) >= len("--processe") and "--processes".startswith(name):
            skip = "=" not in tok
            continue
        out.append(tok)
    return out


def _describe(code: int) -> str:
    if code < 0:
        try:
            return f"was killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"was killed by signal {-code}"
    return f"exited with code {code}"


def _stop(procs: list[subprocess.Popen], grace: float) -> None:
    for p in procs:
        if p.poll() is None:
            p.terminate()
    deadline = time.monotonic() + grace
    for p in procs:
        try:
            p.wait(max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def launch(module: str, argv: list[str], n: int, *, quiet_flag: str | None = "--quiet", grace: float = KILL_GRACE_S,
           poll_s: float = 0.1) -> int:
    """Run ``python -m module argv`` as ``n`` processes of one run on this machine.

    Args:
        module: the command line's module (``ignjax.evaluate``, ``ignjax.sweep``).
        argv: its arguments (``--processes`` is dropped).
        n: processes (>= 2).
        quiet_flag: added to the arguments of every process but 0 (one progress display).

    The coordinator's port stays reserved (:func:`reserved_port`) until the
    processes are done, so no other program can take it before process 0's
    coordinator binds it.

    Returns:
        0 when every process exited with 0; else the exit code of the first
        process that failed (1 when a signal ended it).
    """
    if os.environ.get(LAUNCHED_ENV):
        print("error: --processes: this process was itself started by a launcher", file=sys.stderr)
        return 2
    with reserved_port() as port:
        return _run(module, argv, n, port, quiet_flag, grace, poll_s)


def _run(module: str, argv: list[str], n: int, port: int, quiet_flag: str | None, grace: float, poll_s: float) -> int:
    """:func:`launch` with the coordinator's port held by the caller."""
    base = strip_processes(list(argv))
    env = dict(os.environ, **{LAUNCHED_ENV: "1"})
    if not env.get(ENV_VAR, "").strip():
        env[ENV_VAR] = str(local_cpu_devices(n, available_cores()))
    procs: list[subprocess.Popen] = []
    print(f"starting {n} processes (coordinator 127.0.0.1:{port}, {env[ENV_VAR]} CPU devices each)", file=sys.stderr,
          flush=True)

    def on_signal(signum, frame):
        _stop(procs, grace)
        sys.exit(128 + signum)

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGTERM, signal.SIGINT)}
    try:
        for i in range(n):
            args = base + ["--coordinator", f"127.0.0.1:{port}", "--num-processes", str(n), "--process-id", str(i)]
            if i and quiet_flag and quiet_flag not in args:
                args.append(quiet_flag)
            procs.append(subprocess.Popen([sys.executable, "-m", module] + args, env=env))
        while True:
            codes = [p.poll() for p in procs]
            failed = next((i for i, c in enumerate(codes) if c not in (None, 0)), None)
            if failed is not None:
                code = codes[failed]
                print(f"error: process {failed} of {n} {_describe(code)}; stopping the others", file=sys.stderr,
                      flush=True)
                _stop(procs, grace)
                return code if code > 0 else 1
            if all(c == 0 for c in codes):
                return 0
            time.sleep(poll_s)
    finally:
        _stop(procs, grace)
        for s, h in old.items():
            signal.signal(s, h)


__all__ = ["KILL_GRACE_S", "LAUNCHED_ENV", "launch", "reserved_port", "strip_processes"]
