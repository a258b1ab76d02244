"""Scripted agents' memory of one episode (:class:`Memory`) and how an
observation is folded into it.

* a coarse visit map in the odometry frame (start-centred, world axes,
  ``VISIT_CELL`` metres per cell) to prefer unexplored directions;
* candidate slots: every instance of the instruction's category the agent
  has seen (handle, estimated position from range and bearing, attributes,
  the room label the agent stood in at its nearest sighting within 3 m and
  every label it stood in at a sighting within 3 m, log-likelihood of the oracle's route and confirmation answers, rejected
  by a Type-4 "no");
* the Type-1 and Type-2 facts received (the description's attributes, the
  goal room label): their likelihood under a candidate is taken from what
  memory holds about it now (:func:`fact_loglik`), so a candidate first
  seen through a doorway from the next room and later from inside its own
  is judged by both sightings;
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
        room: (M,) int32 room label the agent stood in at its nearest sighting of the candidate
            within 3 m (-1 unknown): a nearer sighting replaces the label of a farther one.
        room_range: (M,) float32 range of that sighting (inf: none).
        room_seen: (M,) int32 bit l set when the agent saw the candidate within 3 m
            while standing in a room of label l.
        logw: (M,) float32 log-likelihood of the Type-3 and Type-4 answers under "this candidate is
            the target" (the Type-1 and Type-2 facts enter through :func:`fact_loglik`).
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
        facts: (5,) int32 the Type-1 attributes said (colour, material, size,
            state) and the Type-2 goal room label, -1 unsaid or not known yet.
    """

    visits: jax.Array
    handle: jax.Array
    pos: jax.Array
    attrs: jax.Array
    room: jax.Array
    room_range: jax.Array
    room_seen: jax.Array
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
    facts: jax.Array

    @staticmethod
    def empty() -> "Memory":
        M = MAX_CANDIDATES
        return Memory(visits=jnp.zeros((VISIT_SIZE, VISIT_SIZE), VISIT_DTYPE), handle=jnp.full(M, -1, jnp.int32),
                      pos=jnp.zeros((M, 2), jnp.float32), attrs=jnp.full((M, 4), -1, jnp.int32),
                      room=jnp.full(M, -1, jnp.int32), room_range=jnp.full(M, jnp.inf, jnp.float32),
                      room_seen=jnp.zeros(M, jnp.int32), logw=jnp.zeros(M, jnp.float32), rejected=jnp.zeros(M, bool),
                      unseen_logw=jnp.zeros((N_ROOM_LABELS, 8), jnp.float32), hint_heading=jnp.float32(0.0),
                      has_hint=jnp.array(False), hint_done=jnp.array(False), last_asked=jnp.int32(0),
                      asked_about=jnp.int32(-1),
                      approach=jnp.int32(-1), pending_stop=jnp.array(False), t=jnp.int32(0),
                      consumed=jnp.zeros(4, bool), facts=jnp.full(5, -1, jnp.int32))


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


def fact_loglik(mem: Memory):
    """(M,) log-likelihood of the Type-1 and Type-2 facts known (``mem.facts``)
    under "this candidate is the target", from the attributes it was last seen
    with (:func:`attribute_loglik`) and the room labels the agent stood in
    when it saw it within 3 m: :data:`ROOM_MISMATCH_LOGLIK` when it was seen
    so but never from a room with the goal label. Recomputed from memory at
    every decision rather than fixed at the first sighting: an object seen
    through a doorway from the next room, or from a room open to its own,
    is cleared by a sighting from inside a room with the goal label."""
    goal = mem.facts[4]
    from_goal = (jnp.right_shift(mem.room_seen, jnp.maximum(goal, 0)) & 1) == 1
    room_bad = (goal >= 0) & (mem.room_seen != 0) & ~from_goal
    return attribute_loglik(mem.attrs, mem.facts[:4]) + jnp.where(room_bad, ROOM_MISMATCH_LOGLIK, 0.0)


def observe_memory(mem: Memory, obs: T.Observation) -> Memory:
    """Fold an observation into memory: mark the visit, add/refresh the
    candidates of the goal category in sight (position and attributes from
    the latest sighting; the room label the agent stands in, among the
    labels it was seen from when within 3 m, and as its label when this
    is the nearest such sighting so far)."""
    ij = visit_index(obs.odometry[:2])
    v = mem.visits[ij[1], ij[0]]
    visits = mem.visits.at[ij[1], ij[0]].set(jnp.where(v < jnp.iinfo(v.dtype).max, v + 1, v))

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
        r = obs.visible_range[k]
        near = can & (r <= 3.0) & (obs.room_label >= 0)
        nearer = near & (new | (r < m.room_range[slot]))
        bit = jnp.left_shift(jnp.int32(1), jnp.maximum(obs.room_label, 0))
        seen_from = jnp.where(new, 0, m.room_seen[slot]) | jnp.where(near, bit, 0)
        return dataclasses.replace(
            m,
            handle=m.handle.at[slot].set(jnp.where(can, h, m.handle[slot])),
            pos=m.pos.at[slot].set(jnp.where(can, p, m.pos[slot])),
            attrs=m.attrs.at[slot].set(jnp.where(can, obs.visible_attrs[k], m.attrs[slot])),
            room=m.room.at[slot].set(jnp.where(nearer, obs.room_label, jnp.where(new, -1, m.room[slot]))),
            room_range=m.room_range.at[slot].set(jnp.where(nearer, r, jnp.where(new, jnp.inf, m.room_range[slot]))),
            room_seen=m.room_seen.at[slot].set(jnp.where(can, seen_from, m.room_seen[slot])),
            logw=m.logw.at[slot].set(jnp.where(new, 0.0, m.logw[slot])),
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
           "VISIT_DTYPE", "VISIT_SIZE", "attribute_loglik", "candidate_relative", "fact_loglik", "observe_memory",
           "visit_index"]
