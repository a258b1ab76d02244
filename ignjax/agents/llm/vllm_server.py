"""A live vLLM server (CPU build) serving the tiny Qwen2-VL-style model, for
tests and load measurements.

:func:`start_vllm_server` (a context manager) starts
``python -m vllm.entrypoints.openai.api_server`` from the environment that
``.ci/prepare-vllm`` builds under ``${IGNJAX_VLLM_HOME:-~/.cache/ignjax/vllm}``
(``venv/``, ``model/``, ``status``; :func:`vllm_home`), on a loopback port
the server chooses itself (below), in its own process group, waits until
``/v1/models`` answers, yields a
:class:`VllmServer` (``base_url`` = ``http://127.0.0.1:PORT/v1``, ``model`` =
``"tiny-vl"``, ``log_path``) and stops the server's whole process group at
the end. :func:`environment_problem` says why the environment is absent (not
prepared, no torch CPU wheel on the machine, install failed), with the reason
``prepare-vllm`` recorded; the tests skip with it and ``python -m ignjax.bench
--llm`` reports it. This module imports neither torch nor vLLM: the server
runs the prepared environment's own python.

Server settings (vLLM 0.32.0) and why:

- ``--max-model-len 4096 --max-num-seqs 8``;
- ``--limit-mm-per-prompt '{"image": 8, "video": 0}'`` (JSON; a ninth image
  is a 400; no video profiling);
- ``--structured-outputs-config '{"backend": "xgrammar",
  "disable_any_whitespace": true}'`` (``response_format`` json_schema gives
  compact JSON);
- ``--max-num-batched-tokens 4096 --no-enable-chunked-prefill``: on the CPU,
  vLLM 0.32's model runner calls ``Generator.set_offset`` for a *seeded*
  request whose prefill is split into chunks, which CPU generators do not
  support ("CPU Generator does not use offset"): the engine dies and every
  later request gets a 500 or a refused connection. With the default
  2,048-token step budget, any seeded prompt over ~2,048 tokens (eight
  256-token images, say) triggers it. Not chunking prefills avoids it (vLLM
  warns that this model "does not officially support disabling chunked
  prefill"; the conformance tests show it works);
- ``--enforce-eager``: skips torch.compile warm-up (starts in 40-85 s here,
  depending on the machine's load, instead of 30 s more; same outputs);
- ``--seed 0``; ``VLLM_CPU_KVCACHE_SPACE=1`` (GiB); offline Hugging Face.

The port. The server is started with ``--port 0``: it binds 127.0.0.1
port 0 itself, so the OS gives it a free port in the same call that takes
it, and no other program can take that port first (choosing a free port
here, closing it and passing its number would leave a gap in which another
program could bind it). vLLM 0.32 binds its socket before it builds the
engine, listens on it only once the engine is ready, and never says which
port it got (its log says "Starting vLLM server on http://127.0.0.1:0", the
number it was given, and uvicorn, handed the bound socket, logs no
address), so the port is read from the kernel: :func:`listening_ports`
lists the TCP ports on which the server's process (the API server, the
group's leader) holds a listening socket, matching the socket inodes of
``/proc/PID/fd`` with the LISTEN entries of ``/proc/PID/net/tcp`` and
``tcp6``; the server is ready when one of them answers ``/v1/models`` with
the served model. Only the leader's sockets count: vLLM's worker process
listens on a dozen ports of its own. Other ways were ruled out: this entry
point's socket sets ``SO_REUSEADDR`` but not ``SO_REUSEPORT`` (``vllm
serve`` sets it only with several API servers), so a port cannot be held
for it with ``SO_REUSEPORT`` as :func:`ignjax.devices.launch.reserved_port`
does for JAX's coordinator; it takes no socket or file descriptor from its
parent; and ``--uds`` (a Unix socket) would need every client to speak HTTP
over a Unix socket.

It uses about 3.1-3.3 GB of RAM (API server 0.7, engine core 0.7, worker 1.8-1.9).
``IGNJAX_VLLM_START_TIMEOUT`` (seconds, default 180) bounds the start unless
``start_timeout_s`` is given.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

SERVED_MODEL = "tiny-vl"
MAX_MODEL_LEN = 4096
MAX_IMAGES = 8
MAX_NUM_SEQS = 8
DEFAULT_START_TIMEOUT_S = 180.0


class VllmServerError(RuntimeError):
    """The vLLM server could not be started: the environment is not usable,
    or the server exited or did not answer in time (the message holds the
    reason and the tail of its log)."""


def vllm_home() -> Path:
    """The prepared environment's folder: ``$IGNJAX_VLLM_HOME`` or ``~/.cache/ignjax/vllm``."""
    return Path(os.environ.get("IGNJAX_VLLM_HOME") or Path.home() / ".cache" / "ignjax" / "vllm")


