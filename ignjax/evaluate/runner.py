"""Run agents over a benchmark in fixed-size batches (library behind
``python -m ignjax.evaluate`` and the sweep's ``eval`` study).

Episodes are run in chunks of ``batch`` (the last chunk padded with masked
copies), so every chunk reuses one compiled rollout, sharded over the
devices (:func:`ignjax.sim.rollout.rollout`); each episode's PRNG key
comes from the seed and its index in the episode file, so its randomness
does not depend on the batch size (float rounding at other vectorised
widths can, in rare episodes; the device count does not).
"""

from __future__ import annotations

import jax
import numpy as np

from ignjax.agents import Agent, get_agent
from ignjax.episodes.dataset import EpisodeSet
from ignjax.sim.rollout import episode_keys, pad_batch, rollout
from ignjax.sim.env import check_specs
from ignjax.sim.world import World
from ignjax.errors import ConfigError
from ignjax.protocol import N_VIEWS
from ignjax.sim.types import SimConfig


def make_world(es: EpisodeSet, config: SimConfig = SimConfig()) -> World:
    """The simulator world of an episode set (bank + goal fields)."""
    return World(es.bank, es.fields, config)


def episode_batches(es: EpisodeSet, batch: int, seed: int = 0, progress=None):
    """Yield ``(n_real, specs, keys)`` for consecutive chunks of ``batch``
    episodes of ``es``: the last chunk padded with masked copies so every
    chunk has the same shape (one compiled rollout), and each episode's key
    from the seed and its index in the file (:func:`ignjax.sim.rollout.episode_keys`).
    ``progress`` optionally wraps the iterable of chunk starts (a progress bar)."""
    n = len(es)
    batch = max(1, min(int(batch), n))
    keys_all = episode_keys(seed, np.arange(n))
    starts = list(range(0, n, batch))
    for start in (progress(starts) if progress else starts):
        idx = np.arange(start, min(start + batch, n))
        specs = jax.tree.map(lambda a: a[idx], es.specs)
        keys = keys_all[idx]
        specs, keys = pad_batch(specs, keys, batch)
        yield len(idx), specs, keys


def run_agent(es: EpisodeSet, agent: Agent | str, *, params=None, batch: int = 256, seed: int = 0,
              config: SimConfig = SimConfig(), progress=None, world: World | None = None, parts: int | None = None):
    """Roll out every episode of ``es`` with one agent, ``batch`` episodes per
    rollout, each sharded over ``parts`` devices (None or 0: every device;
    :func:`ignjax.sim.rollout.batch_parts`). The results do not depend on ``parts``.

    Returns:
        (OutcomeRow, Trajectory) as numpy pytrees with leading axis len(es).
    """
    agent = get_agent(agent) if isinstance(agent, str) else agent
    params = agent.default_params() if params is None else params
    world = world or make_world(es, config)
    if world.config.n_views != N_VIEWS:
        raise ConfigError(None, "sim.n_views", f"the built-in JAX agents plan with {N_VIEWS} views; got "
                          f"{world.config.n_views} (other view counts are for image-based agents)")
    check_specs(world, es.specs)
    outs = []
    for n_real, specs, keys in episode_batches(es, batch, seed, progress):
        out, traj = rollout(world, specs, agent, params, keys, parts=parts)
        outs.append(jax.tree.map(lambda a, m=n_real: np.asarray(a)[:m], (out, traj)))
    return jax.tree.map(lambda *xs: np.concatenate(xs), *outs)


__all__ = ["episode_batches", "make_world", "run_agent"]
