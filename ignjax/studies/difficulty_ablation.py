"""Difficulty ablation: how the alpha coefficients and bin thresholds of the
difficulty score (:mod:`ignjax.episodes.difficulty`) change the bins and
the per-bin success, and alpha calibrated against observed failures.

``D_e = alpha . F_e`` (4 factors in [0, 1], alpha on the simplex); bins easy
``D < t0``, medium ``t0 <= D < t1``, hard ``D >= t1``.

:func:`ablate` scores every episode under every alpha (G of them) and bins
it under every threshold pair (H), then reports the bin proportions, each
agent's success rate per bin and whether the bins are *ordered* (easy >=
medium >= hard SR for every agent). It never materialises (G, H, E): per
alpha, episodes are sorted by D once, success and validity are
cumulatively summed along that order, and every threshold's bin sums are
differences of those prefix sums at ``#(D < t)`` (float64 comparisons, the
same as :func:`~ignjax.episodes.difficulty.difficulty_bin`).

:func:`calibrate` chooses alpha on one half of the episodes to maximise the
rank correlation between D and failure, and reports it on the other half.
"""

from __future__ import annotations

import os

import numpy as np
from scipy.stats import rankdata

from ignjax.studies.cost_derivation import simplex_grid
from ignjax.episodes.difficulty import difficulty_score
from ignjax.errors import ConfigError, InputError
from ignjax.protocol import BIN_NAMES, FACTOR_NAMES
from ignjax.protocol import DIFFICULTY_ALPHA as DEFAULT_ALPHA
from ignjax.protocol import DIFFICULTY_THRESHOLDS as DEFAULT_THRESHOLDS
from ignjax.studies._common import as_array, new_figure, save

EMPTY_RULES = ("unordered", "skip")


# ---------------------------------------------------------------------------
# Grids
# ---------------------------------------------------------------------------


def _check_step(step, where):
    if not isinstance(step, (int, float)) or not (0 < step <= 1) or abs(1 / step - round(1 / step)) > 1e-9:
        raise ConfigError(None, where, f"must be 1/k for a positive integer k, got {step!r}")


def alpha_grid(step: float = 0.05) -> np.ndarray:
    """Every alpha on the 4-simplex (non-negative, sum 1) with spacing ``step``.

    Returns:
        (G, 4) float64; G = C(1/step + 3, 3) (1771 for 0.05, 286 for 0.1).
        The default alpha (0.35, 0.25, 0.15, 0.25) is on the 0.05 grid.
    """
    _check_step(step, "alpha_grid.step")
    return simplex_grid(step, dim=4)


def threshold_grid(step: float = 0.05, lo: float | None = None, hi: float | None = None) -> np.ndarray:
    """Every threshold pair ``lo <= t0 < t1 <= hi`` on a grid of ``step``.

    Args:
        lo, hi: range of the thresholds (default ``step`` and ``1 - step``,
            so no bin is empty by construction of the thresholds alone).

    Returns:
        (H, 2) float64, t0-major order; (0.30, 0.60) is on the 0.05 and 0.1 grids.
    """
    _check_step(step, "threshold_grid.step")
    k = int(round(1 / step))
    lo = step if lo is None else lo
    hi = 1 - step if hi is None else hi
    if not (0 <= lo < hi <= 1):
        raise ConfigError(None, "threshold_grid", f"needs 0 <= lo < hi <= 1, got lo={lo!r}, hi={hi!r}")
    v = np.round(np.arange(k + 1) / k, 12)
    v = v[(v >= lo - 1e-12) & (v <= hi + 1e-12)]
    i, j = np.triu_indices(len(v), 1)
    return np.stack([v[i], v[j]], 1)


def _alphas(alphas, where="alphas") -> np.ndarray:
    a = np.asarray(alphas, dtype=np.float64)
    if a.ndim == 1:
        a = a[None]
    if a.ndim != 2 or a.shape[1] != 4 or a.shape[0] == 0:
        raise ConfigError(None, where, f"must have shape (G, 4) (one weight per factor), got {np.shape(alphas)}")
    for cond, reason in ((~np.isfinite(a).all(1), "has a NaN or infinite entry"), ((a < 0).any(1), "has a negative entry"),
                         (np.abs(a.sum(1) - 1) > 1e-6, "entries must sum to 1")):
        if cond.any():
            i = int(np.argmax(cond))
            raise ConfigError(None, f"{where}[{i}]", f"{reason}: {a[i].tolist()}")
    return a


