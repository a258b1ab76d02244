"""Scene look-ups for one episode that the executor, the oracle and the
observation share: grid cells, navigability, rooms, distances to the target
(geodesic from its field, Euclidean to its footprint), view sectors and
line of sight to an instance.
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp

from ignjax.sim import geometry as G
from ignjax.sim import types as T
from ignjax.sim.rays import queries as SR
from ignjax.sim.world import World


def cell_index(world: World, s, xy):
    """(row, col) int32: the navigation cell of ``xy`` (..., 2) in scene ``s`` (may lie outside the grid)."""
    g = world.bank.grid
    col = jnp.floor((xy[..., 0] - g.origin[s, 0]) / g.resolution).astype(jnp.int32)
    row = jnp.floor((xy[..., 1] - g.origin[s, 1]) / g.resolution).astype(jnp.int32)
    return row, col


def navigable_at(world: World, s, xy):
    """(...) bool: the cell containing ``xy`` (..., 2) is navigable in scene ``s``."""
    g = world.bank.grid
    row, col = cell_index(world, s, xy)
    inside = (row >= 0) & (col >= 0) & (row < g.shape[s, 0]) & (col < g.shape[s, 1])
    return inside & g.navigable[s, jnp.clip(row, 0, g.navigable.shape[1] - 1), jnp.clip(col, 0, g.navigable.shape[2] - 1)]


def room_at(world: World, s, xy):
    """() int32 room index at ``xy`` (-1 outside rooms)."""
    g = world.bank.grid
    row, col = cell_index(world, s, xy)
    inside = (row >= 0) & (col >= 0) & (row < g.shape[s, 0]) & (col < g.shape[s, 1])
    r = g.room[s, jnp.clip(row, 0, g.room.shape[1] - 1), jnp.clip(col, 0, g.room.shape[2] - 1)]
    return jnp.where(inside, r, -1)


def geodesic_to_target(world: World, ep: T.EpisodeSpec, xy):
    """() float32 geodesic distance from ``xy`` to the episode's target."""
    g = world.bank.grid
    row, col = cell_index(world, ep.scene, xy)
    inside = (row >= 0) & (col >= 0) & (row < g.shape[ep.scene, 0]) & (col < g.shape[ep.scene, 1])
    return jnp.where(inside, world.fields.at(ep.field, row, col), jnp.inf)


def euclidean_to_target(world: World, ep: T.EpisodeSpec, xy):
    """() float32 2-D distance from ``xy`` to the target's floor footprint."""
    inst = world.bank.instances
    c = inst.center[ep.scene, ep.target]
    h = inst.half_extents[ep.scene, ep.target]
    yaw = inst.yaw[ep.scene, ep.target]
    d = xy - c[:2]
    cy, sy = jnp.cos(yaw), jnp.sin(yaw)
    lx = d[0] * cy + d[1] * sy
    ly = -d[0] * sy + d[1] * cy
    return jnp.hypot(jnp.maximum(jnp.abs(lx) - h[0], 0.0), jnp.maximum(jnp.abs(ly) - h[1], 0.0))


def sector_of(rel):
    """Sector 0..7 (view layout) of a relative angle."""
    return (jnp.round(G.wrap_angle(rel) / (math.pi / 4)).astype(jnp.int32)) % 8


SIGHT_POINTS = 2
"""Points of an instance a sight line may reach: its box centre, then near its top."""


def sight_lines(world: World, s, i, eye):
    """The sight lines from ``eye`` to instance i (:data:`SIGHT_POINTS` of
    them: its box centre and near its top), each checked until it enters the
    box: (u (2, 3) unit directions, limit (2,) lengths checked), for
    :func:`ignjax.sim.rays.queries.segment_blocked`."""
    inst = world.bank.instances
    c = inst.center[s, i]
    h = inst.half_extents[s, i]
    yaw = inst.yaw[s, i]
    pts = jnp.stack([c, c.at[2].set(c[2] + h[2] * 0.9)])

    def one(p):
        d = p - eye
        L = jnp.linalg.norm(d)
        u = d / jnp.maximum(L, 1e-6)
        t_in = SR.box_entry(eye, u, c, h, yaw)
        before = L - jnp.minimum(t_in, L) + 0.06
        return SR.segment_ray(eye, p, before)

    return jax.vmap(one)(pts)


def sight_samples(world: World) -> tuple[float, int]:
    """(step, samples) of a sight line's march: every two navigation cells up to ``obs_range + 1`` m."""
    step = world.bank.grid.resolution * 2
    return step, int(math.ceil((world.config.obs_range + 1.0) / step))


def instance_in_sight(world: World, s, i, eye):
    """() bool: nothing blocks the view from ``eye`` to instance i's box
    (its centre or top centre) before the ray enters the box."""
    step, n = sight_samples(world)
    u, limit = sight_lines(world, s, i, eye)
    blocked = jax.vmap(lambda u_, l_: SR.segment_blocked(world.bank.rays, s, eye, u_, l_, step, 0, n,
                                                         world.columns))(u, limit)
    return jnp.any(~blocked) & world.bank.instances.valid[s, i]