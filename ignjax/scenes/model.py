"""The host-side scene model.

A :class:`Scene` is what every scene source (procedural houses, USD stages,
ProcTHOR houses, glTF/OBJ meshes) is turned into, and what compilation to
MuJoCo/MJX, navigation grids and episode construction read. It is plain,
immutable Python data (frozen dataclasses of tuples and floats, numpy arrays
only for mesh buffers), so it can be hashed, compared, serialised to JSON and
written to USD without loss.

Frame and units (everywhere): right-handed, Z up, metres, floor at z = 0.
Yaw is a rotation about +Z, radians, counter-clockwise from +X.

Objects
    An :class:`Instance` is one object: its category, structured
    :class:`Attributes`, base pose (``position`` is the centre of the
    object's footprint at the height of its lowest point, ``yaw`` its
    heading), an upright oriented bounding box in world coordinates, the room
    it stands in, the instance it stands on (``support``) and its geometry as
    a tuple of :class:`Geom` in the instance's local frame (origin at
    ``position``, x axis along ``yaw``).

Building
    :class:`Room` (normalised label, floor polygon), :class:`Door` (an opening
    in a wall between two rooms, or to the outside) and :class:`Wall`
    (a straight box segment; gaps for doors are already cut, a lintel over a
    door is a wall with ``bottom > 0``). Imported stages whose walls are
    meshes keep them as structural instances instead.

The room-object graph is derived, see :mod:`ignjax.scenes.graph`.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from typing import Any, Iterable, Sequence

import numpy as np

from ignjax.errors import SceneError
from ignjax.scenes import vocab

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

GEOM_KINDS: tuple[str, ...] = ("box", "cylinder", "sphere", "capsule", "ellipsoid", "mesh")
"""Geometry kinds. Sizes follow MuJoCo: box half-sizes (x, y, z); cylinder and
capsule (radius, half-length, unused); sphere (radius, unused, unused);
ellipsoid semi-axes (x, y, z); mesh (1, 1, 1)."""


def _t(values, n: int | None = None) -> tuple[float, ...]:
    out = tuple(float(v) for v in values)
    if n is not None and len(out) != n:
        raise ValueError(f"expected {n} numbers, got {len(out)}")
    return out


@dataclass(frozen=True, eq=False)
class MeshData:
    """A triangle mesh. ``vertices``: (V, 3) float64 metres; ``faces``: (F, 3) int32."""

    vertices: np.ndarray
    faces: np.ndarray

    def __post_init__(self):
        v = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        f = np.ascontiguousarray(self.faces, dtype=np.int32).reshape(-1, 3)
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, MeshData)
            and self.vertices.shape == other.vertices.shape
            and self.faces.shape == other.faces.shape
            and bool(np.array_equal(self.vertices, other.vertices))
            and bool(np.array_equal(self.faces, other.faces))
        )

    def __hash__(self) -> int:
        return hash((self.vertices.shape, self.faces.shape, self.vertices.tobytes()[:256]))


@dataclass(frozen=True)
class Geom:
    """One geometric part of an instance, in the instance's local frame.

    Attributes:
        kind: one of :data:`GEOM_KINDS`.
        size: MuJoCo size triple (see :data:`GEOM_KINDS`).
        pos: (3,) centre in the instance frame, metres.
        quat: (4,) orientation in the instance frame, (w, x, y, z).
        rgba: (4,) colour in 0..1.
        part: what the part is ("seat", "leg", "screen"); free text.
        material: material class from :data:`vocab.MATERIALS` or None; used
            for rendering (specular, shininess).
        mesh: the mesh for ``kind == "mesh"`` (vertices in the geom frame).
    """

    kind: str
    size: Vec3
    pos: Vec3 = (0.0, 0.0, 0.0)
    quat: Quat = (1.0, 0.0, 0.0, 0.0)
    rgba: tuple[float, float, float, float] = (0.7, 0.7, 0.7, 1.0)
    part: str = ""
    material: str | None = None
    mesh: MeshData | None = None

    def __post_init__(self):
        object.__setattr__(self, "size", _t(self.size, 3))
        object.__setattr__(self, "pos", _t(self.pos, 3))
        object.__setattr__(self, "quat", _t(self.quat, 4))
        object.__setattr__(self, "rgba", _t(self.rgba, 4))


@dataclass(frozen=True)
class Attributes:
    """Structured appearance attributes (closed vocabularies in :mod:`vocab`).

    Attributes:
        color: dominant colour name, or None when unknown.
        material: dominant material, or None.
        size: size class ``small``/``medium``/``large``, or None.
        state: ``open``/``closed``/``on``/``off``/``full``/``empty``/
            ``made``/``unmade``, or None when the category has no state.
    """

    color: str | None = None
    material: str | None = None
    size: str | None = None
    state: str | None = None

    def as_dict(self) -> dict[str, str | None]:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class OrientedBox:
    """An upright oriented bounding box.

    Attributes:
        center: (3,) world centre, metres.
        half_extents: (3,) half sizes along the box's own x, y and world z.
        yaw: rotation of the box's x axis about +Z, radians.
    """

    center: Vec3
    half_extents: Vec3
    yaw: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "center", _t(self.center, 3))
        object.__setattr__(self, "half_extents", _t(self.half_extents, 3))
        object.__setattr__(self, "yaw", float(self.yaw))

    def footprint(self) -> np.ndarray:
        """(4, 2) corners of the box's floor footprint, counter-clockwise."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        hx, hy = self.half_extents[0], self.half_extents[1]
        local = np.array([[hx, hy], [-hx, hy], [-hx, -hy], [hx, -hy]])
        rot = np.array([[c, -s], [s, c]])
        return local @ rot.T + np.array(self.center[:2])

    @property
    def zmin(self) -> float:
        return self.center[2] - self.half_extents[2]

    @property
    def zmax(self) -> float:
        return self.center[2] + self.half_extents[2]

    def distance_xy(self, points) -> np.ndarray:
        """2-D distance from points (..., 2) to the footprint (0 inside)."""
        p = np.asarray(points, dtype=np.float64)
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        d = p - np.asarray(self.center[:2])
        lx = d[..., 0] * c + d[..., 1] * s
        ly = -d[..., 0] * s + d[..., 1] * c
        ex = np.maximum(np.abs(lx) - self.half_extents[0], 0.0)
        ey = np.maximum(np.abs(ly) - self.half_extents[1], 0.0)
        return np.hypot(ex, ey)


