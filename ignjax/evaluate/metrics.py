"""Metrics over episode outcomes, as array programs.

For success threshold tau (metres) and per-type question costs w:

* ``SR@tau``  = mean over episodes of 1{d_final <= tau}: the paper's rule
  (Eq. wsr, §4.1), whether the episode ended by STOP or by the step budget;
  ``require_stop=True`` also requires an explicit STOP (Habitat's convention);
* ``OSR@tau`` = mean of 1{min distance along the path <= tau};
* ``NE``      = mean final distance (m); ``TL`` = mean path length (m);
* ``Q_t``     = mean number of charged type-t questions, ``|Q|`` their sum;
* ``WSR@tau`` = mean of 1{success} * exp(-sum_t w_t n_{e,t})  (paper Eq. wsr,
  Appendix Eq. app:wsr): repeated questions are charged repeatedly, failed
  episodes score 0, and no-question successes score 1.

Distances are geodesic by default (Habitat's convention): the outcome
table stores both the geodesic and the Euclidean final distance, and
:func:`summarize` uses whichever table it is given.

Every function takes arrays with any leading batch dimensions (agents,
cost vectors, seeds...) over a trailing episode axis, reduces with masked
means (``valid``) and groups (difficulty bin, scene, ...) with one-hot
segment sums, so the same code runs on one agent's 500 episodes or on
10^6 cost vectors x 500 episodes, in numpy or under ``jit``/``vmap``.
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ignjax.arrays import xp as _xp
from ignjax.protocol import BIN_NAMES, LOCKED_COSTS, N_QUESTION_TYPES, SUCCESS_REQUIRES_STOP
from ignjax.protocol import SUCCESS_THRESHOLDS as DEFAULT_THRESHOLDS
from ignjax.sim.types import ABORTED, OutcomeRow


def episode_success(final_distance, stopped, thresholds=DEFAULT_THRESHOLDS, require_stop: bool = SUCCESS_REQUIRES_STOP,
                    stop_reason=None):
    """(..., E, T) bool: 1{d <= tau} (and stopped, when required). With
    ``stop_reason`` (..., E), an episode ended by a model failure
    (:data:`~ignjax.sim.types.ABORTED`) is never a success."""
    xp = _xp(final_distance, stopped)
    d = xp.asarray(final_distance)[..., None]
    ok = d <= xp.asarray(thresholds, dtype=d.dtype)
    if stop_reason is not None:
        ok = ok & (xp.asarray(stop_reason) != ABORTED)[..., None]
    return ok & xp.asarray(stopped)[..., None] if require_stop else ok


def success_rule(require_stop: bool, distance: str = "geodesic") -> str:
    """One sentence naming the success rule, for report and table headers."""
    rule = f"success = final {distance} distance <= tau"
    if require_stop:
        return rule + " and an explicit STOP (Habitat's convention, not the paper's)"
    return rule + " (the paper's rule: an episode ends by STOP or by the step budget, and either counts)"


def question_discount(n_questions, costs=LOCKED_COSTS):
    """exp(-sum_t w_t n_{e,t}).

    Args:
        n_questions: (..., E, 4) counts.
        costs: (4,) or (K, 4); with (K, 4) a new leading axis K is added.

    Returns:
        (..., E) or (K, ..., E) discounts in (0, 1].
    """
    xp = _xp(n_questions, costs)
    n = xp.asarray(n_questions).astype(xp.float32 if xp is jnp else np.float64)
    w = xp.asarray(costs, dtype=n.dtype)
    if w.ndim == 1:
        return xp.exp(-(n @ w))
    # Shape: (K, ..., E)
    return xp.exp(-xp.tensordot(w, n, axes=([-1], [-1])))


def episode_wsr(success, n_questions, costs=LOCKED_COSTS):
    """(..., E, T) episode WSR = success * discount (paper Eq. wsr)."""
    xp = _xp(success, n_questions, costs)
    return xp.asarray(success) * question_discount(n_questions, costs)[..., None]


def _masked_mean(x, mask, xp, axis):
    m = mask.astype(x.dtype)
    return (x * m).sum(axis) / xp.maximum(m.sum(axis), 1)


def summarize(outcomes: OutcomeRow, thresholds=DEFAULT_THRESHOLDS, costs=LOCKED_COSTS, require_stop: bool = SUCCESS_REQUIRES_STOP,
              groups=None, n_groups: int | None = None) -> dict:
    """All metrics, optionally per group.

    Args:
        outcomes: per-episode outcomes with leading dims ``...`` and E episodes.
        thresholds: (T,) success thresholds, metres.
        costs: (4,) per-type question costs.
        require_stop: success also requires an explicit STOP (default: the
            paper's rule, the final distance alone).
        groups: optional (..., E) int group index per episode (e.g.
            ``outcomes.difficulty``); ``n_groups`` groups.

    Returns:
        dict with ``SR``, ``OSR``, ``WSR`` (..., [G,] T); ``NE``, ``TL``,
        ``Q_total``, ``count`` (..., [G]); ``Q`` (..., [G,] 4).
    """
    o = outcomes
    xp = _xp(o.final_distance)
    fdt = np.float64 if xp is np else jnp.float32
    d = xp.asarray(o.final_distance, dtype=fdt)
    succ = episode_success(d, o.stopped, thresholds, require_stop, o.stop_reason).astype(fdt)
    osucc = episode_success(xp.asarray(o.min_distance, dtype=fdt), o.stopped, thresholds, False).astype(fdt)
    wsr = episode_wsr(succ, o.n_questions, costs).astype(fdt)
    nq = xp.asarray(o.n_questions).astype(fdt)
    per_episode = {
        "SR": succ,  # (..., E, T)
        "OSR": osucc,
        "WSR": wsr,
        "NE": d,  # (..., E)
        "TL": xp.asarray(o.path_length, dtype=fdt),
        "Q": nq,  # (..., E, 4)
        "Q_total": nq.sum(-1),
    }
    valid = xp.asarray(o.valid)
    if groups is None:
        out = {}
        for k, v in per_episode.items():
            if v.ndim == valid.ndim:  # (..., E)
                out[k] = _masked_mean(v, valid, xp, -1)
            else:  # (..., E, X)
                out[k] = _masked_mean(v, valid[..., None], xp, -2)
        out["count"] = valid.sum(-1)
        return out
    if n_groups is None:
        raise ValueError("n_groups is required with groups")
    # Shape: (..., E, G) one-hot of valid rows
    onehot = (xp.asarray(groups)[..., None] == xp.arange(n_groups)) & valid[..., None]
    oh = onehot.astype(fdt)
    counts = oh.sum(-2)  # (..., G)
    denom = xp.maximum(counts, 1)
    out = {}
    for k, v in per_episode.items():
        if v.ndim == valid.ndim:
            out[k] = xp.einsum("...e,...eg->...g", v, oh) / denom
        else:
            out[k] = xp.einsum("...ex,...eg->...gx", v, oh) / denom[..., None]
    out["count"] = counts
    return out


# ---------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------

TABLE1_COLUMNS: tuple[str, ...] = (
    "Easy SR@1.5", "Easy |Q|", "Medium SR@1.5", "Medium |Q|", "Hard SR@1.5", "Hard |Q|",
    "SR/OSR@0.5", "SR/OSR@1.5", "SR/OSR@3", "NE", "TL", "Q1", "Q2", "Q3", "Q4", "|Q|", "WSR@1.5", "WSR@3",
)


def _fmt_tau(t: float) -> str:
    return f"{t:g}"


def metric_row(outcomes: OutcomeRow, thresholds=DEFAULT_THRESHOLDS, costs=LOCKED_COSTS, require_stop: bool = SUCCESS_REQUIRES_STOP) -> dict:
    """One agent's metrics as a flat dict of Python floats (percentages for
    SR/OSR/WSR, as the paper reports them), overall and per difficulty."""
    thresholds = tuple(float(t) for t in thresholds)
    overall = summarize(outcomes, thresholds, costs, require_stop)
    per = summarize(outcomes, thresholds, costs, require_stop, groups=outcomes.difficulty, n_groups=len(BIN_NAMES))
    row: dict[str, float] = {"episodes": int(np.asarray(overall["count"]))}
    for i, t in enumerate(thresholds):
        row[f"SR@{_fmt_tau(t)}"] = 100 * float(overall["SR"][i])
        row[f"OSR@{_fmt_tau(t)}"] = 100 * float(overall["OSR"][i])
        row[f"WSR@{_fmt_tau(t)}"] = 100 * float(overall["WSR"][i])
    row["NE"] = float(overall["NE"])
    row["TL"] = float(overall["TL"])
    for q in range(N_QUESTION_TYPES):
        row[f"Q{q + 1}"] = float(overall["Q"][q])
    row["|Q|"] = float(overall["Q_total"])
    for g, name in enumerate(BIN_NAMES):
        row[f"{name}.episodes"] = int(np.asarray(per["count"])[g])
        for i, t in enumerate(thresholds):
            row[f"{name}.SR@{_fmt_tau(t)}"] = 100 * float(per["SR"][g, i])
            row[f"{name}.OSR@{_fmt_tau(t)}"] = 100 * float(per["OSR"][g, i])
            row[f"{name}.WSR@{_fmt_tau(t)}"] = 100 * float(per["WSR"][g, i])
        row[f"{name}.NE"] = float(per["NE"][g])
        row[f"{name}.TL"] = float(per["TL"][g])
        row[f"{name}.|Q|"] = float(per["Q_total"][g])
        for q in range(N_QUESTION_TYPES):
            row[f"{name}.Q{q + 1}"] = float(per["Q"][g, q])
    return row


def md_cell(v) -> str:
    """One cell of a GitHub-flavoured markdown table: strings as given, floats
    to 4 significant digits (``nan`` when not finite); a ``|`` in the text
    (the ``|Q|`` columns) is escaped as ``\\|`` so it does not split the cell."""
    if isinstance(v, (float, np.floating)):
        v = "nan" if not np.isfinite(float(v)) else f"{float(v):.4g}"
    return str(v).replace("\\|", "|").replace("|", "\\|")


def md_table(header: list[str], rows: list[list]) -> str:
    """A GitHub-flavoured markdown table (cells by :func:`md_cell`): every
    row has as many cells as the header."""
    lines = ["| " + " | ".join(md_cell(h) for h in header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(md_cell(v) for v in r) + " |" for r in rows]
    return "\n".join(lines)


def table1(rows: dict[str, dict], fmt: str = "markdown") -> str:
    """Format the paper's Table-1 columns for several agents.

    Args:
        rows: agent name -> :func:`metric_row` output (thresholds must
            include 0.5, 1.5 and 3).
        fmt: ``"markdown"`` or ``"text"``.
    """
    def cell(row: dict, col: str) -> str:
        if col.startswith(("Easy", "Medium", "Hard")):
            level, metric = col.split(" ", 1)
            key = f"{level.lower()}.{metric}" if metric != "|Q|" else f"{level.lower()}.|Q|"
            v = row.get(key, float("nan"))
            return f"{v:.1f}" if "SR" in metric else f"{v:.2f}"
        if col.startswith("SR/OSR@"):
            t = col.split("@")[1]
            return f"{row.get(f'SR@{t}', float('nan')):.1f}/{row.get(f'OSR@{t}', float('nan')):.1f}"
        v = row.get(col, float("nan"))
        return f"{v:.1f}" if col.startswith("WSR") else f"{v:.2f}"

    header = ["Agent"] + list(TABLE1_COLUMNS)
    body = [[name] + [cell(r, c) for c in TABLE1_COLUMNS] for name, r in rows.items()]
    if fmt == "markdown":
        return md_table(header, body)
    widths = [max(len(str(x)) for x in col) for col in zip(header, *body)]
    return "\n".join("  ".join(str(x).rjust(w) for x, w in zip(r, widths)) for r in [header] + body)
