"""Import ProcTHOR houses (AI2-THOR / Unity JSON) as :class:`Scene` objects.

A ProcTHOR house is a JSON object with ``rooms`` (``roomType``,
``floorPolygon``), ``walls`` (vertical polygons, one per room side),
``doors`` and ``windows`` (holes in walls) and ``objects`` (``assetId``,
``position``, ``rotation``, nested ``children`` standing on them). Two
schemas occur in the wild and both are read:

* ``1.0.0`` (``metadata.schema``): holes are ``holePolygon`` (two corners)
  plus ``assetPosition``; materials are objects (``{"name": ...}``).
* ``0.0.1`` and older (ProcTHOR-10K): holes are ``boundingBox``
  (``min``/``max``) plus ``assetOffset``; materials are plain strings.

The format is recognised per door/window (``holePolygon`` or
``boundingBox``), so mixed or unlabelled files work too.

Frame conversion
    Unity is Y-up and left-handed. A point ``(x_u, y_u, z_u)`` becomes
    ``(x_u, z_u, y_u)`` in ours (Z up, right-handed, metres). The swap of two
    axes is a reflection, which is what turns a left-handed frame into a
    right-handed one, so no axis changes sign.

    Unity's ``rotation`` is Euler angles in degrees applied Z, then X, then Y
    (``R = Ry @ Rx @ Rz`` on column vectors). ``Ry(t)`` takes the asset's
    forward axis ``+z_u`` to ``(sin t, 0, cos t)`` and its ``+x_u`` to
    ``(cos t, 0, -sin t)``. In our frame that is: forward ->
    ``(sin t, cos t)``, right ``+x_u`` -> ``(cos t, -sin t)``, i.e. the
    asset's ``+x_u`` ends up at angle ``-t``.

    ProcTHOR assets face ``+z_u`` (the shared houses show it: every
    painting's ``+z_u`` points away from its wall into its room, chairs
    around a table point at the table, a TV stand against the wall at
    ``x = 0`` with ``rotation.y = 90`` faces ``+x``). Our instances face
    their local ``+x`` (see :mod:`ignjax.scenes.procgen.catalogue`), so::

        yaw = pi/2 - radians(rotation.y)        (wrapped to (-pi, pi])

    and the asset's bounding box ``(size_x, size_y, size_z)`` becomes the
    upright box with half extents ``(size_z/2, size_x/2, size_y/2)`` along
    (front, left, up) at that yaw. Equivalently, the asset's ``+x_u`` edge
    lies at angle ``-radians(rotation.y)``: a box long along Unity x turned
    by 90 degrees is long along our y. Objects tilted about x or z (a
    baseball bat lying on the floor) get the upright box that holds all
    eight rotated corners, measured along the same heading.

Positions
    An object's ``position`` is the centre of its bounding box in the world
    (verified on the shared houses: all 47 upright floor-standing objects
    have ``position.y`` equal to half their asset height to within 3
    micrometres).
    :attr:`Instance.position` is the footprint centre at the box's lowest
    point; :attr:`Instance.bbox` the upright oriented box.

Building
    * Rooms: ``id`` kept as given (a string such as ``"room|4"``), label
      from ``roomType`` via :func:`vocab.normalize_room_label`, polygon from
      the ``x``/``z`` of ``floorPolygon`` (an explicit closing point is
      dropped).
    * Walls: ProcTHOR lists each wall once per side (one per room, plus an
      ``exterior`` copy). Copies of the same segment become one
      :class:`Wall` bounding all their rooms, :data:`WALL_THICKNESS` thick,
      as tall as its polygon. A hole's ``x`` range is measured along its
      ``wall0`` from that wall polygon's first point (the shared houses
      confirm it: with that reading no painting, shelf or hamper overlaps a
      door, with the other reading several do).
    * Doors: every door between two rooms is cut out of its wall
      (a :class:`Door` with the hole's width and centre, and a lintel wall
      over it). ``Doorframe`` assets give ``kind="opening"``, ``Doorway``
      assets ``kind="door"``. An exterior door is cut and recorded with
      ``rooms=(room, None)`` when it is open (``openness > 0``); a closed one
      (the usual ProcTHOR front door) leaves the wall solid and becomes a
      structural ``door`` instance.
    * Walls marked ``"empty": true`` (open-plan boundaries) are not built;
      each becomes a :class:`Door` of ``kind="opening"`` as wide as the
      wall, so the rooms stay connected.
    * Windows: structural ``window`` instances in the wall; the wall stays
      solid.

Objects
    Category from the asset's ``objectType`` through
    :func:`vocab.normalize_category`; box size from the asset table
    (:data:`~ignjax.scenes.io.procthor_assets.DEFAULT_ASSET_TABLE`, derived from ProcTHOR's
    ``asset-database.json`` by
    :func:`~ignjax.scenes.io.procthor_assets.derive_asset_table`). Nested
    ``children`` stand on their parent (``support`` = the parent's id).
    Each object gets one box :class:`Geom` filling its box, coloured by the
    object's ``color`` when the JSON gives one, else by a fixed colour per
    category. Attributes hold what the JSON says: ``color`` -> nearest
    palette colour, ``material`` -> material class when its name contains
    one (``"WornWood"`` -> ``wood``), ``isOn`` -> ``on``/``off``,
    ``openness`` -> ``open``/``closed``; everything else is None. An
    object's room is the room whose polygon holds its footprint centre (or,
    for an object hung on a wall line, the nearest room within 0.3 m).

The asset table and its command line are in :mod:`ignjax.scenes.io.procthor_assets`;
the frame conversion in :mod:`~ignjax.scenes.io.procthor_frame`, walls, doors
and windows in :mod:`~ignjax.scenes.io.procthor_walls`, typed reads of the
JSON fields in :mod:`~ignjax.scenes.io.procthor_fields`.
"""

