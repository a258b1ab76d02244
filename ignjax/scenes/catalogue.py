"""The object catalogue of procedural houses.

Each category is a :class:`CategorySpec`: where it goes (rooms, floor / wall
/ on a support), which attribute values it can take, and a ``build`` function
that turns sampled :class:`~ignjax.scenes.model.Attributes` into geometry: a
recognisable composition of MuJoCo primitives (a chair is a seat, a back and
four legs; a laptop a base and a screen, open or closed).

Attributes are expressed in the geometry:

* colour -> the RGBA of the object's main parts (:data:`vocab.COLORS`);
* material -> :attr:`Geom.material` (rendered with that material's
  reflectance) and, for wood/metal/glass parts without a colour of their
  own, their tint;
* size class -> a uniform scale (:data:`vocab.SIZE_SCALE`) of the default
  dimensions;
* state -> the shape (an open laptop has a raised screen, a closed one a
  flat lid; an open wardrobe shows its doors swung out; a lamp that is on
  has an emissive shade; a made bed has a flat blanket, an unmade one a
  rumpled one).

Builder frame: origin at the centre of the object's footprint at its lowest
point, z up, +x is the object's *front* (where a chair faces, where a
painting looks, the side a wardrobe opens to). Objects that stand against a
wall are placed with their back (-x) to the wall. Wall-mounted objects are
built with z = 0 at their lowest point and hung at ``mount_height``.

Registry: :data:`CATALOGUE` is an immutable mapping name -> spec; add a
category by writing its builder and listing it in ``_SPECS``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Callable, Mapping

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes, Geom, Instance, OrientedBox

PLACEMENTS = ("floor", "floor_wall", "wall", "on_support")
"""``floor``: free-standing in the room; ``floor_wall``: on the floor with
its back against a wall; ``wall``: hung on a wall at ``mount_height``;
``on_support``: standing on a support surface of another instance."""


@dataclass(frozen=True)
class Surface:
    """A horizontal surface others can stand on, in the builder frame.

    Attributes:
        height: z of the top of the surface, metres.
        half_extents: (hx, hy) half sizes of the usable area.
        center: (x, y) centre of the usable area.
    """

    height: float
    half_extents: tuple[float, float]
    center: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class Built:
    """What a builder returns.

    Attributes:
        geoms: parts in the builder frame (see module docstring).
        half_extents: (hx, hy, hz) of the object's box; the box is centred
            at (0, 0, hz) in the builder frame.
        surfaces: support surfaces (tables, shelves, beds, counters).
    """

    geoms: tuple[Geom, ...]
    half_extents: tuple[float, float, float]
    surfaces: tuple[Surface, ...] = ()


Builder = Callable[[Attributes, np.random.Generator], Built]


@dataclass(frozen=True)
class CategorySpec:
    """How one category appears in procedural houses.

    Attributes:
        name: canonical category (must be in :data:`vocab.TARGET_WHITELIST`).
        placement: one of :data:`PLACEMENTS`.
        rooms: room label -> relative weight of appearing in that room.
        colors: colours it can take (names from :data:`vocab.COLORS`).
        materials: materials it can take.
        states: states it can take; empty when the category has none.
        sizes: size classes it can take.
        supports: for ``on_support``: categories it may stand on.
        mount_height: for ``wall``: height of its lowest point, metres.
        build: the builder.
    """

    name: str
    placement: str
    rooms: Mapping[str, float]
    colors: tuple[str, ...]
    materials: tuple[str, ...]
    build: Builder
    states: tuple[str, ...] = ()
    sizes: tuple[str, ...] = vocab.SIZES
    supports: tuple[str, ...] = ()
    mount_height: float = 0.0

    def sample_attributes(self, rng: np.random.Generator) -> Attributes:
        """Draw colour, material, size and state uniformly from the allowed sets."""
        return Attributes(
            color=str(rng.choice(self.colors)) if self.colors else None,
            material=str(rng.choice(self.materials)) if self.materials else None,
            size=str(rng.choice(self.sizes)) if self.sizes else None,
            state=str(rng.choice(self.states)) if self.states else None,
        )


# ---------------------------------------------------------------------------
# Geometry helpers used by builders
# ---------------------------------------------------------------------------

MATERIAL_TINT = MappingProxyType(
    {
        "wood": (0.55, 0.38, 0.22),
        "metal": (0.62, 0.64, 0.67),
        "fabric": (0.60, 0.58, 0.55),
        "leather": (0.30, 0.18, 0.10),
        "plastic": (0.85, 0.85, 0.85),
        "glass": (0.75, 0.85, 0.90),
        "ceramic": (0.95, 0.95, 0.93),
        "stone": (0.60, 0.60, 0.58),
        "wicker": (0.72, 0.58, 0.36),
    }
)
"""Tint of parts that show their material rather than the object's colour."""


