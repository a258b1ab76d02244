"""Rollouts: one jitted ``lax.scan`` over planner steps, vmapped over episodes.

:func:`rollout_episode` runs ONE episode (reset, then ``max_steps`` rounds
of observe -> act -> step; finished episodes stay finished);
:func:`rollout_rows` runs a batch of them with the same results row for row,
paying only for the work each step's episodes need (the executor for the
rows that MOVE, the oracle for the rows that ASK, nothing for finished
rows); :func:`rollout` jits it once per (agent, piece shape), and
:func:`rollout_sweep` runs K agent parameter settings x E episodes as one
batch of K E rows (e.g. K cost vectors in one call). Both run a batch as
concurrent pieces on CPU (:func:`batch_parts`), since XLA:CPU gives the
body of a scan one core. The pieces share one compiled program (kept in a
bounded, locked cache of :data:`MAX_EXECUTABLES` programs) and one
process-wide pool of :data:`POOL_WORKERS` threads, made once under a lock.

Agents are pure functions (:class:`ignjax.agents.Agent`): ``init`` and
``act`` see the :class:`~ignjax.sim.types.Observation` and the oracle's
:class:`~ignjax.sim.types.Answer` only; privileged agents (labelled as such)
also receive :class:`~ignjax.sim.types.Privileged` information
(:func:`ignjax.sim.env.privileged_info`).

Besides the outcome row, a rollout records a compact trajectory per episode
(:class:`~ignjax.sim.types.Trajectory`: pose after every step, the decision
with its MOVE cell or question, the executor's waypoint and blocked
headings, the oracle's answer codes, the charged questions, and the
instances in sight when the agent decided; :func:`step_record`), used for
trajectory plots, the interaction analyses and the episode viewer
(:mod:`ignjax.view`). The record only copies values the step computed
anyway.
"""

from __future__ import annotations

import dataclasses
import threading
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor
from functools import partial

import jax
import jax.numpy as jnp

from ignjax.sim import env as E
from ignjax.sim import types as T
from ignjax.sim.compact import chunk_size, even_chunk, first_equal, masked_map
from ignjax.sim.world import World


def step_record(obs: T.Observation, action: T.Action, kind, before: T.SimState, after: T.SimState,
                n_views: int = T.N_VIEWS) -> tuple:
    """One step's entry of the :class:`~ignjax.sim.types.Trajectory`, for one
    episode or a batch (leading axes alike): the observation the agent
    decided on, its action, the kind recorded (-1 once the episode had
    ended) and the state before and after the step. Returns the values of
    :attr:`~ignjax.sim.types.Trajectory.STEP_FIELDS`, in that order."""
    i32 = jnp.int32
    is_move = kind == T.MOVE
    is_ask = kind == T.ASK
    q = jnp.where(is_ask, jnp.clip(action.question, 1, 4), 0).astype(i32)
    on_move = lambda v, lo, hi: jnp.where(is_move, jnp.clip(v, lo, hi), -1).astype(i32)  # noqa: E731
    a = after.answers
    candidate = jnp.where(is_ask & (q == 4), action.candidate, -1).astype(i32)
    waypoint = jnp.where(is_move[..., None], after.waypoint, before.pose[..., :2])
    return (kind.astype(i32), q, on_move(action.direction, 0, n_views - 1), on_move(action.col, 1, 8),
            on_move(action.row, 1, 8), candidate, waypoint, after.blocked & is_move[..., None],
            is_ask & a.refused, after.n_questions, a.confirm, a.follow_up, a.hint_room_label, a.hint_sector,
            a.hint_landmark, a.hint_in_room, a.hint_progress, obs.room_label, obs.visible_handle,
            obs.visible_attrs.astype(jnp.int8))