from __future__ import annotations

import gzip
import json
import os
import zlib
from pathlib import Path
from typing import Any, Iterator, Mapping

import numpy as np

from ignjax.errors import SceneError
from ignjax.scenes import vocab
from ignjax.scenes.io.procthor_assets import AssetInfo, resolve_assets
from ignjax.scenes.io.procthor_fields import ReadContext
from ignjax.scenes.io.procthor_frame import unity_to_world, unity_yaw, upright_box
from ignjax.scenes.io.procthor_walls import read_building
from ignjax.scenes.model import Attributes, Geom, Instance, OrientedBox, Room, Scene, SceneMeta, room_containing
from ignjax.scenes.model.polygons import polygon_problem
from ignjax.scenes.model.validation import validate_scene

__all__ = [
    "WALL_THICKNESS",
    "unity_to_world",
    "unity_yaw",
    "house_to_scene",
    "iter_procthor",
    "load_procthor",
]

WALL_THICKNESS = 0.04
"""Thickness of imported walls, metres. ProcTHOR walls are zero-thickness
planes with wall decorations hung 5 mm off them and furniture at least
25 mm off them, so a thin wall keeps both visible and clear."""

ROOM_SNAP_DISTANCE = 0.3
"""An object whose footprint centre lies outside every room polygon (a
painting on a wall line) is given the nearest room within this distance."""

_MATERIAL_KEYWORDS: tuple[tuple[str, str], ...] = (
    ("wood", "wood"), ("oak", "wood"), ("walnut", "wood"), ("pine", "wood"), ("parquet", "wood"),
    ("metal", "metal"), ("steel", "metal"), ("chrome", "metal"), ("brass", "metal"), ("alumin", "metal"),
    ("iron", "metal"), ("copper", "metal"),
    ("fabric", "fabric"), ("cloth", "fabric"), ("carpet", "fabric"), ("wool", "fabric"), ("linen", "fabric"),
    ("leather", "leather"),
    ("plastic", "plastic"),
    ("glass", "glass"),
    ("ceramic", "ceramic"), ("porcelain", "ceramic"), ("tile", "ceramic"),
    ("marble", "stone"), ("granite", "stone"), ("stone", "stone"), ("concrete", "stone"), ("brick", "stone"),
    ("wicker", "wicker"), ("rattan", "wicker"),
)


# ---------------------------------------------------------------------------
# Parsing helpers
# ---------------------------------------------------------------------------