def _thresholds(thresholds, where="thresholds") -> np.ndarray:
    t = np.asarray(thresholds, dtype=np.float64)
    if t.ndim == 1:
        t = t[None]
    if t.ndim != 2 or t.shape[1] != 2 or t.shape[0] == 0:
        raise ConfigError(None, where, f"must have shape (H, 2) (easy/medium, medium/hard), got {np.shape(thresholds)}")
    bad = ~np.isfinite(t).all(1) | ~((0 <= t[:, 0]) & (t[:, 0] < t[:, 1]) & (t[:, 1] <= 1))
    if bad.any():
        i = int(np.argmax(bad))
        raise ConfigError(None, f"{where}[{i}]", f"must satisfy 0 <= t0 < t1 <= 1, got {t[i].tolist()}")
    return t


def _factors(factors) -> np.ndarray:
    return as_array(factors, "factors", ndim=2, last=4, dtype=np.float64, finite=True)


def _agent_rows(x, name, E) -> np.ndarray:
    a = as_array(x, name, ndim=(1, 2), dtype=np.float64, finite=True)
    a = a[None] if a.ndim == 1 else a
    if a.shape[1] != E:
        raise InputError(None, name, f"must have {E} episodes (one per row of factors), got shape {a.shape}")
    return a


def _valid(valid, A, E) -> np.ndarray:
    if valid is None:
        return np.ones((A, E), bool)
    v = as_array(valid, "valid", ndim=(1, 2))
    if v.shape not in ((E,), (A, E)):
        raise InputError(None, "valid", f"must have shape ({E},) or ({A}, {E}), got {v.shape}")
    return np.broadcast_to(v.astype(bool), (A, E))


# ---------------------------------------------------------------------------
# Ablation
# ---------------------------------------------------------------------------


