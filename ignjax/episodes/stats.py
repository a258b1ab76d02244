"""Benchmark statistics: printed summaries and one figure.

:func:`summarize` counts episodes per difficulty bin, goal-room label,
target category and scene, and describes distractors per episode and the
start-distance distribution; :func:`statistics_figure` draws six panels in
the spirit of the paper's benchmark-statistics figure (difficulty, distractor
count, same-room distractors, target categories, start distance, goal
rooms), for the whole corpus and the evaluation subset side by side.
"""

from __future__ import annotations

import math
import os
from collections import Counter

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from ignjax.episodes.difficulty import FactorNorms
from ignjax.protocol import BIN_NAMES
from ignjax.scenes.viz.mapplot import save_figure


def _start_distance(rec: dict, cons: dict | None, norms: FactorNorms) -> float:
    if cons is not None and "start_distance" in cons:
        return float(cons["start_distance"])
    return float(rec["factors"]["F_start"]) * norms.start_cap  # capped at start_cap


def _n_distractors(rec: dict, cons: dict | None, norms: FactorNorms) -> int:
    if cons is not None:
        return len(cons["distractors"])
    f = float(rec["factors"]["F_distractor"])
    return int(round(np.expm1(f * np.log1p(norms.distractor_cap))))


def summarize(records: list[dict], construction: list[dict] | None = None, norms: FactorNorms = FactorNorms()) -> dict:
    """Counts and distributions of a list of episode records."""
    cons = {c["episode_id"]: c for c in construction or []}
    dist = np.array([_start_distance(r, cons.get(r["episode_id"]), norms) for r in records]) if records else np.zeros(0)
    nd = np.array([_n_distractors(r, cons.get(r["episode_id"]), norms) for r in records]) if records else np.zeros(0)
    same = np.array([len(cons[r["episode_id"]]["same_room_distractors"]) for r in records if r["episode_id"] in cons])
    D = np.array([r["difficulty_score"] for r in records]) if records else np.zeros(0)
    return {
        "episodes": len(records),
        "per_bin": {b: sum(r["difficulty"] == b for r in records) for b in BIN_NAMES},
        "per_room": dict(Counter(r["goal_room"]["label"] for r in records).most_common()),
        "per_category": dict(Counter(r["target_category"] for r in records).most_common()),
        "per_scene": dict(Counter(r["scene_id"] for r in records).most_common()),
        "targets": len({(r["scene_id"], r["target_id"]) for r in records}),
        "distractors": {"mean": float(nd.mean()) if len(nd) else 0.0, "max": int(nd.max()) if len(nd) else 0,
                        "values": nd.tolist()},
        "same_room_distractors": {"mean": float(same.mean()) if len(same) else float("nan"), "values": same.tolist()},
        "start_distance": {"mean": float(dist.mean()) if len(dist) else 0.0,
                           "quartiles": [float(q) for q in np.percentile(dist, [25, 50, 75])] if len(dist) else [],
                           "values": dist.tolist()},
        "difficulty_score": {"mean": float(D.mean()) if len(D) else 0.0, "values": D.tolist()},
    }


def format_summary(name: str, s: dict, top: int = 10) -> str:
    """Plain-text lines of a :func:`summarize` result."""
    lines = [f"{name}: {s['episodes']} episodes, {s['targets']} targets in {len(s['per_scene'])} scenes, "
             f"{len(s['per_category'])} categories, {len(s['per_room'])} goal-room labels"]
    lines.append("  difficulty: " + ", ".join(f"{b} {n}" for b, n in s["per_bin"].items())
                 + f" (mean D {s['difficulty_score']['mean']:.3f})")
    q = s["start_distance"]["quartiles"]
    lines.append(f"  distractors per episode: mean {s['distractors']['mean']:.2f}, max {s['distractors']['max']}; "
                 f"start distance mean {s['start_distance']['mean']:.2f} m" + (f" (quartiles {q[0]:.1f}/{q[1]:.1f}/{q[2]:.1f} m)" if q else ""))
    lines.append("  goal rooms: " + ", ".join(f"{k} {v}" for k, v in s["per_room"].items()))
    cats = list(s["per_category"].items())
    lines.append("  top categories: " + ", ".join(f"{k} {v}" for k, v in cats[:top]) + (f", ... ({len(cats)} in all)" if len(cats) > top else ""))
    return "\n".join(lines)


