"""Progress and current bearing of a Type-3 hint, through ``env.step`` on
the procedural houses of the test benchmark.

After a Type-3 answer, every MOVE reports (``Answer.hint_progress``,
:data:`ignjax.sim.types.HINT_PROGRESS`): "closer" when it brought the agent
nearer the hinted point, "farther" when it took it away, "reached" within
``hint_reached`` of that point, "stop_eligible" within ``stop_radius``
(geodesic) of the target; "none" while no hint is active. The distances
are recomputed here from the poses, the hinted point kept in the state and
the target's geodesic field.

The hint's bearing (``Answer.hint_bearing``) is the sector 0..7 (view
layout: 0 ahead, 2 left, 4 behind, 6 right) in which the hinted point lies
relative to the agent's pose and heading; it is set when the hint is given
and recomputed after every MOVE, while the sector first spoken
(``hint_sector``) stays as it was. It is recomputed here in numpy from the
poses and the hinted point.

Each state is copied onto 24 rows that take 24 different MOVEs (every view,
three grid cells), so one compiled batched step answers every candidate.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.sim import env as E
from ignjax.sim import types as T

CELLS = ((4, 1), (4, 2), (5, 3))
MOVES = tuple((d, c, r) for d in range(8) for c, r in CELLS)
B = len(MOVES)
MARGIN = 0.15  # a change of distance this large is a clear "closer" / "farther"


@pytest.fixture(scope="module")
def sim(small_benchmark, small_world):
    return {"es": small_benchmark["set"], "world": small_world, "step": jax.jit(E.step_batch), "reset": jax.jit(E.reset)}


def _spec(es, k):
    return jax.tree.map(lambda a: a[k], es.specs)


def _rows(state):
    return jax.tree.map(lambda a: jnp.broadcast_to(a, (B,) + a.shape), state)


def _row(states, k):
    return jax.tree.map(lambda a: a[k], states)


def _actions(kind, direction=0, col=4, row=2, question=1):
    v = lambda x: jnp.broadcast_to(jnp.asarray(x, jnp.int32), (B,))  # noqa: E731
    return T.Action(v(kind), v(direction), v(col), v(row), v(question), v(-1))


def _ask(sim, state, question):
    return _row(sim["step"](sim["world"], _rows(state), _actions(T.ASK, question=question)), 0)


def _every_move(sim, state):
    d, c, r = (np.array(x) for x in zip(*MOVES))
    return sim["step"](sim["world"], _rows(state), _actions(T.MOVE, d, c, r))


def _geodesic(world, spec, xy) -> np.ndarray:
    """(N,) the target's geodesic field at world points (N, 2), read in numpy."""
    g = world.bank.grid
    s, f = int(spec.scene), int(spec.field)
    origin, shape = np.asarray(g.origin[s]), np.asarray(g.shape[s])
    col = np.floor((xy[:, 0] - origin[0]) / g.resolution).astype(int)
    row = np.floor((xy[:, 1] - origin[1]) / g.resolution).astype(int)
    inside = (row >= 0) & (col >= 0) & (row < shape[0]) & (col < shape[1])
    field = world.fields.field(int(f))
    return np.where(inside, field[np.clip(row, 0, field.shape[0] - 1), np.clip(col, 0, field.shape[1] - 1)], np.inf)


def _check_codes(sim, before, after) -> dict:
    """Check every row's progress code against the distances; returns them."""
    cfg = sim["world"].config
    hint = np.asarray(before.hint_point)
    old = np.asarray(before.pose[:2])
    new = np.asarray(after.pose[:, :2])
    d_old = np.linalg.norm(old - hint)
    d_new = np.linalg.norm(new - hint, axis=1)
    geo = _geodesic(sim["world"], before.episode, new)
    code = np.asarray(after.answers.hint_progress)
    stop = geo <= cfg.stop_radius
    reached = ~stop & (d_new <= cfg.hint_reached)
    rest = ~stop & ~reached
    assert np.all(code[stop] == T.HINT_STOP)
    assert np.all(code[reached] == T.HINT_REACHED)
    assert np.all(code[rest & (d_new < d_old - MARGIN)] == T.HINT_CLOSER)
    assert np.all(code[rest & (d_new > d_old + MARGIN)] == T.HINT_FARTHER)
    same = code == T.HINT_SAME
    assert np.all(np.abs(d_new[same] - d_old) <= MARGIN)
    assert np.all(np.asarray(after.answers.hint_active))
    return {"d_old": d_old, "d_new": d_new, "geo": geo, "code": code}


