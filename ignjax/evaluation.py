"""Run agents over a benchmark in fixed-size batches (library behind
``python -m ignjax.evaluate`` and the sweep's ``eval`` study).

Episodes are run in chunks of ``batch`` (the last chunk padded with masked
copies), so every chunk reuses one compiled rollout; each episode's PRNG key
comes from the seed and its index in the episode file, so results do not
depend on the batch size.
"""

from __future__ import annotations

import jax
import numpy as np

from ignjax.agents.base import Agent, get_agent
from ignjax.episodes.batch import EpisodeSet
from ignjax.rollout import episode_keys, pad_specs, rollout
from ignjax.sim.env import World, check_specs
from ignjax.sim.types import SimConfig


def make_world(es: EpisodeSet, config: SimConfig = SimConfig()) -> World:
    """The simulator world of an episode set (bank + goal fields)."""
    return World(es.bank, es.fields, config)


def run_agent(es: EpisodeSet, agent: Agent | str, *, params=None, batch: int = 256, seed: int = 0,
              config: SimConfig = SimConfig(), progress=None, world: World | None = None):
    """Roll out every episode of ``es`` with one agent.

    Returns:
        (OutcomeRow, Trajectory) as numpy pytrees with leading axis len(es).
    """
    agent = get_agent(agent) if isinstance(agent, str) else agent
    params = agent.default_params() if params is None else params
    world = world or make_world(es, config)
    check_specs(world, es.specs)
    n = len(es)
    batch = max(1, min(int(batch), n))
    keys_all = episode_keys(seed, np.arange(n))
    outs = []
    chunks = list(range(0, n, batch))
    for start in (progress(chunks) if progress else chunks):
        idx = np.arange(start, min(start + batch, n))
        specs = jax.tree.map(lambda a: a[idx], es.specs)
        keys = keys_all[idx]
        if len(idx) < batch:
            specs = pad_specs(specs, batch)
            keys = jax.numpy.concatenate([keys, jax.numpy.repeat(keys[-1:], batch - len(idx))])
        out, traj = rollout(world, specs, agent, params, keys)
        outs.append(jax.tree.map(lambda a, m=len(idx): np.asarray(a)[:m], (out, traj)))
    return jax.tree.map(lambda *xs: np.concatenate(xs), *outs)


__all__ = ["make_world", "run_agent"]
