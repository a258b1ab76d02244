"""Navigation grids derived from a compiled scene, and geodesic distance fields.

:func:`build_navgrid` turns a :class:`~ignjax.scenes.compile.CompiledScene`
into a :class:`NavGrid` (host-side numpy arrays): a voxel occupancy of every
non-floor geom, height-band occupancy, the navigable mask, a room-id grid,
connected components, and the acceleration structures of the fast ray caster
(:mod:`ignjax.sim.rays.caster`). :func:`geodesic_field` is the JAX array program
for geodesic distances on the navigable mask.

Cells
    The grid is axis-aligned, ``resolution`` metres per cell. Rows run along
    +y, columns along +x: cell ``(row, col)`` covers
    ``x in [origin_x + col * res, origin_x + (col + 1) * res)`` and
    ``y in [origin_y + row * res, origin_y + (row + 1) * res)``; its centre is
    ``origin + (col + 1/2, row + 1/2) * res``. ``origin`` (world x, y of the
    lower-left corner of cell (0, 0)) is a multiple of the resolution, so
    walls snapped to the resolution lie on cell boundaries. See
    :meth:`NavGrid.world_to_cell` and :meth:`NavGrid.cell_to_world`.

Voxels
    Slice ``k`` covers heights ``[k * slice_height, (k + 1) * slice_height)``
    from the floor (z = 0) up to ``n_slices * slice_height`` (the top of the
    scene's geometry, rounded up to whole list bands, or
    ``GridConfig.max_height``). Voxel ``(k, row, col)`` is occupied when some
    geom overlaps it (closed-box overlap, shrunk by 1 um so geometry that only
    touches a voxel face does not count). Every primitive is voxelized through
    its oriented bounding box (a box exactly; a cylinder, sphere, ellipsoid or
    capsule through its box, which contains it), with an exact separating-axis
    test, so the voxelization is conservative: a 2 mm laptop screen still
    marks every voxel it passes through. Meshes are voxelized by sampling
    their triangles at a spacing below 0.4 voxel (conservative up to that
    spacing); closed object meshes (geom group 2) are also filled inside.
    The floor plane (group 0) is never voxelized, and neither are invisible
    geoms (alpha 0, which ``mj_ray`` ignores too). The ray caster also marks
    the slice that an upright primitive's top or bottom face only touches
    (the face grown by 10 um, ``voxcode`` 2), so a horizontal ray at exactly
    a table top's height still finds the table.

Bands and navigability
    Band ``b`` (``GridConfig.bands``, heights in metres) is occupied in a cell
    when any slice overlapping the open interval ``(lo, hi)`` is occupied, so
    rugs below the lowest band and lintels above the highest do not block.
    A cell is *blocked* when it is occupied in some band or outside all
    rooms. A cell is *navigable* when it lies in a room and a disc of radius
    ``agent_radius`` around its centre overlaps no blocked cell (exact
    disc/square test). Components are 4-connected, which equals the
    connectivity of the 8-connected grid without corner cutting used by
    :func:`geodesic_field`.

Acceleration structures of the fast ray caster
    ``voxcode[k, r, c]`` (:func:`march_codes`): 0 for a voxel partly
    occupied, 1 for one entirely inside a primitive, 2 for a free voxel that
    a face only touches, ``c >= 3`` for a free voxel whose chessboard
    (L-infinity, voxel index units) distance to the nearest non-free voxel
    is ``c - 2``, so the cube of voxels within ``c - 3`` of it is free
    (``voxcode <= 1`` is the occupancy). ``sub_box`` (:func:`pack_sub_boxes`):
    the part of each non-free voxel, in quarters, that its geometry lies in.
    ``prims``: every primitive geom as one or more
    exact primitives (a box intersected with a quadric; a capsule is a
    cylinder and two spheres); the primitives overlapping column ``(r, c)``
    between heights ``b * list_band_height`` and ``(b + 1) *
    list_band_height`` (a column segment) are ``seg_prims[seg_start[r, c, b]:
    seg_start[r, c, b] + seg_count[r, c, b]]`` (compressed rows);
    ``approx[r, c, b]``: the segment holds more than ``max_list`` primitives
    or a mesh, so the ray caster stays at voxel accuracy there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
from scipy import ndimage

from ignjax.errors import ConfigError, SceneError
from ignjax.scenes.model import OrientedBox, Scene, points_in_polygon

#: Columns of a row of :attr:`NavGrid.prims`.
PRIM_COLUMNS = ("cx", "cy", "cz", "r00", "r01", "r02", "r10", "r11", "r12", "r20", "r21", "r22",
                "hx", "hy", "hz", "qa", "qb", "qc")
"""A primitive is ``{p : |p_local| <= h} & {qa x^2 + qb y^2 + qc z^2 <= 1}`` in
its local frame ``p_local = R^T (p - c)``; ``R`` is stored row-major. A box has
``q = 0``; a cylinder (radius r, half height h) ``h = (r, r, h), q = (1/r^2,
1/r^2, 0)``; an ellipsoid with semi-axes a, b, c ``h = (a, b, c), q = (1/a^2,
1/b^2, 1/c^2)``. An unused row has ``h = -1`` (never hit)."""

N_PRIM_COLUMNS = len(PRIM_COLUMNS)
_SHRINK = 1e-6  # metres: geometry that only touches a voxel face does not occupy it
_TOUCH = 1e-5  # metres: ...but the ray caster still looks there (rays grazing a face hit it, as in mj_ray)
VOX_PARTIAL, VOX_FULL, VOX_TOUCH = 0, 1, 2
FREE_MAX = 252  # largest chessboard distance stored (code 254; 255 is padding)


# ---------------------------------------------------------------------------
# Configuration
# ---------------------------------------------------------------------------


def _bad(name: str, reason: str) -> ConfigError:
    return ConfigError(None, f"GridConfig.{name}", reason)


@dataclass(frozen=True)
class GridConfig:
    """Static configuration of navigation grids (validated on construction).

    Attributes:
        resolution: cell size in x and y, metres.
        agent_radius: radius of the agent's footprint disc, metres. 0.18 m is
            a compact wheeled robot (LoCoBot-like); procedural houses keep
            their passages connected for a 0.2 m radius, so anything up to
            that works on them.
        bands: height bands ``(lo, hi)`` in metres, increasing and disjoint:
            by default low furniture (beds, seats: 0.05-0.45 m), table level
            (0.45-1.0 m) and tall furniture (1.0-1.9 m). Geometry below the
            first band (rugs) or above the last (lintels, ceiling lamps) never
            blocks the agent.
        band_names: one name per band.
        margin: free border around the scene's bounds, metres.
        slice_height: voxel height, metres; must divide ``list_band_height``.
        max_height: top of the voxel grid, metres; None (default) covers the
            scene's geometry (rounded up to whole list bands). Geometry above
            it is ignored by the voxel grid and the fast ray caster.
        list_band_height: height of the column segments whose primitive lists
            the fast ray caster tests exactly, metres.
        max_list: at most this many primitives per column segment; fuller
            segments fall back to voxel accuracy (counted in
            :attr:`NavGrid.n_approx`).
        ray_groups: MuJoCo geom groups that are obstacles and ray targets
            (default walls 1, objects 2, structural instances 3; the floor,
            group 0, is handled analytically by the ray caster).
    """

    resolution: float = 0.05
    agent_radius: float = 0.18
    bands: tuple[tuple[float, float], ...] = ((0.05, 0.45), (0.45, 1.0), (1.0, 1.9))
    band_names: tuple[str, ...] = ("low", "table", "tall")
    margin: float = 0.5
    slice_height: float = 0.05
    max_height: float | None = None
    list_band_height: float = 0.25
    max_list: int = 32
    ray_groups: tuple[int, ...] = (1, 2, 3)

    def __post_init__(self):
        def pos(name):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v <= 0:
                raise _bad(name, f"must be a positive number, got {v!r}")
            object.__setattr__(self, name, float(v))

        for name in ("resolution", "slice_height", "list_band_height"):
            pos(name)
        for name in ("agent_radius", "margin"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v < 0:
                raise _bad(name, f"must be a non-negative number, got {v!r}")
            object.__setattr__(self, name, float(v))
        if self.max_height is not None:
            pos("max_height")
        ratio = self.list_band_height / self.slice_height
        if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
            raise _bad("list_band_height",
                       f"must be a whole number of slice_height ({self.slice_height}), got {self.list_band_height}")
        try:
            bands = tuple((float(lo), float(hi)) for lo, hi in self.bands)
        except (TypeError, ValueError):
            raise _bad("bands", f"expected a sequence of (lo, hi) pairs, got {self.bands!r}") from None
        if not bands:
            raise _bad("bands", "needs at least one (lo, hi) band")
        prev = -math.inf
        for lo, hi in bands:
            if not (math.isfinite(lo) and math.isfinite(hi)) or lo < 0 or hi <= lo or lo < prev:
                raise _bad("bands",
                           f"bands must be increasing, disjoint (lo, hi) pairs with 0 <= lo < hi, got {self.bands}")
            prev = hi
        object.__setattr__(self, "bands", bands)
        names = tuple(str(n) for n in self.band_names)
        if len(names) != len(bands):
            names = tuple(f"band_{i}" for i in range(len(bands))) if self.band_names == GridConfig.band_names else names
        if len(names) != len(bands):
            raise _bad("band_names", f"needs one name per band ({len(bands)}), got {len(names)}")
        object.__setattr__(self, "band_names", names)
        if not isinstance(self.max_list, int) or isinstance(self.max_list, bool) or not 1 <= self.max_list <= 255:
            raise _bad("max_list", f"must be an integer in 1..255, got {self.max_list!r}")
        try:
            groups = tuple(int(g) for g in self.ray_groups)
        except (TypeError, ValueError):
            raise _bad("ray_groups", f"expected a sequence of integers, got {self.ray_groups!r}") from None
        if any(g < 0 or g >= mujoco.mjNGROUP for g in groups):
            raise _bad("ray_groups", f"groups must be in 0..{mujoco.mjNGROUP - 1}, got {self.ray_groups}")
        object.__setattr__(self, "ray_groups", groups)

    @property
    def slices_per_list_band(self) -> int:
        return int(round(self.list_band_height / self.slice_height))


# ---------------------------------------------------------------------------
# The grid
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class NavGrid:
    """A scene's navigation grid (host-side numpy). See the module docstring
    for the cell and voxel conventions.

    Attributes:
        scene_id: the scene's id.
        config: the configuration used.
        origin: (2,) float64, world (x, y) of the lower-left corner of cell (0, 0).
        shape: (H, W) = (rows along y, columns along x).
        n_slices: number of voxel slices (Z).
        room_ids: scene room ids; ``room[r, c] = i`` means ``room_ids[i]``.
        occupancy: (Z, H, W) bool voxel occupancy of non-floor geoms.
        bands: (n_bands, H, W) bool band occupancy.
        obstacle: (H, W) bool, occupied in some band.
        room: (H, W) int32 index of the first room (scene order) whose floor
            polygon contains the cell centre, -1 outside all rooms.
        clearance: (H, W) float32, metres from the cell centre to the nearest
            blocked cell's centre (blocked: obstacle or outside all rooms).
        navigable: (H, W) bool.
        components: (H, W) int32 component label of navigable cells, -1 elsewhere.
        n_components: number of components.
        voxcode: (Z, H, W) uint8 march code of each voxel (see :func:`march_codes`).
        sub_box: (Z, H, W) uint16 where in each occupied voxel its geometry
            lies (see :func:`pack_sub_boxes`); 0 in free voxels.
        prims: (P, 18) float32 exact primitives, see :data:`PRIM_COLUMNS`.
        prim_geom: (P,) int32 MuJoCo geom id of each primitive.
        seg_start: (H, W, B) int32 first entry of each column segment in ``seg_prims``.
        seg_count: (H, W, B) uint8 number of primitives of each segment.
        seg_prims: (M,) int32 primitive indices, segment after segment.
        approx: (H, W, B) bool, segment kept at voxel accuracy.
        n_approx: number of approximate segments that are occupied.
    """

    scene_id: str
    config: GridConfig
    origin: np.ndarray
    shape: tuple[int, int]
    n_slices: int
    room_ids: tuple[str, ...]
    occupancy: np.ndarray
    bands: np.ndarray
    obstacle: np.ndarray
    room: np.ndarray
    clearance: np.ndarray
    navigable: np.ndarray
    components: np.ndarray
    n_components: int
    voxcode: np.ndarray
    sub_box: np.ndarray
    prims: np.ndarray
    prim_geom: np.ndarray
    seg_start: np.ndarray
    seg_count: np.ndarray
    seg_prims: np.ndarray
    approx: np.ndarray
    n_approx: int

    @property
    def resolution(self) -> float:
        return self.config.resolution

    @property
    def slice_height(self) -> float:
        return self.config.slice_height

    @property
    def height(self) -> float:
        """Top of the voxel grid, metres."""
        return self.n_slices * self.config.slice_height

    def world_to_cell(self, xy) -> np.ndarray:
        """(..., 2) world (x, y) -> (..., 2) int (row, col); may be out of range."""
        p = np.asarray(xy, dtype=np.float64)
        col = np.floor((p[..., 0] - self.origin[0]) / self.resolution)
        row = np.floor((p[..., 1] - self.origin[1]) / self.resolution)
        return np.stack([row, col], -1).astype(np.int64)

    def cell_to_world(self, rc) -> np.ndarray:
        """(..., 2) (row, col) -> (..., 2) world (x, y) of the cell centres."""
        q = np.asarray(rc, dtype=np.float64)
        x = self.origin[0] + (q[..., 1] + 0.5) * self.resolution
        y = self.origin[1] + (q[..., 0] + 0.5) * self.resolution
        return np.stack([x, y], -1)

    def in_bounds(self, rc) -> np.ndarray:
        """(..., 2) (row, col) -> (...) bool, inside the grid."""
        q = np.asarray(rc)
        return (q[..., 0] >= 0) & (q[..., 0] < self.shape[0]) & (q[..., 1] >= 0) & (q[..., 1] < self.shape[1])

    def cell_centers(self) -> np.ndarray:
        """(H, W, 2) world (x, y) of every cell centre."""
        rows, cols = np.mgrid[0:self.shape[0], 0:self.shape[1]]
        return self.cell_to_world(np.stack([rows, cols], -1))

    def room_index(self, room_id: str | None) -> int:
        """Index of a room id in :attr:`room_ids` (-1 for None)."""
        if room_id is None:
            return -1
        return self.room_ids.index(room_id)

    def navigable_points(self) -> np.ndarray:
        """(M, 2) world (x, y) centres of the navigable cells."""
        return self.cell_to_world(np.argwhere(self.navigable))


# ---------------------------------------------------------------------------
# Primitives and voxelization
# ---------------------------------------------------------------------------


def _prim_row(center, rot, half, quad) -> np.ndarray:
    row = np.empty(N_PRIM_COLUMNS, dtype=np.float64)
    row[0:3] = center
    row[3:12] = np.asarray(rot, dtype=np.float64).reshape(9)
    row[12:15] = half
    row[15:18] = quad
    return row


def geom_prims(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> list[np.ndarray]:
    """Exact primitives (rows of :data:`PRIM_COLUMNS`) of one primitive geom.

    Returns an empty list for planes, meshes and other non-primitive types.
    """
    t = int(model.geom_type[geom])
    s = model.geom_size[geom].astype(np.float64)
    c = data.geom_xpos[geom].astype(np.float64)
    R = data.geom_xmat[geom].reshape(3, 3).astype(np.float64)
    G = mujoco.mjtGeom
    if t == G.mjGEOM_BOX:
        return [_prim_row(c, R, s, (0.0, 0.0, 0.0))]
    if t == G.mjGEOM_SPHERE:
        r = s[0]
        return [_prim_row(c, R, (r, r, r), (1 / r**2,) * 3)]
    if t == G.mjGEOM_ELLIPSOID:
        return [_prim_row(c, R, s, 1.0 / s**2)]
    if t == G.mjGEOM_CYLINDER:
        r, h = s[0], s[1]
        return [_prim_row(c, R, (r, r, h), (1 / r**2, 1 / r**2, 0.0))]
    if t == G.mjGEOM_CAPSULE:
        r, h = s[0], s[1]
        axis = R[:, 2]
        return [
            _prim_row(c, R, (r, r, h), (1 / r**2, 1 / r**2, 0.0)),
            _prim_row(c + h * axis, R, (r, r, r), (1 / r**2,) * 3),
            _prim_row(c - h * axis, R, (r, r, r), (1 / r**2,) * 3),
        ]
    return []


def _geom_visible(model: mujoco.MjModel, geom: int) -> bool:
    """Whether ``mj_ray`` can hit the geom (it skips fully transparent geoms)."""
    mat = int(model.geom_matid[geom])
    if mat >= 0:
        return bool(model.mat_rgba[mat, 3] != 0)
    return bool(model.geom_rgba[geom, 3] != 0)


class _Voxelizer:
    """Marks voxels overlapped by boxes and triangles on a (Z, H, W) grid."""

    def __init__(self, origin: np.ndarray, shape: tuple[int, int], n_slices: int, res: float, dz: float):
        self.lo = np.array([origin[0], origin[1], 0.0])
        self.cell = np.array([res, res, dz])
        self.dims = np.array([shape[1], shape[0], n_slices])  # x, y, z counts

    def _range(self, lo, hi):
        i0 = np.floor((lo - self.lo) / self.cell).astype(np.int64)
        i1 = np.floor((hi - self.lo) / self.cell).astype(np.int64)
        return np.maximum(i0, 0), np.minimum(i1, self.dims - 1)

    def box(self, center, rot, half) -> tuple[np.ndarray, np.ndarray]:
        """Voxels overlapping an oriented box (separating-axis test).

        Returns:
            idx: (M, 3) voxel (ix, iy, iz) indices overlapping the box; an
                upright box is grown by :data:`_TOUCH` vertically (a voxel its
                top or bottom face merely touches is included, for horizontal
                rays at exactly that height), any other box in every direction.
            strict: (M,) bool, the voxel overlaps the box shrunk by
                :data:`_SHRINK` (what occupancy and navigation use).
        """
        center = np.asarray(center, dtype=np.float64)
        rot = np.asarray(rot, dtype=np.float64).reshape(3, 3)
        half = np.asarray(half, dtype=np.float64)
        grown = half + _TOUCH
        shrunk = np.maximum(half - _SHRINK, 0.0)
        ext = np.abs(rot) @ grown
        i0, i1 = self._range(center - ext, center + ext)
        if np.any(i1 < i0):
            return np.zeros((0, 3), np.int64), np.zeros(0, bool)
        vh = self.cell / 2
        if abs(abs(rot[2, 2]) - 1.0) < 1e-9:
            # upright: 2-D separating axes in xy, exact z intervals
            xs = np.arange(i0[0], i1[0] + 1)
            ys = np.arange(i0[1], i1[1] + 1)
            dx = (self.lo[0] + (xs + 0.5) * self.cell[0])[None, :] - center[0]
            dy = (self.lo[1] + (ys + 0.5) * self.cell[1])[:, None] - center[1]
            u, v = rot[:2, 0], rot[:2, 1]
            ok_s = np.ones((len(ys), len(xs)), bool)
            for ax in (np.array([1.0, 0.0]), np.array([0.0, 1.0]), u, v):
                sep = np.abs(dx * ax[0] + dy * ax[1]) - (vh[0] * abs(ax[0]) + vh[1] * abs(ax[1]))
                ok_s &= sep <= shrunk[0] * abs(ax @ u) + shrunk[1] * abs(ax @ v)
            yy, xx = np.nonzero(ok_s)
            if len(xx) == 0:
                return np.zeros((0, 3), np.int64), np.zeros(0, bool)
            zs = np.arange(i0[2], i1[2] + 1)
            zc = self.lo[2] + (zs + 0.5) * self.cell[2]
            z_s = np.abs(zc - center[2]) <= vh[2] + shrunk[2]
            n = len(zs)
            idx = np.stack([np.repeat(xs[xx], n), np.repeat(ys[yy], n), np.tile(zs, len(xx))], -1)
            strict = np.tile(z_s, len(xx))
            return idx, strict
        grids = np.meshgrid(*[np.arange(a, b + 1) for a, b in zip(i0, i1)], indexing="ij")
        idx = np.stack([g.ravel() for g in grids], -1)
        d = self.lo + (idx + 0.5) * self.cell - center
        # the 15 separating axes: world axes, box axes and their cross products
        cross = np.cross(np.eye(3)[:, None, :], rot.T[None, :, :]).reshape(9, 3)
        norm = np.linalg.norm(cross, axis=1)
        axes = np.concatenate([np.eye(3), rot.T, cross[norm > 1e-9] / norm[norm > 1e-9, None]])  # Shape: (A, 3)
        sep = np.abs(d @ axes.T) - np.abs(axes) @ vh  # Shape: (M, A)
        proj = np.abs(axes @ rot)  # Shape: (A, 3): |axis . box axis j|
        ok_g = np.all(sep <= proj @ grown, axis=1)
        ok_s = np.all(sep <= proj @ shrunk, axis=1)
        return idx[ok_g], ok_s[ok_g]

    def sub_box(self, idx: np.ndarray, row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Quantised bounds (in 1/SUB_Q voxel) of a primitive's bounding box
        (grown by :data:`_TOUCH`) within each voxel: (M, 3) low and high
        quarter indices such that the box lies in ``[lo, hi + 1] / SUB_Q``."""
        c, R, h = row[0:3], row[3:12].reshape(3, 3), row[12:15]
        ext = np.abs(R) @ (h + _TOUCH)
        v0 = self.lo + idx * self.cell
        lo = np.clip((c - ext - v0) / self.cell, 0.0, 1.0)
        hi = np.clip((c + ext - v0) / self.cell, 0.0, 1.0)
        qlo = np.clip(np.floor(lo * SUB_Q), 0, SUB_Q - 1).astype(np.uint8)
        qhi = np.clip(np.ceil(hi * SUB_Q) - 1, 0, SUB_Q - 1).astype(np.uint8)
        return qlo, np.maximum(qhi, qlo)

    def inside(self, idx: np.ndarray, row: np.ndarray) -> np.ndarray:
        """(M,) bool: voxel lies entirely inside the primitive ``row`` (all
        eight corners inside a convex set)."""
        c, R, h, q = row[0:3], row[3:12].reshape(3, 3), row[12:15], row[15:18]
        if len(idx) == 0 or 2 * h.min() + 2 * _SHRINK < self.cell.min():
            return np.zeros(len(idx), bool)  # too thin to hold a whole voxel
        corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], np.float64)
        pts = self.lo + (idx[:, None, :] + corners[None]) * self.cell  # Shape: (M, 8, 3)
        loc = (pts - c) @ R  # local frame
        ok = np.all(np.abs(loc) <= h + _SHRINK, axis=-1) & ((loc**2 * q).sum(-1) <= 1.0 + 1e-9)
        return ok.all(1)

    def triangles(self, verts: np.ndarray, faces: np.ndarray) -> np.ndarray:
        """(M, 3) voxel indices hit by samples of the triangles (spacing < 0.4 voxel)."""
        spacing = 0.4 * float(self.cell.min())
        a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
        edge = np.maximum.reduce([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1),
                                  np.linalg.norm(a - c, axis=1)])
        n_sub = np.maximum(np.ceil(edge / spacing).astype(np.int64), 1)
        out = []
        for n in np.unique(n_sub):
            sel = n_sub == n
            i, j = np.mgrid[0:n + 1, 0:n + 1]
            keep = i + j <= n
            u = (i[keep] / n)[None, :, None]
            v = (j[keep] / n)[None, :, None]
            pts = a[sel, None] + u * (b[sel, None] - a[sel, None]) + v * (c[sel, None] - a[sel, None])
            out.append(pts.reshape(-1, 3))
        pts = np.concatenate(out) if out else np.zeros((0, 3))
        idx = np.floor((pts - self.lo) / self.cell).astype(np.int64)
        ok = np.all((idx >= 0) & (idx < self.dims), axis=1)
        return np.unique(idx[ok], axis=0)