def test_no_hint_reports_none(sim):
    """Without a Type-3 answer (none yet, or only other types), MOVEs report "none"."""
    es = sim["es"]
    st = sim["reset"](sim["world"], _spec(es, 0))
    for state in (st, _ask(sim, _ask(sim, st, 1), 2)):
        after = _every_move(sim, state)
        assert np.any(np.linalg.norm(np.asarray(after.pose[:, :2]) - np.asarray(state.pose[:2]), axis=1) > 0.3)
        assert np.all(np.asarray(after.answers.hint_progress) == T.HINT_NONE)
        assert not np.any(np.asarray(after.answers.hint_active))
        assert np.all(np.asarray(after.answers.hint_bearing) == -1)


def _far_episode(sim, minimum: float) -> int:
    """An episode whose start is at least ``minimum`` metres (geodesic) from its target."""
    es = sim["es"]
    starts = np.asarray(es.specs.start)
    for k in range(len(es)):
        if _geodesic(sim["world"], _spec(es, k), starts[k:k + 1, :2])[0] >= minimum:
            return k
    pytest.fail(f"no episode of the test benchmark starts {minimum} m from its target")


def test_moves_toward_and_away_from_the_hint_point(sim):
    """After a Type-3 answer the MOVE that ends nearest the hinted point
    reports "closer", the one that ends farthest "farther", and every move's
    code agrees with its change of distance."""
    cfg = sim["world"].config
    k = _far_episode(sim, cfg.hint_lookahead + cfg.stop_radius + 2.0)
    st = _ask(sim, sim["reset"](sim["world"], _spec(sim["es"], k)), 3)
    assert bool(st.answers.hint_active) and int(st.answers.hint_progress) == T.HINT_NONE
    after = _every_move(sim, st)
    r = _check_codes(sim, st, after)
    toward, away = int(np.argmin(r["d_new"])), int(np.argmax(r["d_new"]))
    assert r["d_new"][toward] < r["d_old"] - MARGIN and r["d_new"][away] > r["d_old"] + MARGIN
    assert r["code"][toward] in (T.HINT_CLOSER, T.HINT_REACHED)
    assert r["code"][away] == T.HINT_FARTHER
    assert (r["code"] == T.HINT_CLOSER).sum() >= 2 and (r["code"] == T.HINT_FARTHER).sum() >= 2


def test_reaching_the_hint_point(sim):
    """MOVEs toward the hinted point (the best of the 24 each time) until the
    agent is within ``hint_reached`` of it: that MOVE reports "reached"
    (the target itself is still farther than ``stop_radius``)."""
    cfg = sim["world"].config
    k = _far_episode(sim, cfg.hint_lookahead + cfg.stop_radius + 2.0)
    st = _ask(sim, sim["reset"](sim["world"], _spec(sim["es"], k)), 3)
    for _ in range(8):
        after = _every_move(sim, st)
        r = _check_codes(sim, st, after)
        best = int(np.argmin(r["d_new"]))
        st = _row(after, best)
        if r["d_new"][best] <= cfg.hint_reached:
            break
    else:
        pytest.fail(f"the hinted point was not reached in 8 moves (last distance {r['d_new'][best]:.2f} m)")
    assert r["geo"][best] > cfg.stop_radius
    assert int(st.answers.hint_progress) == T.HINT_REACHED


def test_within_the_stop_radius_is_stop_eligible(sim):
    """Starting 0.3-0.7 m (geodesic) from the target, after a Type-3 answer
    the MOVEs that end within ``stop_radius`` of the target report
    "stop_eligible" (whatever they did to the distance to the hinted point)."""
    es = sim["es"]
    world = sim["world"]
    cfg = world.config
    spec = _spec(es, 0)
    s = int(spec.scene)
    grid = es.bank.navgrids[s]
    pts = grid.navigable_points()
    geo = _geodesic(world, spec, pts)
    near = pts[(geo >= 0.3) & (geo <= 0.7)]
    assert len(near)
    spec = dataclasses.replace(spec, start=jnp.asarray([near[0][0], near[0][1], 0.0], jnp.float32))
    st = _ask(sim, sim["reset"](world, spec), 3)
    after = _every_move(sim, st)
    r = _check_codes(sim, st, after)
    assert (r["geo"] <= cfg.stop_radius).sum() >= 1
    assert np.all(r["code"][r["geo"] <= cfg.stop_radius] == T.HINT_STOP)
    assert (r["code"] == T.HINT_STOP).sum() >= 1


