"""Figures of the interaction analyses (:mod:`ignjax.studies.interaction`).

Each figure has a ``*_figure`` function that returns the matplotlib Figure
(for a notebook, or a test that reads its axes) and a ``plot_*`` function
that writes it as a PNG and returns the path. Legends sit outside the axes;
counts go in the tick labels, not over the bars.
"""

from __future__ import annotations

import os

import numpy as np

from ignjax.errors import InputError
from ignjax.protocol import BIN_NAMES, TYPE_LABELS
from ignjax.studies._common import new_figure, save
from ignjax.studies.interaction import UNCLASSIFIED
from ignjax.studies.locations import LOCATION_CLASSES

TYPE_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
"""Colour of each question type (the same in every figure of the report)."""

Z95 = 1.96


def _legend_right(ax, **kw) -> None:
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=8, frameon=False, **kw)


def question_timing_figure(result: dict, title: str | None = None):
    """Share of each type's questions per progress bin. ``result``: :func:`~ignjax.studies.interaction.question_timing`."""
    e = result["edges"]
    centers = 100 * (e[1:] + e[:-1]) / 2
    fig, axs = new_figure(1, 1, size=(8.5, 4.2))
    ax = axs[0, 0]
    for t in range(4):
        if result["n"][t]:
            ax.plot(centers, 100 * result["share"][t], marker="o", ms=3, color=TYPE_COLORS[t],
                    label=f"{TYPE_LABELS[t]} (n={result['n'][t]})")
    ax.set_xlabel("episode progress when asked (step / steps used, %)")
    ax.set_ylabel("share of the type's questions (%)")
    ax.set_xlim(0, 100)
    ax.grid(alpha=0.3)
    _legend_right(ax)
    ax.set_title(title or "When questions are asked", fontsize=10)
    fig.tight_layout()
    return fig


def plot_question_timing(result: dict, path: str | os.PathLike, title: str | None = None):
    """:func:`question_timing_figure` written to ``path``; returns the path."""
    return save(question_timing_figure(result, title), path)


def location_classes_figure(result: dict, title: str | None = None, content: dict | None = None,
                            steps: dict | None = None):
    """Share of Type-3 questions per location class (``result``:
    :func:`~ignjax.studies.locations.type3_locations`) next to the share of
    all planner steps spent there (``steps``: :func:`~ignjax.studies.locations.step_locations`,
    the base rate), and, with an applicable ``content``
    (:func:`~ignjax.studies.interaction.type3_content`), a second panel with
    the share per content class. A content split that does not apply draws
    nothing (the report's text says why), not an empty panel."""
    panel = content is not None and content["applicable"]
    fig, axs = new_figure(1, 2 if panel else 1, size=(12.5 if panel else 7.5, 4.2))
    ax = axs[0, 0]
    x = np.arange(4)
    frac = np.nan_to_num(result["fractions"])
    names = [c.replace("_", " ") for c in LOCATION_CLASSES]
    n_q = int(np.sum(result["counts"]))
    if steps is not None:
        base = np.nan_to_num(steps["fractions"])
        ax.bar(x - 0.2, 100 * frac, 0.4, color="tab:green", label=f"Type-3 questions (n={n_q})")
        ax.bar(x + 0.2, 100 * base, 0.4, color="0.65",
               label=f"all planner steps (n={int(np.sum(steps['counts']))}): the base rate")
        ticks = [f"{c}\n{int(k)} q. / {int(b)} steps" for c, k, b in zip(names, result["counts"], steps["counts"])]
    else:
        ax.bar(x, 100 * frac, 0.6, color="tab:green", label=f"Type-3 questions (n={n_q})")
        ticks = [f"{c}\n(n={int(k)})" for c, k in zip(names, result["counts"])]
    ax.set_xticks(x, ticks, fontsize=8)
    ax.set_xlabel("location class at the pose")
    ax.set_ylabel("share (%)")
    ax.set_ylim(0, 100)
    ax.grid(alpha=0.3, axis="y")
    ax.set_title(title or f"Where Type-3 questions arise ({result['n_unknown']} unclassified)", fontsize=10)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), fontsize=8, frameon=False, ncol=1)
    if panel:
        _content_panel(axs[0, 1], content)
    fig.tight_layout()
    return fig


