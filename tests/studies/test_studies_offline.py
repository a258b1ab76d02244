"""Offline studies: cost sensitivity, difficulty ablation, interaction analyses.

Every study is checked against an independent reference: a plain-Python
loop over episodes with the metrics functions, scipy's rank statistics, or a
hand-built case whose answer is known in advance.
"""

import math
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.stats

from ignjax.evaluate import metrics as M
from ignjax.episodes.difficulty import score_and_bin
from ignjax.errors import ConfigError, InputError
from ignjax.studies import cost_figures as CF
from ignjax.studies import cost_sensitivity as CS
from ignjax.studies import difficulty_ablation as DA
from ignjax.studies import interaction as IA
from ignjax.studies import interaction_plots as IP
from ignjax.studies import locations as LOC
from ignjax.sim.types import OutcomeRow

PNG = b"\x89PNG\r\n\x1a\n"


def _random_outcomes(rng, A=3, E=40, T=3):
    success = rng.random((A, E, T)) < 0.5
    n = rng.poisson([0.4, 0.9, 1.3, 1.6], size=(A, E, 4))
    valid = rng.random((A, E)) < 0.9
    diff = rng.integers(0, 3, size=E)
    return success, n, valid, diff


# ---------------------------------------------------------------------------
# Cost sensitivity
# ---------------------------------------------------------------------------


def _loop_wsr(success, n, valid, costs, groups=None):
    """Plain loop over cost vectors, agents and episodes with metrics.episode_wsr."""
    K, (A, E, T) = len(costs), success.shape
    G = 1 if groups is None else 3
    out = np.full((K, A, G, T), np.nan)
    for k in range(K):
        for a in range(A):
            for g in range(G):
                tot, cnt = np.zeros(T), 0
                for e in range(E):
                    if not valid[a, e] or (groups is not None and groups[e] != g):
                        continue
                    tot += M.episode_wsr(success[a, e].astype(float), n[a, e], costs[k])
                    cnt += 1
                if cnt:
                    out[k, a, g] = tot / cnt
    return out if groups is not None else out[:, :, 0]


def test_offline_wsr_equals_episode_loop():
    rng = np.random.default_rng(1)
    success, n, valid, diff = _random_outcomes(rng)
    costs = CS.cost_samples(7, seed=3)
    ref = _loop_wsr(success, n, valid, costs)
    got = CS.offline_wsr(success, n, valid, costs)
    assert got.shape == (7, 3, 3)
    np.testing.assert_allclose(got, ref, rtol=2e-6, atol=1e-7)
    # chunked evaluation (chunk of 2 cost vectors, last chunk padded) gives the same numbers
    few = CS.offline_wsr(success, n, valid, costs, max_elements=2 * len(np.unique(n.reshape(-1, 4), axis=0)))
    np.testing.assert_allclose(few, got, rtol=1e-6, atol=1e-7)
    # 2-D success and a single cost vector drop their axes
    one = CS.offline_wsr(success[..., 1], n, valid, costs[4])
    np.testing.assert_allclose(one, ref[4, :, 1], rtol=2e-6, atol=1e-7)
    # per difficulty bin, with an empty bin -> NaN
    d = np.where(diff == 2, 1, diff)
    per = CS.offline_wsr(success, n, valid, costs, difficulty=d)
    assert per.shape == (7, 3, 3, 3)
    assert np.isnan(per[:, :, 2]).all()
    np.testing.assert_allclose(per[:, :, :2], _loop_wsr(success, n, valid, costs, d)[:, :, :2], rtol=2e-6, atol=1e-7)