def _clean(v: float) -> float:
    """Round to a nanometre so that float noise (-1e-17) does not leak out."""
    return round(float(v), 9) + 0.0


def _material_class(value) -> str | None:
    name = value.get("name") if isinstance(value, dict) else value
    if not isinstance(name, str):
        return None
    low = name.lower()
    for key, cls in _MATERIAL_KEYWORDS:
        if key in low:
            return cls
    return None


def _category_rgba(category: str) -> tuple[float, float, float, float]:
    """A fixed, well-separated colour per category (golden-ratio hues)."""
    h = (zlib.crc32(category.encode("utf-8")) * 0.6180339887498949) % 1.0
    s, v = 0.45, 0.80
    i = int(h * 6.0) % 6
    f = h * 6.0 - int(h * 6.0)
    p, q, t = v * (1 - s), v * (1 - f * s), v * (1 - (1 - f) * s)
    r, g, b = [(v, t, p), (q, v, p), (p, v, t), (p, q, v), (t, p, v), (v, p, q)][i]
    return (round(r, 4), round(g, 4), round(b, 4), 1.0)



# ---------------------------------------------------------------------------
# Houses
# ---------------------------------------------------------------------------


def _parse_rooms(house: dict, ctx: ReadContext) -> list[Room]:
    rooms_raw = house.get("rooms")
    if rooms_raw is None or (isinstance(rooms_raw, list) and not rooms_raw):
        raise ctx.err("rooms", "the house has no rooms")
    rooms_raw = ctx.lst(rooms_raw, "rooms")
    rooms: list[Room] = []
    seen: set[str] = set()
    for i, r in enumerate(rooms_raw):
        w = f"rooms[{i}]"
        ctx.obj(r, w)
        rid = ctx.ident(r.get("id"), f"{w}.id")
        if rid in seen:
            raise ctx.err(f"{w}.id", f"duplicate room id {rid!r}")
        seen.add(rid)
        rtype = r.get("roomType")
        if rtype is not None and not isinstance(rtype, str):
            raise ctx.err(f"{w}.roomType", f"expected a string, got {rtype!r}")
        pts_raw = ctx.lst(r.get("floorPolygon"), f"{w}.floorPolygon")
        pts = [ctx.xyz(p, f"{w}.floorPolygon[{j}]", "xz") for j, p in enumerate(pts_raw)]
        for j, p in enumerate(pts_raw):
            if isinstance(p, dict) and "y" in p:
                ctx.num(p["y"], f"{w}.floorPolygon[{j}].y")
        # Drop an explicit closing point and repeated consecutive points.
        clean: list[tuple[float, float]] = []
        for p in pts:
            if not clean or abs(p[0] - clean[-1][0]) > 1e-9 or abs(p[1] - clean[-1][1]) > 1e-9:
                clean.append((p[0], p[1]))
        if len(clean) >= 2 and abs(clean[0][0] - clean[-1][0]) <= 1e-9 and abs(clean[0][1] - clean[-1][1]) <= 1e-9:
            clean.pop()
        problem = polygon_problem(clean) if clean else "has no points"
        if problem:
            raise ctx.err(f"{w}.floorPolygon", f"floor polygon {problem}")
        rooms.append(Room(rid, vocab.normalize_room_label(rtype), tuple(clean), rtype or ""))
    return rooms



