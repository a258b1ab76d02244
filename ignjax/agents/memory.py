"""Scripted agents' memory of one episode (:class:`Memory`) and how an
observation is folded into it.

* a coarse visit map in the odometry frame (start-centred, world axes,
  ``VISIT_CELL`` metres per cell) to prefer unexplored directions;
* candidate slots: every instance of the instruction's category the agent
  has seen (handle, estimated position from range and bearing, attributes,
  the room label the agent stood in when it saw it, log-likelihood of the
  oracle's answers, rejected by a Type-4 "no");
* the belief state of the belief-based agents (:mod:`ignjax.agents.belief`):
  the "not seen yet" log-likelihoods, the last route hint, the pending
  question.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp

from ignjax.arrays import pytree_dataclass
from ignjax.scenes import vocab
from ignjax.sim import types as T
from ignjax.sim.geometry import wrap_angle

N_ROOM_LABELS = len(vocab.ALL_ROOM_LABELS)
VISIT_CELL = 0.5
VISIT_SIZE = 64
VISIT_DTYPE = jnp.uint8  # visit counts saturate at 255; a cell is counted once per decision
MAX_CANDIDATES = 12
ATTR_MISMATCH_LOGLIK = -8.0  # log-likelihood of a Type-1 answer per said attribute a candidate was seen without
ROOM_MISMATCH_LOGLIK = -4.0  # log-likelihood of a Type-2 answer under a candidate seen in a room of another label


@pytree_dataclass
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
        hint_done: () bool, the active hint's point was reached (reset by a new hint).
        last_asked: () int32 question type asked at the previous step (0 none).
        asked_about: () int32 slot a pending Type-4 question was about (-1).
        approach: () int32 slot being approached (-1).
        pending_stop: () bool, the Type-4 follow-up's one closer move was made:
            STOP at the next decision.
        t: () int32 decisions taken.
        consumed: (4,) bool, answers of each type already folded into the
            belief (Type 1 and 2 facts are folded once).
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
    hint_done: jax.Array
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
                      unseen_logw=jnp.zeros((N_ROOM_LABELS, 8), jnp.float32), hint_heading=jnp.float32(0.0),
                      has_hint=jnp.array(False), hint_done=jnp.array(False), last_asked=jnp.int32(0),
                      asked_about=jnp.int32(-1),
                      approach=jnp.int32(-1), pending_stop=jnp.array(False), t=jnp.int32(0),
                      consumed=jnp.zeros(4, bool))


def visit_index(xy):
    """(2,) int32 (column, row) of the visit-map cell holding odometry-frame point ``xy`` (clipped to the map)."""
    ij = jnp.floor(xy / VISIT_CELL).astype(jnp.int32) + VISIT_SIZE // 2
    return jnp.clip(ij, 0, VISIT_SIZE - 1)


def attribute_loglik(attrs, said):
    """(...) log-likelihood of a Type-1 answer that says attributes ``said``
    (4,) int32 (colour, material, size, state; -1 unsaid) under "the
    candidate with observed ``attrs`` (..., 4) is the target":
    :data:`ATTR_MISMATCH_LOGLIK` per said attribute the candidate was seen
    with another value of (unobserved attributes agree with anything)."""
    bad = (attrs >= 0) & (said >= 0) & (attrs != said)
    return ATTR_MISMATCH_LOGLIK * jnp.sum(bad, axis=-1).astype(jnp.float32)


def observe_memory(mem: Memory, obs: T.Observation, attrs_known=None, room_known=None) -> Memory:
    """Fold an observation into memory: mark the visit, add/refresh the
    candidates of the goal category in sight. New candidates start with
    the log-likelihood of the Type-1 attributes and Type-2 room answers
    already received (``attrs_known``: (4,) int32 said colour, material,
    size and state codes, -1 unsaid; ``room_known``: () int32 code or -1)."""
    ij = visit_index(obs.odometry[:2])
    v = mem.visits[ij[1], ij[0]]
    visits = mem.visits.at[ij[1], ij[0]].set(jnp.where(v < jnp.iinfo(v.dtype).max, v + 1, v))
    attrs_known = jnp.full(4, -1, jnp.int32) if attrs_known is None else jnp.asarray(attrs_known, jnp.int32)
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
        lw = attribute_loglik(obs.visible_attrs[k], attrs_known) \
            + jnp.where((room_known >= 0) & (room >= 0) & (room != room_known), ROOM_MISMATCH_LOGLIK, 0.0)
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


__all__ = ["ATTR_MISMATCH_LOGLIK", "MAX_CANDIDATES", "Memory", "N_ROOM_LABELS", "ROOM_MISMATCH_LOGLIK", "VISIT_CELL",
           "VISIT_DTYPE", "VISIT_SIZE", "attribute_loglik", "candidate_relative", "observe_memory", "visit_index"]
