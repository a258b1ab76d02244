"""Ray casting: the exact path (MuJoCo / MJX) and the fast voxel path.

Distances are metres along a unit direction; a miss is ``+inf`` on every
path here (MuJoCo's ``-1`` is converted), and the geom id of a miss is -1.

Exact path
    :func:`exact_rays` is ``mjx.ray`` on the compiled model, vmapped over rays
    and jitted. ``mjx.ray`` (mujoco-mjx 3.17) has no cylinder intersection and
    silently ignores cylinder geoms, so :func:`exact_rays` intersects the
    cylinders itself (the same primitive test as the fast path) and keeps the
    nearer hit; the result matches ``mujoco.mj_ray``. The C references are
    :func:`mj_rays` (a loop over ``mujoco.mj_ray``, any origins) and
    :func:`mj_multiray` (``mujoco.mj_multiRay``, one origin). Rays are cast
    with ``flg_static=1``; ``geomgroup`` selects groups as in MuJoCo (a
    6-sequence of flags, None = every group).

Fast path
    :func:`fast_ray` / :func:`fast_ray_hit` (one ray, to be vmapped) and
    :func:`fast_rays` (a batch, same results, much faster) are pure functions
    of a :class:`RayGrid`: arrays with a leading scene axis, so one stacked
    grid serves episodes from different scenes through ``scene_index``
    without copying any grid (pass it unbatched under ``vmap``). Distances
    are exact up to float32 for primitive geoms (boxes, spheres, ellipsoids,
    cylinders, capsules); meshes are voxel-accurate. A ray works in three
    parts (voxel index space, see :mod:`ignjax.scenes.navgrid`):

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
       intersected with a quadric; a capsule is three of them, all widened
       by 10 um so that a ray lying in a face's plane hits it, as in
       ``mj_ray``). A hit inside the segment is the answer; otherwise the
       voxel was only touched by a bounding box (a "false positive") and the
       march resumes after the segment. After ``rounds`` false positives a
       ray stops at the voxel it reached (voxel accuracy, conservative);
       segments holding a mesh or more than ``max_list`` primitives are
       answered at the voxel too.
    3. *Floor.* The floor plane (z = 0, its finite MuJoCo extent, hit from
       above only) is intersected analytically when ``include_floor``.

    A vmapped ``while_loop`` runs as long as its slowest ray; :func:`fast_rays`
    therefore works in stages and gathers the unfinished rays into dense
    batches between them (see its docstring).

    XLA's CPU fusion recomputes cheap elementwise chains in every consumer
    and drops ``optimization_barrier``; :func:`_keep` materialises shared
    intermediates (it divides by a runtime 1.0, an "expensive" op that XLA
    does not duplicate). Without it the exact tests ran 10x slower.

Agreement with ``mj_ray`` (tested): a fast distance agrees when both miss
within ``max_dist``, or both hit within it and ``|d_fast - d_exact| <=
resolution`` (one grid cell); hits within 1e-3 m of ``max_dist`` on either
side count as agreeing either way.
"""

from __future__ import annotations

import math
import time
import weakref
from dataclasses import dataclass
from functools import partial
from typing import NamedTuple, Sequence

import jax
import jax.numpy as jnp
import mujoco
import numpy as np

from ignjax.scenes.navgrid import N_PRIM_COLUMNS, SUB_Q, NavGrid, geom_prims

_EPS = 1e-4  # metres: tolerance of the exact window and of resuming after a segment
_TINY = 1e-20  # replaces exact zero direction components (slab tests need no special case)
_TOUCH = 1e-5  # metres: the fast path's primitives are this much wider, so a ray exactly in a face's plane hits it


# ---------------------------------------------------------------------------
# The fast-path grid
# ---------------------------------------------------------------------------


@partial(jax.tree_util.register_dataclass,
         data_fields=["voxcode", "sub_box", "seg_start", "seg_count", "seg_prims", "approx", "prims", "prim_geom",
                      "origin", "dims", "floor"],
         meta_fields=["resolution", "slice_height", "slices_per_band", "max_count"])
