"""Ray queries of the simulator, written for one episode and vmapped once.

Two kinds of query serve the rollouts:

* :func:`cast` - general 3-D rays (the executor's pixel depth), answered by
  the exact fast path :func:`ignjax.sim.raycast.fast_rays`. ``fast_rays``
  is fastest on one large batch (it gathers unfinished rays into dense
  sub-batches), while a ``vmap`` of a single-ray ``while_loop`` costs as
  much as its slowest lane. :func:`cast` is therefore a
  :func:`jax.custom_batching.custom_vmap` function: code written for one
  episode calls it with that episode's K rays, and under ``vmap`` (at any
  nesting depth: agents x cost vectors x episodes) the batch axes are
  flattened and every ray of the batch is cast in one ``fast_rays`` call.
* :func:`horizontal_free` and :func:`segment_clear` - the many short
  queries of collision checks, free-space observations and visibility,
  answered by fixed-step marches over the voxel occupancy (``voxcode <= 1``
  of the ray grid, a conservative voxelization): a fixed number of samples
  at a fixed spacing, so their cost under ``vmap`` is predictable. A hit is
  reported at the first occupied sample: never later than the true surface
  by more than the spacing (corner grazes thinner than the spacing aside),
  and early only where a real surface lies within about one voxel diagonal
  of the stopping sample (a ray grazing a wall). Leaving the grid counts as
  a hit: the exterior behind an outside door behaves like a wall.
  ``tests/test_sim.py`` measures these bounds against ``mj_ray`` (about 93%
  of collision rays agree with it within one cell).
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
from jax import custom_batching

from ignjax.sim.raycast import RayGrid, fast_rays

_OCCUPIED_MAX_CODE = 1  # voxcode 0: partly occupied, 1: inside a primitive, 2: free but touched, >= 3: free


@custom_batching.custom_vmap
def cast(grid: RayGrid, pnts: jax.Array, vecs: jax.Array, max_dist: jax.Array, scene: jax.Array) -> jax.Array:
    """Distances of K rays of one scene (exact fast path, floor included).

    Args:
        grid: the bank's ray grid (never batched).
        pnts: (K, 3) origins.
        vecs: (K, 3) unit directions.
        max_dist: (K,) ranges, metres.
        scene: (K,) int32 scene of each ray.

    Returns:
        (K,) float32 distances, +inf on a miss.
    """
    return fast_rays(grid, pnts, vecs, max_dist, scene)[0]


@cast.def_vmap
def _cast_batched(axis_size, in_batched, grid, pnts, vecs, max_dist, scene):
    grid_batched = any(jax.tree.leaves(in_batched[0]))
    if grid_batched:  # a batched grid is not supported by the flattening rule: fall back to a loop
        return jax.lax.map(lambda a: cast(*a), (grid, pnts, vecs, max_dist, scene)), True
    def lift(x, batched):
        return x if batched else jnp.broadcast_to(x, (axis_size,) + x.shape)

    pnts = lift(pnts, in_batched[1])
    vecs = lift(vecs, in_batched[2])
    max_dist = lift(max_dist, in_batched[3])
    scene = lift(scene, in_batched[4])
    k = pnts.shape[1]
    # Shape: (B * K, ...) - one flat batch; nested vmaps flatten again through `cast` itself
    out = cast(grid, pnts.reshape(-1, 3), vecs.reshape(-1, 3), max_dist.reshape(-1), scene.reshape(-1))
    return out.reshape(axis_size, k), True


def _occupied(grid: RayGrid, scene, k, row, col):
    """Occupancy of voxel (k, row, col) of a scene; outside the valid grid counts as occupied."""
    W, H, Z = grid.dims[scene, 0], grid.dims[scene, 1], grid.dims[scene, 2]
    inside = (col >= 0) & (col < W) & (row >= 0) & (row < H)
    above = k >= Z
    code = grid.voxcode[scene, jnp.clip(k, 0, grid.voxcode.shape[1] - 1), jnp.clip(row, 0, grid.voxcode.shape[2] - 1),
                        jnp.clip(col, 0, grid.voxcode.shape[3] - 1)]
    occ = code <= _OCCUPIED_MAX_CODE
    return jnp.where(inside, jnp.where(above | (k < 0), False, occ), True)


def horizontal_free(grid: RayGrid, scene, xy, heading, height: float, max_dist: float, step: float):
    """Free distance along a horizontal ray (fixed-step march).

    Args:
        grid: ray grid.
        scene: () int32 scene index.
        xy: (2,) start point.
        heading: () direction, radians.
        height: ray height above the floor, metres (static).
        max_dist: range, metres (static).
        step: sample spacing, metres (static).

    Returns:
        () float32: distance of the first occupied sample, ``max_dist`` when
        none is occupied within range.
    """
    n = int(math.ceil(max_dist / step))
    t = (jnp.arange(1, n + 1, dtype=jnp.float32)) * step  # Shape: (n,)
    x = xy[0] + t * jnp.cos(heading)
    y = xy[1] + t * jnp.sin(heading)
    res = grid.resolution
    col = jnp.floor((x - grid.origin[scene, 0]) / res).astype(jnp.int32)
    row = jnp.floor((y - grid.origin[scene, 1]) / res).astype(jnp.int32)
    k = jnp.int32(int(math.floor(height / grid.slice_height + 1e-6)))  # 0.6 / 0.05 must be slice 12, not 11
    occ = _occupied(grid, scene, k, row, col)
    first = jnp.argmax(occ)
    return jnp.where(jnp.any(occ), t[first] - step, jnp.float32(max_dist))


def segment_clear(grid: RayGrid, scene, a, b, stop_before, max_len: float, step: float):
    """Whether the segment from ``a`` towards ``b`` is free up to
    ``|b - a| - stop_before`` (fixed-step 3-D march, floor included).

    Args:
        grid: ray grid.
        scene: () int32.
        a, b: (3,) points.
        stop_before: () metres before ``b`` where checking stops (e.g. where
            the ray enters the object looked at).
        max_len: longest segment handled, metres (static); samples beyond
            the segment are ignored.
        step: sample spacing, metres (static).

    Returns:
        () bool.
    """
    n = int(math.ceil(max_len / step))
    d = b - a
    length = jnp.linalg.norm(d)
    u = d / jnp.maximum(length, 1e-6)
    t = (jnp.arange(1, n + 1, dtype=jnp.float32)) * step
    use = t <= length - stop_before
    p = a[None] + t[:, None] * u[None]
    res = grid.resolution
    col = jnp.floor((p[:, 0] - grid.origin[scene, 0]) / res).astype(jnp.int32)
    row = jnp.floor((p[:, 1] - grid.origin[scene, 1]) / res).astype(jnp.int32)
    k = jnp.floor(p[:, 2] / grid.slice_height).astype(jnp.int32)
    occ = _occupied(grid, scene, k, row, col) | (p[:, 2] < 0)
    return ~jnp.any(occ & use)


def box_entry(a, u, center, half, yaw):
    """Distance along the ray ``a + t u`` (u unit) at which it enters an
    upright oriented box; 0 when ``a`` is inside, +inf when it misses."""
    c, s = jnp.cos(yaw), jnp.sin(yaw)
    d = a - center
    lo_x = d[0] * c + d[1] * s
    lo_y = -d[0] * s + d[1] * c
    ux = u[0] * c + u[1] * s
    uy = -u[0] * s + u[1] * c
    p = jnp.stack([lo_x, lo_y, d[2]])
    v = jnp.stack([ux, uy, u[2]])
    v = jnp.where(jnp.abs(v) < 1e-9, 1e-9, v)
    t1 = (-half - p) / v
    t2 = (half - p) / v
    tmin = jnp.max(jnp.minimum(t1, t2))
    tmax = jnp.min(jnp.maximum(t1, t2))
    hit = tmax >= jnp.maximum(tmin, 0.0)
    return jnp.where(hit, jnp.maximum(tmin, 0.0), jnp.inf)
