"""``python -m ignjax.bench --json``: the last stdout line is one JSON object
with every figure the module docstring lists.

Its smallest run (``--quick``) still times rollouts at B = 256, 1024 and
4096 and the in-the-loop sweep over 500 episodes, many minutes on a small
CPU, so the command itself runs only in the optional ``slow`` tests
(``pytest -m slow``). The default run checks the record's parts that the
bench's library functions make in seconds: the probe-ray agreement
(:func:`ignjax.bench.rays.bench_probe_rays`) and the decision-steps table
(:func:`ignjax.bench.rollouts.bench_steps`, at the test benchmark's size)
and the pieces of a step (:func:`ignjax.bench.pieces.bench_pieces`, 16 episodes).
"""

from __future__ import annotations

import ctypes.util
import json
import math
import os
import subprocess
import sys

import pytest

from ignjax.agents import get_agent
from ignjax.bench.pieces import PIECES, bench_pieces
from ignjax.bench.rays import bench_probe_rays
from ignjax.bench.rl import bench_rl
from ignjax.bench.rollouts import bench_steps

RAY_KEYS = {"fast", "mjx", "mj_multiray", "rollout_depth_march"}
PROBE_KEYS = {"collision", "collision_2m", "observation"}
STUDY_KEYS = {"offline_wsr_1e6_x_500_s", "in_loop_vectors", "in_loop_episodes", "in_loop_s", "in_loop_run_s",
              "in_loop_episodes_per_s"}
TOP_KEYS = {"device", "quick", "n_rays", "ngeom", "rays_per_s", "ray_agreement", "ray_agreement_depth_march",
            "scene_compile_s", "speedup_vs_mjx", "speedup_vs_multiray", "probe_ray_agreement", "rollout_parts",
            "steps_per_s", "compile_s", "studies", "limit", "pieces", "scaling", "time_to_result", "rl"}
RL_KEYS = {"batch", "steps_per_call", "parts", "env_steps_per_s", "episodes_per_s", "random_rollout_steps_per_s", "ratio",
           "compile_s"}
SIZES = ("256", "1024", "4096")