def _shares(ax, sets, key: str, edges, xlabel: str) -> None:
    """One histogram per set as side-by-side bars in each bin, each set's bars summing to 100 %."""
    width = np.diff(edges)
    k = len(sets)
    for j, (lab, s, col) in enumerate(sets):
        v = np.asarray(s[key]["values"], np.float64)
        if len(v):
            counts = np.histogram(np.clip(v, edges[0], edges[-1]), bins=edges)[0]
            ax.bar(edges[:-1] + width * j / k, 100 * counts / len(v), width / k, align="edge", color=col, label=lab)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("share of the set's episodes (%)")


def statistics_figure(corpus: dict, subset: dict | None, path: str | os.PathLike, title: str = "Benchmark statistics",
                      thresholds=(0.30, 0.60)):
    """Draw six panels (corpus in grey, subset in colour, bars side by side
    in every bin: no blended colour; one legend for all, above the panels)
    and write a PNG atomically."""
    fig = Figure(figsize=(15, 8.5), dpi=110)
    axes = fig.subplots(2, 3)
    sets = [("corpus", corpus, "#9e9e9e")] + ([("subset", subset, "#1f77b4")] if subset else [])

    ax = axes[0, 0]
    width = 0.38
    for j, (lab, s, col) in enumerate(sets):
        vals = [s["per_bin"][b] for b in BIN_NAMES]
        ax.bar(np.arange(3) + (j - 0.5 * (len(sets) - 1)) * width, vals, width, label=lab, color=col)
    ax.set_xticks(range(3), BIN_NAMES)
    ax.set_ylabel("episodes")
    ax.set_title("(a) episodes per difficulty bin")

    ax = axes[0, 1]
    top = max([int(np.max(s["distractors"]["values"], initial=0)) for _, s, _ in sets] + [0])
    _shares(ax, sets, "distractors", np.arange(top + 2) - 0.5, "same-category distractors in the scene")
    ax.set_title("(b) distractors per episode")

    ax = axes[0, 2]
    _shares(ax, sets, "difficulty_score", np.linspace(0, 1, 21), "difficulty score D")
    for t in thresholds:
        ax.axvline(t, color="k", lw=1, ls="--")
    ax.text(thresholds[0], 1.0, " easy | medium", transform=ax.get_xaxis_transform(), va="top", ha="center",
            fontsize=8)
    ax.text(thresholds[1], 1.0, " medium | hard", transform=ax.get_xaxis_transform(), va="top", ha="center",
            fontsize=8)
    ax.set_title("(c) difficulty scores and bin thresholds (dashed)", pad=14)

    ax = axes[1, 0]
    base = subset or corpus
    cats = list(base["per_category"].items())[:20]
    ax.barh([c.replace("_", " ") for c, _ in cats][::-1], [n for _, n in cats][::-1], color=sets[-1][2])
    ax.set_xlabel("episodes")
    ax.set_title(f"(d) top target categories, {sets[-1][0]} ({len(base['per_category'])} in all)")
    ax.tick_params(axis="y", labelsize=7)

    ax = axes[1, 1]
    far = max([float(np.max(s["start_distance"]["values"], initial=0.0)) for _, s, _ in sets] + [1.0])
    _shares(ax, sets, "start_distance", np.arange(0.0, math.ceil(far) + 1.0, 1.0),
            "geodesic start-to-target distance (m)")
    ax.set_title("(e) start distance")

    ax = axes[1, 2]
    rooms = list(base["per_room"].items())
    ax.bar(range(len(rooms)), [n for _, n in rooms], color=sets[-1][2])
    ax.set_xticks(range(len(rooms)), [r.replace("_", " ") for r, _ in rooms], rotation=45, ha="right", fontsize=8)
    ax.set_ylabel("episodes")
    ax.set_title(f"(f) goal-room labels, {sets[-1][0]}")

    fig.suptitle(title, y=0.99)
    handles = [Patch(color=col, label=f"{lab} ({s['episodes']} episodes)" if "episodes" in s else lab)
               for lab, s, col in sets]
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.965), ncol=len(sets), frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    save_figure(fig, path, 110)
    return fig
