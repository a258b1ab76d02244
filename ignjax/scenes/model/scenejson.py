"""The lossless JSON form of a scene (:func:`scene_to_dict`,
:func:`scene_from_dict`, :func:`scene_to_json`), for caches, tests and
debugging, and the ``inspect --json`` summary (:func:`scene_summary`).
"""

from __future__ import annotations

import dataclasses
import json
from typing import Any

import numpy as np

from ignjax.errors import SceneError
from ignjax.scenes.model.elements import Attributes, Door, Geom, Instance, MeshData, OrientedBox, Room, Scene, SceneMeta, Wall
from ignjax.scenes.model.validation import validate_scene

__all__ = ["SCENE_JSON_VERSION", "scene_to_dict", "scene_from_dict", "scene_to_json", "scene_summary"]

SCENE_JSON_VERSION = 1


def _geom_to_dict(g: Geom) -> dict[str, Any]:
    d: dict[str, Any] = {"kind": g.kind, "size": list(g.size), "pos": list(g.pos), "quat": list(g.quat),
                         "rgba": list(g.rgba), "part": g.part, "material": g.material}
    if g.mesh is not None:
        d["mesh"] = {"vertices": g.mesh.vertices.tolist(), "faces": g.mesh.faces.tolist()}
    return d


def _geom_from_dict(d: dict[str, Any]) -> Geom:
    mesh = d.get("mesh")
    return Geom(kind=d["kind"], size=d["size"], pos=d["pos"], quat=d["quat"], rgba=d["rgba"],
                part=d.get("part", ""), material=d.get("material"),
                mesh=MeshData(np.array(mesh["vertices"]), np.array(mesh["faces"])) if mesh else None)


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """Lossless JSON-ready dict of a scene."""
    return {
        "format": "ignjax-scene",
        "version": SCENE_JSON_VERSION,
        "id": scene.id,
        "wall_height": scene.wall_height,
        "meta": dataclasses.asdict(scene.meta),
        "rooms": [{"id": r.id, "label": r.label, "polygon": [list(p) for p in r.polygon], "name": r.name} for r in scene.rooms],
        "doors": [{"id": d.id, "position": list(d.position), "width": d.width, "yaw": d.yaw, "rooms": list(d.rooms),
                   "height": d.height, "kind": d.kind} for d in scene.doors],
        "walls": [{"id": w.id, "start": list(w.start), "end": list(w.end), "thickness": w.thickness, "height": w.height,
                   "bottom": w.bottom, "rooms": list(w.rooms)} for w in scene.walls],
        "instances": [
            {"id": i.id, "category": i.category, "position": list(i.position), "yaw": i.yaw,
             "bbox": {"center": list(i.bbox.center), "half_extents": list(i.bbox.half_extents), "yaw": i.bbox.yaw},
             "room": i.room, "attributes": i.attributes.as_dict(), "support": i.support, "structural": i.structural,
             "geoms": [_geom_to_dict(g) for g in i.geoms], "name": i.name}
            for i in scene.instances
        ],
    }


def scene_from_dict(d: dict[str, Any], path: str | None = None) -> Scene:
    """Inverse of :func:`scene_to_dict`; raises :class:`SceneError` on bad input."""
    if d.get("format") != "ignjax-scene":
        raise SceneError(path, "format", "not an ignjax scene document (expected format 'ignjax-scene')")
    if d.get("version") != SCENE_JSON_VERSION:
        raise SceneError(path, "version", f"unsupported scene version {d.get('version')!r}; this ignjax reads {SCENE_JSON_VERSION}")
    try:
        scene = Scene(
            id=d["id"],
            wall_height=d.get("wall_height", 2.5),
            meta=SceneMeta(**d.get("meta", {})),
            rooms=tuple(Room(r["id"], r["label"], tuple(tuple(p) for p in r["polygon"]), r.get("name", "")) for r in d["rooms"]),
            doors=tuple(Door(x["id"], x["position"], x["width"], x["yaw"], tuple(x["rooms"]), x.get("height", 2.1), x.get("kind", "door")) for x in d.get("doors", [])),
            walls=tuple(Wall(x["id"], x["start"], x["end"], x["thickness"], x["height"], x.get("bottom", 0.0), tuple(x.get("rooms", ()))) for x in d.get("walls", [])),
            instances=tuple(
                Instance(id=x["id"], category=x["category"], position=x["position"], yaw=x["yaw"],
                         bbox=OrientedBox(**x["bbox"]), room=x.get("room"), attributes=Attributes(**x.get("attributes", {})),
                         support=x.get("support"), structural=x.get("structural", False),
                         geoms=tuple(_geom_from_dict(g) for g in x.get("geoms", [])), name=x.get("name", ""))
                for x in d.get("instances", [])
            ),
        )
    except (KeyError, TypeError, ValueError) as e:
        raise SceneError(path, None, f"malformed scene document: {e!r}") from e
    return validate_scene(scene, path)


def scene_to_json(scene: Scene) -> str:
    return json.dumps(scene_to_dict(scene), separators=(",", ":"))


def scene_summary(scene: Scene) -> dict[str, Any]:
    """The ``inspect --json`` summary: source, units, rooms and instances.

    Positions are metres in the Z-up frame (the instance's ``position``).
    Structural instances are left out of ``instances``.
    """
    return {
        "source": scene.meta.source,
        "scene_id": scene.id,
        "format": scene.meta.source_format,
        "up_axis": scene.meta.up_axis,
        "meters_per_unit": scene.meta.meters_per_unit,
        "rooms": [{"id": r.id, "label": r.label} for r in scene.rooms],
        "instances": [
            {"id": i.id, "category": i.category, "room": i.room, "position": [round(v, 6) for v in i.position]}
            for i in scene.objects
        ],
    }