def test_locked_costs_reproduce_summarize():
    rng = np.random.default_rng(2)
    A, E, thr = 2, 60, M.DEFAULT_THRESHOLDS
    fd = rng.uniform(0, 5, (A, E))
    stopped = rng.random((A, E)) < 0.8
    n = rng.poisson(1.0, (A, E, 4))
    diff = rng.integers(0, 3, E)
    success = M.episode_success(fd, stopped, thr)  # (A, E, T)
    costs = CS.cost_samples(5, seed=0)
    assert np.allclose(costs[0], M.LOCKED_COSTS)
    wsr = CS.offline_wsr(success, n, None, costs)
    per = CS.offline_wsr(success, n, None, costs, difficulty=diff)
    for a in range(A):
        o = OutcomeRow.from_numpy(final_distance=fd[a], min_distance=fd[a], path_length=fd[a], stopped=stopped[a],
                                  n_questions=n[a], difficulty=diff)
        s = M.summarize(o, thr, M.LOCKED_COSTS)
        np.testing.assert_allclose(wsr[0, a], s["WSR"], rtol=2e-6)
        sg = M.summarize(o, thr, M.LOCKED_COSTS, groups=o.difficulty, n_groups=3)
        np.testing.assert_allclose(per[0, a], sg["WSR"], rtol=2e-6)
        # any other row equals summarize with that row's costs
        np.testing.assert_allclose(wsr[3, a], M.summarize(o, thr, tuple(costs[3]))["WSR"], rtol=2e-6)


def test_cost_samples_and_grid():
    c = CS.cost_samples(1000, seed=5)
    assert c.shape == (1000, 4)
    np.testing.assert_allclose(c[0], M.LOCKED_COSTS)
    np.testing.assert_allclose(c[1], [0.687 / 4] * 4)
    np.testing.assert_allclose(c.sum(1), 0.687)
    assert (c >= 0).all()
    np.testing.assert_array_equal(c, CS.cost_samples(1000, seed=5))
    assert not np.array_equal(c[2:], CS.cost_samples(1000, seed=6)[2:])
    g = CS.cost_grid(0.25)
    assert g.shape == (2 + 35, 4)
    np.testing.assert_allclose(g.sum(1), 0.687)
    with pytest.raises(ConfigError, match="cost_samples.n"):
        CS.cost_samples(1)
    with pytest.raises(ConfigError, match="cost_grid.step"):
        CS.cost_grid(0.3)


@pytest.mark.parametrize("bad, where, reason", [
    ([[0.1, 0.2, 0.3, 0.4], [0.1, -0.2, 0.3, 0.4]], r"costs\[1\]", "negative"),
    ([[0.1, np.nan, 0.3, 0.4]], r"costs\[0\]", "NaN or infinite"),
    ([0.1, np.inf, 0.3, 0.4], "costs", "NaN or infinite"),
    ([[0.1, 0.2, 0.3, 0.4], [0, 0, 0, 0]], r"costs\[1\]", "all four costs are zero"),
    ([0.1, 0.2, 0.3], "costs", "shape"),
])
def test_bad_costs_rejected(bad, where, reason):
    with pytest.raises(ConfigError, match=f"{where}.*{reason}"):
        CS.validate_costs(bad)
    with pytest.raises(ConfigError, match=reason):
        CS.offline_wsr(np.ones((1, 3), bool), np.zeros((1, 3, 4), int), None, bad)


def test_offline_wsr_rejects_mismatched_inputs():
    with pytest.raises(InputError, match="n_questions"):
        CS.offline_wsr(np.ones((2, 5), bool), np.zeros((2, 4, 4), int), None, M.LOCKED_COSTS)
    with pytest.raises(InputError, match="valid"):
        CS.offline_wsr(np.ones((2, 5), bool), np.zeros((2, 5, 4), int), np.ones(4, bool), M.LOCKED_COSTS)
    with pytest.raises(InputError, match="difficulty"):
        CS.offline_wsr(np.ones((2, 5), bool), np.zeros((2, 5, 4), int), None, M.LOCKED_COSTS, difficulty=[0, 1, 2, 3, 0])


