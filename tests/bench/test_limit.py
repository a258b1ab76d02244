"""The bench's ``limit`` block (:mod:`ignjax.bench.limit`): the counting of
a program's work, checked on programs whose work is known by hand, and the
block's parts on the test benchmark."""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.agents import get_agent
from ignjax.bench.limit import CACHED_TABLE_BYTES, COUNTERS, counted_program, limit, machine_rates, step_work
from ignjax.sim.rollout import episode_keys, rollout


def _counts(fn, *args):
    out, k = counted_program(fn, *args)(*args)
    return out, dict(zip(COUNTERS, np.asarray(k).tolist()))


def test_counts_follow_loops_as_they_run():
    small = jnp.arange(16, dtype=jnp.int32)  # 64 bytes: a cached table
    big = jnp.arange(CACHED_TABLE_BYTES // 4 + 1, dtype=jnp.int32)  # just over: a world-sized one
    idx = jnp.arange(8, dtype=jnp.int32)

    def f(x, n):
        def body(c):
            i, acc = c
            # 8 + 8 look-ups; 2 x 8 adds, 1 add (the counter), 1 compare (the loop's test), and per look-up
            # jnp's index wrapping: compare, add, select on each of the 8 indices
            return i + 1, acc + small[idx] + big[idx]
        _, acc = jax.lax.while_loop(lambda c: c[0] < n, body, (jnp.int32(0), x))
        return acc * 2  # 8 multiplies

    for n in (0, 3, 7):
        out, k = _counts(f, jnp.zeros(8, jnp.int32), jnp.int32(n))
        assert np.array_equal(out, f(jnp.zeros(8, jnp.int32), n))
        assert k["gather_cached"] == 8 * n and k["gather_world"] == 8 * n, (n, k)
        assert k["elementwise"] == 8 + n * (8 + 8 + 1 + 1 + 2 * 3 * 8), (n, k)
        assert k["scatter_rows"] == 0


def test_counts_of_a_vmapped_loop_run_to_its_longest_lane():
    """A loop vmapped over lanes with different trip counts runs until the
    longest lane is done, every lane's operations each time (the masked
    lanes' work counts: it is the program's)."""
    def f(n):
        return jax.lax.while_loop(lambda c: c[0] < n, lambda c: (c[0] + 1, c[1] * 3), (jnp.int32(0), jnp.int32(1)))[1]

    n = jnp.array([0, 2, 5, 1], jnp.int32)
    out, k = _counts(jax.vmap(f), n)
    assert np.array_equal(out, 3 ** np.asarray(n))
    # 5 rounds, every lane: the test's compare (counted once a round, as in the unbatched loop: the test that let
    # the round run), the body's add and multiply, a select for each of the 2 carries
    assert k["elementwise"] == 5 * 4 * (1 + 2 + 2), k


def test_counts_through_scan_cond_and_dot():
    table = jnp.arange(32, dtype=jnp.float32)

    def f(xs, m):
        def body(c, x):
            y = jax.lax.cond(x > 0, lambda v: v + table[jnp.array([1, 2, 3])].sum(), lambda v: v, c)
            return y, y
        c, ys = jax.lax.scan(body, jnp.float32(0), xs)
        return c + (m @ m).sum() + ys.at[jnp.array([0, 1])].set(0.0).sum()

    xs = jnp.array([1, -1, 2, 3, -5], jnp.float32)
    m = jnp.ones((4, 4), jnp.float32)
    out, k = _counts(f, xs, m)
    assert np.isclose(out, f(xs, m))
    assert k["gather_cached"] == 3 * 3  # the branch that looks up runs for the 3 positive x
    assert k["scatter_rows"] == 2
    # dot: 2 x 16 outputs x 4; the branch taken 3 times: 1 add, a 3-element sum and the index wrapping of its
    # 3 look-ups (compare, add, select each); per step: 1 compare; outside: the sums of 16 and 5 elements,
    # 2 adds, and the wrapping of the 2 scattered indices
    assert k["elementwise"] == 2 * 16 * 4 + 3 * (1 + 3 + 3 * 3) + 5 * 1 + (16 + 5) + 2 + 2 * 3, k


def test_step_work_and_limit(small_benchmark, small_world):
    es = small_benchmark["set"]
    agent = get_agent("random")
    params = agent.default_params()
    keys = episode_keys(0, np.arange(len(es)))
    work = step_work(small_world, es.specs, agent, params, keys)
    # the counted program is one device's share of the rollout: about the same decisions for its rows (float
    # rounding may move a rare episode)
    steps = float(np.asarray(rollout(small_world, es.specs, agent, params, keys)[0].steps)[:work["rows"]].sum())
    assert abs(work["decisions"] - steps) <= 0.05 * steps + 1, (work, steps)
    assert work["gather_world"] > 100 and work["elementwise"] > 1e4, work  # rays cost look-ups in the world's tables
    rates = machine_rates(10 << 20, quick=True)
    assert all(v > 0 and math.isfinite(v) for v in rates.values()), rates
    assert rates["world_table_bytes"] == 64 << 20  # a world under 64 MB is timed on a 64 MB table
    lim = limit(rates, work)
    assert lim["bound"] in ("gather", "bandwidth", "compute")
    assert math.isclose(lim["steps_per_s"], 1.0 / max(lim["seconds_per_step"].values()))
    assert lim["seconds_per_step"][lim["bound"]] == max(lim["seconds_per_step"].values())


def test_limit_arithmetic_on_rates_and_work_given_by_hand():
    """Per decision: look-ups at the cached rate, 64 bytes a world-sized look-up at the bandwidth, elementwise
    at its rate; the limit is one over the largest, and the uncached figure times each world-sized look-up at
    the world-sized table's rate instead."""
    rates = {"gather_cached_per_s": 1e9, "gather_world_per_s": 1e8, "bandwidth_bytes_per_s": 64e9,
             "elementwise_per_s": 1e10}
    work = {"gather_cached": 300.0, "gather_world": 200.0, "elementwise": 2e4}
    lim = limit(rates, work)
    assert lim["seconds_per_step"] == pytest.approx({"gather": 5e-7, "bandwidth": 2e-7, "compute": 2e-6}, rel=1e-12)
    assert lim["bound"] == "compute" and lim["steps_per_s"] == pytest.approx(5e5, rel=1e-12)
    assert lim["steps_per_s_uncached"] == pytest.approx(1 / (300 / 1e9 + 200 / 1e8), rel=1e-12)  # 2.3 us a step
    assert limit(rates, {**work, "elementwise": 1e3})["bound"] == "gather"
    slow_memory = limit({**rates, "bandwidth_bytes_per_s": 1e9}, work)
    assert slow_memory["bound"] == "bandwidth" and slow_memory["steps_per_s"] == pytest.approx(1e9 / 12800, rel=1e-12)
