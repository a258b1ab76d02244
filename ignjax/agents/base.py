"""Agent interface, registry and the shared building blocks of scripted agents.

An :class:`Agent` is a pair of pure functions::

    init(params, obs, key) -> pstate
    act(params, obs, answers, pstate, key, priv) -> (Action, pstate)

written for one episode (vmapped by the rollout). ``obs`` is an
:class:`~ignjax.sim.types.Observation`, ``answers`` the oracle's
:class:`~ignjax.sim.types.Answer`; ``priv`` is
:class:`~ignjax.sim.rollout.Privileged` for agents with ``privileged=True`` and
None for every other agent. ``params`` is a pytree the rollout can vmap
over (e.g. per-type cost vectors for in-the-loop sweeps).

Shared pieces (:class:`Memory`):

* a coarse visit map in the odometry frame (start-centred, world axes,
  ``VISIT_CELL`` metres per cell) to prefer unexplored directions;
* candidate slots: every instance of the instruction's category the agent
  has seen (handle, estimated position from range and bearing, attributes,
  the room label the agent stood in when it saw it, log-likelihood of the
  oracle's answers, rejected by a Type-4 "no");
* :func:`move_toward`: the grid cell (view, column, row) whose executor
  waypoint lies toward a relative bearing at about a given distance.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import partial
from typing import Any, Callable, Mapping

import jax
import jax.numpy as jnp

from ignjax.scenes import vocab
from ignjax.sim import types as T
from ignjax.sim.geometry import wrap_angle

N_LABELS = len(vocab.ALL_ROOM_LABELS)
VISIT_CELL = 0.5
VISIT_SIZE = 64
VISIT_DTYPE = jnp.uint8  # visit counts saturate at 255; a cell is counted once per decision
MAX_CANDIDATES = 12


@dataclass(frozen=True)
class Agent:
    """A registered agent.

    Attributes:
        name: registry name.
        init: ``(params, obs, key) -> pstate``.
        act: ``(params, obs, answers, pstate, key, priv) -> (Action, pstate)``.
        default_params: ``() -> params``.
        privileged: receives shortest-path information (an upper bound,
            never a fair competitor).
        asks: may ask questions.
        description: one line for ``--help`` and reports.
    """

    name: str
    init: Callable
    act: Callable
    default_params: Callable[[], Any]
    privileged: bool = False
    asks: bool = False
    description: str = ""


def pytree_dataclass(cls):
    """Register a (frozen) dataclass as a pytree whose every field is data."""
    names = [f.name for f in dataclasses.fields(cls)]
    return partial(jax.tree_util.register_dataclass, data_fields=names, meta_fields=[])(cls)


@pytree_dataclass
@dataclass(frozen=True)
class Memory:
    """Scripted agents' memory (one episode).

    Attributes:
        visits: (G, G) uint8 visit counts of odometry-frame cells (a cell
            is counted at most once per decision; counts saturate at 255). A
            quarter of the int32 grid's bytes: this grid is most of the
            memory every rollout step moves per episode.
        handle: (M,) int32 instance handle of each candidate slot (-1 empty).
        pos: (M, 2) float32 estimated candidate positions, odometry frame.
        attrs: (M, 4) int32 observed colour/material/size/state codes.
        room: (M,) int32 room label the agent stood in when it saw the candidate (-1 unknown).
        logw: (M,) float32 log-likelihood of the oracle's answers under "this candidate is the target".
        rejected: (M,) bool, a Type-4 answer said no.
        unseen_logw: (L, 8) float32 the same for "the target is an instance not
            seen yet, in a room with label l, in absolute direction sector s
            (45 degree sectors of world heading) from the agent".
        hint_heading: () float32 absolute heading of the last Type-3 hint.
        has_hint: () bool.
        last_asked: () int32 question type asked at the previous step (0 none).
        asked_about: () int32 slot a pending Type-4 question was about (-1).
        approach: () int32 slot being approached (-1).
        pending_stop: () bool, stop at the next decision (Type-4 follow-up).
        t: () int32 decisions taken.
        consumed: (4,) bool, answers of each type already folded into the belief.
    """

    visits: jax.Array
    handle: jax.Array
    pos: jax.Array
    attrs: jax.Array
    room: jax.Array
    logw: jax.Array
    rejected: jax.Array
    unseen_logw: jax.Array
    hint_heading: jax.Array
    has_hint: jax.Array
    last_asked: jax.Array
    asked_about: jax.Array
    approach: jax.Array
    pending_stop: jax.Array
    t: jax.Array
    consumed: jax.Array

    @staticmethod
    def empty() -> "Memory":
        M = MAX_CANDIDATES
        return Memory(visits=jnp.zeros((VISIT_SIZE, VISIT_SIZE), VISIT_DTYPE), handle=jnp.full(M, -1, jnp.int32),
                      pos=jnp.zeros((M, 2), jnp.float32), attrs=jnp.full((M, 4), -1, jnp.int32),
                      room=jnp.full(M, -1, jnp.int32), logw=jnp.zeros(M, jnp.float32), rejected=jnp.zeros(M, bool),
                      unseen_logw=jnp.zeros((N_LABELS, 8), jnp.float32), hint_heading=jnp.float32(0.0), has_hint=jnp.array(False),
                      last_asked=jnp.int32(0), asked_about=jnp.int32(-1), approach=jnp.int32(-1),
                      pending_stop=jnp.array(False), t=jnp.int32(0), consumed=jnp.zeros(4, bool))


def _visit_index(xy):
    ij = jnp.floor(xy / VISIT_CELL).astype(jnp.int32) + VISIT_SIZE // 2
    return jnp.clip(ij, 0, VISIT_SIZE - 1)


def observe_memory(mem: Memory, obs: T.Observation, colour_known=None, room_known=None) -> Memory:
    """Fold an observation into memory: mark the visit, add/refresh the
    candidates of the goal category in sight. New candidates start with
    the log-likelihood of the Type-1 colour and Type-2 room answers already
    received (``colour_known`` / ``room_known``: () int32 codes or -1)."""
    ij = _visit_index(obs.odometry[:2])
    v = mem.visits[ij[1], ij[0]]
    visits = mem.visits.at[ij[1], ij[0]].set(jnp.where(v < jnp.iinfo(v.dtype).max, v + 1, v))
    colour_known = jnp.int32(-1) if colour_known is None else colour_known
    room_known = jnp.int32(-1) if room_known is None else room_known

    def add(k, m: Memory):
        h = obs.visible_handle[k]
        ok = (h >= 0) & (obs.visible_category[k] == obs.goal_category)
        ang = obs.heading + obs.visible_bearing[k]
        p = obs.odometry[:2] + obs.visible_range[k] * jnp.stack([jnp.cos(ang), jnp.sin(ang)])
        p = jnp.where(jnp.isfinite(p), p, 0.0)
        match = m.handle == h
        exists = jnp.any(match)
        free = m.handle < 0
        slot = jnp.where(exists, jnp.argmax(match), jnp.argmax(free))
        can = ok & (exists | jnp.any(free))
        new = ok & ~exists & jnp.any(free)
        room = jnp.where(obs.visible_range[k] <= 3.0, obs.room_label, -1)
        colour = obs.visible_attrs[k, 0]
        lw = jnp.where((colour_known >= 0) & (colour >= 0) & (colour != colour_known), -8.0, 0.0) \
            + jnp.where((room_known >= 0) & (room >= 0) & (room != room_known), -4.0, 0.0)
        return dataclasses.replace(
            m,
            handle=m.handle.at[slot].set(jnp.where(can, h, m.handle[slot])),
            pos=m.pos.at[slot].set(jnp.where(can, p, m.pos[slot])),
            attrs=m.attrs.at[slot].set(jnp.where(can, obs.visible_attrs[k], m.attrs[slot])),
            room=m.room.at[slot].set(jnp.where(new, room, jnp.where(can & (m.room[slot] < 0), room, m.room[slot]))),
            logw=m.logw.at[slot].set(jnp.where(new, lw, m.logw[slot])),
        )

    mem = dataclasses.replace(mem, visits=visits)
    return jax.lax.fori_loop(0, obs.visible_handle.shape[0], add, mem)


def candidate_relative(mem: Memory, obs: T.Observation):
    """(M,) distance and (M,) relative bearing of every candidate slot."""
    d = mem.pos - obs.odometry[None, :2]
    dist = jnp.linalg.norm(d, axis=1)
    bearing = wrap_angle(jnp.arctan2(d[:, 1], d[:, 0]) - obs.heading)
    return dist, bearing


def move_toward(bearing, distance, config: T.SimConfig = T.SimConfig()) -> T.Action:
    """A MOVE whose executor waypoint lies toward ``bearing`` (relative,
    radians, left positive) at about ``distance`` metres on the floor
    (rows 1..3; shorter distances use the bottom row)."""
    W, H = config.image_size
    f = (W / 2) / math.tan(math.radians(config.hfov) / 2)
    k = (jnp.round(wrap_angle(bearing) / (math.pi / 4)).astype(jnp.int32)) % 8
    theta = wrap_angle(bearing - k.astype(jnp.float32) * (math.pi / 4))
    u = W / 2 - f * jnp.tan(theta)
    col = jnp.clip(jnp.floor(u / (W / 8)).astype(jnp.int32) + 1, 1, 8)
    phi = jnp.arctan2(config.eye_height, jnp.maximum(distance, 0.3))
    v = H / 2 + f * jnp.tan(jnp.minimum(phi, 1.5))
    row = jnp.clip(8 - jnp.floor(v / (H / 8)).astype(jnp.int32), 1, 3)
    return T.Action.make(T.MOVE, k, col, row)


def explore_direction(mem: Memory, obs: T.Observation, bias=None, bias_weight=0.0, rng=None):
    """Relative bearing of the most promising view to explore: long free
    space, few visits two metres ahead, not behind, not blocked; optionally
    biased toward an absolute heading (a route hint)."""
    rel = jnp.arange(8, dtype=jnp.float32) * (math.pi / 4)
    free = jnp.mean(jnp.minimum(obs.free_space, 4.0), axis=1)
    ahead = obs.odometry[:2][None] + 2.0 * jnp.stack([jnp.cos(obs.heading + rel), jnp.sin(obs.heading + rel)], -1)
    ij = jax.vmap(_visit_index)(ahead)
    seen = mem.visits[ij[:, 1], ij[:, 0]].astype(jnp.float32)
    rear = jnp.array([0, 0, 0, 1, 1, 1, 0, 0], jnp.float32)
    score = free - 0.8 * seen - 0.6 * rear - 2.0 * obs.blocked.astype(jnp.float32)
    score = jnp.where(free < 0.8, score - 3.0, score)
    if bias is not None:
        score = score + bias_weight * jnp.cos(wrap_angle(bias - (obs.heading + rel)))
    if rng is not None:
        score = score + 0.3 * jax.random.uniform(rng, (8,))
    k = jnp.argmax(score)
    return rel[k], free[k]


def registry() -> Mapping[str, Agent]:
    """Immutable mapping of the built-in agents (name -> :class:`Agent`)."""
    from ignjax.agents.policies import AGENTS

    return AGENTS


def get_agent(name: str) -> Agent:
    """The agent registered as ``name``.

    Raises:
        ConfigError: unknown name (the message lists the known ones).
    """
    from ignjax.errors import ConfigError

    reg = registry()
    if name not in reg:
        raise ConfigError(None, "agent", f"unknown agent {name!r}; known agents: {sorted(reg)}")
    return reg[name]
