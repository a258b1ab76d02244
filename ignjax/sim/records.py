"""What a rollout records and what privileged agents receive: the outcome of
each episode (:class:`OutcomeRow`), its per-step record (:class:`Trajectory`)
and the privileged information (:class:`Privileged`).

The codes these records hold (action kinds, stop reasons, hint progress,
Type-4 candidates) are defined in :mod:`ignjax.sim.types`, which re-exports
the three classes.
"""

from __future__ import annotations

import dataclasses

import jax
import numpy as np

from ignjax.arrays import pytree_dataclass


@pytree_dataclass
class OutcomeRow:
    """One episode's outcome (arrays; a leading batch axis under vmap).

    Attributes:
        final_distance: () float32 geodesic distance to the target at the end.
        final_euclidean: () float32 2-D distance to the target footprint.
        min_distance: () float32 smallest geodesic distance along the path.
        path_length: () float32 metres travelled.
        steps: () int32 planner steps used.
        stopped: () bool, ended by STOP.
        stop_reason: () int32 (the codes of :mod:`ignjax.sim.types`).
        n_questions: (4,) int32 charged questions per type.
        n_refused: () int32 refused questions.
        n_invalid: () int32 clamped out-of-range actions.
        trace_type, trace_step, trace_charged: (T,) the question trace.
        difficulty: () int32 bin.
        valid: () bool.
    """

    final_distance: jax.Array
    final_euclidean: jax.Array
    min_distance: jax.Array
    path_length: jax.Array
    steps: jax.Array
    stopped: jax.Array
    stop_reason: jax.Array
    n_questions: jax.Array
    n_refused: jax.Array
    n_invalid: jax.Array
    trace_type: jax.Array
    trace_step: jax.Array
    trace_charged: jax.Array
    difficulty: jax.Array
    valid: jax.Array

    METRIC_FIELDS = ("final_distance", "min_distance", "path_length", "stopped", "n_questions", "difficulty")
    """The columns every metric needs (:mod:`ignjax.evaluate.metrics`)."""

    @staticmethod
    def from_numpy(**columns) -> "OutcomeRow":
        """Outcomes of many episodes from numpy columns (any leading shape).

        The :attr:`METRIC_FIELDS` are required; ``valid`` defaults to all
        True; other fields not given are zeros (``final_euclidean`` the
        final distance, question traces of length 0).
        """
        missing = [k for k in OutcomeRow.METRIC_FIELDS if k not in columns]
        if missing:
            raise TypeError(f"OutcomeRow.from_numpy: missing columns {missing}")
        shape = np.shape(columns["final_distance"])
        defaults = {"final_euclidean": columns["final_distance"], "valid": np.ones(shape, bool),
                    "steps": np.zeros(shape, np.int32), "stop_reason": np.zeros(shape, np.int32),
                    "n_refused": np.zeros(shape, np.int32), "n_invalid": np.zeros(shape, np.int32),
                    "trace_type": np.zeros(shape + (0,), np.int32), "trace_step": np.zeros(shape + (0,), np.int32),
                    "trace_charged": np.zeros(shape + (0,), bool)}
        unknown = set(columns) - {f.name for f in dataclasses.fields(OutcomeRow)}
        if unknown:
            raise TypeError(f"OutcomeRow.from_numpy: unknown columns {sorted(unknown)}")
        return OutcomeRow(**{f.name: np.asarray(columns[f.name] if f.name in columns else defaults[f.name])
                             for f in dataclasses.fields(OutcomeRow)})


@pytree_dataclass
class Trajectory:
    """Per-step record of one episode: what the agent decided on, what it
    decided, and what the simulator answered (what the episode viewer,
    :mod:`ignjax.view`, replays and the trajectory plots and interaction
    analyses read).

    S is ``max_steps``; the steps after the episode ended have ``kind ==
    -1`` (their other entries are the fill values below or repeat the final
    state). Everything the viewer
    words (the oracle's answers through :mod:`ignjax.sim.oracle_text`) is
    kept as the simulator's codes, not text, so the record stays a few
    hundred bytes per episode and step.

    Attributes:
        pose: (S + 1, 3) float32 pose before the first step and after each step.
        kind: (S,) int32 action kind of each step (-1 after the episode ended).
        question: (S,) int32 question type of ASK steps, 0 otherwise.
        direction, col, row: (S,) int32 the MOVE's view (0..7) and grid
            cell (column and row 1..8), as executed (clamped into range);
            -1 for other steps.
        candidate: (S,) int32 the instance handle a Type-4 question asked
            about (-1: "what is in front of me", and for other steps; -2: the
            question pointed at no object).
        waypoint: (S, 2) float32 the executor's waypoint of a MOVE (world);
            the pose before the step for other steps.
        blocked: (S, 8) bool headings (relative to the yaw before the MOVE,
            view layout) found blocked during a MOVE; False for other steps.
        refused: (S,) bool the step's question was refused (budget spent).
        n_questions: (S, 4) int32 charged questions per type after the step
            (the running cost discount; with ``upfront_description`` it
            starts at one Type-1 and one Type-2).
        confirm, follow_up: (S,) int32 the Type-4 answer and follow-up
            state after the step (:class:`~ignjax.sim.types.Answer` codes).
        hint_room_label, hint_sector, hint_landmark: (S,) int32 the Type-3
            answer's facts after the step.
        hint_in_room: (S,) bool the Type-3 route stays in the room.
        hint_progress: (S,) int32 the active hint's progress code after the step.
        room_label: (S,) int32 the room label the agent perceived when it
            decided (the observation before the step).
        visible: (S, K) int32 handles of the instances in sight when it
            decided (the scene's instance index; -1 empty), K = ``max_visible``.
        visible_attrs: (S, K, 4) int8 their perceived colour, material,
            size and state codes (differ from the scene's under perception
            noise; -1 unknown).
    """

    pose: jax.Array
    kind: jax.Array
    question: jax.Array
    direction: jax.Array
    col: jax.Array
    row: jax.Array
    candidate: jax.Array
    waypoint: jax.Array
    blocked: jax.Array
    refused: jax.Array
    n_questions: jax.Array
    confirm: jax.Array
    follow_up: jax.Array
    hint_room_label: jax.Array
    hint_sector: jax.Array
    hint_landmark: jax.Array
    hint_in_room: jax.Array
    hint_progress: jax.Array
    room_label: jax.Array
    visible: jax.Array
    visible_attrs: jax.Array

    STEP_FIELDS = ("kind", "question", "direction", "col", "row", "candidate", "waypoint", "blocked", "refused",
                   "n_questions", "confirm", "follow_up", "hint_room_label", "hint_sector", "hint_landmark",
                   "hint_in_room", "hint_progress", "room_label", "visible", "visible_attrs")
    """The fields with one entry per step (every field but ``pose``), in
    the order :func:`ignjax.sim.rollout.step_record` returns them."""


@pytree_dataclass
class Privileged:
    """Information only privileged agents receive (:func:`ignjax.sim.env.privileged_info`).

    Attributes:
        geodesic: () float32 geodesic distance to the target now.
        best_direction, best_col, best_row: () int32 the MOVE whose executor
            waypoint is geodesically closest to the target, among views
            0..7 x columns {3, 4, 5, 6} x rows {1, 2, 3}.
        best_value: () float32 geodesic distance at that waypoint.
    """

    geodesic: jax.Array
    best_direction: jax.Array
    best_col: jax.Array
    best_row: jax.Array
    best_value: jax.Array