def test_rankings_and_kendall_tau_equal_scipy():
    rng = np.random.default_rng(3)
    x = rng.integers(0, 4, size=(200, 6)).astype(float)  # many ties
    ranks = CS.rankings(x)
    for k in range(len(x)):
        np.testing.assert_allclose(ranks[k], scipy.stats.rankdata(-x[k], method="average"))
    ref = x[0]
    tau = CS.kendall_tau(x, ref)
    for k in range(len(x)):
        want = scipy.stats.kendalltau(x[k], ref).statistic
        if np.isnan(want):
            assert np.isnan(tau[k])
        else:
            assert tau[k] == pytest.approx(want, abs=1e-12)
    # ranks give the same tau as the values; row vs row; all-tied rows are NaN
    np.testing.assert_allclose(CS.kendall_tau(ranks, ranks[0]), tau)
    assert CS.kendall_tau([1.0, 2.0, 3.0], [3.0, 2.0, 1.0]) == pytest.approx(-1.0)
    assert np.isnan(CS.kendall_tau(np.ones((1, 4)), [1.0, 2.0, 3.0, 4.0])[0])
    with pytest.raises(InputError, match="NaN"):
        CS.rankings([[0.1, np.nan]])


def test_ranking_flips_where_the_analysis_says():
    """Agent 0 always succeeds but asks three Type-4 questions per episode;
    agent 1 succeeds in 60% of episodes without asking. WSR_0 = exp(-3 w4),
    WSR_1 = 0.6, so agent 0 ranks first exactly when w4 < ln(1/0.6) / 3."""
    E = 50
    success = np.stack([np.ones(E, bool), np.arange(E) < 30])
    n = np.zeros((2, E, 4), int)
    n[0, :, 3] = 3
    costs = CS.cost_samples(3000, seed=0)
    res = CS.run_study(success, n, None, costs, agent_names=["asker", "silent"], bins=10)
    np.testing.assert_allclose(res["wsr"][:, 0], np.exp(-3 * costs[:, 3]), rtol=1e-6)
    np.testing.assert_allclose(res["wsr"][:, 1], 0.6, rtol=1e-6)
    w4 = math.log(1 / 0.6) / 3
    assert costs[0, 3] < w4  # locked: the asker ranks first
    np.testing.assert_array_equal(res["reference_ranks"], [1, 2])
    margin = np.abs(costs[:, 3] - w4) > 1e-4
    expected = costs[:, 3] > w4
    f = res["flips"]
    np.testing.assert_array_equal(f["flipped"][margin], expected[margin])
    np.testing.assert_allclose(res["tau"][margin], np.where(expected[margin], -1.0, 1.0))
    assert f["fraction_flipped"] == pytest.approx(expected.mean(), abs=2e-3)
    assert f["mean_costs_flipped"][3] > w4 > f["mean_costs_kept"][3]
    # the map: share axis y = Type-4 share; cells far above the boundary flip, cells far below do not
    rate, edges = f["flip_rate"], f["edges"]
    assert rate.shape == (10, 10) and np.nanmax(rate) == 1.0 and np.nanmin(rate) == 0.0
    share_boundary = w4 / 0.687
    assert np.all(rate[edges[1:] < share_boundary - 1e-9][np.isfinite(rate[edges[1:] < share_boundary - 1e-9])] == 0)
    assert np.all(rate[edges[:-1] > share_boundary][np.isfinite(rate[edges[:-1] > share_boundary])] == 1)
    mc = res["marginals"]
    assert mc["mean"].shape == (4, 10, 2)
    # the asker's WSR falls with the Type-4 cost; the silent agent's is flat
    m4 = mc["mean"][3]
    ok = np.isfinite(m4[:, 0])
    assert np.all(np.diff(m4[ok, 0]) < 0) and np.allclose(m4[ok, 1], 0.6, atol=1e-6)


# ---------------------------------------------------------------------------
# Difficulty ablation
# ---------------------------------------------------------------------------


def _ordering_case():
    """F0 rises over episodes, F1 = 1 - F0; success iff F0 small."""
    E = 101
    f0 = (np.arange(E) + 0.5) / E
    factors = np.stack([f0, 1 - f0, np.full(E, 0.5), np.full(E, 0.5)], 1)
    success = np.stack([f0 < 0.5, f0 < 0.45])
    alphas = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0.5, 0.5, 0, 0]], float)
    thresholds = np.array([[0.3, 0.6], [0.05, 0.95]])
    return factors, success, alphas, thresholds


