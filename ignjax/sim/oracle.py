"""The oracle as array facts: what each question type answers (the ASK
rules of :mod:`ignjax.sim.env`'s docstring), the charging of questions
against the budget, and the progress and current bearing of an active
route hint after a MOVE.

Answers are :class:`~ignjax.sim.types.Answer` arrays; their words are
rendered on the host by :mod:`ignjax.sim.oracle_text`.
"""

from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp

from ignjax.sim import geometry as G
from ignjax.sim import types as T
from ignjax.sim.queries import cell_index, euclidean_to_target, geodesic_to_target, instance_in_sight, room_at, sector_of
from ignjax.sim.world import World


def target_visible_front(world: World, ep: T.EpisodeSpec, pose):
    """() bool: the target is in the front view's field of view (the view's
    own width, ``view_hfov``: 30 degrees with 12 narrow views), within
    ``confirm_range`` and in line of sight."""
    cfg = world.config
    inst = world.bank.instances
    c = inst.center[ep.scene, ep.target]
    rel = jnp.arctan2(c[1] - pose[1], c[0] - pose[0]) - pose[2]
    in_fov = jnp.abs(G.wrap_angle(rel)) <= math.radians(cfg.view_hfov) / 2
    close = euclidean_to_target(world, ep, pose[:2]) <= cfg.confirm_range
    eye = jnp.array([pose[0], pose[1], cfg.eye_height], jnp.float32)
    seen = instance_in_sight(world, ep.scene, ep.target, eye)
    return in_fov & close & seen


def route_facts(world: World, ep: T.EpisodeSpec, pose):
    """Type-3 facts: follow the target's geodesic field downhill from the
    agent for ``hint_lookahead`` metres.

    Returns:
        (room_label, sector, landmark_category, in_room, hint_point (2,)).
    """
    cfg = world.config
    bank = world.bank
    g = bank.grid
    s = ep.scene
    fi = ep.field
    res = g.resolution
    n = int(math.ceil(cfg.hint_lookahead / res))
    row0, col0 = cell_index(world, s, pose[:2])
    Hh, Ww = world.fields.shape
    nbr = jnp.array([[-1, -1], [-1, 0], [-1, 1], [0, -1], [0, 1], [1, -1], [1, 0], [1, 1]], jnp.int32)
    cost = jnp.where(jnp.all(nbr != 0, axis=1), res * math.sqrt(2), res).astype(jnp.float32)
    room0 = room_at(world, s, pose[:2])

    def walk(_, carry):
        r, c, travelled, exit_r, exit_c, left = carry
        rr = jnp.clip(r + nbr[:, 0], 0, Hh - 1)
        cc = jnp.clip(c + nbr[:, 1], 0, Ww - 1)
        vals = world.fields.at(fi, rr, cc)
        here = world.fields.at(fi, r, c)
        k = jnp.argmin(vals)
        better = (vals[k] < here) & (travelled < cfg.hint_lookahead)
        nr = jnp.where(better, rr[k], r)
        nc = jnp.where(better, cc[k], c)
        travelled = travelled + jnp.where(better, cost[k], 0.0)
        room_here = g.room[s, nr, nc]
        newly = better & ~left & (room_here != room0) & (room_here >= 0)
        exit_r = jnp.where(newly, nr, exit_r)
        exit_c = jnp.where(newly, nc, exit_c)
        left = left | newly
        return nr, nc, travelled, exit_r, exit_c, left

    r, c, _, er, ec, left = jax.lax.fori_loop(0, n, walk, (row0, col0, jnp.float32(0.0), row0, col0, jnp.array(False)))
    to_world = lambda rr, cc: jnp.stack([g.origin[s, 0] + (cc + 0.5) * res, g.origin[s, 1] + (rr + 0.5) * res])  # noqa: E731
    end = to_world(r, c)
    exit_pt = to_world(er, ec)
    aim = jnp.where(left, exit_pt, end)
    sector = sector_of(jnp.arctan2(aim[1] - pose[1], aim[0] - pose[0]) - pose[2])
    room_end = g.room[s, r, c]
    room_next = jnp.where(left, g.room[s, er, ec], room_end)
    label = jnp.where(room_next >= 0, bank.rooms.label[s, jnp.maximum(room_next, 0)], -1)
    # landmark: a sizeable object near the route's end (not of the goal category)
    inst = bank.instances
    big = inst.valid[s] & ~inst.structural[s] & (inst.half_extents[s, :, 0] * inst.half_extents[s, :, 1] > 0.04) \
        & (inst.category[s] != ep.category) & (inst.support[s] < 0)
    dist = jnp.linalg.norm(inst.center[s, :, :2] - end[None], axis=1)
    dist = jnp.where(big, dist, jnp.inf)
    j = jnp.argmin(dist)
    landmark = jnp.where(dist[j] <= 1.5, inst.category[s, j], -1)
    return label.astype(jnp.int32), sector, landmark.astype(jnp.int32), ~left, end


def description_facts(world: World, ep: T.EpisodeSpec) -> dict:
    """The Type-1 facts (description) and Type-2 facts (goal room and region) of an episode, as answer fields."""
    goal_label = jnp.where(ep.goal_room >= 0, world.bank.rooms.label[ep.scene, jnp.maximum(ep.goal_room, 0)], -1)
    return dict(color=ep.fact_attrs[0], material=ep.fact_attrs[1], size=ep.fact_attrs[2], state=ep.fact_attrs[3],
                on_category=ep.fact_on, near_categories=ep.fact_near, room_label=goal_label.astype(jnp.int32),
                region_category=ep.region_category)


