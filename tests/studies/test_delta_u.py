"""Delta-U (paper §4.3) on constructed trajectories with known areas: 1 m
cells and r = 0.5 m, so a path covers exactly the cells whose centres it
passes through."""

from __future__ import annotations

import numpy as np
import pytest

from ignjax.studies import interaction as IA

S = 10  # planner steps of the trajectory arrays (poses: S + 1)


def _poses(points, used):
    """(S + 1, 2) poses: ``points`` = pose[0..used]; finished episodes stay put."""
    p = np.asarray(points, np.float64)
    assert len(p) == used + 1
    return np.concatenate([p, np.repeat(p[-1:], S + 1 - len(p), axis=0)])


def _events(questions, used, difficulty):
    """Events dict from (episode, type, step) triples."""
    ep, ty, st = (np.asarray(x, np.int64) for x in zip(*questions))
    return {"episode": ep, "type": ty, "step": st, "charged": np.ones(len(ep), bool),
            "steps_used": np.asarray(used, np.int64), "difficulty": np.asarray(difficulty, np.int64),
            "episode_id": np.asarray([str(i) for i in range(len(used))])}


@pytest.fixture()
def case():
    c = lambda x, y: (x + 0.5, y + 0.5)  # noqa: E731  the centre of cell (x, y)
    # 0 (hard): three moves east, Type 3 at step 3, one move north, STOP at step 5 (6 steps used)
    a = _poses([c(0, 0), c(1, 0), c(2, 0), c(3, 0), c(3, 0), c(3, 1), c(3, 1)], 6)
    # 1 (easy): Type 1 at step 0 (no motion), one move, Type 3 at step 2, two moves north, STOP (6 steps)
    b = _poses([c(0, 0), c(0, 0), c(1, 0), c(1, 0), c(1, 1), c(1, 2), c(1, 2)], 6)
    # 2 (medium): Type 3 at step 0, then moves; Type 3 again at its last step (4 steps used)
    d = _poses([c(0, 0), c(0, 0), c(1, 0), c(2, 0), c(2, 0)], 4)
    poses = np.stack([a, b, d])
    events = _events([(0, 3, 3), (1, 1, 0), (1, 3, 2), (2, 3, 0), (2, 3, 3)], used=[6, 6, 4], difficulty=[2, 0, 1])
    return poses, events


def test_matched_horizon_areas(case):
    poses, events = case
    du = IA.delta_u(poses, events, h=5, r=0.5, cell=1.0)
    # only Type-3 questions, in event order: (0, step 3), (1, step 2), (2, step 0), (2, step 3)
    np.testing.assert_array_equal(du["episode"], [0, 1, 2, 2])
    # horizon m = min(h, s); 0 for the last-step question of episode 2
    np.testing.assert_array_equal(du["horizon"], [3, 2, 0, 0])
    # episode 0: before = cells (0..3, 0) = 4; after = 3 steps cut at the STOP: (3,0), (3,1) = 2
    # episode 1: before = pose[0..2] = (0,0), (1,0) = 2 (the Type-1 step explores nothing);
    #            after = pose[3..5] = (1,0), (1,1), (1,2) = 3
    np.testing.assert_allclose(du["area_before"][:2], [4.0, 2.0])
    np.testing.assert_allclose(du["area_after"][:2], [2.0, 3.0])
    np.testing.assert_allclose(du["delta_u"][:2], [0.5, -0.5])
    # no before window (step 0) and no step after the answer (last step): left out, not zero
    assert np.isnan(du["delta_u"][2:]).all() and np.isnan(du["area_before"][2:]).all()
    np.testing.assert_array_equal(du["count"], [1, 0, 1])
    np.testing.assert_allclose(du["mean"][[0, 2]], [-0.5, 0.5])
    assert np.isnan(du["mean"][1])
    assert du["mean_all"] == pytest.approx(0.0) and du["n_kept"] == 2


def test_stopping_soon_after_the_answer_shrinks_the_explored_area(case):
    """The after window is matched to the before window, not to the steps
    left: the shortened window of episode 0 (steps left after the answer: 2)
    would give Delta-U = (3 - 2) / 3 instead of (4 - 2) / 4."""
    poses, events = case
    du = IA.delta_u(poses, events, h=5, r=0.5, cell=1.0)
    assert du["delta_u"][0] == pytest.approx(0.5)
    # a shorter horizon: before = (2,0), (3,0) (h = 1), after = (3,0), (3,1)
    assert IA.delta_u(poses, events, h=1, r=0.5, cell=1.0)["delta_u"][0] == pytest.approx(0.0)


def test_min_horizon_leaves_out_early_questions(case):
    poses, events = case
    du = IA.delta_u(poses, events, h=5, r=0.5, cell=1.0, min_horizon=3)
    # episode 1's question at step 2 has m = 2 < 3
    assert np.isfinite(du["delta_u"][0]) and np.isnan(du["delta_u"][1])
    np.testing.assert_array_equal(du["count"], [0, 0, 1])
