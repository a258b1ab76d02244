"""Rooms, walls and doors of a stage: ``ignjax`` rooms, walls and doors
restored from their stored attributes (moved along when turned or moved
about Z in an editor), room polygons outlined from floor geometry or the
hull of the objects, and the room a point lies in.
"""

from __future__ import annotations

import math

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.io.footprint import convex_hull, padded_rect
from ignjax.scenes.io.usd.frames import Frames, apply, pose, upright_rigid, wrap
from ignjax.scenes.io.usd.instances import InstanceBuilder
from ignjax.scenes.io.usd.parts import Part, authored
from ignjax.scenes.io.usd.stage import ATTR_ID, NS, warn_import
from ignjax.scenes.io.usd.traversal import Owner
from ignjax.scenes.model import Door, Instance, Room, Wall
from ignjax.scenes.model.polygons import points_in_polygon, polygon_area, polygon_problem


class Structure:
    """Reads the rooms, walls and doors of one stage."""

    def __init__(self, spath: str, frames: Frames, instances: InstanceBuilder):
        self.spath, self.frames, self.instances = spath, frames, instances

    # -- rooms, walls, doors ---------------------------------------------------------
    def _planar(self, prim, expected: np.ndarray) -> tuple[np.ndarray | None, float]:
        delta = self.frames.frame(prim) @ np.linalg.inv(expected)
        if np.allclose(delta, np.eye(4), atol=1e-6):
            return None, 0.0
        theta = upright_rigid(delta)
        if theta is None:
            warn_import(self.spath, f"{prim.GetPath()} was scaled or tilted after export; its stored ignjax values are used as they are")
            return None, 0.0
        return delta, theta

    @staticmethod
    def room_from_parts(parts: list[Part]) -> list[tuple[float, float]] | None:
        """The outline of floor parts, else the convex hull of their footprint; None without parts."""
        if not parts:
            return None
        verts = np.concatenate([p.verts for p in parts])
        poly = outline(parts)
        if poly is None:
            poly = hull_polygon(verts[:, :2])
        return poly

    def ignjax_room(self, owner: Owner, members: list[Instance]) -> Room | None:
        """A room stored by :func:`~ignjax.scenes.io.usd.export.save_usd` (its polygon moved along with the prim)."""
        prim = owner.prim
        rid = str(authored(prim, ATTR_ID) or prim.GetName())
        label = str(authored(prim, NS + "label") or vocab.normalize_room_label(prim.GetName()))
        name = str(authored(prim, NS + "name") or "")
        poly = authored(prim, NS + "polygon")
        if poly is not None:
            poly = [tuple(map(float, q)) for q in poly]
            delta, _ = self._planar(prim, np.eye(4))
            if delta is not None:
                poly = [tuple(apply(delta, np.array([[x, y, 0.0]]))[0, :2]) for x, y in poly]
        else:
            poly = self.room_polygon(owner, members)
            if poly is None:
                warn_import(self.spath, f"room prim {prim.GetPath()} has no polygon and no geometry; ignored")
                return None
        return Room(rid, label, tuple(poly), name)

    def wall(self, prim) -> Wall | None:
        """A wall stored by :func:`~ignjax.scenes.io.usd.export.save_usd`; None without its attributes."""
        vals = {k: authored(prim, NS + k) for k in ("start", "end", "thickness", "height", "bottom", "rooms")}
        if any(vals[k] is None for k in ("start", "end", "thickness", "height")):
            warn_import(self.spath, f"wall prim {prim.GetPath()} lacks ignjax wall attributes; ignored")
            return None
        start, end = tuple(map(float, vals["start"])), tuple(map(float, vals["end"]))
        h, bottom = float(vals["height"]), float(vals["bottom"] or 0.0)
        angle = math.atan2(end[1] - start[1], end[0] - start[0])
        delta, _ = self._planar(prim, pose(((start[0] + end[0]) / 2, (start[1] + end[1]) / 2, bottom + h / 2), angle))
        if delta is not None:
            pts = apply(delta, np.array([[*start, 0.0], [*end, 0.0]]))
            start, end = tuple(pts[0, :2]), tuple(pts[1, :2])
        return Wall(str(authored(prim, ATTR_ID) or prim.GetName()), start, end, float(vals["thickness"]), h, bottom,
                    tuple(str(r) for r in (vals["rooms"] or ())))

    def door(self, prim) -> Door | None:
        """A door stored by :func:`~ignjax.scenes.io.usd.export.save_usd`; None without its attributes."""
        vals = {k: authored(prim, NS + k) for k in ("position", "width", "yaw", "rooms", "height", "doorKind")}
        if any(vals[k] is None for k in ("position", "width", "yaw")):
            warn_import(self.spath, f"door prim {prim.GetPath()} lacks ignjax door attributes; ignored")
            return None
        pos, yaw = tuple(map(float, vals["position"])), float(vals["yaw"])
        delta, theta = self._planar(prim, pose((pos[0], pos[1], 0.0), yaw))
        if delta is not None:
            pos, yaw = tuple(apply(delta, np.array([[*pos, 0.0]]))[0, :2]), wrap(yaw + theta)
        rooms = [str(r) or None for r in (vals["rooms"] or ())]
        rooms = (rooms + [None, None])[:2]
        return Door(str(authored(prim, ATTR_ID) or prim.GetName()), pos, float(vals["width"]), yaw, tuple(rooms),
                    float(vals["height"]) if vals["height"] is not None else 2.1, str(vals["doorKind"] or "door"))

    def room_polygon(self, owner: Owner, members: list[Instance]) -> list[tuple[float, float]] | None:
        """A room prim's floor polygon: from its floor geometry, else the
        hull of the objects below it."""
        poly = self.room_from_parts(self.instances.parts(owner))
        if poly is None and members:
            poly = hull_polygon(np.concatenate([m.bbox.footprint() for m in members]))
        return poly

    @staticmethod
    def cover(instances: list[Instance], walls: list[Wall]) -> list[tuple[float, float]] | None:
        """The polygon of the one default room: the hull of all boxes and walls (else a padded rectangle)."""
        pts = [i.bbox.footprint() for i in instances]
        pts += [np.array([w.start, w.end]) for w in walls]
        if not pts:
            return None
        xy = np.concatenate(pts)
        poly = hull_polygon(xy)
        return poly if poly is not None else padded_rect(xy)


