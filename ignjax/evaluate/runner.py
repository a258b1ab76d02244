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


def batch_count(n: int, batch: int) -> int:
    """How many chunks :func:`episode_batches` cuts ``n`` episodes into."""
    batch = max(1, min(int(batch), n))
    return -(-n // batch)


def episode_batches(es: EpisodeSet, batch: int, seed: int = 0, progress=None, select=None):
    """Yield ``(n_real, specs, keys)`` for consecutive chunks of ``batch``
    episodes of ``es``: the last chunk padded with masked copies so every
    chunk has the same shape (one compiled rollout), and each episode's key
    from the seed and its index in the file (:func:`ignjax.sim.rollout.episode_keys`).
    ``select`` optionally names the chunks to yield (indices in
    ``range(batch_count(len(es), batch))``, in that order): a process's
    share of a run (:mod:`ignjax.devices.processes`); a chunk is the same
    whichever process runs it. ``progress`` optionally wraps the iterable
    of chunk starts (a progress bar)."""
    n = len(es)
    batch = max(1, min(int(batch), n))
    keys_all = episode_keys(seed, np.arange(n))
    starts = list(range(0, n, batch))
    if select is not None:
        starts = [starts[i] for i in select]
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
    outs = [(out, traj) for _, out, traj in agent_batches(es, agent, params=params, batch=batch, seed=seed,
                                                          config=config, progress=progress, world=world, parts=parts)]
    return jax.tree.map(lambda *xs: np.concatenate(xs), *outs)


def agent_batches(es: EpisodeSet, agent: Agent | str, *, params=None, batch: int = 256, seed: int = 0,
                  config: SimConfig = SimConfig(), progress=None, world: World | None = None, parts: int | None = None,
                  select=None):
    """:func:`run_agent` one chunk at a time: yield ``(index, OutcomeRow,
    Trajectory)`` (numpy, the chunk's real episodes only) for the chunks
    ``select`` names (default all; :func:`episode_batches`)."""
    agent = get_agent(agent) if isinstance(agent, str) else agent
    params = agent.default_params() if params is None else params
    world = world or make_world(es, config)
    if world.config.n_views != N_VIEWS:
        raise ConfigError(None, "sim.n_views", f"the built-in JAX agents plan with {N_VIEWS} views; got "
                          f"{world.config.n_views} (other view counts are for image-based agents)")
    check_specs(world, es.specs)
    select = list(range(batch_count(len(es), batch))) if select is None else list(select)
    for i, (n_real, specs, keys) in zip(select, episode_batches(es, batch, seed, progress, select)):
        out, traj = rollout(world, specs, agent, params, keys, parts=parts)
        out, traj = jax.tree.map(lambda a, m=n_real: np.asarray(a)[:m], (out, traj))
        yield i, out, traj


__all__ = ["agent_batches", "batch_count", "episode_batches", "make_world", "run_agent"]
