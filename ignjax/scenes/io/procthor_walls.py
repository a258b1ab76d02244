"""The walls of a ProcTHOR house and the holes in them, for the importer
(:mod:`ignjax.scenes.io.procthor`, whose docstring gives the rules): the
per-room copies of a wall merged into one segment, doors and windows placed
along their ``wall0``, doors cut out of their walls (with a lintel above),
closed exterior doors and windows as structural instances, open-plan
boundaries as openings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ignjax.scenes.io.procthor_assets import AssetInfo
from ignjax.scenes.io.procthor_fields import ReadContext
from ignjax.scenes.model import Door, Geom, Instance, OrientedBox, Room, Wall

__all__ = ["Building", "read_building"]

_WINDOW_RGBA = (0.62, 0.78, 0.90, 1.0)
_DOOR_RGBA = (0.55, 0.40, 0.25, 1.0)


@dataclass(frozen=True)
class Building:
    """What :func:`read_building` reads from a house.

    Attributes:
        walls: the wall segments, doors cut out.
        doors: doors between rooms or to the outside, then open-plan openings.
        instances: structural ``door`` (closed exterior doors) and ``window`` instances.
        wall_height: the top of the tallest wall (2.5 m when there are none).
    """

    walls: list[Wall]
    doors: list[Door]
    instances: list[Instance]
    wall_height: float


def read_building(house: dict, ctx: ReadContext, rooms_by_id: Mapping[str, Room], assets: Mapping[str, AssetInfo],
                  wall_thickness: float) -> Building:
    """The walls, doors and windows of ``house`` (rooms already read), walls
    ``wall_thickness`` thick; raises :class:`SceneError` naming the field."""
    groups, by_id = _parse_walls(house, ctx, set(rooms_by_id))
    doors, structural = _cut_doors(house, ctx, rooms_by_id, groups, by_id, assets, wall_thickness)
    structural += _windows(house, ctx, rooms_by_id, groups, by_id, assets, wall_thickness)
    doors += _openings(groups)
    wall_height = max((g.top for g in groups.values()), default=2.5)
    return Building(_cut_walls(groups, wall_thickness), doors, structural, wall_height)


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


def _is_exterior_wall(wall_id: str | None, wall: dict | None) -> bool:
    if wall_id is None:
        return True
    if wall_id.startswith("wall|exterior"):
        return True
    return wall is not None and wall.get("roomId") == "exterior"


def _parse_walls(house: dict, ctx: ReadContext, room_ids: set[str]):
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


def _hole(ctx: ReadContext, d: dict, where: str) -> tuple[float, float, float, float]:
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


def _place_hole(ctx: ReadContext, where: str, by_id, groups, wall0: str, x0: float, x1: float):
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


def _read_hole(ctx: ReadContext, item: dict, where: str, rooms_by_id: Mapping[str, Room],
               groups: dict[tuple, _WallGroup], by_id):
    """A door's or window's id and its hole on its ``wall0``: (id, (x0, x1,
    y0, y1) as given, group, t0, t1 along the group, centre xy, room). The
    room is ``wall0``'s, else the item's ``room0``, else the group's first
    room, else None."""
    ctx.obj(item, where)
    iid = ctx.ident(item.get("id"), f"{where}.id")
    wall0 = ctx.ident(item.get("wall0"), f"{where}.wall0")
    x0, x1, y0, y1 = _hole(ctx, item, where)
    g, t0, t1, centre, room0 = _place_hole(ctx, where, by_id, groups, wall0, x0, x1)
    if room0 not in rooms_by_id:
        room0 = item.get("room0") if item.get("room0") in rooms_by_id else (g.rooms[0] if g.rooms else None)
    return iid, (x0, x1, y0, y1), g, t0, t1, centre, room0


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


def _cut_doors(house: dict, ctx: ReadContext, rooms_by_id: Mapping[str, Room], groups: dict[tuple, _WallGroup], by_id,
               assets: Mapping[str, AssetInfo], wall_thickness: float) -> tuple[list[Door], list[Instance]]:
    """Doors cut out of their walls (each a hole in its wall group), and
    closed exterior doors as structural instances in a solid wall."""
    doors: list[Door] = []
    structural: list[Instance] = []
    for i, d in enumerate(ctx.lst(house.get("doors") or [], "doors")):
        w = f"doors[{i}]"
        did, (x0, x1, y0, y1), g, t0, t1, centre, room0 = _read_hole(ctx, d, w, rooms_by_id, groups, by_id)
        wall1 = d.get("wall1")
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
    return doors, structural


def _windows(house: dict, ctx: ReadContext, rooms_by_id: Mapping[str, Room], groups: dict[tuple, _WallGroup], by_id,
             assets: Mapping[str, AssetInfo], wall_thickness: float) -> list[Instance]:
    """Windows as structural instances in their (solid) walls."""
    structural: list[Instance] = []
    for i, wd in enumerate(ctx.lst(house.get("windows") or [], "windows")):
        wid, (x0, x1, y0, y1), g, _, _, centre, room0 = _read_hole(ctx, wd, f"windows[{i}]", rooms_by_id, groups, by_id)
        asset = wd.get("assetId") if isinstance(wd.get("assetId"), str) else ""
        info = assets.get(asset)
        depth = max(wall_thickness + 0.02, info.size[2] if info is not None else 0.0)
        structural.append(_wall_instance(wid, "window", centre, _inward_yaw(rooms_by_id, room0, centre, g.direction),
                                         x1 - x0, y0, y1, depth, room0, asset, _WINDOW_RGBA))
    return structural


def _openings(groups: dict[tuple, _WallGroup]) -> list[Door]:
    """An ``opening`` door as wide as each empty (open-plan) wall, so its rooms stay connected."""
    doors: list[Door] = []
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
    return doors
