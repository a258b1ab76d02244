"""Floor-plane polygon geometry the scene model and its readers share:
signed area and centroid, point-in-polygon and distance to the boundary,
and why a floor polygon is unusable (:func:`polygon_problem`). Plain numpy
on (x, y) points in metres; nothing here knows about scenes.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

__all__ = ["Vec2", "polygon_area", "polygon_centroid", "points_in_polygon", "polygon_edge_distance",
           "polygon_problem"]

Vec2 = tuple[float, float]


def polygon_area(poly: Sequence[Vec2]) -> float:
    """Signed area (positive when counter-clockwise)."""
    p = np.asarray(poly, dtype=np.float64).reshape(-1, 2)
    if len(p) < 3:
        return 0.0
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def polygon_centroid(poly: Sequence[Vec2]) -> Vec2:
    p = np.asarray(poly, dtype=np.float64).reshape(-1, 2)
    a = polygon_area(p)
    if abs(a) < 1e-12:
        m = p.mean(0)
        return float(m[0]), float(m[1])
    x, y = p[:, 0], p[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    cx = float(((x + xn) * cross).sum() / (6 * a))
    cy = float(((y + yn) * cross).sum() / (6 * a))
    return cx, cy


def points_in_polygon(points, poly: Sequence[Vec2]) -> np.ndarray:
    """Even-odd rule point-in-polygon for points (..., 2); vectorised."""
    pts = np.asarray(points, dtype=np.float64)
    shape = pts.shape[:-1]
    pts = pts.reshape(-1, 2)
    v = np.asarray(poly, dtype=np.float64).reshape(-1, 2)
    x, y = pts[:, 0:1], pts[:, 1:2]
    x0, y0 = v[:, 0][None], v[:, 1][None]
    x1, y1 = np.roll(v[:, 0], -1)[None], np.roll(v[:, 1], -1)[None]
    cond = (y0 > y) != (y1 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xint = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    inside = np.logical_and(cond, x < xint).sum(axis=1) % 2 == 1
    return inside.reshape(shape)


def polygon_edge_distance(point, poly: Sequence[Vec2]) -> float:
    """Distance from a 2-D point to the nearest edge of a polygon."""
    p = np.asarray(point, dtype=np.float64)
    v = np.asarray(poly, dtype=np.float64).reshape(-1, 2)
    a, b = v, np.roll(v, -1, axis=0)
    ab = b - a
    t = np.clip(((p - a) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-18), 0.0, 1.0)
    return float(np.hypot(*(a + t[:, None] * ab - p).T).min())

def _segments_cross(a0, a1, b0, b1) -> bool:
    def orient(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    d1, d2 = orient(b0, b1, a0), orient(b0, b1, a1)
    d3, d4 = orient(a0, a1, b0), orient(a0, a1, b1)
    return (d1 * d2 < -1e-12) and (d3 * d4 < -1e-12)


def polygon_problem(poly: Sequence[Sequence[float]]) -> str | None:
    """Why a floor polygon is unusable (too few points, zero area,
    self-intersecting, non-finite), or None when it is fine."""
    p = np.asarray(poly, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2:
        return f"expected a list of (x, y) points, got shape {p.shape}"
    if not np.all(np.isfinite(p)):
        return "has NaN or infinite coordinates"
    if len(p) >= 2 and np.allclose(p[0], p[-1]):
        p = p[:-1]
    if len(p) < 3:
        return f"has {len(p)} distinct points; a polygon needs at least 3"
    if abs(polygon_area(p)) < 1e-6:
        return "has zero area"
    n = len(p)
    for i in range(n):
        for j in range(i + 1, n):
            if abs(i - j) in (1, n - 1):
                continue
            if _segments_cross(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]):
                return f"is self-intersecting (edges {i} and {j} cross)"
    return None
