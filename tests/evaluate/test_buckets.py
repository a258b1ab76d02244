"""Benchmarks run a bucket of scenes at a time: the byte estimate the plan
uses against the world's real arrays, the plan's buckets, and a bucketed run
equal to a one-bank run (library and ``python -m ignjax.evaluate --bank-mb``)."""

from __future__ import annotations

import dataclasses
import json

import jax
import numpy as np
import pytest

from ignjax.agents.llm.serve import ScriptedServer
from ignjax.episodes.dataset import open_benchmark
from ignjax.errors import ConfigError
from ignjax.evaluate.cli import main
from ignjax.evaluate.runner import (WORLD_BYTES_PER_CELL, bucket_batches, make_world, plan_run, run_agent)
from ignjax.scenes.buckets import padded_bytes, plan_buckets


@pytest.fixture(scope="module")
def scenes(small_benchmark):
    return open_benchmark(small_benchmark["path"])


def _world_bytes(world) -> int:
    return sum(a.nbytes for a in jax.tree.leaves(world))


def test_estimate_matches_the_worlds_arrays(scenes):
    """The plan's estimate is the world's bytes (bank, probe maps, goal
    fields) to within the small per-instance tables it leaves out."""
    for pos in [np.arange(len(scenes))] + [np.flatnonzero(scenes.scene_of() == s) for s in range(2)]:
        es = scenes.episode_set(pos)
        targets = np.unique(np.stack([np.asarray(es.specs.scene), np.asarray(es.specs.field)], 1), axis=0)
        per_scene = np.bincount(targets[:, 0], minlength=es.bank.n_scenes)
        assert per_scene.sum() == len(es.fields)
        est = padded_bytes(es.bank.navgrids, per_scene, WORLD_BYTES_PER_CELL)
        real = _world_bytes(make_world(es))
        assert est <= real and real - est < 64 * 1024, (est, real)


def test_plan_buckets_fit_the_budget(scenes):
    grids = scenes.host.navgrids
    sizes = [padded_bytes([g]) for g in grids]
    whole = padded_bytes(grids)
    assert whole > sum(sizes)  # two scenes of different sizes: padding costs
    assert plan_buckets(grids, whole) == [[0, 1]]
    split = plan_buckets(grids, whole - 1)
    assert sorted(i for b in split for i in b) == [0, 1] and len(split) == 2
    # fewest grid rows first
    rows = [grids[b[0]].shape[0] for b in split]
    assert rows == sorted(rows)
    # a scene over the budget on its own still gets its bucket
    assert sorted(map(tuple, plan_buckets(grids, 1))) == [(0,), (1,)]
    # fields count: one bucket only while the fields fit too
    assert len(plan_buckets(grids, whole, fields=[1, 1])) == 2
    with pytest.raises(ConfigError, match="budget"):
        plan_buckets(grids, 0)


def test_plan_of_many_scenes_keeps_memory_near_their_sum(scenes):
    """Twenty scenes of two sizes: buckets each within the budget, every
    scene once, and the buckets' total near the scenes' own sum."""
    grids = list(scenes.host.navgrids) * 10
    own = sum(padded_bytes([g]) for g in grids)
    budget = 4 * max(padded_bytes([g]) for g in grids)
    plan = plan_buckets(grids, budget)
    assert sorted(i for b in plan for i in b) == list(range(20))
    totals = [padded_bytes([grids[i] for i in b]) for b in plan]
    assert all(t <= budget for t in totals)
    assert sum(totals) < 1.1 * own < padded_bytes(grids)


def test_bucketed_run_equals_one_bank(scenes, small_benchmark):
    es = small_benchmark["set"]
    whole = plan_run(scenes, 8)
    assert len(whole.buckets) == 1 and np.array_equal(whole.order, np.arange(len(es)))
    plan = plan_run(scenes, 8, bank_mb=(padded_bytes(scenes.host.navgrids) - 1) / 2**20)
    assert len(plan.buckets) == 2
    assert sorted(plan.order.tolist()) == list(range(len(es)))
    ref = run_agent(es, "random", batch=8, seed=3)
    jobs = {"random": ("random", None, range(len(plan.chunks)))}
    got = sorted(((i, out) for _, i, out, _ in bucket_batches(scenes, plan, jobs, seed=3)), key=lambda x: x[0])
    assert [i for i, _ in got] == list(range(len(plan.chunks)))
    got = plan.to_run_order(jax.tree.map(lambda *xs: np.concatenate(xs), *[o for _, o in got]))
    for f in dataclasses.fields(ref[0]):
        np.testing.assert_array_equal(getattr(got, f.name), getattr(ref[0], f.name), err_msg=f.name)


