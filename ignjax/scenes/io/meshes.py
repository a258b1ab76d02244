"""Import glTF / GLB / OBJ mesh scenes as :class:`Scene` objects.

Every geometry node of the file's scene graph becomes one
:class:`~ignjax.scenes.model.Instance` whose geometry is the node's mesh
(one ``Geom(kind="mesh")`` per mesh, vertices in the instance frame), placed
with the node's world transform. Files are read with trimesh
(``trimesh.load(path, force="scene", process=False)``: the vertices are kept
exactly as stored, so NaNs are caught rather than silently dropped).

Grouping
    * glTF: a node whose mesh has several primitives (one per material) is
      split by trimesh into one geometry per primitive; they are put back
      together as one instance named after the node, with one geom each.
    * OBJ: each ``o`` object becomes an instance; a file without ``o`` lines
      is split by its ``g`` groups instead.

Frame and units
    glTF is Y-up by specification and OBJ is Y-up by common convention
    (Blender, Maya and 3ds Max exports), so both are converted with
    ``(x, y, z) -> (x, -z, y)`` (a +90 degree turn about x; right-handed to
    right-handed) unless the sidecar says ``"up_axis": "Z"``. Coordinates are
    multiplied by ``meters_per_unit`` (default 1; glTF is metres by
    specification). Nothing is shifted: the floor should already be at
    height 0 after conversion.

Instances
    * ``id`` / ``name``: the node name (the glTF node, the OBJ object).
    * ``category``: from the sidecar's ``categories`` (by node name, or by
      the name of an ancestor node; :func:`vocab.normalize_category` of the
      text given), else :func:`~ignjax.scenes.io.names.category_from_name`
      of the node name, else of the mesh name (index and side suffixes
      stripped: ``Chair_01``, ``chair.002``, ``BishopL``, ``light3`` ->
      ``chair``, ``chair``, ``bishop``, ``light``).
    * ``structural``: the category is structural (:func:`vocab.is_structural`)
      or the node (or an ancestor) is listed in the sidecar's ``structural``.
    * ``yaw``: the node's local +x axis projected onto the floor (0 for an
      unrotated node; mesh files carry no notion of an object's front).
    * ``bbox``: the upright box around the world vertices along ``yaw``;
      ``position`` its footprint centre at the lowest vertex.
    * ``attributes.color``: the nearest palette colour when the whole
      instance has one uniform, untextured colour (vertex/face colours or a
      material base colour); otherwise None, like every other attribute.
    * ``room``: the room whose polygon holds the footprint centre (or the
      nearest room within 0.3 m).

Rooms
    From the sidecar; without one, a single room ``room_0`` labelled
    ``other`` whose polygon is the convex hull of all geometry's footprint.

Sidecar
    Optional JSON next to the file, named ``<file>.ignjax.json``
    (``kitchen.glb`` -> ``kitchen.glb.ignjax.json``), or given as the
    ``sidecar`` argument (a path or an already parsed dict). Every field is
    optional; unknown fields are errors (to catch typos)::

        {
          "scene_id": "kitchen_01",           # default: the file's stem
          "up_axis": "Y",                      # "Y" or "Z"; default "Y"
          "meters_per_unit": 1.0,              # > 0; default 1
          "categories": {"Cube.003": "chair"}, # node name -> category text
          "structural": ["Floor", "Walls"],    # node names that belong to the building
          "rooms": [                           # floor polygons, metres, in ignjax's
            {"id": "r0", "label": "kitchen",   # Z-up frame (x, y) after conversion
             "polygon": [[0, 0], [4, 0], [4, 3], [0, 3]]}
          ]
        }

    Names in ``categories`` and ``structural`` must exist in the file.
    Room labels go through :func:`vocab.normalize_room_label`.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from ignjax.errors import SceneError
from ignjax.scenes import vocab
from ignjax.scenes.io.footprint import outline_hull
from ignjax.scenes.io.formats import MESH_SUFFIXES, SIDECAR_SUFFIX
from ignjax.scenes.io.names import category_from_name
from ignjax.scenes.model import Attributes, Geom, Instance, MeshData, OrientedBox, Room, Scene, SceneMeta, room_containing
from ignjax.scenes.model.polygons import polygon_problem
from ignjax.scenes.model.validation import validate_scene

__all__ = ["SIDECAR_SUFFIX", "MESH_SUFFIXES", "Sidecar", "sidecar_path", "read_sidecar", "load_mesh_scene"]

ROOM_SNAP_DISTANCE = 0.3
_SIDECAR_KEYS = ("scene_id", "up_axis", "meters_per_unit", "categories", "structural", "rooms")
_DEFAULT_RGBA = (0.7, 0.7, 0.7, 1.0)
# Y-up -> Z-up: (x, y, z) -> (x, -z, y).
_Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


@dataclass(frozen=True)
class Sidecar:
    """A parsed, validated sidecar (see the module docstring for the schema).

    Attributes:
        path: the file it was read from, or None (given as a dict / absent).
        scene_id: scene id, or None for the mesh file's stem.
        up_axis: ``"Y"`` or ``"Z"``, or None for the format's default.
        meters_per_unit: unit scale.
        categories: node name -> category text.
        structural: node names that are part of the building.
        rooms: rooms in ignjax's frame, or empty for the default room.
    """

    path: str | None = None
    scene_id: str | None = None
    up_axis: str | None = None
    meters_per_unit: float = 1.0
    categories: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    structural: frozenset[str] = frozenset()
    rooms: tuple[Room, ...] = ()


def sidecar_path(mesh_path: str | os.PathLike) -> Path:
    """The default sidecar of a mesh file: ``<file>.ignjax.json`` beside it."""
    p = Path(mesh_path)
    return p.with_name(p.name + SIDECAR_SUFFIX)


def read_sidecar(source: str | os.PathLike | Mapping[str, Any] | None) -> Sidecar:
    """Read and validate a sidecar.

    Args:
        source: a path to the JSON file, an already parsed dict, or None
            (an empty sidecar).

    Returns:
        The validated :class:`Sidecar`.

    Raises:
        SceneError: naming the sidecar file, the field (``rooms[1].polygon``,
            ``meters_per_unit``) and the reason.
    """
    if source is None:
        return Sidecar()
    where_file: str | None
    if isinstance(source, Mapping):
        doc, where_file = dict(source), "sidecar"
    else:
        p = Path(source)
        where_file = str(p)
        try:
            text = p.read_text(encoding="utf-8")
        except FileNotFoundError as e:
            raise SceneError(p, None, "sidecar file not found") from e
        except (OSError, UnicodeDecodeError) as e:
            raise SceneError(p, None, f"cannot read the sidecar: {e}") from e
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as e:
            raise SceneError(p, f"line {e.lineno}, column {e.colno}", f"invalid JSON: {e.msg}") from e

    def err(where: str | None, reason: str) -> SceneError:
        return SceneError(where_file, where, reason)

    if not isinstance(doc, dict):
        raise err(None, f"a sidecar must be a JSON object, got {type(doc).__name__}")
    for key in doc:
        if key not in _SIDECAR_KEYS:
            raise err(key, f"unknown sidecar field; expected one of {', '.join(_SIDECAR_KEYS)}")

    scene_id = doc.get("scene_id")
    if scene_id is not None and (not isinstance(scene_id, str) or not scene_id):
        raise err("scene_id", f"expected a non-empty string, got {scene_id!r}")
    up = doc.get("up_axis")
    if up is not None:
        if not isinstance(up, str) or up.upper() not in ("Y", "Z"):
            raise err("up_axis", f"expected \"Y\" or \"Z\", got {up!r}")
        up = up.upper()
    mpu = doc.get("meters_per_unit", 1.0)
    if isinstance(mpu, bool) or not isinstance(mpu, (int, float)) or not math.isfinite(mpu) or mpu <= 0:
        raise err("meters_per_unit", f"expected a positive finite number, got {mpu!r}")
    cats = doc.get("categories", {})
    if not isinstance(cats, dict):
        raise err("categories", "expected an object mapping node names to categories")
    for k, v in cats.items():
        if not isinstance(v, str) or not v.strip():
            raise err(f"categories.{k}", f"expected a category name, got {v!r}")
    structural = doc.get("structural", [])
    if not isinstance(structural, list) or not all(isinstance(s, str) for s in structural):
        raise err("structural", "expected a list of node names")
    rooms_raw = doc.get("rooms", [])
    if not isinstance(rooms_raw, list):
        raise err("rooms", "expected a list of rooms")
    rooms: list[Room] = []
    seen: set[str] = set()
    for i, r in enumerate(rooms_raw):
        w = f"rooms[{i}]"
        if not isinstance(r, dict):
            raise err(w, "expected an object with id, label and polygon")
        for key in r:
            if key not in ("id", "label", "polygon"):
                raise err(f"{w}.{key}", "unknown room field; expected id, label, polygon")
        rid = r.get("id", f"room_{i}")
        if not isinstance(rid, str) or not rid:
            raise err(f"{w}.id", f"expected a non-empty string, got {rid!r}")
        if rid in seen:
            raise err(f"{w}.id", f"duplicate room id {rid!r}")
        seen.add(rid)
        label = r.get("label")
        if label is not None and not isinstance(label, str):
            raise err(f"{w}.label", f"expected a string, got {label!r}")
        poly = r.get("polygon")
        if not isinstance(poly, list) or not all(
            isinstance(p, (list, tuple)) and len(p) == 2
            and all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in p) for p in poly
        ):
            raise err(f"{w}.polygon", "expected a list of [x, y] number pairs")
        problem = polygon_problem(poly) if poly else "has no points"
        if problem:
            raise err(f"{w}.polygon", f"floor polygon {problem}")
        pts = [tuple(float(c) for c in p) for p in poly]
        if len(pts) >= 2 and pts[0] == pts[-1]:
            pts.pop()
        rooms.append(Room(rid, vocab.normalize_room_label(label), tuple(pts), label or ""))
    return Sidecar(
        path=where_file if not isinstance(source, Mapping) else None,
        scene_id=scene_id,
        up_axis=up,
        meters_per_unit=float(mpu),
        categories=MappingProxyType(dict(cats)),
        structural=frozenset(structural),
        rooms=tuple(rooms),
    )


# ---------------------------------------------------------------------------
# Helpers
# ---------------------------------------------------------------------------


def _clean(v: float) -> float:
    """Round to a nanometre so that float noise (-1e-17) does not leak out."""
    return round(float(v), 9) + 0.0


def _visual_rgba(geom) -> tuple[tuple[float, float, float, float], bool]:
    """(main colour, whether it is one uniform untextured colour) of a mesh."""
    visual = getattr(geom, "visual", None)
    kind = getattr(visual, "kind", None)
    if visual is None or kind is None:
        return _DEFAULT_RGBA, False
    if kind in ("face", "vertex"):
        cols = np.asarray(visual.face_colors if kind == "face" else visual.vertex_colors, dtype=np.float64)
        if cols.size == 0:
            return _DEFAULT_RGBA, False
        mean = cols.mean(axis=0) / 255.0
        uniform = bool(np.all(cols == cols[0]))
        return tuple(float(c) for c in mean[:4]), uniform  # type: ignore[return-value]
    if kind == "texture":
        mat = getattr(visual, "material", None)
        if mat is None:
            return _DEFAULT_RGBA, False
        textured = getattr(mat, "baseColorTexture", None) is not None or getattr(mat, "image", None) is not None
        main = getattr(mat, "main_color", None)
        if main is None:
            return _DEFAULT_RGBA, False
        c = np.asarray(main, dtype=np.float64).reshape(-1)
        if c.size < 3:
            return _DEFAULT_RGBA, False
        c = c / 255.0 if c.max() > 1.0 else c
        rgba = (float(c[0]), float(c[1]), float(c[2]), float(c[3]) if c.size > 3 else 1.0)
        return rgba, not textured
    return _DEFAULT_RGBA, False


def _ancestors(graph, node: str) -> list[str]:
    parents = graph.transforms.parents
    out: list[str] = []
    cur = parents.get(node)
    while cur is not None and cur != graph.base_frame and cur not in out:
        out.append(cur)
        cur = parents.get(cur)
    return out


def _obj_split_kwargs(path: Path) -> dict[str, Any]:
    has_o = has_g = False
    try:
        with open(path, "rb") as f:
            for raw in f:
                if raw.startswith(b"o ") or raw.startswith(b"o\t"):
                    has_o = True
                    break
                if raw.startswith(b"g ") or raw.startswith(b"g\t"):
                    has_g = True
    except OSError as e:
        raise SceneError(path, None, f"cannot read: {e}") from e
    if has_o or not has_g:
        return {"split_objects": True}
    return {"split_groups": True}


@dataclass
class _Group:
    """One future instance: a node and the geometry under it."""

    name: str
    transform: np.ndarray  # the node's world transform (source frame)
    members: list[tuple[str, str, np.ndarray]]  # (node, geometry name, world transform)


# ---------------------------------------------------------------------------
# Loader
# ---------------------------------------------------------------------------


def load_mesh_scene(path: str | os.PathLike, *, sidecar: str | os.PathLike | Mapping[str, Any] | None = None) -> Scene:
    """Read a glTF (``.gltf``), GLB (``.glb``) or OBJ (``.obj``) file as a scene.

    Args:
        path: the mesh file.
        sidecar: a sidecar path or parsed dict (schema in the module
            docstring); by default ``<file>.ignjax.json`` beside the file
            when it exists.

    Returns:
        The validated scene: one instance per geometry node, rooms from the
        sidecar or one ``other`` room around all geometry.

    Raises:
        SceneError: the file is missing, not a readable mesh file, holds no
            triangle geometry or non-finite vertices, or the sidecar is
            invalid; the message names the file, the node or field, and the
            reason.
    """
    import trimesh  # heavy import, only when meshes are read

    p = Path(path)
    if not p.exists():
        raise SceneError(p, None, "no such file")
    if p.is_dir():
        raise SceneError(p, None, "expected a .gltf, .glb or .obj file, got a directory")
    suffix = p.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise SceneError(p, None, f"unsupported mesh file type {suffix or '(none)'!r}; expected .gltf, .glb or .obj")
    if sidecar is None and sidecar_path(p).is_file():
        sidecar = sidecar_path(p)
    side = read_sidecar(sidecar)
    up = side.up_axis or "Y"
    mpu = side.meters_per_unit
    conv = (_Y_UP_TO_Z_UP if up == "Y" else np.eye(3)) * mpu

    kwargs: dict[str, Any] = {"force": "scene", "process": False}
    if suffix == ".obj":
        kwargs.update(_obj_split_kwargs(p))
    try:
        loaded = trimesh.load(str(p), **kwargs)
    except Exception as e:  # trimesh raises many unrelated types on corrupt input
        raise SceneError(p, None, f"not a readable {suffix[1:].upper()} file ({type(e).__name__}: {e})") from e
    if not isinstance(loaded, trimesh.Scene):
        raise SceneError(p, None, f"not a mesh scene (trimesh returned {type(loaded).__name__})")
    graph = loaded.graph

    # Collect geometry nodes, grouping the primitives of one glTF mesh.
    groups: dict[str, _Group] = {}
    names_in_file: set[str] = set()
    for node in sorted(graph.nodes_geometry):
        transform, gname = graph[node]
        geom = loaded.geometry.get(gname)
        names_in_file.update([node, str(gname)] + _ancestors(graph, node))
        if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
            continue
        owner = node
        if geom.metadata.get("from_gltf_primitive"):
            parent = graph.transforms.parents.get(node)
            if parent is not None and parent != graph.base_frame:
                owner = parent
        if owner not in groups:
            owner_tf = graph.get(owner)[0] if owner != node else transform
            groups[owner] = _Group(owner, np.asarray(owner_tf, dtype=np.float64), [])
        groups[owner].members.append((node, str(gname), np.asarray(transform, dtype=np.float64)))
    if not groups:
        raise SceneError(p, None, "the file holds no triangle geometry")
    for key in side.categories:
        if key not in names_in_file:
            raise SceneError(side.path or "sidecar", f"categories.{key}", f"no node or mesh named {key!r} in {p.name}")
    for key in side.structural:
        if key not in names_in_file:
            raise SceneError(side.path or "sidecar", "structural", f"no node or mesh named {key!r} in {p.name}")

    prepared = []
    all_xy = []
    for name in sorted(groups):
        g = groups[name]
        parts = []
        for node, gname, tf in sorted(g.members, key=lambda m: (m[1], m[0])):
            geom = loaded.geometry[gname]
            v = np.asarray(geom.vertices, dtype=np.float64)
            if not np.all(np.isfinite(v)):
                raise SceneError(p, f"node {node!r}", f"mesh {gname!r} has NaN or infinite vertices")
            if not np.all(np.isfinite(tf)):
                raise SceneError(p, f"node {node!r}", "the node transform has NaN or infinite values")
            world = (v @ tf[:3, :3].T + tf[:3, 3]) @ conv.T
            parts.append((node, gname, geom, world, np.asarray(geom.faces, dtype=np.int64)))
            all_xy.append(world[:, :2])
        prepared.append((g, parts))

    # Rooms.
    if side.rooms:
        rooms = side.rooms
    else:
        hull = outline_hull(np.concatenate(all_xy))
        if len(hull) < 3 or polygon_problem(hull) is not None:
            raise SceneError(p, None, "cannot derive a room: the geometry's floor footprint has no area "
                                      "(give rooms in a sidecar)")
        rooms = (Room("room_0", vocab.OTHER_ROOM, tuple((float(x), float(y)) for x, y in hull), "convex hull"),)

    instances: list[Instance] = []
    for g, parts in prepared:
        lineage = [g.name] + [m[0] for m in g.members] + [m[1] for m in g.members] + _ancestors(graph, g.name)
        category_text = next((side.categories[n] for n in lineage if n in side.categories), None)
        if category_text is not None:
            category = vocab.normalize_category(category_text)
        else:
            category = category_from_name(g.name)
            if category == vocab.UNKNOWN_CATEGORY:
                category = category_from_name(parts[0][1])
        structural = vocab.is_structural(category) or any(n in side.structural for n in lineage)

        # Heading: the node's local +x projected onto the floor.
        axes = conv @ g.transform[:3, :3]
        hx = axes[:2, 0]
        if float(np.hypot(*hx)) < 1e-9:
            hx = axes[:2, 1]
        yaw = math.atan2(hx[1], hx[0]) if float(np.hypot(*hx)) >= 1e-9 else 0.0
        yaw = round(yaw, 12) + 0.0
        c, s = math.cos(yaw), math.sin(yaw)
        to_local = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # world -> yaw frame
        verts = np.concatenate([w for _, _, _, w, _ in parts])
        local = verts @ to_local.T
        lo, hi = local.min(axis=0), local.max(axis=0)
        mid = 0.5 * (lo + hi)
        cx, cy = c * mid[0] - s * mid[1], s * mid[0] + c * mid[1]
        origin_local = np.array([mid[0], mid[1], lo[2]])
        half = 0.5 * (hi - lo)
        bbox = OrientedBox((_clean(cx), _clean(cy), _clean(mid[2])), tuple(_clean(h) for h in half), yaw)
        position = (_clean(cx), _clean(cy), _clean(lo[2]))

        geoms = []
        colours = []
        for node, gname, geom, world, faces in parts:
            rgba, uniform = _visual_rgba(geom)
            colours.append((rgba, uniform))
            mesh_v = world @ to_local.T - origin_local
            geoms.append(Geom("mesh", (1.0, 1.0, 1.0), rgba=rgba, part=gname, mesh=MeshData(mesh_v, faces)))
        color = None
        if all(u for _, u in colours) and all(np.allclose(colours[0][0], rgba, atol=1e-6) for rgba, _ in colours):
            color = vocab.nearest_color(colours[0][0][:3])
        instances.append(Instance(
            id=g.name, category=category, position=position, yaw=yaw, bbox=bbox,
            room=room_containing(rooms, position[:2], ROOM_SNAP_DISTANCE), attributes=Attributes(color=color),
            structural=structural, geoms=tuple(geoms), name=g.name,
        ))

    params = json.dumps({"format": suffix[1:], "sidecar": side.path, "nodes": len(instances)}, sort_keys=True)
    scene = Scene(
        id=side.scene_id or p.stem,
        rooms=rooms,
        instances=tuple(instances),
        meta=SceneMeta(source=str(p), source_format="mesh", up_axis=up, meters_per_unit=mpu, params=params),
    )
    return validate_scene(scene, str(p))