def test_ordering_on_a_constructed_case():
    factors, success, alphas, thresholds = _ordering_case()
    r = DA.ablate(factors, success, None, alphas, thresholds)
    # D = F0 orders (easy all succeed, hard all fail); D = 1 - F0 reverses; D = 0.5 puts every episode in medium
    np.testing.assert_array_equal(r["ordered"], [[True, True], [False, False], [False, False]])
    assert r["fraction_ordered"] == pytest.approx(2 / 6)
    np.testing.assert_array_equal(r["nonempty"], [[True, True], [True, True], [False, False]])
    assert r["fraction_ordered_nonempty"] == pytest.approx(2 / 4)
    np.testing.assert_allclose(r["proportions"][2], [[0, 1, 0], [0, 1, 0]])
    np.testing.assert_allclose(r["sr"][0, 0, :, 0], 1.0)
    np.testing.assert_allclose(r["sr"][0, 0, :, 2], 0.0)
    assert np.isnan(r["sr"][2, 0, :, 0]).all()
    np.testing.assert_allclose(r["proportions"].sum(-1), 1.0)
    skip = DA.ablate(factors, success, None, alphas, thresholds, empty="skip")
    np.testing.assert_array_equal(skip["ordered"], [[True, True], [False, False], [True, True]])
    with pytest.raises(ConfigError, match="empty"):
        DA.ablate(factors, success, None, alphas, thresholds, empty="nope")


def test_ablation_matches_score_and_bin():
    rng = np.random.default_rng(4)
    E, A = 120, 3
    factors = np.round(rng.random((E, 4)), 2)  # coarse values: many D exactly on a threshold
    success = rng.random((A, E)) < 0.5
    valid = rng.random((A, E)) < 0.9
    alphas, thresholds = DA.alpha_grid(0.25), DA.threshold_grid(0.25)
    assert alphas.shape == (35, 4) and np.allclose(alphas.sum(1), 1)
    np.testing.assert_allclose(thresholds, [[0.25, 0.5], [0.25, 0.75], [0.5, 0.75]])
    r = DA.ablate(factors, success, valid, alphas, thresholds, max_elements=2000)  # several alpha chunks
    for g in range(len(alphas)):
        _, bins = score_and_bin(factors, np.repeat(alphas[g:g + 1], len(thresholds), 0), thresholds)
        for h in range(len(thresholds)):
            for a in range(A):
                for b in range(3):
                    m = (bins[h] == b) & valid[a]
                    assert r["count"][g, h, a, b] == m.sum()
                    if m.any():
                        assert r["sr"][g, h, a, b] == pytest.approx(success[a][m].mean())
            assert r["proportions"][g, h] == pytest.approx(np.bincount(bins[h][valid.any(0)], minlength=3) / valid.any(0).sum())
    d = r["default"]
    _, b0 = score_and_bin(factors, np.array([[0.35, 0.25, 0.15, 0.25]]), np.array([[0.3, 0.6]]))
    np.testing.assert_allclose(d["proportions"], np.bincount(b0[0][valid.any(0)], minlength=3) / valid.any(0).sum())
    with pytest.raises(ConfigError, match=r"alphas\[1\].*sum to 1"):
        DA.ablate(factors, success, valid, [[1, 0, 0, 0], [0.5, 0.2, 0, 0]], thresholds)
    with pytest.raises(ConfigError, match=r"thresholds\[0\]"):
        DA.ablate(factors, success, valid, alphas, [[0.6, 0.3]])


