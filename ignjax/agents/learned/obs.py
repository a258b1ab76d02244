"""The observation vector of a learned policy: one fixed-size float32 vector
per episode, built from what the JAX agents may see and nothing else. The RL
environment (:mod:`ignjax.rl.env`, which re-exports this module as
:mod:`ignjax.rl.obs`) observes it and the ``learned`` agent
(:mod:`ignjax.agents.learned.agent`) computes it the same way, from the same
function, so the two cannot drift apart.

:func:`encode` reads the simulator's :class:`~ignjax.sim.types.Observation`,
the oracle's :class:`~ignjax.sim.types.Answer` (both on the allow-list
:data:`ignjax.sim.types.AGENT_FIELDS`) and the episode's question costs
(the environment's parameters, never the world): no target id, position or
distance can enter it. :func:`obs_layout` names every slice of the vector,
its size, the fields it is computed from and its meaning (docs/agents.md,
"Learned agents and the RL environment", lists them); a test checks that every
source is an allow-listed field or :data:`COSTS_SOURCE`.

Values are scaled to about [-1, 1] (distances by ``obs_range`` or
``horizon``, budgets by their maxima, codes one-hot), except the costs,
which are the costs themselves (0 .. a few).

Detections are compared with the facts known so far rather than given as
codes: per slot, whether the detection's category is the goal's, whether
each perceived attribute agrees (+1) or disagrees (-1) with what the Type-1
answer said (0 while unsaid), whether it is an object the description or
the Type-2 answer names (support, anchors, region anchor) or the Type-3
answer's landmark. The raw instance handles are not in the vector.
"""

from __future__ import annotations

from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.scenes import vocab
from ignjax.sim import types as T

COSTS_SOURCE = "EnvState.costs"
"""The source name of the episode's question costs (drawn from the environment's parameters, not the world)."""

N_ROOMS = len(vocab.ALL_ROOM_LABELS)
SLOT_FEATURES = ("present", "goal_category", "range", "sin_bearing", "cos_bearing", "in_front", "colour", "material",
                 "size", "state", "named_anchor", "hint_landmark")
"""The features of one visible-instance slot (the ``visible`` slice is ``max_visible`` of them, nearest first)."""
HOME_SCALE = 10.0
"""Metres that map to 1 in the ``home`` slice (clipped to [-1, 1])."""


@dataclass(frozen=True)
class Slice:
    """One named part of the observation vector: ``vector[start:start + size]``."""

    name: str
    start: int
    size: int
    sources: tuple[str, ...]
    meaning: str


def _parts(config: T.SimConfig) -> tuple[tuple[str, int, tuple[str, ...], str], ...]:
    R, K = config.obs_rays_per_view, config.max_visible
    A = "Answer."
    O = "Observation."  # noqa: E741
    return (
        ("free_space", 8 * R, (O + "free_space",), f"depth to the first obstacle, 8 sectors x {R} rays / obs_range"),
        ("blocked", 8, (O + "blocked",), "headings found blocked in the last MOVE (1 / 0)"),
        ("last_move", 1, (O + "last_move",), "metres the last MOVE went / horizon"),
        ("home", 4, (O + "heading", O + "odometry"),
         f"the start point relative to the agent's facing (forward, left) / {HOME_SCALE:g} m, sin and cos of the "
         "turn since the start"),
        ("room", N_ROOMS + 1, (O + "room_label",), "one-hot room label the agent stands in (last: outside rooms)"),
        ("room_facts", 2, (O + "room_label", A + "room_label", A + "hint_room_label"),
         "the room's label is the Type-2 answer's goal room; is the Type-3 answer's room"),
        ("visible", K * len(SLOT_FEATURES),
         (O + "visible_handle", O + "visible_category", O + "goal_category", O + "visible_range",
          O + "visible_bearing", O + "visible_view", O + "visible_attrs", A + "color", A + "material", A + "size",
          A + "state", A + "on_category", A + "near_categories", A + "region_category", A + "hint_landmark"),
         f"{K} slots, nearest first, each: " + ", ".join(SLOT_FEATURES)),
        ("known", 4, (A + "known",), "which question types have been answered"),
        ("last_answer", 5 + 1, (A + "last_type", A + "refused"), "one-hot type of the latest answer (0: none); refused"),
        ("confirm", 3 + 3, (A + "confirm", A + "follow_up"),
         "one-hot Type-4 answer (not asked / no / yes); one-hot follow-up (none / stop now / one closer move)"),
        ("hint", 1 + 6 + 9 + 9 + 1, (A + "hint_active", A + "hint_progress", A + "hint_bearing", A + "hint_sector",
                                     A + "hint_in_room"),
         "hint active; one-hot progress (6 codes); one-hot bearing and sector (none, 0..7); route stays in the room"),
        ("budget", 2 + 4, (O + "steps_left", O + "questions_left", O + "n_questions"),
         "steps left / max_steps, questions left / max_questions, charged questions per type / max_questions"),
        ("costs", 4 + 1, (COSTS_SOURCE, O + "n_questions"),
         "the episode's cost per question type w_t; the cost charged so far sum_t w_t n_t"),
    )


def obs_layout(config: T.SimConfig = T.SimConfig()) -> tuple[Slice, ...]:
    """The slices of the observation vector under ``config``, in order."""
    out, start = [], 0
    for name, size, sources, meaning in _parts(config):
        out.append(Slice(name, start, size, sources, meaning))
        start += size
    return tuple(out)