def rgba(color: str | None, alpha: float = 1.0, default: str = "gray") -> tuple[float, float, float, float]:
    """RGBA of a palette colour name."""
    r, g, b = vocab.COLORS.get(color or default, vocab.COLORS[default])
    return (r, g, b, alpha)


def tint(material: str | None, alpha: float = 1.0) -> tuple[float, float, float, float]:
    """RGBA tint of a material (for legs, frames and other secondary parts)."""
    r, g, b = MATERIAL_TINT.get(material or "wood", MATERIAL_TINT["wood"])
    return (r, g, b, alpha)


def scale_of(attrs: Attributes) -> float:
    return vocab.SIZE_SCALE.get(attrs.size or "medium", 1.0)


def quat_axis_angle(axis, angle: float) -> tuple[float, float, float, float]:
    """Quaternion (w, x, y, z) for a rotation of ``angle`` radians about ``axis``."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), float(a[0] * s), float(a[1] * s), float(a[2] * s))


def box(part: str, half, pos, color, material=None, quat=(1.0, 0.0, 0.0, 0.0)) -> Geom:
    """A box part; ``half`` are half sizes, ``pos`` its centre."""
    return Geom("box", tuple(half), tuple(pos), tuple(quat), tuple(color), part, material)


def cylinder(part: str, radius: float, half_length: float, pos, color, material=None, quat=(1.0, 0.0, 0.0, 0.0)) -> Geom:
    """A cylinder part along its local z (rotate with ``quat``)."""
    return Geom("cylinder", (radius, half_length, 0.0), tuple(pos), tuple(quat), tuple(color), part, material)


def sphere(part: str, radius: float, pos, color, material=None) -> Geom:
    return Geom("sphere", (radius, 0.0, 0.0), tuple(pos), (1.0, 0.0, 0.0, 0.0), tuple(color), part, material)


def capsule(part: str, radius: float, half_length: float, pos, color, material=None, quat=(1.0, 0.0, 0.0, 0.0)) -> Geom:
    return Geom("capsule", (radius, half_length, 0.0), tuple(pos), tuple(quat), tuple(color), part, material)


def ellipsoid(part: str, semi, pos, color, material=None, quat=(1.0, 0.0, 0.0, 0.0)) -> Geom:
    return Geom("ellipsoid", tuple(semi), tuple(pos), tuple(quat), tuple(color), part, material)


def legs4(hx: float, hy: float, height: float, radius: float, color, material, inset: float = 0.03) -> list[Geom]:
    """Four cylindrical legs under a rectangle of half sizes (hx, hy)."""
    out = []
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        out.append(cylinder(f"leg{i}", radius, height / 2, (sx * (hx - inset), sy * (hy - inset), height / 2), color, material))
    return out


# ---------------------------------------------------------------------------
# Builders (examples; the full catalogue follows the same pattern)
# ---------------------------------------------------------------------------


def build_chair(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A seat, a back and four legs; the back is at -x (the chair faces +x)."""
    s = scale_of(attrs)
    hx = hy = 0.22 * s
    seat_h = 0.45 * s
    main = rgba(attrs.color)
    frame = tint(attrs.material)
    geoms = legs4(hx, hy, seat_h - 0.03 * s, 0.018 * s, frame, attrs.material)
    geoms.append(box("seat", (hx, hy, 0.03 * s), (0, 0, seat_h - 0.015 * s), main, attrs.material))
    back_h = 0.45 * s
    geoms.append(box("back", (0.02 * s, hy, back_h / 2), (-hx + 0.02 * s, 0, seat_h + back_h / 2), main, attrs.material))
    return Built(tuple(geoms), (hx, hy, (seat_h + back_h) / 2))


