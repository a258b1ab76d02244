"""Runs of several processes (``--processes N``, JAX's distributed runtime on
127.0.0.1): the outputs are the same bytes as one process's, a process that
dies ends the run cleanly and ``--resume`` completes it from the part files,
and bad process settings are refused before any work.

Real subprocesses and the real ``jax.distributed``; every process gets one
CPU device (``IGNJAX_CPU_DEVICES=1``), so two processes use the CI
machine's two cores."""

from __future__ import annotations

import errno
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ignjax.devices.launch import reserved_port, strip_processes
from ignjax.devices.processes import ProcessGroup, share
from ignjax.evaluate.cli import main as evaluate_main
from ignjax.sweep.cli import main as sweep_main

REPO = Path(__file__).resolve().parents[2]
EPISODES = REPO / "scenes" / "benchmark.jsonl.gz"
OUTPUTS = ("outcomes.parquet", "outcomes.csv", "metrics.csv", "trajectories.npz", "run.json")


def _env() -> dict:
    return dict(os.environ, IGNJAX_CPU_DEVICES="1", PYTHONHASHSEED="0")


def _evaluate_args(out: Path) -> list[str]:
    # 24 batches of one episode: process 1 still has batches to run when it is killed after the first part
    return [sys.executable, "-m", "ignjax.evaluate", "--episodes", str(EPISODES), "--agent", "random", "--limit", "24",
            "--batch", "1", "--quiet", "--out", str(out)]


def _run(args, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run(args, cwd=REPO, env=_env(), capture_output=True, text=True, timeout=timeout)


def _same_files(a: Path, b: Path, skip=("checkpoints",)) -> None:
    files = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file() and not set(skip) & set(p.parts))
    assert files == sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file() and not set(skip) & set(p.parts))
    for f in files:
        assert (a / f).read_bytes() == (b / f).read_bytes(), f


@pytest.fixture(scope="module")
def one_process(tmp_path_factory):
    out = tmp_path_factory.mktemp("eval1") / "run"
    r = _run(_evaluate_args(out))
    assert r.returncode == 0, r.stderr[-3000:]
    return out


def test_two_processes_write_the_bytes_of_one(one_process, tmp_path):
    out = tmp_path / "run"
    r = _run(_evaluate_args(out) + ["--processes", "2"])
    assert r.returncode == 0, r.stderr[-3000:]
    assert "process 1 of 2: joining the coordinator" in r.stderr
    for name in OUTPUTS:
        assert (out / name).read_bytes() == (one_process / name).read_bytes(), name
    assert not (out / "parts").exists()  # part files are gone once the outputs are written