def environment_problem(home: Path) -> str | None:
    """Why the prepared environment under ``home`` cannot be used, or None."""
    home = Path(home)
    status_file = home / "status"
    try:
        status = status_file.read_text(encoding="utf-8").strip()
    except OSError:
        return f"no {status_file}"
    if status.startswith("unavailable:"):
        return status.split(":", 1)[1].strip() or "unavailable"
    if status != "ready":
        return f"{status_file} says {status!r}"
    if not (home / "venv" / "bin" / "python").exists():
        return f"{home / 'venv' / 'bin' / 'python'} is missing"
    if not (home / "model" / "config.json").exists():
        return f"{home / 'model' / 'config.json'} is missing"
    return None


def start_timeout_from_env() -> float:
    """``IGNJAX_VLLM_START_TIMEOUT`` in seconds (default 180)."""
    raw = os.environ.get("IGNJAX_VLLM_START_TIMEOUT", "")
    if not raw.strip():
        return DEFAULT_START_TIMEOUT_S
    try:
        value = float(raw)
    except ValueError:
        raise VllmServerError(f"IGNJAX_VLLM_START_TIMEOUT: must be a number of seconds, got {raw!r}") from None
    if not value > 0:
        raise VllmServerError(f"IGNJAX_VLLM_START_TIMEOUT: must be > 0, got {raw!r}")
    return value


@dataclass(frozen=True)
class VllmServer:
    """A running server (:func:`start_vllm_server`)."""

    base_url: str  # http://127.0.0.1:PORT/v1
    model: str  # the served model name
    log_path: Path
    model_dir: Path
    max_model_len: int
    max_images: int
    pid: int
    max_num_seqs: int = MAX_NUM_SEQS


TCP_LISTEN = "0A"
"""The state of a listening socket in ``/proc/net/tcp`` (``TCP_LISTEN`` = 10)."""


def _socket_inodes(pid: int) -> set[str]:
    """The inodes of the sockets among process ``pid``'s open files."""
    fd_dir = Path(f"/proc/{pid}/fd")
    try:
        names = os.listdir(fd_dir)
    except OSError:  # no such process, or not Linux
        return set()
    inodes = set()
    for name in names:
        try:
            target = os.readlink(fd_dir / name)
        except OSError:  # closed meanwhile
            continue
        if target.startswith("socket:[") and target.endswith("]"):
            inodes.add(target[len("socket:["):-1])
    return inodes


def listening_ports(pid: int) -> set[int]:
    """The TCP ports (IPv4 and IPv6) on which process ``pid`` holds a
    listening socket, read from ``/proc``; empty when the process is gone
    or ``/proc`` does not tell (not Linux). A socket that is bound but not
    yet listening is not counted."""
    inodes = _socket_inodes(pid)
    ports = set()
    for table in ("tcp", "tcp6"):
        try:
            lines = Path(f"/proc/{pid}/net/{table}").read_text(encoding="ascii").splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            # sl local_address rem_address st tx_queue:rx_queue tr:tm->when retrnsmt uid timeout inode ...
            fields = line.split()
            if len(fields) > 9 and fields[3] == TCP_LISTEN and fields[9] in inodes:
                ports.add(int(fields[1].rsplit(":", 1)[1], 16))
    return ports


def _tail(path: Path, lines: int = 60) -> str:
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        return f"(no log: {exc})"
    return "\n".join(text.splitlines()[-lines:])


def server_command(python: Path, model_dir: Path, port: int = 0, *, max_num_seqs: int = MAX_NUM_SEQS) -> list[str]:
    """The server's command line (settings and reasons: module docstring);
    ``port`` 0 lets the server take a free port itself."""
    return [
        str(python),
        "-m",
        "vllm.entrypoints.openai.api_server",
        "--model",
        str(model_dir),
        "--served-model-name",
        SERVED_MODEL,
        "--host",
        "127.0.0.1",
        "--port",
        str(port),
        "--max-model-len",
        str(MAX_MODEL_LEN),
        "--max-num-seqs",
        str(max_num_seqs),
        "--max-num-batched-tokens",
        str(MAX_MODEL_LEN),
        "--no-enable-chunked-prefill",
        "--limit-mm-per-prompt",
        json.dumps({"image": MAX_IMAGES, "video": 0}),
        "--structured-outputs-config",
        json.dumps({"backend": "xgrammar", "disable_any_whitespace": True}),
        "--enforce-eager",
        "--seed",
        "0",
    ]