def build_dining_table(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A top on four legs; the top is a support surface."""
    s = scale_of(attrs)
    hx, hy, h = 0.8 * s, 0.45 * s, 0.75
    top = rgba(attrs.color, default="brown")
    geoms = legs4(hx, hy, h - 0.04, 0.03, tint(attrs.material), attrs.material, inset=0.06)
    geoms.append(box("top", (hx, hy, 0.02), (0, 0, h - 0.02), top, attrs.material))
    return Built(tuple(geoms), (hx, hy, h / 2), (Surface(h, (hx - 0.08, hy - 0.08)),))


def build_laptop(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A base with a keyboard deck and a screen: raised (open) or folded flat (closed).

    The screen hinges at the back edge (-x); open, it leans back 20 degrees
    from vertical so the display faces +x.
    """
    s = scale_of(attrs)
    hx, hy, t = 0.12 * s, 0.17 * s, 0.01 * s
    shell = rgba(attrs.color, default="gray")
    geoms = [box("base", (hx, hy, t), (0, 0, t), shell, attrs.material),
             box("keyboard", (hx * 0.6, hy * 0.85, 0.002), (0.01 * s, 0, 2 * t + 0.002), rgba("black"), "plastic")]
    if attrs.state == "closed":
        geoms.append(box("lid", (hx, hy, t * 0.6), (0, 0, 2 * t + 0.008), shell, attrs.material))
        return Built(tuple(geoms), (hx, hy, t + 0.01))
    tilt = math.radians(20.0)
    sh = 0.11 * s  # screen half height
    cx = -hx - math.sin(tilt) * sh + 0.005
    cz = 2 * t + math.cos(tilt) * sh
    q = quat_axis_angle((0, 1, 0), -tilt)
    geoms.append(box("screen", (0.006, hy, sh), (cx, 0, cz), shell, attrs.material, quat=q))
    geoms.append(box("display", (0.001, hy * 0.9, sh * 0.88), (cx + 0.007 * math.cos(tilt), 0, cz + 0.007 * math.sin(tilt)),
                     (0.15, 0.25, 0.45, 1.0), "glass", quat=q))
    top = cz + math.cos(tilt) * sh
    return Built(tuple(geoms), (hx + 0.05 * s, hy, top / 2))


def build_painting(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A thin framed canvas hung on a wall; the picture faces +x."""
    s = scale_of(attrs)
    hy, hz, t = 0.4 * s, 0.3 * s, 0.02
    frame = tint(attrs.material)
    geoms = [box("frame", (t, hy, hz), (t, 0, hz), frame, attrs.material),
             box("canvas", (0.003, hy * 0.88, hz * 0.85), (2 * t + 0.003, 0, hz), rgba(attrs.color), "fabric")]
    return Built(tuple(geoms), (t + 0.003, hy, hz))


def build_bed(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A frame with a headboard at -x, a mattress, pillows and a blanket
    (flat when made, rumpled when unmade); the mattress is a support."""
    s = scale_of(attrs)
    hx, hy = 1.0, 0.8 * s
    frame_h, mat_h = 0.3, 0.22
    wood = tint(attrs.material)
    cover = rgba(attrs.color)
    geoms = [box("frame", (hx, hy, frame_h / 2), (0, 0, frame_h / 2), wood, attrs.material),
             box("headboard", (0.04, hy, 0.5), (-hx + 0.04, 0, 0.5), wood, attrs.material),
             box("mattress", (hx - 0.06, hy - 0.03, mat_h / 2), (0.02, 0, frame_h + mat_h / 2), rgba("white"), "fabric")]
    top = frame_h + mat_h
    n_pillows = 2 if hy > 0.6 else 1
    for k in range(n_pillows):
        y = 0.0 if n_pillows == 1 else (k - 0.5) * hy
        geoms.append(ellipsoid(f"pillow{k}", (0.15, 0.26, 0.07), (-hx + 0.28, y, top + 0.06), rgba("white"), "fabric"))
    if attrs.state == "unmade":
        for k in range(3):
            geoms.append(ellipsoid(f"blanket{k}", (0.35, hy * 0.7, 0.06), (0.1 + 0.3 * k, (k - 1) * 0.15, top + 0.03), cover, "fabric"))
    else:
        geoms.append(box("blanket", (hx * 0.7, hy - 0.02, 0.02), (hx * 0.28, 0, top + 0.01), cover, "fabric"))
    return Built(tuple(geoms), (hx, hy, 0.5), (Surface(top, (hx * 0.7, hy * 0.8), (hx * 0.2, 0.0)),))


def instantiate(
    instance_id: str,
    category: str,
    attrs: Attributes,
    built: Built,
    position,
    yaw: float,
    room: str | None = None,
    support: str | None = None,
    name: str = "",
) -> Instance:
    """Place a built object in the world as an :class:`Instance`.

    Args:
        position: (3,) world position of the builder origin (footprint
            centre at the object's lowest point).
        yaw: heading of the object's front (+x of the builder frame).
    """
    px, py, pz = (float(v) for v in position)
    hx, hy, hz = built.half_extents
    bbox = OrientedBox((px, py, pz + hz), (hx, hy, hz), yaw)
    return Instance(id=instance_id, category=category, position=(px, py, pz), yaw=yaw, bbox=bbox, room=room,
                    attributes=attrs, support=support, structural=vocab.is_structural(category), geoms=built.geoms,
                    name=name or instance_id)


def surfaces_world(inst: Instance, built: Built) -> list[tuple[float, np.ndarray]]:
    """World footprints of a placed object's support surfaces: list of
    (height, (4, 2) corners counter-clockwise)."""
    c, s = math.cos(inst.yaw), math.sin(inst.yaw)
    rot = np.array([[c, -s], [s, c]])
    out = []
    for surf in built.surfaces:
        hx, hy = surf.half_extents
        local = np.array([[hx, hy], [-hx, hy], [-hx, -hy], [hx, -hy]]) + np.array(surf.center)
        out.append((inst.position[2] + surf.height, local @ rot.T + np.array(inst.position[:2])))
    return out


_ALL_COLORS = tuple(vocab.COLORS)
_SPECS: tuple[CategorySpec, ...] = (
    CategorySpec("chair", "floor", {"dining_room": 3, "kitchen": 1, "office": 1, "bedroom": 0.5, "living_room": 0.5},
                 _ALL_COLORS, ("wood", "metal", "plastic"), build_chair),
    CategorySpec("dining_table", "floor", {"dining_room": 3, "kitchen": 1},
                 ("brown", "white", "black", "gray"), ("wood", "stone", "glass"), build_dining_table),
    CategorySpec("laptop", "on_support", {"office": 3, "living_room": 1, "bedroom": 1, "dining_room": 0.5},
                 ("gray", "black", "white", "blue", "pink"), ("metal", "plastic"), build_laptop,
                 states=("open", "closed"), supports=("desk", "dining_table", "coffee_table", "bed", "side_table")),
    CategorySpec("painting", "wall", {"living_room": 3, "bedroom": 2, "hallway": 2, "dining_room": 2, "office": 1, "entryway": 1},
                 _ALL_COLORS, ("wood", "metal"), build_painting, mount_height=1.2),
    CategorySpec("bed", "floor_wall", {"bedroom": 5}, _ALL_COLORS, ("wood", "metal"), build_bed,
                 states=("made", "unmade")),
)

CATALOGUE: Mapping[str, CategorySpec] = MappingProxyType({s.name: s for s in _SPECS})
"""Category name -> spec, for every category procedural houses can place."""
