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


def _sweep_args(small_benchmark) -> list[str]:
    return ["--study", "eval", "--quick", "--quiet", "--set", f"benchmark.episodes='{small_benchmark['path']}'",
            "--set", "eval.agents=['random']", "--set", "eval.batch=8", "--set", "analysis.trajectories=1"]


def test_main_job_twice_cold_then_warm_writes_the_same_bytes(small_benchmark, tmp_path):
    """Two fresh processes on an empty cache folder (the bench's
    ``time_to_result`` measurement): the first compiles and fills it, the
    second loads every program from it (no new compilation entry; the
    rollout programs whole, without tracing) and its scene arrays, and writes every output file byte for byte the same; the
    block's split adds up."""
    from ignjax.bench.time_to_result import cold_and_warm

    cache = tmp_path / "cache"
    seen: dict = {}  # the compiled entries after the cold run (the log line comes after each run)
    runs = cold_and_warm("sweep", _sweep_args(small_benchmark), tmp_path, env=_env(cache),
                         log=lambda line: seen.setdefault("entries", {p.name for p in (cache / "jax").iterdir()}))
    cold, warm = runs["cold"], runs["warm"]
    assert len(seen["entries"]) > 10, "the first run wrote no compiled programs into <cache>/jax"
    assert list((cache / "derived" / "navgrid").glob("*.npz")) and list((cache / "derived" / "goal_field").glob("*.npz"))
    added = {p.name for p in (cache / "jax").iterdir()} - seen["entries"]
    assert not [n for n in added if n.startswith("jit_")], f"the second run compiled again: {sorted(added)[:5]}"
    assert runs["same_outputs"] is True
    # at least the goal-field program, the rollout program and the episode keys' (tables go up by device_put)
    assert cold["compiled"] == cold["programs"] >= 3 and cold["cache_hits"] == 0
    assert warm["compiled"] == 0 and warm["cache_hits"] == warm["programs"] >= 3
    stored = list((cache / "programs" / "rollout").glob("*.npz"))  # the rollout programs, kept whole
    assert stored and cold["whole"] == 0 and warm["whole"] == len(stored), (len(stored), warm)
    for r in (cold, warm):
        assert r["load_s"] > 0 and r["compile_s"] > 0 and r["run_s"] > 0
        assert abs(r["load_s"] + r["compile_s"] + r["run_s"] - r["total_s"]) < 1e-6


def test_unwritable_cache_folder_is_one_warning_and_the_command_goes_on(small_benchmark, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("a file where the cache folder should be")
    house = small_benchmark["root"] / "small_a.usda"
    run = subprocess.run([sys.executable, "-m", "ignjax.build", "inspect", str(house)], cwd=REPO,
                         env=_env(blocker / "cache"), capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stderr.count("cannot be written") == 1 and "compiling without it" in run.stderr
    assert "small_a" in run.stdout
