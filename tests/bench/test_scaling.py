"""``python -m ignjax.bench --scaling``'s curves (:mod:`ignjax.bench.scaling`)
at the test benchmark's size: the record, the figure, the bank of copied
scenes (the same episodes give the same outcomes in it) and the memory
analysis."""

from __future__ import annotations

import json

import jax
import numpy as np
import pytest
from ignjax.agents import get_agent
from ignjax.bench.scaling import _tile, growth_curves, write_growth
from ignjax.sim.rollout import episode_keys, rollout, rollout_memory


def _fields(out):
    return {k: np.asarray(getattr(out, k)) for k in ("final_distance", "path_length", "steps", "stopped",
                                                      "n_questions", "trace_type", "trace_step")}


def test_copied_scenes_give_the_same_outcomes(small_benchmark, small_world):
    es = small_benchmark["set"]
    agent = get_agent("eig")
    params = agent.default_params()
    B = 16
    keys = episode_keys(0, np.arange(B))
    world5, specs5 = _tile(es, small_world, 5, B)
    assert world5.bank.n_scenes == 5 and len(set(world5.bank.scene_ids)) == 5
    scene = np.asarray(specs5.scene)
    assert scene.max() >= 2, "episodes should be spread over the copies"
    base_specs = jax.tree.map(lambda a: a[np.arange(B) % len(es)], es.specs)
    assert np.array_equal(scene % 2, np.asarray(base_specs.scene))
    a = rollout(small_world, base_specs, agent, params, keys, parts=1)[0]
    b = rollout(world5, specs5, agent, params, keys, parts=1)[0]
    fa, fb = _fields(a), _fields(b)
    assert fa and fa.keys() == fb.keys()
    for k in fa:
        assert np.array_equal(fa[k], fb[k]), k
    m2 = rollout_memory(small_world, base_specs, agent, params, keys, parts=1)
    m5 = rollout_memory(world5, specs5, agent, params, keys, parts=1)
    assert m5["arguments"] > m2["arguments"] > 0
    assert m2["peak"] >= m2["arguments"]


@pytest.mark.slow  # about 3 minutes on a 2-core CPU (five rollout programs compiled)
def test_growth_curves_record_and_figure(small_benchmark, small_world, tmp_path):
    es = small_benchmark["set"]
    # a million scenes cannot fit: that point is skipped with its estimate, before anything is allocated
    rec = growth_curves(es, small_world, quick=False, batches=(16, 32), scene_counts=(2, 4, 10**6), vector_counts=(2,),
                        scenes_batch=16, vector_episodes=8, devices_batch=16)
    assert "scenes=1000000" in rec["skipped"] and "GiB" in rec["skipped"]["scenes=1000000"]
    for curve, keys in (("batch", ("16", "32")), ("scenes", ("2", "4")), ("vectors", ("2",))):
        assert sorted(rec[curve], key=int) == list(keys), rec[curve]
        for p in rec[curve].values():
            assert p["steps_per_s"] > 0 and p["decision_steps"] > 0 and p["seconds"] > 0
            assert p["memory_mb"]["peak"] > 0
    # a larger batch needs more temporaries; more scenes a larger world
    assert rec["batch"]["32"]["memory_mb"]["temporaries"] > rec["batch"]["16"]["memory_mb"]["temporaries"]
    assert rec["scenes"]["4"]["world_mb"] > rec["scenes"]["2"]["world_mb"]
    assert rec["scenes"]["4"]["memory_mb"]["arguments"] > rec["scenes"]["2"]["memory_mb"]["arguments"]
    assert set(rec["devices"]) >= {"1"} and all(v > 0 for v in rec["devices"].values())
    files = write_growth(rec, tmp_path / "bench")
    png = (tmp_path / "bench" / "scaling.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    assert json.loads((tmp_path / "bench" / "scaling.json").read_text())["batch"].keys() == rec["batch"].keys()
    assert files["png"].endswith("scaling.png")
    assert not list((tmp_path / "bench").glob(".*tmp*")), "no temporary file left behind"
