"""The figure of the in-the-loop cost study (``costs_in_loop.png``): one
agent re-run with every cost vector it is charged (:func:`ignjax.sweep.report.in_loop_costs`).

Top row, all costs scaled together (log axis, ticks at the scales run):
(a) questions per episode per type and in all; (b) SR and WSR, with 95 %
intervals over episodes and the ``explorer`` (an agent that asks nothing,
so its WSR is its SR) as a reference line. Bottom row, one type's cost
multiplied (when the run has those settings): (c) that type's questions
next to the same type's under the locked costs; (d) SR and WSR of each.
Every legend sits outside its axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.ticker import FixedLocator, NullLocator

from ignjax.protocol import TYPE_LABELS
from ignjax.studies._common import new_figure

TYPE_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
"""Colour of each question type."""

Z95 = 1.96


@dataclass(frozen=True)
class InLoopRuns:
    """The in-the-loop rollouts, as drawn.

    Attributes:
        agent: the agent re-run.
        labels: (K,) setting names (``all x<s>`` then ``Type <t> x<f>``).
        scales: the S scales of the first S settings (all costs x scale).
        factor: the per-type factor of the remaining settings (0: none).
        n_questions: (K, E, 4) questions per type.
        success: (K, E) bool at ``threshold``.
        discount: (K, E) exp(-w . n) under each setting's own costs.
        threshold: the success threshold, m.
        reference: agent -> SR (0..1) at ``threshold`` of an agent that asks nothing (drawn as a line).
    """

    agent: str
    labels: tuple[str, ...]
    scales: tuple[float, ...]
    factor: float
    n_questions: np.ndarray
    success: np.ndarray
    discount: np.ndarray
    threshold: float
    reference: dict


def _mean_ci(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean over the last axis and the half-width of its 95 % normal interval."""
    x = np.asarray(x, np.float64)
    n = x.shape[-1]
    return x.mean(-1), Z95 * x.std(-1, ddof=1) / np.sqrt(n) if n > 1 else np.zeros(x.shape[:-1])


def _scale_axis(ax, scales) -> None:
    ax.set_xscale("log")
    ax.xaxis.set_major_locator(FixedLocator(list(scales)))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.set_xticklabels([f"{s:g}" for s in scales])
    ax.set_xlabel("cost scale s (every type's cost = s x locked cost)")
    ax.grid(alpha=0.3)


def _legend_right(ax, **kw) -> None:
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=8, frameon=False, **kw)


def _references(ax, runs: InLoopRuns) -> None:
    for name, sr in runs.reference.items():
        ax.axhline(100 * sr, color="0.35", ls=":", lw=1.5, label=f"{name} (asks nothing: WSR = SR)")


def _rates_panel(ax, runs: InLoopRuns, rows: np.ndarray, x, kind: str) -> None:
    thr = f"{runs.threshold:g}"
    sr, sr_ci = _mean_ci(runs.success[rows].astype(np.float64))
    wsr, wsr_ci = _mean_ci(runs.success[rows] * runs.discount[rows])
    if kind == "line":
        for v, ci, m, lab in ((sr, sr_ci, "o", f"SR@{thr} (band: 95 % interval)"),
                              (wsr, wsr_ci, "s", f"WSR@{thr}, charged costs (band: 95 % interval)")):
            line, = ax.plot(x, 100 * v, marker=m, label=lab)
            ax.fill_between(x, 100 * (v - ci), 100 * (v + ci), color=line.get_color(), alpha=0.2, lw=0)
    else:
        ax.bar(x - 0.18, 100 * sr, 0.36, yerr=100 * sr_ci, capsize=3, label=f"SR@{thr} (bar: 95 % interval)")
        ax.bar(x + 0.18, 100 * wsr, 0.36, yerr=100 * wsr_ci, capsize=3,
               label=f"WSR@{thr}, charged costs (bar: 95 % interval)")
    _references(ax, runs)
    ax.set_ylabel("rate over the episodes (%)")


