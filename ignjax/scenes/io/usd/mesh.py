"""Mesh geometry of USD prims: triangulating polygon faces (concave ones
included) and the triangle meshes of USD's geometric primitives (``Cube``,
``Sphere``, ``Cylinder``, ``Cone``, ``Capsule``, ``Plane``) in their own frame.
"""

from __future__ import annotations

import functools
import math
from typing import Iterable

import mapbox_earcut
import numpy as np

from ignjax.errors import SceneError


def _newell_normal(p: np.ndarray) -> np.ndarray:
    # Shape: p (n, 3) -> (3,)
    q = np.roll(p, -1, axis=0)
    return np.array([
        np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
        np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
        np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1])),
    ])


def _earclip_face(points: np.ndarray, ring: np.ndarray) -> list[tuple[int, int, int]]:
    """Triangulate one polygon face (indices ``ring`` into ``points``)."""
    p = points[ring]
    n = _newell_normal(p)
    norm = float(np.linalg.norm(n))
    if norm < 1e-300:
        return []
    n = n / norm
    # An orthonormal basis (u, v, n), right-handed, so that a face wound
    # counter-clockwise about its normal is counter-clockwise in (u, v).
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, n)
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    d = p - p[0]
    xy = np.stack([d @ u, d @ v], axis=1)
    tri = np.asarray(mapbox_earcut.triangulate_float64(xy, np.array([len(ring)], dtype=np.uint32)), dtype=np.int64)
    tri = tri.reshape(-1, 3)
    out = []
    for a, b, c in tri:
        area2 = (xy[b, 0] - xy[a, 0]) * (xy[c, 1] - xy[a, 1]) - (xy[b, 1] - xy[a, 1]) * (xy[c, 0] - xy[a, 0])
        if area2 < 0:
            b, c = c, b
        out.append((int(ring[a]), int(ring[b]), int(ring[c])))
    return out


