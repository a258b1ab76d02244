"""The simulator's settings: :class:`SimConfig`, the static configuration every
episode of a rollout shares (step and question budgets, the executor's and
the oracle's distances, the panel's views, the observation's sizes,
perception noise).

It is the ``[sim]`` table of the sweep's configuration (:mod:`ignjax.config`
writes that table's defaults and comments from this class's fields and
docstring) and the static part of :class:`~ignjax.sim.world.World`, so part
of every compiled rollout program's key. Re-exported by :mod:`ignjax.sim.types`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from ignjax import protocol
from ignjax.errors import ConfigError


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
    n_views: int = protocol.N_VIEWS
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
        if self.n_views != protocol.N_VIEWS and self.hfov != protocol.VIEW_HFOV:
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
