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

from concurrent.futures import ThreadPoolExecutor

import jax
import numpy as np

from dataclasses import dataclass

from ignjax.cache.clock import in_phase
from ignjax.agents import Agent, get_agent
from ignjax.agents.params import make_params
from ignjax.episodes.dataset import BenchmarkScenes, EpisodeSet
from ignjax.sim.rollout import compile_ahead, episode_keys, pad_index, pad_specs, rollout, rollout_call
from ignjax.sim.env import check_specs
from ignjax.sim.world import FINE, World, world_shapes
from ignjax.errors import ConfigError
from ignjax.protocol import N_VIEWS
from ignjax.sim.types import SimConfig


@in_phase("load")
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
    from the seed and its position in the run (:attr:`EpisodeSet.key_index`,
    :func:`ignjax.sim.rollout.episode_keys`).
    ``select`` optionally names the chunks to yield (indices in
    ``range(batch_count(len(es), batch))``, in that order): a process's
    share of a run (:mod:`ignjax.devices.processes`); a chunk is the same
    whichever process runs it. ``progress`` optionally wraps the iterable
    of chunk starts (a progress bar)."""
    n = len(es)
    batch = max(1, min(int(batch), n))
    # cut on the host and put on the device whole: indexing the device tables would run one small
    # compiled program per table and chunk shape (a dozen per run, each compiled or looked up in the cache)
    host = jax.tree.map(np.asarray, es.specs)
    key_index = np.asarray(es.key_index)
    starts = list(range(0, n, batch))
    if select is not None:
        starts = [starts[i] for i in select]
    for start in (progress(starts) if progress else starts):
        rows = np.arange(start, min(start + batch, n))
        specs = jax.device_put(pad_specs(jax.tree.map(lambda a: a[rows], host), batch))
        yield len(rows), specs, episode_keys(seed, key_index[rows][pad_index(len(rows), batch)])


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
    world = world or make_world(es, config)
    params = make_params(agent, config=world.config) if params is None else params  # the defaults
    if world.config.n_views != N_VIEWS:
        raise ConfigError(None, "sim.n_views", f"the built-in JAX agents plan with {N_VIEWS} views; got "
                          f"{world.config.n_views} (other view counts are for image-based agents)")
    check_specs(world, es.specs)
    select = list(range(batch_count(len(es), batch))) if select is None else list(select)
    # the chunks first: zip then runs a progress wrapper to its end (its last update) before it stops
    for (n_real, specs, keys), i in zip(episode_batches(es, batch, seed, progress, select), select):
        out, traj = rollout(world, specs, agent, params, keys, parts=parts)
        out, traj = jax.tree.map(lambda a, m=n_real: np.asarray(a)[:m], (out, traj))
        yield i, out, traj


WORLD_BYTES_PER_CELL = FINE * FINE + 4 + 4
"""Bytes the simulator's world adds per navigation cell of a scene: its probe
map (:data:`~ignjax.sim.world.FINE` ^ 2 fine cells of one byte), the packed
observation heights and the packed collision heights (4 bytes each)."""
BANK_MB = 1024
"""Default budget of one bucket of scenes (``--bank-mb``)."""


@dataclass(frozen=True)
class BucketPlan:
    """A run of an episode file a bucket of scenes at a time.

    Attributes:
        buckets: per bucket, the positions of its episodes in the run
            (increasing; :meth:`BenchmarkScenes.buckets`).
        batch: episodes per compiled batch; each bucket is cut into its own
            batches (:func:`episode_batches`), so no batch mixes buckets.
        chunks: ``(bucket, chunk within the bucket)`` of each of the run's
            batches, bucket after bucket: the index of a batch in this list
            is what a process's share and a run's part files count.
    """

    buckets: tuple[np.ndarray, ...]
    batch: int

    @property
    def chunks(self) -> list[tuple[int, int]]:
        return [(b, c) for b, pos in enumerate(self.buckets) for c in range(batch_count(len(pos), self.batch))]

    @property
    def order(self) -> np.ndarray:
        """(E,) the run position of each row of the batches' outputs, concatenated in batch order."""
        return np.concatenate(self.buckets) if self.buckets else np.zeros(0, np.int64)

    def to_run_order(self, tree, axis: int = 0):
        """Outputs concatenated in batch order along ``axis`` (the episode axis) -> in run order."""
        order = self.order
        if np.array_equal(order, np.arange(len(order))):
            return tree

        def put(a):
            a = np.asarray(a)
            out = np.empty_like(a)
            index = [slice(None)] * a.ndim
            index[axis] = order
            out[tuple(index)] = a
            return out

        return jax.tree.map(put, tree)


def plan_run(bs: BenchmarkScenes, batch: int, bank_mb: float = BANK_MB) -> BucketPlan:
    """The :class:`BucketPlan` of ``bs`` with buckets of at most ``bank_mb``
    MiB of scene tables, probe maps and goal fields (one device's copy of the
    world); one bucket, the whole run, when it fits.

    Raises:
        ConfigError: ``batch`` or ``bank_mb`` not positive.
    """
    if batch < 1:
        raise ConfigError(None, "batch", f"must be >= 1, got {batch}")
    if not bank_mb > 0:
        raise ConfigError(None, "bank_mb", f"must be > 0, got {bank_mb}")
    return BucketPlan(tuple(bs.buckets(bank_mb * 2**20, WORLD_BYTES_PER_CELL)), int(batch))