def obs_size(config: T.SimConfig = T.SimConfig()) -> int:
    """Length of the observation vector under ``config``."""
    last = obs_layout(config)[-1]
    return last.start + last.size


def obs_bounds(config: T.SimConfig = T.SimConfig()) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) of every entry: [-1, 1], and [0, inf) for the ``costs`` slice."""
    n = obs_size(config)
    low, high = np.full(n, -1.0, np.float32), np.full(n, 1.0, np.float32)
    for s in obs_layout(config):
        if s.name == "costs":
            low[s.start:s.start + s.size], high[s.start:s.start + s.size] = 0.0, np.inf
    return low, high


def _one_hot(code, lo: int, n: int):
    return jax.nn.one_hot(jnp.asarray(code, jnp.int32) - lo, n, dtype=jnp.float32)


def _agree(seen, said):
    """+1 the detection's attribute equals what the description said, -1 it differs, 0 unsaid or unknown."""
    known = (said >= 0) & (seen >= 0)
    return jnp.where(known, jnp.where(seen == said, 1.0, -1.0), 0.0)


def _slots(obs: T.Observation, answers: T.Answer, config: T.SimConfig):
    """(K, len(SLOT_FEATURES)) the visible-instance slots."""
    present = obs.visible_handle >= 0
    cat = obs.visible_category
    said = jnp.stack([answers.color, answers.material, answers.size, answers.state])
    agree = jax.vmap(lambda a: _agree(a, said))(obs.visible_attrs)  # Shape: (K, 4)
    named = jnp.concatenate([answers.on_category[None], answers.near_categories, answers.region_category[None]])
    anchor = jnp.any((cat[:, None] == named[None]) & (named[None] >= 0), axis=1)
    landmark = (cat == answers.hint_landmark) & (answers.hint_landmark >= 0)
    rng = jnp.where(present, jnp.minimum(obs.visible_range, config.obs_range) / config.obs_range, 0.0)
    cols = [present, present & (cat == obs.goal_category), rng, jnp.sin(obs.visible_bearing),
            jnp.cos(obs.visible_bearing), present & (obs.visible_view == 0)]
    out = jnp.concatenate([jnp.stack([c.astype(jnp.float32) for c in cols], -1), agree,
                           jnp.stack([present & anchor, present & landmark], -1).astype(jnp.float32)], -1)
    return jnp.where(present[:, None], out, 0.0)


def _home(obs: T.Observation):
    """The start point in the agent's frame (forward, left) / HOME_SCALE, and sin / cos of the turn since the start."""
    dx, dy, dyaw = -obs.odometry[0], -obs.odometry[1], obs.odometry[2]
    c, s = jnp.cos(obs.heading), jnp.sin(obs.heading)
    fwd, left = dx * c + dy * s, -dx * s + dy * c
    return jnp.concatenate([jnp.clip(jnp.stack([fwd, left]) / HOME_SCALE, -1.0, 1.0),
                            jnp.stack([jnp.sin(dyaw), jnp.cos(dyaw)])])


def encode(obs: T.Observation, answers: T.Answer, costs, config: T.SimConfig = T.SimConfig()) -> jax.Array:
    """The observation vector of one episode (vmap for a batch).

    Args:
        obs: the simulator's observation (:func:`ignjax.sim.env.observe`).
        answers: the oracle's answers so far (``SimState.answers``).
        costs: (4,) the episode's cost per question type.
        config: the simulator's configuration (scales and slot counts).

    Returns:
        (:func:`obs_size`,) float32, laid out as :func:`obs_layout`.
    """
    f32 = lambda x: jnp.asarray(x, jnp.float32).reshape(-1)  # noqa: E731
    a = answers
    room = jnp.where(obs.room_label >= 0, obs.room_label, N_ROOMS)
    in_room = obs.room_label >= 0
    q_max = config.max_questions if config.question_budget else config.max_steps
    costs = jnp.asarray(costs, jnp.float32)
    parts = [
        f32(jnp.minimum(obs.free_space, config.obs_range) / config.obs_range),
        f32(obs.blocked),
        f32(jnp.minimum(obs.last_move / config.horizon, 1.0)),
        _home(obs),
        _one_hot(room, 0, N_ROOMS + 1),
        f32(jnp.stack([in_room & (obs.room_label == a.room_label), in_room & (obs.room_label == a.hint_room_label)])),
        f32(_slots(obs, a, config)),
        f32(a.known),
        _one_hot(a.last_type, 0, 5), f32(a.refused),
        _one_hot(a.confirm, -1, 3), _one_hot(a.follow_up, 0, 3),
        f32(a.hint_active), _one_hot(a.hint_progress, 0, 6), _one_hot(a.hint_bearing, -1, 9),
        _one_hot(a.hint_sector, -1, 9), f32(a.hint_in_room),
        f32(obs.steps_left / config.max_steps), f32(obs.questions_left / q_max),
        f32(obs.n_questions / config.max_questions),
        costs, f32(jnp.dot(obs.n_questions.astype(jnp.float32), costs)),
    ]
    return jnp.concatenate(parts)


__all__ = ["COSTS_SOURCE", "HOME_SCALE", "SLOT_FEATURES", "Slice", "encode", "obs_bounds", "obs_layout", "obs_size"]