def _parse_objects(house: dict, ctx: ReadContext, assets: Mapping[str, AssetInfo], rooms: list[Room]) -> list[Instance]:
    objs = house.get("objects", [])
    objs = ctx.lst(objs if objs is not None else [], "objects")
    out: list[Instance] = []
    ids: set[str] = set()

    def visit(o, where: str, parent: Instance | None):
        ctx.obj(o, where)
        oid = ctx.ident(o.get("id"), f"{where}.id")
        if oid in ids:
            raise ctx.err(f"{where}.id", f"duplicate object id {oid!r}")
        ids.add(oid)
        aid = o.get("assetId")
        if not isinstance(aid, str) or not aid:
            raise ctx.err(f"{where}.assetId", f"missing or not a string (object {oid!r})")
        info = assets.get(aid)
        if info is None:
            raise ctx.err(f"{where}.assetId", f"unknown assetId {aid!r} (object {oid!r}): not in the ProcTHOR asset table")
        pos = np.array(ctx.xyz(o.get("position"), f"{where}.position"))
        rot = ctx.xyz(o["rotation"], f"{where}.rotation", default=0.0) if "rotation" in o else (0.0, 0.0, 0.0)
        box, yaw = upright_box(pos, info.size, rot)
        category = vocab.normalize_category(info.object_type)
        color = None
        rgba = _category_rgba(category)
        if o.get("color") is not None:
            r, g, b = ctx.xyz(o["color"], f"{where}.color", "rgb")
            color = vocab.nearest_color((r, g, b))
            rgba = (min(max(r, 0.0), 1.0), min(max(g, 0.0), 1.0), min(max(b, 0.0), 1.0), 1.0)
        material = _material_class(o.get("material"))
        state = None
        if isinstance(o.get("isOn"), bool):
            state = "on" if o["isOn"] else "off"
        elif "openness" in o and o["openness"] is not None:
            state = "open" if ctx.num(o["openness"], f"{where}.openness") > 0 else "closed"
        box = OrientedBox(tuple(_clean(v) for v in box.center), tuple(_clean(v) for v in box.half_extents), box.yaw)
        position = (box.center[0], box.center[1], _clean(box.zmin))
        room = room_containing(rooms, position[:2], ROOM_SNAP_DISTANCE)
        if room is None and parent is not None:
            room = parent.room
        half = box.half_extents
        geom = Geom("box", half, (0.0, 0.0, half[2]), rgba=rgba, part=category, material=material)
        inst = Instance(oid, category, position, yaw, box, room=room,
                        attributes=Attributes(color=color, material=material, state=state),
                        support=parent.id if parent is not None else None,
                        structural=vocab.is_structural(category), geoms=(geom,), name=aid)
        out.append(inst)
        children = o.get("children")
        if children is not None:
            for j, ch in enumerate(ctx.lst(children, f"{where}.children")):
                visit(ch, f"{where}.children[{j}]", inst)

    for i, o in enumerate(objs):
        visit(o, f"objects[{i}]", None)
    return out


def _convert(house: Any, ctx: ReadContext, scene_id: str, assets: Mapping[str, AssetInfo], wall_thickness: float) -> Scene:
    if not isinstance(house, dict):
        raise ctx.err("", f"a ProcTHOR house must be a JSON object, got {type(house).__name__}")
    meta = house.get("metadata") if isinstance(house.get("metadata"), dict) else {}
    schema = meta.get("schema") if isinstance(meta.get("schema"), str) else None
    rooms = _parse_rooms(house, ctx)
    building = read_building(house, ctx, {r.id: r for r in rooms}, assets, wall_thickness)
    instances = _parse_objects(house, ctx, assets, rooms) + building.instances
    params = json.dumps({"schema": schema, "wall_thickness": wall_thickness}, sort_keys=True)
    scene = Scene(scene_id, tuple(rooms), tuple(building.doors), tuple(building.walls), tuple(instances),
                  SceneMeta(source=ctx.source, source_format="procthor", up_axis="Y", meters_per_unit=1.0, params=params),
                  wall_height=building.wall_height)
    try:
        return validate_scene(scene, ctx.source)
    except SceneError as e:
        raise SceneError(ctx.source, f"{ctx.prefix}{e.where}" if e.where else None, e.reason) from e


def house_to_scene(house: dict, *, source: str, scene_id: str,
                   assets: Mapping[str, AssetInfo] | str | os.PathLike | None = None,
                   wall_thickness: float = WALL_THICKNESS) -> Scene:
    """Convert one ProcTHOR house (a parsed JSON object) into a :class:`Scene`.

    Args:
        house: the house document (schema 1.0.0 or 0.0.1).
        source: where it came from (used in :class:`SceneMeta` and errors).
        scene_id: id of the resulting scene.
        assets: the asset table (a mapping assetId -> :class:`AssetInfo`, or
            a path for :func:`~ignjax.scenes.io.procthor_assets.load_asset_table`); the shipped table when None.
        wall_thickness: thickness of the imported walls, metres.

    Returns:
        The validated scene (frames and conventions in the module docstring).

    Raises:
        SceneError: naming ``source``, the field (``objects[3].assetId``,
            ``rooms[1].floorPolygon``) and the reason.
    """
    return _convert(house, ReadContext(str(source)), scene_id, resolve_assets(assets), float(wall_thickness))