def _sectors(pose, hint) -> tuple[np.ndarray, np.ndarray]:
    """The hinted point's sector (view layout, 45 degrees each, sector 0
    centred ahead, counter-clockwise) from poses (N, 3), in float64, and
    whether each lies clear of a sector edge (0.01 rad)."""
    pose = np.atleast_2d(np.asarray(pose, np.float64))
    hint = np.asarray(hint, np.float64)
    rel = np.arctan2(hint[1] - pose[:, 1], hint[0] - pose[:, 0]) - pose[:, 2]
    rel = (rel + np.pi) % (2 * np.pi) - np.pi
    step = rel / (np.pi / 4)
    clear = np.abs(step - np.floor(step) - 0.5) > 0.01 / (np.pi / 4)
    return np.round(step).astype(int) % 8, clear


def _check_bearings(after, hint) -> np.ndarray:
    """Every row's bearing against the sector recomputed from its pose; returns them."""
    want, clear = _sectors(after.pose, hint)
    code = np.atleast_1d(np.asarray(after.answers.hint_bearing))
    assert clear.sum() >= len(clear) - 2
    np.testing.assert_array_equal(code[clear], want[clear])
    return code


def test_bearing_is_set_with_the_hint_and_follows_every_move(sim):
    """The Type-3 answer sets the bearing from the pose it was asked at; after
    each of 24 MOVEs it is the hinted point's sector from the new pose and
    heading, while the sector first spoken is left as it was. The moves
    face eight ways, so the bearing takes several values."""
    cfg = sim["world"].config
    k = _far_episode(sim, cfg.hint_lookahead + cfg.stop_radius + 2.0)
    st = sim["reset"](sim["world"], _spec(sim["es"], k))
    assert int(st.answers.hint_bearing) == -1
    st = _ask(sim, st, 3)
    hint = np.asarray(st.hint_point)
    _check_bearings(st, hint)
    after = _every_move(sim, st)
    code = _check_bearings(after, hint)
    assert np.all(np.asarray(after.answers.hint_sector) == int(st.answers.hint_sector))
    assert len(set(code.tolist())) >= 3
    # a question after the moves leaves the bearing as the last move set it
    row = _row(after, 0)
    asked = _ask(sim, row, 1)
    assert int(asked.answers.hint_bearing) == int(row.answers.hint_bearing)


def _facing_the_hint(sim, k):
    """Episode k started facing its hinted point, with the hint given:
    (state, hinted point, start pose)."""
    world = sim["world"]
    spec = _spec(sim["es"], k)
    hint = np.asarray(_ask(sim, sim["reset"](world, spec), 3).hint_point)
    start = np.asarray(spec.start, np.float64)
    start[2] = np.arctan2(hint[1] - start[1], hint[0] - start[0])
    st = _ask(sim, sim["reset"](world, dataclasses.replace(spec, start=jnp.asarray(start, jnp.float32))), 3)
    np.testing.assert_allclose(np.asarray(st.hint_point), hint)  # the route does not depend on the facing
    return st, hint, start


def test_bearing_turns_from_ahead_to_the_side_when_the_agent_turns_left(sim):
    """An agent that faces the hinted point hears it straight ahead (sector
    0); after a MOVE into its left view that leaves it facing about 90
    degrees further counter-clockwise, the point lies on its right (sector
    6, or 5 behind-right when the move carried it well sideways), as the
    pose and the point give it, while the sector first spoken stays.
    Episodes are tried in order until one has room for such a move."""
    cfg = sim["world"].config
    starts = np.asarray(sim["es"].specs.start)
    is_left = np.array([d == 2 for d, _, _ in MOVES])
    far = cfg.hint_lookahead + cfg.stop_radius + 2.0
    for k in range(len(sim["es"])):
        if _geodesic(sim["world"], _spec(sim["es"], k), starts[k:k + 1, :2])[0] < far:
            continue
        st, hint, start = _facing_the_hint(sim, k)
        assert int(st.answers.hint_bearing) == 0
        after = _every_move(sim, st)
        code = _check_bearings(after, hint)
        pose = np.asarray(after.pose, np.float64)
        turn = (pose[:, 2] - start[2] - np.pi / 2 + np.pi) % (2 * np.pi) - np.pi
        left = is_left & (np.linalg.norm(pose[:, :2] - start[:2], axis=1) > 0.3) & (np.abs(turn) < np.radians(10))
        if left.any():
            break
    else:
        pytest.fail("no episode has a MOVE into the left view that turns the agent about 90 degrees")
    assert set(code[left].tolist()) <= {5, 6}
    assert np.all(np.asarray(after.answers.hint_sector)[left] == int(st.answers.hint_sector))