def in_loop_figure(runs: InLoopRuns):
    """The figure (module doc); returns the matplotlib Figure."""
    n_s = len(runs.scales)
    per_type = runs.factor > 0 and len(runs.labels) >= n_s + 4
    fig, axs = new_figure(2 if per_type else 1, 2, size=(13.0, 8.2 if per_type else 4.2))
    scales = np.asarray(runs.scales, np.float64)
    nq = np.asarray(runs.n_questions, np.float64)
    ax = axs[0, 0]
    for t in range(4):
        m, ci = _mean_ci(nq[:n_s, :, t])
        ax.errorbar(scales, m, yerr=ci, marker="o", capsize=2, color=TYPE_COLORS[t], label=TYPE_LABELS[t])
    m, ci = _mean_ci(nq[:n_s].sum(-1))
    ax.errorbar(scales, m, yerr=ci, marker="s", capsize=2, color="k", label="all types (|Q|)")
    _scale_axis(ax, scales)
    ax.set_ylabel("questions per episode (95 % interval)")
    ax.set_title(f"(a) {runs.agent}: asking as every cost is scaled", fontsize=10)
    _legend_right(ax)
    ax = axs[0, 1]
    _rates_panel(ax, runs, np.arange(n_s), scales, "line")
    _scale_axis(ax, scales)
    ax.set_title(f"(b) {runs.agent}: success under the charged costs", fontsize=10)
    _legend_right(ax)
    if per_type:
        _per_type_panels(axs[1, 0], axs[1, 1], runs, n_s)
    fig.tight_layout()
    return fig


def _per_type_panels(ax_q, ax_r, runs: InLoopRuns, n_s: int) -> None:
    nq = np.asarray(runs.n_questions, np.float64)
    rows = np.arange(n_s, n_s + 4)
    x = np.arange(4)
    locked = [i for i, s in enumerate(runs.scales) if s == 1.0]
    f = f"{runs.factor:g}"
    mine = np.array([_mean_ci(nq[rows[t], :, t]) for t in range(4)])  # (4, 2): mean, interval
    if locked:
        base = np.array([_mean_ci(nq[locked[0], :, t]) for t in range(4)])
        ax_q.bar(x - 0.18, base[:, 0], 0.36, yerr=base[:, 1], capsize=3, color="0.7", label="locked costs (all x1)")
    xs = x + 0.18 if locked else x
    ax_q.bar(xs, mine[:, 0], 0.36, yerr=mine[:, 1], capsize=3, color=[TYPE_COLORS[t] for t in range(4)],
             label=f"that type's cost x{f}, others locked")
    for xi, (m, ci) in zip(xs, mine):
        ax_q.annotate(f"{m:.2f}", (xi, m + ci), xytext=(0, 3), textcoords="offset points", ha="center", fontsize=7)
    ax_q.set_xticks(x, ["{} {}\n{}".format(*TYPE_LABELS[t].split(" ", 2)) for t in range(4)],
                    fontsize=8)
    ax_q.set_xlabel("question type whose cost is raised")
    ax_q.set_ylabel("questions of that type per episode (95 % interval)")
    ax_q.set_title(f"(c) {runs.agent}: asking when one type costs x{f}", fontsize=10)
    ax_q.grid(alpha=0.3, axis="y")
    _legend_right(ax_q)
    _rates_panel(ax_r, runs, rows, x.astype(np.float64), "bar")
    if locked:
        k = locked[0]
        ax_r.axhline(100 * runs.success[k].mean(), color="tab:blue", ls="--", lw=1, label="SR, locked costs")
        ax_r.axhline(100 * (runs.success[k] * runs.discount[k]).mean(), color="tab:orange", ls="--", lw=1,
                     label="WSR, locked costs")
    ax_r.set_xticks(x, [f"{TYPE_LABELS[t].split()[0]} {t + 1} x{f}" for t in range(4)], fontsize=8)
    ax_r.set_xlabel("setting (one type's cost raised, others locked)")
    ax_r.set_title(f"(d) {runs.agent}: success when one type costs x{f}", fontsize=10)
    ax_r.grid(alpha=0.3, axis="y")
    _legend_right(ax_r)


__all__ = ["InLoopRuns", "TYPE_COLORS", "in_loop_figure"]