@dataclass(frozen=True)
class RayGrid:
    """Arrays of the fast ray caster for S scenes, padded to shared maxima.

    Attributes:
        voxcode: (S, Z, H, W) uint8 voxel march codes (:func:`navgrid.march_codes`).
        sub_box: (S, Z, H, W) uint16 where the geometry of each occupied voxel
            lies (:func:`navgrid.pack_sub_boxes`).
        seg_start: (S, H, W, B) int32 first entry of each column segment in ``seg_prims``.
        seg_count: (S, H, W, B) uint8 primitives in each segment.
        seg_prims: (S, M) int32 primitive indices, segment after segment.
        approx: (S, H, W, B) bool, segment answered at voxel accuracy.
        prims: (S, 18, P) float32 primitives, one row of
            :data:`navgrid.PRIM_COLUMNS` per column (structure of arrays).
        prim_geom: (S, P) int32 MuJoCo geom id of each primitive.
        origin: (S, 2) float32 world (x, y) of the grid's corner.
        dims: (S, 3) int32 valid extent (W, H, Z) of each scene's grid.
        floor: (S, 5) float32 floor plane rectangle (cx, cy, hx, hy) and its
            geom id (as a float); hx < 0 for no floor.
        resolution: cell size, metres (static).
        slice_height: voxel height, metres (static).
        slices_per_band: voxel slices per list segment (static).
        max_count: largest ``seg_count`` (static): exact tests per segment.
    """

    voxcode: jax.Array
    sub_box: jax.Array
    seg_start: jax.Array
    seg_count: jax.Array
    seg_prims: jax.Array
    approx: jax.Array
    prims: jax.Array
    prim_geom: jax.Array
    origin: jax.Array
    dims: jax.Array
    floor: jax.Array
    resolution: float = 0.05
    slice_height: float = 0.05
    slices_per_band: int = 5
    max_count: int = 1

    @property
    def n_scenes(self) -> int:
        return int(self.voxcode.shape[0])


def _floor_row(compiled) -> np.ndarray:
    """(5,) floor rectangle (cx, cy, hx, hy, geom id) of a compiled scene."""
    m, d = compiled.model, compiled.data
    for g in range(m.ngeom):
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE:
            R = d.geom_xmat[g].reshape(3, 3)
            if abs(R[2, 2] - 1.0) < 1e-9 and abs(d.geom_xpos[g][2]) < 1e-9:
                sx, sy = float(m.geom_size[g][0]), float(m.geom_size[g][1])
                big = 1e9
                return np.array([d.geom_xpos[g][0], d.geom_xpos[g][1], sx if sx > 0 else big, sy if sy > 0 else big, g],
                                np.float32)
    return np.array([0, 0, -1, -1, -1], np.float32)


def ray_grid_arrays(grid: NavGrid, compiled=None) -> dict[str, np.ndarray]:
    """Per-scene host arrays of a :class:`RayGrid` (no scene axis).

    Args:
        grid: the scene's navigation grid.
        compiled: its compiled scene, for the floor plane (None: no floor).
    """
    prims = grid.prims if len(grid.prims) else np.full((1, N_PRIM_COLUMNS), -1.0, np.float32)
    return {
        "voxcode": grid.voxcode,
        "sub_box": grid.sub_box,
        "seg_start": grid.seg_start,
        "seg_count": grid.seg_count,
        "seg_prims": grid.seg_prims if len(grid.seg_prims) else np.full((1,), -1, np.int32),
        "approx": grid.approx,
        "prims": np.ascontiguousarray(prims.T),
        "prim_geom": grid.prim_geom if len(grid.prim_geom) else np.full((1,), -1, np.int32),
        "origin": np.asarray(grid.origin, np.float32),
        "dims": np.array([grid.shape[1], grid.shape[0], grid.n_slices], np.int32),
        "floor": _floor_row(compiled) if compiled is not None else np.array([0, 0, -1, -1, -1], np.float32),
    }