def room_at(rooms, xy) -> str | None:
    """The id of the first room whose polygon holds the point ``xy``, or None."""
    p = np.asarray(xy, dtype=np.float64)[None]
    for r in rooms:
        if bool(points_in_polygon(p, r.polygon)[0]):
            return r.id
    return None


def outline(parts: list[Part]) -> list[tuple[float, float]] | None:
    """The outline of the upward- (else downward-) facing triangles of the
    parts, projected on the floor, when it is one simple loop."""
    tris = np.concatenate([p.verts[p.faces] for p in parts])  # Shape: (T, 3, 3)
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    norm = np.linalg.norm(n, axis=1)
    ok = norm > 1e-12
    up = ok & (n[:, 2] >= 0.9 * norm)
    sel = up if up.any() else ok & (n[:, 2] <= -0.9 * norm)
    if not sel.any():
        return None
    xy = tris[sel][:, :, :2].reshape(-1, 2)
    keys = np.round(xy / 1e-6).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1, 3)
    pts = xy[first]
    edges = np.concatenate([inverse[:, [0, 1]], inverse[:, [1, 2]], inverse[:, [2, 0]]])
    edges = edges[edges[:, 0] != edges[:, 1]]
    und = np.sort(edges, axis=1)
    uniq, counts = np.unique(und, axis=0, return_counts=True)
    boundary = uniq[counts == 1]
    if len(boundary) < 3:
        return None
    adj: dict[int, list[int]] = {}
    for a, b in boundary:
        adj.setdefault(int(a), []).append(int(b))
        adj.setdefault(int(b), []).append(int(a))
    if any(len(v) != 2 for v in adj.values()):
        return None
    start = int(boundary[0, 0])
    loop, prev, cur = [start], None, start
    while True:
        nxt = adj[cur][0] if adj[cur][0] != prev else adj[cur][1]
        if nxt == start:
            break
        loop.append(nxt)
        prev, cur = cur, nxt
        if len(loop) > len(adj):
            return None
    if len(loop) != len(adj):
        return None  # several loops (holes, separate pieces)
    poly = [tuple(map(float, pts[i])) for i in loop]
    # drop collinear points
    arr = np.asarray(poly)
    prev_p, next_p = np.roll(arr, 1, 0), np.roll(arr, -1, 0)
    cross = (arr[:, 0] - prev_p[:, 0]) * (next_p[:, 1] - prev_p[:, 1]) - (arr[:, 1] - prev_p[:, 1]) * (next_p[:, 0] - prev_p[:, 0])
    poly = [p for p, c in zip(poly, cross) if abs(c) > 1e-12]
    if polygon_problem(poly) is not None:
        return None
    if polygon_area(poly) < 0:
        poly = poly[::-1]
    return poly


def hull_polygon(xy: np.ndarray) -> list[tuple[float, float]] | None:
    """The convex hull of floor points as a valid room polygon, or None."""
    corners = convex_hull(xy)
    if not len(corners):
        return None
    poly = [tuple(map(float, xy[i])) for i in corners]
    return poly if polygon_problem(poly) is None else None
