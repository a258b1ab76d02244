"""The fast ray caster's device arrays: :class:`RayGrid` and its builder
:func:`ray_grid`, stacked from the :class:`~ignjax.scenes.navgrid.NavGrid`
of one or several scenes (padded to shared maxima, with a leading scene
axis). The ray code that reads them is in :mod:`ignjax.sim.rays.fast` and
:mod:`ignjax.sim.rays.queries`.
"""

from __future__ import annotations

from typing import Sequence

import jax
import mujoco
import numpy as np

from ignjax.arrays import host_empty, on_device, pytree_dataclass
from ignjax.scenes.navgrid import NavGrid
from ignjax.scenes.voxels import N_PRIM_COLUMNS


@pytree_dataclass(static=("resolution", "slice_height", "slices_per_band", "max_count"))
class RayGrid:
    """Arrays of the fast ray caster for S scenes, padded to shared maxima.

    Attributes:
        voxcode: (S, Z, H, W) uint8 voxel march codes (:func:`voxels.march_codes`).
        sub_box: (S, Z, H, W) uint16 where the geometry of each occupied voxel
            lies (:func:`voxels.pack_sub_boxes`).
        seg_start: (S, H, W, B) int32 first entry of each column segment in ``seg_prims``.
        seg_count: (S, H, W, B) uint8 primitives in each segment.
        seg_prims: (S, M) int32 primitive indices, segment after segment.
        approx: (S, H, W, B) bool, segment answered at voxel accuracy.
        prims: (S, 18, P) float32 primitives, one row of
            :data:`voxels.PRIM_COLUMNS` per column (structure of arrays).
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


COLUMN_WORD_BITS = 32
"""Voxels per word of :func:`occupied_columns`."""


def column_words(n_slices: int) -> int:
    """Words of :func:`occupied_columns` per column of ``n_slices`` voxels."""
    return -(-int(n_slices) // COLUMN_WORD_BITS)


def occupied_columns(grid: RayGrid) -> np.ndarray:
    """(S, H, W, ceil(Z / 32)) uint32 the ray grid's occupancy packed per
    column: bit ``k % 32`` of word ``k // 32`` is set when voxel ``k`` of the
    column is occupied (``voxcode <= 1``, the test of line-of-sight marches)
    and ``k`` lies below the scene's valid height. One 4-byte look-up then
    answers a sample that ``voxcode`` answers with a byte of a table eight
    times larger, which matters where the samples miss the cache (the
    observation's sight lines). Computed on the host."""
    vox = np.asarray(grid.voxcode)
    S, Z, H, W = vox.shape
    heights = np.asarray(grid.dims)[:, 2]
    out = np.zeros((S, H, W, column_words(Z)), np.uint32)
    for k in range(Z):
        occ = (vox[:, k] <= 1) & (k < heights)[:, None, None]
        out[..., k // COLUMN_WORD_BITS] |= occ.astype(np.uint32) << np.uint32(k % COLUMN_WORD_BITS)
    return out


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
        stacked = host_empty((len(items),) + shape, items[0].dtype)  # shared with CPU devices, not copied
        stacked.fill(_PAD_VALUES[name])
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
    return RayGrid(**{k: on_device(v) for k, v in arrs.items()}, resolution=cfg.resolution,
                   slice_height=cfg.slice_height, slices_per_band=cfg.slices_per_list_band,
                   max_count=max(int(arrs["seg_count"].max(initial=0)), 1))
