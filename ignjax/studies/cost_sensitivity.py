"""Cost sensitivity: WSR re-weighted offline under many question-cost vectors.

WSR (paper Eq. wsr, :mod:`ignjax.evaluate.metrics`) charges every Type-t question a
penalty w_t through the discount ``exp(-sum_t w_t n_{e,t})``
(:func:`ignjax.evaluate.metrics.question_discount`, reused here unchanged)::

    WSR_k(a) = 1/|E_a| sum_{e valid} success_{a,e} * exp(-n_{a,e} . c_k)

Only the per-episode success flags and question counts are needed, so any
number of cost vectors ``c_k`` can be evaluated after a single rollout.

Cost vectors
    Costs are per-question-type penalties (unitless: a question of type t
    multiplies the episode's score by ``exp(-w_t)``). Only their sizes
    relative to each other change which kind of interaction is cheap, while
    their sum sets the overall price of asking; we therefore sample on the
    4-simplex scaled to the locked sum ``0.182 + 0.162 + 0.240 + 0.103 =
    0.687`` (:func:`cost_samples`, :func:`cost_grid`), so every vector has
    the locked overall price and the study isolates the allocation between
    types. Rows 0 and 1 are always the locked costs and uniform costs of the
    same sum (0.17175 each); row 0 is the reference ranking.

Efficiency
    The discount depends on an episode only through its count vector
    ``n_{a,e}``, and question counts are small integers, so across all agents
    and episodes there are few distinct count vectors U (typically tens to a
    few hundred). :func:`offline_wsr` sums the weights ``success * valid /
    count`` of the episodes sharing each count vector into a (U, X) matrix
    (X = agents x bins x thresholds), then evaluates
    ``question_discount(unique_counts, costs_chunk) @ weights`` for chunks of
    cost vectors inside one jitted ``lax.map``: K x U exponentials and a
    (K, U) x (U, X) matmul instead of K x A x E. 10^6 cost vectors x 500
    episodes x 5 agents take about a second on two CPU cores, in chunks of a
    few MB.

Rankings
    :func:`rankings` ranks agents per cost vector (1 = highest WSR, ties get
    their average rank); :func:`kendall_tau` is Kendall's tau-b (equal to
    ``scipy.stats.kendalltau``) of every row against the reference;
    :func:`flip_regions` summarises where the ranking differs from the locked
    one, and projects cost vectors onto the shares of two types for a map.
"""

from __future__ import annotations

import math
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.evaluate import metrics as M
from ignjax.studies.cost_derivation import simplex_grid
from ignjax.errors import ConfigError, InputError
from ignjax.protocol import LOCKED_COSTS
from ignjax.studies._common import as_array

LOCKED = np.asarray(LOCKED_COSTS, dtype=np.float64)
LOCKED_SUM = float(LOCKED.sum())
"""Sum of the locked costs, 0.687: the scale of sampled cost vectors."""
UNIFORM = np.full(4, LOCKED_SUM / 4)
"""Uniform costs with the locked sum (0.17175 per type)."""


# ---------------------------------------------------------------------------
# Cost vectors
# ---------------------------------------------------------------------------


