"""Which object a Type-4 question asks about.

The paper's Type 4 "returns a positive answer only when the queried
candidate is the target, visible in front, and within 3 m"; the oracle's
slots include the candidate query. An MLLM agent names its candidate as a
cell of its front view's 8 x 8 grid (columns 1..8 left to right, rows 1..8
bottom to top, Eq. app:grid-to-pixel's grid): the ASK action carries it in
``(col, row)``. Before the oracle answers, the host loop resolves the cell
to one instance of the scene:

* rendered views (panel observations): the front view's instance
  segmentation, the very image the model was shown. The candidate is the
  object covering the most pixels of the cell (ties: the lower index).
  Structural instances (walls, floors, doors, windows) are never
  candidates;
* text observations: the objects in sight, each placed in the front-view
  cell its bounding-box centre projects to (:func:`front_cells`, the same
  numbers the text gives the agent); the nearest one in the named cell.

No object in the cell gives :data:`~ignjax.sim.types.NO_CANDIDATE`, which
the oracle answers "no" with the reason that nothing is there to check; the
question is charged as every Type-4 question is (paper: "Otherwise, it
returns 'no' or a short negative rationale").
"""

from __future__ import annotations

import math

import jax.numpy as jnp
import numpy as np

from ignjax.sim import geometry as G
from ignjax.sim import types as T


def cell_bounds(col: int, row: int, height: int, width: int) -> tuple[slice, slice]:
    """Image rows and columns of grid cell ``(col, row)`` (both 1..8) in an
    image of ``height`` x ``width`` pixels (row 1 at the bottom edge)."""
    if not (1 <= int(col) <= 8 and 1 <= int(row) <= 8):
        raise ValueError(f"grid cell ({col}, {row}) is outside 1..8")
    v0, v1 = (round(height - int(row) * height / 8), round(height - (int(row) - 1) * height / 8))
    u0, u1 = round((int(col) - 1) * width / 8), round(int(col) * width / 8)
    return slice(v0, v1), slice(u0, u1)


def segmented_candidate(instance: np.ndarray, structural: np.ndarray, col: int, row: int) -> int:
    """The instance a Type-4 question about cell ``(col, row)`` asks about,
    from a rendered view's segmentation.

    Args:
        instance: (H, W) int instance index per pixel (-1: none), the front view.
        structural: (N,) bool, the scene's structural instances.
        col, row: the grid cell, 1..8.

    Returns:
        The object covering the most pixels of the cell, or :data:`~ignjax.sim.types.NO_CANDIDATE`.
    """
    rows, cols = cell_bounds(col, row, *instance.shape[:2])
    ids = np.asarray(instance[rows, cols]).ravel()
    ids = ids[(ids >= 0) & (ids < len(structural))]
    ids = ids[~np.asarray(structural, bool)[ids]]
    if ids.size == 0:
        return T.NO_CANDIDATE
    return int(np.argmax(np.bincount(ids)))


def front_cells(cfg: T.SimConfig, pose, centers: np.ndarray) -> np.ndarray:
    """(K, 2) int grid cells ``(col, row)`` of the front view that points at
    ``centers`` (K, 3) project to from ``pose`` (x, y, yaw); ``(0, 0)`` for a
    point outside the view or behind the camera. The camera is the
    executor's (:func:`ignjax.sim.executor.cell_ray`): eye at
    ``cfg.eye_height``, level, ``cfg.view_hfov`` wide."""
    centers = np.asarray(centers, np.float64).reshape(-1, 3)
    x, y, yaw = (float(v) for v in np.asarray(pose)[:3])
    W, H = (float(v) for v in cfg.image_size)
    K = np.asarray(G.intrinsics(W, H, math.radians(cfg.view_hfov)), np.float64)
    R_wc = np.asarray(G.view_rotation(jnp.float32(yaw)), np.float64)  # columns: camera x, y, z in world
    cam = (centers - np.array([x, y, float(cfg.eye_height)])) @ R_wc  # camera frame: x right, y down, z forward
    z = cam[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = K[0, 0] * cam[:, 0] / z + K[0, 2]
        v = K[1, 1] * cam[:, 1] / z + K[1, 2]
    inside = (z > 1e-6) & (u >= 0) & (u < W) & (v >= 0) & (v < H)
    col = np.where(inside, np.floor(np.where(inside, u, 0) / (W / 8)) + 1, 0)
    row = np.where(inside, np.floor((H - np.where(inside, v, H)) / (H / 8)) + 1, 0)
    return np.stack([np.clip(col, 0, 8), np.clip(row, 0, 8)], -1).astype(np.int32)


def projected_candidate(cells: np.ndarray, handles: np.ndarray, ranges: np.ndarray, col: int, row: int) -> int:
    """The instance a Type-4 question about cell ``(col, row)`` asks about,
    from the objects in sight: ``handles`` (K,) with their front-view
    ``cells`` (K, 2) (:func:`front_cells`) and ``ranges`` (K,); the nearest
    one in the cell, or :data:`~ignjax.sim.types.NO_CANDIDATE`."""
    handles = np.asarray(handles)
    hit = (handles >= 0) & (np.asarray(cells)[:, 0] == int(col)) & (np.asarray(cells)[:, 1] == int(row))
    if not hit.any():
        return T.NO_CANDIDATE
    idx = np.flatnonzero(hit)
    return int(handles[idx[np.argmin(np.asarray(ranges)[idx])]])


__all__ = ["cell_bounds", "front_cells", "projected_candidate", "segmented_candidate"]