def server_env(home: Path) -> dict[str, str]:
    """The server's environment: ours without Python path settings, offline, caches under ``home``."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "PYTHONSTARTUP")}
    env.update(
        VLLM_CPU_KVCACHE_SPACE="1",
        HF_HUB_OFFLINE="1",
        TRANSFORMERS_OFFLINE="1",
        VLLM_NO_USAGE_STATS="1",
        DO_NOT_TRACK="1",
        HF_HOME=str(home / "hf-home"),
        VLLM_CACHE_ROOT=str(home / "vllm-cache"),
        PYTHONUNBUFFERED="1",
    )
    return env


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        else:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                pass
    try:  # the engine core and worker, should they outlive the API server
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        pass


def _models_answer(base_url: str) -> bool:
    try:
        with urllib.request.urlopen(base_url + "/models", timeout=5) as r:
            return r.status == 200 and any(m.get("id") == SERVED_MODEL for m in json.load(r).get("data", []))
    except (urllib.error.URLError, OSError, ValueError):
        return False


def _serving_url(proc: subprocess.Popen, log: Path, timeout: float) -> str:
    """The base URL of the server ``proc`` started with ``--port 0``, once
    ``/v1/models`` answers on a port its process listens on (module
    docstring: the port)."""
    deadline = time.monotonic() + timeout
    while True:
        ports = listening_ports(proc.pid)
        for port in sorted(ports):
            url = f"http://127.0.0.1:{port}/v1"
            if _models_answer(url):
                return url
        if proc.poll() is not None:
            raise VllmServerError(f"vLLM server exited with {proc.returncode} while starting; log {log}:\n{_tail(log)}")
        if time.monotonic() > deadline:
            listening = ", ".join(map(str, sorted(ports))) or "none"
            where = f"on any port it listens on ({listening})"
            raise VllmServerError(f"vLLM server did not answer /v1/models {where} within {timeout:.0f} s; "
                                  f"log {log}:\n{_tail(log)}")
        time.sleep(0.5)


@contextlib.contextmanager
def start_vllm_server(home: str | os.PathLike | None = None, *, max_num_seqs: int = MAX_NUM_SEQS,
                      start_timeout_s: float | None = None,
                      log_path: str | os.PathLike | None = None) -> Iterator[VllmServer]:
    """Start the tiny model's vLLM server; stop it (its whole process group) on exit.

    Args:
        home: the prepared environment (default :func:`vllm_home`).
        max_num_seqs: sequences the server batches at once (``--max-num-seqs``).
        start_timeout_s: how long to wait for ``/v1/models`` (default
            ``IGNJAX_VLLM_START_TIMEOUT`` or 180 s).
        log_path: the server's stdout and stderr (default: a file in a
            temporary folder, removed on exit unless the start failed).

    Yields:
        the :class:`VllmServer`.

    Raises:
        VllmServerError: the environment is not usable (the reason), or the
            server exited or did not answer in time (the log's tail).
    """
    if max_num_seqs < 1:
        raise VllmServerError(f"max_num_seqs: must be >= 1, got {max_num_seqs}")
    home = Path(home) if home is not None else vllm_home()
    problem = environment_problem(home)
    if problem:
        raise VllmServerError(f"vLLM server environment not prepared: run .ci/prepare-vllm ({problem})")
    timeout = float(start_timeout_s) if start_timeout_s is not None else start_timeout_from_env()
    if not timeout > 0:
        raise VllmServerError(f"start_timeout_s: must be > 0, got {start_timeout_s}")
    # the server's working folder is never the clone: `python -m` puts the cwd on sys.path
    workdir = Path(tempfile.mkdtemp(prefix="ignjax-vllm-"))
    log = Path(log_path) if log_path is not None else workdir / "server.log"
    log.parent.mkdir(parents=True, exist_ok=True)
    keep_workdir = False
    with open(log, "wb") as fh:
        proc = subprocess.Popen(
            server_command(home / "venv" / "bin" / "python", home / "model", 0, max_num_seqs=max_num_seqs),
            cwd=workdir,
            env=server_env(home),
            stdin=subprocess.DEVNULL,
            stdout=fh,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # its own process group, stopped as one
        )
    try:
        try:
            base_url = _serving_url(proc, log, timeout)
        except VllmServerError:
            keep_workdir = True
            raise
        yield VllmServer(
            base_url=base_url,
            model=SERVED_MODEL,
            log_path=log,
            model_dir=home / "model",
            max_model_len=MAX_MODEL_LEN,
            max_images=MAX_IMAGES,
            pid=proc.pid,
            max_num_seqs=max_num_seqs,
        )
    finally:
        _stop(proc)
        if not keep_workdir:
            shutil.rmtree(workdir, ignore_errors=True)


__all__ = ["DEFAULT_START_TIMEOUT_S", "MAX_IMAGES", "MAX_MODEL_LEN", "MAX_NUM_SEQS", "SERVED_MODEL", "VllmServer",
           "VllmServerError", "environment_problem", "listening_ports", "server_command", "server_env",
           "start_timeout_from_env", "start_vllm_server", "vllm_home"]