def validate_costs(costs, where: str = "costs") -> np.ndarray:
    """Check cost vectors: shape (4,) or (K, 4), finite, non-negative, and no
    vector all zero.

    Returns:
        float64 array of the same shape.

    Raises:
        ConfigError: naming ``where`` (and the row, ``where[i]``) and the reason.
    """
    try:
        c = np.asarray(costs, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ConfigError(None, where, f"must be numbers, got {costs!r}") from e
    if c.ndim not in (1, 2) or c.shape[-1] != 4:
        raise ConfigError(None, where, f"must have shape (4,) or (K, 4) (one cost per question type), got {c.shape}")
    rows = c.reshape(-1, 4)
    if rows.shape[0] == 0:
        raise ConfigError(None, where, "holds no cost vector")

    def name(i):
        return f"{where}[{i}]" if c.ndim == 2 else where

    bad = ~np.isfinite(rows).all(1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ConfigError(None, name(i), f"has a NaN or infinite entry: {rows[i].tolist()}")
    bad = (rows < 0).any(1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ConfigError(None, name(i), f"has a negative cost: {rows[i].tolist()}")
    bad = (rows == 0).all(1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ConfigError(None, name(i), "all four costs are zero (WSR would equal SR); at least one must be positive")
    return c


def _check_total(total) -> float:
    total = LOCKED_SUM if total is None else total
    if not isinstance(total, (int, float)) or isinstance(total, bool) or not math.isfinite(total) or total <= 0:
        raise ConfigError(None, "cost_samples.total", f"must be a positive finite number, got {total!r}")
    return float(total)


def _include(include) -> np.ndarray:
    inc = np.stack([LOCKED, UNIFORM]) if include is None else validate_costs(include, "cost_samples.include")
    return inc.reshape(-1, 4)


def cost_samples(n: int, seed: int = 0, *, total: float | None = None, concentration=1.0, include=None) -> np.ndarray:
    """``n`` cost vectors: the ``include`` rows, then Dirichlet samples.

    Args:
        n: number of rows in all (at least ``len(include)``).
        seed: seed of ``numpy.random.default_rng``.
        total: the sum of every sampled vector (default: the locked sum 0.687).
        concentration: Dirichlet concentration, scalar or (4,); 1 (default)
            is uniform on the simplex.
        include: (I, 4) rows placed first; default (locked costs, uniform
            costs with the locked sum), so row 0 is the reference.

    Returns:
        (n, 4) float64.
    """
    total = _check_total(total)
    inc = _include(include)
    if not isinstance(n, (int, np.integer)) or n < len(inc):
        raise ConfigError(None, "cost_samples.n", f"must be an integer >= {len(inc)} (the included rows), got {n!r}")
    conc = np.broadcast_to(np.asarray(concentration, dtype=np.float64), (4,))
    if not (np.all(np.isfinite(conc)) and np.all(conc > 0)):
        raise ConfigError(None, "cost_samples.concentration", f"must be positive and finite, got {concentration!r}")
    rng = np.random.default_rng(seed)
    samples = rng.dirichlet(conc, size=int(n) - len(inc)) * total
    return np.concatenate([inc, samples], 0)


def cost_grid(step: float = 0.05, *, total: float | None = None, include=None) -> np.ndarray:
    """The include rows (default locked, uniform) followed by every point of a
    regular grid on the 4-simplex with spacing ``step``, scaled to ``total``
    (default the locked sum). Grid points with a zero entry are kept (a free
    question type) as long as some entry is positive.

    Returns:
        (I + G, 4) float64; G = C(1/step + 3, 3) (1771 for step 0.05).
    """
    if not isinstance(step, (int, float)) or not (0 < step <= 1) or abs(1 / step - round(1 / step)) > 1e-9:
        raise ConfigError(None, "cost_grid.step", f"must be 1/k for a positive integer k, got {step!r}")
    total = _check_total(total)
    return np.concatenate([_include(include), simplex_grid(step, dim=4) * total], 0)


# ---------------------------------------------------------------------------
# Offline WSR
# ---------------------------------------------------------------------------


@partial(jax.jit, static_argnames=("chunk",))
def _wsr_chunks(costs: jax.Array, counts: jax.Array, weights: jax.Array, chunk: int) -> jax.Array:
    """(Kp, 4) costs (Kp a multiple of ``chunk``), (U, 4) distinct count
    vectors, (U, X) summed episode weights -> (Kp, X)."""
    k = costs.shape[0]

    def one(c):  # (chunk, 4) -> (chunk, X)
        return M.question_discount(counts, c) @ weights  # (chunk, U) @ (U, X)

    return jax.lax.map(one, costs.reshape(k // chunk, chunk, 4)).reshape(k, weights.shape[1])


def _episode_mask(valid, shape, name="valid") -> np.ndarray:
    A, E = shape
    if valid is None:
        return np.ones((A, E), bool)
    v = as_array(valid, name, ndim=(1, 2))
    if v.shape not in ((E,), (A, E)):
        raise InputError(None, name, f"must have shape ({E},) or ({A}, {E}), got {v.shape}")
    return np.broadcast_to(v.astype(bool), (A, E))


def _bins(difficulty, shape, n_bins: int, name="difficulty") -> np.ndarray:
    A, E = shape
    d = as_array(difficulty, name, ndim=(1, 2))
    if d.shape not in ((E,), (A, E)):
        raise InputError(None, name, f"must have shape ({E},) or ({A}, {E}), got {d.shape}")
    if d.dtype.kind not in "iub" or d.size and (d.min() < 0 or d.max() >= n_bins):
        raise InputError(None, name, f"must be integer bin indices in 0..{n_bins - 1}")
    return np.broadcast_to(d.astype(np.int64), (A, E))


def offline_wsr(success, n_questions, valid, costs, *, difficulty=None, n_bins: int = 3,
                max_elements: int = 1 << 22) -> np.ndarray:
    """WSR of every agent under every cost vector.

    Args:
        success: (A, E) or (A, E, T) success flags (bool or 0/1), e.g.
            :func:`ignjax.evaluate.metrics.episode_success` per agent.
        n_questions: (A, E, 4) charged questions per type.
        valid: None, (E,) or (A, E) bool, rows that count.
        costs: (4,) or (K, 4) cost vectors (checked by :func:`validate_costs`).
        difficulty: optional (E,) or (A, E) bin index per episode; when
            given, WSR is computed per bin (mean over the bin's valid
            episodes; NaN for a bin without any).
        n_bins: number of difficulty bins.
        max_elements: size of the (chunk, U) discount block evaluated at once.

    Returns:
        float64 array of shape ``[K,] A, [n_bins,] [T]`` (K absent for a single
        (4,) cost vector, T absent for 2-D ``success``). Computed in float32
        (relative error ~1e-6).
    """
    s = as_array(success, "success", ndim=(2, 3))
    squeeze_t = s.ndim == 2
    s = s[..., None] if squeeze_t else s
    A, E, T = s.shape
    if s.dtype.kind == "f" and not np.all(np.isfinite(s)):
        raise InputError(None, "success", "contains NaN or infinite values")
    n = as_array(n_questions, "n_questions", ndim=3, last=4, finite=True)
    if n.shape[:2] != (A, E):
        raise InputError(None, "n_questions", f"must have shape ({A}, {E}, 4) to match success, got {n.shape}")
    if np.any(n < 0):
        raise InputError(None, "n_questions", "question counts must be non-negative")
    c = validate_costs(costs)
    single = c.ndim == 1
    c = c.reshape(-1, 4)
    v = _episode_mask(valid, (A, E))
    if difficulty is None:
        g, G = np.zeros((A, E), np.int64), 1
    else:
        g, G = _bins(difficulty, (A, E), n_bins), n_bins

    # Per-episode weights (A, E, G, T): success / |valid episodes of the agent (and bin)|.
    onehot = (g[..., None] == np.arange(G)) & v[..., None]  # (A, E, G)
    count = onehot.sum(1)  # (A, G)
    w = onehot[..., None] * s.astype(np.float64)[:, :, None, :] / np.maximum(count, 1)[:, None, :, None]
    # Episodes sharing a count vector share the discount: sum their weights.
    uniq, inv = np.unique(n.reshape(-1, 4), axis=0, return_inverse=True)
    U = uniq.shape[0]
    X = A * G * T
    rows = (inv.reshape(A, E) * A + np.arange(A)[:, None]).ravel()
    summed = np.zeros((U * A, G * T))
    np.add.at(summed, rows, w.reshape(A * E, G * T))
    weights = summed.reshape(U, X)  # column order (a, g, t)

    K = c.shape[0]
    chunk = int(max(1, min(K, max_elements // max(U, 1))))
    kp = -(-K // chunk) * chunk
    cp = np.zeros((kp, 4), np.float32)
    cp[:K] = c
    out = _wsr_chunks(jnp.asarray(cp), jnp.asarray(uniq, jnp.float32), jnp.asarray(weights, jnp.float32), chunk)
    out = np.asarray(out, dtype=np.float64)[:K].reshape(K, A, G, T)
    out = np.where((count == 0)[None, :, :, None], np.nan, out)
    if difficulty is None:
        out = out[:, :, 0]
    if squeeze_t:
        out = out[..., 0]
    return out[0] if single else out


# ---------------------------------------------------------------------------
# Rankings
# ---------------------------------------------------------------------------


def rankings(wsr, *, max_elements: int = 1 << 24) -> np.ndarray:
    """Rank agents per cost vector: 1 = highest WSR; tied agents share their
    average rank (as ``scipy.stats.rankdata(-x, method="average")``).

    Args:
        wsr: (K, A) or (A,), no NaN.

    Returns:
        float64 ranks of the same shape.
    """
    x = as_array(wsr, "wsr", ndim=(1, 2), dtype=np.float64)
    if np.isnan(x).any():
        raise InputError(None, "wsr", "contains NaN (e.g. an empty difficulty bin); rank finite values only")
    x2 = x.reshape(-1, x.shape[-1])
    A = x2.shape[1]
    out = np.empty_like(x2)
    step = max(1, max_elements // max(A * A, 1))
    for i in range(0, x2.shape[0], step):
        b = x2[i:i + step]
        gt = (b[:, None, :] > b[:, :, None]).sum(-1)  # agents strictly better than agent i
        eq = (b[:, None, :] == b[:, :, None]).sum(-1)  # including itself
        out[i:i + step] = 1 + gt + (eq - 1) / 2
    return out.reshape(x.shape)


def kendall_tau(a, b, *, max_elements: int = 1 << 24) -> np.ndarray:
    """Kendall's tau-b of each row of ``a`` against ``b``.

    tau_b = (n_c - n_d) / sqrt((n_0 - n_1)(n_0 - n_2)), n_1 and n_2 the pairs
    tied in ``a`` and in ``b``; computed as ``sum sign(da) sign(db) /
    sqrt(sum |sign(da)| sum |sign(db)|)`` over the A(A-1)/2 pairs. Equals
    ``scipy.stats.kendalltau(a_k, b_k).statistic``; NaN where a row (or ``b``)
    is all tied. Ranks and WSR values give the same tau.

    Args:
        a: (K, A) or (A,).
        b: (A,) or (K, A).

    Returns:
        (K,) float64, or a float for 1-D inputs.
    """
    x = as_array(a, "a", ndim=(1, 2), dtype=np.float64)
    y = as_array(b, "b", ndim=(1, 2), dtype=np.float64)
    if x.shape[-1] != y.shape[-1]:
        raise InputError(None, "b", f"must rank the same {x.shape[-1]} agents as a, got shape {y.shape}")
    scalar = x.ndim == 1 and y.ndim == 1
    x2, y2 = np.atleast_2d(x), np.atleast_2d(y)
    K = max(x2.shape[0], y2.shape[0])
    if x2.shape[0] not in (1, K) or y2.shape[0] not in (1, K):
        raise InputError(None, "b", f"row count {y2.shape[0]} does not match a's {x2.shape[0]}")
    i, j = np.triu_indices(x.shape[-1], 1)
    out = np.empty(K)
    step = max(1, max_elements // max(len(i), 1))
    for k0 in range(0, K, step):
        xa = x2[k0:k0 + step] if x2.shape[0] == K else x2
        ya = y2[k0:k0 + step] if y2.shape[0] == K else y2
        sa = np.sign(xa[:, i] - xa[:, j])
        sb = np.sign(ya[:, i] - ya[:, j])
        num = (sa * sb).sum(-1)
        den = np.sqrt(np.abs(sa).sum(-1) * np.abs(sb).sum(-1))
        with np.errstate(invalid="ignore", divide="ignore"):
            val = np.where(den > 0, num / np.where(den > 0, den, 1), np.nan)
        out[k0:k0 + step] = np.broadcast_to(val, (min(step, K - k0),))
    return float(out[0]) if scalar else out


def share_projection(costs, axes=(2, 3)) -> np.ndarray:
    """(K, 4) costs -> (K, 2) shares ``(w_i / sum w, w_j / sum w)`` of the two
    types in ``axes`` (0-based; default Type 3 route and Type 4
    confirmation). Points lie in the triangle x, y >= 0, x + y <= 1."""
    c = validate_costs(costs).reshape(-1, 4)
    i, j = _axes(axes)
    tot = c.sum(1)
    return np.stack([c[:, i] / tot, c[:, j] / tot], 1)


def _axes(axes) -> tuple[int, int]:
    try:
        i, j = (int(v) for v in axes)
    except (TypeError, ValueError) as e:
        raise ConfigError(None, "axes", f"must be two type indices in 0..3, got {axes!r}") from e
    if not (0 <= i < 4 and 0 <= j < 4 and i != j):
        raise ConfigError(None, "axes", f"must be two different type indices in 0..3, got {axes!r}")
    return i, j


def flip_regions(costs, tau, *, axes=(2, 3), bins: int = 20, tol: float = 1e-9) -> dict:
    """Where the ranking differs from the reference (locked) ranking.

    A cost vector *flips* the ranking when ``tau < 1 - tol`` (tau-b is 1
    exactly when both rankings order every pair the same way, ties
    included); a NaN tau (all agents tied, or fewer than two agents) counts
    as a flip.

    Args:
        costs: (K, 4) cost vectors.
        tau: (K,) Kendall tau-b against the reference (:func:`kendall_tau`).
        axes: the two types of the 2-D projection (:func:`share_projection`).
        bins: bins per axis of the flip-rate map over [0, 1]^2.

    Returns:
        dict with ``n``, ``n_flipped``, ``fraction_flipped``, ``flipped``
        (K,) bool, ``mean_costs_flipped`` / ``mean_costs_kept`` (4,) mean cost
        per type over flipping / non-flipping vectors (NaN if none),
        ``tau_mean``, ``tau_min``, ``xy`` (K, 2) projection, ``axes``,
        ``edges`` (bins + 1,), ``flip_rate`` (bins, bins) share of vectors in
        each cell (row = y bin, column = x bin) that flip (NaN where empty),
        ``cell_count`` (bins, bins).
    """
    c = validate_costs(costs).reshape(-1, 4)
    t = as_array(tau, "tau", ndim=1, dtype=np.float64)
    if t.shape[0] != c.shape[0]:
        raise InputError(None, "tau", f"must have one value per cost vector ({c.shape[0]}), got {t.shape[0]}")
    if not isinstance(bins, (int, np.integer)) or bins < 1:
        raise ConfigError(None, "bins", f"must be a positive integer, got {bins!r}")
    flipped = ~(t >= 1 - tol)
    nf = int(flipped.sum())
    mean_f = c[flipped].mean(0) if nf else np.full(4, np.nan)
    mean_k = c[~flipped].mean(0) if nf < len(c) else np.full(4, np.nan)
    xy = share_projection(c, axes)
    edges = np.linspace(0.0, 1.0, bins + 1)
    ix = np.clip(np.searchsorted(edges, xy[:, 0], side="right") - 1, 0, bins - 1)
    iy = np.clip(np.searchsorted(edges, xy[:, 1], side="right") - 1, 0, bins - 1)
    cell = iy * bins + ix
    cnt = np.bincount(cell, minlength=bins * bins).reshape(bins, bins)
    nfl = np.bincount(cell, weights=flipped.astype(float), minlength=bins * bins).reshape(bins, bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = np.where(cnt > 0, nfl / np.maximum(cnt, 1), np.nan)
    finite = t[np.isfinite(t)]
    return {
        "n": int(len(c)), "n_flipped": nf, "fraction_flipped": nf / len(c), "flipped": flipped,
        "mean_costs_flipped": mean_f, "mean_costs_kept": mean_k,
        "tau_mean": float(finite.mean()) if finite.size else float("nan"),
        "tau_min": float(finite.min()) if finite.size else float("nan"),
        "xy": xy, "axes": _axes(axes), "edges": edges, "flip_rate": rate, "cell_count": cnt,
    }


def marginal_curves(costs, wsr, bins: int = 20, se=None) -> dict:
    """Mean WSR of each agent as a function of each type's cost (averaging
    over the other types' costs among the sampled vectors).

    Args:
        costs: (K, 4).
        wsr: (K, A).
        bins: equal-width bins over each type's sampled cost range.
        se: optional (K, A) standard error of each WSR over the episodes
            (:func:`wsr_standard_error`).

    Returns:
        dict with ``edges`` (4, bins + 1), ``centers`` (4, bins), ``mean``
        (4, bins, A) (NaN in empty bins), ``count`` (4, bins); with ``se``,
        also ``se`` (4, bins, A): the bin's mean standard error.
    """
    c = validate_costs(costs).reshape(-1, 4)
    w = as_array(wsr, "wsr", ndim=2, dtype=np.float64)
    if w.shape[0] != c.shape[0]:
        raise InputError(None, "wsr", f"must have one row per cost vector ({c.shape[0]}), got {w.shape[0]}")
    edges = np.empty((4, bins + 1))
    mean = np.full((4, bins, w.shape[1]), np.nan)
    count = np.zeros((4, bins), np.int64)
    e = None if se is None else as_array(se, "se", ndim=2, dtype=np.float64)
    if e is not None and e.shape != w.shape:
        raise InputError(None, "se", f"must have the shape of wsr {w.shape}, got {e.shape}")
    mean_se = None if e is None else np.full_like(mean, np.nan)
    for t in range(4):
        lo, hi = float(c[:, t].min()), float(c[:, t].max())
        hi = hi if hi > lo else lo + 1e-12
        edges[t] = np.linspace(lo, hi, bins + 1)
        idx = np.clip(np.searchsorted(edges[t], c[:, t], side="right") - 1, 0, bins - 1)
        count[t] = np.bincount(idx, minlength=bins)
        sums = np.stack([np.bincount(idx, weights=w[:, a], minlength=bins) for a in range(w.shape[1])], -1)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean[t] = np.where(count[t][:, None] > 0, sums / np.maximum(count[t], 1)[:, None], np.nan)
            if e is not None:
                se_sums = np.stack([np.bincount(idx, weights=e[:, a], minlength=bins) for a in range(w.shape[1])], -1)
                mean_se[t] = np.where(count[t][:, None] > 0, se_sums / np.maximum(count[t], 1)[:, None], np.nan)
    out = {"edges": edges, "centers": (edges[:, 1:] + edges[:, :-1]) / 2, "mean": mean, "count": count}
    if mean_se is not None:
        out["se"] = mean_se
    return out


def wsr_standard_error(success, n_questions, valid, costs, wsr) -> np.ndarray:
    """(K, A) standard error over the episodes of each WSR in ``wsr`` (K, A)
    (success (A, E) at one threshold; the other arguments as
    :func:`offline_wsr`). A WSR is the mean of ``success * exp(-w . n)``;
    its second moment is the WSR under the doubled costs, since
    ``exp(-w . n) ** 2 = exp(-2 w . n)`` and ``success ** 2 = success``."""
    c = validate_costs(costs).reshape(-1, 4)
    second = offline_wsr(success, n_questions, valid, 2.0 * c)
    n = _episode_mask(valid, np.shape(success)[:2]).sum(1)  # (A,)
    var = np.maximum(second - np.asarray(wsr, np.float64) ** 2, 0.0)
    return np.sqrt(var / np.maximum(n - 1, 1))


def run_study(success, n_questions, valid, costs, *, agent_names=None, threshold_index: int | None = None,
              bins: int = 20, axes=(2, 3)) -> dict:
    """The whole cost-sensitivity study; row 0 of ``costs`` is the reference.

    Args:
        success: (A, E) or (A, E, T); with T thresholds, ``threshold_index``
            picks the one used for rankings (default: the middle one).
        n_questions, valid, costs: as :func:`offline_wsr`.
        agent_names: A names (default ``agent_0`` ...).

    Returns:
        dict with ``agent_names``, ``costs`` (K, 4), ``wsr`` (K, A[, T]),
        ``wsr_ranked`` (K, A) the WSR used for rankings, ``wsr_se`` (K, A)
        its standard error over the episodes (:func:`wsr_standard_error`),
        ``asks`` (A,) whether the agent asked at all, ``ranks`` (K, A),
        ``reference_ranks`` (A,), ``tau`` (K,), ``flips``
        (:func:`flip_regions`), ``marginals`` (:func:`marginal_curves`),
        ``threshold_index``.
    """
    c = validate_costs(costs).reshape(-1, 4)
    wsr = offline_wsr(success, n_questions, valid, c)
    if wsr.ndim == 3:
        ti = wsr.shape[2] // 2 if threshold_index is None else int(threshold_index)
        if not 0 <= ti < wsr.shape[2]:
            raise ConfigError(None, "threshold_index", f"must be in 0..{wsr.shape[2] - 1}, got {threshold_index}")
        ranked = wsr[:, :, ti]
    else:
        ti, ranked = None, wsr
    A = ranked.shape[1]
    names = [f"agent_{a}" for a in range(A)] if agent_names is None else [str(x) for x in agent_names]
    if len(names) != A:
        raise InputError(None, "agent_names", f"must name {A} agents, got {len(names)}")
    ranks = rankings(ranked)
    tau = kendall_tau(ranks, ranks[0])
    s_ranked = as_array(success, "success")
    s_ranked = s_ranked[..., ti] if s_ranked.ndim == 3 else s_ranked
    se = wsr_standard_error(s_ranked, n_questions, valid, c, ranked)
    return {"agent_names": names, "costs": c, "wsr": wsr, "wsr_ranked": ranked, "wsr_se": se, "ranks": ranks,
            "reference_ranks": ranks[0], "tau": tau, "flips": flip_regions(c, tau, axes=axes, bins=bins),
            "marginals": marginal_curves(c, ranked, bins=bins, se=se), "threshold_index": ti,
            "asks": np.asarray(n_questions).sum((1, 2)) > 0}


__all__ = ["LOCKED", "LOCKED_SUM", "UNIFORM", "validate_costs", "cost_samples", "cost_grid", "offline_wsr", "rankings",
           "kendall_tau", "share_projection", "flip_regions", "marginal_curves", "run_study", "wsr_standard_error"]
