"""Rollouts sharded over devices: the session has two CPU devices
(tests/conftest.py), and a rollout or a sweep sharded over both gives, bit
for bit, what the same call on one device gives, for a batch that divides
by two and one that does not (padded, and the padding cut off). Also the
device count setting (:func:`ignjax.devices.configure_cpu_devices`), the
``parts`` check and the shard sizes."""

from __future__ import annotations

import dataclasses

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.agents import get_agent
from ignjax.devices import ENV_VAR, configure_cpu_devices
from ignjax.errors import ConfigError
from ignjax.protocol import LOCKED_COSTS
from ignjax.sim.compact import CHUNKS
from ignjax.cache.clock import CompileClock
from ignjax.sim import rollout as R
from ignjax.sim.rollout import (
    _shard_rows, _shard_widths, _widths, batch_parts, compile_ahead, episode_keys, pad_specs, rollout, rollout_call,
    rollout_sweep,
)

two_devices = pytest.mark.skipif(jax.device_count() < 2, reason=f"needs 2 devices (set {ENV_VAR}=2 or more)")


def _batch(es, n: int):
    """The first ``n`` episodes of the set and their keys."""
    specs = jax.tree.map(lambda a: a[:n], es.specs)
    return pad_specs(specs, n), episode_keys(0, np.arange(n))


def _host(tree):
    return jax.tree.map(np.asarray, tree)


def test_configure_cpu_devices_once_jax_has_started(monkeypatch):
    have = jax.local_device_count("cpu")
    monkeypatch.delenv(ENV_VAR, raising=False)
    assert configure_cpu_devices(have) == have  # the count the backends have: nothing to change
    with pytest.warns(RuntimeWarning, match="already initialised"):
        assert configure_cpu_devices(have + 1) is None
    monkeypatch.setenv(ENV_VAR, str(have))  # the environment wins over the argument
    assert configure_cpu_devices(have + 1) == have
    monkeypatch.setenv(ENV_VAR, "two")
    with pytest.raises(ValueError, match=ENV_VAR):
        configure_cpu_devices()
    monkeypatch.delenv(ENV_VAR)
    with pytest.raises(ValueError, match="n: expected a positive integer"):
        configure_cpu_devices(0)
    assert jax.local_device_count("cpu") == have


def test_parts_counts_devices():
    d = jax.device_count()
    assert batch_parts(100) == batch_parts(100, 0) == d
    assert batch_parts(3, 1) == 1 and batch_parts(1, d) == d  # a batch smaller than the devices is padded, not refused
    for bad in (d + 1, -1):
        with pytest.raises(ConfigError, match=r"^parts: must be in 0\.\.") as e:
            batch_parts(100, bad)
        assert str(bad) in str(e.value)


@pytest.mark.parametrize("n, copies, parts, chunk", [
    (40, 1, 1, None), (39, 1, 2, None), (37, 1, 2, None), (40, 3, 2, 8), (39, 2, 2, None), (5, 1, 2, 8),
    (4096, 1, 2, None), (4096, 1, 8, None), (4096, 1, 32, None), (500, 16, 4, None), (3, 1, 16, None), (1, 4, 2, None),
])
def test_shards_hold_whole_chunks(n, copies, parts, chunk):
    """Every shard holds its share of the episodes, whole agent chunks and at
    least one simulator chunk; the widths are the whole batch's unless a
    share is smaller than a chunk (more devices than chunks), and the
    padding stays below a chunk per device."""
    widths = _shard_widths(n, copies, parts, chunk)
    act, sim, group = widths
    m = _shard_rows(n, copies, parts, widths)
    assert m * parts >= n
    assert (m * copies) % act == 0 and m * copies >= max(sim, group)
    assert m * parts - n < parts * act + max(sim, group)
    whole = _widths(n * copies, n, chunk)
    if chunk is None and parts <= CHUNKS:
        assert widths == whole
    if parts == 1 and (n * copies) % act == 0:
        assert m == n
    if n >= 1000:
        assert m * parts < 1.1 * n  # large batches barely grow, however many devices


def test_padding_keeps_padded_rows_padded(small_benchmark):
    specs = small_benchmark["set"].specs
    specs = dataclasses.replace(jax.tree.map(lambda a: a[:4], specs), valid=jnp.array([True, True, False, True]))
    got = pad_specs(specs, 6)
    assert np.asarray(got.valid).tolist() == [True, True, False, True, False, False]
    np.testing.assert_array_equal(np.asarray(got.target)[4:], np.asarray(specs.target)[[3, 3]])


