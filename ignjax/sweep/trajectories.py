"""Top-down trajectory figures of a sweep run: one figure per episode, every
evaluated agent in its own panel on the same map.

:func:`pick_episodes` chooses the episodes (difficulties in turn, each from a
house not drawn yet, in an order shuffled by the run's seed);
:func:`trajectory_figure` draws one episode: the house map with room labels,
each agent's path coloured by planner step (one shared colour bar) with
arrows giving the direction, start and end marks, where each question type
was asked, the target and its same-category distractors on top of the
furniture, and the outcome in each panel's title; the legend and colour bar
sit outside the maps. :func:`plot_trajectories` writes the figures of a run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.colors import ListedColormap, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from ignjax.protocol import BIN_NAMES, TYPE_LABELS
from ignjax.scenes import vocab
from ignjax.scenes.viz.mapplot import plot_scene_map, save_figure

QUESTION_STYLE = {1: ("o", "tab:purple"), 2: ("s", "tab:orange"), 3: ("^", "tab:red"), 4: ("D", "tab:cyan")}
"""Marker and colour of the pose where each question type was asked."""

TIME_CMAP = ListedColormap(colormaps["viridis"](np.linspace(0.0, 0.85, 256)), name="viridis_dark")
"""Colour map of the path along the planner steps (viridis without its palest yellows, which vanish on the light
room fills)."""

MARK_Z = 20
"""Lowest z-order of the marks drawn on the map (above every footprint, highlight and room label of
:func:`~ignjax.scenes.viz.mapplot.plot_scene_map`)."""

PANEL_WIDTH = 3.4
"""Width of one map panel, inches."""


@dataclass(frozen=True)
class AgentPath:
    """One agent's episode, as drawn.

    Attributes:
        agent: the agent's name.
        xy: (M + 1, 2) positions: the start and after each of the M planner steps used.
        questions: (M,) question type asked at each step (0: none); asked at ``xy[step]``.
        success: the episode succeeded (at ``threshold``).
        final_distance: the final distance to the target, m.
        threshold: the success threshold, m.
        n_questions: the questions charged (the outcome's count: a refused question is marked but not counted).
    """

    agent: str
    xy: np.ndarray
    questions: np.ndarray
    success: bool
    final_distance: float
    threshold: float
    n_questions: int


def pick_episodes(difficulties, houses, n: int, seed: int) -> list[int]:
    """``n`` episode indices (fewer if there are fewer episodes): the k-th
    has difficulty ``BIN_NAMES[k % 3]`` and a house not picked yet while the
    file has one, taken in an order shuffled by ``seed``."""
    order = [int(i) for i in np.random.default_rng(seed).permutation(len(difficulties))]
    chosen: list[int] = []
    for k in range(min(n, len(order))):
        want, used = BIN_NAMES[k % 3], {houses[i] for i in chosen}
        rules = (lambda i: difficulties[i] == want and houses[i] not in used, lambda i: houses[i] not in used,
                 lambda i: difficulties[i] == want, lambda i: True)
        left = [i for i in order if i not in chosen]
        chosen.append(next(i for rule in rules for i in left if rule(i)))
    return chosen


def _path_colors(ax, xy: np.ndarray, norm: Normalize):
    """The path as segments coloured by step, with arrowheads along it."""
    cmap = TIME_CMAP
    if len(xy) < 2:
        return
    seg = np.stack([xy[:-1], xy[1:]], 1)
    moved = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1) > 1e-6
    lc = LineCollection(seg[moved], cmap=cmap, norm=norm, linewidths=2.2, zorder=MARK_Z, capstyle="round")
    lc.set_array(np.arange(len(seg))[moved] + 0.5)
    ax.add_collection(lc)
    steps = np.nonzero(moved)[0]
    for s in steps[len(steps) // 8::max(1, len(steps) // 4)]:
        a, b = xy[s], xy[s + 1]
        ax.annotate("", xy=tuple(b), xytext=tuple((a + b) / 2), zorder=MARK_Z + 1,
                    arrowprops={"arrowstyle": "-|>", "color": cmap(norm(s + 0.5)), "lw": 0, "mutation_scale": 14,
                                "shrinkA": 0, "shrinkB": 0})


def _draw_run(ax, run: AgentPath, norm: Normalize) -> None:
    xy = np.asarray(run.xy, np.float64)
    _path_colors(ax, xy, norm)
    ax.plot(*xy[0], "o", ms=9, mfc="white", mec="black", mew=1.5, zorder=MARK_Z + 2)
    ax.plot(*xy[-1], "s", ms=10, mfc="none", mec="black", mew=1.8, zorder=MARK_Z + 4)
    q = np.asarray(run.questions)
    for t, (m, c) in QUESTION_STYLE.items():
        at = np.nonzero(q == t)[0]
        if len(at):
            ax.plot(xy[at, 0], xy[at, 1], m, ms=7, color=c, mec="black", mew=0.8, ls="none", zorder=MARK_Z + 5)
    outcome = "success" if run.success else "failure"
    ax.set_title(f"{run.agent}\n{outcome}: {run.final_distance:.2f} m from the target "
                 f"(<= {run.threshold:g} m), {run.n_questions} question{'s' if run.n_questions != 1 else ''}",
                 fontsize=8)


def _draw_goal(ax, scene, target_id: str) -> None:
    by_id = {inst.id: inst for inst in scene.instances}
    tgt = by_id.get(target_id)
    if tgt is None:
        return
    same = [x for x in scene.instances if x.category == tgt.category and x.id != tgt.id]
    if same:
        ax.plot([x.position[0] for x in same], [x.position[1] for x in same], "*", ms=13, color="silver", mec="black",
                mew=0.8, ls="none", zorder=MARK_Z + 3)
    ax.plot(tgt.position[0], tgt.position[1], "*", ms=17, color="gold", mec="black", mew=0.9, zorder=MARK_Z + 3)


def legend_handles() -> list:
    """The marks of a trajectory figure, for its legend."""
    h = [Line2D([], [], color=TIME_CMAP(0.6), lw=2.2, label="path: planner-step poses joined (colour: step)"),
         Line2D([], [], marker="o", ms=9, mfc="white", mec="black", mew=1.5, ls="none", label="start"),
         Line2D([], [], marker="s", ms=10, mfc="none", mec="black", mew=1.8, ls="none", label="end (final pose)"),
         Line2D([], [], marker="*", ms=17, color="gold", mec="black", ls="none", label="target"),
         Line2D([], [], marker="*", ms=13, color="silver", mec="black", ls="none",
                label="same-category distractor")]
    h += [Line2D([], [], marker=m, ms=7, color=c, mec="black", ls="none", label=f"{TYPE_LABELS[t - 1]} asked")
          for t, (m, c) in QUESTION_STYLE.items()]
    return h


def trajectory_figure(scene, record: dict, runs: list[AgentPath]) -> Figure:
    """One episode, one panel per agent on the same map (``record``: the
    episode's record: ``episode_id``, ``difficulty``, ``target_id``,
    ``target_category``)."""
    lo, hi = scene.bounds()
    w, h = max(float(hi[0] - lo[0]), 1.0), max(float(hi[1] - lo[1]), 1.0)
    ncols = min(len(runs), 2 if w > 1.5 * h else 3)
    nrows = math.ceil(len(runs) / ncols)
    panel_h = PANEL_WIDTH * min(h / w, 2.2) + 0.6
    fig = Figure(figsize=(PANEL_WIDTH * ncols + 0.4, panel_h * nrows + 1.9), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False)
    steps = max([len(r.xy) - 1 for r in runs] + [1])
    norm = Normalize(0, steps)
    for k, ax in enumerate(axes.flat):
        if k >= len(runs):
            ax.set_axis_off()
            continue
        plot_scene_map(scene, ax=ax, show_labels=True, legend=False)
        _draw_goal(ax, scene, record["target_id"])
        _draw_run(ax, runs[k], norm)
        ax.tick_params(labelsize=7)
        ax.xaxis.label.set_fontsize(8)
        ax.yaxis.label.set_fontsize(8)
    cb = fig.colorbar(_mappable(norm), ax=axes.ravel().tolist(), orientation="horizontal", location="bottom",
                      fraction=0.04, aspect=40, pad=0.02)
    cb.set_label("planner step along the path (arrows: direction of travel)", fontsize=8)
    cb.ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    cb.ax.tick_params(labelsize=7)
    fig.legend(handles=legend_handles(), loc="outside lower center", ncol=3, fontsize=7, frameon=False)
    category = vocab.category_display(record.get("target_category", "")) if record.get("target_category") else "?"
    fig.suptitle(f"{record['episode_id']}: {record['difficulty']} episode, target a {category}", fontsize=10)
    return fig


def _mappable(norm: Normalize):
    from matplotlib.cm import ScalarMappable

    return ScalarMappable(norm=norm, cmap=TIME_CMAP)


def agent_paths(tree: dict, index: int, agent: str, success: bool, threshold: float) -> AgentPath:
    """Episode ``index`` of one agent's rollout (``tree``: ``traj`` with ``pose``, ``kind``, ``question``;
    ``out`` with ``final_distance`` and ``n_questions``)."""
    kind = np.asarray(tree["traj"]["kind"][index])
    used = int((kind >= 0).sum())
    pose = np.asarray(tree["traj"]["pose"][index])
    return AgentPath(agent, pose[: used + 1, :2], np.asarray(tree["traj"]["question"][index])[:used], bool(success),
                     float(np.asarray(tree["out"]["final_distance"])[index]), float(threshold),
                     int(np.asarray(tree["out"]["n_questions"])[index].sum()))


def plot_trajectories(es, rollouts: dict, success: dict, n: int, folder: Path, seed: int,
                      threshold: float) -> list[tuple[Path, dict]]:
    """``trajectory_<k>.png`` for :func:`pick_episodes`' ``n`` episodes of
    ``es``, one panel per agent of ``rollouts`` (``success``: agent -> (E,)
    bool at ``threshold``); returns each figure's path with its episode record."""
    if n <= 0 or not rollouts:
        return []
    scene_of = np.asarray(es.specs.scene)
    picked = pick_episodes([r["difficulty"] for r in es.records], [int(s) for s in scene_of], n, seed)
    paths = []
    for k, i in enumerate(picked):
        runs = [agent_paths(tree, i, name, success[name][i], threshold) for name, tree in rollouts.items()]
        fig = trajectory_figure(es.bank.scene(int(scene_of[i])), es.records[i], runs)
        paths.append((save_figure(fig, folder / f"trajectory_{k}.png", dpi=110), es.records[i]))
    return paths


__all__ = ["AgentPath", "MARK_Z", "QUESTION_STYLE", "TIME_CMAP", "agent_paths", "legend_handles", "pick_episodes",
           "plot_trajectories", "trajectory_figure"]
