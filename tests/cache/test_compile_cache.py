"""The commands' persistent compilation cache: on by default in the ignjax
cache folder, the same output bytes whether programs were compiled or
loaded, and a folder that cannot be written is a warning, not a failure."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def _env(cache: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("JAX_COMPILATION_CACHE", "IGNJAX_NO_CACHE"))}
    return dict(env, IGNJAX_CACHE_DIR=str(cache), PYTHONHASHSEED="0")


def _sweep(small_benchmark, out: Path, env: dict, *extra: str) -> subprocess.CompletedProcess:
    args = [sys.executable, "-m", "ignjax.sweep", "--study", "eval", "--quick", "--quiet", "--out", str(out),
            "--set", f"benchmark.episodes='{small_benchmark['path']}'", "--set", "eval.agents=['random']",
            "--set", "eval.batch=8", "--set", "analysis.trajectories=1", *extra]
    return subprocess.run(args, cwd=REPO, env=env, capture_output=True, text=True, timeout=600)


def _files(folder: Path) -> dict:
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and "checkpoints" not in p.parts}


def test_main_job_twice_cold_then_warm_writes_the_same_bytes(small_benchmark, tmp_path):
    """Two fresh processes on an empty cache folder: the first compiles and
    fills it, the second loads its programs and scene arrays (no new
    compilation entry) and writes every output file byte for byte the same."""
    cache, env = tmp_path / "cache", _env(tmp_path / "cache")
    cold = _sweep(small_benchmark, tmp_path / "cold", env)
    assert cold.returncode == 0, cold.stderr[-3000:]
    entries = {p.name for p in (cache / "jax").iterdir()}
    assert len(entries) > 10, "the first run wrote no compiled programs into <cache>/jax"
    assert list((cache / "derived" / "navgrid").glob("*.npz")) and list((cache / "derived" / "goal_field").glob("*.npz"))
    warm = _sweep(small_benchmark, tmp_path / "warm", env)
    assert warm.returncode == 0, warm.stderr[-3000:]
    added = {p.name for p in (cache / "jax").iterdir()} - entries
    assert not [n for n in added if n.startswith("jit_")], f"the second run compiled again: {sorted(added)[:5]}"
    a, b = _files(tmp_path / "cold"), _files(tmp_path / "warm")
    assert a.keys() == b.keys() and len(a) > 5
    for name in a:
        assert a[name] == b[name], name


def test_unwritable_cache_folder_is_one_warning_and_the_command_goes_on(small_benchmark, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("a file where the cache folder should be")
    house = small_benchmark["root"] / "small_a.usda"
    run = subprocess.run([sys.executable, "-m", "ignjax.build", "inspect", str(house)], cwd=REPO,
                         env=_env(blocker / "cache"), capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stderr.count("cannot be written") == 1 and "compiling without it" in run.stderr
    assert "small_a" in run.stdout
