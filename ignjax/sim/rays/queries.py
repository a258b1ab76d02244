"""Ray queries of the simulator, written for one episode and vmapped once.

* :func:`march` - general 3-D rays (the executor's pixel depth): a
  fixed-count voxel traversal of the ray grid with free-space skipping,
  sub-box tests and exact confirmation against the voxel's primitives. Its
  cost under ``vmap`` is the same for every ray; it agrees with ``mj_ray``
  within one grid cell on >= 99.5% of random rays (``tests/test_sim.py``).
  :func:`march_begin` and :func:`march_resume` are the same march cut in
  two, so that a batch resumes only the rays its first steps left open.
* :func:`segment_clear` - line of sight for visibility: a fixed-step march
  over the voxel occupancy (``voxcode <= 1``, a conservative voxelization);
  :func:`segment_blocked` is its test over any range of samples.
* :func:`box_entry` - where a ray enters an upright oriented box.

The collision and free-space probes of the controller read the per-scene
probe map of :class:`ignjax.sim.env.World` instead. The exact batched fast
path for large ray batches is :func:`ignjax.sim.rays.fast.fast_rays`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import jax
import jax.numpy as jnp

from ignjax.scenes.raygrid import COLUMN_WORD_BITS, RayGrid
from ignjax.sim.rays.fast import _prim_hit

_OCCUPIED_MAX_CODE = 1  # voxcode 0: partly occupied, 1: inside a primitive, 2: free but touched, >= 3: free
_NO_STEP = 1e30  # t_delta of an axis the ray does not move along (finite: 0 steps times it is 0)


def _occupied(grid: RayGrid, scene, k, row, col, columns=None):
    """Occupancy of voxel (k, row, col) of a scene; outside the valid grid counts as occupied.
    ``columns``: read from the packed columns of :func:`ignjax.scenes.raygrid.occupied_columns`
    instead of ``voxcode`` (the same answers)."""
    W, H, Z = grid.dims[scene, 0], grid.dims[scene, 1], grid.dims[scene, 2]
    inside = (col >= 0) & (col < W) & (row >= 0) & (row < H)
    above = k >= Z
    if columns is None:
        code = grid.voxcode[scene, jnp.clip(k, 0, grid.voxcode.shape[1] - 1), jnp.clip(row, 0, grid.voxcode.shape[2] - 1),
                            jnp.clip(col, 0, grid.voxcode.shape[3] - 1)]
        occ = code <= _OCCUPIED_MAX_CODE
    else:
        kk = jnp.clip(k, 0, columns.shape[3] * COLUMN_WORD_BITS - 1)
        word = columns[scene, jnp.clip(row, 0, columns.shape[1] - 1), jnp.clip(col, 0, columns.shape[2] - 1),
                       kk // COLUMN_WORD_BITS]
        occ = ((word >> (kk % COLUMN_WORD_BITS).astype(jnp.uint32)) & jnp.uint32(1)) != 0
    return jnp.where(inside, jnp.where(above | (k < 0), False, occ), True)


EXACT_ROUNDS = 6  # exact confirmations per ray: a sub-box hit the primitives miss resumes the traversal


def _sub_box_bounds(packed):
    """(lo, hi) fractions of a voxel, (3,) each, from a packed sub-box."""
    v = packed.astype(jnp.int32)
    sh = jnp.array([0, 2, 4], jnp.int32)
    lo = ((v >> sh) & 3).astype(jnp.float32) / 4.0
    hi = (((v >> (sh + 6)) & 3) + 1).astype(jnp.float32) / 4.0
    return lo, hi


def march(grid: RayGrid, scene, pnt, vec, max_dist, *, static_range: float, outside_hits: bool,
          include_floor: bool = True, exact: int = 0, iterations: int | None = None):
    """Distance to the first surface along one 3-D ray (voxel traversal).

    A fixed-count Amanatides-Woo traversal of the ray grid: every voxel the
    ray crosses is visited in order; in an occupied voxel (``voxcode <= 1``)
    the ray is tested against the voxel's sub-box (the quarter-voxel box that
    holds its geometry), so a ray passing through the empty part of a
    partly occupied voxel goes on. The floor plane (z = 0) is intersected
    analytically. The iteration count is static (from ``static_range``), so
    the cost under ``vmap`` is the same for every ray.

    Args:
        grid: ray grid.
        scene: () int32 scene index.
        pnt: (3,) origin; vec: (3,) unit direction.
        max_dist: () range of this ray, metres (<= ``static_range``).
        static_range: longest range any call uses (static; sets the
            iteration count).
        outside_hits: leaving the grid sideways counts as a hit (the house's
            exterior acts as a wall: collision and free-space rays) rather
            than a miss (pixel depth).
        include_floor: intersect the floor plane z = 0 from above.
        exact: when > 0, a sub-box hit is confirmed by testing the voxel's
            column-segment primitives exactly (up to ``exact`` of them; a
            segment with more, or one marked approximate, keeps the sub-box
            hit). A hit the primitives miss resumes the traversal from the
            next voxel, up to :data:`EXACT_ROUNDS` rounds (later rounds take
            a quarter of the iterations; the last keeps a sub-box hit). The cheap
            traversal and the few exact tests are separate, so their costs
            add rather than multiply.

        iterations: traversal steps (static); default: enough to cross every
            voxel up to ``static_range``. Free voxels far from geometry are
            crossed several at a time, so far fewer usually suffice.

    Returns:
        () float32 distance, +inf when nothing is hit within ``max_dist``.
    """
    return march_resume(grid, scene, pnt, vec, max_dist, march_begin(
        grid, scene, pnt, vec, max_dist, static_range=static_range, outside_hits=outside_hits,
        include_floor=include_floor, exact=exact, iterations=iterations, steps=0),
        static_range=static_range, outside_hits=outside_hits, include_floor=include_floor, exact=exact,
        iterations=iterations, steps=0)


class MarchState(NamedTuple):
    """A :func:`march` stopped after the first steps of its traversal
    (:func:`march_begin`): the traversal's carry, and whether the answer is
    already known (``done``, the distance ``value``)."""

    carry: tuple
    done: jax.Array
    value: jax.Array


def _march_parts(grid: RayGrid, scene, pnt, vec, max_dist, *, static_range: float, outside_hits: bool,
                 include_floor: bool, exact: int, iterations: int | None):
    """The pieces of :func:`march`, recomputed alike by each of its parts:
    (iteration count, traversal body, exact test, first carry, finish)."""
    res, sh = grid.resolution, grid.slice_height
    n_iter = int(math.ceil(static_range * (math.sqrt(2.0) / res + 1.0 / sh))) + 3 if iterations is None else iterations
    inf = jnp.float32(jnp.inf)
    size = jnp.array([res, res, sh], jnp.float32)
    org = jnp.array([grid.origin[scene, 0], grid.origin[scene, 1], 0.0], jnp.float32)
    dims = grid.dims[scene]  # (W, H, Z)
    q = (pnt - org) / size  # position in voxel units
    safe = jnp.where(jnp.abs(vec) < 1e-9, 1e-9, vec)
    inv = 1.0 / safe
    stepi = jnp.where(vec >= 0, 1, -1).astype(jnp.int32)
    cell = jnp.floor(q).astype(jnp.int32)
    nxt = jnp.where(vec >= 0, cell + 1, cell).astype(jnp.float32)
    t_max = jnp.where(jnp.abs(vec) < 1e-9, inf, (nxt - q) * size * inv)
    # an axis the ray does not move along: t_max is inf (never crossed) and t_delta finite, so
    # that the advance's m - 1 = 0 steps along it add 0, not 0 * inf = NaN
    t_delta = jnp.where(jnp.abs(vec) < 1e-9, _NO_STEP, size * jnp.abs(inv))
    t_floor = jnp.where(include_floor & (vec[2] < 0) & (pnt[2] >= 0), -pnt[2] / safe[2], inf)
    limit = jnp.minimum(max_dist, t_floor)
    zmax = grid.voxcode.shape[1] - 1

    vox_shape = jnp.array([grid.voxcode.shape[3] - 1, grid.voxcode.shape[2] - 1, zmax])

    def body(_, carry):
        cell, t_max, t_cur, hit, h_ci, h_t0, h_t1, h_rough = carry
        live = jnp.isinf(hit) & (t_cur <= limit)
        out_xy = (cell[0] < 0) | (cell[0] >= dims[0]) | (cell[1] < 0) | (cell[1] >= dims[1])
        above = cell[2] >= dims[2]
        below = cell[2] < 0
        ci = jnp.clip(cell, 0, vox_shape)
        code = grid.voxcode[scene, ci[2], ci[1], ci[0]]
        occ = (code <= _OCCUPIED_MAX_CODE) & ~out_xy & ~above & ~below
        lo, hi = _sub_box_bounds(grid.sub_box[scene, ci[2], ci[1], ci[0]])
        base = org + cell.astype(jnp.float32) * size
        t1 = (base + lo * size - pnt) * inv
        t2 = (base + hi * size - pnt) * inv
        t_in = jnp.max(jnp.minimum(t1, t2))
        t_out = jnp.min(jnp.maximum(t1, t2))
        t_exit = jnp.min(t_max)
        box_hit = occ & (t_out >= jnp.maximum(t_in, t_cur) - 1e-6) & (t_in <= t_exit + 1e-6)
        t_box = jnp.maximum(t_in, t_cur)
        leaves = out_xy & ~outside_hits
        new_hit = jnp.where(box_hit, t_box, jnp.where(out_xy & outside_hits, t_cur, inf))
        took = live & jnp.isfinite(new_hit)
        hit = jnp.where(live, new_hit, hit)
        h_ci = jnp.where(took, ci, h_ci)
        h_t0 = jnp.where(took, t_cur, h_t0)
        h_t1 = jnp.where(took, t_exit, h_t1)
        h_rough = jnp.where(took, ~box_hit, h_rough)  # leaving the grid is no voxel to test exactly
        # advance: m DDA steps at once, m - 1 being how many voxels around a free voxel are known free
        # (voxcode c >= 3: chessboard distance c - 2 to the nearest non-free voxel)
        m = jnp.where(occ | (code < 3) | out_xy | below, 1, jnp.maximum(code.astype(jnp.int32) - 3, 1))
        m = jnp.where(above, 1, m).astype(jnp.float32)
        t_new = jnp.min(t_max + (m - 1.0) * t_delta)
        n_cross = jnp.where(t_max <= t_new, jnp.floor((t_new - t_max) / t_delta + 1e-6) + 1.0, 0.0)
        n_cross = jnp.minimum(jnp.where(jnp.isfinite(n_cross), n_cross, 0.0), m)
        # the state moves past the voxel of a new hit, then freezes there: a later round resumes from it
        cell = jnp.where(live, cell + stepi * n_cross.astype(jnp.int32), cell)
        t_next = jnp.where(leaves, inf, jnp.where(m > 1, t_new, t_exit))
        t_max = jnp.where(live, t_max + n_cross * t_delta, t_max)
        t_cur = jnp.where(live, t_next, t_cur)
        return cell, t_max, t_cur, hit, h_ci, h_t0, h_t1, h_rough

    def exact_test(ci, t0, t1):
        """Exact distance within [t0, t1] to the primitives of voxel ci's column segment, and
        whether the segment is too crowded (or approximate) to answer exactly."""
        band = jnp.clip(ci[2] // grid.slices_per_band, 0, grid.seg_start.shape[3] - 1)
        start = grid.seg_start[scene, ci[1], ci[0], band]
        count = grid.seg_count[scene, ci[1], ci[0], band].astype(jnp.int32)
        rough = grid.approx[scene, ci[1], ci[0], band] | (count > exact)
        j = jnp.arange(exact)
        ids = grid.seg_prims[scene, jnp.clip(start + j, 0, grid.seg_prims.shape[1] - 1)]
        pid = jnp.clip(ids, 0, grid.prims.shape[2] - 1)
        f = grid.prims[scene, :, pid].T  # Shape: (18, exact); one gather, never a copy of the scene's table
        th = _prim_hit(tuple(f[c] for c in range(18)), pnt[0], pnt[1], pnt[2], vec[0], vec[1], vec[2])
        th = jnp.where((j < count) & (ids >= 0) & (th >= t0 - 1e-5) & (th <= t1 + 1e-5), th, inf)
        return jnp.maximum(jnp.min(th), 0.0), rough

    first = (cell, t_max, jnp.float32(0.0), inf, jnp.zeros(3, jnp.int32), jnp.float32(0.0), jnp.float32(0.0),
             jnp.array(False))

    def finish(result):
        hit = jnp.where(result <= limit, result, inf)
        return jnp.where(jnp.isinf(hit) & jnp.isfinite(t_floor) & (t_floor <= max_dist), t_floor, hit)

    def moving(carry):  # the traversal would still step: nothing hit yet and within range
        return jnp.isinf(carry[3]) & (carry[2] <= limit)

    return n_iter, body, exact_test, first, finish, moving


def _round(exact_test, exact: int, r: int, rounds: int, carry, pending, result):
    """The end of round ``r`` of :func:`march`'s traversal: a hit found is
    confirmed exactly (or kept, in the last round). Returns (result, pending)."""
    hit, h_ci, h_t0, h_t1, h_rough = carry[3:]
    found = pending & jnp.isfinite(hit)
    if exact:
        t_ex, rough = exact_test(h_ci, h_t0, h_t1)
        rough = rough | h_rough
        accept = found & (rough | jnp.isfinite(t_ex) | (r == rounds - 1))  # the last round keeps a sub-box hit
        value = jnp.where(rough | ~jnp.isfinite(t_ex), hit, t_ex)
    else:
        accept, value = found, hit
    return jnp.where(accept, value, result), found & ~accept


def march_begin(grid: RayGrid, scene, pnt, vec, max_dist, *, static_range: float, outside_hits: bool,
                include_floor: bool = True, exact: int = 0, iterations: int | None = None,
                steps: int) -> MarchState:
    """The first ``steps`` traversal steps of :func:`march` (same arguments),
    and whether they decide the answer: a hit confirmed (or kept) in the
    first round, or a ray past its range or out of the grid with nothing hit.
    :func:`march_resume` continues it; a batch resumes only its rays not
    ``done`` (each step is the same computation, so the answer is
    :func:`march`'s)."""
    n_iter, body, exact_test, carry, finish, moving = _march_parts(
        grid, scene, pnt, vec, max_dist, static_range=static_range, outside_hits=outside_hits,
        include_floor=include_floor, exact=exact, iterations=iterations)
    if steps == 0:
        return MarchState(carry, jnp.array(False), jnp.float32(jnp.inf))
    carry = jax.lax.fori_loop(0, min(steps, n_iter), body, carry)
    rounds = EXACT_ROUNDS if exact else 1
    result, pending = _round(exact_test, exact, 0, rounds, carry, jnp.array(True), jnp.float32(jnp.inf))
    hit = carry[3]
    # nothing hit and no step left to take (beyond the range or the floor, out of the grid): no later step
    # changes it; or a hit the first round keeps
    idle = jnp.isinf(hit) & (~moving(carry) | (steps >= n_iter))
    done = (jnp.isfinite(hit) & ~pending) | idle
    return MarchState(carry, done, finish(result))


def march_resume(grid: RayGrid, scene, pnt, vec, max_dist, state: MarchState, *, static_range: float,
                 outside_hits: bool, include_floor: bool = True, exact: int = 0, iterations: int | None = None,
                 steps: int) -> jax.Array:
    """:func:`march`'s distance, from the state :func:`march_begin` left after ``steps`` steps."""
    n_iter, body, exact_test, _, finish, _ = _march_parts(
        grid, scene, pnt, vec, max_dist, static_range=static_range, outside_hits=outside_hits,
        include_floor=include_floor, exact=exact, iterations=iterations)
    rounds = EXACT_ROUNDS if exact else 1
    carry = jax.lax.fori_loop(min(steps, n_iter), n_iter, body, state.carry)
    result, pending = _round(exact_test, exact, 0, rounds, carry, jnp.array(True), jnp.float32(jnp.inf))

    def again(r, c):  # a later round: a shorter traversal from where the last one stopped, and its exact test
        carry, result, pending = c
        carry = jax.lax.fori_loop(0, max(n_iter // 4, 1), body, (*carry[:3], *_fresh(carry)))
        result, pending = _round(exact_test, exact, r, rounds, carry, pending, result)
        return carry, result, pending

    if rounds > 1:  # one loop, not the rounds unrolled: the same steps, a program a fraction of the size
        carry, result, pending = jax.lax.fori_loop(1, rounds, again, (carry, result, pending))
    return finish(result)


def _fresh(carry):
    """A new round's hit record (nothing hit yet)."""
    return (jnp.float32(jnp.inf), jnp.zeros(3, jnp.int32), jnp.float32(0.0), jnp.float32(0.0), jnp.array(False))


def segment_ray(a, b, stop_before):
    """The direction and checked length of the segment from ``a`` towards
    ``b`` that :func:`segment_clear` marches: (u (3,) unit, limit ())
    with ``limit = |b - a| - stop_before``."""
    d = b - a
    length = jnp.linalg.norm(d)
    return d / jnp.maximum(length, 1e-6), length - stop_before


def segment_blocked(grid: RayGrid, scene, a, u, limit, step: float, start: int, stop: int, columns=None):
    """() bool: one of samples ``start .. stop - 1`` of the march from ``a``
    along ``u`` (sample ``i`` at ``(i + 1) * step``) within ``limit`` lies in
    an occupied voxel or below the floor (:func:`segment_clear`'s test).
    ``columns``: the grid's packed occupancy
    (:func:`ignjax.scenes.raygrid.occupied_columns`, :attr:`ignjax.sim.world.World.columns`)
    to read instead of ``voxcode``: the same answer from a table an eighth its size."""
    t = (jnp.arange(start + 1, stop + 1, dtype=jnp.float32)) * step
    use = t <= limit
    p = a[None] + t[:, None] * u[None]
    res = grid.resolution
    col = jnp.floor((p[:, 0] - grid.origin[scene, 0]) / res).astype(jnp.int32)
    row = jnp.floor((p[:, 1] - grid.origin[scene, 1]) / res).astype(jnp.int32)
    k = jnp.floor(p[:, 2] / grid.slice_height).astype(jnp.int32)
    occ = _occupied(grid, scene, k, row, col, columns) | (p[:, 2] < 0)
    return jnp.any(occ & use)


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
    u, limit = segment_ray(a, b, stop_before)
    return ~segment_blocked(grid, scene, a, u, limit, step, 0, int(math.ceil(max_len / step)))


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