def test_calibration_finds_the_failure_factor():
    rng = np.random.default_rng(5)
    E = 400
    factors = rng.random((E, 4))
    failure = np.stack([factors[:, 1] > 0.5, factors[:, 1] > 0.6]).astype(float)  # driven by factor 2 (F_room) only
    r = DA.calibrate(factors, failure, None, DA.alpha_grid(0.1), split_seed=7)
    np.testing.assert_allclose(r["alpha"], [0, 1, 0, 0])
    assert r["fit_corr"] > 0.8 and r["holdout_corr"] > 0.8
    assert r["holdout_corr"] > r["default_holdout_corr"] + 0.2
    assert len(r["fit_index"]) == len(r["holdout_index"]) == 200
    assert not set(r["fit_index"]) & set(r["holdout_index"])
    again = DA.calibrate(factors, failure, None, DA.alpha_grid(0.1), split_seed=7)
    np.testing.assert_array_equal(again["fit_index"], r["fit_index"])
    assert not np.array_equal(DA.split_halves(E, 8)[0], r["fit_index"])
    # the criterion is scipy's Spearman, averaged over agents
    g = r["index"]
    fit = r["fit_index"]
    d = factors[fit] @ r["alphas"][g]
    want = np.mean([scipy.stats.spearmanr(d, failure[a, fit]).statistic for a in range(2)])
    assert r["fit_corr"] == pytest.approx(want)
    x = rng.integers(0, 5, size=(3, 30)).astype(float)
    y = rng.integers(0, 2, size=30).astype(float)
    np.testing.assert_allclose(DA.spearman_rows(x, y), [scipy.stats.spearmanr(xi, y).statistic for xi in x])
    with pytest.raises(InputError, match="failure"):
        DA.calibrate(factors, np.zeros(E), None, DA.alpha_grid(0.5))


# ---------------------------------------------------------------------------
# Interaction
# ---------------------------------------------------------------------------

RES = 0.05


def _grid(*rects, size=200, room=None):
    """A NavGrid-like object (origin 0, 5 cm cells) whose navigable mask is
    the union of (x0, x1, y0, y1) rectangles in metres."""
    nav = np.zeros((size, size), bool)
    for x0, x1, y0, y1 in rects:
        nav[round(y0 / RES):round(y1 / RES), round(x0 / RES):round(x1 / RES)] = True
    return SimpleNamespace(navigable=nav, origin=np.zeros(2), resolution=RES,
                           room=np.where(nav, 0, -1) if room is None else room)


CORRIDOR = (1.0, 9.0, 4.6, 5.4)  # 0.8 m wide on the navigable mask, along x
STEM = (4.6, 5.4, 5.4, 9.0)  # a branch going +y from the corridor's middle
STEM_DOWN = (4.6, 5.4, 1.0, 4.6)
ROOM = (2.5, 7.5, 2.5, 7.5)


@pytest.mark.parametrize("rects, xy, want", [
    ((CORRIDOR,), (5.0, 5.0), "corridor"),
    ((CORRIDOR,), (2.0, 4.8), "corridor"),  # off the centre line
    ((CORRIDOR, STEM), (5.0, 5.0), "junction"),  # T-junction
    ((CORRIDOR, STEM, STEM_DOWN), (5.0, 5.0), "junction"),  # four ways
    ((CORRIDOR,), (1.3, 5.0), "dead_end"),  # 0.3 m from the closed end
    ((CORRIDOR,), (8.5, 5.1), "dead_end"),
    ((ROOM,), (5.0, 5.0), "room"),
    ((ROOM,), (2.7, 5.0), "room"),  # next to a wall
    ((ROOM,), (2.7, 2.7), "room"),  # in a corner
    ((CORRIDOR, ROOM), (5.0, 5.0), "room"),
])
def test_location_classes_on_hand_built_masks(rects, xy, want):
    r = LOC.classify_locations(_grid(*rects), np.array([xy]))
    assert LOC.LOCATION_CLASSES[r["cls"][0]] == want