@two_devices
@pytest.mark.parametrize("n", [40, 39])
def test_rollout_on_two_devices_equals_one_device(small_benchmark, small_world, n):
    es = small_benchmark["set"]
    specs, keys = _batch(es, n)
    agent = get_agent("naive_asker")
    params = agent.default_params()
    one = _host(rollout(small_world, specs, agent, params, keys, parts=1))
    two = _host(rollout(small_world, specs, agent, params, keys, parts=2))
    chex.assert_trees_all_equal(two, one)
    assert one[0].steps.shape == (n,) and one[1].kind.shape[0] == n
    assert np.asarray(one[0].valid).all()  # no padding row in the result
    assert len(set(np.asarray(one[0].steps).tolist())) > 3  # the episodes differ: a shuffle would show


@two_devices
def test_programs_compiled_ahead_are_the_ones_that_run_with_the_same_bytes(small_benchmark, small_world):
    """compile_ahead compiles several rollout programs side by side; rollout then runs them (no compilation of its
    own) and gives what it gives without them, bit for bit."""
    specs, keys = _batch(small_benchmark["set"], 40)
    agent = get_agent("naive_asker")
    params = agent.default_params()
    R._run_sharded.clear_cache()  # so a call that did not run a program compiled ahead would have to obtain one
    calls = [rollout_call(small_world, specs, agent, params, keys, parts=p) for p in (1, 2)]
    compile_ahead(calls)
    assert compile_ahead(calls) == 0  # both kept: nothing compiled again
    clock = CompileClock().start()
    ahead = [_host(rollout(small_world, specs, agent, params, keys, parts=p)) for p in (1, 2)]
    clock.stop()
    assert "jit(_run_sharded)" not in clock.names, "rollout obtained a program instead of running the one compiled ahead"
    R._AHEAD.clear()
    plain = [_host(rollout(small_world, specs, agent, params, keys, parts=p)) for p in (1, 2)]
    for a, b in zip(ahead, plain):
        chex.assert_trees_all_equal(a, b)


@two_devices
@pytest.mark.parametrize("n", [39])
def test_sweep_on_two_devices_equals_one_device(small_benchmark, small_world, n):
    es = small_benchmark["set"]
    specs, keys = _batch(es, n)
    eig = get_agent("eig")
    K = 2
    params = jax.tree.map(lambda x: jnp.broadcast_to(x, (K,) + jnp.shape(x)), eig.default_params())
    costs = jnp.asarray(LOCKED_COSTS, jnp.float32)[None] * jnp.asarray([0.5, 4.0], jnp.float32)[:, None]
    params = dataclasses.replace(params, costs=costs)
    one = _host(rollout_sweep(small_world, specs, eig, params, keys, parts=1))
    two = _host(rollout_sweep(small_world, specs, eig, params, keys, parts=2))
    chex.assert_trees_all_equal(two, one)
    assert one[0].steps.shape == (K, n) and one[1].kind.shape[:2] == (K, n)
    q = np.asarray(one[0].n_questions).sum(-1)
    assert q[0].sum() > q[1].sum()  # the settings differ, so a swap of the K axis would show


@two_devices
def test_world_is_copied_to_the_devices_once_per_world(small_benchmark):
    import gc

    from ignjax.sim import rollout as R
    from ignjax.sim.types import SimConfig
    from ignjax.sim.world import World

    es = small_benchmark["set"]
    world = World(es.bank, es.fields, SimConfig())
    mesh = R.device_mesh(2)
    copy = R.replicate_world(world, mesh)
    assert R.replicate_world(world, mesh) is copy
    assert R.replicate_world(world, R.device_mesh(1)) is world  # one device: the world as it is
    leaf = jax.tree.leaves(copy)[0]
    assert len(leaf.sharding.device_set) == 2 and leaf.sharding.is_fully_replicated
    key = (id(world), mesh)
    assert key in R._REPLICAS
    del world, copy, leaf
    gc.collect()
    assert key not in R._REPLICAS


@two_devices
def test_the_padding_is_cut_without_a_program_across_the_devices():
    """A batch padded to equal shards is cut back on the host: no XLA program runs over both devices after the
    rollout (an eager slice of each sharded output was one, with an all-gather at which XLA:CPU aborts the process
    when one device waits 40 s for the other's shard)."""
    from jax.sharding import NamedSharding, PartitionSpec as P

    mesh = R.device_mesh(2)
    tree = {"a": jnp.arange(24.0).reshape(6, 4), "b": jnp.arange(18).reshape(3, 6)}
    sharded = {"a": jax.device_put(tree["a"], NamedSharding(mesh, P(R.AXIS))),
               "b": jax.device_put(tree["b"], NamedSharding(mesh, P(None, R.AXIS)))}
    clock = CompileClock().start()
    cut_a = R.cut_padding({"a": sharded["a"]}, 5, 0)["a"]
    cut_b = R.cut_padding({"b": sharded["b"]}, 4, 1)["b"]
    clock.stop()
    assert clock.names == []
    np.testing.assert_array_equal(cut_a, np.asarray(tree["a"])[:5])
    np.testing.assert_array_equal(cut_b, np.asarray(tree["b"])[:, :4])
    assert len(cut_a.sharding.device_set) == 1 and len(cut_b.sharding.device_set) == 1