def triangulate_faces(points, counts, indices, *, left_handed: bool = False,
                      holes: Iterable[int] = (), path=None, where: str | None = None) -> np.ndarray:
    """Triangulate USD polygon faces, concave ones included.

    Triangles pass through; quads are split along the diagonal that lies
    inside the face; faces with more vertices are projected onto their
    best-fit (Newell) plane and ear-clipped. Triangles keep the face's
    winding; ``left_handed`` flips it so the result is right-handed.
    Faces with fewer than three vertices and faces listed in ``holes``
    (USD ``holeIndices``) are dropped.

    Args:
        points: (V, 3) vertex positions.
        counts: (F,) ``faceVertexCounts``.
        indices: (sum(counts),) ``faceVertexIndices``.

    Returns:
        (T, 3) int64 vertex indices.

    Raises:
        SceneError: counts and indices disagree, or an index is out of range.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    counts = np.asarray(counts, dtype=np.int64).reshape(-1)
    idx = np.asarray(indices, dtype=np.int64).reshape(-1)
    if counts.size and counts.min() < 0:
        raise SceneError(path, where, "faceVertexCounts has negative entries")
    if int(counts.sum()) != idx.size:
        raise SceneError(path, where, f"faceVertexCounts sum to {int(counts.sum())} but there are {idx.size} faceVertexIndices")
    if idx.size and (idx.min() < 0 or idx.max() >= len(pts)):
        raise SceneError(path, where, f"faceVertexIndices refer to vertex {int(idx.max()) if idx.max() >= len(pts) else int(idx.min())} "
                                      f"but there are {len(pts)} points")
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]) if counts.size else np.zeros(0, np.int64)
    keep = np.ones(len(counts), dtype=bool)
    hole_list = [h for h in holes if 0 <= h < len(counts)]
    keep[hole_list] = False
    parts: list[np.ndarray] = []
    # Shape: (n3, 3)
    sel = keep & (counts == 3)
    if sel.any():
        s = starts[sel]
        parts.append(np.stack([idx[s], idx[s + 1], idx[s + 2]], axis=1))
    sel = keep & (counts == 4)
    if sel.any():
        s = starts[sel]
        q = np.stack([idx[s + k] for k in range(4)], axis=1)  # Shape: (n4, 4)
        P = pts[q]  # Shape: (n4, 4, 3)
        nq = _newell_batch(P)
        c1 = np.einsum("ij,ij->i", np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), nq)
        c2 = np.einsum("ij,ij->i", np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 0]), nq)
        ok = (c1 >= 0) & (c2 >= 0)
        a = np.where(ok[:, None], q[:, [0, 1, 2]], q[:, [1, 2, 3]])
        b = np.where(ok[:, None], q[:, [0, 2, 3]], q[:, [1, 3, 0]])
        parts += [a, b]
    big = np.nonzero(keep & (counts > 4))[0]
    if big.size:
        tris: list[tuple[int, int, int]] = []
        for f in big:
            ring = idx[starts[f]:starts[f] + counts[f]]
            tris += _earclip_face(pts, ring)
        if tris:
            parts.append(np.asarray(tris, dtype=np.int64))
    if not parts:
        return np.zeros((0, 3), dtype=np.int64)
    out = np.concatenate(parts).astype(np.int64)
    if left_handed:
        out = out[:, [0, 2, 1]]
    return out


def _newell_batch(P: np.ndarray) -> np.ndarray:
    # Shape: P (n, k, 3) -> (n, 3)
    Q = np.roll(P, -1, axis=1)
    return np.stack([
        np.sum((P[..., 1] - Q[..., 1]) * (P[..., 2] + Q[..., 2]), axis=1),
        np.sum((P[..., 2] - Q[..., 2]) * (P[..., 0] + Q[..., 0]), axis=1),
        np.sum((P[..., 0] - Q[..., 0]) * (P[..., 1] + Q[..., 1]), axis=1),
    ], axis=1)


# ---------------------------------------------------------------------------
# Canonical primitive meshes (surfaces of revolution about +z)
# ---------------------------------------------------------------------------


def _revolve(profile, sections: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """Closed mesh of revolution about z of a profile [(r, z), ...] that runs
    from the bottom pole (r = 0) to the top pole (r = 0)."""
    prof = np.asarray(profile, dtype=np.float64)
    inner = prof[1:-1]
    phi = 2 * math.pi * np.arange(sections) / sections
    rings = np.stack([np.outer(inner[:, 0], np.cos(phi)), np.outer(inner[:, 0], np.sin(phi)),
                      np.repeat(inner[:, 1:2], sections, axis=1)], axis=-1).reshape(-1, 3)
    verts = np.concatenate([[[0.0, 0.0, prof[0, 1]]], rings, [[0.0, 0.0, prof[-1, 1]]]])
    top = len(verts) - 1
    j = np.arange(sections)
    jn = (j + 1) % sections
    faces = [np.stack([np.zeros(sections, int), 1 + jn, 1 + j], 1)]
    for k in range(len(inner) - 1):
        a, b = 1 + k * sections, 1 + (k + 1) * sections
        faces += [np.stack([a + j, a + jn, b + jn], 1), np.stack([a + j, b + jn, b + j], 1)]
    last = 1 + (len(inner) - 1) * sections
    faces.append(np.stack([np.full(sections, top), last + j, last + jn], 1))
    f = np.concatenate(faces)
    tri = verts[f]
    vol = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum()
    if vol < 0:
        f = f[:, [0, 2, 1]]
    return verts, f


def _arc(radius: float, z0: float, lower: bool, n: int = 8):
    t = np.linspace(0.0, math.pi / 2, n + 1)
    if lower:
        return [(radius * math.sin(a), z0 - radius * math.cos(a)) for a in t]
    return [(radius * math.cos(a), z0 + radius * math.sin(a)) for a in t]


@functools.lru_cache(maxsize=256)
def canonical_mesh(kind: str, params: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of a USD primitive in its own frame with its axis on +z."""
    if kind == "Cube":
        h = params[0] / 2
        v = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])
        f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
        return v, f
    if kind == "Sphere":
        r = params[0]
        return _revolve(_arc(r, 0.0, True) + _arc(r, 0.0, False)[1:])
    if kind in ("Cylinder", "Cone"):
        r_bottom, r_top, height = params
        prof = [(0.0, -height / 2), (r_bottom, -height / 2)]
        prof += [(r_top, height / 2), (0.0, height / 2)] if r_top > 0 else [(0.0, height / 2)]
        return _revolve(prof)
    if kind == "Capsule":
        r_bottom, r_top, height = params
        if abs(r_bottom - r_top) <= 1e-12 * max(r_bottom, 1e-300):
            return _revolve(_arc(r_bottom, -height / 2, True) + _arc(r_top, height / 2, False))
        import trimesh  # only for unequal capsule radii; importing trimesh takes seconds

        a, _ = canonical_mesh("Sphere", (r_bottom,))
        b, _ = canonical_mesh("Sphere", (r_top,))
        hull = trimesh.convex.convex_hull(np.concatenate([a - [0, 0, height / 2], b + [0, 0, height / 2]]))
        return np.asarray(hull.vertices), np.asarray(hull.faces)
    if kind == "Plane":
        w, length = params[0] / 2, params[1] / 2
        v = np.array([[-w, -length, 0.0], [w, -length, 0.0], [w, length, 0.0], [-w, length, 0.0]])
        return v, np.array([[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]])
    raise ValueError(kind)
