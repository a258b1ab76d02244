"""Figures of the cost-sensitivity study (:mod:`ignjax.studies.cost_sensitivity`):
the marginal WSR of each agent against each question type's cost, and the map
of where the agents' ranking flips. Kept apart from the study's arithmetic,
which runs without matplotlib (a sweep's configuration check and the bench
import it)."""

from __future__ import annotations

import os

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ignjax.protocol import TYPE_LABELS
from ignjax.scenes.viz.mapplot import save_figure
from ignjax.studies._common import new_figure, save
from ignjax.studies.cost_sensitivity import LOCKED


def marginal_wsr_figure(result: dict, title: str | None = None) -> Figure:
    """Four panels (one per question type), one y scale: mean WSR of each
    agent that asks against that type's cost, with a 95 % band over the
    episodes and the locked cost marked. An agent that asks nothing has one
    WSR whatever the costs: a dotted line when it falls in the range of the
    others, else only its value in the legend (so the range where the
    curves cross keeps the height). ``result``: :func:`run_study`."""
    m = result["marginals"]
    names = result["agent_names"]
    asks = np.asarray(result.get("asks", np.ones(len(names), bool)), bool)
    se = m.get("se", np.zeros_like(m["mean"]))
    lo, hi = 100 * (m["mean"] - 1.96 * se), 100 * (m["mean"] + 1.96 * se)
    if asks.any():
        y0, y1 = float(np.nanmin(lo[..., asks])), float(np.nanmax(hi[..., asks]))
    else:
        y0, y1 = float(np.nanmin(100 * m["mean"])), float(np.nanmax(100 * m["mean"]))
    pad = max(1.0, 0.08 * (y1 - y0))
    y0, y1 = max(0.0, y0 - pad), min(100.0, y1 + pad)
    fig = Figure(figsize=(16.0, 4.4), layout="constrained")
    FigureCanvasAgg(fig)
    axs = fig.subplots(1, 4, sharey=True)
    colors = [f"C{a % 10}" for a in range(len(names))]
    off_axis = []
    for t, ax in enumerate(axs):
        for a, name in enumerate(names):
            x, y = m["centers"][t], 100 * m["mean"][t, :, a]
            if asks[a]:
                ax.plot(x, y, marker="o", ms=3, color=colors[a], label=f"{name} (band: 95 % interval)")
                ax.fill_between(x, lo[t, :, a], hi[t, :, a], color=colors[a], alpha=0.2, lw=0)
            else:
                v = float(np.nanmean(y))
                if y0 <= v <= y1:
                    ax.axhline(v, color=colors[a], ls=":", lw=1.5, label=f"{name}: {v:.1f} % at every cost (asks nothing)")
                elif t == 0:
                    off_axis.append(Line2D([], [], color=colors[a], ls=":", lw=1.5,
                                           label=f"{name}: {v:.1f} % at every cost (asks nothing; off the axis)"))
        ax.axvline(LOCKED[t], color="k", ls="--", lw=1, label="locked cost")
        ax.set_xlabel(f"cost w{t + 1} (penalty per question, unitless)")
        ax.set_title(TYPE_LABELS[t], fontsize=10)
        ax.grid(alpha=0.3)
    axs[0].set_ylim(y0, y1)
    axs[0].set_ylabel("mean WSR over sampled cost vectors (%)")
    fig.legend(handles=axs[0].get_legend_handles_labels()[0] + off_axis, loc="outside right upper", fontsize=8,
               frameon=False)
    if title:
        fig.suptitle(title)
    return fig


def plot_marginal_wsr(result: dict, path: str | os.PathLike, title: str | None = None):
    """:func:`marginal_wsr_figure`, written as a PNG at ``path``; returns the path."""
    return save_figure(marginal_wsr_figure(result, title), path, dpi=120)


def plot_flip_map(result: dict, path: str | os.PathLike, title: str | None = None):
    """Share of cost vectors whose agent ranking differs from the locked one,
    over the cost shares of two types. ``result``: :func:`run_study` (or a
    dict with ``flips`` from :func:`flip_regions` and ``costs``)."""
    f = result["flips"]
    i, j = f["axes"]
    fig, axs = new_figure(1, 1, size=(5.5, 4.6))
    ax = axs[0, 0]
    im = ax.imshow(100 * f["flip_rate"], origin="lower", extent=(0, 1, 0, 1), vmin=0, vmax=100, cmap="magma",
                   aspect="equal")
    cb = fig.colorbar(im, ax=ax)
    cb.set_label("cost vectors with a different ranking (%)")
    ref = LOCKED / LOCKED.sum()
    ax.plot([ref[i]], [ref[j]], marker="*", color="cyan", ms=12, ls="none", label="locked costs")
    ax.set_xlabel(f"share of total cost on {TYPE_LABELS[i]} (w{i + 1} / sum w)")
    ax.set_ylabel(f"share of total cost on {TYPE_LABELS[j]} (w{j + 1} / sum w)")
    ax.set_title(title or f"ranking flips: {100 * f['fraction_flipped']:.1f}% of {f['n']} cost vectors", fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    return save(fig, path)


__all__ = ["marginal_wsr_figure", "plot_flip_map", "plot_marginal_wsr"]