def test_location_rule_details():
    corridor = _grid(CORRIDOR)
    r = LOC.classify_locations(corridor, np.array([[5.0, 5.0], [5.0, 5.45], [5.0, 7.0], [1.3, 5.0]]))
    assert LOC.LOCATION_CLASSES[r["cls"][0]] == "corridor"
    assert r["width"][0] == pytest.approx(0.8, abs=0.05)  # the corridor's width on the mask
    assert r["sectors"][0] == 2 and r["sectors"][3] == 1
    assert r["lengths"][0, 0] == pytest.approx(2.0) and r["lengths"][0, 4] == pytest.approx(0.4, abs=0.05)
    # 5 cm off the mask: snapped back; 1.6 m away: unknown
    assert r["snapped"][1] and LOC.LOCATION_CLASSES[r["cls"][1]] == "corridor"
    assert r["cls"][2] == LOC.UNKNOWN
    # room labels: a narrow passage inside a bedroom is inside a room; a wide hallway is a corridor
    assert LOC.classify_locations(corridor, np.array([[5.0, 5.0]]), room_labels=["bedroom"])["cls"][0] == LOC.ROOM
    assert LOC.classify_locations(corridor, np.array([[5.0, 5.0]]), room_labels=["hallway"])["cls"][0] == LOC.CORRIDOR
    hall = _grid(ROOM)
    assert LOC.classify_locations(hall, np.array([[5.0, 5.0]]), room_labels=["hallway"])["cls"][0] == LOC.CORRIDOR
    with pytest.raises(ConfigError, match="n_rays"):
        LOC.LocationParams(n_rays=3)
    with pytest.raises(ConfigError, match="mask"):
        LOC.classify_locations(corridor, np.array([[5.0, 5.0]]), mask="walls")


def test_layout_mask_ignores_low_furniture():
    """A 5 m room with a bed (low band) filling a 0.8 m gap to the west wall
    and a wardrobe (tall band) doing the same to the east: on the navigable
    mask both gaps are closed, on the layout mask only the wardrobe's."""
    size = 200
    room = np.full((size, size), -1)
    room[50:150, 50:150] = 0  # x, y in [2.5, 7.5)
    bands = np.zeros((3, size, size), bool)
    bands[0, 60:140, 66:76] = True  # bed: x in [3.3, 3.8)
    bands[2, 60:140, 124:134] = True  # wardrobe: x in [6.2, 6.7)
    r = 0.18
    grid = SimpleNamespace(room=room, bands=bands, config=SimpleNamespace(agent_radius=r), origin=np.zeros(2),
                           resolution=RES)
    lay = LOC.layout_mask(grid)
    blocked = (room < 0) | bands.any(0)
    from scipy import ndimage
    nav = ~ndimage.binary_dilation(blocked, structure=np.ones((9, 9), bool), border_value=1) & (room >= 0)
    grid.navigable = nav
    assert lay[100, 70] and not nav[100, 70]  # on the bed: free in the layout
    assert not lay[100, 128]  # in the wardrobe
    assert not lay[100, 50] and lay[100, 54] and not lay[100, 53]  # 0.18 m agent from the west wall
    assert lay[nav].all()
    auto = LOC.classify_locations(grid, np.array([[3.0, 5.0]]))  # the strip between wall and bed
    narrow = LOC.classify_locations(grid, np.array([[3.0, 5.0]]), mask="navigable")
    assert auto["cls"][0] == LOC.ROOM and narrow["width"][0] < 0.5


def _episodes():
    """Two hand-built episodes (S = 10 planner steps).

    Episode 0 (hard, 8 steps): MOVE x3 along y = 0.5 (1 m each), ASK Type 3
    at step 3, MOVE +y, ASK Type 4 at step 5, a blocked MOVE, STOP.
    Episode 1 (easy, 5 steps): ASK 1 at 0, ASK 2 at 1, MOVE, MOVE, ASK 3 at
    step 4 (the last step: no horizon after it), plus a refused Type 4.
    """
    S = 10
    pose = np.zeros((2, S + 1, 3))
    path0 = [(0.5, 0.5), (1.5, 0.5), (2.5, 0.5), (3.5, 0.5), (3.5, 0.5), (3.5, 1.5), (3.5, 1.5), (3.5, 1.5), (3.5, 1.5)]
    pose[0, :len(path0), :2] = path0
    pose[0, len(path0):, :2] = path0[-1]
    kind = np.full((2, S), -1)
    kind[0, :8] = [0, 0, 0, 1, 0, 1, 0, 2]
    kind[1, :5] = [1, 1, 0, 0, 1]
    question = np.zeros((2, S), int)
    question[0, 3], question[0, 5] = 3, 4
    question[1, 0], question[1, 1], question[1, 4] = 1, 2, 3
    traj = SimpleNamespace(pose=pose, kind=kind, question=question)
    rows = [
        {"agent": "a", "episode_id": "e0", "difficulty": "hard", "steps": 8, "trace": "3@3 4@5"},
        {"agent": "a", "episode_id": "e1", "difficulty": "easy", "steps": 5, "trace": "1@0 2@1 4@2! 3@4"},
    ]
    return traj, rows


