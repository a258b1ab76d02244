"""Voxelization of a compiled scene, and the fast ray caster's acceleration
structures: the host-side arrays that :func:`ignjax.scenes.navgrid.build_navgrid`
stores in a :class:`~ignjax.scenes.navgrid.NavGrid` (cell conventions there).

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

import mujoco
import numpy as np

from ignjax.arrays import ragged_index
from ignjax.scenes.model import Scene

#: Columns of a row of :attr:`NavGrid.prims <ignjax.scenes.navgrid.NavGrid.prims>`.
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

    def prim_voxels(self, rows: np.ndarray, ext: np.ndarray, chunk: int = 1 << 19):
        """Voxels overlapping each primitive's oriented bounding box
        (separating-axis test), many primitives at a time.

        Args:
            rows: (P, 18) primitives (:data:`PRIM_COLUMNS`).
            ext: (P, 3) half extents of their bounding boxes grown by :data:`_TOUCH` (:func:`_extents`).
            chunk: about how many candidate voxels one yielded piece covers.

        Yields:
            ``(idx, strict, pid)``: (M, 3) voxel (ix, iy, iz) indices, each
            overlapping primitive ``pid`` (M,) of ``rows``; an upright box is
            grown by :data:`_TOUCH` vertically (a voxel its top or bottom face
            merely touches is included, for horizontal rays at exactly that
            height), any other box in every direction. ``strict`` (M,) bool:
            the voxel overlaps the box shrunk by :data:`_SHRINK` (what
            occupancy and navigation use). A primitive's voxels all come in
            one piece.
        """
        boxes = [_box_params(self, r, e, p) for p, (r, e) in enumerate(zip(rows, ext))]
        for upright in (True, False):
            sel = [p for p, b in enumerate(boxes) if b is not None and b.upright == upright]
            size = [int(np.prod(boxes[p].i1 - boxes[p].i0 + 1)) for p in sel]
            lo = 0
            while lo < len(sel):
                hi, total = lo + 1, size[lo]
                while hi < len(sel) and total + size[hi] <= chunk:
                    total += size[hi]
                    hi += 1
                part = [boxes[p] for p in sel[lo:hi]]
                yield self._upright(part) if upright else self._general(part)
                lo = hi

    def _centres(self, idx: np.ndarray, axis: int) -> np.ndarray:
        return self.lo[axis] + (idx + 0.5) * self.cell[axis]

    def _upright(self, part: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`prim_voxels` of upright boxes: 2-D separating axes in xy, exact z intervals."""
        i0 = np.stack([b.i0 for b in part])
        n = np.stack([b.i1 for b in part]) - i0 + 1
        owner, off = ragged_index(n[:, 0] * n[:, 1])
        xs = i0[owner, 0] + off % n[owner, 0]
        ys = i0[owner, 1] + off // n[owner, 0]
        cx = np.array([b.center[0] for b in part])[owner]
        cy = np.array([b.center[1] for b in part])[owner]
        dx = self._centres(xs, 0) - cx
        dy = self._centres(ys, 1) - cy
        ax = np.stack([b.axes for b in part])[owner]  # Shape: (N, 4, 2)
        vterm = np.stack([b.vterm for b in part])[owner]
        thr = np.stack([b.thr for b in part])[owner]
        ok = np.ones(len(owner), bool)
        for a in range(4):
            sep = np.abs(dx * ax[:, a, 0] + dy * ax[:, a, 1]) - vterm[:, a]
            ok &= sep <= thr[:, a]
        owner, xs, ys = owner[ok], xs[ok], ys[ok]
        cell, zoff = ragged_index(n[owner, 2])
        zs = i0[owner[cell], 2] + zoff
        zc = self._centres(zs, 2)
        cz = np.array([b.center[2] for b in part])
        zlim = np.array([b.zlim for b in part])
        pid = np.array([b.pid for b in part], np.int64)
        o = owner[cell]
        strict = np.abs(zc - cz[o]) <= zlim[o]
        return np.stack([xs[cell], ys[cell], zs], -1), strict, pid[o]

    def _general(self, part: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`prim_voxels` of other boxes: the 15 separating axes in 3-D."""
        i0 = np.stack([b.i0 for b in part])
        n = np.stack([b.i1 for b in part]) - i0 + 1
        owner, off = ragged_index(n.prod(1))
        nyz = n[owner, 1] * n[owner, 2]
        idx = np.stack([i0[owner, 0] + off // nyz, i0[owner, 1] + (off // n[owner, 2]) % n[owner, 1],
                        i0[owner, 2] + off % n[owner, 2]], -1)
        centre = np.stack([b.center for b in part])[owner]
        d = self.lo + (idx + 0.5) * self.cell - centre
        axes = np.stack([b.axes for b in part])[owner]  # Shape: (M, 15, 3), unused axes 0
        sep = np.abs(np.einsum("mk,mak->ma", d, axes)) - np.stack([b.vterm for b in part])[owner]
        ok_g = np.all(sep <= np.stack([b.thr for b in part])[owner], axis=1)
        ok_s = np.all(sep <= np.stack([b.thr_s for b in part])[owner], axis=1)
        pid = np.array([b.pid for b in part], np.int64)
        return idx[ok_g], ok_s[ok_g], pid[owner[ok_g]]

    def sub_boxes(self, idx: np.ndarray, centre: np.ndarray, ext: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Quantised bounds (in 1/SUB_Q voxel) of a bounding box (centre
        ``centre[m]``, half extents ``ext[m]``) within voxel ``idx[m]``: (M, 3)
        low and high quarter indices such that the box lies in
        ``[lo, hi + 1] / SUB_Q``."""
        v0 = self.lo + idx * self.cell
        lo = np.clip((centre - ext - v0) / self.cell, 0.0, 1.0)
        hi = np.clip((centre + ext - v0) / self.cell, 0.0, 1.0)
        qlo = np.clip(np.floor(lo * SUB_Q), 0, SUB_Q - 1).astype(np.uint8)
        qhi = np.clip(np.ceil(hi * SUB_Q) - 1, 0, SUB_Q - 1).astype(np.uint8)
        return qlo, np.maximum(qhi, qlo)

    def inside(self, idx: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """(M,) bool: voxel ``idx[m]`` lies entirely inside primitive
        ``rows[m]`` (all eight corners inside a convex set; never for a
        primitive too thin to hold a whole voxel).

        The box part is tested at the voxel's centre: its corners all lie in
        the box exactly when, along each box axis ``j``, the centre's local
        coordinate plus the voxel's half extent ``sum_i cell_i / 2 |R_ij|``
        does; the quadric part (convex) is tested at the eight corners of the
        voxels that pass."""
        c, R, h, q = rows[:, 0:3], rows[:, 3:12].reshape(-1, 3, 3), rows[:, 12:15], rows[:, 15:18]
        out = 2 * h.min(1) + 2 * _SHRINK >= self.cell.min()
        m = np.nonzero(out)[0]
        if len(m) == 0:
            return out
        d = self.lo + (idx[m] + 0.5) * self.cell - c[m]
        loc = d[:, 0, None] * R[m, 0] + d[:, 1, None] * R[m, 1] + d[:, 2, None] * R[m, 2]
        half = (self.cell / 2) @ np.abs(R[m])  # Shape: (M, 3)
        ok = np.all(np.abs(loc) + half <= h[m] + _SHRINK, axis=1)
        curved = ok & np.any(q[m] != 0, axis=1)
        if curved.any():
            k = m[curved]
            corners = np.array([[i, j, l] for i in (0, 1) for j in (0, 1) for l in (0, 1)], np.float64)
            pts = self.lo + (idx[k, None, :] + corners[None]) * self.cell - c[k, None]  # Shape: (K, 8, 3)
            lc = np.einsum("kci,kij->kcj", pts, R[k])
            ok[curved] = ((lc**2 * q[k, None]).sum(-1) <= 1.0 + 1e-9).all(1)
        out[m] = ok
        return out

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


class _Box:
    """One primitive's bounding box as :meth:`_Voxelizer.prim_voxels` tests it."""

    __slots__ = ("pid", "center", "i0", "i1", "upright", "axes", "vterm", "thr", "thr_s", "zlim")


def _box_params(vz: _Voxelizer, row: np.ndarray, ext: np.ndarray, pid: int) -> "_Box | None":
    """The separating-axis test's per-primitive terms (None: no voxel in range)."""
    center, rot, half = row[0:3], row[3:12].reshape(3, 3), row[12:15]
    grown = half + _TOUCH
    shrunk = np.maximum(half - _SHRINK, 0.0)
    i0, i1 = vz._range(center - ext, center + ext)
    if np.any(i1 < i0):
        return None
    b = _Box()
    b.pid, b.center, b.i0, b.i1 = pid, center, i0, i1
    b.upright = bool(abs(abs(rot[2, 2]) - 1.0) < 1e-9)
    vh = vz.cell / 2
    if b.upright:
        u, v = rot[:2, 0], rot[:2, 1]
        axes = [np.array([1.0, 0.0]), np.array([0.0, 1.0]), u, v]
        b.axes = np.stack(axes)
        b.vterm = np.array([vh[0] * abs(ax[0]) + vh[1] * abs(ax[1]) for ax in axes])
        b.thr = np.array([shrunk[0] * abs(ax @ u) + shrunk[1] * abs(ax @ v) for ax in axes])
        b.zlim = vh[2] + shrunk[2]
        return b
    cross = np.cross(np.eye(3)[:, None, :], rot.T[None, :, :]).reshape(9, 3)
    norm = np.linalg.norm(cross, axis=1)
    axes = np.concatenate([np.eye(3), rot.T, cross[norm > 1e-9] / norm[norm > 1e-9, None]])  # Shape: (A, 3)
    proj = np.abs(axes @ rot)  # Shape: (A, 3): |axis . box axis j|
    pad = 15 - len(axes)  # unused axes: 0, never separating
    b.axes = np.concatenate([axes, np.zeros((pad, 3))])
    b.vterm = np.concatenate([np.abs(axes) @ vh, np.zeros(pad)])
    b.thr = np.concatenate([proj @ grown, np.full(pad, np.inf)])
    b.thr_s = np.concatenate([proj @ shrunk, np.full(pad, np.inf)])
    return b


def _extents(rows: np.ndarray, grow: float) -> np.ndarray:
    """(P, 3) half extents of the primitives' axis-aligned bounding boxes, grown by ``grow``."""
    return np.stack([np.abs(r[3:12].reshape(3, 3)) @ (r[12:15] + grow) for r in rows]) if len(rows) else \
        np.zeros((0, 3))


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
    from scipy import ndimage  # here, not at import: a warm run reads its grids from the cache
    if len(vox) == 0:
        return vox
    lo = vox.min(0)
    hi = vox.max(0)
    block = np.zeros(tuple(hi - lo + 1), bool)
    block[tuple((vox - lo).T)] = True
    filled = ndimage.binary_fill_holes(block)
    return np.argwhere(filled) + lo


def scene_extent(compiled, config) -> tuple[np.ndarray, tuple[int, int], int]:
    """Grid origin, (H, W) and number of slices covering the scene.

    Args:
        compiled: a :class:`~ignjax.scenes.compile.CompiledScene`.
        config: a :class:`~ignjax.scenes.navgrid.GridConfig`.
    """
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


def voxelize(compiled, config, origin, shape, n_slices):
    """Occupancy, exact primitives and their (column, list band) memberships.

    Args:
        compiled: a :class:`~ignjax.scenes.compile.CompiledScene`.
        config: a :class:`~ignjax.scenes.navgrid.GridConfig`.
        origin, shape, n_slices: the grid's extent (:func:`scene_extent`).

    Returns:
        ``(occupied, touched, full, sub_box, prims, prim_geom, (seg_start,
        seg_count, seg_prims), approx)``: the (Z, H, W) occupancy, occupancy
        or face contact, inside-one-primitive masks, packed sub-boxes, the
        (P, 18) primitives and their geom ids, the column segments' lists
        and the (H, W, B) voxel-accuracy flags (see :class:`~ignjax.scenes.navgrid.NavGrid`).
    """
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
    keys: list[np.ndarray] = []  # column segment * primitive count + primitive index
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
            prims.append(row)
            prim_geom.append(g)
    rows = np.stack(prims) if prims else np.zeros((0, N_PRIM_COLUMNS))
    ext = _extents(rows, _TOUCH)
    n_prims = max(len(rows), 1)
    for vox, strict, pid in vz.prim_voxels(rows, ext):
        at = (vox[:, 2], vox[:, 1], vox[:, 0])
        occ_ray[at] = True
        qlo, qhi = vz.sub_boxes(vox, rows[pid, 0:3], ext[pid])
        np.minimum.at(sub_lo, at, qlo)
        np.maximum.at(sub_hi, at, qhi)
        sv, spid = vox[strict], pid[strict]
        occ[sv[:, 2], sv[:, 1], sv[:, 0]] = True
        inner = sv[vz.inside(sv, rows[spid])]
        full[inner[:, 2], inner[:, 1], inner[:, 0]] = True
        seg = (vox[:, 1] * W + vox[:, 0]) * n_lb + vox[:, 2] // spb
        keys.append(np.unique(seg * n_prims + pid))  # (segment, primitive) pairs, sorted by segment then primitive
    K = config.max_list
    n_seg = H * W * n_lb
    approx = np.zeros(n_seg, bool)
    if keys:
        pair = np.sort(np.concatenate(keys))
        key, val = pair // n_prims, pair % n_prims
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
    prim_arr = rows.astype(np.float32)
    seg = (start.astype(np.int32).reshape(H, W, n_lb), count.astype(np.uint8).reshape(H, W, n_lb), seg_prims)
    sub = pack_sub_boxes(sub_lo, sub_hi)
    sub[~occ_ray] = 0
    return occ, occ_ray, full, sub, prim_arr, np.asarray(prim_geom, np.int32), seg, approx.reshape(H, W, n_lb)


SUB_Q = 4
"""Sub-voxel quantisation of :attr:`NavGrid.sub_box <ignjax.scenes.navgrid.NavGrid.sub_box>` (quarters of a voxel)."""


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
    from scipy import ndimage  # here, not at import: a warm run reads its grids from the cache (0.27 s)
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