def _mesh_world(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> tuple[np.ndarray, np.ndarray]:
    mid = int(model.geom_dataid[geom])
    v0, nv = int(model.mesh_vertadr[mid]), int(model.mesh_vertnum[mid])
    f0, nf = int(model.mesh_faceadr[mid]), int(model.mesh_facenum[mid])
    verts = model.mesh_vert[v0:v0 + nv].astype(np.float64)
    faces = model.mesh_face[f0:f0 + nf].astype(np.int64)
    R = data.geom_xmat[geom].reshape(3, 3)
    return verts @ R.T + data.geom_xpos[geom], faces


def _watertight(faces: np.ndarray) -> bool:
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    e = np.sort(e, axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return bool(len(counts) and np.all(counts == 2))


def _fill_inside(vox: np.ndarray) -> np.ndarray:
    """Fill the enclosed interior of a voxelized closed surface."""
    if len(vox) == 0:
        return vox
    lo = vox.min(0)
    hi = vox.max(0)
    block = np.zeros(tuple(hi - lo + 1), bool)
    block[tuple((vox - lo).T)] = True
    filled = ndimage.binary_fill_holes(block)
    return np.argwhere(filled) + lo


def _scene_extent(compiled, config: GridConfig) -> tuple[np.ndarray, tuple[int, int], int]:
    """Grid origin, (H, W) and number of slices covering the scene."""
    scene: Scene = compiled.scene
    lo, hi = scene.bounds()
    model, data = compiled.model, compiled.data
    top = float(hi[2]) if len(scene.rooms) else 0.0
    for g in range(model.ngeom):
        if int(model.geom_group[g]) not in config.ray_groups or model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE:
            continue
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            verts, _ = _mesh_world(model, data, g)
            if len(verts) == 0:
                continue
            glo, ghi = verts.min(0), verts.max(0)
        else:
            rows = geom_prims(model, data, g)
            if not rows:
                continue
            ext = np.stack([np.abs(r[3:12].reshape(3, 3)) @ r[12:15] for r in rows])
            ctr = np.stack([r[0:3] for r in rows])
            glo, ghi = (ctr - ext).min(0), (ctr + ext).max(0)
        lo[:2] = np.minimum(lo[:2], glo[:2])
        hi[:2] = np.maximum(hi[:2], ghi[:2])
        top = max(top, float(ghi[2]))
    res = config.resolution
    origin = np.floor((lo[:2] - config.margin) / res + 1e-9) * res
    far = np.ceil((hi[:2] + config.margin) / res - 1e-9) * res
    W = max(int(round((far[0] - origin[0]) / res)), 1)
    H = max(int(round((far[1] - origin[1]) / res)), 1)
    if config.max_height is not None:
        height = config.max_height
    else:
        lb = config.list_band_height
        height = max(math.ceil(top / lb - 1e-9), 1) * lb
    n_slices = max(int(math.ceil(height / config.slice_height - 1e-9)), 1)
    return origin, (H, W), n_slices


def _voxelize(compiled, config: GridConfig, origin, shape, n_slices):
    """Occupancy, exact primitives and their (column, list band) memberships."""
    model, data = compiled.model, compiled.data
    H, W = shape
    vz = _Voxelizer(origin, shape, n_slices, config.resolution, config.slice_height)
    occ = np.zeros((n_slices, H, W), bool)
    occ_ray = np.zeros((n_slices, H, W), bool)
    full = np.zeros((n_slices, H, W), bool)
    sub_lo = np.full((n_slices, H, W, 3), SUB_Q - 1, np.uint8)
    sub_hi = np.zeros((n_slices, H, W, 3), np.uint8)
    spb = config.slices_per_list_band
    n_lb = -(-n_slices // spb)
    prims: list[np.ndarray] = []
    prim_geom: list[int] = []
    keys: list[np.ndarray] = []  # (column-segment key, prim index or -1 for meshes)
    vals: list[np.ndarray] = []
    mesh_keys: list[np.ndarray] = []
    G = mujoco.mjtGeom
    for g in range(model.ngeom):
        if int(model.geom_group[g]) not in config.ray_groups or not _geom_visible(model, g):
            continue
        t = int(model.geom_type[g])
        if t == G.mjGEOM_PLANE:
            continue
        if t == G.mjGEOM_MESH:
            verts, faces = _mesh_world(model, data, g)
            vox = vz.triangles(verts, faces)
            if int(model.geom_group[g]) == 2 and _watertight(faces):
                vox = _fill_inside(vox)
            if len(vox):
                occ[vox[:, 2], vox[:, 1], vox[:, 0]] = True
                occ_ray[vox[:, 2], vox[:, 1], vox[:, 0]] = True
                sub_lo[vox[:, 2], vox[:, 1], vox[:, 0]] = 0
                sub_hi[vox[:, 2], vox[:, 1], vox[:, 0]] = SUB_Q - 1
                mesh_keys.append(np.unique((vox[:, 1] * W + vox[:, 0]) * n_lb + vox[:, 2] // spb))
            continue
        for row in geom_prims(model, data, g):
            vox, strict = vz.box(row[0:3], row[3:12], row[12:15])
            p = len(prims)
            prims.append(row)
            prim_geom.append(g)
            if len(vox) == 0:
                continue
            occ_ray[vox[:, 2], vox[:, 1], vox[:, 0]] = True
            qlo, qhi = vz.sub_box(vox, row)
            at = (vox[:, 2], vox[:, 1], vox[:, 0])
            np.minimum.at(sub_lo, at, qlo)
            np.maximum.at(sub_hi, at, qhi)
            sv = vox[strict]
            occ[sv[:, 2], sv[:, 1], sv[:, 0]] = True
            inner = sv[vz.inside(sv, row)]
            full[inner[:, 2], inner[:, 1], inner[:, 0]] = True
            k = np.unique((vox[:, 1] * W + vox[:, 0]) * n_lb + vox[:, 2] // spb)
            keys.append(k)
            vals.append(np.full(len(k), p, np.int64))
    K = config.max_list
    n_seg = H * W * n_lb
    approx = np.zeros(n_seg, bool)
    if keys:
        key = np.concatenate(keys)
        val = np.concatenate(vals)
        order = np.lexsort((val, key))
        key, val = key[order], val[order]
        count = np.bincount(key, minlength=n_seg)
        approx |= count > K
        keep = ~approx[key]
        key, val = key[keep], val[keep]
        count = np.bincount(key, minlength=n_seg)
        start = np.concatenate([[0], np.cumsum(count)[:-1]])
        seg_prims = val.astype(np.int32)
    else:
        count = np.zeros(n_seg, np.int64)
        start = np.zeros(n_seg, np.int64)
        seg_prims = np.zeros(0, np.int32)
    if mesh_keys:
        approx[np.concatenate(mesh_keys)] = True
    prim_arr = np.stack(prims).astype(np.float32) if prims else np.zeros((0, N_PRIM_COLUMNS), np.float32)
    seg = (start.astype(np.int32).reshape(H, W, n_lb), count.astype(np.uint8).reshape(H, W, n_lb), seg_prims)
    sub = pack_sub_boxes(sub_lo, sub_hi)
    sub[~occ_ray] = 0
    return occ, occ_ray, full, sub, prim_arr, np.asarray(prim_geom, np.int32), seg, approx.reshape(H, W, n_lb)


SUB_Q = 4
"""Sub-voxel quantisation of :attr:`NavGrid.sub_box` (quarters of a voxel)."""


def pack_sub_boxes(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Pack per-voxel sub-boxes into uint16.

    Args:
        lo, hi: (..., 3) uint8 quarter indices 0..3 along (x, y, z): the
            geometry in a voxel lies within ``[lo / 4, (hi + 1) / 4]`` of it
            along each axis (a conservative bound of the primitives' bounding
            boxes clipped to the voxel).

    Returns:
        (...) uint16: bits ``2a`` and ``2a + 1`` hold ``lo[a]``, bits
        ``6 + 2a`` and ``7 + 2a`` hold ``hi[a]``.
    """
    lo = lo.astype(np.uint16)
    hi = hi.astype(np.uint16)
    return (lo[..., 0] | lo[..., 1] << 2 | lo[..., 2] << 4 | hi[..., 0] << 6 | hi[..., 1] << 8
            | hi[..., 2] << 10).astype(np.uint16)


def march_codes(occupied: np.ndarray, touched: np.ndarray, full: np.ndarray) -> np.ndarray:
    """Voxel codes of the fast ray march, (Z, H, W) uint8.

    ``0`` (:data:`VOX_PARTIAL`): partly occupied (the ray tests the
    primitives exactly); ``1`` (:data:`VOX_FULL`): entirely inside one
    primitive (a ray entering it from free space hits its face exactly
    there); ``2`` (:data:`VOX_TOUCH`): free, but a primitive's face touches it
    (the ray tests it like a partly occupied voxel, for rays lying exactly in
    that face's plane); ``c >= 3``: free, and the chessboard distance (voxel
    index units) to the nearest voxel of the other kinds is ``c - 2``, so
    every voxel within ``c - 3`` of it is free (clipped to :data:`FREE_MAX`).
    Occupancy is ``code <= 1``.

    Args:
        occupied: (Z, H, W) bool, geometry overlaps the voxel.
        touched: (Z, H, W) bool, geometry overlaps or touches it.
        full: (Z, H, W) bool, the voxel lies inside one primitive.
    """
    touched = touched | occupied
    if touched.any():
        cheb = ndimage.distance_transform_cdt(~touched, metric="chessboard")
        cheb = np.minimum(cheb, FREE_MAX)
    else:
        cheb = np.full(touched.shape, FREE_MAX)
    code = (cheb + 2).astype(np.uint8)
    code[touched] = VOX_TOUCH
    code[occupied] = VOX_PARTIAL
    code[full & occupied] = VOX_FULL
    return code


def _band_occupancy(occ: np.ndarray, config: GridConfig) -> np.ndarray:
    dz = config.slice_height
    out = []
    for lo, hi in config.bands:
        k0 = int(math.floor(lo / dz + 1e-9))
        k1 = int(math.ceil(hi / dz - 1e-9))  # slices k0..k1-1 overlap (lo, hi)
        k1 = min(k1, occ.shape[0])
        if k1 <= k0:
            out.append(np.zeros(occ.shape[1:], bool))
        else:
            out.append(occ[k0:k1].any(0))
    return np.stack(out)


def _disc_footprint(radius: float, res: float) -> np.ndarray:
    """Offsets (as a boolean kernel) of cells whose square lies within
    ``radius`` of the centre of the kernel's middle cell."""
    n = int(math.ceil(radius / res + 0.5))
    o = np.arange(-n, n + 1)
    dx = np.maximum(np.abs(o)[None, :] - 0.5, 0.0) * res
    dy = np.maximum(np.abs(o)[:, None] - 0.5, 0.0) * res
    return dx**2 + dy**2 < radius**2


def room_grid(scene: Scene, origin, shape, res: float) -> np.ndarray:
    """(H, W) int32 index of the first room containing each cell centre, -1 if none."""
    H, W = shape
    out = np.full((H, W), -1, np.int32)
    for i, room in enumerate(scene.rooms):
        poly = np.asarray(room.polygon, dtype=np.float64)
        if len(poly) < 3:
            continue
        c0 = max(int(math.floor((poly[:, 0].min() - origin[0]) / res)) - 1, 0)
        c1 = min(int(math.ceil((poly[:, 0].max() - origin[0]) / res)) + 1, W)
        r0 = max(int(math.floor((poly[:, 1].min() - origin[1]) / res)) - 1, 0)
        r1 = min(int(math.ceil((poly[:, 1].max() - origin[1]) / res)) + 1, H)
        if c1 <= c0 or r1 <= r0:
            continue
        xs = origin[0] + (np.arange(c0, c1) + 0.5) * res
        ys = origin[1] + (np.arange(r0, r1) + 0.5) * res
        pts = np.stack(np.meshgrid(xs, ys), -1)
        inside = points_in_polygon(pts, poly)
        sub = out[r0:r1, c0:c1]
        sub[(sub < 0) & inside] = i
    return out


def build_navgrid(compiled, config: GridConfig = GridConfig()) -> NavGrid:
    """Build a scene's navigation grid from its compiled MuJoCo model.

    Args:
        compiled: a :class:`~ignjax.scenes.compile.CompiledScene` (geom world
            poses are read from ``compiled.data`` after ``mj_forward``).
        config: grid configuration.

    Returns:
        The :class:`NavGrid`.
    """
    if not isinstance(config, GridConfig):
        raise ConfigError(None, "config", f"expected GridConfig, got {type(config).__name__}")
    scene: Scene = compiled.scene
    origin, shape, n_slices = _scene_extent(compiled, config)
    occ, occ_ray, full, sub_box, prims, prim_geom, (seg_start, seg_count, seg_prims), approx = _voxelize(
        compiled, config, origin, shape, n_slices)
    bands = _band_occupancy(occ, config)
    obstacle = bands.any(0)
    room = room_grid(scene, origin, shape, config.resolution)
    blocked = obstacle | (room < 0)
    clearance = ndimage.distance_transform_edt(~blocked, sampling=config.resolution).astype(np.float32)
    if not blocked.any():
        clearance[:] = np.inf
    near = ndimage.binary_dilation(blocked, structure=_disc_footprint(config.agent_radius, config.resolution)) \
        if config.agent_radius > 0 else blocked
    navigable = (room >= 0) & ~near & ~blocked
    labels, n = ndimage.label(navigable)
    components = (labels - 1).astype(np.int32)
    voxcode = march_codes(occ, occ_ray, full)
    n_approx = int(approx.sum())
    return NavGrid(
        scene_id=scene.id, config=config, origin=origin, shape=shape, n_slices=n_slices,
        room_ids=tuple(r.id for r in scene.rooms), occupancy=occ, bands=bands, obstacle=obstacle,
        room=room, clearance=clearance, navigable=navigable, components=components, n_components=int(n),
        voxcode=voxcode, sub_box=sub_box, prims=prims, prim_geom=prim_geom, seg_start=seg_start,
        seg_count=seg_count, seg_prims=seg_prims, approx=approx, n_approx=n_approx,
    )


# ---------------------------------------------------------------------------
# Reachability
# ---------------------------------------------------------------------------


def unreachable_rooms(scene: Scene, grid: NavGrid) -> list[str]:
    """Ids of rooms with no navigable cell in the main component.

    The main component is the navigable component touching the most rooms
    (ties: the larger one). A room is reachable when some navigable cell of
    it lies in the main component.
    """
    labels = grid.components
    n_rooms = len(grid.room_ids)
    if n_rooms == 0:
        return []
    if grid.n_components == 0:
        return list(grid.room_ids)
    nav = grid.navigable
    pairs = np.unique(np.stack([grid.room[nav], labels[nav]], -1), axis=0)
    pairs = pairs[pairs[:, 0] >= 0]
    rooms_per_comp = np.bincount(pairs[:, 1], minlength=grid.n_components)
    size = np.bincount(labels[nav], minlength=grid.n_components)
    main = int(np.lexsort((size, rooms_per_comp))[-1])
    reached = set(pairs[pairs[:, 1] == main, 0].tolist())
    return [grid.room_ids[i] for i in range(n_rooms) if i not in reached]


def check_reachable(scene: Scene, grid: NavGrid, path: str | None = None) -> None:
    """Raise :class:`~ignjax.errors.SceneError` unless every room has a
    navigable cell in one common navigable component.

    Args:
        scene: the scene the grid was built from.
        grid: its navigation grid.
        path: the source file to name in the error (default ``scene.meta.source``).

    Raises:
        SceneError: naming every unreachable room (id, label, and whether it
            has no navigable cells at all).
    """
    bad = unreachable_rooms(scene, grid)
    if not bad:
        return
    parts = []
    for rid in bad:
        i = grid.room_index(rid)
        n_cells = int((grid.navigable & (grid.room == i)).sum())
        label = scene.room(rid).label
        why = "has no navigable cells" if n_cells == 0 else f"is cut off from the rest ({n_cells} navigable cells)"
        parts.append(f"{rid} ({label}) {why}")
    reached = [r for r in grid.room_ids if r not in bad]
    raise SceneError(
        path or scene.meta.source, f"scene {scene.id!r} navigation grid",
        f"rooms not reachable from the others for an agent of radius {grid.config.agent_radius} m: "
        + "; ".join(parts) + (f" (reachable: {', '.join(reached)})" if reached else ""),
    )


# ---------------------------------------------------------------------------
# Geodesic distance fields (JAX)
# ---------------------------------------------------------------------------


_REL_TOL = 4e-7  # about 3 float32 ulps


def _sweep(d: jax.Array, w: jax.Array, axis: int, reverse: bool) -> jax.Array:
    """One directional relaxation pass along ``axis`` (a ``lax.scan``).

    ``w[i]`` is the cost of the edge from element ``i - 1`` (``i + 1`` when
    ``reverse``) to element ``i`` along ``axis``, +inf when absent; the pass
    computes ``d'[i] = min(d[i], d'[i -/+ 1] + w[i])``, so it relaxes a whole
    straight run of cells at once.
    """
    dm = jnp.moveaxis(d, axis, 0)
    wm = jnp.moveaxis(w, axis, 0)

    def step(prev, x):
        di, wi = x
        cur = jnp.minimum(di, prev + wi)
        return cur, cur

    _, out = jax.lax.scan(step, jnp.full(dm.shape[1:], jnp.inf, dm.dtype), (dm, wm), reverse=reverse)
    return jnp.moveaxis(out, 0, axis)


def _skew_index(H: int, W: int, anti: bool) -> tuple[np.ndarray, np.ndarray]:
    """Gather/scatter indices that put the diagonals of an (H, W) grid into
    the columns of an (H, H + W - 1) array."""
    r = np.arange(H)[:, None]
    s = np.arange(H + W - 1)[None, :]
    c = (s - r) if anti else (s - (H - 1) + r)
    valid = (c >= 0) & (c < W)
    flat = np.where(valid, r * W + np.clip(c, 0, W - 1), H * W)  # H*W: the padding element
    rr, cc = np.mgrid[0:H, 0:W]
    back = rr * (H + W - 1) + ((cc + rr) if anti else (cc - rr + H - 1))
    return flat, back


def _edge_costs(nav: jax.Array, res: float):
    """Costs of the 8 move directions into each cell, +inf where not allowed."""
    inf = jnp.float32(jnp.inf)
    H, W = nav.shape
    n = nav
    pad = jnp.pad(n, 1)  # False outside
    up = pad[:-2, 1:-1]  # neighbour at row - 1
    down = pad[2:, 1:-1]  # row + 1
    left = pad[1:-1, :-2]  # col - 1
    right = pad[1:-1, 2:]  # col + 1
    ul = pad[:-2, :-2]
    ur = pad[:-2, 2:]
    dl = pad[2:, :-2]
    dr = pad[2:, 2:]
    o = jnp.float32(res)
    g = jnp.float32(res * math.sqrt(2.0))
    c = lambda m, cost: jnp.where(n & m, cost, inf)  # noqa: E731
    return {
        "from_left": c(left, o), "from_right": c(right, o), "from_up": c(up, o), "from_down": c(down, o),
        # diagonal from (r-1, c-1): needs (r-1, c) and (r, c-1)
        "from_ul": c(ul & up & left, g), "from_ur": c(ur & up & right, g),
        "from_dl": c(dl & down & left, g), "from_dr": c(dr & down & right, g),
    }


def geodesic_field(navigable: jax.Array, seeds: jax.Array, resolution: float,
                   max_rounds: int | None = None) -> jax.Array:
    """Geodesic distance from seed cells over the navigable grid.

    The graph is the 8-connected grid of navigable cells: orthogonal steps
    cost ``resolution``, diagonal steps ``resolution * sqrt(2)`` and are
    allowed only when both orthogonal neighbours they pass are navigable (no
    corner cutting). The result is ``min over seeds s of seeds[s] +
    path_length(s, cell)``.

    Each ``lax.while_loop`` iteration runs eight directional min-plus sweeps
    (left-right, right-left, down, up and the four diagonals, each a
    ``lax.scan`` of ``d[i] = min(d[i], d[i - 1] + w[i])`` over rows, columns
    or diagonals), so a straight stretch of any length is relaxed in one
    iteration; iteration stops when a round changes nothing (beyond float32
    rounding of equal-length paths, a relative 4e-7), the fixed point of
    Bellman-Ford: the same distances as Dijkstra up to float32 rounding.
    A 10-room house (about 250 x 270 cells) takes about a dozen rounds.

    Args:
        navigable: (H, W) bool.
        seeds: (H, W) float32 initial cost at seed cells, +inf elsewhere;
            seeds on non-navigable cells are ignored.
        resolution: cell size, metres (static).
        max_rounds: optional cap on the rounds (None: H * W, never reached).

    Returns:
        (H, W) float32 distances in metres, +inf where no seed is reachable
        (and on every non-navigable cell).

    Jit-able and vmappable (e.g. over seeds for many targets at once).
    """
    with jax.named_scope("geodesic_field"):
        nav = jnp.asarray(navigable, bool)
        H, W = nav.shape
        inf = jnp.float32(jnp.inf)
        d0 = jnp.where(nav, jnp.asarray(seeds, jnp.float32), inf)
        w = _edge_costs(nav, resolution)
        # diagonals as columns of skewed arrays. Shape: (H, H + W - 1)
        fwd_flat, fwd_back = _skew_index(H, W, anti=False)  # cells with c - r constant
        anti_flat, anti_back = _skew_index(H, W, anti=True)  # cells with c + r constant

        def skew(a, flat):
            return jnp.concatenate([a.reshape(-1), jnp.full((1,), inf, a.dtype)])[flat]

        def unskew(a, back):
            return a.reshape(-1)[back]

        w_ul = skew(w["from_ul"], fwd_flat)
        w_dr = skew(w["from_dr"], fwd_flat)
        w_ur = skew(w["from_ur"], anti_flat)
        w_dl = skew(w["from_dl"], anti_flat)

        def one_round(d):
            d = _sweep(d, w["from_left"], axis=1, reverse=False)
            d = _sweep(d, w["from_right"], axis=1, reverse=True)
            d = _sweep(d, w["from_up"], axis=0, reverse=False)
            d = _sweep(d, w["from_down"], axis=0, reverse=True)
            s = skew(d, fwd_flat)
            s = _sweep(s, w_ul, axis=0, reverse=False)
            s = _sweep(s, w_dr, axis=0, reverse=True)
            d = unskew(s, fwd_back)
            s = skew(d, anti_flat)
            s = _sweep(s, w_ur, axis=0, reverse=False)
            s = _sweep(s, w_dl, axis=0, reverse=True)
            return unskew(s, anti_back)

        cap = H * W if max_rounds is None else int(max_rounds)

        def cond(state):
            _, changed, i = state
            return changed & (i < cap)

        def body(state):
            d, _, i = state
            nd = one_round(d)
            # float sums of equal-length paths differ in the last bits; ignore such changes
            return nd, jnp.any(nd < jnp.where(jnp.isinf(d), d, d - _REL_TOL * d)), i + 1

        d, _, _ = jax.lax.while_loop(cond, body, (d0, jnp.array(True), jnp.array(0, jnp.int32)))
        return d


def seeds_from_box(navigable: jax.Array, room: jax.Array, origin: jax.Array, resolution: float,
                   center: jax.Array, half_extents: jax.Array, yaw: jax.Array, room_index: jax.Array,
                   seed_radius: float) -> jax.Array:
    """Seeds (initial costs) for the geodesic distance to an object (jnp).

    Seed cells are the navigable cells of the object's room whose centres lie
    within ``seed_radius`` of the object's floor footprint; each is seeded
    with its 2-D distance to the footprint. When no cell qualifies, the
    room's navigable cells nearest the footprint (within one cell of the
    minimum distance) are used instead. ``room_index < 0`` allows every room.

    Args:
        navigable: (H, W) bool.
        room: (H, W) int32 room-id grid.
        origin: (2,) grid origin (world x, y of cell (0, 0)'s corner).
        resolution: cell size, metres.
        center: (3,) or (2,) box centre, world.
        half_extents: (3,) or (2,) box half sizes along its own x, y.
        yaw: () box yaw, radians.
        room_index: () int32 index of the object's room, -1 for any.
        seed_radius: metres.

    Returns:
        (H, W) float32 seeds, +inf where not a seed.
    """
    H, W = navigable.shape
    inf = jnp.float32(jnp.inf)
    xs = origin[0] + (jnp.arange(W, dtype=jnp.float32) + 0.5) * resolution  # Shape: (W,)
    ys = origin[1] + (jnp.arange(H, dtype=jnp.float32) + 0.5) * resolution  # Shape: (H,)
    dx = xs[None, :] - center[0]
    dy = ys[:, None] - center[1]
    c, s = jnp.cos(yaw), jnp.sin(yaw)
    lx = dx * c + dy * s
    ly = -dx * s + dy * c
    ex = jnp.maximum(jnp.abs(lx) - half_extents[0], 0.0)
    ey = jnp.maximum(jnp.abs(ly) - half_extents[1], 0.0)
    dist = jnp.sqrt(ex**2 + ey**2).astype(jnp.float32)  # Shape: (H, W)
    allowed = navigable & ((room == room_index) | (room_index < 0))
    near = allowed & (dist <= seed_radius)
    dmin = jnp.min(jnp.where(allowed, dist, inf))
    fallback = allowed & (dist <= dmin + resolution)
    mask = jnp.where(jnp.any(near), near, fallback)
    return jnp.where(mask, dist, inf)


_seeds_jit = jax.jit(seeds_from_box, static_argnums=(3, 8))


def target_seeds(grid: NavGrid, bbox: OrientedBox, room_index: int | None, seed_radius: float = 1.0) -> np.ndarray:
    """Seeds for the geodesic distance to an object on a :class:`NavGrid`.

    See :func:`seeds_from_box`; ``room_index`` indexes ``grid.room_ids``
    (None or -1: any room).

    Returns:
        (H, W) float32 seeds, +inf where not a seed.
    """
    ri = -1 if room_index is None else int(room_index)
    out = _seeds_jit(
        jnp.asarray(grid.navigable), jnp.asarray(grid.room), jnp.asarray(grid.origin, jnp.float32),
        grid.resolution, jnp.asarray(bbox.center, jnp.float32), jnp.asarray(bbox.half_extents, jnp.float32),
        jnp.float32(bbox.yaw), jnp.int32(ri), float(seed_radius),
    )
    return np.asarray(out)
