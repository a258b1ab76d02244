"""Rollouts: one jitted ``lax.scan`` over planner steps, vmapped over episodes.

:func:`rollout_episode` runs ONE episode (reset, then ``max_steps`` rounds
of observe -> act -> step; finished episodes stay finished);
:func:`rollout_rows` runs a batch of them with the same results row for row,
paying only for the work each step's episodes need (the executor for the
rows that MOVE, the oracle for the rows that ASK, nothing for finished
rows); :func:`rollout` runs a batch of E episodes with one agent, and
:func:`rollout_sweep` K agent parameter settings x E episodes as one batch
of K E rows (e.g. K cost vectors in one call). Both are one jitted program,
compiled once per (agent, batch shape, device count), that shards the
episodes over a 1-D mesh of devices (:func:`device_mesh`, axis
:data:`AXIS`, with ``jax.shard_map``): the CPU devices of
:func:`ignjax.devices.configure_cpu_devices` (XLA:CPU gives the body of a
scan one core, so one device per core uses them all), several GPUs or a TPU
slice alike. Each device runs its share of the episodes (and, in a sweep,
every setting of them) with no communication; the batch is padded with
finished copies to equal shards, and every row runs at the vectorised
widths of the whole batch, so a row's result does not depend on the device
count (tested bitwise) as long as each device's share holds a chunk
(:func:`_shard_widths`).

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
import math
import weakref
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec as P

from ignjax.cache.programs import load_or_compile
from ignjax.devices import available_cores
from ignjax.errors import ConfigError
from ignjax.sim import compact
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


AXIS = "episodes"
"""Name of the device mesh axis the episodes are sharded over."""


def batch_parts(n_rows: int | None = None, parts: int | None = None) -> int:
    """How many devices a rollout shards its episodes over.

    Args:
        n_rows: rows of the batch (unused: any batch is padded to a multiple
            of the count; kept so callers can say which batch they mean).
        parts: requested devices; None or 0: every local device of the
            default backend (``jax.local_devices()``: this process's GPUs,
            TPU chips, or the CPU devices of
            :func:`ignjax.devices.configure_cpu_devices`; in a run of several
            processes each shards its own batches over its own devices,
            :mod:`ignjax.devices.processes`).

    Returns:
        int in 1..``jax.local_device_count()``.

    Raises:
        ConfigError: ``parts`` is negative or more than the devices there are.
    """
    available = jax.local_device_count()
    if not parts:
        if parts is not None and parts < 0:
            raise ConfigError(None, "parts", f"must be >= 0 (0: every device), got {parts}")
        return available
    parts = int(parts)
    if parts < 0 or parts > available:
        raise ConfigError(None, "parts", f"must be in 0..{available} (devices to shard over; 0: all {available} "
                          f"{jax.default_backend()} devices), got {parts}"
                          + (" (more CPU devices: IGNJAX_CPU_DEVICES, set before JAX starts)"
                             if jax.default_backend() == "cpu" and parts > available else ""))
    return parts


def device_mesh(parts: int) -> Mesh:
    """A 1-D mesh (axis :data:`AXIS`) over this process's first ``parts`` devices."""
    return Mesh(np.array(jax.local_devices()[:parts]), (AXIS,))


def _widths(rows: int, episodes: int, chunk: int | None) -> tuple[int, int, int]:
    """The vectorised widths of a batch of ``rows`` rows (``episodes``
    distinct episodes): the agent's chunk, the simulator's chunk and, for a
    sweep, the simulator's chunk in group mode (:func:`rollout_rows`)."""
    act = even_chunk(rows, chunk or chunk_size(rows))
    sim = min(chunk or chunk_size(rows), rows)
    group = min(chunk or chunk_size(episodes), rows)
    return act, sim, group


