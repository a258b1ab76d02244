"""``python -m ignjax.bench --scaling``'s curves (:mod:`ignjax.bench.scaling`)
at the test benchmark's size: the record, the figure, the scenes copied to
reach a point's count (a copy's episodes give the same outcomes as the
original's) and the memory analysis, bucket by bucket."""

from __future__ import annotations

import json
import os

import jax
import numpy as np
import pytest
from ignjax.agents import get_agent
from ignjax.bench.scaling import growth_curves, write_growth
from ignjax.episodes.dataset import open_benchmark
from ignjax.evaluate.runner import WORLD_BYTES_PER_CELL, make_world
from ignjax.scenes.buckets import padded_bytes
from ignjax.sim.rollout import episode_keys, rollout


def _fields(out):
    return {k: np.asarray(getattr(out, k)) for k in ("final_distance", "path_length", "steps", "stopped",
                                                      "n_questions", "trace_type", "trace_step")}


def test_copied_scenes_give_the_same_outcomes(small_benchmark):
    """Five scenes made of the test benchmark's two: each copy a scene of its
    own in the bank, and an episode's copy runs as the episode does."""
    scenes = open_benchmark(small_benchmark["path"])
    five = scenes.with_scenes(5)
    assert five.host.n_scenes == 5 and len(set(five.host.scene_ids)) == 5
    assert five.host.scene_ids[:2] == scenes.host.scene_ids
    assert len(five) == sum(len(np.flatnonzero(scenes.scene_of() == k % 2)) for k in range(5))
    one = scenes.with_scenes(1)
    assert one.host.n_scenes == 1 and {r["scene_id"] for r in one.records} == {scenes.host.scene_ids[0]}
    es5 = five.episode_set(np.arange(len(five)))
    assert es5.bank.n_scenes == 5
    copies = [k for k, r in enumerate(five.records) if r["scene_id"].endswith("~1")]
    assert copies
    originals = [next(k for k, o in enumerate(five.records) if o["episode_id"] == five.records[c]["episode_id"].rsplit("~", 1)[0])
                 for c in copies]
    agent = get_agent("eig")
    params = agent.default_params()
    world5 = make_world(es5)
    keys = episode_keys(0, np.zeros(len(copies), np.int64))  # same key for original and copy
    run = lambda idx: rollout(world5, jax.tree.map(lambda a: a[np.asarray(idx)], es5.specs), agent, params, keys,  # noqa: E731
                              parts=1)[0]
    fa, fb = _fields(run(originals)), _fields(run(copies))
    for k in fa:
        assert np.array_equal(fa[k], fb[k]), k


@pytest.mark.slow  # about 3 minutes on a 2-core CPU (five rollout programs compiled)
def test_growth_curves_record_and_figure(small_benchmark, tmp_path):
    scenes = open_benchmark(small_benchmark["path"])
    # a budget of one scene: the four scenes run in four buckets
    one = max(padded_bytes([g], 64, WORLD_BYTES_PER_CELL) for g in scenes.host.navgrids) / 2**20
    rec = growth_curves(scenes, quick=False, batches=(16, 32), scene_counts=(2, 4), vector_counts=(2,),
                        scenes_batch=16, vector_episodes=8, devices_batch=16, bank_mb=one)
    assert rec["scenes"]["4"]["buckets"] == 4
    assert rec["scenes"]["4"]["bank_total_mb"] > rec["scenes"]["2"]["bank_total_mb"]
    assert rec["scenes"]["4"]["world_mb"] == pytest.approx(rec["scenes"]["2"]["world_mb"])
    for curve, keys in (("batch", ("16", "32")), ("scenes", ("2", "4")), ("vectors", ("2",))):
        assert sorted(rec[curve], key=int) == list(keys), rec[curve]
        for p in rec[curve].values():
            assert p["steps_per_s"] > 0 and p["decision_steps"] > 0 and p["seconds"] > 0
            assert p["memory_mb"]["peak"] > 0
    # a larger batch needs more temporaries; more scenes a larger world
    assert rec["batch"]["32"]["memory_mb"]["temporaries"] > rec["batch"]["16"]["memory_mb"]["temporaries"]
    assert set(rec["devices"]) >= {"1"} and all(v > 0 for v in rec["devices"].values())
    if len(rec["devices"]) > 1 and hasattr(os, "sched_setaffinity"):  # one device in a process pinned to one core
        assert rec["one_device_one_core"] > 0
    files = write_growth(rec, tmp_path / "bench")
    png = (tmp_path / "bench" / "scaling.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    assert json.loads((tmp_path / "bench" / "scaling.json").read_text())["batch"].keys() == rec["batch"].keys()
    assert files["png"].endswith("scaling.png")
    assert not list((tmp_path / "bench").glob(".*tmp*")), "no temporary file left behind"
