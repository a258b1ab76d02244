"""The paper's protocol constants: one source for every module.

Everything here is fixed by the paper ("Ask When It Pays", §3-§4 and the
appendices) or by the conventions of DESIGN.md. Values a study may vary
(costs, thresholds, difficulty coefficients) are only the *defaults* here;
they are passed as configuration everywhere else.

* Question types are int32 codes 1..4; index ``t - 1`` of every per-type
  array (costs, counts) is type ``t``.
* The locked costs ``w`` charge each question in the Weighted Success Rate,
  ``WSR_e(tau) = 1{d_e <= tau} * exp(-sum_t w_t n_{e,t})``.
* Difficulty ``D = alpha . (F_distractor, F_room, F_context, F_start)``;
  easy ``D < 0.30``, medium ``D < 0.60``, hard otherwise; the evaluation
  subset is sampled 30:40:30.
* Views: ``N_VIEWS`` first-person views, view ``k`` at relative yaw
  ``+45 degrees * k`` (counter-clockwise, so 2 is left), each ``VIEW_HFOV``
  = 90 degrees wide, so neighbours overlap by half (the paper's main
  setting). The observation ablation's 4 and 12 views tile the circle
  instead, ``360 / n`` degrees each (:func:`view_hfov`).
"""

from __future__ import annotations

QUESTION_TYPES: tuple[str, ...] = ("appearance", "region", "route", "confirmation")
"""Question type names; type code ``t`` (1..4) is ``QUESTION_TYPES[t - 1]``."""
N_QUESTION_TYPES = len(QUESTION_TYPES)
TYPE_LABELS: tuple[str, ...] = tuple(f"Type {t} {name}" for t, name in enumerate(QUESTION_TYPES, 1))
"""Short labels of the question types for tables and figures."""

LOCKED_COSTS: tuple[float, float, float, float] = (0.182, 0.162, 0.240, 0.103)
"""The paper's locked per-type question costs (Type 1 appearance, 2 region, 3 route, 4 confirmation)."""

SUCCESS_THRESHOLDS: tuple[float, ...] = (0.5, 1.5, 3.0)
"""Success distances tau (m) of the paper's SR / OSR / WSR columns."""
SUCCESS_REQUIRES_STOP = False
"""The paper's success rule (Eq. wsr, §4.1): ``d_e <= tau`` on the final
distance, whether the episode ended by STOP or by the step budget. True is
Habitat's convention (success also needs an explicit STOP), an option."""

MAX_STEPS = 20
"""Planner steps per episode (an ASK is a step)."""
MAX_QUESTIONS = 10
"""Questions per episode."""
COLLISION_DISTANCE = 0.6
"""Collision rays stop motion at this distance, m."""
HINT_LOOKAHEAD = 4.0
"""Type-3 hints look this far along the shortest path, m."""
CONFIRM_RANGE = 3.0
"""Type 4 says yes only if the target is in the front view and this close, m."""

DIFFICULTY_ALPHA: tuple[float, float, float, float] = (0.35, 0.25, 0.15, 0.25)
"""Weights of (F_distractor, F_room, F_context, F_start) in the difficulty D."""
DIFFICULTY_THRESHOLDS: tuple[float, float] = (0.30, 0.60)
"""Bin edges of D: easy below the first, medium below the second, hard otherwise."""
SUBSET_PROPORTIONS: tuple[float, float, float] = (0.3, 0.4, 0.3)
"""easy : medium : hard proportions of the evaluation subset."""
FACTOR_NAMES: tuple[str, ...] = ("F_distractor", "F_room", "F_context", "F_start")
BIN_NAMES: tuple[str, ...] = ("easy", "medium", "hard")
BIN_INDEX = {name: i for i, name in enumerate(BIN_NAMES)}

N_VIEWS = 8
VIEW_NAMES: tuple[str, ...] = ("front", "front-left", "left", "rear-left", "rear", "rear-right", "right", "front-right")
"""View ``k`` of the 8-view panel looks along ``yaw + k * 45 degrees``."""
VIEW_HFOV = 90.0
"""Horizontal field of view of each of the 8 views, degrees (the paper's "90 degree Field-of-View RGB view",
centres 45 degrees apart: neighbours overlap by half)."""
VIEW_COUNTS: tuple[int, ...] = (4, 8, 12)
"""Panel sizes: 8 (the paper's main setting) and the observation ablation's 4 and 12."""


def view_hfov(n_views: int, hfov8: float = VIEW_HFOV) -> float:
    """Horizontal field of view of each view of an ``n_views`` panel, degrees.

    8 views are ``hfov8`` wide each (the paper's 90 degrees; they overlap).
    4 and 12 views tile the circle: ``360 / n_views`` each, so 4 views are
    90 degrees (the paper's "4 views (90 degrees only)") and 12 views are
    30 degrees (its "12 narrow views": "each view becomes narrower"); the
    right edge of view k is the left edge of view k - 1, with no overlap and
    no gap. Our reading: the paper gives no width for its narrow views, and
    360 / 12 is the width at which 12 views cover the circle exactly once,
    as its 4 views do.
    """
    if isinstance(n_views, bool) or n_views not in VIEW_COUNTS:
        raise ValueError(f"n_views must be one of {VIEW_COUNTS}, got {n_views!r}")
    return float(hfov8) if n_views == N_VIEWS else 360.0 / n_views

GRID_CELLS = 8
"""The Grounder's grid is GRID_CELLS x GRID_CELLS: columns 1..8 left to right, rows 1..8 bottom to top."""

__all__ = [
    "QUESTION_TYPES", "N_QUESTION_TYPES", "TYPE_LABELS", "LOCKED_COSTS", "SUCCESS_THRESHOLDS", "SUCCESS_REQUIRES_STOP", "MAX_STEPS",
    "MAX_QUESTIONS", "COLLISION_DISTANCE", "HINT_LOOKAHEAD", "CONFIRM_RANGE", "DIFFICULTY_ALPHA",
    "DIFFICULTY_THRESHOLDS", "SUBSET_PROPORTIONS", "FACTOR_NAMES", "BIN_NAMES", "BIN_INDEX", "N_VIEWS", "VIEW_NAMES",
    "VIEW_HFOV", "VIEW_COUNTS", "view_hfov", "GRID_CELLS",
]