@dataclass(frozen=True)
class Instance:
    """One object instance.

    Attributes:
        id: unique within the scene, stable across export/import.
        category: canonical category (:func:`vocab.normalize_category`).
        position: (3,) footprint centre at the object's lowest point, world.
        yaw: heading about +Z, radians.
        bbox: upright oriented bounding box in world coordinates.
        room: id of the room the object is in, or None (outside all rooms).
        attributes: colour, material, size class and state.
        support: id of the instance this one stands on, or None (floor/wall).
        structural: True for walls, floors, doors, windows, ceiling lights.
        geoms: geometry in the instance frame; may be empty for imported
            objects known only by their box (then the box is the geometry).
        name: the source's own name for it (prim path, asset id, node name).
    """

    id: str
    category: str
    position: Vec3
    yaw: float
    bbox: OrientedBox
    room: str | None = None
    attributes: Attributes = field(default_factory=Attributes)
    support: str | None = None
    structural: bool = False
    geoms: tuple[Geom, ...] = ()
    name: str = ""

    def __post_init__(self):
        object.__setattr__(self, "position", _t(self.position, 3))
        object.__setattr__(self, "yaw", float(self.yaw))
        object.__setattr__(self, "geoms", tuple(self.geoms))


@dataclass(frozen=True)
class Room:
    """A room.

    Attributes:
        id: unique within the scene.
        label: normalised label from :data:`vocab.ALL_ROOM_LABELS`.
        polygon: floor polygon, counter-clockwise, not closed, metres.
        name: the source's own label ("LivingRoom", "Bedroom 2").
    """

    id: str
    label: str
    polygon: tuple[Vec2, ...]
    name: str = ""

    def __post_init__(self):
        poly = tuple(_t(p, 2) for p in self.polygon)
        if len(poly) >= 3 and polygon_area(poly) < 0:
            poly = tuple(reversed(poly))
        object.__setattr__(self, "polygon", poly)

    @property
    def area(self) -> float:
        return abs(polygon_area(self.polygon))

    @property
    def centroid(self) -> Vec2:
        return polygon_centroid(self.polygon)

    def contains(self, points) -> np.ndarray:
        """Boolean mask of the points (..., 2) inside the floor polygon."""
        return points_in_polygon(points, self.polygon)


@dataclass(frozen=True)
class Door:
    """An opening between two rooms (or a room and the outside).

    Attributes:
        id: unique within the scene.
        position: (2,) centre of the opening on the wall line, metres.
        width: clear width, metres.
        yaw: direction of the wall line the door sits in, radians; one
            passes through the door along ``yaw + pi/2``.
        rooms: the two room ids; the second is None for an exterior door.
        height: clear height, metres.
        kind: ``"door"`` (a doorway) or ``"opening"`` (a wall gap).
    """

    id: str
    position: Vec2
    width: float
    yaw: float
    rooms: tuple[str, str | None]
    height: float = 2.1
    kind: str = "door"

    def __post_init__(self):
        object.__setattr__(self, "position", _t(self.position, 2))
        object.__setattr__(self, "width", float(self.width))
        object.__setattr__(self, "yaw", float(self.yaw))
        object.__setattr__(self, "height", float(self.height))
        object.__setattr__(self, "rooms", tuple(self.rooms))


