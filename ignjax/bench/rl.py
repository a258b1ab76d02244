"""The ``rl`` figures of ``python -m ignjax.bench``: environment steps per
second of the RL environment (:mod:`ignjax.rl`) at B = 4096 with random
valid actions and auto-reset (:meth:`ignjax.rl.vector.VecEnv.random_steps`:
one jitted ``lax.scan`` of :data:`RL_STEPS` steps, sharded over the devices
like the rollouts), next to the ``random`` agent's rollout decision steps
per second on the same episodes, the two timed in turns
(:func:`ignjax.bench.timing.time_interleaved`) so their ratio holds on a
shared machine.

Every environment step is a decision of a running episode (auto-reset keeps
all B rows in an episode), and it includes what a learner needs besides the
simulator: the draws of the new episodes and their costs, the reward, the
observation vector and the action mask. The rollout's decision steps count
its unfinished episodes' MOVEs, ASKs and STOPs.
"""

from __future__ import annotations

import time

import jax
import numpy as np

from ignjax.agents import get_agent
from ignjax.bench.timing import log, time_interleaved
from ignjax.rl import Env, VecEnv, make_params
from ignjax.sim.rollout import episode_keys, rollout

RL_BATCH = 4096
"""Environments B of the figure (the rollouts' largest batch)."""
RL_STEPS = 20
"""Environment steps per timed call (one episode's step budget)."""


def bench_rl(es, world, batch: int = RL_BATCH, steps: int = RL_STEPS, repeats: int = 3) -> dict:
    """Env steps/s of the RL environment and the random agent's rollout decision steps/s at ``batch``.

    Returns:
        dict: ``batch``, ``steps_per_call``, ``parts`` (devices), ``env_steps_per_s``,
        ``episodes_per_s`` (episodes the environment ended per second), ``random_rollout_steps_per_s``,
        ``ratio`` (the first over the second), ``compile_s`` (the environment program's first call
        less a compiled one).
    """
    env = Env(world.config)
    params = make_params(world, es.specs)
    vec = VecEnv(env, batch)
    _, state = vec.reset(jax.random.key(0), params)
    jax.block_until_ready(state)
    env_call = lambda: jax.block_until_ready(vec.random_steps(jax.random.key(1), state, params, steps))  # noqa: E731
    t = time.perf_counter()
    _, totals = env_call()
    first = time.perf_counter() - t

    agent = get_agent("random")
    idx = np.arange(batch) % len(es)
    specs = jax.tree.map(lambda a: a[idx], es.specs)
    keys = episode_keys(0, np.arange(batch))
    agent_params = agent.default_params()
    roll_call = lambda: jax.block_until_ready(rollout(world, specs, agent, agent_params, keys))  # noqa: E731
    decisions = float(np.asarray(roll_call()[0].steps).sum())

    env_s, roll_s = time_interleaved([env_call, roll_call], repeats)
    env_rate, roll_rate = batch * steps / env_s, decisions / roll_s
    out = {"batch": batch, "steps_per_call": steps, "parts": vec.parts, "env_steps_per_s": env_rate,
           "episodes_per_s": float(np.asarray(totals["episodes"]).sum()) / env_s,
           "random_rollout_steps_per_s": roll_rate, "ratio": env_rate / roll_rate, "compile_s": first - env_s}
    log(f"  RL environment B={batch}: {env_rate:10.0f} env steps/s (random valid actions, auto-reset), random rollout "
        f"{roll_rate:10.0f} decision steps/s: ratio {env_rate / roll_rate:.2f} (first call {first:.1f} s)")
    return out


__all__ = ["RL_BATCH", "RL_STEPS", "bench_rl"]