def test_events_timing_and_counts():
    traj, rows = _episodes()
    ev = IA.events_from_rows(rows)
    assert list(zip(ev["episode"], ev["type"], ev["step"])) == [(0, 3, 3), (0, 4, 5), (1, 1, 0), (1, 2, 1), (1, 3, 4)]
    np.testing.assert_array_equal(ev["steps_used"], [8, 5])
    np.testing.assert_array_equal(ev["difficulty"], [2, 0])
    assert len(IA.events_from_rows(rows, include_refused=True)["type"]) == 6
    evt = IA.events_from_trajectory(traj, difficulty=[2, 0])
    np.testing.assert_array_equal(evt["steps_used"], [8, 5])
    assert sorted(zip(evt["episode"], evt["type"], evt["step"])) == sorted(zip(ev["episode"], ev["type"], ev["step"]))
    with pytest.raises(InputError, match="agent"):
        IA.events_from_rows(rows + [dict(rows[0], agent="b")])

    t = IA.question_timing(ev, bins=10)
    # progress = step / steps used: 3/8, 5/8 in episode 0; 0/5, 1/5, 4/5 in episode 1
    np.testing.assert_allclose(np.sort(t["progress"]), [0.0, 0.2, 0.375, 0.625, 0.8])
    want = np.zeros((4, 10), int)
    want[0, 0] = want[1, 2] = want[2, 3] = want[2, 8] = want[3, 6] = 1
    np.testing.assert_array_equal(t["counts"], want)
    np.testing.assert_allclose(t["share"][2, [3, 8]], [0.5, 0.5])
    np.testing.assert_allclose(t["episodes_with_type"], [0.5, 0.5, 1.0, 0.5])

    q = IA.questions_per_difficulty(IA.counts_from_events(ev), ev["difficulty"])
    np.testing.assert_allclose(q["mean_per_type"][0], [1, 1, 1, 0])
    np.testing.assert_allclose(q["mean_per_type"][2], [0, 0, 1, 1])
    assert np.isnan(q["mean_per_type"][1]).all()
    np.testing.assert_allclose(q["mean_total"][[0, 2]], [3, 2])
    np.testing.assert_array_equal(q["count"], [1, 0, 1])
    two = IA.questions_per_difficulty(np.stack([IA.counts_from_events(ev)] * 2), ev["difficulty"], [[1, 1], [1, 0]])
    np.testing.assert_array_equal(two["count"], [[1, 0, 1], [0, 0, 1]])


def test_explored_area_and_delta_u_by_hand():
    # 1 m cells, r = 0.5: only the cells whose centre the path crosses count
    assert IA.explored_area([[0.5, 0.5]], r=0.5, cell=1.0) == 1.0
    assert IA.explored_area([[0.5, 0.5], [3.5, 0.5]], r=0.5, cell=1.0) == 4.0
    # fine cells approach the capsule area 2 r L + pi r^2
    assert IA.explored_area([[0.0, 0.0], [3.0, 0.0]], r=1.0, cell=0.02) == pytest.approx(6 + math.pi, rel=0.01)

    traj, rows = _episodes()
    ev = IA.events_from_rows(rows)
    du = IA.delta_u(traj.pose, ev, h=3, r=0.5, cell=1.0)
    # episode 0: horizon min(3, 3, 8 - 1 - 3) = 3; before: (0.5,0.5)->(3.5,0.5) covers 4 cells,
    # after: (3.5,0.5)->(3.5,1.5) covers 2 cells -> Delta-U = (4 - 2) / 4
    # episode 1: asked at the last step, horizon 0 -> left out
    np.testing.assert_array_equal(du["horizon"], [3, 0])
    np.testing.assert_allclose(du["area_before"][:1], [4.0])
    np.testing.assert_allclose(du["area_after"][:1], [2.0])
    assert du["delta_u"][0] == pytest.approx(0.5) and np.isnan(du["delta_u"][1])
    np.testing.assert_array_equal(du["count"], [0, 0, 1])
    assert du["mean"][2] == pytest.approx(0.5) and np.isnan(du["mean"][0])
    assert du["mean_all"] == pytest.approx(0.5) and du["n_kept"] == 1
    # a shorter horizon: before = (2.5,.5)->(3.5,.5) (2 cells), after = (3.5,.5)->(3.5,1.5) (2 cells)
    assert IA.delta_u(traj.pose, ev, h=1, r=0.5, cell=1.0)["delta_u"][0] == pytest.approx(0.0)
    with pytest.raises(ConfigError, match="delta_u.h"):
        IA.delta_u(traj.pose, ev, h=0)