def _shard_rows(n: int, copies: int, parts: int, widths: tuple[int, int, int]) -> int:
    """Episodes per device when ``n`` episodes (each run ``copies`` times)
    are sharded over ``parts`` devices at these ``widths``: at least its share
    of ``n``, and enough, with ``copies``, for whole agent chunks and a full
    simulator chunk, so that every row runs at these widths."""
    act, sim, group = widths
    m = max(-(-n // parts), -(-max(sim, group) // copies))
    step = act // math.gcd(act, copies)
    return -(-m // step) * step


def _shard_widths(n: int, copies: int, parts: int, chunk: int | None) -> tuple[int, int, int]:
    """The widths rows run at when ``n`` episodes (each run ``copies``
    times) are sharded over ``parts`` devices: the whole batch's
    (:func:`_widths`), so that a row's result does not depend on the device
    count, unless a device's share of the rows is smaller than a chunk
    (more devices than chunks: with the default chunk, more than
    :data:`ignjax.sim.compact.CHUNKS`); then the share's, rather than
    padding every device to a whole chunk."""
    widths = _widths(n * copies, n, chunk)
    share = -(-n // parts)
    if share * copies < max(widths):
        widths = _widths(share * copies, share, chunk)
    return widths


def shard_layout(n: int, parts: int, copies: int = 1, chunk: int | None = None) -> tuple[int, tuple[int, int, int]]:
    """How a rollout of ``n`` episodes (each run ``copies`` times) lays out
    over ``parts`` devices: (episodes per device, padding included; the
    vectorised widths its rows run at: the agent's chunk, the simulator's
    chunk and the simulator's chunk in group mode)."""
    widths = _shard_widths(n, copies, parts, chunk)
    return _shard_rows(n, copies, parts, widths), widths


_REPLICAS: dict = {}


def replicate_world(world: World, mesh: Mesh) -> World:
    """``world`` with a copy on every device of ``mesh``, made once per world
    and mesh and dropped with the world: the scene bank is large (about half
    a gigabyte for the shipped benchmark), and copying it to the devices on
    every call would cost a good part of a batch's time. Each device holds
    its own copy; CPU devices share one (:func:`_shared_on_cpu`). A world of shapes
    (:func:`ignjax.sim.world.world_shapes`) gets the copies' placement."""
    if mesh.size == 1 or any(isinstance(x, jax.core.Tracer) for x in jax.tree.leaves(world)):
        return world
    if all(isinstance(x, jax.ShapeDtypeStruct) for x in jax.tree.leaves(world)):
        every = NamedSharding(mesh, P())
        return jax.tree.map(lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=every, weak_type=x.weak_type),
                            world)
    key = (id(world), mesh)
    hit = _REPLICAS.get(key)
    if hit is not None and hit[0]() is world:
        return hit[1]
    copy = jax.device_put(_shared_on_cpu(world, mesh), NamedSharding(mesh, P()))
    _REPLICAS[key] = (weakref.ref(world, lambda _, k=key: _REPLICAS.pop(k, None)), copy)
    return copy


def _shared_on_cpu(world: World, mesh: Mesh) -> World:
    """On CPU devices, ``world``'s arrays as host views of their buffers, which
    ``jax.device_put`` then shares with every device of the mesh instead of
    copying (CPU devices alias host memory that is 64-byte aligned, as device
    buffers are): the copies share one memory, so half a gigabyte per device
    is neither allocated nor written. Elsewhere ``world`` itself."""
    if any(d.platform != "cpu" for d in mesh.devices.flat):
        return world
    return jax.tree.map(lambda x: np.asarray(x) if isinstance(x, jax.Array) and not x.weak_type else x, world)


def _sharded_args(fn, world, specs, agent, params, keys, chunk, parts: int, copies: int, out_axis: int):
    """The arguments of :func:`_run_sharded` for :func:`_sharded` (episodes
    padded to ``parts`` equal shards): (args, static keyword arguments, padded rows)."""
    n = specs.scene.shape[0]
    rows, widths = shard_layout(n, parts, copies, chunk)
    size = rows * parts
    specs, keys = pad_batch(specs, keys, size)
    mesh = device_mesh(parts)
    return ((replicate_world(world, mesh), specs, params, keys),
            dict(fn=fn, agent=agent, widths=widths, mesh=mesh, out_axis=out_axis), size)


def _sharded(fn, world, specs, agent, params, keys, chunk, parts: int, copies: int, out_axis: int):
    """``fn(world, specs, agent, params, keys, widths)`` with the episode axis
    of ``specs`` and ``keys`` split over ``parts`` devices, each episode run
    ``copies`` times (a sweep's settings). The episodes are padded with
    finished copies to ``parts`` equal shards (:func:`_shard_rows`); the
    outputs' episode axis is ``out_axis``, and the padding is cut from it.
    A program compiled ahead for arguments like these (:func:`compile_ahead`)
    is the one that runs."""
    n = specs.scene.shape[0]
    args, static, size = _sharded_args(fn, world, specs, agent, params, keys, chunk, parts, copies, out_axis)
    key = _program_key(args, static)
    if key not in _AHEAD:
        compile_ahead([(args, static)])
    out = _AHEAD[key](*args)
    if size == n:
        return out
    return cut_padding(out, n, out_axis)


def cut_padding(out, n: int, axis: int):
    """The first ``n`` rows along ``axis`` of every leaf of a sharded output,
    cut on the host (each leaf gathered shard by shard) and put on the default device.

    Not an eager ``lax.slice_in_dim``: on the sharded arrays that is one small
    XLA program per leaf with an all-gather across the devices, and XLA:CPU
    kills the process (``AwaitAndLogIfStuck``: abort after 40 s) when one
    device waits that long at such a rendezvous: the devices' shards of a
    rollout finish at different times (asynchronous dispatch, a loaded
    machine), and the programs of several leaves in flight at once can take
    every worker thread of the CPU client's pool while the other device's
    halves wait for one. The host copy has no rendezvous."""
    cut = (slice(None),) * axis + (slice(0, n),)
    return jax.tree.map(lambda a: jax.device_put(np.asarray(a)[cut]), out)


@partial(jax.jit, static_argnames=("fn", "agent", "widths", "mesh", "out_axis"),
         compiler_options=ROLLOUT_COMPILER_OPTIONS)
def _run_sharded(world, specs, params, keys, *, fn, agent, widths, mesh: Mesh, out_axis: int):
    rows = P(AXIS)
    out = P(*([None] * out_axis + [AXIS]))
    run = jax.shard_map(lambda w, s, p, k: fn(w, s, agent, p, k, widths), mesh=mesh,
                        in_specs=(P(), rows, P(), rows), out_specs=out, check_vma=False)
    return run(world, specs, params, keys)


AHEAD_KEPT = 16
"""Programs compiled ahead that a process keeps (:func:`compile_ahead`), the latest compiled."""
_AHEAD: OrderedDict = OrderedDict()


def _program_key(args, static: dict) -> tuple:
    """What makes :func:`_run_sharded` another program: its static arguments, the arguments' tree and each
    leaf's shape, dtype and placement, and the tracing switch :data:`ignjax.sim.compact.ONE_PASS`."""
    leaves, tree = jax.tree.flatten(args)
    return (compact.ONE_PASS, tuple(static[k] for k in sorted(static)), tree,
            tuple((np.shape(x), str(getattr(x, "dtype", type(x))), getattr(x, "sharding", None)) for x in leaves))


def rollout_call(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array, chunk: int | None = None,
                 parts: int | None = None, sweep: bool = False) -> tuple:
    """The program :func:`rollout` (with ``sweep``, :func:`rollout_sweep`,
    ``params`` with a leading K axis) runs for these arguments, as
    ``(arguments, static arguments)`` for :func:`compile_ahead`."""
    n = specs.scene.shape[0]
    keys = _keys(keys, n)
    fn, copies, out_axis = (_rollout_sweep, jax.tree.leaves(params)[0].shape[0], 1) if sweep else (_rollout, 1, 0)
    args, static, _ = _sharded_args(fn, world, specs, agent, params, keys, chunk, batch_parts(n, parts), copies,
                                    out_axis)
    return args, static


def compile_ahead(calls, workers: int | None = None) -> int:
    """Compile the rollout programs of ``calls`` (:func:`rollout_call`) side
    by side, one thread per core (``workers``): XLA compiles without holding
    Python's lock, so a run of several programs (a sweep's agents and its
    in-the-loop stage) pays for about one compile per core instead of one
    after another. :func:`rollout` and :func:`rollout_sweep` then run these
    programs for arguments of the same shapes; they are the programs a first
    call would compile (the same lowering and compiler options, the same
    persistent-cache entries), so results are the same bytes. A process keeps
    the :data:`AHEAD_KEPT` latest.

    Returns:
        How many programs were compiled (those already kept are not).
    """
    todo = {}
    for args, static in calls:
        key = _program_key(args, static)
        if key not in _AHEAD:
            todo[key] = (args, static)
    if not todo:
        return 0

    def compile_one(item):
        key, (args, static) = item
        return key, load_or_compile(_run_sharded, args, static, "rollout", context=(compact.ONE_PASS,))

    with ThreadPoolExecutor(max(1, min(len(todo), workers or available_cores()))) as pool:
        for key, program in pool.map(compile_one, todo.items()):
            _AHEAD[key] = program
            while len(_AHEAD) > AHEAD_KEPT:
                _AHEAD.popitem(last=False)
    return len(todo)


def episode_keys(seed: int, indices) -> jax.Array:
    """One PRNG key per episode, from the seed and the episode's index in its
    file, so results do not depend on how episodes are batched."""
    base = jax.random.key(int(seed))
    return jax.vmap(lambda i: jax.random.fold_in(base, i))(jnp.asarray(indices, jnp.uint32))


def _keys(key: jax.Array, n: int) -> jax.Array:
    return key if key.shape == (n,) else jax.random.split(key, n)


def rollout_start(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array):
    """The start of :func:`rollout_rows`: (state, observation, agent state,
    privileged information or None, step keys (max_steps, B)), all with
    leading axis B but the step keys."""
    state = jax.vmap(lambda sp, k: E.reset(world, sp, k))(specs, keys)
    obs = jax.vmap(lambda st: E.observe(world, st))(state)
    split = jax.vmap(jax.random.split)(keys)
    pstate = jax.vmap(agent.init)(params, obs, split[:, 1])
    step_keys = jnp.swapaxes(jax.vmap(lambda k: jax.random.split(k, world.config.max_steps))(split[:, 0]), 0, 1)
    priv0 = jax.vmap(lambda st: E.privileged_info(world, st))(state) if agent.privileged else None
    return state, obs, pstate, priv0, step_keys


def rollout_rows(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array, chunk: int | None = None,
                 groups: jax.Array | None = None, group_chunk: int | None = None, act_chunk: int | None = None):
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
        act_chunk: rows per vectorised call of the agent (default: the
            divisor of B nearest below ``chunk``, :func:`ignjax.sim.compact.even_chunk`).

    Returns:
        (OutcomeRow, Trajectory, final SimState) with leading axis B.
    """
    state, obs, pstate, priv0, step_keys = rollout_start(world, specs, agent, params, keys)
    privileged = (lambda st: E.privileged_info(world, st)) if agent.privileged else None
    act = lambda x: agent.act(*x)  # noqa: E731
    act_chunk = act_chunk or even_chunk(keys.shape[0], chunk or chunk_size(keys.shape[0]))

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


def _rollout(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array, widths: tuple):
    """One device's share of :func:`rollout`."""
    n = specs.scene.shape[0]
    act, sim, _ = widths
    rows = jax.tree.map(lambda x: jnp.broadcast_to(x, (n,) + jnp.shape(x)), params)
    return rollout_rows(world, specs, agent, rows, keys, sim, act_chunk=act)[:2]


def _rollout_sweep(world: World, specs: T.EpisodeSpec, agent, params_batch, keys: jax.Array, widths: tuple):
    """One device's share of :func:`rollout_sweep`: its episodes under every setting."""
    n = specs.scene.shape[0]
    act, sim, group = widths
    K = jax.tree.leaves(params_batch)[0].shape[0]
    rows = jax.tree.map(lambda x: jnp.repeat(x, n, axis=0), params_batch)
    tile = jnp.tile(jnp.arange(n), K)
    out = rollout_rows(world, jax.tree.map(lambda a: a[tile], specs), agent, rows, keys[tile], sim,
                       groups=tile, group_chunk=group, act_chunk=act)[:2]
    return jax.tree.map(lambda a: a.reshape((K, n) + a.shape[1:]), out)


def rollout(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array, chunk: int | None = None,
            parts: int | None = None):
    """Run a batch of episodes (leading axis E of ``specs``) with one agent.

    One jitted program, compiled once per agent, batch shape and device
    count, with the episodes sharded over ``parts`` devices. E need not
    divide by ``parts``: the batch is padded with finished copies of the
    last episode, which are cut from the result. Each row's result is the
    same whatever ``parts`` is, up to :data:`ignjax.sim.compact.CHUNKS`
    devices with the default ``chunk`` (with more, the rows run at the
    shards' widths, and float rounding can change a rare episode).

    Args:
        keys: (E,) per-episode keys (see :func:`episode_keys`), or one key
            that is split.
        chunk: rows per vectorised call (:func:`rollout_rows`; default: an
            eighth of the whole batch, whatever the device count).
        parts: devices to shard over: None or 0 for every device
            of this process (``jax.local_devices()``), else 1 up to their number (:func:`batch_parts`).

    Returns:
        (OutcomeRow, Trajectory) with leading axis E.

    Raises:
        ConfigError: ``parts`` is negative or more than the devices there are.
    """
    n = specs.scene.shape[0]
    keys = _keys(keys, n)
    return _sharded(_rollout, world, specs, agent, params, keys, chunk, batch_parts(n, parts), 1, 0)


def rollout_sweep(world: World, specs: T.EpisodeSpec, agent, params_batch, keys: jax.Array, chunk: int | None = None,
                  parts: int | None = None):
    """Run every episode under every parameter setting (leading axis K of
    ``params_batch``): K x E episodes in one call, as one batch of K E rows,
    the same key per episode across settings (paired comparisons). The
    episodes (axis E) are sharded over ``parts`` devices, each device running
    its episodes under every setting; ``parts``, ``chunk`` and the padding
    are as in :func:`rollout` (``chunk``'s default counts the K E rows).

    Returns:
        (OutcomeRow, Trajectory) with leading axes (K, E).
    """
    n = specs.scene.shape[0]
    keys = _keys(keys, n)
    K = jax.tree.leaves(params_batch)[0].shape[0]
    return _sharded(_rollout_sweep, world, specs, agent, params_batch, keys, chunk, batch_parts(n, parts), K, 1)


def rollout_memory(world: World, specs: T.EpisodeSpec, agent, params, keys: jax.Array, chunk: int | None = None,
                   parts: int | None = None, sweep: bool = False) -> dict:
    """XLA's memory analysis of the program :func:`rollout` (or, with
    ``sweep``, :func:`rollout_sweep`, ``params`` with a leading K axis) runs
    for these arguments, per device, in bytes: ``arguments`` (the world's
    copy, the specs, parameters and keys), ``outputs``, ``temporaries``
    (the scan's state and every intermediate buffer XLA keeps at once) and
    ``peak`` (their sum less what outputs alias from arguments): the memory
    the compiled program needs on one device, whatever the backend reports
    at run time (the CPU backend keeps no allocation statistics). Compiles
    the program (the compilation cache makes a later call with the same
    shapes free)."""
    args, static = rollout_call(world, specs, agent, params, keys, chunk, parts, sweep)
    m = _run_sharded.lower(*args, **static).compile().memory_analysis()
    arg, out, tmp = int(m.argument_size_in_bytes), int(m.output_size_in_bytes), int(m.temp_size_in_bytes)
    alias = int(getattr(m, "alias_size_in_bytes", 0))
    return {"arguments": arg, "outputs": out, "temporaries": tmp, "peak": arg + out + tmp - alias}


def pad_index(n: int, size: int) -> np.ndarray:
    """The rows of an ``n``-row batch padded to ``size`` rows: ``0 .. n - 1``,
    then copies of the last row (:func:`pad_specs`)."""
    return np.minimum(np.arange(max(n, size)), n - 1)


def pad_specs(specs: T.EpisodeSpec, size: int) -> T.EpisodeSpec:
    """Pad a batch of specs to ``size`` rows with invalid copies of the last
    row (padding rows start finished and are masked out of every metric;
    rows that were already padding stay padding). Host (numpy) specs stay on
    the host."""
    n = specs.scene.shape[0]
    if n >= size:
        return specs
    out = jax.tree.map(lambda a: a[pad_index(n, size)], specs)
    return dataclasses.replace(out, valid=out.valid & (np.arange(size) < n))


def pad_batch(specs: T.EpisodeSpec, keys: jax.Array, size: int) -> tuple[T.EpisodeSpec, jax.Array]:
    """:func:`pad_specs`, and the (E,) keys padded alike (copies of the last key)."""
    n = keys.shape[0]
    if n < size:
        keys = jnp.concatenate([keys, jnp.repeat(keys[-1:], size - n)])
    return pad_specs(specs, size), keys
