"""The report's figures, checked as figures: each kind is drawn from small
arrays, written as a non-empty PNG (the same bytes twice), and its
matplotlib objects carry the expected titles, labels and ticks, with every
legend outside the axes it explains and the marks above the map's
furniture. Pixels are never compared."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from ignjax.scenes.viz.mapplot import FAMILY_NAMES, category_family, plot_scene_map, save_figure
from ignjax.studies import cost_figures as CF
from ignjax.studies import cost_sensitivity as CS
from ignjax.studies import interaction_plots as IP
from ignjax.studies import locations as LOC
from ignjax.sweep.in_loop import InLoopRuns, in_loop_figure
from ignjax.sweep.trajectories import MARK_Z, AgentPath, pick_episodes, trajectory_figure

PNG = b"\x89PNG\r\n\x1a\n"


def _renderer(fig):
    if fig.canvas is None or not hasattr(fig.canvas, "get_renderer"):
        FigureCanvasAgg(fig)
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def _assert_outside(fig, legend, axes) -> None:
    """``legend``'s box lies inside the figure (nothing cut) and meets none of ``axes``' boxes."""
    assert legend is not None
    r = _renderer(fig)
    box = legend.get_window_extent(r)
    f = fig.bbox
    assert f.x0 - 0.5 <= box.x0 and box.x1 <= f.x1 + 0.5 and f.y0 - 0.5 <= box.y0 and box.y1 <= f.y1 + 0.5
    for ax in axes:
        a = ax.get_window_extent(r)
        overlap = min(box.x1, a.x1) - max(box.x0, a.x0) > 0.5 and min(box.y1, a.y1) - max(box.y0, a.y0) > 0.5
        assert not overlap, (legend.get_texts()[0].get_text(), ax.get_title())


def _written(make, path) -> bytes:
    """Write the figure ``make()`` returns, twice: a non-empty PNG, the same bytes both times."""
    save_figure(make(), path)
    data = path.read_bytes()
    assert data[:8] == PNG and len(data) > 5_000
    save_figure(make(), path.with_name("again.png"))
    assert path.with_name("again.png").read_bytes() == data
    return data


def _labels(legend) -> list[str]:
    return [t.get_text() for t in legend.get_texts()]


# ---------------------------------------------------------------------------
# trajectories
# ---------------------------------------------------------------------------


def _runs() -> list[AgentPath]:
    xy = np.array([[1.0, 1.0], [2.0, 1.0], [3.0, 1.5], [4.5, 2.0], [6.0, 2.0], [7.5, 1.5]])
    q = np.array([0, 3, 0, 1, 0])
    return [AgentPath("eig", xy, q, True, 0.42, 1.5, 1),  # the Type-1 question was refused: one charged
            AgentPath("explorer", xy[:4], np.zeros(3, int), False, 4.2, 1.5, 0),
            AgentPath("shortest_path", xy[[0, 3, 5]], np.zeros(2, int), True, 0.3, 1.5, 0)]


def test_trajectory_figure_draws_every_agent_on_the_same_map(two_room_scene, tmp_path):
    record = {"episode_id": "two_rooms/chair_2/0", "difficulty": "medium", "target_id": "chair_2",
              "target_category": "chair"}
    fig = trajectory_figure(two_room_scene, record, _runs())
    maps = [ax for ax in fig.axes if ax.get_aspect() == 1.0 and ax.axison]
    assert [ax.get_title().split("\n")[0] for ax in maps] == ["eig", "explorer", "shortest_path"]
    assert "success: 0.42 m from the target (<= 1.5 m), 1 question" in maps[0].get_title()
    assert maps[1].get_title().endswith("failure: 4.20 m from the target (<= 1.5 m), 0 questions")
    assert "two_rooms/chair_2/0" in fig._suptitle.get_text() and "medium" in fig._suptitle.get_text()
    colorbars = [ax for ax in fig.axes if "planner step" in ax.get_xlabel()]
    assert len(colorbars) == 1
    [legend] = fig.legends
    assert {"start", "end (final pose)", "target", "same-category distractor", "Type 3 route asked"} <= set(_labels(legend))
    _assert_outside(fig, legend, maps)
    for ax in maps:
        assert ax.get_xlabel() == "x (m)" and ax.get_ylabel() == "y (m)"
        rooms = {t.get_text() for t in ax.texts}
        assert {"living room", "bedroom"} <= rooms  # room labels on the map
        furniture = max(p.get_zorder() for p in ax.patches)
        marks = [ln for ln in ax.lines if ln.get_marker() in ("*", "o", "s", "^", "D")]
        stars = [ln for ln in marks if ln.get_marker() == "*"]
        assert len(stars) == 2  # target and its same-category distractors
        assert min(ln.get_zorder() for ln in marks) >= MARK_Z > furniture
        assert len(ax.collections) >= 1 and ax.collections[-1].get_array() is not None  # path coloured by step
    _written(lambda: trajectory_figure(two_room_scene, record, _runs()), tmp_path / "trajectory.png")


def test_pick_episodes_spreads_difficulties_and_houses_deterministically():
    diffs = ["easy", "medium", "hard"] * 6
    houses = [i % 5 for i in range(18)]
    a = pick_episodes(diffs, houses, 4, seed=0)
    assert a == pick_episodes(diffs, houses, 4, seed=0)
    assert [diffs[i] for i in a] == ["easy", "medium", "hard", "easy"]
    assert len({houses[i] for i in a}) == 4
    assert len(pick_episodes(diffs, houses, 40, seed=1)) == 18
    assert any(pick_episodes(diffs, houses, 3, seed=s) != a[:3] for s in range(1, 6))


# ---------------------------------------------------------------------------
# costs
# ---------------------------------------------------------------------------


def _in_loop(rng) -> InLoopRuns:
    labels = ("all x0.25", "all x1", "all x4", "Type 1 x4", "Type 2 x4", "Type 3 x4", "Type 4 x4")
    K, E = len(labels), 40
    nq = rng.integers(0, 3, (K, E, 4))
    succ = rng.random((K, E)) < 0.4
    disc = np.exp(-0.2 * nq.sum(-1))
    return InLoopRuns("eig", labels, (0.25, 1.0, 4.0), 4.0, nq, succ, disc, 1.5, {"explorer": 0.2})


def test_in_loop_figure_labels_the_scales_and_draws_every_setting(tmp_path):
    fig = in_loop_figure(_in_loop(np.random.default_rng(0)))
    axes = [ax for ax in fig.axes]
    assert [ax.get_title()[:3] for ax in axes] == ["(a)", "(b)", "(c)", "(d)"]
    for ax in axes[:2]:
        assert ax.get_xscale() == "log"
        assert [t.get_text() for t in ax.get_xticklabels()] == ["0.25", "1", "4"]
        assert len(ax.xaxis.get_minorticklocs()) == 0  # no piled-up minor labels
        assert ax.get_xlabel().startswith("cost scale")
    assert [t.get_text() for t in axes[3].get_xticklabels()] == ["Type 1 x4", "Type 2 x4", "Type 3 x4", "Type 4 x4"]
    assert axes[0].get_ylabel().startswith("questions per episode")
    assert axes[1].get_ylabel() == "rate over the episodes (%)"
    for ax in (axes[1], axes[3]):
        assert any(label.startswith("explorer") for label in _labels(ax.get_legend()))
    for ax in axes:
        _assert_outside(fig, ax.get_legend(), axes)
    _written(lambda: in_loop_figure(_in_loop(np.random.default_rng(0))), tmp_path / "in_loop.png")
    fig = in_loop_figure(InLoopRuns(**{**_in_loop(np.random.default_rng(0)).__dict__, "factor": 0.0}))
    assert len(fig.axes) == 2  # no per-type settings: the top row only


def _offline(rng, A=3, E=50):
    success = rng.random((A, E)) < np.array([0.2, 0.3, 0.9])[:, None]
    n = rng.integers(0, 3, (A, E, 4))
    n[2] = 0  # the third agent asks nothing
    return success, n


def test_wsr_standard_error_matches_the_episode_values():
    rng = np.random.default_rng(3)
    success, n = _offline(rng)
    costs = CS.cost_samples(20, seed=2)
    wsr = CS.offline_wsr(success, n, None, costs)
    se = CS.wsr_standard_error(success, n, None, costs, wsr)
    for k in (0, 7):
        x = success * np.exp(-(n * costs[k]).sum(-1))  # (A, E) per-episode values
        np.testing.assert_allclose(se[k], x.std(1, ddof=1) / np.sqrt(x.shape[1]), rtol=1e-3, atol=1e-6)


def test_marginal_wsr_zooms_on_the_asking_agents_with_bands(tmp_path):
    rng = np.random.default_rng(4)
    success, n = _offline(rng)
    res = CS.run_study(success, n, None, CS.cost_samples(400, seed=1), agent_names=["a", "b", "silent"], bins=8)
    assert res["marginals"]["se"].shape == (4, 8, 3) and res["asks"].tolist() == [True, True, False]
    fig = CF.marginal_wsr_figure(res)
    axes = fig.axes
    assert [ax.get_title() for ax in axes] == ["Type 1 appearance", "Type 2 region", "Type 3 route",
                                               "Type 4 confirmation"]
    lo, hi = axes[0].get_ylim()
    assert hi - lo < 60 and hi < 90  # not 0..100: the silent agent's 90 % sits off the axis
    assert all(ax.get_ylim() == (lo, hi) for ax in axes)  # one y scale
    assert all(len(ax.collections) == 2 for ax in axes)  # a 95 % band per asking agent
    [legend] = fig.legends
    labels = _labels(legend)
    assert any(lab.startswith("silent:") and "off the axis" in lab for lab in labels)
    assert "locked cost" in labels
    _assert_outside(fig, legend, axes)
    assert axes[0].get_ylabel().startswith("mean WSR")
    _written(lambda: CF.marginal_wsr_figure(res), tmp_path / "marginal.png")


# ---------------------------------------------------------------------------
# interaction
# ---------------------------------------------------------------------------


def test_delta_u_figure_states_the_plotted_formula(tmp_path):
    du = {"delta_u": np.array([0.2, -0.1, 0.3, np.nan, -0.4]), "difficulty": np.array([0, 0, 1, 1, 2]),
          "count": np.array([2, 1, 1]), "h": 5, "r": 1.0}
    fig = IP.delta_u_figure(du)
    ax = fig.axes[0]
    assert ax.get_ylabel() == IP.DELTA_U_LABEL == "ΔU = (A_before − A_after) / A_before (%)"
    assert "ΔU" in ax.get_title() and "reduction" not in ax.get_title()
    assert [t.get_text() for t in ax.get_xticklabels()] == ["easy\n(n=2 questions)", "medium\n(n=1 questions)",
                                                            "hard\n(n=1 questions)"]
    heights = [p.get_height() for p in ax.patches]
    np.testing.assert_allclose(heights, [5.0, 30.0, -40.0])
    _written(lambda: IP.delta_u_figure(du), tmp_path / "delta_u.png")


def test_location_figure_shows_the_base_rate_and_no_blank_panel(tmp_path):
    loc = {"counts": np.array([3, 1, 0, 6]), "fractions": np.array([0.3, 0.1, 0.0, 0.6]), "n_unknown": 0}
    steps = {"counts": np.array([10, 5, 5, 80]), "fractions": np.array([0.1, 0.05, 0.05, 0.8])}
    na = {"applicable": False, "reason": "`eig` writes no question text"}
    fig = IP.location_classes_figure(loc, content=na, steps=steps)
    assert len(fig.axes) == 1
    ax = fig.axes[0]
    assert any("base rate" in lab for lab in _labels(ax.get_legend()))
    assert ax.get_xticklabels()[0].get_text() == "corridor\n3 q. / 10 steps"
    assert not fig.texts and all(a.axison for a in fig.axes)  # no blank half
    _assert_outside(fig, ax.get_legend(), fig.axes)
    _written(lambda: IP.location_classes_figure(loc, content=na, steps=steps), tmp_path / "loc.png")
    content = {"applicable": True, "fractions": np.array([0.5, 0.25, 0.25]), "counts": np.array([2, 1, 1, 0]),
               "n_without_text": 0}
    assert len(IP.location_classes_figure(loc, content=content, steps=steps).axes) == 2


def test_step_locations_count_every_step_used():
    grid = type("G", (), {})()
    grid.navigable = np.zeros((200, 200), bool)
    grid.navigable[50:150, 50:150] = True  # a 5 m square room
    grid.origin, grid.resolution, grid.room = np.zeros(2), 0.05, np.where(grid.navigable, 0, -1)
    poses = np.full((2, 6, 3), 5.0)
    r = LOC.step_locations(grid, poses, np.array([5, 2]))
    assert r["n"] == 7 and r["counts"].tolist() == [0, 0, 0, 7] and r["fractions"][3] == 1.0


def test_question_figures_keep_legends_off_the_bars(tmp_path):
    qpd = {"mean_per_type": np.array([[0.4, 0.0, 0.8, 0.2], [0.6, 0.1, 0.9, 0.3], [0.5, 0.1, 1.0, 0.3]]),
           "mean_total": np.array([1.4, 1.9, 1.9]), "count": np.array([5, 6, 4])}
    timing = {"edges": np.linspace(0, 1, 11), "share": np.full((4, 10), 0.1), "n": np.array([3, 0, 5, 2])}
    for fig, ylabel in ((IP.questions_per_difficulty_figure(qpd), "questions per episode"),
                        (IP.question_timing_figure(timing), "share of the type's questions (%)")):
        ax = fig.axes[0]
        assert ax.get_ylabel() == ylabel
        _assert_outside(fig, ax.get_legend(), fig.axes)
    _written(lambda: IP.question_timing_figure(timing), tmp_path / "timing.png")


# ---------------------------------------------------------------------------
# house map, benchmark statistics, catalogue
# ---------------------------------------------------------------------------


def test_map_legend_lists_families_outside_the_map(two_room_scene, tmp_path):
    fig = plot_scene_map(two_room_scene)
    ax = fig.axes[0]
    labels = _labels(ax.get_legend())
    fams = {category_family(i.category) for i in two_room_scene.objects}
    assert fams == {"seating", "tables", "storage", "wall", "small"}
    assert [lab.rsplit(" (", 1)[0] for lab in labels[:len(fams)]] == [FAMILY_NAMES[f] for f in FAMILY_NAMES if f in fams]
    assert "seating (3)" in labels  # three chairs
    assert len(labels) <= len(FAMILY_NAMES) + 4
    _assert_outside(fig, ax.get_legend(), [ax])
    assert category_family("no_such_category") == "other"
    _written(lambda: plot_scene_map(two_room_scene), tmp_path / "map.png")


def test_statistics_figure_bars_side_by_side(tmp_path):
    from ignjax.episodes.stats import statistics_figure

    rng = np.random.default_rng(0)

    def summary(n):
        return {"episodes": n, "per_bin": {"easy": n // 3, "medium": n // 3, "hard": n - 2 * (n // 3)},
                "distractors": {"values": rng.integers(0, 6, n).tolist()},
                "difficulty_score": {"values": rng.random(n).tolist()},
                "start_distance": {"values": (3 + 10 * rng.random(n)).tolist()},
                "per_category": {"chair": 5, "cup": 3}, "per_room": {"kitchen": 4, "bedroom": 2}}

    fig = statistics_figure(summary(90), summary(30), tmp_path / "stats.png")
    assert (tmp_path / "stats.png").read_bytes()[:8] == PNG
    [legend] = fig.legends  # one legend for every panel, above them
    assert _labels(legend) == ["corpus (90 episodes)", "subset (30 episodes)"]
    _assert_outside(fig, legend, fig.axes)
    for ax in fig.axes[1], fig.axes[2], fig.axes[4]:
        assert ax.get_ylabel() == "share of the set's episodes (%)"
        assert all(p.get_alpha() in (None, 1.0) for p in ax.patches)  # nothing translucent, no blended colour
        spans = sorted((round(p.get_x(), 9), round(p.get_x() + p.get_width(), 9)) for p in ax.patches)
        assert all(b[0] >= a[1] - 1e-9 for a, b in zip(spans, spans[1:]))  # no bar over another
        assert ax.get_legend() is None
        sums = {}
        for p in ax.patches:
            sums[p.get_facecolor()] = sums.get(p.get_facecolor(), 0.0) + p.get_height()
        assert all(s == pytest.approx(100.0) for s in sums.values())


def test_catalogue_captions_wrap_instead_of_being_cut():
    from PIL import Image, ImageDraw

    from ignjax.scenes.viz import gallery

    font = gallery._caption_font(96)
    draw = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    lines = gallery.wrap_caption(draw, "laundry basket (empty)\n52 cm", font, 92)
    assert len(lines) >= 3 and " ".join(lines[:-1]) == "laundry basket (empty)" and lines[-1] == "52 cm"
    assert all(draw.textlength(line, font=font) <= 92 for line in lines)
    tiles = [("washing machine (closed)\n85 cm", np.zeros((96, 96, 3), np.uint8))] * 3
    plain = gallery.compose(tiles, 96)
    titled = gallery.compose(tiles, 96, title="Object catalogue: 1 category")
    assert titled.size[0] == plain.size[0] and titled.size[1] > plain.size[1]