def _children(pid: int) -> list[int]:
    try:
        return [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


def _kill_after_first_part(args, parts: Path, timeout=240) -> tuple[subprocess.Popen, str]:
    """Start a launcher, SIGKILL its process 1 once a part file is written; return it finished and its stderr,
    once every process it started is gone."""
    proc = subprocess.Popen(args, cwd=REPO, env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        if parts.is_dir() and any(parts.glob("*/part_*.npz")):
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before a process could be killed: " + proc.stderr.read()[-3000:]
    kids = _children(proc.pid)
    assert len(kids) == 2, kids
    os.kill(kids[1], signal.SIGKILL)
    _, err = proc.communicate(timeout=60)
    for k in kids:  # the launcher stopped and reaped every process
        with pytest.raises(ProcessLookupError):
            os.kill(k, 0)
    return proc, err


def test_killed_process_fails_the_run_and_resume_completes_it(one_process, tmp_path):
    out = tmp_path / "run"
    args = _evaluate_args(out) + ["--processes", "2"]
    proc, err = _kill_after_first_part(args, out / "parts")
    assert proc.returncode != 0
    assert "error: process 1 of 2 was killed by SIGKILL; stopping the others" in err
    assert not (out / "outcomes.csv").exists()
    done = _run(args + ["--resume"])
    assert done.returncode == 0, done.stderr[-3000:]
    kept = int(done.stderr.split("resuming: ", 1)[1].split()[0])
    assert kept >= 1  # the finished batches were reused
    for name in OUTPUTS:
        assert (out / name).read_bytes() == (one_process / name).read_bytes(), name


@pytest.mark.slow
def test_sweep_with_two_processes_killed_and_resumed_equals_one(tmp_path):
    """The sweep's eval and in-loop cost stages (K cost vectors per batch) split over two processes: a killed
    process fails the run, ``--resume`` completes it, and the run folder holds the bytes of one process's run."""
    sets = [f"benchmark.episodes='{EPISODES}'", "benchmark.limit=4", "eval.agents=['random']", "eval.batch=1",
            f"run.out='{tmp_path}'", "costs.samples=200", "costs.scales=[1.0, 4.0]", "sim.max_steps=8"]
    base = [sys.executable, "-m", "ignjax.sweep", "--study", "eval,costs", "--quick", "--quiet"]
    base += sum((["--set", s] for s in sets), [])
    one = _run(base + ["--out", str(tmp_path / "one")], timeout=600)
    assert one.returncode == 0, one.stderr[-3000:]
    two = base + ["--out", str(tmp_path / "two"), "--processes", "2"]
    proc, err = _kill_after_first_part(two, tmp_path / "two" / "parts", timeout=400)
    assert proc.returncode != 0 and "process 1 of 2 was killed by SIGKILL; stopping the others" in err
    done = _run(two + ["--resume"], timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "resuming: " in done.stderr
    _same_files(tmp_path / "one", tmp_path / "two")


# ---------------------------------------------------------------------------
# bad input: clear errors before any work
# ---------------------------------------------------------------------------


def _err(main, capsys, argv) -> str:
    assert main(argv) == 2
    return capsys.readouterr().err


@pytest.mark.parametrize("main", [evaluate_main, sweep_main])
@pytest.mark.parametrize("flags, message", [
    (["--num-processes", "0", "--process-id", "0"], "--num-processes: must be >= 1, got 0"),
    (["--num-processes", "2", "--process-id", "2", "--coordinator", "127.0.0.1:1234"],
     "--process-id: must be in 0..1 (--num-processes is 2), got 2"),
    (["--num-processes", "2", "--process-id", "-1", "--coordinator", "127.0.0.1:1234"], "--process-id: must be >= 0"),
    (["--num-processes", "2", "--coordinator", "127.0.0.1:1234"], "--process-id: --num-processes is 2"),
    (["--num-processes", "2", "--process-id", "1"], "--coordinator: --num-processes is 2"),
    (["--num-processes", "2", "--process-id", "1", "--coordinator", "localhost"], "--coordinator: expected HOST:PORT"),
    (["--processes", "0"], "--processes: must be >= 1, got 0"),
    (["--processes", "2", "--process-id", "1"], "--processes: starts its processes itself"),
    (["--coordinator-timeout", "0"], "--coordinator-timeout: must be > 0"),
])
def test_bad_process_settings_are_refused(main, flags, message, capsys, tmp_path):
    argv = (["--episodes", str(EPISODES), "--agent", "random"] if main is evaluate_main else ["--study", "eval"])
    assert message in _err(main, capsys, argv + ["--out", str(tmp_path / "o")] + flags)


def test_environment_variables_are_checked(monkeypatch, capsys, tmp_path):
    monkeypatch.setenv("JAX_NUM_PROCESSES", "2")
    monkeypatch.setenv("JAX_PROCESS_ID", "5")
    monkeypatch.setenv("JAX_COORDINATOR_ADDRESS", "127.0.0.1:1234")
    err = _err(evaluate_main, capsys, ["--episodes", str(EPISODES), "--agent", "random", "--out", str(tmp_path)])
    assert "JAX_PROCESS_ID: must be in 0..1 (JAX_NUM_PROCESSES is 2), got 5" in err


def test_silent_coordinator_is_an_error_within_the_timeout(tmp_path):
    with reserved_port() as port:  # held, never listening: every connection to it is refused
        r = _run(_evaluate_args(tmp_path / "o") + ["--num-processes", "2", "--process-id", "1", "--coordinator",
                                                    f"127.0.0.1:{port}", "--coordinator-timeout", "2"], timeout=120)
    assert r.returncode == 2, r.stderr[-2000:]
    assert f"--coordinator: the coordinator 127.0.0.1:{port} did not answer within 2 s" in r.stderr


def _bind_error(port: int, *options: int) -> int | None:
    """The errno of binding and listening on 127.0.0.1:``port`` with the given SOL_SOCKET options set, or None."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        for opt in options:
            s.setsockopt(socket.SOL_SOCKET, opt, 1)
        try:
            s.bind(("127.0.0.1", port))
            s.listen()
        except OSError as e:
            return e.errno
        return None


def test_a_reserved_port_is_held_until_released():
    """Two reservations get different ports; while one is held, connections are refused, a plain socket cannot
    bind it, and a ``SO_REUSEPORT`` listener (what JAX's gRPC coordinator opens) can; once that listener holds
    it, a ``SO_REUSEADDR`` socket cannot either. Once released, a plain socket binds it."""
    with reserved_port() as a, reserved_port() as b:
        assert a != b and a > 0 and b > 0
        assert _bind_error(a) == errno.EADDRINUSE
        with pytest.raises(ConnectionRefusedError):
            socket.create_connection(("127.0.0.1", a), timeout=10).close()
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as server:
            server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
            server.bind(("127.0.0.1", a))
            server.listen()
            assert _bind_error(a, socket.SO_REUSEADDR) == errno.EADDRINUSE
            with socket.create_connection(("127.0.0.1", a), timeout=10) as client:
                conn, peer = server.accept()
                conn.close()
                assert peer == client.getsockname()
    assert _bind_error(b) is None  # released: a plain socket binds it


def test_too_many_parts_for_a_process_is_refused_and_ends_the_run(tmp_path):
    r = _run(_evaluate_args(tmp_path / "o") + ["--processes", "2", "--parts", "2"], timeout=120)
    assert r.returncode == 2
    assert "--parts: must be in 0..1" in r.stderr
    assert "error: process" in r.stderr and "exited with code 2; stopping the others" in r.stderr


def test_mllm_agents_are_refused_with_several_processes(capsys, tmp_path):
    err = _err(evaluate_main, capsys, ["--episodes", str(EPISODES), "--agent", "vlm", "--llm-endpoint", "http://x/v1",
                                       "--llm-model", "m", "--processes", "2", "--out", str(tmp_path)])
    assert "--processes: the MLLM agents (vlm) run in one process" in err


def test_each_process_gets_a_contiguous_block_of_batches():
    assert [list(share(7, 3, i)) for i in range(3)] == [[0, 1, 2], [3, 4], [5, 6]]
    assert [list(share(1, 3, i)) for i in range(3)] == [[0], [], []]
    assert list(ProcessGroup().share(5)) == [0, 1, 2, 3, 4]
    assert strip_processes(["--a", "--processes", "2", "--b", "--processes=3", "--processe", "4"]) == ["--a", "--b"]
