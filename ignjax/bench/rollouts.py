"""The rollout figures of ``python -m ignjax.bench``: decision steps per
second of full rollouts per agent and batch size (:func:`bench_steps`), and
the cost studies' timings (:func:`bench_studies`: offline WSR of 10^6 cost
vectors, the in-the-loop sweep)."""

from __future__ import annotations

import dataclasses
import time

import jax
import numpy as np

from ignjax.agents import get_agent
from ignjax.arrays import on_device, stack_copies, take_rows
from ignjax.bench.timing import log, timed
from ignjax.protocol import LOCKED_COSTS
from ignjax.sim.rollout import episode_keys, rollout, rollout_sweep
from ignjax.studies.cost_sensitivity import cost_samples, offline_wsr

AGENTS = ("random", "explorer", "naive_asker", "eig", "shortest_path")
STEP_REPEATS = 3  # timed calls per decision-steps figure (the best is reported)


def bench_steps(es, world, agents, sizes) -> tuple[dict, float]:
    """Decision steps per second of each agent's rollouts at each batch size
    (best of :data:`STEP_REPEATS` compiled calls), and the EIG agent's compile
    time at the first size (its first call minus a compiled one).

    Returns:
        ({agent: {str(B): steps/s}}, compile seconds).
    """
    out: dict = {}
    compile_s = float("nan")
    for name in agents:
        agent = get_agent(name)
        params = agent.default_params()
        out[name] = {}
        for B in sizes:
            idx = np.arange(B) % len(es)
            specs = take_rows(es.specs, idx)
            keys = episode_keys(0, np.arange(B))
            t = time.perf_counter()
            res = rollout(world, specs, agent, params, keys)
            jax.block_until_ready(res)
            first = time.perf_counter() - t
            dt = min(timed(lambda: jax.block_until_ready(rollout(world, specs, agent, params, keys)))
                     for _ in range(STEP_REPEATS))  # best of a few: this figure is a throughput, not a latency
            steps = float(np.asarray(res[0].steps).sum())
            out[name][str(B)] = steps / dt
            if name == "eig" and B == sizes[0]:
                compile_s = first - dt
            log(f"  {name:14s} B={B:5d}: {steps / dt:10.0f} decision steps/s (first call {first:.1f} s)")
    return out, compile_s


def in_loop_sweep(es, world, K: int, E: int = 500):
    """The EIG agent's in-the-loop sweep as a call: K cost vectors (the
    locked costs scaled by 0.25 .. 8, geometrically) x E episodes (the
    episode set repeated to E) in one vmapped rollout, waited for."""
    agent = get_agent("eig")
    base = agent.default_params()
    scales = np.geomspace(0.25, 8.0, K)
    params = dataclasses.replace(stack_copies(base, K),
                                 costs=on_device(scales[:, None] * np.asarray(LOCKED_COSTS), np.float32))
    idx = np.arange(E) % len(es)
    specs = take_rows(es.specs, idx)
    keys = episode_keys(0, np.arange(E))
    return lambda: jax.block_until_ready(rollout_sweep(world, specs, agent, params, keys))


def bench_studies(es, world, quick: bool) -> dict:
    """Offline WSR of 10^6 cost vectors x 500 episodes x 5 agents, and the
    EIG agent's in-the-loop sweep (K cost vectors x 500 episodes in one
    vmapped call; K = 16 when ``quick``, else 256), first and second call."""
    rng = np.random.default_rng(0)
    A, E = 5, 500
    success = rng.random((A, E, 3)) < 0.4
    nq = rng.integers(0, 4, (A, E, 4))
    valid = np.ones((A, E), bool)
    costs = cost_samples(1_000_000, 0)
    offline_wsr(success, nq, valid, costs[:1000])  # compile
    t = time.perf_counter()
    offline_wsr(success, nq, valid, costs)
    offline_s = time.perf_counter() - t
    K = 16 if quick else 256
    n = min(len(es), E)
    sweep = in_loop_sweep(es, world, K, E)
    in_loop_s = timed(sweep)
    run_s = timed(sweep)
    log(f"  offline WSR 1e6 cost vectors x {E} episodes x {A} agents: {offline_s:.2f} s")
    log(f"  in-the-loop {K} cost vectors x {E} episodes (benchmark of {n}): {in_loop_s:.1f} s incl. compile, "
         f"{run_s:.1f} s compiled")
    return {"offline_wsr_1e6_x_500_s": offline_s, "in_loop_vectors": K, "in_loop_episodes": E,
            "in_loop_s": in_loop_s, "in_loop_run_s": run_s, "in_loop_episodes_per_s": K * E / run_s}
