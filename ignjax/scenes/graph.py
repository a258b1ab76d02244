"""The room-object graph, derived from a :class:`~ignjax.scenes.model.Scene`.

* room -> instances standing in it (:func:`room_instances`),
* instance -> nearby instances (:func:`nearby_instances`: footprint-to-
  footprint distance within a radius, structural instances left out),
* room -> rooms it connects to through doors (:func:`room_adjacency`).
"""

from __future__ import annotations

from collections import defaultdict, deque

import numpy as np

from ignjax.scenes.model import Instance, OrientedBox, Scene
from ignjax.scenes.model.polygons import _segments_cross


def room_instances(scene: Scene, include_structural: bool = False) -> dict[str, list[str]]:
    """Room id -> ids of the instances whose ``room`` is that room (scene order)."""
    out: dict[str, list[str]] = {r.id: [] for r in scene.rooms}
    for inst in scene.instances:
        if inst.room is not None and (include_structural or not inst.structural):
            out.setdefault(inst.room, []).append(inst.id)
    return out


def footprint_distance(a: OrientedBox, b: OrientedBox) -> float:
    """2-D distance between two boxes' floor footprints (0 when they overlap)."""
    pa, pb = a.footprint(), b.footprint()
    for i in range(4):
        for j in range(4):
            if _segments_cross(pa[i], pa[(i + 1) % 4], pb[j], pb[(j + 1) % 4]):
                return 0.0
    return float(min(b.distance_xy(pa).min(), a.distance_xy(pb).min()))


def nearby_instances(scene: Scene, radius: float = 1.5, include_structural: bool = False) -> dict[str, list[str]]:
    """Instance id -> ids of other instances within ``radius`` metres.

    Distance is between floor footprints (so a laptop on a desk is at
    distance 0 from the desk). Only non-structural instances take part
    unless ``include_structural``. Symmetric by construction.
    """
    items: list[Instance] = [i for i in scene.instances if include_structural or not i.structural]
    out: dict[str, list[str]] = {i.id: [] for i in items}
    if not items:
        return out
    centers = np.array([i.bbox.center[:2] for i in items])
    reach = np.array([np.hypot(*i.bbox.half_extents[:2]) for i in items])
    for a in range(len(items)):
        d = np.hypot(*(centers - centers[a]).T)
        cand = np.nonzero(d <= reach + reach[a] + radius)[0]
        for b in cand:
            if b <= a:
                continue
            if footprint_distance(items[a].bbox, items[b].bbox) <= radius:
                out[items[a].id].append(items[b].id)
                out[items[b].id].append(items[a].id)
    return out


def room_adjacency(scene: Scene) -> dict[str, set[str]]:
    """Room id -> ids of the rooms reachable through one door or opening."""
    adj: dict[str, set[str]] = {r.id: set() for r in scene.rooms}
    for d in scene.doors:
        a, b = d.rooms
        if a is not None and b is not None and a != b:
            adj.setdefault(a, set()).add(b)
            adj.setdefault(b, set()).add(a)
    return adj


def rooms_unreachable_by_doors(scene: Scene, start: str | None = None) -> list[str]:
    """Rooms that cannot be reached from ``start`` (default: the first room)
    through doors, by the door graph alone. Empty when all are connected."""
    if not scene.rooms:
        return []
    adj = room_adjacency(scene)
    start = start or scene.rooms[0].id
    seen = {start}
    queue = deque([start])
    while queue:
        r = queue.popleft()
        for n in adj.get(r, ()):
            if n not in seen:
                seen.add(n)
                queue.append(n)
    return [r.id for r in scene.rooms if r.id not in seen]


def category_instances(scene: Scene) -> dict[str, list[str]]:
    """Category -> ids of its non-structural instances (scene order)."""
    out: dict[str, list[str]] = defaultdict(list)
    for inst in scene.objects:
        out[inst.category].append(inst.id)
    return dict(out)
