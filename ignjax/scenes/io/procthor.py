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

The asset table and its command line are in :mod:`ignjax.scenes.io.procthor_assets`.
"""

from __future__ import annotations

import gzip
import json
import math
import os
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Mapping, Sequence

import numpy as np

from ignjax.errors import SceneError
from ignjax.scenes import vocab
from ignjax.scenes.io.procthor_assets import AssetInfo, resolve_assets
from ignjax.scenes.model import Attributes, Door, Geom, Instance, OrientedBox, Room, Scene, SceneMeta, Wall, room_containing
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

_WINDOW_RGBA = (0.62, 0.78, 0.90, 1.0)
_DOOR_RGBA = (0.55, 0.40, 0.25, 1.0)
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
# Frame conversion
# ---------------------------------------------------------------------------


def unity_to_world(point) -> np.ndarray:
    """Unity (x, y, z), Y-up left-handed -> ours (x, z, y), Z-up right-handed.

    Works on any array (..., 3).
    """
    p = np.asarray(point, dtype=np.float64)
    return p[..., [0, 2, 1]]


def _clean(v: float) -> float:
    """Round to a nanometre so that float noise (-1e-17) does not leak out."""
    return round(float(v), 9) + 0.0


def _wrap(angle: float) -> float:
    a = math.remainder(angle, 2.0 * math.pi)
    return math.pi if a == -math.pi else a


def unity_yaw(rotation_y_degrees: float) -> float:
    """Our heading (radians, CCW from +x) of a ProcTHOR asset turned by
    ``rotation.y`` degrees about Unity's up axis: ``pi/2 - radians(y)``.

    The asset's forward axis (Unity ``+z``) is the direction the result
    points along; see the module docstring for the derivation.
    """
    return _wrap(math.pi / 2.0 - math.radians(rotation_y_degrees))


def _unity_rotation(rx: float, ry: float, rz: float) -> np.ndarray:
    """Unity's Euler rotation (degrees, applied Z then X then Y) as a matrix
    acting on Unity column vectors."""
    x, y, z = (math.radians(v) for v in (rx, ry, rz))
    cx, sx, cy, sy, cz, sz = math.cos(x), math.sin(x), math.cos(y), math.sin(y), math.cos(z), math.sin(z)
    mx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    my = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    mz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return my @ mx @ mz


_CORNER_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)


def _upright_box(center_u: np.ndarray, size_u: Sequence[float], rot_u: Sequence[float]) -> tuple[OrientedBox, float]:
    """Upright box (ours) of an asset box centred at ``center_u`` (Unity)."""
    rx, ry, rz = rot_u
    yaw = unity_yaw(ry)
    half = 0.5 * np.asarray(size_u, dtype=np.float64)
    if abs(math.remainder(rx, 360.0)) < 1e-6 and abs(math.remainder(rz, 360.0)) < 1e-6:
        c = unity_to_world(center_u)
        return OrientedBox(tuple(c), (half[2], half[0], half[1]), yaw), yaw
    corners_u = center_u + (_CORNER_SIGNS * half) @ _unity_rotation(rx, ry, rz).T
    corners = unity_to_world(corners_u)
    u = np.array([math.cos(yaw), math.sin(yaw)])
    v = np.array([-math.sin(yaw), math.cos(yaw)])
    c0 = unity_to_world(center_u)
    d = corners[:, :2] - c0[:2]
    pu, pv = d @ u, d @ v
    cu, cv = 0.5 * (pu.max() + pu.min()), 0.5 * (pv.max() + pv.min())
    cxy = c0[:2] + cu * u + cv * v
    zlo, zhi = corners[:, 2].min(), corners[:, 2].max()
    box = OrientedBox((cxy[0], cxy[1], 0.5 * (zlo + zhi)),
                      (0.5 * (pu.max() - pu.min()), 0.5 * (pv.max() - pv.min()), 0.5 * (zhi - zlo)), yaw)
    return box, yaw


# ---------------------------------------------------------------------------
# Parsing helpers
# ---------------------------------------------------------------------------


class _Ctx:
    """Where errors point: the file and a prefix (``line 7, `` for JSONL)."""

    def __init__(self, source: str, prefix: str = ""):
        self.source = source
        self.prefix = prefix

    def err(self, where: str, reason: str) -> SceneError:
        return SceneError(self.source, f"{self.prefix}{where}" if where else (self.prefix.rstrip(", .") or None), reason)

    def num(self, value, where: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.err(where, f"expected a number, got {value!r}")
        v = float(value)
        if not math.isfinite(v):
            raise self.err(where, f"expected a finite number, got {value!r}")
        return v

    def obj(self, value, where: str) -> dict:
        if not isinstance(value, dict):
            raise self.err(where, f"expected a JSON object, got {type(value).__name__}")
        return value

    def lst(self, value, where: str) -> list:
        if not isinstance(value, list):
            raise self.err(where, f"expected a list, got {type(value).__name__}")
        return value

    def xyz(self, value, where: str, keys: str = "xyz", default: float | None = None) -> tuple[float, ...]:
        d = self.obj(value, where)
        out = []
        for k in keys:
            if k not in d:
                if default is None:
                    raise self.err(f"{where}.{k}", "missing")
                out.append(default)
            else:
                out.append(self.num(d[k], f"{where}.{k}"))
        return tuple(out)

    def ident(self, value, where: str) -> str:
        if isinstance(value, bool) or not isinstance(value, (str, int)) or value == "":
            raise self.err(where, f"expected a non-empty string id, got {value!r}")
        return str(value)


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


@dataclass
class _WallGroup:
    """One physical wall segment (all ProcTHOR copies of it)."""

    id: str
    start: np.ndarray
    end: np.ndarray
    bottom: float
    top: float
    rooms: list[str]
    empty: bool
    holes: list[tuple[float, float, float]]  # (t0, t1, top) along start->end

    @property
    def length(self) -> float:
        return float(np.hypot(*(self.end - self.start)))

    @property
    def direction(self) -> np.ndarray:
        return (self.end - self.start) / max(self.length, 1e-12)


def _parse_rooms(house: dict, ctx: _Ctx) -> list[Room]:
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


def _is_exterior_wall(wall_id: str | None, wall: dict | None) -> bool:
    if wall_id is None:
        return True
    if wall_id.startswith("wall|exterior"):
        return True
    return wall is not None and wall.get("roomId") == "exterior"


def _parse_walls(house: dict, ctx: _Ctx, room_ids: set[str]):
    walls_raw = house.get("walls", [])
    walls_raw = ctx.lst(walls_raw if walls_raw is not None else [], "walls")
    groups: dict[tuple, _WallGroup] = {}
    by_id: dict[str, tuple[tuple, dict, np.ndarray, np.ndarray]] = {}
    for i, wraw in enumerate(walls_raw):
        w = f"walls[{i}]"
        ctx.obj(wraw, w)
        wid = ctx.ident(wraw.get("id"), f"{w}.id")
        poly = ctx.lst(wraw.get("polygon"), f"{w}.polygon")
        pts = [ctx.xyz(p, f"{w}.polygon[{j}]") for j, p in enumerate(poly)]
        if len(pts) < 3:
            raise ctx.err(f"{w}.polygon", f"a wall polygon needs at least 3 points, got {len(pts)}")
        feet: list[tuple[float, float]] = []
        for x, _, z in pts:
            if not any(abs(x - a) <= 1e-6 and abs(z - b) <= 1e-6 for a, b in feet):
                feet.append((x, z))
        if len(feet) != 2:
            raise ctx.err(f"{w}.polygon", f"expected a vertical rectangle over a floor segment (2 distinct x/z "
                                          f"positions), got {len(feet)}")
        ys = [p[1] for p in pts]
        bottom, top = min(ys), max(ys)
        if top - bottom <= 1e-6:
            raise ctx.err(f"{w}.polygon", "the wall has zero height")
        start, end = np.array(feet[0]), np.array(feet[1])
        key = tuple(sorted((round(x, 3), round(z, 3)) for x, z in feet))
        room = wraw.get("roomId")
        exterior = _is_exterior_wall(wid, wraw)
        g = groups.get(key)
        if g is None:
            g = groups[key] = _WallGroup(wid, start, end, bottom, top, [], bool(wraw.get("empty", False)), [])
        else:
            g.empty = g.empty and bool(wraw.get("empty", False))
            g.bottom, g.top = min(g.bottom, bottom), max(g.top, top)
            if g.id.startswith("wall|exterior") and not exterior:
                g.id = wid
        if not exterior and isinstance(room, str) and room in room_ids and room not in g.rooms:
            g.rooms.append(room)
        if wid in by_id:
            raise ctx.err(f"{w}.id", f"duplicate wall id {wid!r}")
        by_id[wid] = (key, wraw, start, end)
    # Exterior walls of the older schema carry the room id; keep rooms of
    # walls seen only as exterior copies.
    for wid, (key, wraw, _, _) in by_id.items():
        room = wraw.get("roomId")
        if not groups[key].rooms and isinstance(room, str) and room in room_ids:
            groups[key].rooms.append(room)
    return groups, by_id


def _hole(ctx: _Ctx, d: dict, where: str) -> tuple[float, float, float, float]:
    """(x0, x1, y0, y1) of a door/window hole in its wall0's frame."""
    if "holePolygon" in d:
        pts = ctx.lst(d["holePolygon"], f"{where}.holePolygon")
        if len(pts) < 2:
            raise ctx.err(f"{where}.holePolygon", f"expected two corner points, got {len(pts)}")
        xy = [ctx.xyz(p, f"{where}.holePolygon[{j}]", "xy") for j, p in enumerate(pts)]
        if "assetPosition" in d:
            ctx.xyz(d["assetPosition"], f"{where}.assetPosition", default=0.0)
    elif "boundingBox" in d:
        bb = ctx.obj(d["boundingBox"], f"{where}.boundingBox")
        xy = [ctx.xyz(bb.get("min"), f"{where}.boundingBox.min", "xy"),
              ctx.xyz(bb.get("max"), f"{where}.boundingBox.max", "xy")]
        if "assetOffset" in d:
            ctx.xyz(d["assetOffset"], f"{where}.assetOffset", default=0.0)
    else:
        raise ctx.err(where, "has neither holePolygon (schema 1.0.0) nor boundingBox (schema 0.0.1)")
    xs, ys = [p[0] for p in xy], [p[1] for p in xy]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    if x1 - x0 <= 1e-6:
        raise ctx.err(where, f"the hole has zero width ({x0} to {x1})")
    if y1 - y0 <= 1e-6:
        raise ctx.err(where, f"the hole has zero height ({y0} to {y1})")
    return x0, x1, y0, y1