def test_subset_keeps_each_episodes_key(small_benchmark):
    es = small_benchmark["set"]
    sub = es.subset([5, 2])
    assert sub.key_index.tolist() == [5, 2]
    assert sub.subset([1]).key_index.tolist() == [2]


def test_evaluate_bank_mb_writes_the_same_bytes(small_benchmark, scenes, tmp_path, capsys):
    base = ["--episodes", str(small_benchmark["path"]), "--agent", "eig", "--batch", "8",
            "--quiet"]
    assert main(base + ["--out", str(tmp_path / "one")]) == 0
    tight = (padded_bytes(scenes.host.navgrids) - 1) / 2**20
    assert main(base + ["--out", str(tmp_path / "two"), "--bank-mb", f"{tight:.6f}"]) == 0
    assert "2 buckets of scenes" in capsys.readouterr().err
    for f in ("outcomes.csv", "outcomes.parquet", "metrics.csv", "trajectories.npz"):
        assert (tmp_path / "one" / f).read_bytes() == (tmp_path / "two" / f).read_bytes(), f
    one, two = (json.loads((tmp_path / d / "run.json").read_text()) for d in ("one", "two"))
    assert two.pop("bank_mb") == pytest.approx(tight) and one.pop("bank_mb") == 1024
    assert one == two


def test_bad_bank_budget_and_mllm_agents_on_several_buckets(small_benchmark, scenes, tmp_path, capsys):
    base = ["--episodes", str(small_benchmark["path"]), "--out", str(tmp_path / "o"), "--quiet"]
    assert main(base + ["--agent", "random", "--bank-mb", "0"]) == 2
    assert "--bank-mb: must be > 0" in capsys.readouterr().err
    tight = (padded_bytes(scenes.host.navgrids) - 1) / 2**20
    with ScriptedServer() as srv:  # the endpoint answers and serves the model (checked before the scenes load)
        assert main(base + ["--agent", "tandem", "--llm-endpoint", srv.base_url, "--llm-model", srv.model,
                            "--bank-mb", f"{tight:.6f}"]) == 2
        assert srv.stats()["requests"] == 0
    err = capsys.readouterr().err
    assert "--bank-mb" in err and "2 buckets" in err and "one bank" in err
    assert not (tmp_path / "o" / "outcomes.csv").exists()


@pytest.mark.parametrize("parts", [1, 2])
def test_programs_compiled_for_the_worlds_shapes_are_the_worlds(small_benchmark, parts):
    """bucket_worlds compiles a bucket's rollout programs for the world's
    shapes while its fields are computed: the shapes (world_shapes, from the
    set without fields) give the same program keys, in this process
    (compile_ahead) and in the program store, as the finished world, on one
    device and replicated over two."""
    from ignjax.agents import get_agent
    from ignjax.agents.params import make_params
    from ignjax.cache.programs import program_key
    from ignjax.evaluate.runner import batch_program
    from ignjax.sim import compact
    from ignjax.sim.rollout import _program_key, _run_sharded
    from ignjax.sim.world import world_shapes

    if parts > len(jax.devices()):
        pytest.skip(f"{parts} devices needed, {len(jax.devices())} here")
    bs = open_benchmark(small_benchmark["path"])
    pre, pairs = bs.prepare(np.arange(len(bs)))
    assert pre.fields is None
    es = bs.with_fields(pre, pairs)
    world = make_world(es)
    whole = bs.episode_set(np.arange(len(bs)))
    assert all(np.asarray(a).tobytes() == np.asarray(b).tobytes()
               for a, b in zip(jax.tree.leaves(es.fields), jax.tree.leaves(whole.fields)))
    shapes = world_shapes(pre.bank, [s for s, _ in pairs], world.config)
    assert all(isinstance(x, jax.ShapeDtypeStruct) for x in jax.tree.leaves(shapes))
    agent = get_agent("eig")
    params = make_params(agent, config=world.config)
    ahead = batch_program(pre, shapes, agent, params, 8, 0, 0, parts)
    real = batch_program(es, world, agent, params, 8, 0, 0, parts)
    assert _program_key(*ahead) == _program_key(*real)
    key = program_key(_run_sharded, *ahead, (compact.ONE_PASS,))
    assert key is not None and key == program_key(_run_sharded, *real, (compact.ONE_PASS,))