def _suffix(p: Path) -> str:
    name = p.name.lower()
    for s in (".jsonl.gz", ".json.gz", ".jsonl", ".json"):
        if name.endswith(s):
            return s
    return p.suffix.lower()


def _stem(p: Path) -> str:
    suffix = _suffix(p)
    return p.name[: -len(suffix)] if suffix and p.name.lower().endswith(suffix) else p.stem


def iter_procthor(path: str | os.PathLike, *, assets: Mapping[str, AssetInfo] | str | os.PathLike | None = None,
                  wall_thickness: float = WALL_THICKNESS) -> Iterator[Scene]:
    """Yield the scenes of a ProcTHOR file one at a time (for large JSONL files).

    Same inputs and scene ids as :func:`load_procthor`.
    """
    p = Path(path)
    src = str(p)
    if not p.exists():
        raise SceneError(p, None, "no such file")
    if p.is_dir():
        raise SceneError(p, None, "expected a ProcTHOR .json/.jsonl/.jsonl.gz file, got a directory")
    table = resolve_assets(assets)
    suffix = _suffix(p)
    stem = _stem(p)
    opener = gzip.open if suffix.endswith(".gz") else open
    if suffix in (".jsonl", ".jsonl.gz"):
        try:
            with opener(p, "rt", encoding="utf-8") as f:
                for index, line in enumerate(f):
                    if not line.strip():
                        continue
                    where = f"line {index + 1}"
                    try:
                        house = json.loads(line)
                    except json.JSONDecodeError as e:
                        raise SceneError(p, where, f"invalid JSON: {e.msg} (column {e.colno})") from e
                    yield _convert(house, ReadContext(src, f"{where}, "), f"{stem}_{index}", table, float(wall_thickness))
        except UnicodeDecodeError as e:
            raise SceneError(p, None, f"not a text JSONL file ({e.reason})") from e
        except (OSError, EOFError, zlib.error) as e:
            raise SceneError(p, None, f"cannot read: {e}") from e
        return
    try:
        with opener(p, "rt", encoding="utf-8") as f:
            doc = json.load(f)
    except UnicodeDecodeError as e:
        raise SceneError(p, None, f"not a text JSON file ({e.reason})") from e
    except json.JSONDecodeError as e:
        raise SceneError(p, f"line {e.lineno}, column {e.colno}", f"invalid JSON: {e.msg}") from e
    except (OSError, EOFError, zlib.error) as e:
        raise SceneError(p, None, f"cannot read: {e}") from e
    if isinstance(doc, list):
        if not doc:
            raise SceneError(p, None, "the file holds an empty list of houses")
        for i, house in enumerate(doc):
            yield _convert(house, ReadContext(src, f"[{i}]."), f"{stem}_{i}", table, float(wall_thickness))
        return
    yield _convert(doc, ReadContext(src), stem, table, float(wall_thickness))


def load_procthor(path: str | os.PathLike, *, assets: Mapping[str, AssetInfo] | str | os.PathLike | None = None,
                  wall_thickness: float = WALL_THICKNESS) -> list[Scene]:
    """Read ProcTHOR houses from a file.

    Accepted files:

    * ``.json`` / ``.json.gz`` holding one house (scene id = file stem) or
      a JSON list of houses (ids ``<stem>_<index>``);
    * ``.jsonl`` / ``.jsonl.gz`` with one house per line as in ProcTHOR-10K
      (ids ``<stem>_<line index>``, counting lines from 0 as the dataset
      does; blank lines are skipped; errors name the 1-based ``line N``).

    Args:
        path: the file.
        assets: asset table (mapping or path); the shipped table when None.
        wall_thickness: thickness of the imported walls, metres.

    Returns:
        The scenes, in file order.

    Raises:
        SceneError: the file is missing, not (gzipped) JSON, or a house in
            it is invalid; the message names file, place and reason.
    """
    return list(iter_procthor(path, assets=assets, wall_thickness=wall_thickness))