def _place_hole(ctx: _Ctx, where: str, by_id, groups, wall0: str, x0: float, x1: float):
    """Resolve a hole on ``wall0``: (group, t0, t1 along the group, centre xy, room of wall0)."""
    if wall0 not in by_id:
        raise ctx.err(f"{where}.wall0", f"refers to unknown wall {wall0!r}")
    key, wraw, s, e = by_id[wall0]
    g = groups[key]
    length = float(np.hypot(*(e - s)))
    tol = 1e-3
    if x0 < -tol or x1 > length + tol:
        raise ctx.err(where, f"the hole ({x0:.3f} to {x1:.3f} m) extends past wall {wall0!r} ({length:.3f} m long)")
    x0, x1 = max(x0, 0.0), min(x1, length)
    d = (e - s) / max(length, 1e-12)
    centre = s + d * 0.5 * (x0 + x1)
    same = np.allclose(s, g.start, atol=1e-3)
    t0, t1 = (x0, x1) if same else (g.length - x1, g.length - x0)
    return g, t0, t1, centre, wraw.get("roomId")


def _cut_walls(groups: dict[tuple, _WallGroup], thickness: float) -> list[Wall]:
    walls: list[Wall] = []
    for g in groups.values():
        if g.empty:
            continue
        height = g.top - g.bottom
        rooms = tuple(g.rooms)
        if not g.holes:
            walls.append(Wall(g.id, tuple(g.start), tuple(g.end), thickness, height, g.bottom, rooms))
            continue
        holes = sorted(g.holes)
        merged: list[list[float]] = []
        for t0, t1, top in holes:
            if merged and t0 <= merged[-1][1] + 1e-9:
                merged[-1][1] = max(merged[-1][1], t1)
                merged[-1][2] = max(merged[-1][2], top)
            else:
                merged.append([t0, t1, top])
        d = g.direction

        def at(t: float) -> tuple[float, float]:
            p = g.start + d * t
            return float(p[0]), float(p[1])

        cursor, k = 0.0, 0
        for t0, t1, top in merged:
            if t0 - cursor > 1e-4:
                walls.append(Wall(f"{g.id}#{k}", at(cursor), at(t0), thickness, height, g.bottom, rooms))
                k += 1
            if g.top - top > 1e-4:
                walls.append(Wall(f"{g.id}#{k}", at(t0), at(t1), thickness, g.top - top, top, rooms))
                k += 1
            cursor = max(cursor, t1)
        if g.length - cursor > 1e-4:
            walls.append(Wall(f"{g.id}#{k}", at(cursor), at(g.length), thickness, height, g.bottom, rooms))
    return walls


