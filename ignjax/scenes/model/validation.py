"""A scene's internal consistency (:func:`validate_scene`): what every
reader checks before it hands a scene out."""

from __future__ import annotations

import math
from typing import Iterable

import numpy as np

from ignjax.errors import SceneError
from ignjax.scenes import vocab
from ignjax.scenes.model.elements import GEOM_KINDS, Scene
from ignjax.scenes.model.polygons import polygon_problem

__all__ = ["validate_scene"]


def _finite(values: Iterable[float]) -> bool:
    return all(math.isfinite(v) for v in values)


def validate_scene(scene: Scene, path: str | None = None) -> Scene:
    """Check a scene's internal consistency; raise :class:`SceneError` naming
    the element and the reason. Returns the scene unchanged when valid.

    Checks: unique ids; known room labels; usable floor polygons; finite
    numbers everywhere; instance rooms, supports and door rooms that exist.
    (Reachability of rooms is a property of the navigation grid and is
    checked there, see :func:`ignjax.scenes.navgrid.check_reachable`.)
    """
    src = path or scene.meta.source
    if not scene.rooms:
        raise SceneError(src, "rooms", "the scene has no rooms")
    seen: set[str] = set()
    for i, r in enumerate(scene.rooms):
        where = f"rooms[{i}] ({r.id})"
        if r.id in seen:
            raise SceneError(src, where, f"duplicate room id {r.id!r}")
        seen.add(r.id)
        if r.label not in vocab.ALL_ROOM_LABELS:
            raise SceneError(src, where, f"room label {r.label!r} is not one of {vocab.ALL_ROOM_LABELS}")
        problem = polygon_problem(r.polygon)
        if problem:
            raise SceneError(src, f"{where}.polygon", f"floor polygon {problem}")
    room_ids = {r.id for r in scene.rooms}
    for i, d in enumerate(scene.doors):
        where = f"doors[{i}] ({d.id})"
        if not _finite(d.position + (d.width, d.yaw, d.height)):
            raise SceneError(src, where, "has NaN or infinite values")
        if d.width <= 0:
            raise SceneError(src, where, f"door width must be positive, got {d.width}")
        for rid in d.rooms:
            if rid is not None and rid not in room_ids:
                raise SceneError(src, where, f"door refers to unknown room {rid!r}")
    for i, w in enumerate(scene.walls):
        if not _finite(w.start + w.end + (w.thickness, w.height, w.bottom)):
            raise SceneError(src, f"walls[{i}] ({w.id})", "has NaN or infinite values")
    ids: set[str] = set()
    for i, inst in enumerate(scene.instances):
        where = f"instances[{i}] ({inst.id})"
        if inst.id in ids:
            raise SceneError(src, where, f"duplicate instance id {inst.id!r}")
        ids.add(inst.id)
        nums = inst.position + (inst.yaw,) + inst.bbox.center + inst.bbox.half_extents + (inst.bbox.yaw,)
        if not _finite(nums):
            raise SceneError(src, where, "position or bounding box has NaN or infinite values")
        if any(h < 0 for h in inst.bbox.half_extents):
            raise SceneError(src, where, "bounding box has negative extent")
        if inst.room is not None and inst.room not in room_ids:
            raise SceneError(src, where, f"instance refers to unknown room {inst.room!r}")
        for g in inst.geoms:
            if g.kind not in GEOM_KINDS:
                raise SceneError(src, where, f"unknown geom kind {g.kind!r}")
            if not _finite(g.size + g.pos + g.quat):
                raise SceneError(src, where, f"geom {g.part or g.kind} has NaN or infinite values")
            if g.kind == "mesh" and (g.mesh is None or len(g.mesh.faces) == 0):
                raise SceneError(src, where, "mesh geom has no triangles")
            if g.kind == "mesh" and not np.all(np.isfinite(g.mesh.vertices)):
                raise SceneError(src, where, "mesh has NaN or infinite vertices")
    for i, inst in enumerate(scene.instances):
        if inst.support is not None and inst.support not in ids:
            raise SceneError(src, f"instances[{i}] ({inst.id})", f"support refers to unknown instance {inst.support!r}")
    return scene
