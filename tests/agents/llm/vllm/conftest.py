"""A live vLLM server (CPU build) serving the tiny Qwen2-VL-style model.

``vllm_server`` (session scope) starts ``python -m vllm.entrypoints.openai.api_server``
from the environment that ``.ci/prepare-vllm`` builds under
``${IGNJAX_VLLM_HOME:-~/.cache/ignjax/vllm}`` (``venv/``, ``model/``, ``status``),
on a free loopback port, waits until ``/v1/models`` answers, yields a
:class:`VllmServer` (``base_url`` = ``http://127.0.0.1:PORT/v1``, ``model`` =
``"tiny-vl"``, ``log_path``) and stops the server's whole process group at
the end. Where the environment is absent (not prepared, no torch CPU wheel on
the machine, install failed) the tests skip with the reason ``prepare-vllm``
recorded.

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

It uses about 3.1-3.3 GB of RAM (API server 0.7, engine core 0.7, worker 1.8-1.9).
``IGNJAX_VLLM_START_TIMEOUT`` (seconds, default 180) bounds the start.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import time
import urllib.error
import urllib.request
from dataclasses import dataclass
from pathlib import Path

import pytest

SERVED_MODEL = "tiny-vl"
MAX_MODEL_LEN = 4096
MAX_IMAGES = 8
MAX_NUM_SEQS = 8
START_TIMEOUT_S = float(os.environ.get("IGNJAX_VLLM_START_TIMEOUT", "180"))


def vllm_home() -> Path:
    return Path(os.environ.get("IGNJAX_VLLM_HOME") or Path.home() / ".cache" / "ignjax" / "vllm")


def environment_problem(home: Path) -> str | None:
    """Why the prepared environment under ``home`` cannot be used, or None."""
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


@dataclass(frozen=True)
class VllmServer:
    base_url: str  # http://127.0.0.1:PORT/v1
    model: str  # the served model name
    log_path: Path
    model_dir: Path
    max_model_len: int
    max_images: int
    pid: int


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _tail(path: Path, lines: int = 60) -> str:
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        return f"(no log: {exc})"
    return "\n".join(text.splitlines()[-lines:])


def _server_command(python: Path, model_dir: Path, port: int) -> list[str]:
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
        str(MAX_NUM_SEQS),
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
        "--disable-log-stats",
    ]


def _server_env(home: Path) -> dict[str, str]:
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
    if proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, signal.SIGTERM)
    except ProcessLookupError:
        return
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


@pytest.fixture(scope="session")
def vllm_server(tmp_path_factory) -> VllmServer:
    home = vllm_home()
    problem = environment_problem(home)
    if problem:
        pytest.skip(f"vLLM server environment not prepared: run .ci/prepare-vllm ({problem})")
    workdir = tmp_path_factory.mktemp("vllm-server")
    log_path = workdir / "server.log"
    port = _free_port()
    base_url = f"http://127.0.0.1:{port}/v1"
    with open(log_path, "wb") as log:
        proc = subprocess.Popen(
            _server_command(home / "venv" / "bin" / "python", home / "model", port),
            cwd=workdir,  # not the clone: `python -m` puts the cwd on sys.path
            env=_server_env(home),
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # its own process group, stopped as one
        )
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while not _models_answer(base_url):
            if proc.poll() is not None:
                pytest.fail(f"vLLM server exited with {proc.returncode} while starting; log {log_path}:\n{_tail(log_path)}")
            if time.monotonic() > deadline:
                pytest.fail(f"vLLM server did not answer {base_url}/models within {START_TIMEOUT_S:.0f} s; log {log_path}:\n{_tail(log_path)}")
            time.sleep(0.5)
        yield VllmServer(
            base_url=base_url,
            model=SERVED_MODEL,
            log_path=log_path,
            model_dir=home / "model",
            max_model_len=MAX_MODEL_LEN,
            max_images=MAX_IMAGES,
            pid=proc.pid,
        )
    finally:
        _stop(proc)
