"""The scene model's elements: the dataclasses a scene is made of.

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
import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ignjax.scenes.model.polygons import Vec2, points_in_polygon, polygon_area, polygon_centroid, polygon_edge_distance

__all__ = ["GEOM_KINDS", "MeshData", "Geom", "Attributes", "OrientedBox", "Instance", "Room", "Door", "Wall",
           "SceneMeta", "Scene", "room_containing"]

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
