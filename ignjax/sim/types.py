"""Core simulator pytrees: the codes, and what passes between agent and
simulator at each step (actions, observations, answers) with the episode's
fixed facts and state.

Every array field documents its shape and dtype for ONE episode; under
``vmap`` a leading batch axis is added. All pytrees are frozen dataclasses
registered by :func:`ignjax.arrays.pytree_dataclass`; change them with
:func:`dataclasses.replace`.

This module is also the simulator's one import for its types: it re-exports
the configuration (:class:`~ignjax.sim.simconfig.SimConfig`), the rollout's
records and what privileged agents receive (:class:`~ignjax.sim.records.OutcomeRow`,
:class:`~ignjax.sim.records.Trajectory`, :class:`~ignjax.sim.records.Privileged`)
and the pytree helpers of :mod:`ignjax.arrays` (``tree_select``,
``numpy_tree``, ``batch_of_one``, ``only_row``).

Codes
    Action kinds: ``MOVE = 0``, ``ASK = 1``, ``STOP = 2``.
    Question types: 1 appearance, 2 region, 3 route, 4 confirmation.
    Stop reasons: 0 running, 1 agent STOP, 2 step budget exhausted.
    Hint progress: 0 no hint, 1 closer, 2 no change, 3 farther,
    4 hinted area reached, 5 stop-eligible (target within the stop radius).
    Hint bearing: the hinted point's egocentric sector 0..7 from the current
    pose (view layout: 0 ahead, 2 left, 4 behind, 6 right), -1 no hint.
    Follow-up (after a positive Type-4 answer): 0 none, 1 stop now,
    2 one closer move then stop.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ignjax import protocol
from ignjax.arrays import batch_of_one, numpy_tree, only_row, pytree_dataclass, tree_select
from ignjax.sim.records import OutcomeRow, Privileged, Trajectory
from ignjax.sim.simconfig import SimConfig

MOVE, ASK, STOP = 0, 1, 2
ACTION_KINDS = ("move", "ask", "stop")
RUNNING, STOPPED, OUT_OF_STEPS, ABORTED = 0, 1, 2, 3
STOP_REASONS = ("running", "stop", "step_budget", "model_failure")
"""How an episode ended; ``model_failure``: an MLLM agent's requests kept
failing and the host loop ended the episode (it counts as a failure)."""
HINT_NONE, HINT_CLOSER, HINT_SAME, HINT_FARTHER, HINT_REACHED, HINT_STOP = 0, 1, 2, 3, 4, 5
HINT_PROGRESS = ("none", "closer", "no_change", "farther", "reached", "stop_eligible")
FOLLOW_NONE, FOLLOW_STOP_NOW, FOLLOW_ONE_MOVE = 0, 1, 2
ANY_CANDIDATE, NO_CANDIDATE = -1, -2
"""Type-4 candidates that are no instance: ``ANY_CANDIDATE`` asks about
whatever is in front (scripted agents; yes when the target is visible in
front within range), ``NO_CANDIDATE`` is a question that pointed at no
object (the answer is no: :mod:`ignjax.evaluate.candidates`)."""
N_VIEWS = protocol.N_VIEWS
N_QTYPES = protocol.N_QUESTION_TYPES


@pytree_dataclass
class Action:
    """One decision (int32 scalars; out-of-range values are clamped inside a
    rollout and counted as invalid; :func:`ignjax.sim.env.check_action`
    rejects them at the API boundary).

    Attributes:
        kind: () MOVE / ASK / STOP.
        direction: () view 0..n_views-1 (relative yaw k * 360 / n_views deg; 45 deg * k with 8) for MOVE.
        col: () grid column 1..8 (left to right) for MOVE.
        row: () grid row 1..8 (bottom to top) for MOVE.
        question: () question type 1..4 for ASK.
        candidate: () for Type 4: an instance handle from the observation's
            visible list, :data:`ANY_CANDIDATE` (-1) for "what is in front
            of me", or :data:`NO_CANDIDATE` (-2) for a question that pointed
            at no object (answered no).
    """

    kind: jax.Array
    direction: jax.Array
    col: jax.Array
    row: jax.Array
    question: jax.Array
    candidate: jax.Array

    @staticmethod
    def make(kind=MOVE, direction=0, col=4, row=2, question=1, candidate=-1) -> "Action":
        i = lambda v: jnp.asarray(v, jnp.int32)  # noqa: E731
        return Action(i(kind), i(direction), i(col), i(row), i(question), i(candidate))


@pytree_dataclass
class Answer:
    """What the oracle has said so far, as array facts (the latest answer of
    each type; text is rendered on the host by :mod:`ignjax.sim.oracle_text`).

    Attributes:
        known: (4,) bool, a type-t answer has been received.
        last_type: () int32 type of the latest answer (0: none yet).
        refused: () bool, the latest question was refused (budget).
        color, material, size, state: () int32 Type-1 attribute codes from
            the description's facts (-1 when the description does not say).
        on_category: () int32 Type-1: category of the support, -1 if unsaid.
        near_categories: (3,) int32 Type-1: anchor categories said, -1 pad.
        room_label: () int32 Type-2: goal room label code.
        region_category: () int32 Type-2: category of the region's anchor (-1).
        hint_room_label: () int32 Type-3: room label the route leads toward.
        hint_sector: () int32 Type-3: egocentric direction 0..7 of the route's
            first turn-off (0 ahead, 2 left, 4 behind, 6 right) at asking time.
        hint_landmark: () int32 Type-3: category of a landmark on the route (-1).
        hint_in_room: () bool Type-3: the route's first 4 m stay in this room.
        hint_active: () bool, a Type-3 hint is active.
        hint_progress: () int32 progress code (see module docstring).
        hint_bearing: () int32 egocentric sector 0..7 (view layout, as
            ``hint_sector``) of the active hint's point from the agent's
            current pose and heading, recomputed after every step that moves
            or turns the agent (every MOVE) and set when the hint is given;
            -1 while no hint is active. Qualitative, like the paper's
            controller reporting whether the hinted way lies ahead, left or
            right after a detour (Appendix, Eq. relative-target).
        confirm: () int32 Type-4: 1 yes, 0 no, -1 not asked.
        follow_up: () int32 follow-up state after a yes: 1 stop now, 2 one
            closer move then stop; after that move it becomes 1.

    Every field is a code or a flag (no float): an answer carries no
    coordinate, distance, heading or count along the route
    (:data:`AGENT_FIELDS` gives each field's reason).
    """

    known: jax.Array
    last_type: jax.Array
    refused: jax.Array
    color: jax.Array
    material: jax.Array
    size: jax.Array
    state: jax.Array
    on_category: jax.Array
    near_categories: jax.Array
    room_label: jax.Array
    region_category: jax.Array
    hint_room_label: jax.Array
    hint_sector: jax.Array
    hint_landmark: jax.Array
    hint_in_room: jax.Array
    hint_active: jax.Array
    hint_progress: jax.Array
    hint_bearing: jax.Array
    confirm: jax.Array
    follow_up: jax.Array

    @staticmethod
    def empty() -> "Answer":
        m1 = jnp.int32(-1)
        return Answer(known=jnp.zeros(4, bool), last_type=jnp.int32(0), refused=jnp.array(False), color=m1,
                      material=m1, size=m1, state=m1, on_category=m1, near_categories=jnp.full(3, -1, jnp.int32),
                      room_label=m1, region_category=m1, hint_room_label=m1, hint_sector=m1, hint_landmark=m1,
                      hint_in_room=jnp.array(False), hint_active=jnp.array(False),
                      hint_progress=jnp.int32(HINT_NONE), hint_bearing=m1, confirm=m1, follow_up=jnp.int32(FOLLOW_NONE))


@pytree_dataclass
class Observation:
    """What a policy may see (never the target's identity, pose or distance).

    Attributes:
        heading: () float32 own yaw, radians.
        odometry: (3,) float32 (dx, dy, dyaw) from the start pose, world axes.
        free_space: (8, R) float32 distance to the first obstacle along R
            horizontal rays spread over each view's field of view, at eye
            height and at knee height (the minimum), metres, capped at
            ``obs_range``.
        visible_handle: (K,) int32 instance handles of visible instances
            (-1 for empty slots), nearest first.
        visible_category: (K,) int32 category codes (bank vocabulary).
        visible_attrs: (K, 4) int32 colour, material, size, state codes (-1 unknown).
        visible_range: (K,) float32 distance to the instance, metres.
        visible_bearing: (K,) float32 relative bearing, radians (left positive).
        visible_view: (K,) int32 view 0..7 the instance appears in.
        room_label: () int32 label code of the room the agent stands in
            (a perception stand-in; -1 outside rooms).
        goal_category: () int32 category code of the instruction ("Find a laptop").
        steps_left: () int32 planner steps left.
        questions_left: () int32 questions left.
        n_questions: (4,) int32 charged questions per type so far.
        blocked: (8,) bool headings (relative to the current yaw, view
            layout) found blocked during the last MOVE.
        last_move: () float32 metres moved by the last MOVE.
    """

    heading: jax.Array
    odometry: jax.Array
    free_space: jax.Array
    visible_handle: jax.Array
    visible_category: jax.Array
    visible_attrs: jax.Array
    visible_range: jax.Array
    visible_bearing: jax.Array
    visible_view: jax.Array
    room_label: jax.Array
    goal_category: jax.Array
    steps_left: jax.Array
    questions_left: jax.Array
    n_questions: jax.Array
    blocked: jax.Array
    last_move: jax.Array


AGENT_FIELDS: dict[str, str] = {
    # Observation: perception and proprioception of the agent itself
    "Observation.heading": "own yaw from dead reckoning; says nothing about the target",
    "Observation.odometry": "own displacement since the start (dead reckoning), not a map coordinate of anything else",
    "Observation.free_space": "depth to the nearest obstacle per view, what the panorama shows",
    "Observation.visible_handle": "which instances are in sight (opaque ids, the same instance keeps its id); "
                                  "never says which one is the target",
    "Observation.visible_category": "perceived category of each instance in sight",
    "Observation.visible_attrs": "perceived colour / material / size / state of each instance in sight",
    "Observation.visible_range": "depth of each instance in sight, as the panorama's depth gives it",
    "Observation.visible_bearing": "direction of each instance in sight relative to the agent",
    "Observation.visible_view": "panorama view each instance appears in",
    "Observation.room_label": "the room the agent stands in, as the panorama shows it (a perception stand-in)",
    "Observation.goal_category": "the instruction ('find a laptop')",
    "Observation.steps_left": "the agent's own step budget",
    "Observation.questions_left": "the agent's own question budget",
    "Observation.n_questions": "questions the agent has been charged so far",
    "Observation.blocked": "headings the executor found blocked in the last MOVE (written into spatial memory, §3.3)",
    "Observation.last_move": "how far the last MOVE went (the agent's own motion)",
    # Answer: what the oracle said, as codes (text in ignjax.sim.oracle_text)
    "Answer.known": "which question types have been answered",
    "Answer.last_type": "type of the latest answer",
    "Answer.refused": "the latest question was refused (budget spent)",
    "Answer.color": "Type 1: the description's colour",
    "Answer.material": "Type 1: the description's material",
    "Answer.size": "Type 1: the description's size word",
    "Answer.state": "Type 1: the description's state word",
    "Answer.on_category": "Type 1: what the target stands on",
    "Answer.near_categories": "Type 1: objects the description says are near it",
    "Answer.room_label": "Type 2: the goal room's label",
    "Answer.region_category": "Type 2: the region's anchor object",
    "Answer.hint_room_label": "Type 3: the room the route leads toward",
    "Answer.hint_sector": "Type 3: egocentric direction of the way out ('to your left'); no angle, compass word or distance",
    "Answer.hint_landmark": "Type 3: a landmark on the route",
    "Answer.hint_in_room": "Type 3: the route's first stretch stays in this room",
    "Answer.hint_active": "Type 3: a spatial hint is active",
    "Answer.hint_progress": "Type 3: qualitative progress since the last move (closer / farther / reached / stop-eligible)",
    "Answer.hint_bearing": "Type 3: which way the hinted area lies now relative to the agent's facing (ahead / left / "
                           "behind / right, 8 sectors), as the paper's controller recomputes it after each move; "
                           "no angle, compass word or distance",
    "Answer.confirm": "Type 4: yes / no",
    "Answer.follow_up": "Type 4: the follow-up state after a yes (stop now / one closer move then stop)",
}
"""Every field an agent receives (:class:`Observation` and :class:`Answer`)
with the reason it may have it. The paper withholds from the Planner world
coordinates, path lengths, compass headings, step counts along the route
and target distances (§3.3); such facts stay in :class:`SimState` (e.g.
``hint_point``). A test fails when a field appears without an entry here."""


@pytree_dataclass
class EpisodeSpec:
    """The fixed facts of one episode, carried in the state (never observed
    directly; the oracle reads them).

    Attributes:
        scene: () int32 scene index in the bank.
        target: () int32 target instance index in its scene.
        field: () int32 index of the target's geodesic field.
        category: () int32 target category code.
        start: (3,) float32 start pose (x, y, yaw).
        difficulty: () int32 bin (0 easy, 1 medium, 2 hard).
        goal_room: () int32 goal room index in the scene (-1 unknown).
        fact_attrs: (4,) int32 the description's colour/material/size/state (-1 unsaid).
        fact_on: () int32 support category said by the description (-1).
        fact_near: (3,) int32 anchor categories said by the description (-1 pad).
        region_category: () int32 region anchor category of the Type-2 fact (-1).
        valid: () bool, a real episode (False for batch padding).
    """

    scene: jax.Array
    target: jax.Array
    field: jax.Array
    category: jax.Array
    start: jax.Array
    difficulty: jax.Array
    goal_room: jax.Array
    fact_attrs: jax.Array
    fact_on: jax.Array
    fact_near: jax.Array
    region_category: jax.Array
    valid: jax.Array


@pytree_dataclass
class SimState:
    """The state of one episode.

    Attributes:
        episode: the episode's fixed facts.
        pose: (3,) float32 (x, y, yaw).
        step: () int32 planner steps used.
        n_questions: (4,) int32 charged questions per type.
        n_refused: () int32 questions refused (budget exhausted), not charged.
        n_invalid: () int32 out-of-range actions clamped inside the rollout.
        trace_type: (T,) int32 question type of each attempt (0 = empty slot).
        trace_step: (T,) int32 planner step of each attempt (-1 = empty).
        trace_charged: (T,) bool, the attempt was charged (False: refused).
        n_trace: () int32 attempts recorded.
        path_length: () float32 metres travelled.
        min_distance: () float32 smallest geodesic distance to the target so far.
        done: () bool, the episode has ended.
        stop_reason: () int32 stop reason code.
        blocked: (8,) bool relative headings blocked during the last MOVE.
        last_move: () float32 metres moved by the last MOVE.
        waypoint: (2,) float32 the last MOVE's waypoint (world).
        moves_since_confirm: () int32 MOVEs since a positive Type-4 answer.
        hint_point: (2,) float32 world point ``hint_lookahead`` metres along
            the route of the last Type-3 answer (internal: progress is
            reported to the agent as a code, never this point).
        noise_key: (2,) uint32 key data of the episode's perception noise
            (used only when ``SimConfig.miss_rate`` or ``confusion_rate`` > 0).
        answers: the oracle's answers so far (see :class:`Answer`).
    """

    episode: EpisodeSpec
    pose: jax.Array
    step: jax.Array
    n_questions: jax.Array
    n_refused: jax.Array
    n_invalid: jax.Array
    trace_type: jax.Array
    trace_step: jax.Array
    trace_charged: jax.Array
    n_trace: jax.Array
    path_length: jax.Array
    min_distance: jax.Array
    done: jax.Array
    stop_reason: jax.Array
    blocked: jax.Array
    last_move: jax.Array
    waypoint: jax.Array
    moves_since_confirm: jax.Array
    hint_point: jax.Array
    noise_key: jax.Array
    answers: Answer


__all__ = [
    "ABORTED", "ACTION_KINDS", "AGENT_FIELDS", "ANY_CANDIDATE", "ASK", "FOLLOW_NONE", "FOLLOW_ONE_MOVE",
    "FOLLOW_STOP_NOW", "HINT_CLOSER", "HINT_FARTHER", "HINT_NONE", "HINT_PROGRESS", "HINT_REACHED", "HINT_SAME",
    "HINT_STOP", "MOVE", "NO_CANDIDATE", "N_QTYPES", "N_VIEWS", "OUT_OF_STEPS", "RUNNING", "STOP", "STOPPED",
    "STOP_REASONS", "Action", "Answer", "EpisodeSpec", "Observation", "SimState",
    # re-exported from their homes
    "SimConfig", "OutcomeRow", "Trajectory", "Privileged", "tree_select", "numpy_tree", "batch_of_one", "only_row",
]
