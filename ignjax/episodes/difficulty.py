"""Episode difficulty as array programs.

The paper's construction-time difficulty (Appendix B, Eq. difficulty) is

    D = alpha_1 F_distractor + alpha_2 F_room + alpha_3 F_context + alpha_4 F_start

with alpha = (0.35, 0.25, 0.15, 0.25) and bins easy D < 0.30, medium
0.30 <= D < 0.60, hard D >= 0.60. Every factor lies in [0, 1]. The paper
states what each factor grows with but not its exact normalisation; ours
(all constants are fields of :class:`FactorNorms`):

``F_distractor = min(1, log(1 + n_d) / log(1 + distractor_cap))``
    n_d = number of same-category distractors in the scene (instances of
    the target's category other than the target). Log scale capped at 1;
    with the default cap of 16 the factor is 0 with no distractor, 0.39
    with 2, 0.63 with 5, 0.85 with 10 and 1 from 16 on.

``F_room = min(1, log(1 + n_r) / log(1 + room_cap))``
    n_r = same-category distractors in the target's room; default cap 4
    (0 with none, 0.43 with one, 0.68 with two, 1 from four on).

``F_context = 1 - rho``
    rho = fraction of the target's nearby non-structural anchors (within
    the construction's anchor radius) whose category appears among the
    nearby anchors of none of its distractors. Two edge cases: with no
    distractor there is nothing to disambiguate and rho = 1; with
    distractors but no anchors, relations cannot help and rho = 0.

``F_start = min(1, d_start / start_cap)``
    d_start = geodesic distance from the start pose to the target
    (metres, see :mod:`ignjax.scenes.navgrid`), default cap 15 m.

All functions accept numpy or JAX arrays with any leading batch
dimensions and broadcast factors against several alpha vectors and
thresholds at once, so a study can score every episode under every
setting in one call (they are jit-able and vmappable). Given numpy
float64 inputs they compute in numpy float64 (what the episode builder
stores, so a record's ``D`` equals ``alpha . factors`` exactly); given
JAX arrays they stay in JAX.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import jax.numpy as jnp
import numpy as np

from ignjax.arrays import xp as _xp
from ignjax.errors import ConfigError
from ignjax.protocol import BIN_INDEX, BIN_NAMES, FACTOR_NAMES  # noqa: F401  (re-exported for the episode code)
from ignjax.protocol import DIFFICULTY_ALPHA as DEFAULT_ALPHA
from ignjax.protocol import DIFFICULTY_THRESHOLDS as DEFAULT_THRESHOLDS


@dataclass(frozen=True)
class FactorNorms:
    """Normalisation constants of the four difficulty factors (see module doc).

    Attributes:
        distractor_cap: distractor count at which F_distractor reaches 1.
        room_cap: same-room distractor count at which F_room reaches 1.
        start_cap: start geodesic distance (m) at which F_start reaches 1.
    """

    distractor_cap: float = 16.0
    room_cap: float = 4.0
    start_cap: float = 15.0

    def __post_init__(self):
        for name in ("distractor_cap", "room_cap", "start_cap"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ConfigError(None, f"difficulty.{name}", f"must be a positive finite number, got {v!r}")


def context_rho(n_anchors, n_unique, n_distractors):
    """rho from anchor counts, with the edge cases of the module docstring."""
    xp = _xp(n_anchors, n_unique, n_distractors)
    n_anchors = xp.asarray(n_anchors)
    frac = xp.asarray(n_unique) / xp.maximum(n_anchors, 1)
    return xp.where(xp.asarray(n_distractors) == 0, 1.0, xp.where(n_anchors == 0, 0.0, frac))


def difficulty_factors(n_distractors, n_same_room, rho, start_distance, norms: FactorNorms = FactorNorms()):
    """The four factors, stacked on a new last axis.

    Args:
        n_distractors: (...,) same-category distractors in the scene.
        n_same_room: (...,) of those, in the target's room.
        rho: (...,) unique-anchor fraction in [0, 1].
        start_distance: (...,) geodesic start-to-target distance, metres.
        norms: normalisation constants.

    Returns:
        (..., 4) factors (F_distractor, F_room, F_context, F_start) in [0, 1].
    """
    xp = _xp(n_distractors, n_same_room, rho, start_distance)
    nd = xp.asarray(n_distractors, dtype=xp.float64 if xp is np else jnp.float32)
    nr = xp.asarray(n_same_room, dtype=nd.dtype)
    f_d = xp.minimum(1.0, xp.log1p(nd) / math.log1p(norms.distractor_cap))
    f_r = xp.minimum(1.0, xp.log1p(nr) / math.log1p(norms.room_cap))
    f_c = 1.0 - xp.clip(xp.asarray(rho, dtype=nd.dtype), 0.0, 1.0)
    f_s = xp.clip(xp.asarray(start_distance, dtype=nd.dtype) / norms.start_cap, 0.0, 1.0)
    return xp.stack(xp.broadcast_arrays(f_d, f_r, f_c, f_s), axis=-1)


def difficulty_score(factors, alpha=DEFAULT_ALPHA):
    """D = alpha . F.

    Args:
        factors: (..., 4).
        alpha: (4,) or (K, 4) coefficient vectors; with (K, 4) and factors
            (E, 4) the result is (K, E) (every setting scores every episode).

    Returns:
        D with shape ``alpha.shape[:-1] + factors.shape[:-1]``.
    """
    xp = _xp(factors, alpha)
    f = xp.asarray(factors)
    a = xp.asarray(alpha, dtype=f.dtype)
    return xp.tensordot(a, f, axes=([-1], [-1])) if a.ndim > 1 else f @ a


def difficulty_bin(score, thresholds=DEFAULT_THRESHOLDS):
    """Bin index 0 easy (D < t0), 1 medium (t0 <= D < t1), 2 hard (D >= t1).

    Args:
        score: (...,) difficulty scores.
        thresholds: (2,) or (..., 2) broadcastable against ``score[..., None]``;
            with ``score`` (K, E) pass (K, 1, 2) for per-setting thresholds.

    Returns:
        int32 bins with the broadcast shape.
    """
    xp = _xp(score, thresholds)
    d = xp.asarray(score)
    t = xp.asarray(thresholds, dtype=d.dtype)
    return ((d >= t[..., 0]).astype(xp.int32) + (d >= t[..., 1]).astype(xp.int32)).astype(xp.int32)


def score_and_bin(factors, alphas, thresholds):
    """Score and bin every episode under every (alpha, thresholds) setting.

    Args:
        factors: (E, 4).
        alphas: (K, 4).
        thresholds: (K, 2).

    Returns:
        (D (K, E), bins (K, E) int32).
    """
    xp = _xp(factors, alphas, thresholds)
    d = difficulty_score(factors, alphas)
    t = xp.asarray(thresholds)[:, None, :]
    return d, difficulty_bin(d, t)


def validate_alpha(alpha, *, normalize: bool = False, where: str = "alpha") -> tuple[float, float, float, float]:
    """Check a coefficient vector: 4 finite non-negative entries summing to 1.

    With ``normalize=True`` a vector with a positive sum is rescaled to sum 1
    instead of being rejected.

    Raises:
        ConfigError: naming ``where`` and the reason.
    """
    try:
        a = [float(v) for v in alpha]
    except (TypeError, ValueError) as e:
        raise ConfigError(None, where, f"must be 4 numbers, got {alpha!r}") from e
    if len(a) != 4:
        raise ConfigError(None, where, f"must have 4 entries (distractor, room, context, start), got {len(a)}")
    if any(math.isnan(v) or math.isinf(v) for v in a):
        raise ConfigError(None, where, f"has a NaN or infinite entry: {a}")
    if any(v < 0 for v in a):
        raise ConfigError(None, where, f"has a negative entry: {a}")
    s = sum(a)
    if abs(s - 1.0) > 1e-6:
        if normalize and s > 0:
            a = [v / s for v in a]
        else:
            raise ConfigError(None, where, f"entries must sum to 1 (got {s:.6g}); pass normalisation explicitly to rescale")
    return tuple(a)  # type: ignore[return-value]


def validate_thresholds(thresholds, where: str = "thresholds") -> tuple[float, float]:
    """Check bin thresholds: two finite numbers with 0 <= t0 < t1 <= 1."""
    try:
        t = [float(v) for v in thresholds]
    except (TypeError, ValueError) as e:
        raise ConfigError(None, where, f"must be 2 numbers, got {thresholds!r}") from e
    if len(t) != 2 or any(math.isnan(v) or math.isinf(v) for v in t):
        raise ConfigError(None, where, f"must be 2 finite numbers, got {thresholds!r}")
    if not (0.0 <= t[0] < t[1] <= 1.0):
        raise ConfigError(None, where, f"must satisfy 0 <= easy/medium < medium/hard <= 1, got {t}")
    return (t[0], t[1])