def _bin_sums(D: np.ndarray, weights: np.ndarray, thr: np.ndarray, max_elements: int) -> np.ndarray:
    """Per-bin weight sums.

    Args:
        D: (G, E) scores; weights: (E, X); thr: (H, 2).

    Returns:
        (G, H, 3, X) sums of ``weights`` over the episodes of each bin.
    """
    G, E = D.shape
    X = weights.shape[1]
    values, inv = np.unique(thr.ravel(), return_inverse=True)
    i0, i1 = inv.reshape(-1, 2).T
    total = weights.sum(0)  # (X,)
    out = np.empty((G, thr.shape[0], 3, X))
    step = max(1, max_elements // max(E * max(X, len(values)), 1))
    for g0 in range(0, G, step):
        d = D[g0:g0 + step]
        order = np.argsort(d, axis=1, kind="stable")
        cum = np.zeros((d.shape[0], E + 1, X))
        np.cumsum(weights[order], axis=1, out=cum[:, 1:])
        below = (d[:, None, :] < values[None, :, None]).sum(-1)  # (g, V): #(D < t) per threshold value
        at = np.take_along_axis(cum, below[:, :, None], axis=1)  # (g, V, X)
        lo, hi = at[:, i0], at[:, i1]  # (g, H, X)
        out[g0:g0 + step, :, 0] = lo
        out[g0:g0 + step, :, 1] = hi - lo
        out[g0:g0 + step, :, 2] = total - hi
    return out


def _ordered(sr: np.ndarray, count: np.ndarray, empty: str, tol: float) -> np.ndarray:
    """(..., A, 3) SR and counts -> (...,) bool ordered for every agent."""
    ne = count > 0
    s = np.where(ne, sr, 0.0)
    pairs = ((0, 1), (1, 2), (0, 2))
    if empty == "unordered":
        ok = ne.all(-1) & (s[..., 0] >= s[..., 1] - tol) & (s[..., 1] >= s[..., 2] - tol)
    else:  # skip: every pair of non-empty bins in order
        ok = np.ones(sr.shape[:-1], bool)
        for i, j in pairs:
            ok &= ~(ne[..., i] & ne[..., j]) | (s[..., i] >= s[..., j] - tol)
    return ok.all(-1)


def ablate(factors, success, valid, alphas, thresholds, *, empty: str = "unordered", tol: float = 0.0,
           max_elements: int = 1 << 23) -> dict:
    """Bins, per-bin success and ordering under every (alpha, thresholds) setting.

    Args:
        factors: (E, 4) difficulty factors per episode.
        success: (A, E) or (E,) success flags (bool or 0/1) per agent.
        valid: None, (E,) or (A, E) bool.
        alphas: (G, 4) on the simplex (:func:`alpha_grid`).
        thresholds: (H, 2) with 0 <= t0 < t1 <= 1 (:func:`threshold_grid`).
        empty: rule for empty bins in ``ordered``: ``"unordered"`` (default)
            -- a setting where some agent has an empty bin is not ordered
            (the bins do not separate the episodes); ``"skip"`` -- only the
            non-empty bins must be in order (a setting with fewer than two
            non-empty bins is ordered).
        tol: SR differences within ``tol`` count as in order (default exact).

    Returns:
        dict with ``alphas`` (G, 4), ``thresholds`` (H, 2),
        ``proportions`` (G, H, 3) share of episodes (valid for some agent)
        per bin, ``count`` (G, H, A, 3) valid episodes per agent and bin,
        ``sr`` (G, H, A, 3) success rate per bin (NaN for an empty bin),
        ``nonempty`` (G, H) every agent has every bin non-empty, ``ordered``
        (G, H) bool, ``fraction_ordered`` over all settings,
        ``fraction_ordered_nonempty`` over settings with no empty bin (NaN if
        none), ``fraction_ordered_by_alpha`` (G,), ``fraction_ordered_by_threshold``
        (H,), ``default`` (the same for the default alpha and thresholds
        alone: ``proportions`` (3,), ``sr`` (A, 3), ``count`` (A, 3),
        ``ordered``), ``empty`` the rule used.
    """
    if empty not in EMPTY_RULES:
        raise ConfigError(None, "empty", f"must be one of {EMPTY_RULES}, got {empty!r}")
    f = _factors(factors)
    E = f.shape[0]
    s = _agent_rows(success, "success", E)
    A = s.shape[0]
    v = _valid(valid, A, E)
    a = _alphas(alphas)
    t = _thresholds(thresholds)
    anyv = v.any(0)
    w = np.concatenate([v.T, (s * v).T, anyv[:, None]], 1).astype(np.float64)  # (E, 2A + 1)

    def one(al, th):
        sums = _bin_sums(difficulty_score(f, al), w, th, max_elements)  # (G, H, 3, X)
        count = np.moveaxis(sums[..., :A], -1, -2)  # (G, H, A, 3)
        with np.errstate(invalid="ignore", divide="ignore"):
            sr = np.where(count > 0, np.moveaxis(sums[..., A:2 * A], -1, -2) / np.maximum(count, 1), np.nan)
        prop = sums[..., -1] / max(int(anyv.sum()), 1)
        return prop, count.round().astype(np.int64), sr

    prop, count, sr = one(a, t)
    ordered = _ordered(sr, count, empty, tol)
    nonempty = (count > 0).all((-1, -2))
    dprop, dcount, dsr = one(np.asarray([DEFAULT_ALPHA]), np.asarray([DEFAULT_THRESHOLDS]))
    return {
        "alphas": a, "thresholds": t, "proportions": prop, "count": count, "sr": sr, "nonempty": nonempty,
        "ordered": ordered, "fraction_ordered": float(ordered.mean()),
        "fraction_ordered_nonempty": float(ordered[nonempty].mean()) if nonempty.any() else float("nan"),
        "fraction_ordered_by_alpha": ordered.mean(1), "fraction_ordered_by_threshold": ordered.mean(0),
        "default": {"alpha": np.asarray(DEFAULT_ALPHA), "thresholds": np.asarray(DEFAULT_THRESHOLDS),
                    "proportions": dprop[0, 0], "count": dcount[0, 0], "sr": dsr[0, 0],
                    "ordered": bool(_ordered(dsr, dcount, empty, tol)[0, 0])},
        "empty": empty,
    }


# ---------------------------------------------------------------------------
# Calibration
# ---------------------------------------------------------------------------


def spearman_rows(x, y) -> np.ndarray:
    """Spearman rank correlation of every row of ``x`` (G, n) with ``y`` (n,):
    the Pearson correlation of average ranks (ties share their mean rank),
    as ``scipy.stats.spearmanr``. NaN where a row or ``y`` is constant."""
    x = np.atleast_2d(np.asarray(x, np.float64))
    y = np.asarray(y, np.float64)
    if x.shape[1] < 2:
        return np.full(x.shape[0], np.nan)
    rx = rankdata(x, axis=1, method="average")
    ry = rankdata(y, method="average")
    rx = rx - rx.mean(1, keepdims=True)
    ry = ry - ry.mean()
    num = rx @ ry
    den = np.sqrt((rx * rx).sum(1) * (ry @ ry))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1), np.nan)