def _trajectory(start, poses, steps: tuple, axis: int) -> T.Trajectory:
    """The Trajectory from the start poses and the scan's stacked step
    records (step axis first); ``axis`` is where the step axis goes (0 for
    one episode, 1 for a batch)."""
    move = (lambda x: x) if axis == 0 else (lambda x: jnp.swapaxes(x, 0, 1))
    pose = jnp.concatenate([jnp.expand_dims(start.astype(jnp.float32), axis), move(poses)], axis)
    return T.Trajectory(pose=pose, **{name: move(v) for name, v in zip(T.Trajectory.STEP_FIELDS, steps)})


def rollout_episode(world: World, spec: T.EpisodeSpec, agent, params, key: jax.Array):
    """Run one episode to the end. Returns (OutcomeRow, Trajectory, final SimState)."""
    cfg = world.config
    state = E.reset(world, spec, key)
    obs = E.observe(world, state)
    key, k0 = jax.random.split(key)
    pstate = agent.init(params, obs, k0)
    priv0 = E.privileged_info(world, state) if agent.privileged else None

    def body(carry, k):
        state, obs, pstate, priv = carry
        action, pstate = agent.act(params, obs, state.answers, pstate, k, priv)
        was_done = state.done
        before = state
        state = E.step(world, state, action)
        kind = jnp.where(was_done, -1, jnp.clip(action.kind, 0, 2))
        record = step_record(obs, action, kind, before, state)
        obs = E.observe(world, state)
        priv = E.privileged_info(world, state) if agent.privileged else None
        return (state, obs, pstate, priv), (state.pose, record)

    keys = jax.random.split(key, cfg.max_steps)
    (state, _, _, _), (poses, steps) = jax.lax.scan(body, (state, obs, pstate, priv0), keys)
    return E.outcome(world, state), _trajectory(spec.start, poses, steps, 0), state


# Compiler options of the rollout jits. XLA:CPU compiles loop bodies (the scan
# over planner steps and the masked batch maps inside it) several times slower
# with its MLIR fusion emitters than with the classic ones: the simulator's
# gather-heavy ray marches ran 3-4x slower inside a while loop than the same
# code at top level (jax/jaxlib 0.10.2, 2-core CPU), and whole rollouts about
# 1.7x slower. The option is a CPU one; other backends ignore it.
ROLLOUT_COMPILER_OPTIONS = {"xla_cpu_use_fusion_emitters": False}


PARTS = 2
"""Pieces a batch runs as at the same time on CPU, by default (:func:`batch_parts`)."""
MIN_PART_ROWS = 64
"""Smallest piece the default split makes."""


def batch_parts(n_rows: int, parts: int | None = None) -> int:
    """How many equal pieces a rollout of ``n_rows`` rows runs as, each on its own thread.

    XLA:CPU runs the body of a rollout's scan on one core, so a batch runs
    fastest as several pieces executed at once (the EIG agent at B = 4096 on
    a 2-core CPU: 1.7x). The default depends on the batch and the backend
    only, never on the machine's core count, so that a configuration
    compiles the same shapes everywhere: :data:`PARTS` pieces on CPU when
    each gets at least :data:`MIN_PART_ROWS` rows, one otherwise and on
    accelerators (where one program fills the device). Machines with more
    cores profit from more pieces (``parts``). Each piece is the same
    compiled program; a row's result depends on its episode, key and agent
    parameters, and, through float rounding in rare rows, on the piece's
    shape (as on the chunk size).

    Args:
        n_rows: rows of the batch.
        parts: requested pieces (None: the default above).

    Returns:
        int in 1..n_rows.
    """
    if parts is None:
        parts = PARTS if jax.default_backend() == "cpu" and n_rows >= PARTS * MIN_PART_ROWS else 1
    return max(1, min(int(parts), int(n_rows)))


MAX_EXECUTABLES = 64
"""Compiled rollout programs kept for the pieces (the least recently used is dropped first)."""
POOL_WORKERS = 32
"""Threads that run a batch's pieces (made as needed; pieces beyond them wait for a free one)."""