def _inward_yaw(rooms_by_id: Mapping[str, Room], room: str | None, centre: np.ndarray, d: np.ndarray) -> float:
    """Heading perpendicular to a wall (direction ``d``) pointing into ``room``."""
    n = np.array([-d[1], d[0]])
    r = rooms_by_id.get(room) if room else None
    if r is not None and not bool(r.contains((centre + 0.05 * n)[None])[0]) and bool(r.contains((centre - 0.05 * n)[None])[0]):
        n = -n
    return math.atan2(n[1], n[0])


def _wall_instance(iid: str, category: str, centre: np.ndarray, yaw: float, width: float, y0: float, y1: float,
                   depth: float, room: str | None, name: str, rgba) -> Instance:
    half = (0.5 * depth, 0.5 * width, 0.5 * (y1 - y0))
    box = OrientedBox((float(centre[0]), float(centre[1]), 0.5 * (y0 + y1)), half, yaw)
    geom = Geom("box", half, (0.0, 0.0, half[2]), rgba=rgba, part=category)
    return Instance(iid, category, (float(centre[0]), float(centre[1]), y0), yaw, box, room=room,
                    structural=True, geoms=(geom,), name=name)


def _parse_objects(house: dict, ctx: _Ctx, assets: Mapping[str, AssetInfo], rooms: list[Room]) -> list[Instance]:
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
        box, yaw = _upright_box(pos, info.size, rot)
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