def _content_panel(ax, content: dict) -> None:
    x = np.arange(3)
    frac = np.nan_to_num(content["fractions"])
    ax.bar(x, 100 * frac, 0.6, color=["#c44e52", "#4c72b0", "#8172b2"])
    labels = ["route request", "goal-room position", "room relations"]
    ax.set_xticks(x, [f"{c}\n(n={int(k)})" for c, k in zip(labels, content["counts"])], fontsize=8)
    ax.set_xlabel("what the question asked (from its text)")
    ax.set_ylabel("share of classified Type-3 questions (%)")
    ax.set_ylim(0, 100)
    ax.grid(alpha=0.3, axis="y")
    ax.set_title(f"What Type-3 questions asked ({int(content['counts'][UNCLASSIFIED])} unclassified, "
                 f"{content['n_without_text']} without text)", fontsize=10)


def plot_location_classes(result: dict, path: str | os.PathLike, title: str | None = None, content: dict | None = None,
                          steps: dict | None = None):
    """:func:`location_classes_figure` written to ``path``; returns the path."""
    return save(location_classes_figure(result, title, content, steps), path)


def questions_per_difficulty_figure(result: dict, title: str | None = None):
    """Mean questions per episode by type and difficulty (one agent: the
    result of :func:`~ignjax.studies.interaction.questions_per_difficulty` without leading axes)."""
    mean = np.asarray(result["mean_per_type"])
    if mean.ndim != 2:
        raise InputError(None, "result", "plot one agent's result (mean_per_type of shape (3, 4))")
    fig, axs = new_figure(1, 1, size=(8.5, 4.2))
    ax = axs[0, 0]
    x = np.arange(3)
    wbar = 0.16
    for t in range(4):
        ax.bar(x + (t - 2) * wbar, np.nan_to_num(mean[:, t]), wbar, color=TYPE_COLORS[t], label=TYPE_LABELS[t])
    ax.bar(x + 2 * wbar, np.nan_to_num(result["mean_total"]), wbar, color="k", label="|Q| (all types)")
    ax.set_xticks(x, [f"{b}\n(n={int(c)} episodes)" for b, c in zip(BIN_NAMES, result["count"])])
    ax.set_xlabel("episode difficulty")
    ax.set_ylabel("questions per episode")
    ax.grid(alpha=0.3, axis="y")
    _legend_right(ax)
    ax.set_title(title or "Questions by difficulty", fontsize=10)
    fig.tight_layout()
    return fig


def plot_questions_per_difficulty(result: dict, path: str | os.PathLike, title: str | None = None):
    """:func:`questions_per_difficulty_figure` written to ``path``; returns the path."""
    return save(questions_per_difficulty_figure(result, title), path)


DELTA_U_LABEL = "ΔU = (A_before − A_after) / A_before (%)"
"""The y-label of the Delta-U figure: the definition of docs/sweep.md ("The studies"), as plotted."""


def delta_u_figure(result: dict, title: str | None = None):
    """Mean ΔU per difficulty with its 95 % interval over the questions.
    ``result``: :func:`~ignjax.studies.interaction.delta_u`; A_before and
    A_after are the areas covered within ``r`` of the path over the ``h``
    steps before and after each Type-3 question."""
    fig, axs = new_figure(1, 1, size=(6.5, 4.4))
    ax = axs[0, 0]
    x = np.arange(3)
    du = np.asarray(result["delta_u"], np.float64)
    diff = np.asarray(result["difficulty"])
    m = np.full(3, np.nan)
    ci = np.zeros(3)
    for g in range(3):
        v = du[(diff == g) & np.isfinite(du)]
        if v.size:
            m[g] = 100 * v.mean()
            ci[g] = 100 * Z95 * v.std(ddof=1) / np.sqrt(v.size) if v.size > 1 else 0.0
    ax.bar(x, np.nan_to_num(m), 0.6, yerr=ci, capsize=4, color=["#55a868", "#dd8452", "#c44e52"])
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xticks(x, [f"{b}\n(n={int(c)} questions)" for b, c in zip(BIN_NAMES, result["count"])])
    ax.set_xlabel("episode difficulty")
    ax.set_ylabel(DELTA_U_LABEL)
    ax.grid(alpha=0.3, axis="y")
    ax.set_title(title or f"ΔU per Type-3 question: explored area before vs. after the answer\n(mean and 95 % "
                          f"interval; h={result['h']} steps, r={result['r']:g} m)", fontsize=10)
    fig.tight_layout()
    return fig


def plot_delta_u(result: dict, path: str | os.PathLike, title: str | None = None):
    """:func:`delta_u_figure` written to ``path``; returns the path."""
    return save(delta_u_figure(result, title), path)


__all__ = ["DELTA_U_LABEL", "TYPE_COLORS", "delta_u_figure", "location_classes_figure", "plot_delta_u",
           "plot_location_classes", "plot_question_timing", "plot_questions_per_difficulty",
           "question_timing_figure", "questions_per_difficulty_figure"]