class _ExecutableCache:
    """Compiled programs by key, at most ``maxsize`` of them (least recently
    used dropped first); thread-safe, and a program is compiled once however
    many threads ask for it at the same time."""

    def __init__(self, maxsize: int):
        self.maxsize = int(maxsize)
        self._items: OrderedDict = OrderedDict()
        self._lock = threading.Lock()

    def __len__(self) -> int:
        with self._lock:
            return len(self._items)

    def get(self, key, compile_fn):
        """The program under ``key``, compiled by ``compile_fn()`` (under the lock) when absent."""
        with self._lock:
            exe = self._items.get(key)
            if exe is None:
                exe = self._items[key] = compile_fn()
                while len(self._items) > self.maxsize:
                    self._items.popitem(last=False)
            else:
                self._items.move_to_end(key)
            return exe


_EXECUTABLES = _ExecutableCache(MAX_EXECUTABLES)
_POOL: ThreadPoolExecutor | None = None
_POOL_LOCK = threading.Lock()


def _executable(jitted, dynamic: tuple, static: dict):
    """The compiled ``jitted`` for these arguments, compiled once (so that
    pieces started together do not each compile it)."""
    leaves, tree = jax.tree.flatten(dynamic)
    key = (jitted, tuple(sorted(static.items())), tree, tuple(jax.typeof(x) for x in leaves))
    return _EXECUTABLES.get(key, lambda: jitted.lower(*dynamic[:2], static["agent"], *dynamic[2:],
                                                      chunk=static["chunk"]).compile())


def _pool() -> ThreadPoolExecutor:
    """The process's one pool of :data:`POOL_WORKERS` threads for pieces, made on first use."""
    global _POOL
    with _POOL_LOCK:
        if _POOL is None:
            _POOL = ThreadPoolExecutor(POOL_WORKERS, thread_name_prefix="ignjax-rollout")
        return _POOL


