"""The fast ray caster: voxel march with exact primitive tests.

Distances are metres along a unit direction; a miss is ``+inf`` and the geom
id of a miss is -1. The exact reference is :mod:`ignjax.sim.rays.exact`.

:func:`fast_ray` / :func:`fast_ray_hit` (one ray, to be vmapped) and
:func:`fast_rays` (a batch, same results, much faster) are pure functions
of a :class:`~ignjax.scenes.raygrid.RayGrid`: arrays with a leading scene
axis, so one stacked grid serves episodes from different scenes through
``scene_index`` without copying any grid (pass it unbatched under
``vmap``). Distances are exact up to float32 for primitive geoms (boxes,
spheres, ellipsoids, cylinders, capsules); meshes are voxel-accurate. A ray
works in three parts (voxel index space, see :mod:`ignjax.scenes.voxels`):

1. *Empty-space skipping.* A free voxel's code says that the cube of
   voxels around it within its chessboard distance minus one is free, so
   the ray jumps to where it leaves that cube (exact: it never skips an
   occupied voxel). Next to geometry this is a voxel-by-voxel traversal;
   across an open room it is a handful of jumps. A partly occupied voxel
   also carries the box (in quarters of a voxel) that its geometry lies
   in; a ray that misses that box passes the voxel like a free one, which
   spares most exact tests of rays skimming over a table top.
2. *Exact refinement.* A voxel entirely inside one primitive ends the ray
   at its entry point (exact, since the ray enters it from free space).
   At a partly occupied voxel the primitives listed for its column
   segment (``list_band_height`` tall) are intersected exactly (a box
   intersected with a quadric, :func:`prim_hit`; a capsule is three of
   them, all widened by 10 um so that a ray lying in a face's plane hits
   it, as in ``mj_ray``). A hit inside the segment is the answer;
   otherwise the voxel was only touched by a bounding box (a "false
   positive") and the march resumes after the segment. After ``rounds``
   false positives a ray stops at the voxel it reached (voxel accuracy,
   conservative); segments holding a mesh or more than ``max_list``
   primitives are answered at the voxel too.
3. *Floor.* The floor plane (z = 0, its finite MuJoCo extent, hit from
   above only) is intersected analytically when ``include_floor``.

A vmapped ``while_loop`` runs as long as its slowest ray; :func:`fast_rays`
therefore works in stages and gathers the unfinished rays into dense
batches between them (see its docstring).

XLA's CPU fusion recomputes cheap elementwise chains in every consumer
and drops ``optimization_barrier``; :func:`_keep` materialises shared
intermediates (it divides by a runtime 1.0, an "expensive" op that XLA
does not duplicate). Without it the exact tests ran 10x slower.

Agreement with ``mj_ray`` (tested; :func:`ignjax.bench.rays.agreement`): a
fast distance agrees when both miss within ``max_dist``, or both hit within
it and ``|d_fast - d_exact| <= resolution`` (one grid cell); hits within
1e-3 m of ``max_dist`` on either side count as agreeing either way.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from ignjax.scenes.raygrid import RayGrid
from ignjax.scenes.voxels import N_PRIM_COLUMNS, SUB_Q

_EPS = 1e-4  # metres: tolerance of the exact window and of resuming after a segment
_TINY = 1e-20  # replaces exact zero direction components (slab tests need no special case)
_TOUCH = 1e-5  # metres: the fast path's primitives are this much wider, so a ray exactly in a face's plane hits it


# ---------------------------------------------------------------------------
# Primitive intersection (scalar code: vmapped it is elementwise over rays)
# ---------------------------------------------------------------------------


def _prim_hit(f, px, py, pz, vx, vy, vz, grow: float = 0.0):
    """Distance to a primitive given as 18 scalars ``f`` (see :func:`prim_hit`);
    ``grow`` widens its slabs (metres)."""
    inf = jnp.float32(jnp.inf)
    cx, cy, cz, r00, r01, r02, r10, r11, r12, r20, r21, r22, hx, hy, hz, qa, qb, qc = f
    valid = hx >= 0
    if grow:
        hx, hy, hz = hx + grow, hy + grow, hz + grow
    dx, dy, dz = px - cx, py - cy, pz - cz
    lx = dx * r00 + dy * r10 + dz * r20  # origin in the local frame (R^T d)
    ly = dx * r01 + dy * r11 + dz * r21
    lz = dx * r02 + dy * r12 + dz * r22
    ux = vx * r00 + vy * r10 + vz * r20
    uy = vx * r01 + vy * r11 + vz * r21
    uz = vx * r02 + vy * r12 + vz * r22
    ux = jnp.where(ux == 0, _TINY, ux)
    uy = jnp.where(uy == 0, _TINY, uy)
    uz = jnp.where(uz == 0, _TINY, uz)
    ix, iy, iz = 1.0 / ux, 1.0 / uy, 1.0 / uz
    ax, bx = (-hx - lx) * ix, (hx - lx) * ix
    ay, by = (-hy - ly) * iy, (hy - ly) * iy
    az, bz = (-hz - lz) * iz, (hz - lz) * iz
    t_in = jnp.maximum(jnp.maximum(jnp.minimum(ax, bx), jnp.minimum(ay, by)), jnp.minimum(az, bz))
    t_out = jnp.minimum(jnp.minimum(jnp.maximum(ax, bx), jnp.maximum(ay, by)), jnp.maximum(az, bz))
    A = qa * ux * ux + qb * uy * uy + qc * uz * uz
    B = qa * lx * ux + qb * ly * uy + qc * lz * uz
    C = qa * lx * lx + qb * ly * ly + qc * lz * lz - 1.0
    disc = B * B - A * C
    has_a = A > 1e-12
    r = jnp.sqrt(jnp.maximum(disc, 0.0))
    qq = -(B + jnp.where(B >= 0, r, -r))  # stable roots qq / A and C / qq
    safe_qq = jnp.where(qq == 0, 1.0, qq)
    safe_a = jnp.where(has_a, A, 1.0)
    ra = qq / safe_a
    rb = jnp.where(qq == 0, ra, C / safe_qq)
    q_lo = jnp.where(has_a, jnp.where(disc >= 0, jnp.minimum(ra, rb), inf), jnp.where(C <= 0, -inf, inf))
    q_hi = jnp.where(has_a, jnp.where(disc >= 0, jnp.maximum(ra, rb), -inf), jnp.where(C <= 0, inf, -inf))
    t_in = jnp.maximum(t_in, q_lo)
    t_out = jnp.minimum(t_out, q_hi)
    hit = (t_in <= t_out) & (t_out >= 0) & valid
    return jnp.where(hit, jnp.where(t_in >= 0, t_in, t_out), inf)


def prim_hit(row: jax.Array, pnt: jax.Array, vec: jax.Array) -> jax.Array:
    """Distance along a ray to a primitive (box intersected with a quadric).

    Follows ``mj_ray``: the entry distance, or the exit distance when the ray
    starts inside; +inf on a miss.

    Args:
        row: (18,) primitive, :data:`ignjax.scenes.voxels.PRIM_COLUMNS`.
        pnt: (3,) ray origin.
        vec: (3,) ray direction.

    Returns:
        () float32 distance.
    """
    f = tuple(row[i] for i in range(N_PRIM_COLUMNS))
    return _prim_hit(f, pnt[0], pnt[1], pnt[2], vec[0], vec[1], vec[2])


# ---------------------------------------------------------------------------
# Fast path: a per-ray state machine written with scalars
# ---------------------------------------------------------------------------

_DONE, _MARCH, _CAND = 0, 1, 2


def _keep(values, one):
    """Return ``values`` unchanged, computed once.

    XLA's CPU fusion recomputes cheap elementwise chains in every consumer
    (and drops ``optimization_barrier``); a division is "expensive" to it, so
    dividing by a runtime 1.0 makes it materialise the value instead. Integer
    and boolean values take the same route through float32 (exact for
    integers below 2**24).
    """
    out = []
    for v in values:
        if v.dtype == jnp.float32:
            out.append(v / one)
        elif v.dtype == jnp.bool_:
            out.append((v.astype(jnp.float32) / one) > 0.5)
        else:
            out.append((v.astype(jnp.float32) / one).astype(v.dtype))
    return tuple(out)


class _St(NamedTuple):
    """State of one ray (scalars; a batch of rays has (N,) leaves)."""

    px: jax.Array
    py: jax.Array
    pz: jax.Array
    vx: jax.Array
    vy: jax.Array
    vz: jax.Array
    max_dist: jax.Array
    s: jax.Array
    t: jax.Array  # distance reached, metres
    ix: jax.Array  # current voxel
    iy: jax.Array
    iz: jax.Array
    status: jax.Array  # _DONE, _MARCH or _CAND
    dist: jax.Array  # result once _DONE
    geom: jax.Array
    left: jax.Array  # exact tests left


class _Ray:
    """Scalars derived from a ray and its scene; voxel index space is
    ``q = ((x - ox) / res, (y - oy) / res, z / dz)``."""

    def __init__(self, grid: RayGrid, st: _St):
        inf = jnp.float32(jnp.inf)
        res, dz = grid.resolution, grid.slice_height
        s = st.s
        self.ox = grid.origin[s, 0]
        self.oy = grid.origin[s, 1]
        self.wx = grid.dims[s, 0]
        self.wy = grid.dims[s, 1]
        self.wz = grid.dims[s, 2]
        vx = jnp.where(st.vx == 0, _TINY, st.vx)
        vy = jnp.where(st.vy == 0, _TINY, st.vy)
        vz = jnp.where(st.vz == 0, _TINY, st.vz)
        self.inx, self.iny, self.inz = 1.0 / vx, 1.0 / vy, 1.0 / vz  # metres per unit of world coordinate
        self.qx = (st.px - self.ox) / res
        self.qy = (st.py - self.oy) / res
        self.qz = st.pz / dz
        self.dx, self.dy, self.dz = vx / res, vy / res, vz / dz  # voxels per metre
        self.idx, self.idy, self.idz = res * self.inx, res * self.iny, dz * self.inz
        fx, fy, fz = self.wx.astype(jnp.float32), self.wy.astype(jnp.float32), self.wz.astype(jnp.float32)
        ax, bx = -self.qx * self.idx, (fx - self.qx) * self.idx
        ay, by = -self.qy * self.idy, (fy - self.qy) * self.idy
        az, bz = -self.qz * self.idz, (fz - self.qz) * self.idz
        t0 = jnp.maximum(jnp.maximum(jnp.minimum(ax, bx), jnp.minimum(ay, by)), jnp.minimum(az, bz))
        t1 = jnp.minimum(jnp.minimum(jnp.maximum(ax, bx), jnp.maximum(ay, by)), jnp.maximum(az, bz))
        t_floor = jnp.where((st.vz < 0) & (st.pz >= 0), -st.pz * self.inz, inf)
        t_end = jnp.minimum(jnp.minimum(t1, st.max_dist), t_floor)
        self.t_floor, self.t_start, self.t_end = t_floor, jnp.maximum(t0, 0.0), t_end

    def voxel(self, t):
        ix = jnp.clip(jnp.floor(self.qx + t * self.dx).astype(jnp.int32), 0, self.wx - 1)
        iy = jnp.clip(jnp.floor(self.qy + t * self.dy).astype(jnp.int32), 0, self.wy - 1)
        iz = jnp.clip(jnp.floor(self.qz + t * self.dz).astype(jnp.int32), 0, self.wz - 1)
        return ix, iy, iz


def _init(grid: RayGrid, pnt, vec, max_dist, s, rounds: int) -> _St:
    """Initial state of one ray."""
    pnt = jnp.asarray(pnt, jnp.float32)
    vec = jnp.asarray(vec, jnp.float32)
    f32 = lambda x: jnp.asarray(x, jnp.float32)  # noqa: E731
    i32 = lambda x: jnp.asarray(x, jnp.int32)  # noqa: E731
    st = _St(pnt[0], pnt[1], pnt[2], vec[0], vec[1], vec[2], f32(max_dist), i32(s), f32(0.0), i32(0), i32(0),
             i32(0), i32(_MARCH), f32(jnp.inf), i32(-1), i32(rounds))
    r = _Ray(grid, st)
    ix, iy, iz = r.voxel(r.t_start)
    return st._replace(t=r.t_start, ix=ix, iy=iy, iz=iz, status=jnp.where(r.t_start < r.t_end, _MARCH, _DONE))


def _march(grid: RayGrid, st: _St, budget: int | jax.Array, shortcut: bool) -> _St:
    """Advance a MARCH ray to its first occupied voxel (at most ``budget`` jumps).

    Each jump goes to where the ray leaves the free cube around its voxel. A
    partly occupied voxel makes the ray a candidate (CAND); a voxel entirely
    inside a primitive ends it there when ``shortcut`` (exact: it is entered
    from free space); passing ``t_end`` ends it with a miss.
    """
    r = _Ray(grid, st)
    _, Z, H, W = grid.voxcode.shape
    codes = grid.voxcode.reshape(-1)
    subs = grid.sub_box.reshape(-1)
    base = st.s * (Z * H * W)
    t_end = r.t_end
    one = jnp.where(st.t == st.t, jnp.float32(1.0), jnp.float32(2.0))

    def cond(c):
        return (c[4] == _MARCH) & (c[6] < budget)

    def body(c):
        t, ix, iy, iz, status, dist, it = c
        flat = base + (iz * H + iy) * W + ix
        code = codes[flat].astype(jnp.int32)
        # a partly occupied voxel whose geometry box the ray misses is passed like a free one
        sb = subs[flat].astype(jnp.int32)
        q = jnp.float32(1.0 / SUB_Q)

        def slab(i, qq, ii, lo_bits, hi_bits):
            a = (i.astype(jnp.float32) + ((sb >> lo_bits) & 3).astype(jnp.float32) * q - qq) * ii
            b = (i.astype(jnp.float32) + (((sb >> hi_bits) & 3) + 1).astype(jnp.float32) * q - qq) * ii
            return jnp.minimum(a, b), jnp.maximum(a, b)

        lx, hx = slab(ix, r.qx, r.idx, 0, 6)
        ly, hy = slab(iy, r.qy, r.idy, 2, 8)
        lz, hz = slab(iz, r.qz, r.idz, 4, 10)
        t_lo = jnp.maximum(jnp.maximum(lx, ly), lz)
        t_hi = jnp.minimum(jnp.minimum(hx, hy), hz)
        passed = ((code == 0) | (code == 2)) & ((t_lo > t_hi + 1e-6) | (t_hi < t - 1e-6))
        (code,) = _keep((jnp.where(passed, 3, code),), one)
        D = code - 2
        tx = (jnp.where(r.dx > 0, ix + D, ix - D + 1).astype(jnp.float32) - r.qx) * r.idx
        ty = (jnp.where(r.dy > 0, iy + D, iy - D + 1).astype(jnp.float32) - r.qy) * r.idy
        tz = (jnp.where(r.dz > 0, iz + D, iz - D + 1).astype(jnp.float32) - r.qz) * r.idz
        tm = jnp.minimum(jnp.minimum(tx, ty), tz)
        sx = tx <= tm
        sy = ~sx & (ty <= tm)
        sz = ~sx & ~sy
        D, code, tm, sx, sy, sz = _keep((D, code, tm, sx, sy, sz), one)

        def nxt(sel, i, q, d, w):
            inner = jnp.clip(jnp.floor(q + tm * d).astype(jnp.int32), i - D + 1, i + D - 1)
            return jnp.clip(jnp.where(sel, jnp.where(d > 0, i + D, i - D), inner), 0, w - 1)

        free = code >= 3
        go = free & (tm < t_end)
        full = (code == 1) & (t > 0) if shortcut else jnp.zeros_like(free)
        status = jnp.where(free, jnp.where(go, _MARCH, _DONE), jnp.where(full, _DONE, _CAND))
        dist = jnp.where(full, t, dist)
        return (jnp.where(go, tm, t),
                jnp.where(go, nxt(sx, ix, r.qx, r.dx, r.wx), ix),
                jnp.where(go, nxt(sy, iy, r.qy, r.dy, r.wy), iy),
                jnp.where(go, nxt(sz, iz, r.qz, r.dz, r.wz), iz),
                status, dist, it + 1)

    c = (st.t, st.ix, st.iy, st.iz, st.status, st.dist, jnp.int32(0))
    t, ix, iy, iz, status, dist, _ = jax.lax.while_loop(cond, body, c)
    return st._replace(t=t, ix=ix, iy=iy, iz=iz, status=status, dist=dist)


def _refine(grid: RayGrid, st: _St, k: int | jax.Array) -> _St:
    """Exact test of a CAND ray against its voxel's column segment.

    Tests at most ``k`` primitives of the segment (a loop as long as the
    longest list in a batch); when the segment holds more, the ray stays a
    candidate (undecided). A hit inside the segment ends the ray; an
    approximate segment ends it at the voxel; otherwise the ray resumes
    marching after the segment, or, with no exact tests left, ends at the
    voxel.
    """
    inf = jnp.float32(jnp.inf)
    r = _Ray(grid, st)
    res, dz, spb = grid.resolution, grid.slice_height, grid.slices_per_band
    _, H, W, B = grid.seg_count.shape
    P = grid.prims.shape[2]
    M = grid.seg_prims.shape[1]
    s, ix, iy, iz = st.s, st.ix, st.iy, st.iz
    b = jnp.minimum(iz // spb, B - 1)
    # the segment box and the ray's interval in it (world units)
    x0 = r.ox + ix.astype(jnp.float32) * res
    y0 = r.oy + iy.astype(jnp.float32) * res
    z0 = b.astype(jnp.float32) * (spb * dz)
    g = 2 * _TOUCH  # the segment grown like the primitives, so grazing hits stay inside it
    ax, bx = (x0 - g - st.px) * r.inx, (x0 + res + g - st.px) * r.inx
    ay, by = (y0 - g - st.py) * r.iny, (y0 + res + g - st.py) * r.iny
    az, bz = (z0 - g - st.pz) * r.inz, (z0 + spb * dz + g - st.pz) * r.inz
    ta = jnp.maximum(jnp.maximum(jnp.minimum(ax, bx), jnp.minimum(ay, by)), jnp.minimum(az, bz))
    tb = jnp.minimum(jnp.minimum(jnp.maximum(ax, bx), jnp.maximum(ay, by)), jnp.maximum(az, bz))
    seg = ((s * H + iy) * W + ix) * B + b
    start = grid.seg_start.reshape(-1)[seg]
    count = grid.seg_count.reshape(-1)[seg].astype(jnp.int32)
    ids = grid.seg_prims.reshape(-1)
    prims = grid.prims.reshape(-1)
    pbase = s * (N_PRIM_COLUMNS * P)
    one = jnp.where(st.t == st.t, jnp.float32(1.0), jnp.float32(2.0))
    ta, tb = _keep((ta, tb), one)
    n_test = jnp.where(st.status == _CAND, jnp.minimum(count, k), 0)

    def body(c):
        j, best, best_id = c
        pid = ids[s * M + jnp.minimum(start + j, M - 1)]
        safe = jnp.maximum(pid, 0)
        f = tuple(prims[pbase + c * P + safe] for c in range(N_PRIM_COLUMNS))
        (th,) = _keep((_prim_hit(f, st.px, st.py, st.pz, st.vx, st.vy, st.vz, _TOUCH),), one)
        ok = (j < n_test) & (pid >= 0) & (th >= ta - _EPS) & (th <= tb + _EPS) & (th < best)
        return j + 1, jnp.where(ok, th, best), jnp.where(ok, pid, best_id)

    _, best, best_id = jax.lax.while_loop(lambda c: c[0] < n_test, body, (jnp.int32(0), inf, jnp.int32(-1)))
    geom = grid.prim_geom.reshape(-1)[s * P + jnp.maximum(best_id, 0)]
    approx = grid.approx.reshape(-1)[seg]
    undecided = (count > k) & ~approx
    decide = (st.status == _CAND) & ~undecided
    hit = best < inf
    done_hit = decide & hit
    resume = decide & ~hit & ~approx & (st.left > 1)
    done_vox = decide & ~hit & ~resume
    t_res = tb + _EPS
    nx, ny, nz = r.voxel(t_res)
    # shared by every output: computed once
    done_hit, done_vox, resume, best, geom, t_res, nx, ny, nz = _keep(
        (done_hit, done_vox, resume, best, geom, t_res, nx, ny, nz), one)
    status = jnp.where(done_hit | done_vox, _DONE,
                       jnp.where(resume, jnp.where(t_res < r.t_end, _MARCH, _DONE), st.status))
    return st._replace(
        dist=jnp.where(done_hit, best, jnp.where(done_vox, st.t, st.dist)),
        geom=jnp.where(done_hit, geom, jnp.where(done_vox, -1, st.geom)),
        status=status,
        t=jnp.where(resume, t_res, st.t),
        ix=jnp.where(resume, nx, ix), iy=jnp.where(resume, ny, iy), iz=jnp.where(resume, nz, iz),
        left=jnp.where(resume, st.left - 1, st.left),
    )


def _finalize(grid: RayGrid, st: _St, include_floor: bool) -> tuple[jax.Array, jax.Array]:
    """Distance and geom of a finished ray (floor plane included)."""
    inf = jnp.float32(jnp.inf)
    dist = jnp.where(st.status == _DONE, st.dist, jnp.where(st.status == _CAND, st.t, inf))
    geom = jnp.where(st.status == _DONE, st.geom, -1)
    dist = jnp.where(dist <= st.max_dist, dist, inf)
    geom = jnp.where(dist < inf, geom, -1)
    if include_floor:
        r = _Ray(grid, st)
        fl = grid.floor[st.s]
        tf = r.t_floor
        fx = st.px + tf * st.vx
        fy = st.py + tf * st.vy
        on = (fl[2] >= 0) & (jnp.abs(fx - fl[0]) <= fl[2]) & (jnp.abs(fy - fl[1]) <= fl[3]) & (tf <= st.max_dist)
        take = on & (tf < dist)
        dist = jnp.where(take, tf, dist)
        geom = jnp.where(take, fl[4].astype(jnp.int32), geom)
    return dist, geom


_MAX_STEPS = 100_000


def _solve(grid: RayGrid, st: _St, shortcut: bool) -> _St:
    """Run a ray to completion: march, exact test, resume... until done."""
    K = grid.max_count

    def body(st):
        st = _march(grid, st, _MAX_STEPS, shortcut)
        return _refine(grid, st, K)

    return jax.lax.while_loop(lambda st: st.status != _DONE, body, st)


DEFAULT_ROUNDS = 16
"""Exact tests per ray before a ray stops at the voxel it reached."""


def fast_ray_hit(grid: RayGrid, pnt: jax.Array, vec: jax.Array, max_dist: float | jax.Array,
                 scene_index: jax.Array | int = 0, include_floor: bool = True, rounds: int = DEFAULT_ROUNDS,
                 want_geom: bool = True) -> tuple[jax.Array, jax.Array]:
    """Fast ray cast of one ray against one scene of a :class:`RayGrid`.

    Args:
        grid: the ray grid (leading scene axis; pass it unbatched under vmap).
        pnt: (3,) ray origin, world.
        vec: (3,) unit direction.
        max_dist: () farthest distance considered, metres.
        scene_index: () int32 scene of the ray.
        include_floor: hit the floor plane (static).
        rounds: exact tests of occupied voxels before the ray stops at a
            voxel (static).
        want_geom: report the geom of hits on voxels entirely inside a
            primitive too (static; False is faster and gives -1 there).

    Returns:
        dist: () float32 distance to the first hit within ``max_dist``, +inf
            on a miss.
        geom: () int32 MuJoCo geom id hit (the floor's id for the floor), -1
            on a miss or where unknown (voxel-accuracy hits).
    """
    with jax.named_scope("fast_ray"):
        st = _init(grid, pnt, vec, max_dist, scene_index, rounds)
        st = _solve(grid, st, shortcut=not want_geom)
        return _finalize(grid, st, include_floor)


def fast_ray(grid: RayGrid, pnt: jax.Array, vec: jax.Array, max_dist: float | jax.Array,
             scene_index: jax.Array | int = 0, include_floor: bool = True) -> jax.Array:
    """Distance to the first hit along one ray (fast path), +inf on a miss.

    See :func:`fast_ray_hit` for the arguments; this is the same ray without
    the geom id.

    Returns:
        () float32 distance, metres.
    """
    return fast_ray_hit(grid, pnt, vec, max_dist, scene_index, include_floor, want_geom=False)[0]


def _prefix_slots(mask: jax.Array) -> tuple[jax.Array, jax.Array]:
    """An exclusive prefix count of ``mask`` (in a fixed column-major order).

    Returns:
        pos: (N,) int32, distinct in 0..count-1 over the True entries.
        count: () int32.
    """
    n = mask.shape[0]
    C = min(512, n)
    R = -(-n // C)
    m = jnp.pad(mask.astype(jnp.int32), (0, R * C - n)).reshape(R, C)
    tot, excl = jax.lax.scan(lambda c, row: (c + row, c), jnp.zeros((C,), jnp.int32), m)
    off = jnp.cumsum(tot) - tot
    return (excl + off[None, :]).reshape(-1)[:n], jnp.sum(tot)


def _compact_apply(fn, st: _St, todo: jax.Array, cap: int) -> _St:
    """Apply a per-ray function only to the rays with ``todo``, ``cap`` at a time.

    The indices of the ``todo`` rays are gathered once into a dense list,
    which is then worked through in chunks of ``cap`` rays (a ``while_loop``
    over chunks; the last one padded).

    Args:
        fn: per-ray ``_St -> _St``.
        st: batched state, (N,) leaves.
        todo: (N,) bool.
        cap: rays per chunk (static).
    """
    n = todo.shape[0]
    cap = max(1, min(cap, n))
    pos, count = _prefix_slots(todo)
    order = jnp.zeros((n + cap,), jnp.int32).at[jnp.where(todo, pos, n + cap)].set(
        jnp.arange(n, dtype=jnp.int32), mode="drop")  # todo rays first, then zeros

    def body(c):
        st, k = c
        idx = jax.lax.dynamic_slice(order, (k * cap,), (cap,))
        valid = k * cap + jnp.arange(cap) < count
        new = jax.vmap(fn)(jax.tree.map(lambda a: a[idx], st))
        tgt = jnp.where(valid, idx, n)
        st = jax.tree.map(lambda a, b: a.at[tgt].set(b, mode="drop"), st, new)
        return st, k + 1

    st, _ = jax.lax.while_loop(lambda c: c[1] * cap < count, body, (st, jnp.int32(0)))
    return st


def fast_rays(grid: RayGrid, pnts: jax.Array, vecs: jax.Array, max_dist: float | jax.Array,
              scene_index: jax.Array | int = 0, include_floor: bool = True, rounds: int = DEFAULT_ROUNDS,
              want_geom: bool = False, first_steps: int = 6, second_steps: int = 10,
              cap_fraction: float = 0.25) -> tuple[jax.Array, jax.Array]:
    """Many rays at once: the results of vmapped :func:`fast_ray_hit` (up to
    float32 rounding, about 1e-6 m), several times faster.

    A vmapped ``while_loop`` costs as much as its slowest ray, so the rays
    are worked in stages: every ray gets ``first_steps`` jumps; those still
    marching are gathered into dense batches (``cap_fraction`` of the rays
    at a time) for ``second_steps`` more; then, until every ray is done,
    stages of one exact test and a doubling jump budget work on the rest in
    batches of an eighth of that size, and of a sixty-fourth once few rays
    are left.

    Args:
        grid: ray grid.
        pnts: (N, 3) origins.
        vecs: (N, 3) unit directions.
        max_dist: () or (N,) range, metres.
        scene_index: () or (N,) int32 scene of each ray.
        include_floor, rounds, want_geom: as :func:`fast_ray_hit` (static).
        first_steps, second_steps: jump budgets of the first two stages.
        cap_fraction: batch size of the later stages, as a fraction of N.

    Returns:
        dist: (N,) float32, +inf on a miss; geom: (N,) int32.
    """
    with jax.named_scope("fast_rays"):
        pnts = jnp.asarray(pnts, jnp.float32)
        vecs = jnp.asarray(vecs, jnp.float32)
        n = pnts.shape[0]
        md = jnp.broadcast_to(jnp.asarray(max_dist, jnp.float32), (n,))
        sc = jnp.broadcast_to(jnp.asarray(scene_index, jnp.int32), (n,))
        shortcut = not want_geom
        K = grid.max_count
        st = jax.vmap(lambda p, v, m, s: _march(grid, _init(grid, p, v, m, s, rounds), first_steps, shortcut))(
            pnts, vecs, md, sc)

        # rays still marching get more jumps, in dense batches
        st = _compact_apply(lambda x: _march(grid, x, second_steps, shortcut), st, st.status == _MARCH,
                            int(max(32, n * cap_fraction)))

        def stage(cap):
            def run(c):
                st, i = c
                steps = jnp.minimum(2 * second_steps * 2 ** jnp.minimum(i, 10), _MAX_STEPS)
                # long segment lists wait for every other stage, so most batches test few primitives
                k = jnp.where(i % 2 == 0, min(4, K), K)
                st = _compact_apply(lambda x: _march(grid, _refine(grid, x, k), steps, shortcut), st,
                                    st.status != _DONE, cap)
                return st, i + 1

            return run

        # then exact tests (and more jumps after false positives) until every ray is done:
        # in batches of cap_fraction / 8 of the rays while there are many, then in small ones
        big = int(max(32, n * cap_fraction / 8))
        small = int(max(32, n * cap_fraction / 64))
        c = jax.lax.while_loop(lambda c: jnp.sum(c[0].status != _DONE) > small, stage(big), (st, jnp.int32(0)))
        st, _ = jax.lax.while_loop(lambda c: jnp.any(c[0].status != _DONE), stage(small), c)
        return jax.vmap(lambda x: _finalize(grid, x, include_floor))(st)


def line_of_sight(grid: RayGrid, a: jax.Array, b: jax.Array, scene_index: jax.Array | int = 0,
                  ignore_end: float = 0.05) -> jax.Array:
    """Whether the segment from ``a`` to ``b`` is free (fast path).

    The last ``ignore_end`` metres before ``b`` are not checked, so the
    voxels of an object whose surface point is ``b`` do not hide it. The
    floor counts as an obstacle.

    Args:
        grid: ray grid.
        a: (3,) start point, world.
        b: (3,) end point, world.
        scene_index: () scene.
        ignore_end: metres.

    Returns:
        () bool.
    """
    d = b - a
    length = jnp.sqrt(jnp.sum(d * d))
    vec = d / jnp.maximum(length, 1e-9)
    reach = jnp.maximum(length - ignore_end, 0.0)
    dist = fast_ray(grid, a, vec, reach, scene_index)
    return (dist > reach) | (reach <= 0)