def test_type3_locations_over_several_grids():
    traj, rows = _episodes()
    ev = IA.events_from_rows(rows)
    pose = traj.pose.copy()
    pose[0, 3, :2] = (5.0, 5.0)  # episode 0 asks at a T-junction
    pose[1, 4, :2] = (5.0, 5.0)  # episode 1 inside an open room
    grids = [_grid(CORRIDOR, STEM), _grid(ROOM)]
    r = LOC.type3_locations(grids, pose, ev, scene_index=[0, 1])
    np.testing.assert_array_equal(r["cls"], [LOC.JUNCTION, LOC.ROOM])
    np.testing.assert_array_equal(r["counts"], [0, 1, 0, 1])
    np.testing.assert_allclose(r["fractions"], [0, 0.5, 0, 0.5])
    assert r["counts_by_difficulty"][2, LOC.JUNCTION] == 1 and r["counts_by_difficulty"][0, LOC.ROOM] == 1
    with pytest.raises(InputError, match="scene_index"):
        LOC.type3_locations(grids, pose, ev)


def test_plots_write_pngs(tmp_path):
    rng = np.random.default_rng(6)
    success, n, valid, diff = _random_outcomes(rng, A=3, E=30)
    res = CS.run_study(success, n, valid, CS.cost_samples(500, seed=1), bins=8)
    factors, succ, alphas, thresholds = _ordering_case()
    abl = DA.ablate(factors, succ, None, DA.alpha_grid(0.25), DA.threshold_grid(0.25))
    cal = DA.calibrate(factors, 1 - succ, None, DA.alpha_grid(0.25))
    traj, rows = _episodes()
    ev = IA.events_from_rows(rows)
    loc = LOC.type3_locations(_grid(CORRIDOR), traj.pose, ev)
    calls = [
        (CF.plot_marginal_wsr, res), (CF.plot_flip_map, res), (DA.plot_ordering, abl), (DA.plot_calibration, cal),
        (IP.plot_question_timing, IA.question_timing(ev)), (IP.plot_location_classes, loc),
        (IP.plot_questions_per_difficulty, IA.questions_per_difficulty(IA.counts_from_events(ev), ev["difficulty"])),
        (IP.plot_delta_u, IA.delta_u(traj.pose, ev, h=3)),
    ]
    for i, (fn, result) in enumerate(calls):
        path = tmp_path / "figs" / f"{fn.__name__}.png"
        assert fn(result, path) == path
        assert path.read_bytes()[:8] == PNG, fn.__name__
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == sorted(f"{fn.__name__}.png" for fn, _ in calls)


def test_the_cost_arithmetic_imports_no_matplotlib():
    """The sweep's configuration check and the bench import the cost study's
    arithmetic; matplotlib (about half a second to import) comes only with its
    figures (ignjax.studies.cost_figures)."""
    code = ("import sys, ignjax.config, ignjax.studies.cost_sensitivity, ignjax.bench.rollouts; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'matplotlib'))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
    code = "import sys, ignjax.studies.cost_figures; print('matplotlib.figure' in sys.modules)"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.stdout.strip() == "True", proc.stderr