def bucket_worlds(bs: BenchmarkScenes, plans: dict, todo: dict, config: SimConfig = SimConfig(), programs=None):
    """The buckets that have work, one at a time: each bucket's
    :class:`EpisodeSet` and world are built once, handed out, and dropped
    before the next bucket is built.

    Args:
        plans: key -> :class:`BucketPlan` (the same buckets; the batch may differ, e.g. a sweep's in-loop stage).
        todo: key -> the batch indices (into that plan's :attr:`BucketPlan.chunks`) to run.
        programs: optional ``programs(es, world, work)`` -> the rollout programs
            (:func:`batch_program`) the bucket's work runs; they compile
            (:func:`ignjax.sim.rollout.compile_ahead`) in a thread while the
            bucket's goal fields and probe map are computed, for the set
            without its fields and the world's shapes
            (:meth:`~ignjax.episodes.dataset.BenchmarkScenes.prepare`,
            :func:`ignjax.sim.world.world_shapes`): the same programs as for
            the finished world (the shipped benchmark's ``evaluate`` cold on 2
            cores: 36.8 -> 34.2 s and 32.9 -> 29.8 s, measured back to back).
            A failure of either side is raised once both have ended.

    Yields:
        ``(EpisodeSet, World, {key: [(batch index, chunk within the bucket), ...]})`` for each bucket
        with work, in bucket order, each key's batches in increasing order.
    """
    keys = list(plans)
    if not keys:
        return
    buckets = plans[keys[0]].buckets
    chunks = {k: plans[k].chunks for k in keys}
    where = {k: {int(i): chunks[k][int(i)] for i in todo.get(k, ())} for k in keys}
    for b, pos in enumerate(buckets):
        work = {k: [(i, c) for i, (bb, c) in sorted(where[k].items()) if bb == b] for k in keys}
        if not any(work.values()):
            continue
        pre, pairs = bs.prepare(pos)
        with ThreadPoolExecutor(1) as pool:
            ahead = pool.submit(compile_ahead, programs(pre, world_shapes(pre.bank, [s for s, _ in pairs], config), work)
                                ) if programs else None
            es = bs.with_fields(pre, pairs)
            world = make_world(es, config)
            if ahead is not None:
                ahead.result()
        yield es, world, work
        del es, world, pre


def batch_program(es: EpisodeSet, world: World, agent, params, batch: int, seed: int, chunk: int,
                  parts: int | None = None, sweep: bool = False) -> tuple:
    """The rollout program (:func:`ignjax.sim.rollout.rollout_call`) of chunk ``chunk`` of ``es`` cut in batches
    of ``batch`` (:func:`episode_batches`; every chunk of a run is the same program), for
    :func:`ignjax.sim.rollout.compile_ahead`. ``sweep``: ``params`` carry a leading axis of settings; None: the
    agent's defaults (as :func:`agent_batches`). ``world`` may be its shapes (:func:`ignjax.sim.world.world_shapes`)."""
    agent = get_agent(agent) if isinstance(agent, str) else agent
    params = make_params(agent, config=world.config) if params is None else params  # the defaults, as agent_batches
    _, specs, keys = next(episode_batches(es, batch, seed, select=[chunk]))
    return rollout_call(world, specs, agent, params, keys, parts=parts, sweep=sweep)


def bucket_batches(bs: BenchmarkScenes, plan: BucketPlan, jobs: dict, *, seed: int = 0,
                   config: SimConfig = SimConfig(), parts: int | None = None):
    """Roll out the batches ``jobs`` name, a bucket at a time (:func:`bucket_worlds`).

    Args:
        jobs: name -> ``(agent, params, batch indices)`` (indices into
            :attr:`BucketPlan.chunks`).

    Yields:
        ``(name, batch index, OutcomeRow, Trajectory)``, numpy, the batch's
        real episodes only; bucket after bucket, the jobs in their order.
    """
    todo = {name: idx for name, (_, _, idx) in jobs.items()}

    def programs(es, world, work):  # every busy agent's, side by side and beside the bucket's loading
        return [batch_program(es, world, agent, params, plan.batch, seed, work[name][0][1], parts)
                for name, (agent, params, _) in jobs.items() if work[name]]

    for es, world, work in bucket_worlds(bs, dict.fromkeys(jobs, plan), todo, config, programs):
        for name, (agent, params, _) in jobs.items():
            if not work[name]:
                continue
            index = {c: i for i, c in work[name]}
            for c, out, traj in agent_batches(es, agent, params=params, batch=plan.batch, seed=seed, world=world,
                                              parts=parts, select=[c for _, c in work[name]]):
                yield name, index[c], out, traj


__all__ = ["BANK_MB", "BucketPlan", "WORLD_BYTES_PER_CELL", "agent_batches", "batch_count", "batch_program", "bucket_batches",
           "bucket_worlds", "episode_batches", "make_world", "plan_run", "run_agent"]
