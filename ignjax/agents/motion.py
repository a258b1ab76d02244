"""Where scripted agents move: a MOVE toward a relative bearing
(:func:`move_toward`, the grid cell whose executor waypoint lies that way)
and the most promising direction to explore (:func:`explore_direction`)."""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp

from ignjax.agents.memory import Memory, visit_index
from ignjax.sim import types as T
from ignjax.sim.geometry import wrap_angle


def move_toward(bearing, distance, config: T.SimConfig = T.SimConfig()) -> T.Action:
    """A MOVE whose executor waypoint lies toward ``bearing`` (relative,
    radians, left positive) at about ``distance`` metres on the floor
    (rows 1..3; shorter distances use the bottom row)."""
    W, H = config.image_size
    f = (W / 2) / math.tan(math.radians(config.hfov) / 2)
    k = (jnp.round(wrap_angle(bearing) / (math.pi / 4)).astype(jnp.int32)) % 8
    theta = wrap_angle(bearing - k.astype(jnp.float32) * (math.pi / 4))
    u = W / 2 - f * jnp.tan(theta)
    col = jnp.clip(jnp.floor(u / (W / 8)).astype(jnp.int32) + 1, 1, 8)
    phi = jnp.arctan2(config.eye_height, jnp.maximum(distance, 0.3))
    v = H / 2 + f * jnp.tan(jnp.minimum(phi, 1.5))
    row = jnp.clip(8 - jnp.floor(v / (H / 8)).astype(jnp.int32), 1, 3)
    return T.Action.make(T.MOVE, k, col, row)


def explore_direction(mem: Memory, obs: T.Observation, bias=None, bias_weight=0.0, rng=None):
    """Relative bearing of the most promising view to explore: long free
    space, few visits two metres ahead, not behind, not blocked; optionally
    biased toward an absolute heading (a route hint)."""
    rel = jnp.arange(8, dtype=jnp.float32) * (math.pi / 4)
    free = jnp.mean(jnp.minimum(obs.free_space, 4.0), axis=1)
    ahead = obs.odometry[:2][None] + 2.0 * jnp.stack([jnp.cos(obs.heading + rel), jnp.sin(obs.heading + rel)], -1)
    ij = jax.vmap(visit_index)(ahead)
    seen = mem.visits[ij[:, 1], ij[:, 0]].astype(jnp.float32)
    rear = jnp.array([0, 0, 0, 1, 1, 1, 0, 0], jnp.float32)
    score = free - 0.8 * seen - 0.6 * rear - 2.0 * obs.blocked.astype(jnp.float32)
    score = jnp.where(free < 0.8, score - 3.0, score)
    if bias is not None:
        score = score + bias_weight * jnp.cos(wrap_angle(bias - (obs.heading + rel)))
    if rng is not None:
        score = score + 0.3 * jax.random.uniform(rng, (8,))
    k = jnp.argmax(score)
    return rel[k], free[k]


__all__ = ["explore_direction", "move_toward"]
