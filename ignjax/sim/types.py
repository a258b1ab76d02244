"""Core simulator pytrees: configuration, state, actions, observations, answers.

Every array field documents its shape and dtype for ONE episode; under
``vmap`` a leading batch axis is added. All pytrees are frozen dataclasses
registered by :func:`ignjax.arrays.pytree_dataclass`; change them with
:func:`dataclasses.replace`. The rollout's records (:class:`OutcomeRow`,
:class:`Trajectory`) and what privileged agents receive (:class:`Privileged`)
live here too.

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

import dataclasses
import math
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from ignjax import protocol
from ignjax.arrays import pytree_dataclass
from ignjax.errors import ConfigError

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


@dataclass(frozen=True)
class SimConfig:
    """Static simulator configuration (hashable; shapes and limits).

    Attributes:
        max_steps: planner steps per episode (an ASK is a step); paper: 20.
        max_questions: questions charged per episode; paper: 10.
        horizon: longest waypoint a MOVE may command, metres; default 3.
        collision_distance: forward rays stop motion at this range, m; 0.6.
        collision_heights: heights of the forward collision rays, m.
        micro_step: longest single motion of the local controller, m.
        max_micro_steps: micro-steps per MOVE.
        eye_height: camera height, m.
        image_size: (W, H) of a view, pixels (for the grid-to-pixel map).
        hfov: horizontal field of view of each of the 8 views, degrees
            (the paper's 90: neighbours overlap by half). 4 and 12 views
            tile the circle instead, 360 / n_views degrees each
            (``view_hfov``), so with them this must stay 90. The symbolic observation's 8 sectors are this wide
            whatever ``n_views`` is.
        n_views: views of the egocentric panel (4, 8 or 12); a MOVE's
            ``direction`` k means view k, along ``heading + k * 360 / n_views``
            degrees (counter-clockwise), ``view_hfov`` degrees wide (90 with
            4 and 8 views, 30 with 12). The paper's
            agents use 8; 4 and 12 are its observation ablation. The
            symbolic observation keeps its 8 sectors whatever this is, and
            the built-in JAX agents plan with 8 views
            (:func:`ignjax.evaluate.runner.run_agent` refuses another value
            for them).
        depth_range: longest valid depth of a pixel ray, m.
        pullback: distance the waypoint is pulled back from a hit surface, m.
        waypoint_tolerance: a waypoint closer than this is reached, m.
        hint_lookahead: Type-3 hints look this far along the shortest path, m; 4.
        confirm_range: Type-4 says yes only within this distance, m; 3.
        stop_radius: a confirmed target this close means "stop now", m.
        hint_reached: the hinted point counts as reached within this, m.
        obs_rays_per_view: free-space rays per view in the observation.
        obs_range: range of observation rays and of visibility, m.
        max_visible: visible-instance slots in the observation.
        trace_len: question-trace slots (attempts, charged or refused); 0
            (default): ``max_steps``, one per possible attempt (:attr:`trace_slots`).
        question_budget: questions beyond ``max_questions`` are refused; false:
            no question is ever refused (an unbudgeted protocol, as the
            paper's naive rows read; docs/protocol.md, "Reading the paper's tables").
        upfront_description: the agent receives the target's full
            description (the Type-1 and Type-2 facts) at reset, charged as one
            Type-1 and one Type-2 question (counted in ``n_questions`` and
            the budget, not in the question trace).
        miss_rate: noisy perception: probability that an instance in sight is
            missed, at 3 m for an object 0.5 m across; it grows linearly with
            distance and shrinks with size (clipped to [0, 1]). 0: perfect.
        confusion_rate: noisy perception: probability that each perceived
            attribute (colour, material, size, state) is replaced by another
            value, scaled like ``miss_rate``. 0: perfect.
    """

    max_steps: int = protocol.MAX_STEPS
    max_questions: int = protocol.MAX_QUESTIONS
    horizon: float = 3.0
    collision_distance: float = protocol.COLLISION_DISTANCE
    collision_heights: tuple[float, ...] = (0.15, 0.6, 1.2)
    micro_step: float = 0.5
    max_micro_steps: int = 8
    eye_height: float = 1.25
    image_size: tuple[int, int] = (640, 640)
    hfov: float = 90.0
    n_views: int = N_VIEWS
    depth_range: float = 10.0
    pullback: float = 0.3
    waypoint_tolerance: float = 0.1
    hint_lookahead: float = protocol.HINT_LOOKAHEAD
    confirm_range: float = protocol.CONFIRM_RANGE
    stop_radius: float = 1.0
    hint_reached: float = 1.0
    obs_rays_per_view: int = 3
    obs_range: float = 6.0
    max_visible: int = 16
    trace_len: int = 0
    question_budget: bool = True
    upfront_description: bool = False
    miss_rate: float = 0.0
    confusion_rate: float = 0.0

    def __post_init__(self):
        if isinstance(self.trace_len, bool) or not isinstance(self.trace_len, int) or self.trace_len < 0:
            raise ConfigError(None, "sim.trace_len", f"must be 0 (max_steps) or a positive integer, got {self.trace_len!r}")
        for name in ("max_steps", "max_questions", "max_micro_steps", "obs_rays_per_view", "max_visible"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ConfigError(None, f"sim.{name}", f"must be a positive integer, got {v!r}")
        for name in ("horizon", "collision_distance", "micro_step", "eye_height", "hfov", "depth_range",
                     "hint_lookahead", "confirm_range", "stop_radius", "hint_reached", "obs_range"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise ConfigError(None, f"sim.{name}", f"must be a positive number, got {v!r}")
        for name in ("question_budget", "upfront_description"):
            if not isinstance(getattr(self, name), bool):
                raise ConfigError(None, f"sim.{name}", f"must be true or false, got {getattr(self, name)!r}")
        for name in ("miss_rate", "confusion_rate"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 <= v <= 1:
                raise ConfigError(None, f"sim.{name}", f"must be a probability in [0, 1], got {v!r}")
        for name in ("pullback", "waypoint_tolerance"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ConfigError(None, f"sim.{name}", f"must be a non-negative number, got {v!r}")
        heights = self.collision_heights
        if not isinstance(heights, (list, tuple)) or not heights or any(
                isinstance(h, bool) or not isinstance(h, (int, float)) or not math.isfinite(h) or h <= 0 for h in heights):
            raise ConfigError(None, "sim.collision_heights", f"must be a list of positive heights, got {heights!r}")
        size = self.image_size
        if not isinstance(size, (list, tuple)) or len(size) != 2 or any(
                isinstance(v, bool) or not isinstance(v, int) or v < 8 for v in size):
            raise ConfigError(None, "sim.image_size", f"must be [width, height] in pixels (>= 8), got {size!r}")
        if not 0 < self.hfov < 180:
            raise ConfigError(None, "sim.hfov", f"must lie in (0, 180) degrees, got {self.hfov}")
        if isinstance(self.n_views, bool) or self.n_views not in protocol.VIEW_COUNTS:
            raise ConfigError(None, "sim.n_views", f"must be 4, 8 or 12 views, got {self.n_views!r}")
        if self.n_views != N_VIEWS and self.hfov != protocol.VIEW_HFOV:
            raise ConfigError(None, "sim.hfov", f"sets the width of each of the 8 views; {self.n_views} views tile the "
                              f"circle ({360 / self.n_views:g} degrees each), so it must stay {protocol.VIEW_HFOV:g} "
                              f"with them, got {self.hfov}")
        if 0 < self.trace_len < self.max_steps:
            raise ConfigError(None, "sim.trace_len", f"must be >= max_steps ({self.max_steps}) to hold every question attempt")
        object.__setattr__(self, "collision_heights", tuple(float(h) for h in self.collision_heights))
        object.__setattr__(self, "image_size", tuple(int(v) for v in self.image_size))

    @classmethod
    def from_values(cls, values: dict, where: str | None = None) -> "SimConfig":
        """A configuration from ``field -> value`` (e.g. ``--set sim.*`` items);
        an unknown field is an error naming it and the known ones."""
        known = [f.name for f in dataclasses.fields(cls)]
        for key in values:
            if key not in known:
                raise ConfigError(where, f"sim.{key}", f"unknown key; known: {', '.join(known)}")
        return cls(**values)

    def to_dict(self) -> dict:
        """``field -> value`` (lists for tuples), as run.json records it."""
        return {f.name: list(v) if isinstance(v := getattr(self, f.name), tuple) else v for f in dataclasses.fields(self)}

    @property
    def view_hfov(self) -> float:
        """Horizontal field of view of each view of the panel, degrees
        (:func:`ignjax.protocol.view_hfov`): ``hfov`` for 8 views, 360 / n for
        4 and 12 (views that tile the circle). The renderers' cameras, the
        executor's back-projection of a grid cell and the oracle's "in the
        front view" test all use it."""
        return protocol.view_hfov(self.n_views, self.hfov)

    @property
    def trace_slots(self) -> int:
        """Slots of the question trace: ``trace_len``, or ``max_steps`` when it is 0."""
        return self.trace_len or self.max_steps



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
        stop_reason: () int32 (see the module docstring).
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
            state after the step (:class:`Answer` codes).
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


def tree_select(pred, on_true, on_false):
    """Elementwise ``where`` over two pytrees of the same structure; ``pred``
    selects along the leading axes (a () pred a whole tree, a (B,) pred rows
    of a batch)."""
    pred = jnp.asarray(pred)
    return jax.tree.map(lambda a, b: jnp.where(pred.reshape(pred.shape + (1,) * (jnp.ndim(a) - pred.ndim)), a, b),
                        on_true, on_false)


def numpy_tree(tree):
    """A pytree of device arrays as numpy arrays (host copy)."""
    return jax.tree.map(lambda a: np.asarray(a), tree)



def batch_of_one(tree):
    """A pytree with a leading batch axis of size 1 added to every leaf."""
    return jax.tree.map(lambda x: x[None], tree)


def only_row(tree):
    """Row 0 of a pytree with a leading batch axis (the inverse of :func:`batch_of_one`)."""
    return jax.tree.map(lambda x: x[0], tree)