def _positive(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0


def _fraction(v) -> bool:
    return isinstance(v, float) and 0.0 <= v <= 1.0


def check_probe_agreement(rec: dict) -> None:
    assert set(rec) == PROBE_KEYS
    assert all(_fraction(v) for v in rec.values()), rec
    assert rec["collision"] >= 0.99 and rec["collision_2m"] >= 0.98 and rec["observation"] >= 0.9, rec


def check_steps(rec: dict, agents, sizes) -> None:
    assert set(rec) == set(agents)
    for name in agents:
        assert set(rec[name]) == set(sizes), rec[name]
        assert all(_positive(v) for v in rec[name].values()), rec[name]


def check_record(res: dict) -> None:
    """Every documented figure of the bench's JSON object, with sane types."""
    assert TOP_KEYS <= set(res), sorted(TOP_KEYS - set(res))
    assert isinstance(res["device"], str) and res["device"]
    assert res["quick"] is True
    assert isinstance(res["n_rays"], int) and res["n_rays"] > 0 and isinstance(res["ngeom"], int) and res["ngeom"] > 0
    assert set(res["rays_per_s"]) == RAY_KEYS and all(_positive(v) for v in res["rays_per_s"].values())
    assert _fraction(res["ray_agreement"]) and res["ray_agreement"] >= 0.99
    assert _fraction(res["ray_agreement_depth_march"]) and res["ray_agreement_depth_march"] >= 0.99
    for k in ("scene_compile_s", "speedup_vs_mjx", "speedup_vs_multiray"):
        assert _positive(res[k]), k
    check_probe_agreement(res["probe_ray_agreement"])
    assert set(res["rollout_parts"]) == set(SIZES)
    assert all(isinstance(v, int) and v >= 1 for v in res["rollout_parts"].values())
    check_steps(res["steps_per_s"], ("random", "eig"), SIZES)  # --quick: the EIG and random agents only
    assert isinstance(res["compile_s"], float) and math.isfinite(res["compile_s"])
    lim = res["limit"]
    assert lim["bound"] in ("gather", "bandwidth", "compute") and _positive(lim["steps_per_s"])
    assert set(lim["agents"]) == {"random", "eig"} and lim["batch"] == 4096
    for name, a in lim["agents"].items():
        assert _positive(a["fraction"]) and _positive(a["work"]["gather_world"]), (name, a)
    assert all(_positive(v) for v in lim["rates"].values()), lim["rates"]
    check_pieces(res["pieces"], ("random", "eig"), decisions_within=PIECES_DECISIONS_WITHIN)
    check_time_to_result(res["time_to_result"])
    check_rl(res["rl"], 4096)
    s = res["studies"]
    assert set(s) == STUDY_KEYS
    assert s["in_loop_vectors"] == 16 and s["in_loop_episodes"] == 500  # --quick: K = 16
    assert all(_positive(v) for v in s.values()), s


def check_time_to_result(block) -> None:
    """Each task cold and warm: a split that adds up, every program compiled cold and loaded warm, the same bytes."""
    assert set(block) == {"evaluate", "sweep_eval_quick", "in_loop"}
    for name, runs in block.items():
        for state in ("cold", "warm"):
            r = runs[state]
            assert all(_positive(r[k]) for k in ("total_s", "load_s", "compile_s", "run_s")), (name, r)
            assert math.isclose(r["load_s"] + r["compile_s"] + r["run_s"], r["total_s"]), (name, r)
            assert r["programs"] == r["compiled"] + r["cache_hits"] > 0, (name, r)
        assert runs["cold"]["cache_hits"] == 0 and runs["warm"]["compiled"] == 0, (name, runs)
        assert runs.get("same_outputs", True) is True, name


PIECES_DECISIONS_WITHIN = 0.01
"""How far the pieces' decision count may stray from the fused rollout's at B = 4096 (docs/performance.md: compiled apart, they
can round a float differently and change a rare episode; 0.3% of the EIG agent's decisions on the 2-core CPU)."""


def check_pieces(block, agents, decisions_within: float = 0.0):
    """The block's figures; its host loop takes the fused rollout's decisions, to within ``decisions_within``
    of them (a share; 0: exactly)."""
    assert set(block["agents"]) == set(agents) and block["rows"] >= 1
    for name, a in block["agents"].items():
        us = a["us_per_decision"]
        privileged = get_agent(name).privileged
        assert set(us) == set(PIECES) - ({"privileged"} if not privileged else set()) | {"sum", "whole"}, (name, us)
        assert all(_positive(v) for k, v in us.items() if k != "step_other"), (name, us)  # step_other: a difference
        assert math.isclose(us["sum"], sum(v for k, v in us.items() if k not in ("sum", "whole")))
        # the host loop of separately compiled pieces takes the rollout's decisions, up to rounding's rare episodes
        assert a["rollout_decisions"] > 0 and a["decisions"] > 0, (name, a)
        assert abs(a["decisions"] - a["rollout_decisions"]) <= decisions_within * a["rollout_decisions"], (name, a)


def test_pieces_follow_the_rollout(small_benchmark, small_world):
    """The pieces, driven step by step from the host, take exactly the
    decisions of the fused rollout of the same rows (at this size no rounding
    difference changes an episode), and each has a time."""
    block = bench_pieces(small_benchmark["set"], small_world, ("shortest_path",), 16, repeats=1)
    assert block["rows"] == 8 and block["batch"] == 16  # one device's share of 16 over the session's 2 devices
    check_pieces(block, ("shortest_path",))


def check_rl(rec: dict, batch: int) -> None:
    assert set(rec) == RL_KEYS and rec["batch"] == batch and rec["steps_per_call"] == 20 and rec["parts"] >= 1
    assert all(_positive(rec[k]) for k in ("env_steps_per_s", "episodes_per_s", "random_rollout_steps_per_s", "ratio"))
    assert math.isclose(rec["ratio"], rec["env_steps_per_s"] / rec["random_rollout_steps_per_s"])


def test_rl_figures(small_benchmark, small_world):
    """The ``rl`` block at a small batch: env steps/s next to the random rollout's, plain JSON values."""
    rec = bench_rl(small_benchmark["set"], small_world, batch=8, repeats=1)
    check_rl(rec, 8)
    assert json.loads(json.dumps(rec)) == rec


def test_probe_ray_agreement_figures():
    check_probe_agreement(bench_probe_rays(quick=True))


def test_decision_steps_figures(small_benchmark, small_world):
    es = small_benchmark["set"]
    steps, compile_s = bench_steps(es, small_world, ("random",), (len(es),))
    check_steps(steps, ("random",), (str(len(es)),))
    assert math.isnan(compile_s)  # measured for the EIG agent only
    assert json.loads(json.dumps(steps)) == steps  # plain JSON values


@pytest.mark.slow
def test_quick_json_line():
    """``python -m ignjax.bench --quick --json`` (many minutes): the last stdout line parses as the full record."""
    # no rendering variable set, no display: the bench selects headless EGL itself where it is installed
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM", "DISPLAY")}
    proc = subprocess.run([sys.executable, "-m", "ignjax.bench", "--quick", "--json"], capture_output=True, text=True,
                          timeout=3600, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stdout.strip().splitlines()
    assert lines, proc.stderr[-2000:]
    res = json.loads(lines[-1])
    assert isinstance(res, dict)
    check_record(res)
    r = res["render"]
    assert r["views"] == 8 and r["batch"] == 16 and r["workers"] >= 1
    assert set(r["panels_per_s"]) == {"warp@224", "warp@128", "egl@224", "egl@128"}
    for key, v in r["panels_per_s"].items():
        assert v is None or v > 0, key
    if sys.platform.startswith("linux") and ctypes.util.find_library("EGL"):
        assert r["panels_per_s"]["egl@224"] > 0, r
    if r["depth_agreement"] is not None:
        assert r["depth_agreement"] > 0.95 and r["segmentation_agreement"] > 0.95