def _convert(house: Any, ctx: _Ctx, scene_id: str, assets: Mapping[str, AssetInfo], wall_thickness: float) -> Scene:
    if not isinstance(house, dict):
        raise ctx.err("", f"a ProcTHOR house must be a JSON object, got {type(house).__name__}")
    meta = house.get("metadata") if isinstance(house.get("metadata"), dict) else {}
    schema = meta.get("schema") if isinstance(meta.get("schema"), str) else None
    rooms = _parse_rooms(house, ctx)
    rooms_by_id = {r.id: r for r in rooms}
    groups, by_id = _parse_walls(house, ctx, set(rooms_by_id))

    doors: list[Door] = []
    structural: list[Instance] = []
    for i, d in enumerate(ctx.lst(house.get("doors") or [], "doors")):
        w = f"doors[{i}]"
        ctx.obj(d, w)
        did = ctx.ident(d.get("id"), f"{w}.id")
        wall0 = ctx.ident(d.get("wall0"), f"{w}.wall0")
        wall1 = d.get("wall1")
        x0, x1, y0, y1 = _hole(ctx, d, w)
        g, t0, t1, centre, room0 = _place_hole(ctx, w, by_id, groups, wall0, x0, x1)
        if room0 not in rooms_by_id:
            room0 = d.get("room0") if d.get("room0") in rooms_by_id else (g.rooms[0] if g.rooms else None)
        if room0 is None:
            raise ctx.err(f"{w}.wall0", f"cannot tell which room door {did!r} belongs to")
        w1raw = by_id[wall1][1] if isinstance(wall1, str) and wall1 in by_id else None
        room1 = None
        if not _is_exterior_wall(wall1 if isinstance(wall1, str) else None, w1raw):
            cand = (w1raw or {}).get("roomId", d.get("room1"))
            room1 = cand if cand in rooms_by_id and cand != room0 else None
        asset = d.get("assetId") if isinstance(d.get("assetId"), str) else ""
        openness = d.get("openness", 1)
        openness = ctx.num(openness, f"{w}.openness") if openness is not None else 1.0
        yaw = math.atan2(g.direction[1], g.direction[0])
        if room1 is None and openness <= 0:
            structural.append(_wall_instance(did, "door", centre, _inward_yaw(rooms_by_id, room0, centre, g.direction),
                                             x1 - x0, 0.0, y1, wall_thickness + 0.02, room0, asset, _DOOR_RGBA))
            continue
        g.holes.append((t0, t1, y1))
        info = assets.get(asset)
        frame = info.object_type == "Doorframe" if info is not None else "doorframe" in asset.lower()
        kind = "opening" if frame else "door"
        doors.append(Door(did, (float(centre[0]), float(centre[1])), x1 - x0, yaw, (room0, room1), y1, kind))

    for i, wd in enumerate(ctx.lst(house.get("windows") or [], "windows")):
        w = f"windows[{i}]"
        ctx.obj(wd, w)
        wid = ctx.ident(wd.get("id"), f"{w}.id")
        wall0 = ctx.ident(wd.get("wall0"), f"{w}.wall0")
        x0, x1, y0, y1 = _hole(ctx, wd, w)
        g, _, _, centre, room0 = _place_hole(ctx, w, by_id, groups, wall0, x0, x1)
        if room0 not in rooms_by_id:
            room0 = wd.get("room0") if wd.get("room0") in rooms_by_id else (g.rooms[0] if g.rooms else None)
        asset = wd.get("assetId") if isinstance(wd.get("assetId"), str) else ""
        info = assets.get(asset)
        depth = max(wall_thickness + 0.02, info.size[2] if info is not None else 0.0)
        structural.append(_wall_instance(wid, "window", centre, _inward_yaw(rooms_by_id, room0, centre, g.direction),
                                         x1 - x0, y0, y1, depth, room0, asset, _WINDOW_RGBA))

    for g in groups.values():
        if not g.empty:
            continue
        a = g.rooms[0] if g.rooms else None
        if a is None:
            continue
        b = g.rooms[1] if len(g.rooms) > 1 else None
        mid = 0.5 * (g.start + g.end)
        doors.append(Door(f"opening|{g.id}", (float(mid[0]), float(mid[1])), g.length,
                          math.atan2(g.direction[1], g.direction[0]), (a, b), g.top - g.bottom, "opening"))

    walls = _cut_walls(groups, wall_thickness)
    instances = _parse_objects(house, ctx, assets, rooms) + structural
    wall_height = max((g.top for g in groups.values()), default=2.5)
    params = json.dumps({"schema": schema, "wall_thickness": wall_thickness}, sort_keys=True)
    scene = Scene(scene_id, tuple(rooms), tuple(doors), tuple(walls), tuple(instances),
                  SceneMeta(source=ctx.source, source_format="procthor", up_axis="Y", meters_per_unit=1.0, params=params),
                  wall_height=wall_height)
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
    return _convert(house, _Ctx(str(source)), scene_id, resolve_assets(assets), float(wall_thickness))


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
                    yield _convert(house, _Ctx(src, f"{where}, "), f"{stem}_{index}", table, float(wall_thickness))
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
            yield _convert(house, _Ctx(src, f"[{i}]."), f"{stem}_{i}", table, float(wall_thickness))
        return
    yield _convert(doc, _Ctx(src), stem, table, float(wall_thickness))


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