def _in_parts(jitted, world, specs, agent, params, keys, chunk, parts: int, out_axis: int):
    """``jitted(world, specs, agent, params, keys, chunk)`` over ``parts``
    equal pieces of the episode axis run at the same time (the last padded
    with finished copies), concatenated along ``out_axis``."""
    n = specs.scene.shape[0]
    dynamic = (world, specs, params, keys)
    if parts <= 1 or any(isinstance(x, jax.core.Tracer) for x in jax.tree.leaves(dynamic)):
        return jitted(world, specs, agent, params, keys, chunk)
    size = -(-n // parts)
    specs, keys = pad_batch(specs, keys, size * parts)
    pieces = [(world, jax.tree.map(lambda a: a[i * size:(i + 1) * size], specs), params, keys[i * size:(i + 1) * size])
              for i in range(parts)]
    exe = _executable(jitted, pieces[0], {"agent": agent, "chunk": chunk})
    futures = [_pool().submit(lambda p: jax.block_until_ready(exe(*p)), p) for p in pieces]
    outs = [f.result() for f in futures]
    return jax.tree.map(lambda *xs: jax.lax.slice_in_dim(jnp.concatenate(xs, out_axis), 0, n, axis=out_axis), *outs)


def episode_keys(seed: int, indices) -> jax.Array:
    """One PRNG key per episode, from the seed and the episode's index in its
    file, so results do not depend on how episodes are batched."""
    base = jax.random.key(int(seed))
    return jax.vmap(lambda i: jax.random.fold_in(base, i))(jnp.asarray(indices, jnp.uint32))


def _keys(key: jax.Array, n: int) -> jax.Array:
    return key if key.shape == (n,) else jax.random.split(key, n)


def rollout_rows(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array, chunk: int | None = None,
                 groups: jax.Array | None = None, group_chunk: int | None = None):
    """Run a batch of episodes (leading axis B) with per-row agent parameters.

    Row for row the same as :func:`rollout_episode` (tested), organised so
    the batch pays for the work its episodes need: the executor runs for the
    rows that MOVE, the oracle for the rows that ASK, and the perception is
    recomputed for the rows that moved (:func:`ignjax.sim.env.step_batch`,
    :func:`ignjax.sim.env.observe_batch`, :func:`ignjax.sim.compact.masked_map`).
    The agent decides for every row, in contiguous chunks: moving the
    unfinished rows' memory in and out of compacted chunks costs more than
    the finished rows' (ignored) decisions.

    Args:
        params: agent parameters with leading axis B (one setting per row).
        keys: (B,) per-episode keys.
        chunk: rows per vectorised call (default: an eighth of the batch).
        groups: optional (B,) int ids; rows with equal ids must have the same
            episode spec (a parameter sweep's copies of one episode). The
            simulator is deterministic, so such rows stay in the same state
            for as long as they take the same actions: each step, the rows of
            a group that act alike are simulated once (by their first row)
            and the others copy the result, so a sweep pays for the distinct
            trajectories, not for every setting. Exact: the same result as
            without ``groups``, row for row (tested).
        group_chunk: rows per vectorised call of the simulator in group mode
            (default: ``chunk``); size it to the number of distinct
            trajectories, not to the batch.

    Returns:
        (OutcomeRow, Trajectory, final SimState) with leading axis B.
    """
    cfg = world.config
    state = jax.vmap(lambda sp, k: E.reset(world, sp, k))(specs, keys)
    obs = jax.vmap(lambda st: E.observe(world, st))(state)
    split = jax.vmap(jax.random.split)(keys)
    pstate = jax.vmap(agent.init)(params, obs, split[:, 1])
    step_keys = jnp.swapaxes(jax.vmap(lambda k: jax.random.split(k, cfg.max_steps))(split[:, 0]), 0, 1)
    privileged = (lambda st: E.privileged_info(world, st)) if agent.privileged else None
    priv0 = jax.vmap(privileged)(state) if privileged else None
    act = lambda x: agent.act(*x)  # noqa: E731
    act_chunk = even_chunk(keys.shape[0], chunk or chunk_size(keys.shape[0]))

    def simulate(state, obs, priv, action, moved, sim_chunk):
        state = E.step_batch(world, state, action, sim_chunk)
        obs = E.observe_batch(world, state, obs, moved, sim_chunk)
        priv = masked_map(privileged, ~state.done, state, priv, sim_chunk) if privileged else None
        return state, obs, priv

    def body(carry, k):
        state, obs, pstate, priv, group = carry
        was_done = state.done
        # every row decides, in contiguous chunks (a finished row's decision is ignored): compacting the
        # unfinished rows would gather and scatter the agents' whole memory every step, which costs more
        action, pstate = jax.lax.map(act, (params, obs, state.answers, pstate, k, priv), batch_size=act_chunk)
        kind = jnp.where(was_done, -1, jnp.clip(action.kind, 0, 2))
        before, obs_before = state, obs
        if group is None:
            state, obs, priv = simulate(state, obs, priv, action, kind == T.MOVE, chunk)
        else:
            # one representative per (group, action); the others are marked done for the
            # simulator (so it skips them) and then copy their representative's result
            rep = first_equal((group,) + tuple(jax.tree.leaves(action)), ~was_done)
            lead = rep == jnp.arange(rep.shape[0])
            sim = dataclasses.replace(state, done=was_done | ~lead)
            out = simulate(sim, obs, priv, action, (kind == T.MOVE) & lead, group_chunk)
            state, obs, priv = jax.tree.map(lambda a: a[rep], out)
            group = rep
        record = step_record(obs_before, action, kind, before, state)
        return (state, obs, pstate, priv, group), (state.pose, record)

    groups = None if groups is None else jnp.asarray(groups, jnp.int32)
    group_chunk = chunk if group_chunk is None else group_chunk
    (state, _, _, _, _), (poses, steps) = jax.lax.scan(body, (state, obs, pstate, priv0, groups), step_keys)
    traj = _trajectory(specs.start, poses, steps, 1)
    return jax.vmap(lambda st: E.outcome(world, st))(state), traj, state


@partial(jax.jit, static_argnames=("agent", "chunk"), compiler_options=ROLLOUT_COMPILER_OPTIONS)
def _rollout(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array, chunk: int | None = None):
    n = specs.scene.shape[0]
    rows = jax.tree.map(lambda x: jnp.broadcast_to(x, (n,) + jnp.shape(x)), params)
    return rollout_rows(world, specs, agent, rows, keys, chunk)[:2]


@partial(jax.jit, static_argnames=("agent", "chunk"), compiler_options=ROLLOUT_COMPILER_OPTIONS)
def _rollout_sweep(world: World, specs: T.EpisodeSpec, agent, params_batch, keys: jax.Array,
                   chunk: int | None = None):
    n = specs.scene.shape[0]
    K = jax.tree.leaves(params_batch)[0].shape[0]
    rows = jax.tree.map(lambda x: jnp.repeat(x, n, axis=0), params_batch)
    tile = jnp.tile(jnp.arange(n), K)
    sim_chunk = chunk if chunk is not None else chunk_size(n)
    out = rollout_rows(world, jax.tree.map(lambda a: a[tile], specs), agent, rows, keys[tile], chunk,
                       groups=tile, group_chunk=sim_chunk)[:2]
    return jax.tree.map(lambda a: a.reshape((K, n) + a.shape[1:]), out)


def rollout(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array, chunk: int | None = None,
            parts: int | None = None):
    """Run a batch of episodes (leading axis E of ``specs``) with one agent.

    One jitted program, compiled once per agent and piece shape: the batch
    runs as ``parts`` equal pieces at the same time (:func:`batch_parts`).

    Args:
        keys: (E,) per-episode keys (see :func:`episode_keys`), or one key
            that is split.
        chunk: rows per vectorised call within a piece (:func:`rollout_rows`).
        parts: concurrent pieces of the batch (default :func:`batch_parts`).

    Returns:
        (OutcomeRow, Trajectory) with leading axis E.
    """
    n = specs.scene.shape[0]
    keys = _keys(keys, n)
    return _in_parts(_rollout, world, specs, agent, params, keys, chunk, batch_parts(n, parts), 0)


def rollout_sweep(world: World, specs: T.EpisodeSpec, agent, params_batch, keys: jax.Array, chunk: int | None = None,
                  parts: int | None = None):
    """Run every episode under every parameter setting (leading axis K of
    ``params_batch``): K x E episodes in one call, as one batch of K E rows,
    the same key per episode across settings (paired comparisons). The
    episodes are split into ``parts`` concurrent pieces (each with every
    setting; :func:`batch_parts` of the K E rows).

    Returns:
        (OutcomeRow, Trajectory) with leading axes (K, E).
    """
    n = specs.scene.shape[0]
    keys = _keys(keys, n)
    K = jax.tree.leaves(params_batch)[0].shape[0]
    return _in_parts(_rollout_sweep, world, specs, agent, params_batch, keys, chunk,
                     min(batch_parts(n * K, parts), n), 1)


def pad_specs(specs: T.EpisodeSpec, size: int) -> T.EpisodeSpec:
    """Pad a batch of specs to ``size`` rows with invalid copies of the last
    row (padding rows start finished and are masked out of every metric)."""
    n = specs.scene.shape[0]
    if n >= size:
        return specs
    idx = jnp.concatenate([jnp.arange(n), jnp.full(size - n, n - 1)])
    out = jax.tree.map(lambda a: a[idx], specs)
    return dataclasses.replace(out, valid=jnp.arange(size) < n)


def pad_batch(specs: T.EpisodeSpec, keys: jax.Array, size: int) -> tuple[T.EpisodeSpec, jax.Array]:
    """:func:`pad_specs`, and the (E,) keys padded alike (copies of the last key)."""
    n = keys.shape[0]
    if n < size:
        keys = jnp.concatenate([keys, jnp.repeat(keys[-1:], size - n)])
    return pad_specs(specs, size), keys