def split_halves(n: int, seed: int, fit_fraction: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Deterministic split of ``range(n)``: a permutation from
    ``numpy.random.default_rng(seed)``; the first ``round(n * fit_fraction)``
    indices (sorted) fit, the rest (sorted) are held out."""
    if not (0 < fit_fraction < 1):
        raise ConfigError(None, "fit_fraction", f"must be in (0, 1), got {fit_fraction!r}")
    perm = np.random.default_rng(int(seed)).permutation(n)
    k = int(round(n * fit_fraction))
    return np.sort(perm[:k]), np.sort(perm[k:])


def _mean_corr(D: np.ndarray, failure: np.ndarray, v: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(G, E) scores -> ((G,) mean over agents, (A, G) per agent) Spearman on episodes ``idx``."""
    per = np.stack([spearman_rows(D[:, idx[v[a, idx]]], failure[a, idx[v[a, idx]]]) for a in range(failure.shape[0])])
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(per)
        mean = np.where(ok.any(0), np.where(ok, per, 0).sum(0) / np.maximum(ok.sum(0), 1), np.nan)
    return mean, per


def calibrate(factors, failure, valid=None, alphas=None, split_seed: int = 0, *, fit_fraction: float = 0.5) -> dict:
    """Fit alpha to failures on one half of the episodes, test on the other.

    The criterion of an alpha on a set of episodes is the Spearman rank
    correlation between D and failure, computed per agent on the agent's
    valid episodes (average ranks for ties, so a 0/1 failure is fine) and
    averaged over the agents where it is defined (an agent whose failure is
    constant on the half, or a D constant on it, is left out of the mean).
    The fitted alpha maximises the criterion on the fit half (first in grid
    order among equals); its criterion on the held-out half is the honest
    estimate.

    Args:
        factors: (E, 4).
        failure: (A, E) or (E,) failure indicator (e.g. ``1 - success@1.5``)
            or any larger-is-worse outcome (final distance).
        valid: None, (E,) or (A, E).
        alphas: (G, 4) candidates (default :func:`alpha_grid` of 0.05).
        split_seed: seed of the split (:func:`split_halves`).

    Returns:
        dict with ``alpha`` (4,) fitted, ``index`` in ``alphas``, ``fit_corr``,
        ``holdout_corr``, ``default_alpha``, ``default_fit_corr``,
        ``default_holdout_corr``, ``fit_corr_grid`` / ``holdout_corr_grid``
        (G,), ``per_agent_fit`` / ``per_agent_holdout`` / ``default_per_agent_holdout``
        (A,), ``fit_index`` / ``holdout_index`` episode indices, ``alphas``.

    Raises:
        InputError: no alpha has a defined correlation on the fit half.
    """
    f = _factors(factors)
    E = f.shape[0]
    y = _agent_rows(failure, "failure", E)
    A = y.shape[0]
    v = _valid(valid, A, E)
    a = _alphas(alpha_grid(0.05) if alphas is None else alphas)
    fit, hold = split_halves(E, split_seed, fit_fraction)
    D = difficulty_score(f, a)  # (G, E)
    Dd = difficulty_score(f, np.asarray([DEFAULT_ALPHA]))  # (1, E)
    fit_grid, fit_per = _mean_corr(D, y, v, fit)
    hold_grid, hold_per = _mean_corr(D, y, v, hold)
    if not np.isfinite(fit_grid).any():
        raise InputError(None, "failure", "no alpha gives a defined rank correlation on the fit half "
                                          "(failure or difficulty is constant there)")
    best = int(np.nanargmax(fit_grid))
    dfit, _ = _mean_corr(Dd, y, v, fit)
    dhold, dhold_per = _mean_corr(Dd, y, v, hold)
    return {
        "alpha": a[best], "index": best, "fit_corr": float(fit_grid[best]), "holdout_corr": float(hold_grid[best]),
        "default_alpha": np.asarray(DEFAULT_ALPHA), "default_fit_corr": float(dfit[0]),
        "default_holdout_corr": float(dhold[0]), "fit_corr_grid": fit_grid, "holdout_corr_grid": hold_grid,
        "per_agent_fit": fit_per[:, best], "per_agent_holdout": hold_per[:, best],
        "default_per_agent_holdout": dhold_per[:, 0], "fit_index": fit, "holdout_index": hold, "alphas": a,
    }


# ---------------------------------------------------------------------------
# Plots
# ---------------------------------------------------------------------------


def plot_ordering(result: dict, path: str | os.PathLike, title: str | None = None):
    """Left: share of alphas giving ordered bins, per threshold pair (t0, t1).
    Right: share of ordered settings against each factor's weight.
    ``result``: :func:`ablate`."""
    t = result["thresholds"]
    fig, axs = new_figure(1, 2, size=(11.0, 4.4))
    ax = axs[0, 0]
    sc = ax.scatter(t[:, 0], t[:, 1], c=100 * result["fraction_ordered_by_threshold"], cmap="viridis", vmin=0,
                    vmax=100, marker="s", s=40)
    cb = fig.colorbar(sc, ax=ax)
    cb.set_label("alphas with ordered bins (%)")
    ax.plot([DEFAULT_THRESHOLDS[0]], [DEFAULT_THRESHOLDS[1]], marker="*", color="red", ms=12, ls="none",
            label="paper thresholds")
    ax.set_xlabel("easy/medium threshold t0 (difficulty D, unitless)")
    ax.set_ylabel("medium/hard threshold t1 (difficulty D, unitless)")
    ax.legend(fontsize=8)
    ax = axs[0, 1]
    a = result["alphas"]
    per_alpha = result["fraction_ordered_by_alpha"]
    for k, name in enumerate(FACTOR_NAMES):
        levels = np.unique(np.round(a[:, k], 9))
        ys = [100 * per_alpha[np.isclose(a[:, k], lv)].mean() for lv in levels]
        ax.plot(levels, ys, marker="o", ms=3, label=name)
    ax.set_xlabel("weight alpha_k of the factor (unitless)")
    ax.set_ylabel("ordered (alpha, threshold) settings (%)")
    ax.set_ylim(-2, 102)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle(title or f"easy >= medium >= hard SR for every agent: {100 * result['fraction_ordered']:.1f}% "
                          f"of settings (empty bins: {result['empty']})", fontsize=10)
    return save(fig, path)


def plot_calibration(result: dict, path: str | os.PathLike, title: str | None = None):
    """Default vs fitted alpha per factor, with fit / held-out rank
    correlations in the legend. ``result``: :func:`calibrate`."""
    fig, axs = new_figure(1, 1, size=(6.5, 4.2))
    ax = axs[0, 0]
    x = np.arange(4)
    ax.bar(x - 0.2, result["default_alpha"], 0.4,
           label=f"default (held-out rho={result['default_holdout_corr']:.3f})")
    ax.bar(x + 0.2, result["alpha"], 0.4,
           label=f"fitted (fit rho={result['fit_corr']:.3f}, held-out rho={result['holdout_corr']:.3f})")
    ax.set_xticks(x)
    ax.set_xticklabels(FACTOR_NAMES)
    ax.set_xlabel("difficulty factor")
    ax.set_ylabel("weight alpha_k (unitless, sums to 1)")
    ax.set_ylim(0, 1.05)
    ax.legend(fontsize=8)
    ax.set_title(title or "alpha calibrated to failures (Spearman rho between D and failure)", fontsize=10)
    return save(fig, path)


__all__ = ["BIN_NAMES", "EMPTY_RULES", "alpha_grid", "threshold_grid", "ablate", "spearman_rows", "split_halves",
           "calibrate", "plot_ordering", "plot_calibration"]