_PAD_VALUES = {"voxcode": 255, "sub_box": 0, "seg_start": 0, "seg_count": 0, "seg_prims": -1, "approx": False,
               "prims": -1.0, "prim_geom": -1, "origin": 0.0, "dims": 0, "floor": -1.0}


def stack_ray_arrays(arrays: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Pad per-scene ray arrays to shared maxima and stack them (scene axis 0).

    Padding is free space (voxel code 255, empty segments, primitives that are
    never hit); rays never reach it because each scene's march is clipped to
    its own ``dims``.
    """
    out = {}
    for name in _PAD_VALUES:
        items = [a[name] for a in arrays]
        shape = tuple(max(s) for s in zip(*[x.shape for x in items]))
        stacked = np.full((len(items),) + shape, _PAD_VALUES[name], dtype=items[0].dtype)
        for i, x in enumerate(items):
            stacked[(i,) + tuple(slice(0, n) for n in x.shape)] = x
        out[name] = stacked
    return out


def ray_grid(grids: NavGrid | Sequence[NavGrid], compiled=None) -> RayGrid:
    """A device :class:`RayGrid` of one or several scenes.

    Args:
        grids: one :class:`NavGrid` or a sequence of them (same resolution,
            slice height and list band height).
        compiled: the matching compiled scene(s), for the floor planes.
    """
    if isinstance(grids, NavGrid):
        grids = [grids]
        compiled = [compiled]
    grids = list(grids)
    compiled = list(compiled) if compiled is not None else [None] * len(grids)
    cfg = grids[0].config
    for g in grids[1:]:
        if (g.config.resolution, g.config.slice_height, g.config.list_band_height) != \
                (cfg.resolution, cfg.slice_height, cfg.list_band_height):
            raise ValueError("all grids of a RayGrid need the same resolution, slice_height and list_band_height")
    arrs = stack_ray_arrays([ray_grid_arrays(g, c) for g, c in zip(grids, compiled)])
    return RayGrid(**{k: jnp.asarray(v) for k, v in arrs.items()}, resolution=cfg.resolution,
                   slice_height=cfg.slice_height, slices_per_band=cfg.slices_per_list_band,
                   max_count=max(int(arrs["seg_count"].max(initial=0)), 1))


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
        row: (18,) primitive, :data:`ignjax.scenes.navgrid.PRIM_COLUMNS`.
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


# ---------------------------------------------------------------------------
# Exact path
# ---------------------------------------------------------------------------


def _group_mask(geomgroup) -> np.ndarray | None:
    if geomgroup is None:
        return None
    g = np.zeros(mujoco.mjNGROUP, np.uint8)
    vals = np.asarray(geomgroup).astype(np.uint8).ravel()
    g[:len(vals)] = vals[:mujoco.mjNGROUP]
    return g


def _cylinder_rows(compiled, geomgroup) -> tuple[np.ndarray, np.ndarray]:
    m, d = compiled.model, compiled.data
    mask = _group_mask(geomgroup)
    rows, ids = [], []
    for g in range(m.ngeom):
        if m.geom_type[g] != mujoco.mjtGeom.mjGEOM_CYLINDER:
            continue
        if mask is not None and not mask[min(int(m.geom_group[g]), mujoco.mjNGROUP - 1)]:
            continue
        mat = int(m.geom_matid[g])
        alpha = m.mat_rgba[mat, 3] if mat >= 0 else m.geom_rgba[g, 3]
        if alpha == 0:
            continue
        rows += geom_prims(m, d, g)
        ids.append(g)
    if not rows:
        return np.zeros((0, N_PRIM_COLUMNS), np.float32), np.zeros((0,), np.int32)
    return np.stack(rows).astype(np.float32), np.asarray(ids, np.int32)


def exact_ray(mjx_model, mjx_data, cylinders: jax.Array, cylinder_ids: jax.Array, pnt: jax.Array,
              vec: jax.Array, geomgroup: tuple[int, ...] = ()) -> tuple[jax.Array, jax.Array]:
    """``mjx.ray`` plus the cylinders it ignores, for one ray.

    Args:
        mjx_model, mjx_data: the MJX model and data.
        cylinders: (C, 18) cylinder primitives (:func:`navgrid.geom_prims`).
        cylinder_ids: (C,) their geom ids.
        pnt: (3,) origin.
        vec: (3,) direction.
        geomgroup: MuJoCo group flags (static), () for all.

    Returns:
        (dist () float32, +inf on a miss; geomid () int32, -1 on a miss).
    """
    from mujoco import mjx

    d, g = mjx.ray(mjx_model, mjx_data, pnt, vec, geomgroup=geomgroup)
    d = jnp.where(d < 0, jnp.inf, d)
    if cylinders.shape[0]:
        tc = jax.vmap(prim_hit, in_axes=(0, None, None))(cylinders, pnt, vec)
        k = jnp.argmin(tc)
        take = tc[k] < d
        d = jnp.where(take, tc[k], d)
        g = jnp.where(take, cylinder_ids[k], g)
    return d, g


_EXACT_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def exact_rays(compiled, pnts, vecs, geomgroup=None) -> tuple[jax.Array, jax.Array]:
    """Exact distances of many rays with ``mjx.ray`` (jitted, vmapped).

    Args:
        compiled: a :class:`~ignjax.scenes.compile.CompiledScene`.
        pnts: (N, 3) origins.
        vecs: (N, 3) unit directions.
        geomgroup: MuJoCo group flags (6 values) or None for every group.

    Returns:
        dist: (N,) float32, +inf on a miss; geomid: (N,) int32, -1 on a miss.
    """
    key = None if geomgroup is None else tuple(int(bool(x)) for x in _group_mask(geomgroup))
    per = _EXACT_CACHE.setdefault(compiled, {})
    if key not in per:
        cyl, cid = _cylinder_rows(compiled, geomgroup)
        mx, dx = compiled.mjx_model, compiled.mjx_data
        cyl_j, cid_j = jnp.asarray(cyl), jnp.asarray(cid)
        gg = key or ()
        per[key] = jax.jit(jax.vmap(lambda p, v: exact_ray(mx, dx, cyl_j, cid_j, p, v, gg)))
    return per[key](jnp.asarray(pnts, jnp.float32), jnp.asarray(vecs, jnp.float32))


def mj_rays(compiled, pnts, vecs, geomgroup=None) -> tuple[np.ndarray, np.ndarray]:
    """C reference: ``mujoco.mj_ray`` for each ray (``flg_static=1``).

    Returns:
        dist: (N,) float64, +inf on a miss; geomid: (N,) int32, -1 on a miss.
    """
    m, d = compiled.model, compiled.data
    mask = _group_mask(geomgroup)
    pnts = np.asarray(pnts, np.float64).reshape(-1, 3)
    vecs = np.asarray(vecs, np.float64).reshape(-1, 3)
    out = np.empty(len(pnts))
    ids = np.empty(len(pnts), np.int32)
    gid = np.zeros(1, np.int32)
    for i in range(len(pnts)):
        out[i] = mujoco.mj_ray(m, d, pnts[i], vecs[i], mask, 1, -1, gid)
        ids[i] = gid[0]
    return np.where(out < 0, np.inf, out), ids


def mj_multiray(compiled, pnt, vecs, geomgroup=None, cutoff: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
    """C reference for rays from one point: ``mujoco.mj_multiRay``.

    Args:
        compiled: compiled scene.
        pnt: (3,) common origin.
        vecs: (N, 3) unit directions.
        geomgroup: group flags or None.
        cutoff: MuJoCo's ``cutoff``: geoms whose bounding sphere lies farther
            are skipped (a speed-up; hits beyond it can still be returned).

    Returns:
        dist: (N,) float64, +inf on a miss; geomid: (N,) int32, -1 on a miss.
    """
    m, d = compiled.model, compiled.data
    vecs = np.ascontiguousarray(np.asarray(vecs, np.float64).reshape(-1, 3))
    n = len(vecs)
    dist = np.empty(n)
    gid = np.empty(n, np.int32)
    cut = float(cutoff) if math.isfinite(cutoff) else mujoco.mjMAXVAL
    mujoco.mj_multiRay(m, d, np.asarray(pnt, np.float64), vecs.ravel(), _group_mask(geomgroup), 1, -1, gid, dist,
                       None, n, cut)
    return np.where(dist < 0, np.inf, dist), gid


def ray_groups_mask(groups: Sequence[int], include_floor: bool = True) -> tuple[int, ...]:
    """MuJoCo geomgroup flags selecting ``groups`` (and the floor, group 0)."""
    g = [0] * mujoco.mjNGROUP
    for k in groups:
        g[k] = 1
    if include_floor:
        g[0] = 1
    return tuple(g)


# ---------------------------------------------------------------------------
# Random rays, agreement and benchmark
# ---------------------------------------------------------------------------


def random_rays(grid: NavGrid, n_origins: int, per_origin: int, rng: np.random.Generator,
                heights=(0.1, 2.0), pitch_deg: float = 45.0, horizontal: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Random rays from random navigable points.

    Origins are uniform over navigable cells (jittered within the cell) at
    heights uniform in ``heights``; each origin gets ``per_origin`` rays with
    uniform yaw and pitch uniform in ``[-pitch_deg, pitch_deg]`` (0 when
    ``horizontal``). Rays are grouped by origin (ray ``i`` starts at origin
    ``i // per_origin``), so :func:`mj_multiray` can cast them too.

    Returns:
        pnts: (n_origins * per_origin, 3); vecs: (n_origins * per_origin, 3) unit.
    """
    cells = np.argwhere(grid.navigable)
    if len(cells) == 0:
        raise ValueError(f"scene {grid.scene_id!r} has no navigable cells")
    pick = cells[rng.integers(0, len(cells), n_origins)]
    xy = grid.cell_to_world(pick) + rng.uniform(-0.5, 0.5, (n_origins, 2)) * grid.resolution
    z = rng.uniform(heights[0], heights[1], n_origins)
    o = np.concatenate([xy, z[:, None]], 1)
    n = n_origins * per_origin
    yaw = rng.uniform(-math.pi, math.pi, n)
    pitch = np.zeros(n) if horizontal else np.radians(rng.uniform(-pitch_deg, pitch_deg, n))
    vecs = np.stack([np.cos(yaw) * np.cos(pitch), np.sin(yaw) * np.cos(pitch), np.sin(pitch)], 1)
    return np.repeat(o, per_origin, axis=0), vecs


def agreement(d_fast, d_exact, max_dist: float, tol: float) -> np.ndarray:
    """Per-ray agreement of two distance arrays (see the module docstring).

    Args:
        d_fast, d_exact: (N,) distances, +inf (or anything > max_dist) on a miss.
        max_dist: the rays' range.
        tol: allowed distance difference for hits (one cell).

    Returns:
        (N,) bool.
    """
    f = np.asarray(d_fast, np.float64)
    e = np.asarray(d_exact, np.float64)
    hf, he = f <= max_dist, e <= max_dist
    both = hf & he & (np.abs(np.where(hf, f, 0) - np.where(he, e, 0)) <= tol)
    neither = ~hf & ~he
    edge = (np.abs(np.minimum(f, 1e9) - max_dist) <= 1e-3) | (np.abs(np.minimum(e, 1e9) - max_dist) <= 1e-3)
    return both | neither | (edge & (hf != he))


def _time_interleaved(fns: Sequence, repeat: int = 3) -> list[float]:
    """Best-of-``repeat`` seconds of each function after a warm-up, the
    functions taking turns in every round, so that a machine whose speed
    drifts (a shared VM) slows each of them alike and their ratios hold."""
    for fn in fns:
        fn()
    best = [math.inf] * len(fns)
    for _ in range(repeat):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            best[i] = min(best[i], time.perf_counter() - t0)
    return best


def benchmark_rays(compiled, grid: NavGrid, n_rays: int = 100_000, max_dist: float = 5.0, seed: int = 0,
                   horizontal: bool = False, heights=(0.1, 2.0), per_origin: int = 32,
                   include_floor: bool = True, repeat: int = 3) -> dict:
    """Throughput and agreement of the fast path against ``mjx.ray`` and
    ``mj_multiRay`` on the same random rays, in one process.

    Rays: :func:`random_rays` (``horizontal=True`` for collision rays), in
    groups of ``per_origin`` rays sharing an origin so that ``mj_multiRay``
    casts exactly the same rays (one call per origin, ``cutoff=max_dist``).
    Timed: the batched fast path (:func:`fast_rays`, jitted), raw
    ``mjx.ray`` (vmapped, jitted; it ignores cylinders), the exact path
    (:func:`exact_rays`: ``mjx.ray`` plus cylinders) and ``mj_multiRay``.
    Times are the best of ``repeat`` runs after a warm-up (compilation
    excluded), the four paths taking turns in every round. Agreement is measured against ``mj_multiRay`` with
    :func:`agreement` at a tolerance of one grid cell.

    Returns:
        dict: ``n_rays``, ``max_dist``, ``horizontal``, ``ngeom``,
        ``fast_rays_per_s``, ``mjx_rays_per_s``, ``exact_rays_per_s``,
        ``multiray_rays_per_s``, ``speedup_vs_mjx``, ``speedup_vs_multiray``,
        ``agreement`` (fast vs mj_multiRay), ``agreement_exact`` (exact path
        vs mj_multiRay, 1 mm) and ``hit_fraction``.
    """
    from mujoco import mjx

    rng = np.random.default_rng(seed)
    n_orig = max(n_rays // per_origin, 1)
    pnts, vecs = random_rays(grid, n_orig, per_origin, rng, heights=heights, horizontal=horizontal)
    n = len(pnts)
    rg = ray_grid(grid, compiled)
    groups = ray_groups_mask(grid.config.ray_groups, include_floor)
    P = jnp.asarray(pnts, jnp.float32)
    V = jnp.asarray(vecs, jnp.float32)
    fast = jax.jit(lambda p, v: fast_rays(rg, p, v, max_dist, 0, include_floor)[0])
    mx, dx = compiled.mjx_model, compiled.mjx_data
    raw = jax.jit(jax.vmap(lambda p, v: mjx.ray(mx, dx, p, v, geomgroup=groups)[0]))
    out = {}

    def run_fast():
        out["fast"] = jax.block_until_ready(fast(P, V))

    def run_raw():
        out["raw"] = jax.block_until_ready(raw(P, V))

    def run_exact():
        out["exact"] = jax.block_until_ready(exact_rays(compiled, P, V, groups)[0])

    def run_multi():
        res = []
        for i in range(n_orig):
            sl = slice(i * per_origin, (i + 1) * per_origin)
            res.append(mj_multiray(compiled, pnts[i * per_origin], vecs[sl], groups, cutoff=max_dist)[0])
        out["multi"] = np.concatenate(res)

    t_fast, t_raw, t_exact, t_multi = _time_interleaved((run_fast, run_raw, run_exact, run_multi), repeat)
    ref = out["multi"]
    agree = agreement(np.asarray(out["fast"]), ref, max_dist, grid.resolution)
    agree_exact = agreement(np.asarray(out["exact"]), ref, max_dist, 1e-3)
    return {
        "n_rays": int(n), "max_dist": float(max_dist), "horizontal": bool(horizontal), "ngeom": int(compiled.ngeom),
        "fast_rays_per_s": n / t_fast, "mjx_rays_per_s": n / t_raw, "exact_rays_per_s": n / t_exact,
        "multiray_rays_per_s": n / t_multi, "speedup_vs_mjx": t_raw / t_fast, "speedup_vs_multiray": t_multi / t_fast,
        "agreement": float(agree.mean()), "agreement_exact": float(agree_exact.mean()),
        "hit_fraction": float((ref <= max_dist).mean()),
    }