def describe_upfront(world: World, state: T.SimState) -> T.SimState:
    """The target's full description given at reset (``SimConfig.upfront_description``):
    the Type-1 and Type-2 facts known, charged as one question of each type
    (in ``n_questions`` and the budget; not in the question trace)."""
    a = dataclasses.replace(state.answers, known=state.answers.known.at[:2].set(True), **description_facts(world, state.episode))
    return dataclasses.replace(state, answers=a, n_questions=state.n_questions.at[:2].add(1))


def ask(world: World, state: T.SimState, qtype, candidate) -> T.SimState:
    """Apply one question (charging, budget, caching, facts, follow-up)."""
    cfg = world.config
    ep = state.episode
    a = state.answers
    charged_so_far = jnp.sum(state.n_questions)
    allowed = (charged_so_far < cfg.max_questions) if cfg.question_budget else jnp.array(True)
    q = jnp.clip(qtype, 1, 4)
    n_q = state.n_questions.at[q - 1].add(jnp.where(allowed, 1, 0))
    slot = jnp.minimum(state.n_trace, cfg.trace_slots - 1)
    trace_type = state.trace_type.at[slot].set(q)
    trace_step = state.trace_step.at[slot].set(state.step)
    trace_charged = state.trace_charged.at[slot].set(allowed)

    # Type 1 / Type 2 facts (cached; charged every time)
    t1 = description_facts(world, ep)
    # Type 3
    label3, sector3, land3, inroom3, point3 = route_facts(world, ep, state.pose)
    # Type 4
    vis = target_visible_front(world, ep, state.pose)
    yes = vis & ((candidate == T.ANY_CANDIDATE) | (candidate == ep.target))
    close = geodesic_to_target(world, ep, state.pose[:2]) <= cfg.stop_radius
    follow = jnp.where(yes, jnp.where(close, T.FOLLOW_STOP_NOW, T.FOLLOW_ONE_MOVE), T.FOLLOW_NONE)

    is1, is2, is3, is4 = (allowed & (q == k) for k in (1, 2, 3, 4))
    new = dataclasses.replace(
        a,
        known=a.known.at[q - 1].set(a.known[q - 1] | allowed),
        last_type=jnp.where(allowed, q, a.last_type),
        refused=~allowed,
        color=jnp.where(is1, t1["color"], a.color), material=jnp.where(is1, t1["material"], a.material),
        size=jnp.where(is1, t1["size"], a.size), state=jnp.where(is1, t1["state"], a.state),
        on_category=jnp.where(is1, t1["on_category"], a.on_category),
        near_categories=jnp.where(is1, t1["near_categories"], a.near_categories),
        room_label=jnp.where(is2, t1["room_label"], a.room_label),
        region_category=jnp.where(is2, t1["region_category"], a.region_category),
        hint_room_label=jnp.where(is3, label3, a.hint_room_label), hint_sector=jnp.where(is3, sector3, a.hint_sector),
        hint_landmark=jnp.where(is3, land3, a.hint_landmark), hint_in_room=jnp.where(is3, inroom3, a.hint_in_room),
        hint_active=a.hint_active | is3,
        hint_progress=jnp.where(is3, T.HINT_NONE, a.hint_progress),
        hint_bearing=jnp.where(is3, hint_bearing(point3, state.pose, jnp.array(True)), a.hint_bearing),
        confirm=jnp.where(is4, yes.astype(jnp.int32), a.confirm),
        follow_up=jnp.where(is4, follow, a.follow_up),
    )
    return dataclasses.replace(
        state, n_questions=n_q, n_refused=state.n_refused + jnp.where(allowed, 0, 1), trace_type=trace_type,
        trace_step=trace_step, trace_charged=trace_charged, n_trace=state.n_trace + 1, answers=new,
        moves_since_confirm=jnp.where(is4 & yes, 0, state.moves_since_confirm),
        hint_point=jnp.where(is3, point3, state.hint_point),
    )


def hint_progress(world: World, ep, a: T.Answer, hint_point, old_xy, new_xy):
    """() int32 progress code of the active Type-3 hint (aimed at the internal
    ``hint_point``) after a MOVE from ``old_xy`` to ``new_xy``
    (:data:`~ignjax.sim.types.HINT_NONE` when no hint is active)."""
    cfg = world.config
    d_old = jnp.linalg.norm(old_xy - hint_point)
    d_new = jnp.linalg.norm(new_xy - hint_point)
    prog = jnp.where(d_new < d_old - 0.1, T.HINT_CLOSER, jnp.where(d_new > d_old + 0.1, T.HINT_FARTHER, T.HINT_SAME))
    prog = jnp.where(d_new <= cfg.hint_reached, T.HINT_REACHED, prog)
    prog = jnp.where(geodesic_to_target(world, ep, new_xy) <= cfg.stop_radius, T.HINT_STOP, prog)
    return jnp.where(a.hint_active, prog, T.HINT_NONE).astype(jnp.int32)


def hint_bearing(hint_point, pose, active):
    """() int32 egocentric sector 0..7 (view layout: 0 ahead, 2 left, 4
    behind, 6 right; :func:`~ignjax.sim.queries.sector_of`) of the internal
    ``hint_point`` seen from ``pose`` (x, y, yaw), -1 when ``active`` is
    false: the relative bearing of the paper's controller (Appendix, Eq.
    relative-target), which keeps the hinted way's side current after a
    turn or a detour. Only the sector reaches the agent, never the angle."""
    _, rel = G.relative_target(pose[:2], pose[2], hint_point)
    return jnp.where(active, sector_of(rel), -1).astype(jnp.int32)