@dataclass(frozen=True)
class Wall:
    """A straight wall segment (a box from ``bottom`` to ``bottom + height``).

    Attributes:
        id: unique within the scene.
        start, end: (2,) end points of the centre line, metres.
        thickness: metres.
        height: metres.
        bottom: height of the segment's underside (0, or a door's height for
            the lintel above it).
        rooms: ids of the rooms the wall bounds (one or two).
    """

    id: str
    start: Vec2
    end: Vec2
    thickness: float = 0.1
    height: float = 2.5
    bottom: float = 0.0
    rooms: tuple[str, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "start", _t(self.start, 2))
        object.__setattr__(self, "end", _t(self.end, 2))
        for name in ("thickness", "height", "bottom"):
            object.__setattr__(self, name, float(getattr(self, name)))
        object.__setattr__(self, "rooms", tuple(self.rooms))

    @property
    def length(self) -> float:
        return math.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1])


@dataclass(frozen=True)
class SceneMeta:
    """Where a scene came from.

    Attributes:
        source: the file it was read from, or ``"procgen"``.
        source_format: ``procgen`` | ``usd`` | ``procthor`` | ``mesh`` | ``json``.
        up_axis: the source's up axis before conversion (``"Z"`` or ``"Y"``).
        meters_per_unit: the source's unit scale before conversion.
        seed: generator seed for procedural houses, else None.
        params: generator parameters or importer options, as JSON text.
    """

    source: str = ""
    source_format: str = "procgen"
    up_axis: str = "Z"
    meters_per_unit: float = 1.0
    seed: int | None = None
    params: str = "{}"


@dataclass(frozen=True)
class Scene:
    """A whole indoor scene. See the module docstring for frames and units."""

    id: str
    rooms: tuple[Room, ...]
    doors: tuple[Door, ...] = ()
    walls: tuple[Wall, ...] = ()
    instances: tuple[Instance, ...] = ()
    meta: SceneMeta = field(default_factory=SceneMeta)
    wall_height: float = 2.5

    def __post_init__(self):
        for name in ("rooms", "doors", "walls", "instances"):
            object.__setattr__(self, name, tuple(getattr(self, name)))

    # -- lookups --------------------------------------------------------------
    def room(self, room_id: str) -> Room:
        for r in self.rooms:
            if r.id == room_id:
                return r
        raise KeyError(f"scene {self.id!r} has no room {room_id!r}")

    def instance(self, instance_id: str) -> Instance:
        for inst in self.instances:
            if inst.id == instance_id:
                return inst
        raise KeyError(f"scene {self.id!r} has no instance {instance_id!r}")

    @property
    def objects(self) -> tuple[Instance, ...]:
        """Non-structural instances."""
        return tuple(i for i in self.instances if not i.structural)

    def categories(self) -> dict[str, int]:
        """Instance count per category, non-structural instances only."""
        out: dict[str, int] = {}
        for inst in self.objects:
            out[inst.category] = out.get(inst.category, 0) + 1
        return dict(sorted(out.items()))

    def room_at(self, xy, snap: float = 0.0) -> str | None:
        """Id of the room containing point ``xy`` (see :func:`room_containing`)."""
        return room_containing(self.rooms, xy, snap)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) of the scene in x, y, z over rooms, walls and instances."""
        pts = [np.array(p + (0.0,)) for r in self.rooms for p in r.polygon]
        for w in self.walls:
            pts += [np.array(w.start + (w.bottom + w.height,)), np.array(w.end + (0.0,))]
        for inst in self.instances:
            fp = inst.bbox.footprint()
            pts += [np.array([x, y, inst.bbox.zmin]) for x, y in fp]
            pts += [np.array([x, y, inst.bbox.zmax]) for x, y in fp]
        if not pts:
            return np.zeros(3), np.zeros(3)
        arr = np.stack(pts)
        return arr.min(0), arr.max(0)

    def replace(self, **changes) -> "Scene":
        return dataclasses.replace(self, **changes)


# ---------------------------------------------------------------------------
# Polygon helpers
# ---------------------------------------------------------------------------


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


def room_containing(rooms: Sequence["Room"], xy, snap: float = 0.0) -> str | None:
    """Id of the first room whose floor polygon contains ``xy``; failing that,
    the room whose boundary is nearest within ``snap`` metres (for objects
    hung on a wall line or standing on a threshold); else None."""
    p = np.asarray(xy, dtype=np.float64)[:2]
    for r in rooms:
        if bool(r.contains(p[None])[0]):
            return r.id
    best, best_d = None, snap
    if snap > 0:
        for r in rooms:
            d = polygon_edge_distance(p, r.polygon)
            if d <= best_d:
                best, best_d = r.id, d
    return best


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


# ---------------------------------------------------------------------------
# Validation
# ---------------------------------------------------------------------------


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


# ---------------------------------------------------------------------------
# JSON (de)serialisation: lossless, for caches, tests and debugging
# ---------------------------------------------------------------------------

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
