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
* size class -> a scale (:data:`vocab.SIZE_SCALE`) of the default
  dimensions; tall furniture (wardrobes, refrigerators, bookshelves, lamps)
  scales its height by half as much so that it stays under the ceiling, and
  curtains only scale their width;
* state -> the shape (an open laptop has a raised screen, a closed one a
  flat lid; an open wardrobe shows its doors swung out and the clothes
  inside; a lamp, television or monitor that is on has a bright shade or
  screen; a full bookshelf holds rows of books; a made bed has a flat
  blanket, an unmade one the covers bunched at its foot).

Builder frame: origin at the centre of the object's footprint at its lowest
point, z up, +x is the object's *front* (where a chair faces, where a
painting looks, the side a wardrobe opens to). Objects that stand against a
wall are placed with their back (-x) to the wall. Wall-mounted objects are
built with z = 0 at their lowest point and hung at ``mount_height``.
Builders compose parts in whatever frame is natural and end with
:func:`finish`, which moves the parts so that the tight axis-aligned box of
all parts is centred at (0, 0, hz) with its bottom at z = 0; so
``Built.half_extents`` always contains every part, and the back of a
``floor_wall``/``wall`` object lies at x = -hx.

Support surfaces (:class:`Surface`) are free of parts: nothing of the object
rises above a surface inside its rectangle, up to ``clearance`` (the next
shelf board for shelves).

Registry: :data:`CATALOGUE` is an immutable mapping name -> spec; add a
category by writing its builder and listing it in ``_SPECS``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from types import MappingProxyType
from typing import Callable, Mapping, Sequence

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
        clearance: free height above the surface (up to the next shelf
            board), metres; ``inf`` when open above.
    """

    height: float
    half_extents: tuple[float, float]
    center: tuple[float, float] = (0.0, 0.0)
    clearance: float = math.inf


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

Color = tuple[float, float, float, float]

LIGHT_ON: Color = (1.0, 0.95, 0.72, 1.0)
"""Colour of a lit bulb or flame core."""
SCREEN_OFF: Color = (0.03, 0.03, 0.04, 1.0)
"""Colour of a switched-off screen or oven window."""
DARK: Color = (0.06, 0.06, 0.07, 1.0)
"""Colour of openings, slots and shadows."""
FLAME: Color = (1.0, 0.55, 0.08, 1.0)
"""Colour of flames and glowing burners."""


def rgba(color: str | None, alpha: float = 1.0, default: str = "gray") -> Color:
    """RGBA of a palette colour name."""
    r, g, b = vocab.COLORS.get(color or default, vocab.COLORS[default])
    return (r, g, b, alpha)


def tint(material: str | None, alpha: float = 1.0) -> Color:
    """RGBA tint of a material (for legs, frames and other secondary parts)."""
    r, g, b = MATERIAL_TINT.get(material or "wood", MATERIAL_TINT["wood"])
    return (r, g, b, alpha)


def shade(color: Sequence[float], factor: float) -> Color:
    """``color`` darkened (factor < 1) or lightened (factor > 1), clipped to 0..1."""
    r, g, b = (min(1.0, max(0.0, float(c) * factor)) for c in tuple(color)[:3])
    return (r, g, b, float(tuple(color)[3]) if len(tuple(color)) > 3 else 1.0)


def mix(a: Sequence[float], b: Sequence[float], t: float) -> Color:
    """Linear blend of two colours: ``a`` at t = 0, ``b`` at t = 1 (alpha of ``a``)."""
    out = tuple((1 - t) * float(x) + t * float(y) for x, y in zip(tuple(a)[:3], tuple(b)[:3]))
    return (out[0], out[1], out[2], float(tuple(a)[3]) if len(tuple(a)) > 3 else 1.0)


def glow(color: Sequence[float]) -> Color:
    """An emissive-looking version of ``color``: blended towards warm white and brightened."""
    c = mix(color, LIGHT_ON, 0.7)
    peak = max(c[:3])
    return shade(c, 1.0 / peak) if peak > 0 else LIGHT_ON


def scale_of(attrs: Attributes) -> float:
    """Uniform scale of the size class (:data:`vocab.SIZE_SCALE`); 1 when unknown."""
    return vocab.SIZE_SCALE.get(attrs.size or "medium", 1.0)


def hscale(s: float, k: float = 0.5) -> float:
    """A damped scale for heights of tall objects: ``1 + k (s - 1)``."""
    return 1.0 + k * (s - 1.0)


def quat_axis_angle(axis, angle: float) -> tuple[float, float, float, float]:
    """Quaternion (w, x, y, z) for a rotation of ``angle`` radians about ``axis``."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), float(a[0] * s), float(a[1] * s), float(a[2] * s))


def quat_mul(a, b) -> tuple[float, float, float, float]:
    """Hamilton product ``a * b`` of quaternions (w, x, y, z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw)


def quat_from_z(direction) -> tuple[float, float, float, float]:
    """Quaternion of the shortest rotation taking +z onto ``direction``."""
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    c = float(d[2])
    if c > 1.0 - 1e-12:
        return (1.0, 0.0, 0.0, 0.0)
    if c < -1.0 + 1e-12:
        return (0.0, 1.0, 0.0, 0.0)
    axis = np.array([-d[1], d[0], 0.0])
    return quat_axis_angle(axis, math.acos(max(-1.0, min(1.0, c))))


def rotation_matrix(quat) -> np.ndarray:
    """(3, 3) rotation matrix of a quaternion (w, x, y, z) (normalised first)."""
    w, x, y, z = (float(v) for v in quat)
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def geom_aabb(geom: Geom) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounds (lo, hi), each (3,), of a part in its instance's frame.

    Exact for every primitive (a rotated cylinder's rim circle, an
    ellipsoid's support function) and for meshes (their vertices).
    """
    rot = rotation_matrix(geom.quat)
    pos = np.asarray(geom.pos, dtype=np.float64)
    size = np.asarray(geom.size, dtype=np.float64)
    if geom.kind == "box":
        ext = np.abs(rot) @ size
    elif geom.kind in ("cylinder", "capsule"):
        r, h = size[0], size[1]
        axis = np.abs(rot[:, 2])
        radial = r * np.sqrt(np.clip(1.0 - axis ** 2, 0.0, 1.0)) if geom.kind == "cylinder" else np.full(3, r)
        ext = axis * h + radial
    elif geom.kind == "sphere":
        ext = np.full(3, size[0])
    elif geom.kind == "ellipsoid":
        ext = np.sqrt((rot ** 2) @ (size ** 2))
    elif geom.kind == "mesh" and geom.mesh is not None:
        pts = geom.mesh.vertices @ rot.T + pos
        return pts.min(0), pts.max(0)
    else:
        raise ValueError(f"cannot bound a geom of kind {geom.kind!r}")
    return pos - ext, pos + ext


def parts_bounds(geoms: Sequence[Geom]) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounds (lo, hi) of a set of parts."""
    los, his = zip(*(geom_aabb(g) for g in geoms))
    return np.min(los, axis=0), np.max(his, axis=0)


def finish(geoms: Sequence[Geom], surfaces: Sequence[Surface] = ()) -> Built:
    """Centre parts (and surfaces) on their tight box and return the :class:`Built`.

    Moves everything so that the axis-aligned box of all parts is centred
    at x = y = 0 with its bottom at z = 0; the half extents are that box's.
    """
    geoms = list(geoms)
    lo, hi = parts_bounds(geoms)
    off = np.array([-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]])
    moved = tuple(dataclasses.replace(g, pos=tuple(float(v) for v in np.asarray(g.pos) + off)) for g in geoms)
    surfs = tuple(dataclasses.replace(sf, height=float(sf.height + off[2]),
                                      center=(float(sf.center[0] + off[0]), float(sf.center[1] + off[1])))
                  for sf in surfaces)
    half = tuple(float(v) for v in (hi - lo) / 2)
    return Built(moved, half, surfs)


def box(part: str, half, pos, color, material=None, quat=(1.0, 0.0, 0.0, 0.0)) -> Geom:
    """A box part; ``half`` are half sizes, ``pos`` its centre."""
    return Geom("box", tuple(half), tuple(pos), tuple(quat), tuple(color), part, material)


def span(part: str, lo, hi, color, material=None) -> Geom:
    """An axis-aligned box part between corners ``lo`` and ``hi`` (each (3,))."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    return box(part, tuple(np.abs(hi - lo) / 2), tuple((lo + hi) / 2), color, material)


def cylinder(part: str, radius: float, half_length: float, pos, color, material=None, quat=(1.0, 0.0, 0.0, 0.0)) -> Geom:
    """A cylinder part along its local z (rotate with ``quat``)."""
    return Geom("cylinder", (radius, half_length, 0.0), tuple(pos), tuple(quat), tuple(color), part, material)


_AXIS_QUAT = {"z": (1.0, 0.0, 0.0, 0.0), "x": quat_axis_angle((0, 1, 0), math.pi / 2), "y": quat_axis_angle((1, 0, 0), math.pi / 2)}


def disk(part: str, radius: float, half_length: float, pos, color, material=None, axis: str = "z") -> Geom:
    """A cylinder whose axis is the frame's ``axis`` (``"x"``, ``"y"`` or ``"z"``)."""
    return cylinder(part, radius, half_length, pos, color, material, quat=_AXIS_QUAT[axis])


def sphere(part: str, radius: float, pos, color, material=None) -> Geom:
    """A sphere part."""
    return Geom("sphere", (radius, 0.0, 0.0), tuple(pos), (1.0, 0.0, 0.0, 0.0), tuple(color), part, material)


def capsule(part: str, radius: float, half_length: float, pos, color, material=None, quat=(1.0, 0.0, 0.0, 0.0)) -> Geom:
    """A capsule part along its local z; ``half_length`` excludes the caps."""
    return Geom("capsule", (radius, half_length, 0.0), tuple(pos), tuple(quat), tuple(color), part, material)


def ellipsoid(part: str, semi, pos, color, material=None, quat=(1.0, 0.0, 0.0, 0.0)) -> Geom:
    """An ellipsoid part with semi-axes ``semi`` along its local axes."""
    return Geom("ellipsoid", tuple(semi), tuple(pos), tuple(quat), tuple(color), part, material)


def segment(part: str, p0, p1, radius: float, color, material=None, kind: str = "capsule") -> Geom:
    """A capsule (or cylinder) whose axis runs from point ``p0`` to point ``p1``."""
    a, b = np.asarray(p0, dtype=np.float64), np.asarray(p1, dtype=np.float64)
    d = b - a
    length = float(np.linalg.norm(d))
    return Geom(kind, (radius, length / 2, 0.0), tuple((a + b) / 2), quat_from_z(d), tuple(color), part, material)


def ring(part: str, center, radii, tube: float, n: int, color, material=None, u=(1, 0, 0), v=(0, 1, 0),
         start: float = 0.0, stop: float = 2 * math.pi) -> list[Geom]:
    """A ring (or an arc from ``start`` to ``stop``) of ``n`` capsules.

    The curve is ``center + rx cos(t) u + ry sin(t) v``; ``radii`` is a
    radius or a pair (rx, ry) for an ellipse.
    """
    rx, ry = (radii, radii) if np.isscalar(radii) else radii
    c, uu, vv = (np.asarray(x, dtype=np.float64) for x in (center, u, v))
    ts = np.linspace(start, stop, n + 1)
    pts = [c + rx * math.cos(t) * uu + ry * math.sin(t) * vv for t in ts]
    return [segment(f"{part}{k}", pts[k], pts[k + 1], tube, color, material) for k in range(n)]


def legs4(hx: float, hy: float, height: float, radius: float, color, material, inset: float = 0.03) -> list[Geom]:
    """Four cylindrical legs under a rectangle of half sizes (hx, hy)."""
    out = []
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        out.append(cylinder(f"leg{i}", radius, height / 2, (sx * (hx - inset), sy * (hy - inset), height / 2), color, material))
    return out


def _pick(rng: np.random.Generator, options: Sequence[str]) -> str:
    """One name of ``options`` drawn with ``rng``."""
    names = tuple(options)
    return str(names[int(rng.integers(len(names)))])


# ---------------------------------------------------------------------------
# Seating
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
    geoms.append(box("back_rail", (0.025 * s, hy * 0.9, 0.03 * s), (-hx + 0.05 * s, 0, seat_h + back_h - 0.05 * s), shade(main, 0.85),
                     attrs.material))
    return finish(geoms)


def _upholstered(attrs: Attributes, width: float, n_cushions: int, *, depth: float, seat_h: float, back_h: float,
                 arm_h: float, arm_w: float, leg_h: float, default: str = "gray") -> Built:
    """Sofa-like seating: legs, a base, rolled armrests, a back, seat and back
    cushions; the seat cushions are the support surface."""
    main = rgba(attrs.color, default=default)
    dark = shade(main, 0.82)
    mat = attrs.material
    hx, hy = depth / 2, width / 2
    g = legs4(hx, hy, leg_h, 0.025, tint("wood"), "wood", inset=0.07)
    base_top = seat_h - 0.14
    g.append(span("base", (-hx, -hy + arm_w, leg_h), (hx - 0.02, hy - arm_w, base_top), dark, mat))
    arm_top = arm_h - arm_w / 2
    for k, sy in enumerate((1, -1)):
        y = sy * (hy - arm_w / 2)
        g.append(span(f"arm{k}", (-hx, y - arm_w / 2, leg_h), (hx, y + arm_w / 2, arm_top), main, mat))
        g.append(disk(f"arm_roll{k}", arm_w / 2, hx, (0, y, arm_top), main, mat, axis="x"))
    back_d = 0.2
    inner = hy - arm_w
    g.append(span("back", (-hx, -inner, base_top), (-hx + back_d, inner, back_h), main, mat))
    seat_x0 = -hx + back_d + 0.14
    cw = 2 * inner / n_cushions
    for k in range(n_cushions):
        y0 = -inner + k * cw
        g.append(span(f"seat_cushion{k}", (-hx + back_d, y0 + 0.003, base_top), (hx - 0.01, y0 + cw - 0.003, seat_h),
                      main if k % 2 == 0 else shade(main, 0.95), mat))
        g.append(span(f"back_cushion{k}", (-hx + back_d, y0 + 0.006, seat_h), (seat_x0, y0 + cw - 0.006, back_h - 0.03),
                      shade(main, 1.06), mat))
    surf = Surface(seat_h, ((hx - 0.02 - seat_x0) / 2 - 0.01, inner - 0.04), ((hx - 0.02 + seat_x0) / 2, 0.0))
    return finish(g, (surf,))


def build_sofa(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A three-seat (two when small) sofa against a wall; the seat is a support."""
    s = scale_of(attrs)
    width = 2.0 * s
    return _upholstered(attrs, width, 3 if width >= 1.8 else 2, depth=0.9, seat_h=0.45, back_h=0.85, arm_h=0.64,
                        arm_w=0.17, leg_h=0.08)


def build_armchair(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A one-seat upholstered chair with rolled arms and a tall back."""
    s = scale_of(attrs)
    return _upholstered(attrs, 0.88 * s, 1, depth=0.85 * s, seat_h=0.44, back_h=0.92 * hscale(s), arm_h=0.64,
                        arm_w=0.15, leg_h=0.12, default="green")


def build_office_chair(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A five-star base on casters, a gas column, a seat, a tilted back and armrests."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="black")
    metal = tint("metal")
    black = rgba("black")
    g = []
    reach = 0.31 * s
    for k in range(5):
        a = 2 * math.pi * k / 5
        end = (reach * math.cos(a), reach * math.sin(a), 0.075)
        g.append(segment(f"star{k}", (0, 0, 0.1), end, 0.02, metal, "metal"))
        g.append(sphere(f"caster{k}", 0.03, (end[0], end[1], 0.03), black, "plastic"))
    seat_h = 0.48 * s
    g.append(disk("sleeve", 0.035, (0.26 - 0.1) / 2, (0, 0, 0.18), black, "plastic"))
    g.append(disk("column", 0.022, (seat_h - 0.08 - 0.1) / 2, (0, 0, (seat_h - 0.08 + 0.1) / 2), metal, "metal"))
    g.append(span("mechanism", (-0.1, -0.1, seat_h - 0.09), (0.1, 0.1, seat_h - 0.05), black, "metal"))
    hs = 0.25 * s
    g.append(box("seat", (hs, hs, 0.04), (0.02, 0, seat_h - 0.01), main, attrs.material))
    tilt = math.radians(12)
    bh = 0.3 * s
    q = quat_axis_angle((0, 1, 0), -tilt)
    bx, bz = -hs - 0.02 + math.sin(tilt) * bh * 0.2, seat_h + 0.1 + bh
    g.append(box("back", (0.035, hs * 0.92, bh), (bx - math.sin(tilt) * bh * 0.5, 0, bz), main, attrs.material, quat=q))
    g.append(segment("back_spine", (-0.15 * s, 0, seat_h - 0.06), (bx - 0.03, 0, seat_h + 0.2), 0.02, black, "metal"))
    for k, sy in enumerate((1, -1)):
        y = sy * (hs + 0.015)
        g.append(span(f"arm_post{k}", (-0.06, y - 0.015, seat_h), (-0.02, y + 0.015, seat_h + 0.2), black, "plastic"))
        g.append(span(f"arm_pad{k}", (-0.14, y - 0.035, seat_h + 0.2), (0.12, y + 0.035, seat_h + 0.23), black, "plastic"))
    return finish(g)


def build_stool(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A bar stool: a round seat on four splayed legs with a foot ring."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    frame = tint(attrs.material)
    h = 0.66 * s
    r_top, r_bot, lr = 0.12 * s, 0.2 * s, 0.016
    g = []
    for k in range(4):
        a = math.pi / 4 + k * math.pi / 2
        c, sn = math.cos(a), math.sin(a)
        g.append(segment(f"leg{k}", (r_bot * c, r_bot * sn, lr), (r_top * c, r_top * sn, h - 0.03), lr, frame, attrs.material))
    zr = 0.25 * s
    rr = r_bot + (r_top - r_bot) * (zr - lr) / (h - 0.03 - lr)
    g += ring("foot_ring", (0, 0, zr), rr, 0.01, 8, frame, attrs.material, start=math.pi / 4, stop=math.pi / 4 + 2 * math.pi)
    g.append(disk("seat", 0.18 * s, 0.025, (0, 0, h - 0.025), main, attrs.material))
    g.append(disk("cushion", 0.165 * s, 0.01, (0, 0, h + 0.008), shade(main, 1.1), attrs.material))
    return finish(g)


def build_bench(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An entryway bench: a long seat on two end panels with a slatted shoe shelf; the seat is a support."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    frame = tint(attrs.material)
    hy, hx, h = 0.6 * s, 0.19, 0.46
    g = [span("seat", (-hx, -hy, h - 0.05), (hx, hy, h), main, attrs.material)]
    for k, sy in enumerate((1, -1)):
        y = sy * (hy - 0.06)
        g.append(span(f"end{k}", (-hx + 0.02, y - 0.025, 0), (hx - 0.02, y + 0.025, h - 0.05), frame, attrs.material))
    for k in range(3):
        x = -hx + 0.06 + k * (2 * hx - 0.12) / 2
        g.append(span(f"slat{k}", (x - 0.04, -hy + 0.085, 0.1), (x + 0.04, hy - 0.085, 0.12), frame, attrs.material))
    return finish(g, (Surface(h, (hx - 0.02, hy - 0.04)),))


def build_ottoman(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An upholstered footstool: a padded body with a cushion top on short legs."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="beige")
    h = 0.3 * s
    g = legs4(h, h, 0.06, 0.02, tint("wood"), "wood", inset=0.04)
    g.append(span("body", (-h, -h, 0.06), (h, h, 0.36), main, attrs.material))
    g.append(span("cushion", (-h + 0.01, -h + 0.01, 0.36), (h - 0.01, h - 0.01, 0.42), shade(main, 1.08), attrs.material))
    g.append(span("piping", (-h - 0.005, -h - 0.005, 0.355), (h + 0.005, h + 0.005, 0.365), shade(main, 0.7), attrs.material))
    return finish(g, (Surface(0.42, (h - 0.05, h - 0.05)),))


def build_dog_bed(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An oval pet bed: a flat cushion inside a rolled rim."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    ax, ay = 0.42 * s, 0.32 * s
    g = [ellipsoid("cushion", (ax - 0.05, ay - 0.05, 0.05), (0, 0, 0.05), shade(main, 1.15), attrs.material)]
    g += ring("rim", (0, 0, 0.08), (ax - 0.07, ay - 0.07), 0.07, 10, main, attrs.material)
    return finish(g)


# ---------------------------------------------------------------------------
# Tables and desks
# ---------------------------------------------------------------------------


def build_dining_table(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A top on four legs; the top is a support surface."""
    s = scale_of(attrs)
    hx, hy, h = 0.8 * s, 0.45 * s, 0.75
    top = rgba(attrs.color, default="brown")
    geoms = legs4(hx, hy, h - 0.04, 0.03, tint(attrs.material), attrs.material, inset=0.06)
    geoms.append(box("top", (hx, hy, 0.02), (0, 0, h - 0.02), top, attrs.material))
    geoms.append(span("apron", (-hx + 0.05, -hy + 0.05, h - 0.1), (hx - 0.05, hy - 0.05, h - 0.04), shade(top, 0.8), attrs.material))
    return finish(geoms, (Surface(h, (hx - 0.08, hy - 0.08)),))


def build_coffee_table(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A low table with a lower shelf; the top is a support."""
    s = scale_of(attrs)
    hx, hy, h = 0.3 * s, 0.55 * s, 0.42
    main = rgba(attrs.color, default="brown")
    frame = tint(attrs.material)
    g = [span("top", (-hx, -hy, h - 0.03), (hx, hy, h), main, attrs.material)]
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        x, y = sx * (hx - 0.04), sy * (hy - 0.04)
        g.append(span(f"leg{i}", (x - 0.02, y - 0.02, 0), (x + 0.02, y + 0.02, h - 0.03), frame, attrs.material))
    g.append(span("shelf", (-hx + 0.02, -hy + 0.06, 0.1), (hx - 0.02, hy - 0.06, 0.12), shade(main, 0.85), attrs.material))
    return finish(g, (Surface(h, (hx - 0.04, hy - 0.05)),))


def build_side_table(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A round pedestal table; the top is a support."""
    s = scale_of(attrs)
    r, h = 0.25 * s, 0.56
    main = rgba(attrs.color, default="brown")
    frame = tint(attrs.material)
    g = [disk("foot", 0.17 * s, 0.012, (0, 0, 0.012), frame, attrs.material),
         disk("pedestal", 0.03, (h - 0.044) / 2, (0, 0, 0.024 + (h - 0.044) / 2), frame, attrs.material),
         disk("top", r, 0.01, (0, 0, h - 0.01), main, attrs.material)]
    return finish(g, (Surface(h, (r * 0.68, r * 0.68)),))


def build_desk(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A writing desk: a top, a leg panel, a three-drawer pedestal and a modesty panel."""
    s = scale_of(attrs)
    hx, hy, h = 0.33, 0.65 * s, 0.75
    main = rgba(attrs.color, default="brown")
    side = shade(main, 0.85)
    g = [span("top", (-hx, -hy, h - 0.03), (hx, hy, h), main, attrs.material),
         span("leg_panel", (-hx + 0.02, -hy + 0.02, 0), (hx - 0.02, -hy + 0.05, h - 0.03), side, attrs.material),
         span("modesty", (-hx + 0.02, -hy + 0.05, 0.35), (-hx + 0.04, hy - 0.4, h - 0.03), side, attrs.material),
         span("pedestal", (-hx + 0.02, hy - 0.42, 0), (hx - 0.03, hy - 0.02, h - 0.03), side, attrs.material)]
    for k in range(3):
        z0 = 0.04 + k * (h - 0.1) / 3
        z1 = z0 + (h - 0.1) / 3 - 0.012
        g.append(span(f"drawer{k}", (hx - 0.03, hy - 0.41, z0), (hx - 0.01, hy - 0.03, z1), main, attrs.material))
        g.append(disk(f"knob{k}", 0.012, 0.01, (hx, hy - 0.22, (z0 + z1) / 2), tint("metal"), "metal", axis="x"))
    return finish(g, (Surface(h, (hx - 0.04, hy - 0.04)),))


def build_kitchen_island(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A free-standing counter: cabinet doors on the front, a countertop overhanging at the back for stools."""
    s = scale_of(attrs)
    hy, h = 0.9 * s, 0.92
    main = rgba(attrs.color, default="white")
    top = tint(attrs.material or "stone")
    x0, x1 = -0.2, 0.42
    g = [span("toe_kick", (x0 + 0.05, -hy + 0.05, 0), (x1 - 0.05, hy - 0.05, 0.1), DARK),
         span("body", (x0, -hy + 0.02, 0.1), (x1, hy - 0.02, h - 0.04), shade(main, 0.9), "wood"),
         span("countertop", (-0.5, -hy, h - 0.04), (x1 + 0.03, hy, h), top, attrs.material)]
    n = 3 if hy > 0.8 else 2
    w = (2 * hy - 0.04) / n
    for k in range(n):
        y0 = -hy + 0.02 + k * w
        g.append(span(f"door{k}", (x1, y0 + 0.005, 0.12), (x1 + 0.02, y0 + w - 0.005, h - 0.06), main, "wood"))
        g.append(segment(f"handle{k}", (x1 + 0.035, y0 + w / 2 - 0.08, h - 0.12), (x1 + 0.035, y0 + w / 2 + 0.08, h - 0.12), 0.008,
                         tint("metal"), "metal"))
    return finish(g, (Surface(h, ((x1 + 0.5) / 2 - 0.04, hy - 0.05), ((x1 - 0.5) / 2, 0.0)),))


def build_workbench(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A heavy bench: a thick wooden top on a frame, a lower shelf, a pegboard with tools and a vise."""
    s = scale_of(attrs)
    hx, hy, h = 0.35, 0.8 * s, 0.9
    frame = rgba(attrs.color, default="gray")
    wood = tint("wood")
    g = []
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        x, y = sx * (hx - 0.05), sy * (hy - 0.05)
        g.append(span(f"leg{i}", (x - 0.03, y - 0.03, 0), (x + 0.03, y + 0.03, h - 0.06), frame, attrs.material))
    g.append(span("top", (-hx, -hy, h - 0.06), (hx, hy, h), wood, "wood"))
    g.append(span("shelf", (-hx + 0.02, -hy + 0.02, 0.14), (hx - 0.02, hy - 0.02, 0.16), shade(wood, 0.85), "wood"))
    g.append(span("pegboard", (-hx, -hy + 0.05, h), (-hx + 0.02, hy - 0.05, h + 0.75), (0.72, 0.6, 0.45, 1.0), "wood"))
    tools = tint("metal")
    g.append(segment("hammer_handle", (-hx + 0.04, -0.4 * s, h + 0.25), (-hx + 0.04, -0.4 * s, h + 0.5), 0.012, wood, "wood"))
    g.append(span("hammer_head", (-hx + 0.025, -0.4 * s - 0.06, h + 0.5), (-hx + 0.055, -0.4 * s + 0.06, h + 0.54), tools, "metal"))
    g.append(span("wrench", (-hx + 0.025, 0.0, h + 0.3), (-hx + 0.035, 0.03, h + 0.55), tools, "metal"))
    g.append(segment("screwdriver", (-hx + 0.04, 0.3 * s, h + 0.3), (-hx + 0.04, 0.3 * s, h + 0.52), 0.012, rgba("red"), "plastic"))
    g.append(span("vise", (hx - 0.1, hy - 0.25, h), (hx + 0.04, hy - 0.07, h + 0.1), rgba("blue"), "metal"))
    return finish(g, (Surface(h, ((2 * hx - 0.14) / 2 - 0.02, hy - 0.3), (-0.02 + 0.05, -0.1)),))


# ---------------------------------------------------------------------------
# Storage
# ---------------------------------------------------------------------------


def build_nightstand(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A bedside table: a two-drawer body on short legs; the top is a support."""
    s = scale_of(attrs)
    hx, hy, h = 0.2 * s, 0.23 * s, 0.57 * hscale(s)
    main = rgba(attrs.color, default="brown")
    g = legs4(hx, hy, 0.06, 0.018, tint(attrs.material), attrs.material, inset=0.03)
    g.append(span("body", (-hx, -hy, 0.06), (hx - 0.02, hy, h - 0.02), shade(main, 0.88), attrs.material))
    g.append(span("top", (-hx, -hy - 0.01, h - 0.02), (hx + 0.01, hy + 0.01, h), main, attrs.material))
    dh = (h - 0.1) / 2
    for k in range(2):
        z0 = 0.07 + k * dh
        g.append(span(f"drawer{k}", (hx - 0.02, -hy + 0.02, z0 + 0.005), (hx, hy - 0.02, z0 + dh - 0.005), main, attrs.material))
        g.append(sphere(f"knob{k}", 0.013, (hx + 0.01, 0, z0 + dh / 2), tint("metal"), "metal"))
    return finish(g, (Surface(h, (hx - 0.03, hy - 0.03)),))


def build_dresser(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A chest of drawers (three rows of two); open pulls out the top row with clothes inside."""
    s = scale_of(attrs)
    hx, hy, h = 0.24, 0.6 * s, 0.85
    main = rgba(attrs.color, default="brown")
    g = [span("plinth", (-hx + 0.02, -hy + 0.02, 0), (hx - 0.03, hy - 0.02, 0.07), shade(main, 0.7), attrs.material),
         span("body", (-hx, -hy, 0.07), (hx - 0.02, hy, h - 0.03), shade(main, 0.85), attrs.material),
         span("top", (-hx, -hy - 0.01, h - 0.03), (hx + 0.01, hy + 0.01, h), main, attrs.material)]
    dh = (h - 0.12) / 3
    opened = attrs.state == "open"
    for row in range(3):
        z0 = 0.08 + row * dh
        for col in range(2):
            y0, y1 = (-hy + 0.015, -0.005) if col == 0 else (0.005, hy - 0.015)
            out = 0.3 if opened and row == 2 else 0.0
            g.append(span(f"drawer{row}{col}", (hx - 0.02 + out, y0, z0 + 0.006), (hx + out, y1, z0 + dh - 0.006), main, attrs.material))
            g.append(segment(f"pull{row}{col}", (hx + out + 0.015, (y0 + y1) / 2 - 0.05, z0 + dh / 2),
                             (hx + out + 0.015, (y0 + y1) / 2 + 0.05, z0 + dh / 2), 0.007, tint("metal"), "metal"))
            if out:
                g.append(span(f"tray{col}", (hx - 0.02, y0 + 0.01, z0 + 0.01), (hx - 0.02 + out, y1 - 0.01, z0 + dh - 0.02),
                              shade(main, 0.75), attrs.material))
                g.append(ellipsoid(f"clothes{col}", (0.1, (y1 - y0) * 0.35, 0.03), (hx + out * 0.5, (y0 + y1) / 2, z0 + dh - 0.02),
                                   rgba(_pick(rng, ("blue", "white", "red", "gray", "pink"))), "fabric"))
    return finish(g, (Surface(h, (hx - 0.04, hy - 0.04), (-0.005, 0.0)),))


def build_wardrobe(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tall two-door wardrobe; open swings the doors out and shows a rail of clothes and a hat shelf."""
    s = scale_of(attrs)
    hy, d, h = 0.5 * s, 0.6, 2.0 * hscale(s, 0.4)
    main = rgba(attrs.color, default="brown")
    inner = shade(main, 0.6)
    mat = attrs.material
    g = [span("plinth", (0.02, -hy + 0.02, 0), (d - 0.02, hy - 0.02, 0.08), shade(main, 0.7), mat),
         span("cornice", (0, -hy - 0.015, h - 0.04), (d + 0.025, hy + 0.015, h), main, mat)]
    wdoor = hy
    if attrs.state != "open":
        g.append(span("body", (0, -hy, 0.08), (d, hy, h - 0.04), shade(main, 0.9), mat))
        for k, sy in enumerate((1, -1)):
            y0, y1 = (0.003, hy) if sy > 0 else (-hy, -0.003)
            g.append(span(f"door{k}", (d, y0, 0.09), (d + 0.02, y1, h - 0.05), main, mat))
            g.append(segment(f"handle{k}", (d + 0.035, sy * 0.05, h / 2 - 0.15), (d + 0.035, sy * 0.05, h / 2 + 0.15), 0.01,
                             tint("metal"), "metal"))
        return finish(g)
    g += [span("back", (0, -hy, 0.08), (0.02, hy, h - 0.04), inner, mat),
          span("side0", (0, hy - 0.02, 0.08), (d, hy, h - 0.04), shade(main, 0.9), mat),
          span("side1", (0, -hy, 0.08), (d, -hy + 0.02, h - 0.04), shade(main, 0.9), mat),
          span("bottom", (0.02, -hy + 0.02, 0.08), (d, hy - 0.02, 0.1), inner, mat),
          span("hat_shelf", (0.02, -hy + 0.02, h - 0.38), (d, hy - 0.02, h - 0.36), shade(main, 0.8), mat),
          segment("rail", (d / 2, -hy + 0.02, h - 0.45), (d / 2, hy - 0.02, h - 0.45), 0.012, tint("metal"), "metal")]
    n = max(3, int(round(2 * hy / 0.16)))
    for k in range(n):
        y = -hy + 0.1 + k * (2 * hy - 0.2) / (n - 1)
        length = float(rng.uniform(0.5, 0.95))
        g.append(ellipsoid(f"garment{k}", (0.22, 0.035, length / 2), (d / 2, y, h - 0.47 - length / 2),
                           rgba(_pick(rng, vocab.COLORS)), "fabric"))
    for k, sy in enumerate((1, -1)):
        alpha = math.radians(-90 + 105) * sy  # door direction from its hinge
        dirx, diry = math.cos(alpha), math.sin(alpha)
        hinge = (d + 0.01, sy * hy)
        cx, cy = hinge[0] + dirx * wdoor / 2, hinge[1] + diry * wdoor / 2
        q = quat_axis_angle((0, 0, 1), alpha - math.pi / 2)
        g.append(box(f"door{k}", (0.01, wdoor / 2, (h - 0.14) / 2), (cx, cy, 0.09 + (h - 0.14) / 2), main, mat, quat=q))
    return finish(g)


def _doors_front(g: list, x: float, y0: float, y1: float, z0: float, z1: float, n: int, color, mat, opened: bool) -> None:
    """Append ``n`` cabinet doors on the plane x (swung out 100 degrees when ``opened``)."""
    w = (y1 - y0) / n
    for k in range(n):
        a0 = y0 + k * w
        hinge_side = 1 if (k % 2 == 1 or n == 1) else -1
        if opened:
            hinge_y = a0 + w if hinge_side > 0 else a0
            d = (math.cos(math.radians(10)), hinge_side * math.sin(math.radians(10)))
            cx, cy = x + 0.01 + d[0] * w / 2, hinge_y + d[1] * w / 2
            q = quat_axis_angle((0, 0, 1), math.atan2(d[1], d[0]) - math.pi / 2)
            g.append(box(f"door{k}", (0.01, w / 2 - 0.004, (z1 - z0) / 2), (cx, cy, (z0 + z1) / 2), color, mat, quat=q))
        else:
            g.append(span(f"door{k}", (x, a0 + 0.004, z0), (x + 0.02, a0 + w - 0.004, z1), color, mat))
            hy_ = a0 + (0.04 if hinge_side > 0 else w - 0.04)
            g.append(segment(f"handle{k}", (x + 0.035, hy_, z1 - 0.18), (x + 0.035, hy_, z1 - 0.04), 0.007, tint("metal"), "metal"))


def build_cabinet(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A base cabinet with a countertop (the support) and two doors; open shows the shelf and contents."""
    s = scale_of(attrs)
    hy, d, h = 0.42 * s, 0.58, 0.9
    main = rgba(attrs.color, default="white")
    top = tint(attrs.material if attrs.material in ("stone", "wood", "metal") else "stone")
    opened = attrs.state == "open"
    g = [span("toe_kick", (0.0, -hy + 0.02, 0), (d - 0.06, hy - 0.02, 0.1), DARK),
         span("countertop", (0, -hy - 0.01, h - 0.04), (d + 0.03, hy + 0.01, h), top, attrs.material)]
    if opened:
        g += [span("back", (0, -hy, 0.1), (0.02, hy, h - 0.04), shade(main, 0.55), "wood"),
              span("side0", (0, hy - 0.02, 0.1), (d, hy, h - 0.04), shade(main, 0.9), "wood"),
              span("side1", (0, -hy, 0.1), (d, -hy + 0.02, h - 0.04), shade(main, 0.9), "wood"),
              span("bottom", (0.02, -hy + 0.02, 0.1), (d, hy - 0.02, 0.12), shade(main, 0.7), "wood"),
              span("shelf", (0.02, -hy + 0.02, 0.47), (d - 0.02, hy - 0.02, 0.49), shade(main, 0.8), "wood")]
        for k in range(3):
            y = -hy + 0.12 + k * (2 * hy - 0.24) / 2
            g.append(disk(f"jar{k}", 0.05, 0.07, (0.3, y, 0.56), rgba(_pick(rng, ("red", "yellow", "white", "green"))), "glass"))
    else:
        g.append(span("body", (0, -hy, 0.1), (d, hy, h - 0.04), shade(main, 0.9), "wood"))
    _doors_front(g, d, -hy, hy, 0.12, h - 0.06, 2, main, "wood", opened)
    return finish(g, (Surface(h, ((d + 0.03) / 2 - 0.04, hy - 0.04), ((d + 0.03) / 2, 0.0)),))


def build_bookshelf(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tall bookcase: sides, back, plinth, top and four shelves; full puts rows
    of books on each level. Every free shelf length (and the top) is a support."""
    s = scale_of(attrs)
    hy, d, h = 0.45 * s, 0.32, 1.8 * hscale(s, 0.4)
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    t = 0.02
    g = [span("back", (0, -hy, 0), (0.01, hy, h), shade(main, 0.8), mat),
         span("side0", (0, hy - t, 0), (d, hy, h), main, mat),
         span("side1", (0, -hy, 0), (d, -hy + t, h), main, mat),
         span("plinth", (0.01, -hy + t, 0), (d, hy - t, 0.07), main, mat),
         span("top", (0, -hy, h - t), (d + 0.01, hy, h), main, mat)]
    n_levels = 5
    pitch = (h - t - 0.07) / n_levels
    surfaces = []
    full = attrs.state == "full"
    inner = hy - t
    for k in range(n_levels):
        z = 0.07 + k * pitch  # top of this level's floor board
        if k > 0:
            g.append(span(f"shelf{k}", (0.01, -inner, z - t), (d, inner, z), main, mat))
        clear = pitch - t if k < n_levels - 1 else pitch
        free0, free1 = -inner, inner
        if full:
            frac = float(rng.uniform(0.5, 0.7))
            left = k % 2 == 0
            y = -inner + 0.005 if left else inner - 0.005
            end = -inner + 2 * inner * frac if left else inner - 2 * inner * frac
            j = 0
            while j < 7 and ((y < end) if left else (y > end)):
                w = float(rng.uniform(0.04, 0.085))
                bh = min(clear - 0.03, float(rng.uniform(0.2, 0.28)) * min(1.0, clear / 0.33))
                bd = float(rng.uniform(0.18, 0.24))
                y0, y1 = (y, y + w) if left else (y - w, y)
                g.append(span(f"book{k}_{j}", (0.02, y0, z), (0.02 + bd, y1, z + bh), rgba(_pick(rng, vocab.COLORS)), "fabric"))
                y = y1 + 0.002 if left else y0 - 0.002
                j += 1
            free0, free1 = (y + 0.01, inner) if left else (-inner, y - 0.01)
        if free1 - free0 > 0.12:
            surfaces.append(Surface(z, (d / 2 - 0.03, (free1 - free0) / 2 - 0.01), (d / 2 + 0.005, (free0 + free1) / 2), clear))
    surfaces.append(Surface(h, (d / 2 - 0.03, hy - 0.03), (d / 2, 0.0)))
    return finish(g, surfaces)


def build_shelf(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An open shelving unit: four corner posts and four boards, each board a support."""
    s = scale_of(attrs)
    hy, d, h = 0.45 * s, 0.4, 1.5 * hscale(s)
    main = rgba(attrs.color, default="gray")
    mat = attrs.material
    g = []
    for i, (x, y) in enumerate(((0.02, hy - 0.02), (d - 0.02, hy - 0.02), (d - 0.02, -hy + 0.02), (0.02, -hy + 0.02))):
        g.append(span(f"post{i}", (x - 0.02, y - 0.02, 0), (x + 0.02, y + 0.02, h), shade(main, 0.8), mat))
    levels = [0.12, 0.12 + (h - 0.14) / 3, 0.12 + 2 * (h - 0.14) / 3, h - 0.02]
    surfaces = []
    for k, z in enumerate(levels):
        g.append(span(f"board{k}", (0.0, -hy, z - 0.02), (d, hy, z), main, mat))
        clear = levels[k + 1] - 0.02 - z if k + 1 < len(levels) else math.inf
        surfaces.append(Surface(z, (d / 2 - 0.05, hy - 0.06), (d / 2, 0.0), clear))
    return finish(g, surfaces)


def build_tv_stand(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A low media console: closed cabinets at the ends, an open dark middle bay; the top is a support."""
    s = scale_of(attrs)
    hy, d, h = 0.75 * s, 0.42, 0.5
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    g = legs4(d / 2, hy, 0.06, 0.02, tint("metal"), "metal", inset=0.05)
    g = [dataclasses.replace(x, pos=(x.pos[0] + d / 2, x.pos[1], x.pos[2])) for x in g]
    g += [span("body", (0, -hy, 0.06), (d, hy, h - 0.02), shade(main, 0.85), mat),
          span("top", (0, -hy - 0.01, h - 0.02), (d + 0.01, hy + 0.01, h), main, mat),
          span("bay", (d, -hy / 3 + 0.01, 0.09), (d + 0.002, hy / 3 - 0.01, h - 0.05), DARK)]
    for k, sy in enumerate((-1, 1)):
        y0, y1 = (-hy + 0.01, -hy / 3 - 0.01) if sy < 0 else (hy / 3 + 0.01, hy - 0.01)
        g.append(span(f"door{k}", (d, y0, 0.08), (d + 0.02, y1, h - 0.04), main, mat))
        g.append(segment(f"handle{k}", (d + 0.03, (y0 + y1) / 2 - 0.06, h - 0.1), (d + 0.03, (y0 + y1) / 2 + 0.06, h - 0.1), 0.007,
                         tint("metal"), "metal"))
    return finish(g, (Surface(h, (d / 2 - 0.03, hy - 0.03), (d / 2, 0.0)),))


def build_crib(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A baby cot: corner posts, top rails, slatted long sides, solid ends and a mattress (the support)."""
    s = scale_of(attrs)
    hy, hx, h = 0.65 * s, 0.36 * s, 1.0
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    mz = 0.36
    g = [span("base", (-hx + 0.03, -hy + 0.03, mz - 0.14), (hx - 0.03, hy - 0.03, mz - 0.1), shade(main, 0.85), mat),
         span("mattress", (-hx + 0.035, -hy + 0.035, mz - 0.1), (hx - 0.035, hy - 0.035, mz), rgba("white"), "fabric")]
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        x, y = sx * (hx - 0.025), sy * (hy - 0.025)
        g.append(span(f"post{i}", (x - 0.025, y - 0.025, 0), (x + 0.025, y + 0.025, h), main, mat))
    for k, sy in enumerate((1, -1)):
        y = sy * (hy - 0.025)
        g.append(span(f"end{k}", (-hx + 0.05, y - 0.012, mz - 0.14), (hx - 0.05, y + 0.012, h - 0.1), main, mat))
    n = max(5, int(round((2 * hy - 0.1) / 0.13)))
    for k, sx in enumerate((1, -1)):
        x = sx * (hx - 0.025)
        g.append(segment(f"rail{k}", (x, -hy + 0.05, h - 0.04), (x, hy - 0.05, h - 0.04), 0.02, main, mat))
        g.append(segment(f"low_rail{k}", (x, -hy + 0.05, mz - 0.12), (x, hy - 0.05, mz - 0.12), 0.02, main, mat))
        for j in range(n):
            y = -hy + 0.05 + (j + 0.5) * (2 * hy - 0.1) / n
            g.append(disk(f"slat{k}_{j}", 0.011, (h - 0.06 - mz + 0.1) / 2, (x, y, (h - 0.06 + mz - 0.1) / 2 - 0.01), main, mat))
    return finish(g, (Surface(mz, (hx - 0.08, hy - 0.08)),))


def build_bed(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A frame on short legs with a headboard at -x and a footboard, a mattress,
    pillows and a blanket. Made: the blanket lies flat over the lower part of
    the bed (its top is the support). Unmade: the covers are bunched at the
    foot, a pillow is askew, and the bare mattress between is the support."""
    s = scale_of(attrs)
    hx, hy = 1.0, 0.8 * s
    frame_h, mat_h = 0.3, 0.22
    wood = tint(attrs.material)
    cover = rgba(attrs.color, default="blue")
    top = frame_h + mat_h
    g = legs4(hx, hy, 0.1, 0.035, wood, attrs.material, inset=0.06)
    g += [span("frame", (-hx, -hy, 0.1), (hx, hy, frame_h), wood, attrs.material),
          span("headboard", (-hx, -hy, 0.1), (-hx + 0.08, hy, 1.05), wood, attrs.material),
          span("footboard", (hx - 0.05, -hy, 0.1), (hx, hy, 0.42), wood, attrs.material),
          span("mattress", (-hx + 0.08, -hy + 0.03, frame_h), (hx - 0.05, hy - 0.03, top), rgba("white"), "fabric")]
    n_pillows = 2 if hy > 0.6 else 1
    unmade = attrs.state == "unmade"
    for k in range(n_pillows):
        y = 0.0 if n_pillows == 1 else (k - 0.5) * hy
        q = quat_axis_angle((0, 0, 1), float(rng.uniform(0.2, 0.5))) if unmade and k == n_pillows - 1 else (1.0, 0.0, 0.0, 0.0)
        g.append(ellipsoid(f"pillow{k}", (0.14, min(0.3, hy / n_pillows - 0.04), 0.07), (-hx + 0.25, y, top + 0.06), rgba("white"),
                           "fabric", quat=q))
    if unmade:
        for k in range(3):
            q = quat_axis_angle((0, 0, 1), float(rng.uniform(-0.25, 0.25)))
            g.append(ellipsoid(f"blanket{k}", (0.2, hy * 0.75, 0.08), (hx - 0.33 + 0.1 * (k - 1), (k - 1) * 0.1 * s, top + 0.05), cover,
                               "fabric", quat=q))
        surf = Surface(top, (0.33, hy - 0.12), (-0.2, 0.0))
    else:
        x0 = -hx + 0.48
        g.append(span("blanket", (x0, -hy + 0.01, top), (hx - 0.05, hy - 0.01, top + 0.04), cover, "fabric"))
        for k, sy in enumerate((1, -1)):
            y = sy * (hy - 0.02)
            g.append(span(f"drape{k}", (x0, y - 0.01, top - 0.2), (hx - 0.05, y + 0.01, top + 0.04), cover, "fabric"))
        surf = Surface(top + 0.04, ((hx - 0.05 - x0) / 2 - 0.05, hy - 0.12), ((hx - 0.05 + x0) / 2, 0.0))
    return finish(g, (surf,))


def build_storage_box(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A lidded storage tote with hand holds; the lid is a support."""
    s = scale_of(attrs)
    hx, hy, h = 0.2 * s, 0.3 * s, 0.3 * s
    main = rgba(attrs.color, default="blue")
    g = [span("body", (-hx + 0.015, -hy + 0.015, 0), (hx - 0.015, hy - 0.015, h - 0.03), main, attrs.material),
         span("lid", (-hx, -hy, h - 0.03), (hx, hy, h), shade(main, 0.8), attrs.material)]
    for k, sy in enumerate((1, -1)):
        g.append(span(f"grip{k}", (-0.05, sy * (hy - 0.015) - 0.003, h - 0.09), (0.05, sy * (hy - 0.015) + 0.003, h - 0.06), DARK))
    return finish(g, (Surface(h, (hx - 0.02, hy - 0.02)),))


def build_shoe_rack(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A low rack: end panels, two slanted slatted levels with pairs of shoes, and a top board (a support)."""
    s = scale_of(attrs)
    hy, d, h = 0.4 * s, 0.3, 0.5
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    g = [span("top", (0, -hy, h - 0.02), (d, hy, h), main, mat)]
    for k, sy in enumerate((1, -1)):
        y = sy * (hy - 0.015)
        g.append(span(f"end{k}", (0, y - 0.015, 0), (d, y + 0.015, h - 0.02), main, mat))
    slant = quat_axis_angle((0, 1, 0), math.radians(12))
    shoe_colors = ("black", "brown", "white", "blue", "red", "gray", "beige")
    for lvl, z in enumerate((0.07, 0.26)):
        g.append(box(f"level{lvl}", (d / 2 - 0.01, hy - 0.03, 0.008), (d / 2, 0, z), shade(main, 0.85), mat, quat=slant))
        n_pairs = int(rng.integers(1, 4))
        for p in range(n_pairs):
            y = -hy + 0.12 + p * (2 * hy - 0.24) / 2
            c = rgba(_pick(rng, shoe_colors))
            for q, dy in enumerate((-0.05, 0.05)):
                g.append(ellipsoid(f"shoe{lvl}_{p}_{q}", (0.13, 0.04, 0.045), (d / 2, y + dy, z + 0.05), c, "leather", quat=slant))
    return finish(g, (Surface(h, (d / 2 - 0.02, hy - 0.02), (d / 2, 0.0)),))


# ---------------------------------------------------------------------------
# Kitchen and laundry appliances
# ---------------------------------------------------------------------------


def build_refrigerator(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tall fridge-freezer: body, freezer drawer below, fridge door above, a
    dark split line, vertical handles and a toe grille."""
    s = scale_of(attrs)
    hy, d, h = 0.38 * s, 0.68, 1.8 * hscale(s, 0.4)
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    split = 0.68 * hscale(s, 0.4)
    metal = tint("metal") if attrs.color not in ("gray",) else shade(main, 0.6)
    g = [span("body", (0, -hy, 0), (d, hy, h), shade(main, 0.9), mat),
         span("grille", (d, -hy + 0.03, 0.02), (d + 0.005, hy - 0.03, 0.08), DARK),
         span("freezer_door", (d, -hy + 0.005, 0.09), (d + 0.04, hy - 0.005, split - 0.008), main, mat),
         span("split", (d, -hy + 0.005, split - 0.008), (d + 0.03, hy - 0.005, split + 0.008), DARK),
         span("fridge_door", (d, -hy + 0.005, split + 0.008), (d + 0.04, hy - 0.005, h - 0.01), main, mat),
         segment("freezer_handle", (d + 0.065, hy - 0.06, split - 0.25), (d + 0.065, hy - 0.06, split - 0.06), 0.012, metal, "metal"),
         segment("fridge_handle", (d + 0.065, hy - 0.06, split + 0.1), (d + 0.065, hy - 0.06, split + 0.6), 0.012, metal, "metal")]
    for k, z in enumerate((split - 0.155, split + 0.35)):
        for j, dz in enumerate((-0.08, 0.08) if k == 0 else (-0.24, 0.24)):
            g.append(segment(f"handle_mount{k}{j}", (d + 0.04, hy - 0.06, z + dz), (d + 0.06, hy - 0.06, z + dz), 0.01, metal, "metal"))
    return finish(g)


def build_stove(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A freestanding range: body, black glass cooktop with four burners
    (glowing when on; their tops are the support), a control backsplash with
    knobs, and an oven door with a window and a bar handle."""
    s = scale_of(attrs)
    hy, d, h = 0.38 * s, 0.62, 0.9
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    on = attrs.state == "on"
    g = [span("body", (0, -hy, 0), (d, hy, h), main, mat),
         span("cooktop", (0, -hy, h), (d, hy, h + 0.015), (0.05, 0.05, 0.06, 1.0), "glass"),
         span("backsplash", (0, -hy, h + 0.015), (0.07, hy, h + 0.17), shade(main, 0.9), mat),
         span("door", (d, -hy + 0.02, 0.14), (d + 0.03, hy - 0.02, h - 0.14), shade(main, 0.95), mat),
         span("window", (d + 0.03, -hy + 0.1, 0.28), (d + 0.033, hy - 0.1, h - 0.3),
              (0.95, 0.45, 0.1, 1.0) if on else SCREEN_OFF, "glass"),
         segment("handle", (d + 0.06, -hy + 0.06, h - 0.18), (d + 0.06, hy - 0.06, h - 0.18), 0.012, tint("metal"), "metal"),
         span("drawer", (d, -hy + 0.02, 0.02), (d + 0.02, hy - 0.02, 0.12), shade(main, 0.9), mat)]
    for k in range(4):
        x = 0.07 + (d - 0.07) * (0.3 if k % 2 == 0 else 0.72)
        y = (-1 if k < 2 else 1) * hy * 0.48
        r = 0.09 if k in (0, 3) else 0.07
        g.append(disk(f"burner{k}", r, 0.0015, (x, y, h + 0.0165), FLAME if on else (0.22, 0.22, 0.24, 1.0), "glass"))
    for k in range(4):
        y = -hy + (k + 0.5) * 2 * hy / 4
        g.append(disk(f"knob{k}", 0.022, 0.012, (0.082, y, h + 0.1), tint("metal"), "metal", axis="x"))
    return finish(g, (Surface(h + 0.018, ((d - 0.1) / 2 - 0.02, hy - 0.03), ((d + 0.1) / 2, 0.0)),))


def build_oven(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tall oven housing with two built-in ovens: fronts with control strips,
    windows (lit orange when on) and bar handles."""
    s = scale_of(attrs)
    hy, d, h = 0.32 * s, 0.6, 2.0 * hscale(s, 0.4)
    front = rgba(attrs.color, default="black")
    housing = (0.88, 0.86, 0.82, 1.0)
    on = attrs.state == "on"
    g = [span("housing", (0, -hy, 0), (d, hy, h), housing, "wood"),
         span("drawer", (d, -hy + 0.01, 0.1), (d + 0.02, hy - 0.01, 0.5), housing, "wood"),
         segment("drawer_handle", (d + 0.035, -0.1, 0.45), (d + 0.035, 0.1, 0.45), 0.008, tint("metal"), "metal")]
    for k, z0 in enumerate((0.55, 1.15)):
        z1 = z0 + 0.58
        g += [span(f"oven{k}", (d, -hy + 0.02, z0), (d + 0.025, hy - 0.02, z1), front, attrs.material),
              span(f"controls{k}", (d + 0.025, -hy + 0.03, z1 - 0.08), (d + 0.03, hy - 0.03, z1 - 0.02), shade(front, 0.6), "glass"),
              span(f"window{k}", (d + 0.025, -hy + 0.08, z0 + 0.08), (d + 0.028, hy - 0.08, z1 - 0.2),
                   (1.0, 0.55, 0.15, 1.0) if on else SCREEN_OFF, "glass"),
              segment(f"handle{k}", (d + 0.055, -hy + 0.05, z1 - 0.13), (d + 0.055, hy - 0.05, z1 - 0.13), 0.011, tint("metal"), "metal")]
    return finish(g)


def build_dishwasher(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A dishwasher: body under a worktop (the support), a full-height door with a control strip and a bar handle."""
    s = scale_of(attrs)
    hy, d, h = 0.3 * s, 0.58, 0.85
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    g = [span("toe_kick", (0, -hy + 0.01, 0), (d - 0.05, hy - 0.01, 0.09), DARK),
         span("body", (0, -hy, 0.09), (d, hy, h - 0.03), shade(main, 0.9), mat),
         span("worktop", (0, -hy, h - 0.03), (d + 0.02, hy, h), tint("stone"), "stone"),
         span("door", (d, -hy + 0.005, 0.1), (d + 0.03, hy - 0.005, h - 0.1), main, mat),
         span("control_strip", (d, -hy + 0.005, h - 0.1), (d + 0.02, hy - 0.005, h - 0.035), (0.2, 0.2, 0.22, 1.0), "plastic"),
         segment("handle", (d + 0.055, -hy + 0.08, h - 0.14), (d + 0.055, hy - 0.08, h - 0.14), 0.01, tint("metal"), "metal")]
    return finish(g, (Surface(h, ((d + 0.02) / 2 - 0.03, hy - 0.03), ((d + 0.02) / 2, 0.0)),))


def _front_loader(attrs: Attributes, rng: np.random.Generator, *, dryer: bool) -> Built:
    """A front-loading washer or dryer: body, control panel, a round door (swung open on its hinge when open)."""
    s = scale_of(attrs)
    hy, d, h = 0.3 * s, 0.6 * s, 0.85 * s
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    chrome = tint("metal")
    r = (0.21 if dryer else 0.19) * s
    zc = h * (0.48 if dryer else 0.45)
    g = [span("body", (0, -hy, 0), (d, hy, h), main, mat),
         span("panel", (d, -hy, h - 0.12 * s), (d + 0.015, hy, h), shade(main, 0.92), mat),
         disk("dial", 0.03 * s, 0.015, (d + 0.03, hy * (0.45 if dryer else 0.55), h - 0.06 * s), chrome, "metal", axis="x")]
    if dryer:
        g.append(span("display", (d + 0.015, -hy * 0.3, h - 0.09 * s), (d + 0.018, hy * 0.2, h - 0.03 * s), SCREEN_OFF, "glass"))
        g.append(span("vent", (d, -hy + 0.05, 0.02), (d + 0.006, hy - 0.05, 0.07), DARK))
        glass = (0.25, 0.25, 0.27, 1.0)
    else:
        g.append(span("drawer", (d + 0.015, -hy + 0.02, h - 0.1 * s), (d + 0.02, -hy + 0.2 * s, h - 0.03 * s), shade(main, 0.8), mat))
        glass = (0.3, 0.45, 0.6, 1.0)
    if attrs.state == "open":
        g.append(disk("opening", r * 0.82, 0.002, (d + 0.002, 0, zc), DARK, axis="x"))
        g.append(disk("drum", r * 0.7, 0.002, (d + 0.0045, 0, zc), (0.55, 0.57, 0.6, 1.0), "metal", axis="x"))
        hinge = np.array([d + 0.03, r, zc])
        ang = math.radians(100)
        direc = np.array([math.sin(ang), -math.cos(ang), 0.0])
        c = hinge + direc * r
        q = quat_from_z((math.cos(ang), math.sin(ang), 0.0))
        g.append(cylinder("door_ring", r, 0.025, tuple(c), chrome, "metal", quat=q))
        g.append(cylinder("door_glass", r * 0.78, 0.03, tuple(c), glass, "glass", quat=q))
    else:
        g.append(disk("door_ring", r, 0.025, (d + 0.025, 0, zc), chrome, "metal", axis="x"))
        g.append(disk("door_glass", r * 0.78, 0.03, (d + 0.03, 0, zc), glass, "glass", axis="x"))
    return finish(g, (Surface(h, (d / 2 - 0.03, hy - 0.03), (d / 2, 0.0)),))


def build_washing_machine(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A front-loading washing machine: a round glass door (open or closed), a dial and a detergent drawer; the top is a support."""
    return _front_loader(attrs, rng, dryer=False)


def build_dryer(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tumble dryer: a larger smoky round door, a dial, a display and a vent; the top is a support."""
    return _front_loader(attrs, rng, dryer=True)


def build_microwave(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A countertop microwave: body, a door with a window (lit yellow with a
    turntable plate when on), a side control panel with buttons."""
    s = scale_of(attrs)
    hy, d, h = 0.25 * s, 0.36 * s, 0.29 * s
    main = rgba(attrs.color, default="black")
    on = attrs.state == "on"
    g = [span("body", (0, -hy, 0.01), (d, hy, h), main, attrs.material),
         span("feet", (0.03, -hy + 0.03, 0), (d - 0.03, hy - 0.03, 0.01), DARK),
         span("door", (d, -hy + 0.01, 0.02), (d + 0.015, hy * 0.4, h - 0.01), shade(main, 0.85), attrs.material),
         span("window", (d + 0.015, -hy + 0.04, 0.05 * s), (d + 0.018, hy * 0.4 - 0.04, h - 0.05 * s),
              (1.0, 0.85, 0.45, 1.0) if on else SCREEN_OFF, "glass"),
         span("panel", (d, hy * 0.4 + 0.005, 0.02), (d + 0.01, hy - 0.01, h - 0.01), (0.15, 0.15, 0.17, 1.0), "plastic")]
    for k in range(3):
        z = h - 0.06 * s - k * 0.05 * s
        g.append(span(f"button{k}", (d + 0.01, hy * 0.55, z - 0.012), (d + 0.016, hy * 0.85, z + 0.012), (0.7, 0.7, 0.72, 1.0), "plastic"))
    if on:
        g.append(span("plate", (d + 0.018, -hy + 0.09, 0.06 * s), (d + 0.02, hy * 0.4 - 0.09, 0.08 * s), (0.95, 0.95, 0.9, 1.0), "glass"))
    return finish(g)


def build_toaster(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A two-slot toaster: a rounded body, two dark slots on top, a lever and feet."""
    s = scale_of(attrs)
    hx, hy, hz = 0.085 * s, 0.1 * s, 0.085 * s
    main = rgba(attrs.color, default="gray")
    z = 0.008 + hz
    g = [span("base", (-hx, -hy - 0.02 * s, 0), (hx, hy + 0.02 * s, 0.008), DARK, "plastic"),
         box("body", (hx, hy, hz), (0, 0, z), main, attrs.material),
         capsule("ends", hx, hy, (0, 0, z), main, attrs.material, quat=_AXIS_QUAT["y"])]
    for k, dx in enumerate((-0.035 * s, 0.035 * s)):
        g.append(span(f"slot{k}", (dx - 0.012 * s, -hy * 0.9, z + hz - 0.001), (dx + 0.012 * s, hy * 0.9, z + hz + 0.002), DARK))
    g.append(span("lever", (0.0, hy + hx - 0.01, z + 0.02), (0.03 * s, hy + hx + 0.02, z + 0.04), DARK, "plastic"))
    return finish(g)


def build_kettle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An electric kettle: a power base, a tapered body, a lid with a knob, a spout and a looped handle."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    r = 0.08 * s
    g = [disk("base", r * 1.05, 0.008, (0, 0, 0.008), DARK, "plastic"),
         disk("body", r, 0.07 * s, (0, 0, 0.016 + 0.07 * s), main, attrs.material),
         disk("shoulder", r * 0.85, 0.025 * s, (0, 0, 0.016 + 0.14 * s + 0.025 * s), main, attrs.material),
         disk("lid", r * 0.7, 0.006, (0, 0, 0.016 + 0.19 * s + 0.006), shade(main, 0.85), attrs.material),
         sphere("knob", 0.014 * s, (0, 0, 0.016 + 0.19 * s + 0.016), DARK, "plastic"),
         segment("spout", (r * 0.8, 0, 0.08 * s), (r + 0.05 * s, 0, 0.18 * s), 0.013 * s, main, attrs.material)]
    g += ring("handle", (-r, 0, 0.115 * s), (0.05 * s, 0.075 * s), 0.012 * s, 5, DARK, "plastic", u=(-1, 0, 0), v=(0, 0, 1),
              start=-math.pi / 2, stop=math.pi / 2)
    return finish(g)


def build_coffee_machine(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An espresso machine: a rear tower with a water tank, an overhanging head
    with a spout and buttons, a drip tray holding a small cup."""
    s = scale_of(attrs)
    hy = 0.12 * s
    main = rgba(attrs.color, default="black")
    mat = attrs.material
    h = 0.36 * s
    g = [span("tray", (-0.16 * s, -hy, 0), (0.17 * s, hy, 0.025 * s), (0.2, 0.2, 0.22, 1.0), "metal"),
         span("tower", (-0.17 * s, -hy, 0), (-0.02 * s, hy, h), main, mat),
         span("tank", (-0.2 * s, -hy * 0.8, 0.05 * s), (-0.17 * s, hy * 0.8, h - 0.04 * s), (0.6, 0.75, 0.85, 1.0), "glass"),
         span("head", (-0.17 * s, -hy, h - 0.07 * s), (0.15 * s, hy, h), main, mat),
         disk("spout", 0.018 * s, 0.015 * s, (0.08 * s, 0, h - 0.085 * s), tint("metal"), "metal"),
         disk("cup", 0.03 * s, 0.03 * s, (0.08 * s, 0, 0.025 * s + 0.03 * s), rgba("white"), "ceramic")]
    for k in range(3):
        g.append(disk(f"button{k}", 0.012 * s, 0.003, (0.1 * s, (k - 1) * 0.05 * s, h + 0.003), tint("metal"), "metal"))
    return finish(g)


# ---------------------------------------------------------------------------
# Electronics
# ---------------------------------------------------------------------------


def _screen_content(g: list, x: float, y0: float, y1: float, z0: float, z1: float, on: bool, desktop: bool) -> None:
    """Append a screen on the plane x: dark when off; when on, a bright picture
    (a landscape for televisions, a desktop with a window for monitors)."""
    if not on:
        g.append(span("screen", (x, y0, z0), (x + 0.003, y1, z1), SCREEN_OFF, "glass"))
        return
    w, hgt = y1 - y0, z1 - z0
    if desktop:
        g.append(span("screen", (x, y0, z0), (x + 0.003, y1, z1), (0.35, 0.6, 0.95, 1.0), "glass"))
        g.append(span("taskbar", (x + 0.003, y0, z0), (x + 0.004, y1, z0 + 0.07 * hgt), (0.12, 0.14, 0.2, 1.0), "glass"))
        g.append(span("window", (x + 0.003, y0 + 0.2 * w, z0 + 0.2 * hgt), (x + 0.004, y0 + 0.75 * w, z0 + 0.85 * hgt),
                      (0.97, 0.97, 0.97, 1.0), "glass"))
    else:
        g.append(span("screen", (x, y0, z0), (x + 0.003, y1, z1), (0.5, 0.78, 1.0, 1.0), "glass"))
        g.append(span("picture_ground", (x + 0.003, y0, z0), (x + 0.004, y1, z0 + 0.4 * hgt), (0.3, 0.7, 0.3, 1.0), "glass"))
        g.append(disk("picture_sun", 0.1 * hgt, 0.0005, (x + 0.0035, y0 + 0.75 * w, z0 + 0.72 * hgt), (1.0, 0.92, 0.4, 1.0), "glass",
                      axis="x"))


def build_television(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A flat-panel TV on a pedestal stand: bezel, screen (a bright picture when on, black when off)."""
    s = scale_of(attrs)
    hw, hh = 0.49 * s, 0.28 * s
    bezel = rgba(attrs.color, default="black")
    z0 = 0.1
    g = [span("foot", (-0.12, -0.3 * s, 0), (0.12, 0.3 * s, 0.015), bezel, attrs.material),
         span("neck", (-0.05, -0.05, 0.015), (-0.02, 0.05, z0 + 0.15), bezel, attrs.material),
         span("panel", (-0.02, -hw, z0), (0.01, hw, z0 + 2 * hh), bezel, attrs.material)]
    _screen_content(g, 0.01, -hw + 0.015, hw - 0.015, z0 + 0.015, z0 + 2 * hh - 0.015, attrs.state == "on", desktop=False)
    return finish(g)


def build_monitor(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A computer monitor: a thin panel on an arm and a flat base; the screen shows a desktop when on."""
    s = scale_of(attrs)
    hw, hh = 0.28 * s, 0.17 * s
    bezel = rgba(attrs.color, default="black")
    z0 = 0.1
    g = [span("base", (-0.11, -0.12, 0), (0.06, 0.12, 0.012), bezel, attrs.material),
         span("arm", (-0.08, -0.025, 0.012), (-0.06, 0.025, z0 + hh), bezel, attrs.material),
         span("panel", (-0.06, -hw, z0), (-0.04, hw, z0 + 2 * hh), bezel, attrs.material)]
    _screen_content(g, -0.04, -hw + 0.01, hw - 0.01, z0 + 0.015, z0 + 2 * hh - 0.01, attrs.state == "on", desktop=True)
    return finish(g)


def build_computer(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A desktop tower: a box with a front panel, a power button, a drive slot and vents."""
    s = scale_of(attrs)
    hx, hy, h = 0.2 * s, 0.09 * s, 0.42 * s
    main = rgba(attrs.color, default="black")
    front = shade(main, 1.4) if max(main[:3]) < 0.3 else shade(main, 0.85)
    g = [span("case", (-hx, -hy, 0.015), (hx, hy, h), main, attrs.material),
         span("feet", (-hx + 0.02, -hy + 0.01, 0), (hx - 0.02, hy - 0.01, 0.015), DARK),
         span("front", (hx, -hy + 0.008, 0.02), (hx + 0.008, hy - 0.008, h - 0.005), front, "plastic"),
         span("drive", (hx + 0.008, -hy + 0.02, h - 0.07), (hx + 0.01, hy - 0.02, h - 0.05), DARK),
         disk("power", 0.012, 0.003, (hx + 0.011, 0, h - 0.025), (0.3, 0.6, 1.0, 1.0), "plastic", axis="x")]
    for k in range(4):
        z = 0.06 + k * 0.035
        g.append(span(f"vent{k}", (hx + 0.008, -hy + 0.02, z), (hx + 0.01, hy - 0.02, z + 0.012), DARK))
    return finish(g)


def build_printer(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An inkjet/laser printer: a body with a scanner lid, a paper feed at the back, an output tray and a control panel."""
    s = scale_of(attrs)
    hx, hy, h = 0.18 * s, 0.22 * s, 0.2 * s
    main = rgba(attrs.color, default="white")
    lid = shade(main, 0.85) if max(main[:3]) > 0.3 else shade(main, 2.0)
    g = [span("body", (-hx, -hy, 0), (hx, hy, h - 0.02), main, attrs.material),
         span("lid", (-hx, -hy, h - 0.02), (hx - 0.02, hy, h), lid, attrs.material),
         span("slot", (hx, -hy + 0.05, 0.06 * s), (hx + 0.002, hy - 0.05, 0.09 * s), DARK),
         span("tray", (hx, -hy + 0.07, 0.045 * s), (hx + 0.12 * s, hy - 0.07, 0.055 * s), shade(main, 0.75), attrs.material),
         span("panel", (hx - 0.06, hy - 0.12, h - 0.02), (hx - 0.02, hy - 0.02, h + 0.005), (0.15, 0.15, 0.17, 1.0), "plastic"),
         box("paper", (0.004, hy - 0.08, 0.08 * s), (-hx + 0.01, 0, h + 0.06 * s), rgba("white"), "fabric",
             quat=quat_axis_angle((0, 1, 0), -math.radians(20)))]
    return finish(g)


def build_speaker(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A floor-standing tower speaker: a tall cabinet on a plinth with a tweeter and two woofer cones."""
    s = scale_of(attrs)
    hx, hy, h = 0.15 * s, 0.12 * s, 0.95 * hscale(s)
    main = rgba(attrs.color, default="black")
    cone = (0.1, 0.1, 0.11, 1.0)
    g = [span("plinth", (-hx - 0.02, -hy - 0.02, 0), (hx + 0.02, hy + 0.02, 0.03), DARK),
         span("cabinet", (-hx, -hy, 0.03), (hx, hy, h), main, attrs.material),
         disk("tweeter", 0.025 * s, 0.008, (hx + 0.008, 0, h - 0.09 * s), cone, "metal", axis="x"),
         sphere("tweeter_dome", 0.012 * s, (hx + 0.014, 0, h - 0.09 * s), tint("metal"), "metal")]
    for k, z in enumerate((h - 0.27 * s, h - 0.5 * s)):
        g.append(disk(f"woofer{k}", 0.08 * s, 0.008, (hx + 0.008, 0, z), cone, "plastic", axis="x"))
        g.append(disk(f"woofer_rim{k}", 0.088 * s, 0.004, (hx + 0.004, 0, z), (0.55, 0.55, 0.58, 1.0), "metal", axis="x"))
        g.append(sphere(f"dust_cap{k}", 0.025 * s, (hx + 0.012, 0, z), (0.2, 0.2, 0.22, 1.0), "plastic"))
    return finish(g)


def build_fan(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A pedestal fan: a round base, a pole, a motor housing, three blades and a guard ring."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    h = 1.15 * hscale(s)
    r = 0.22 * s
    g = [disk("base", 0.17 * s, 0.015, (0, 0, 0.015), main, attrs.material),
         disk("pole", 0.014, (h - 0.08) / 2, (0, 0, 0.03 + (h - 0.08) / 2), tint("metal"), "metal"),
         capsule("motor", 0.06 * s, 0.05 * s, (-0.02, 0, h), main, attrs.material, quat=_AXIS_QUAT["x"]),
         disk("hub", 0.04 * s, 0.015, (0.07 * s, 0, h), shade(main, 0.85), attrs.material, axis="x")]
    for k in range(3):
        a = 2 * math.pi * k / 3 + 0.3
        q = quat_axis_angle((1, 0, 0), a)
        g.append(ellipsoid(f"blade{k}", (0.006, 0.055 * s, 0.1 * s), (0.07 * s, -math.sin(a) * 0.1 * s, h + math.cos(a) * 0.1 * s),
                           (0.7, 0.85, 0.95, 1.0), "plastic", quat=q))
    g += ring("guard", (0.08 * s, 0, h), r, 0.006, 12, main, attrs.material, u=(0, 1, 0), v=(0, 0, 1))
    return finish(g)


def build_vacuum_cleaner(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An upright vacuum cleaner: a floor head with wheels, a tilted body with a clear bin, a handle pole and a grip."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="red")
    mat = attrs.material
    g = [span("head", (-0.05, -0.15 * s, 0.01), (0.22 * s, 0.15 * s, 0.07), main, mat),
         span("brush", (0.16 * s, -0.14 * s, 0.0), (0.22 * s, 0.14 * s, 0.012), DARK)]
    for k, sy in enumerate((1, -1)):
        g.append(disk(f"wheel{k}", 0.045, 0.015, (-0.04, sy * 0.12 * s, 0.045), DARK, "plastic", axis="y"))
    tilt = math.radians(12)
    base = np.array([-0.02, 0.0, 0.09])
    up = np.array([-math.sin(tilt), 0.0, math.cos(tilt)])
    g.append(segment("body", base, base + up * 0.45 * s, 0.075 * s, main, mat))
    g.append(segment("bin", base + up * 0.12 * s + np.array([0.05 * s, 0, 0]), base + up * 0.35 * s + np.array([0.05 * s, 0, 0]),
                     0.05 * s, (0.7, 0.8, 0.85, 1.0), "glass", kind="cylinder"))
    top = base + up * 1.0 * hscale(s)
    g.append(segment("pole", base + up * 0.5 * s, top, 0.014, tint("metal"), "metal", kind="cylinder"))
    g.append(segment("grip", top, top + np.array([0.07, 0, 0.05]), 0.02, DARK, "plastic"))
    return finish(g)


# ---------------------------------------------------------------------------
# Bathroom
# ---------------------------------------------------------------------------


def build_toilet(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A close-coupled toilet: pedestal, bowl, seat ring, a lid (down when
    closed, raised against the tank when open), a cistern with a flush button."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    mat = attrs.material or "ceramic"
    seat_z = 0.4 * s
    g = [ellipsoid("pedestal", (0.14 * s, 0.12 * s, 0.2 * s), (0.02, 0, 0.2 * s), main, mat),
         ellipsoid("bowl", (0.24 * s, 0.19 * s, 0.11 * s), (0.06 * s, 0, seat_z - 0.11 * s), main, mat),
         ellipsoid("seat", (0.24 * s, 0.19 * s, 0.015), (0.06 * s, 0, seat_z), shade(main, 0.96), mat),
         span("tank", (-0.33 * s, -0.2 * s, seat_z - 0.05), (-0.14 * s, 0.2 * s, seat_z + 0.36 * s), main, mat),
         span("tank_lid", (-0.34 * s, -0.21 * s, seat_z + 0.36 * s), (-0.13 * s, 0.21 * s, seat_z + 0.38 * s), shade(main, 0.95), mat),
         disk("flush", 0.02, 0.004, (-0.235 * s, 0, seat_z + 0.38 * s + 0.004), tint("metal"), "metal")]
    if attrs.state == "open":
        g.append(ellipsoid("opening", (0.16 * s, 0.12 * s, 0.004), (0.08 * s, 0, seat_z + 0.012), (0.72, 0.82, 0.88, 1.0), "ceramic"))
        g.append(ellipsoid("lid", (0.012, 0.18 * s, 0.22 * s), (-0.115 * s, 0, seat_z + 0.23 * s), main, mat,
                           quat=quat_axis_angle((0, 1, 0), -math.radians(8))))
    else:
        g.append(ellipsoid("lid", (0.23 * s, 0.18 * s, 0.012), (0.06 * s, 0, seat_z + 0.02), main, mat))
    return finish(g)


def build_sink(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A vanity: a two-door cabinet, a countertop with a round vessel basin
    (with a drain inside) and a mixer tap; the counter beside the basin is a support."""
    s = scale_of(attrs)
    hy, d, h = 0.42 * s, 0.48, 0.86
    main = rgba(attrs.color, default="white")
    basin = tint(attrs.material if attrs.material in ("ceramic", "metal", "stone") else "ceramic")
    bx, by, br = d / 2 + 0.04, -0.06 * s, 0.17
    g = [span("toe_kick", (0, -hy + 0.02, 0), (d - 0.05, hy - 0.02, 0.08), DARK),
         span("cabinet", (0, -hy, 0.08), (d, hy, h - 0.04), shade(main, 0.9), "wood"),
         span("counter", (0, -hy - 0.01, h - 0.04), (d + 0.02, hy + 0.01, h), main, attrs.material),
         disk("basin_foot", 0.11, 0.02, (bx, by, h + 0.02), basin, attrs.material),
         disk("basin", br, 0.035, (bx, by, h + 0.075), basin, attrs.material),
         disk("basin_inside", br - 0.015, 0.001, (bx, by, h + 0.111), mix(basin, (0.45, 0.55, 0.65), 0.45), attrs.material),
         disk("drain", 0.018, 0.0005, (bx, by, h + 0.1125), DARK, "metal"),
         disk("tap_base", 0.025, 0.02, (0.07, -0.06 * s, h + 0.02), tint("metal"), "metal"),
         segment("tap_neck", (0.07, -0.06 * s, h + 0.02), (0.07, -0.06 * s, h + 0.2), 0.012, tint("metal"), "metal"),
         segment("tap_spout", (0.07, -0.06 * s, h + 0.2), (0.2, -0.06 * s, h + 0.16), 0.011, tint("metal"), "metal")]
    _doors_front(g, d, -hy, hy, 0.1, h - 0.06, 2, main, "wood", False)
    y0 = by + br + 0.02
    return finish(g, (Surface(h, (0.13, (hy - 0.02 - y0) / 2), (d / 2 + 0.02, (hy - 0.02 + y0) / 2)),))


def build_bathtub(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A built-in bath: an apron front, thick rims, a white interior with water-blue floor, a tap at one end."""
    s = scale_of(attrs)
    hy, d, h = 0.85 * s, 0.76, 0.56
    main = rgba(attrs.color, default="white")
    mat = attrs.material or "ceramic"
    inner = rgba("white")
    t = 0.09
    g = [span("apron", (d - 0.04, -hy, 0), (d, hy, h - 0.02), main, mat),
         span("base", (0, -hy, 0), (d - 0.04, hy, 0.1), shade(main, 0.9), mat),
         span("floor", (t, -hy + t, 0.1), (d - t, hy - t, 0.12), (0.78, 0.88, 0.95, 1.0), mat),
         span("rim_back", (0, -hy, 0.1), (t, hy, h), main, mat),
         span("rim_front", (d - t, -hy, h - 0.03), (d, hy, h), main, mat),
         span("rim_end0", (0, hy - t, 0.1), (d, hy, h), main, mat),
         span("rim_end1", (0, -hy, 0.1), (d, -hy + t, h), main, mat),
         span("wall_front", (d - t, -hy + t, 0.1), (d - t + 0.02, hy - t, h - 0.03), inner, mat)]
    tap = tint("metal")
    g.append(segment("tap_riser", (t / 2, -hy + t / 2 + 0.05, h), (t / 2, -hy + t / 2 + 0.05, h + 0.12), 0.015, tap, "metal"))
    g.append(segment("tap_spout", (t / 2, -hy + t / 2 + 0.05, h + 0.12), (t / 2 + 0.03, -hy + t + 0.1, h + 0.1), 0.013, tap, "metal"))
    return finish(g)


def build_shower(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A shower enclosure: a tray, a tiled back panel, glass side and front panels
    in a metal frame, a riser with a round head and a mixer."""
    s = scale_of(attrs)
    hy, d, h = 0.45 * s, 0.9 * s, 2.0
    tile = rgba(attrs.color, default="white")
    glass = (0.75, 0.88, 0.95, 0.35)
    metal = tint("metal")
    g = [span("tray", (0, -hy, 0), (d, hy, 0.06), rgba("white"), "ceramic"),
         span("back", (0, -hy, 0.06), (0.03, hy, h), tile, attrs.material),
         span("side_glass", (0.03, hy - 0.008, 0.06), (d, hy, h - 0.02), glass, "glass"),
         span("front_glass", (d - 0.008, -hy, 0.06), (d, hy - 0.01, h - 0.02), glass, "glass"),
         span("frame_top_side", (0.03, hy - 0.015, h - 0.02), (d, hy, h), metal, "metal"),
         span("frame_top_front", (d - 0.015, -hy, h - 0.02), (d, hy, h), metal, "metal"),
         segment("door_handle", (d + 0.025, -hy * 0.2, 0.9), (d + 0.025, -hy * 0.2, 1.2), 0.012, metal, "metal"),
         disk("drain", 0.04, 0.001, (d / 2, 0, 0.061), metal, "metal"),
         segment("riser", (0.05, 0.0, 1.0), (0.05, 0.0, 1.9), 0.012, metal, "metal"),
         segment("arm", (0.05, 0.0, 1.9), (0.18, 0.0, 1.9), 0.01, metal, "metal"),
         cylinder("head", 0.08, 0.012, (0.2, 0.0, 1.88), metal, "metal", quat=quat_axis_angle((0, 1, 0), math.radians(25))),
         disk("mixer", 0.035, 0.02, (0.05, 0.0, 1.05), metal, "metal", axis="x")]
    return finish(g)


def build_radiator(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A column radiator: vertical sections between top and bottom headers, on two feet, with a valve."""
    s = scale_of(attrs)
    n = max(6, int(round(12 * s)))
    main = rgba(attrs.color, default="white")
    pitch = 0.065
    w = (n - 1) * pitch
    z0, z1 = 0.12, 0.7
    g = []
    for k in range(n):
        y = -w / 2 + k * pitch
        g.append(segment(f"column{k}", (0.06, y, z0 + 0.03), (0.06, y, z1 - 0.03), 0.025, main, attrs.material))
    g.append(segment("header_top", (0.06, -w / 2, z1 - 0.04), (0.06, w / 2, z1 - 0.04), 0.02, main, attrs.material))
    g.append(segment("header_bottom", (0.06, -w / 2, z0 + 0.04), (0.06, w / 2, z0 + 0.04), 0.02, main, attrs.material))
    for k, sy in enumerate((1, -1)):
        g.append(span(f"foot{k}", (0.03, sy * (w / 2 - 0.06) - 0.015, 0), (0.09, sy * (w / 2 - 0.06) + 0.015, z0), main, attrs.material))
    g.append(disk("valve", 0.02, 0.03, (0.06, w / 2 + 0.06, z0 + 0.04), tint("metal"), "metal", axis="y"))
    g.append(span("wall_bracket", (0.0, -0.02, z1 - 0.06), (0.04, 0.02, z1 - 0.02), main, attrs.material))
    return finish(g)


def build_fireplace(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A chimney breast fireplace: a surround with a dark firebox, a mantel shelf
    (the support), a hearth slab and logs; on adds flames."""
    s = scale_of(attrs)
    hy, d, h = 0.7 * s, 0.32, 1.1
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    ow, oh = 0.42 * s, 0.62
    g = [span("breast", (0, -hy, 0), (0.06, hy, h), main, mat),
         span("jamb0", (0, ow, 0), (d, hy, h - 0.05), main, mat),
         span("jamb1", (0, -hy, 0), (d, -ow, h - 0.05), main, mat),
         span("lintel", (0, -ow, oh), (d, ow, h - 0.05), main, mat),
         span("firebox", (0.06, -ow, 0.04), (0.1, ow, oh), DARK),
         span("mantel", (0, -hy - 0.06, h - 0.05), (d + 0.06, hy + 0.06, h), shade(main, 0.85), mat),
         span("hearth", (0, -hy - 0.05, 0), (d + 0.35, hy + 0.05, 0.04), tint("stone"), "stone")]
    for k in range(2):
        g.append(disk(f"log{k}", 0.045, ow * 0.65, (0.16 + 0.07 * k, 0, 0.085 + 0.06 * k), (0.4, 0.24, 0.12, 1.0), "wood", axis="y"))
    if attrs.state == "on":
        for k, (y, hz) in enumerate(((-0.12, 0.13), (0.0, 0.18), (0.13, 0.12))):
            g.append(ellipsoid(f"flame{k}", (0.04, 0.07, hz), (0.18, y * s, 0.15 + hz * 0.8), FLAME, "glass"))
        g.append(ellipsoid("flame_core", (0.03, 0.05, 0.09), (0.2, 0, 0.2), LIGHT_ON, "glass"))
    return finish(g, (Surface(h, ((d + 0.06) / 2 - 0.02, hy - 0.02), ((d + 0.06) / 2, 0.0)),))


def build_piano(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An upright piano: a tall case, a keybed with white and black keys, a
    music desk, front legs and pedals; the lid is a support."""
    s = scale_of(attrs)
    hy, h = 0.75 * s, 1.22
    main = rgba(attrs.color, default="black")
    mat = attrs.material
    white = rgba("white")
    g = [span("case", (0, -hy, 0), (0.32, hy, h), main, mat),
         span("lid", (0, -hy - 0.01, h - 0.02), (0.34, hy + 0.01, h), shade(main, 1.3) if max(main[:3]) < 0.2 else shade(main, 0.9), mat),
         span("keybed", (0.32, -hy, 0.64), (0.6, hy, 0.72), main, mat),
         span("white_keys", (0.34, -hy + 0.06, 0.72), (0.58, hy - 0.06, 0.745), white, "plastic"),
         span("key_slip", (0.58, -hy + 0.06, 0.72), (0.6, hy - 0.06, 0.755), main, mat),
         span("fallboard", (0.32, -hy + 0.04, 0.72), (0.34, hy - 0.04, 0.82), main, mat),
         box("music_desk", (0.01, hy * 0.4, 0.1), (0.35, 0, 0.95), main, mat, quat=quat_axis_angle((0, 1, 0), -math.radians(12)))]
    span_keys = 2 * hy - 0.12
    octaves = 4  # drawn wider than real octaves: the pattern of twos and threes is what reads as a keyboard
    ow = span_keys / octaves
    k = 0
    for o in range(octaves):
        for off in (1, 2, 4, 5, 6):  # black keys sit between white keys C-D, D-E, F-G, G-A, A-B
            y = -hy + 0.06 + o * ow + off / 7 * ow
            g.append(span(f"black_key{k}", (0.42, y - 0.006, 0.745), (0.58, y + 0.006, 0.765), rgba("black"), "plastic"))
            k += 1
    for j, sy in enumerate((1, -1)):
        g.append(segment(f"leg{j}", (0.55, sy * (hy - 0.05), 0.0), (0.55, sy * (hy - 0.05), 0.64), 0.03, main, mat, kind="cylinder"))
    for j in range(2):
        g.append(span(f"pedal{j}", (0.32, -0.06 + j * 0.08, 0.06), (0.4, -0.04 + j * 0.08, 0.075), (0.85, 0.7, 0.3, 1.0), "metal"))
    return finish(g, (Surface(h, (0.15, hy - 0.04), (0.17, 0.0)),))


def build_safe(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A steel safe: a heavy cube with an inset door, hinges, a combination dial and a spoked handle."""
    s = scale_of(attrs)
    c = 0.22 * s
    main = rgba(attrs.color, default="gray")
    metal = tint("metal")
    g = [span("body", (-c, -c, 0.02), (c, c, 2 * c + 0.02), main, attrs.material),
         span("feet", (-c + 0.02, -c + 0.02, 0), (c - 0.02, c - 0.02, 0.02), DARK),
         span("door", (c, -c + 0.03, 0.05), (c + 0.02, c - 0.03, 2 * c - 0.01), shade(main, 0.85), attrs.material),
         disk("dial", 0.045 * s, 0.01, (c + 0.03, -0.03, c + 0.1 * s), metal, "metal", axis="x"),
         disk("hub", 0.015, 0.015, (c + 0.035, 0.08 * s, c - 0.06 * s), metal, "metal", axis="x")]
    for k in range(3):
        a = 2 * math.pi * k / 3
        end = (c + 0.045, 0.08 * s + 0.06 * s * math.cos(a), c - 0.06 * s + 0.06 * s * math.sin(a))
        g.append(segment(f"spoke{k}", (c + 0.045, 0.08 * s, c - 0.06 * s), end, 0.007, metal, "metal"))
    for k, z in enumerate((0.12, 2 * c - 0.08)):
        g.append(disk(f"hinge{k}", 0.012, 0.035, (c + 0.01, c - 0.03, z), metal, "metal"))
    return finish(g)


# ---------------------------------------------------------------------------
# Wall-mounted
# ---------------------------------------------------------------------------


def build_painting(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A framed canvas hung on a wall, the picture (a ground colour with two
    shapes) facing +x."""
    s = scale_of(attrs)
    hy, hz, t = 0.4 * s, 0.3 * s, 0.02
    frame = tint(attrs.material)
    ground = rgba(attrs.color)
    x = 2 * t + 0.003
    g = [box("frame", (t, hy, hz), (t, 0, hz), frame, attrs.material),
         box("canvas", (0.003, hy * 0.88, hz * 0.85), (x, 0, hz), ground, "fabric")]
    accents = [c for c in vocab.COLORS if c != attrs.color]
    y = float(rng.uniform(-0.4, 0.1)) * hy
    g.append(span("shape0", (x + 0.003, y - 0.25 * hy, 0.35 * hz), (x + 0.004, y + 0.25 * hy, 1.05 * hz), rgba(_pick(rng, accents)),
                  "fabric"))
    g.append(disk("shape1", 0.22 * hz, 0.0006, (x + 0.0045, float(rng.uniform(0.25, 0.55)) * hy, 1.3 * hz), rgba(_pick(rng, accents)),
                  "fabric", axis="x"))
    return finish(g)


def build_mirror(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A framed wall mirror; the silvered glass faces +x."""
    s = scale_of(attrs)
    hy, hz = 0.3 * s, 0.45 * s
    frame = rgba(attrs.color, default="brown")
    g = [span("frame", (0, -hy, 0), (0.03, hy, 2 * hz), frame, attrs.material),
         span("glass", (0.03, -hy + 0.04, 0.04), (0.034, hy - 0.04, 2 * hz - 0.04), (0.8, 0.87, 0.92, 1.0), "glass"),
         span("glint", (0.034, -hy + 0.08, 2 * hz - 0.25 * s), (0.035, -hy + 0.1, 2 * hz - 0.08), (0.97, 0.98, 1.0, 1.0), "glass")]
    return finish(g)


def build_wall_clock(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A round wall clock: a rim, a white face with twelve ticks, hour and minute hands and a centre pin."""
    s = scale_of(attrs)
    r = 0.16 * s
    rim = rgba(attrs.color, default="black")
    ink = rgba("black") if attrs.color != "black" else (0.1, 0.1, 0.1, 1.0)
    g = [disk("rim", r, 0.022, (0.022, 0, r), rim, attrs.material, axis="x"),
         disk("face", r * 0.88, 0.003, (0.047, 0, r), rgba("white"), "plastic", axis="x")]
    for k in range(12):
        a = 2 * math.pi * k / 12
        ln = 0.018 * s if k % 3 == 0 else 0.009 * s
        c = r * 0.8 - ln / 2
        g.append(box(f"tick{k}", (0.001, 0.004 if k % 3 == 0 else 0.002, ln / 2), (0.051, -math.sin(a) * c, r + math.cos(a) * c), ink,
                     "plastic", quat=quat_axis_angle((1, 0, 0), a)))
    hour = float(rng.uniform(0, 2 * math.pi))
    minute = float(rng.uniform(0, 2 * math.pi))
    for name, a, ln, w, x in (("hour_hand", hour, 0.45 * r, 0.006, 0.052), ("minute_hand", minute, 0.72 * r, 0.004, 0.054)):
        g.append(box(name, (0.001, w, ln / 2), (x, -math.sin(a) * ln / 2, r + math.cos(a) * ln / 2), ink, "metal",
                     quat=quat_axis_angle((1, 0, 0), a)))
    g.append(disk("pin", 0.008, 0.004, (0.055, 0, r), ink, "metal", axis="x"))
    return finish(g)


def build_curtain(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A curtain on a rod: closed, pleats hang across the whole width; open,
    they are gathered at both sides and tied back. Size scales the width only."""
    s = scale_of(attrs)
    width, h = 1.6 * s, 2.2
    main = rgba(attrs.color, default="beige")
    rod = tint("metal")
    g = [segment("rod", (0.1, -width / 2 - 0.06, h), (0.1, width / 2 + 0.06, h), 0.014, rod, "metal"),
         sphere("finial0", 0.03, (0.1, width / 2 + 0.09, h), rod, "metal"),
         sphere("finial1", 0.03, (0.1, -width / 2 - 0.09, h), rod, "metal")]
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"bracket{k}", (0.0, sy * (width / 2 - 0.02), h), (0.1, sy * (width / 2 - 0.02), h), 0.01, rod, "metal"))

    def pleats(prefix: str, y0: float, y1: float, pitch: float, angle: float) -> None:
        """Accordion folds from y0 to y1: panels alternately turned +-angle about z."""
        n = max(2, int(round(abs(y1 - y0) / pitch)))
        step = (y1 - y0) / n
        half = abs(step) / 2 / math.cos(angle)
        for k in range(n):
            sign = 1 if k % 2 else -1
            q = quat_axis_angle((0, 0, 1), sign * angle)
            g.append(box(f"{prefix}{k}", (0.004, half, (h - 0.05) / 2), (0.1, y0 + (k + 0.5) * step, (h - 0.05) / 2),
                         main if k % 2 else shade(main, 0.85), attrs.material, quat=q))

    if attrs.state == "open":
        bundle = 0.22 * s
        for side, sy in enumerate((1, -1)):
            pleats(f"pleat{side}_", sy * (width / 2 + 0.02), sy * (width / 2 - bundle), 0.035, math.radians(65))
            g.append(ellipsoid(f"tieback{side}", (0.06, bundle / 2 + 0.02, 0.025), (0.1, sy * (width / 2 - bundle / 2 + 0.01), 1.0),
                               shade(main, 0.7), attrs.material))
    else:
        pleats("pleat", -width / 2 - 0.02, width / 2 + 0.02, 0.09, math.radians(35))
    return finish(g)


def build_towel_rack(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A wall towel bar on two brackets with a towel folded over it."""
    s = scale_of(attrs)
    hw = 0.3 * s
    main = rgba(attrs.color, default="gray")
    towel = rgba(_pick(rng, ("white", "beige", "blue", "gray", "pink", "green")))
    bar_z, bar_x = 0.5 * s, 0.08
    g = [segment("bar", (bar_x, -hw, bar_z), (bar_x, hw, bar_z), 0.011, main, attrs.material)]
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"bracket{k}", (0.0, sy * hw, bar_z), (bar_x, sy * hw, bar_z), 0.012, main, attrs.material))
        g.append(disk(f"rose{k}", 0.025, 0.006, (0.006, sy * hw, bar_z), main, attrs.material, axis="x"))
    tw = hw - 0.06
    g += [segment("towel_fold", (bar_x, -tw, bar_z + 0.012), (bar_x, tw, bar_z + 0.012), 0.02, towel, "fabric"),
          span("towel_front", (bar_x + 0.013, -tw, 0.0), (bar_x + 0.03, tw, bar_z + 0.012), towel, "fabric"),
          span("towel_back", (bar_x - 0.03, -tw, 0.12 * s), (bar_x - 0.013, tw, bar_z + 0.012), shade(towel, 0.9), "fabric")]
    return finish(g)


# ---------------------------------------------------------------------------
# Floor objects
# ---------------------------------------------------------------------------


def build_coat_rack(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A standing coat rack: splayed feet, a pole, two tiers of hooks, a knob and a coat or two."""
    s = hscale(scale_of(attrs))
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    h = 1.75 * s
    g = []
    for k in range(4):
        a = math.pi / 4 + k * math.pi / 2
        g.append(segment(f"foot{k}", (0.0, 0.0, 0.2), (0.28 * math.cos(a), 0.28 * math.sin(a), 0.02), 0.02, main, mat))
    g.append(disk("pole", 0.022, h / 2 - 0.01, (0, 0, h / 2), main, mat))
    g.append(sphere("knob", 0.04, (0, 0, h + 0.02), main, mat))
    for tier, (z, a0) in enumerate(((h - 0.1, 0.0), (h - 0.3, math.pi / 4))):
        for k in range(4):
            a = a0 + k * math.pi / 2
            g.append(segment(f"hook{tier}_{k}", (0.0, 0.0, z - 0.04), (0.13 * math.cos(a), 0.13 * math.sin(a), z + 0.05), 0.01, main, mat))
    for k in range(int(rng.integers(0, 3))):
        a = k * math.pi + math.pi / 2 + float(rng.uniform(-0.3, 0.3))
        c = rgba(_pick(rng, ("black", "brown", "gray", "blue", "beige", "red", "green")))
        q = quat_axis_angle((0, 0, 1), a)
        px, py = 0.2 * math.cos(a), 0.2 * math.sin(a)
        tx, ty = -math.sin(a), math.cos(a)
        g.append(segment(f"coat{k}_shoulders", (px - 0.16 * tx, py - 0.16 * ty, h - 0.2), (px + 0.16 * tx, py + 0.16 * ty, h - 0.2), 0.06,
                         c, "fabric"))
        g.append(ellipsoid(f"coat{k}", (0.11, 0.24, 0.38), (px, py, h - 0.52), c, "fabric", quat=q))
    return finish(g)


def _leaves(g: list, rng: np.random.Generator, base, n_stems: int, height: tuple[float, float], leaf: tuple[float, float],
            color, spread: float) -> list:
    """Append stems rising from ``base`` with leaves along them; returns the stem tips."""
    bx, by, bz = base
    tips = []
    for k in range(n_stems):
        yaw = 2 * math.pi * k / n_stems + float(rng.uniform(-0.4, 0.4))
        lean = float(rng.uniform(0.1, spread))
        hgt = float(rng.uniform(*height))
        tip = np.array([bx + math.sin(lean) * math.cos(yaw) * hgt, by + math.sin(lean) * math.sin(yaw) * hgt, bz + math.cos(lean) * hgt])
        g.append(segment(f"stem{k}", (bx, by, bz), tip, 0.006, (0.25, 0.4, 0.18, 1.0), "wood"))
        for j, f in enumerate((0.55, 1.0)):
            p = np.array([bx, by, bz]) + f * (tip - np.array([bx, by, bz]))
            a = yaw + (0.0 if j else math.pi / 2)
            q = quat_mul(quat_axis_angle((0, 0, 1), a), quat_axis_angle((0, 1, 0), math.radians(20)))
            c = shade(color, float(rng.uniform(0.8, 1.15)))
            centre = p + np.array([math.cos(a), math.sin(a), 0]) * leaf[0] * 0.8
            g.append(ellipsoid(f"leaf{k}_{j}", (leaf[0], leaf[1], 0.008), tuple(centre), c, "fabric", quat=q))
        tips.append(tip)
    return tips


def build_potted_plant(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A floor plant: a flared pot (showing its material), soil, a trunk with
    branches and clumps of foliage in its colour."""
    s = scale_of(attrs)
    pot = tint(attrs.material or "ceramic")
    foliage = rgba(attrs.color, default="green")
    top = 0.34 * s
    g = [disk("pot_base", 0.11 * s, 0.06 * s, (0, 0, 0.06 * s), shade(pot, 0.9), attrs.material),
         disk("pot_body", 0.145 * s, 0.1 * s, (0, 0, 0.12 * s + 0.1 * s), pot, attrs.material),
         disk("pot_rim", 0.16 * s, 0.01 * s, (0, 0, top - 0.01 * s), shade(pot, 0.95), attrs.material),
         disk("soil", 0.14 * s, 0.003, (0, 0, top + 0.001), (0.25, 0.17, 0.1, 1.0), "stone")]
    bark = (0.4, 0.28, 0.16, 1.0)
    crown = np.array([0.0, 0.0, top + 0.45 * s])
    g.append(segment("trunk", (0, 0, top), crown, 0.018 * s, bark, "wood"))
    n = 7
    for k in range(n):
        a = 2 * math.pi * k / n + float(rng.uniform(-0.3, 0.3))
        up = float(rng.uniform(-0.1, 0.35)) * s
        reach = float(rng.uniform(0.14, 0.22)) * s
        c = crown + np.array([reach * math.cos(a), reach * math.sin(a), up])
        if k % 2 == 0:
            g.append(segment(f"branch{k}", crown - np.array([0, 0, 0.12 * s]), c, 0.01 * s, bark, "wood"))
        semi = np.array([0.15, 0.13, 0.11]) * s * float(rng.uniform(0.85, 1.15))
        g.append(ellipsoid(f"foliage{k}", tuple(semi), tuple(c), shade(foliage, float(rng.uniform(0.75, 1.15))), "fabric",
                           quat=quat_axis_angle((0, 0, 1), a)))
    g.append(ellipsoid("foliage_top", (0.14 * s, 0.14 * s, 0.12 * s), tuple(crown + np.array([0, 0, 0.3 * s])), foliage, "fabric"))
    return finish(g)


def build_houseplant_small(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A small flowering plant in a pot: green leaves and blossoms in its colour."""
    s = scale_of(attrs)
    pot = tint(attrs.material or "ceramic")
    bloom = rgba(attrs.color, default="pink")
    g = [disk("pot", 0.055 * s, 0.045 * s, (0, 0, 0.045 * s), pot, attrs.material),
         disk("pot_rim", 0.062 * s, 0.008 * s, (0, 0, 0.09 * s - 0.008 * s), shade(pot, 0.92), attrs.material),
         disk("soil", 0.05 * s, 0.002, (0, 0, 0.091 * s), (0.25, 0.17, 0.1, 1.0), "stone")]
    tips = _leaves(g, rng, (0.0, 0.0, 0.09 * s), 4, (0.09 * s, 0.15 * s), (0.04 * s, 0.018 * s), rgba("green"), 0.6)
    for k, t in enumerate(tips):
        g.append(sphere(f"bloom{k}", 0.022 * s, tuple(t + np.array([0, 0, 0.012 * s])), bloom, "fabric"))
        eye = rgba("yellow") if attrs.color != "yellow" else rgba("orange")
        g.append(sphere(f"bloom_eye{k}", 0.008 * s, tuple(t + np.array([0, 0, 0.03 * s])), eye, "fabric"))
    return finish(g)


def build_floor_lamp(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A floor lamp: a weighted base, a pole and a drum shade (glowing, with a lit diffuser, when on)."""
    s = scale_of(attrs)
    hs = hscale(s)
    main = rgba(attrs.color, default="beige")
    on = attrs.state == "on"
    metal = tint(attrs.material or "metal")
    h = 1.35 * hs
    r = 0.2 * s
    sh = 0.16 * hs
    g = [disk("base", 0.15 * s, 0.012, (0, 0, 0.012), metal, attrs.material),
         disk("pole", 0.012, h / 2, (0, 0, 0.024 + h / 2), metal, attrs.material),
         disk("shade", r, sh, (0, 0, 0.024 + h + sh * 0.6), glow(main) if on else main, "fabric"),
         disk("diffuser", r * 0.95, 0.002, (0, 0, 0.024 + h - sh * 0.4 - 0.003), LIGHT_ON if on else shade(main, 0.6), "glass")]
    if on:
        g.append(sphere("bulb", 0.035, (0, 0, 0.024 + h - sh * 0.4 - 0.03), LIGHT_ON, "glass"))
    return finish(g)


def build_rug(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A flat area rug: a field in its colour, a contrasting border and a central medallion."""
    s = scale_of(attrs)
    hx, hy = 0.7 * s, 1.0 * s
    main = rgba(attrs.color, default="red")
    trim = shade(main, 0.55) if max(main[:3]) > 0.5 else shade(mix(main, rgba("beige"), 0.6), 1.0)
    b = 0.08 * s
    g = [span("field", (-hx, -hy, 0), (hx, hy, 0.01), main, attrs.material),
         span("border0", (-hx, -hy, 0.0), (-hx + b, hy, 0.013), trim, attrs.material),
         span("border1", (hx - b, -hy, 0.0), (hx, hy, 0.013), trim, attrs.material),
         span("border2", (-hx + b, -hy, 0.0), (hx - b, -hy + b, 0.013), trim, attrs.material),
         span("border3", (-hx + b, hy - b, 0.0), (hx - b, hy, 0.013), trim, attrs.material),
         ellipsoid("medallion", (0.3 * s, 0.42 * s, 0.0025), (0, 0, 0.01), trim, attrs.material)]
    return finish(g)


def build_trash_can(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A pedal bin: a cylindrical body on a base ring, a rim, a domed lid and a foot pedal."""
    s = scale_of(attrs)
    r, h = 0.15 * s, 0.58 * s
    main = rgba(attrs.color, default="gray")
    mat = attrs.material
    g = [disk("base", r * 0.97, 0.015, (0, 0, 0.015), DARK, "plastic"),
         disk("body", r, (h - 0.05) / 2, (0, 0, 0.03 + (h - 0.05) / 2), main, mat),
         disk("rim", r + 0.006, 0.012, (0, 0, h - 0.02), shade(main, 0.8), mat),
         ellipsoid("lid", (r + 0.004, r + 0.004, 0.035 * s), (0, 0, h - 0.008), shade(main, 1.1), mat),
         span("pedal", (r - 0.02, -0.05, 0.02), (r + 0.06, 0.05, 0.04), DARK, "plastic")]
    return finish(g)


def build_laundry_basket(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A hamper: a woven round body with bands, a rim, hand holds and a dark
    opening; full heaps clothes above the rim."""
    s = scale_of(attrs)
    r, h = 0.22 * s, 0.52 * s
    main = rgba(attrs.color, default="beige")
    mat = attrs.material
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, mat),
         disk("rim", r + 0.012, 0.012, (0, 0, h - 0.012), shade(main, 0.8), mat),
         disk("opening", r - 0.01, 0.001, (0, 0, h + 0.001), (0.15, 0.12, 0.1, 1.0))]
    for k in range(3):
        g.append(disk(f"band{k}", r + 0.004, 0.008, (0, 0, 0.08 * s + k * 0.13 * s), shade(main, 0.75), mat))
    for k, sy in enumerate((1, -1)):
        g.append(span(f"handhold{k}", (-0.05, sy * (r + 0.003) - 0.002, h - 0.08), (0.05, sy * (r + 0.003) + 0.002, h - 0.05), DARK))
    if attrs.state == "full":
        for k in range(4):
            a = k * math.pi / 2 + float(rng.uniform(-0.4, 0.4))
            pos = (0.07 * s * math.cos(a), 0.07 * s * math.sin(a), h + 0.02 * s)
            g.append(ellipsoid(f"clothes{k}", (0.12 * s, 0.08 * s, 0.06 * s), pos, rgba(_pick(rng, vocab.COLORS)), "fabric",
                               quat=quat_axis_angle((0, 0, 1), a)))
    return finish(g)


def build_toolbox(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A metal tool box: a body, a lid, a carry handle on posts and two latches."""
    s = scale_of(attrs)
    hx, hy, h = 0.11 * s, 0.23 * s, 0.2 * s
    main = rgba(attrs.color, default="red")
    metal = tint("metal")
    g = [span("body", (-hx, -hy, 0), (hx, hy, h - 0.035 * s), main, attrs.material),
         span("lid", (-hx - 0.004, -hy - 0.004, h - 0.035 * s), (hx + 0.004, hy + 0.004, h), shade(main, 0.85), attrs.material),
         segment("handle", (0, -hy * 0.55, h + 0.04 * s), (0, hy * 0.55, h + 0.04 * s), 0.012, DARK, "plastic")]
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"handle_post{k}", (0, sy * hy * 0.55, h), (0, sy * hy * 0.55, h + 0.04 * s), 0.008, metal, "metal"))
        g.append(span(f"latch{k}", (hx, sy * hy * 0.6 - 0.015, h - 0.07 * s), (hx + 0.008, sy * hy * 0.6 + 0.015, h - 0.02 * s), metal,
                      "metal"))
    return finish(g)


def build_bicycle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A bicycle: two spoked wheels with tyres, a diamond frame in its colour,
    a fork, a saddle, handlebars and a chainring."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="red")
    mat = attrs.material or "metal"
    tyre = (0.06, 0.06, 0.06, 1.0)
    metal = tint("metal")
    rw, tube = 0.32 * s, 0.022
    zc = rw + tube
    wx = 0.52 * s
    g = []
    for w, x in enumerate((-wx, wx)):
        g += ring(f"tyre{w}_", (x, 0, zc), rw, tube, 10, tyre, "plastic", u=(1, 0, 0), v=(0, 0, 1))
        g.append(disk(f"hub{w}", 0.03, 0.05, (x, 0, zc), metal, "metal", axis="y"))
        for k in range(3):
            a = k * math.pi / 3 + 0.2
            d = np.array([math.cos(a), 0, math.sin(a)]) * (rw - 0.01)
            g.append(segment(f"spoke{w}_{k}", np.array([x, 0, zc]) - d, np.array([x, 0, zc]) + d, 0.003, metal, "metal", kind="cylinder"))
    rear, front = np.array([-wx, 0, zc]), np.array([wx, 0, zc])
    bb = np.array([-0.04 * s, 0, 0.3 * s])
    seat = np.array([-0.2 * s, 0, 0.82 * s])
    head_top = np.array([0.42 * s, 0, 0.86 * s])
    head_bot = np.array([0.45 * s, 0, 0.72 * s])
    r = 0.018
    for name, a, b in (("chain_stay", rear, bb), ("seat_stay", rear, seat), ("seat_tube", bb, seat), ("top_tube", seat, head_top),
                       ("down_tube", bb, head_bot), ("head_tube", head_bot, head_top), ("fork", head_bot, front)):
        g.append(segment(name, a, b, r, main, mat))
    post = seat + np.array([-0.03 * s, 0, 0.1 * s])
    g.append(segment("seat_post", seat, post, 0.013, metal, "metal"))
    g.append(ellipsoid("saddle", (0.13 * s, 0.06 * s, 0.025), tuple(post + np.array([0.02, 0, 0.02])), DARK, "leather"))
    stem = head_top + np.array([-0.02 * s, 0, 0.12 * s])
    g.append(segment("stem", head_top, stem, 0.014, metal, "metal"))
    g.append(segment("handlebar", stem + np.array([0, -0.26 * s, 0]), stem + np.array([0, 0.26 * s, 0]), 0.012, DARK, "metal"))
    g.append(disk("chainring", 0.1 * s, 0.004, tuple(bb + np.array([0, 0.05, 0])), metal, "metal", axis="y"))
    g.append(segment("crank", bb + np.array([0, 0.06, 0]), bb + np.array([0.06 * s, 0.06, -0.14 * s]), 0.01, metal, "metal"))
    return finish(g)


def build_ladder(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An A-frame stepladder: two front rails with four treads, two rear legs,
    spreader bars and a top cap."""
    s = hscale(scale_of(attrs))
    main = rgba(attrs.color, default="gray")
    mat = attrs.material
    h = 1.5 * s
    g = []
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"rail{k}", (0.32 * s, sy * 0.22, 0.02), (0.06, sy * 0.18, h - 0.03), 0.02, main, mat))
        g.append(segment(f"rear_leg{k}", (-0.32 * s, sy * 0.22, 0.02), (-0.06, sy * 0.18, h - 0.03), 0.018, main, mat))
        g.append(segment(f"spreader{k}", (0.2 * s, sy * 0.2, 0.6 * s), (-0.2 * s, sy * 0.2, 0.6 * s), 0.006, tint("metal"), "metal"))
    for k in range(4):
        f = (k + 1) / 5
        x = 0.32 * s + f * (0.06 - 0.32 * s)
        z = 0.02 + f * (h - 0.05)
        hw = 0.22 + f * (0.18 - 0.22) - 0.02
        g.append(span(f"tread{k}", (x - 0.05, -hw, z - 0.015), (x + 0.05, hw, z + 0.015), shade(main, 0.8), mat))
    g.append(span("top_cap", (-0.1, -0.21, h - 0.03), (0.12, 0.21, h + 0.02), rgba("black") if attrs.color != "black" else rgba("gray"),
                  "plastic"))
    return finish(g)


def build_dumbbell(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A dumbbell lying on the floor: a knurled bar with two weight plates and a collar at each end."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="black")
    r = 0.07 * s
    g = [disk("bar", 0.016, 0.17 * s, (0, 0, r), tint("metal"), "metal", axis="y"),
         disk("grip", 0.019, 0.06 * s, (0, 0, r), shade(tint("metal"), 0.7), "metal", axis="y")]
    for k, sy in enumerate((1, -1)):
        for j, (off, rr) in enumerate(((0.095, r), (0.13, r * 0.85))):
            g.append(disk(f"plate{k}_{j}", rr, 0.017 * s, (0, sy * off * s, r), main, attrs.material, axis="y"))
        g.append(disk(f"collar{k}", 0.028, 0.01, (0, sy * 0.16 * s, r), tint("metal"), "metal", axis="y"))
    return finish(g)


def build_basketball(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A basketball: an orange sphere with black seams (an equator and two meridians)."""
    s = scale_of(attrs)
    r = 0.12 * s
    main = rgba(attrs.color, default="orange")
    seam = (0.08, 0.06, 0.05, 1.0)
    g = [sphere("ball", r, (0, 0, r), main, attrs.material),
         ellipsoid("seam0", (r * 1.004, r * 1.004, 0.003), (0, 0, r), seam, attrs.material),
         ellipsoid("seam1", (0.003, r * 1.004, r * 1.004), (0, 0, r), seam, attrs.material),
         ellipsoid("seam2", (r * 1.004, 0.003, r * 1.004), (0, 0, r), seam, attrs.material)]
    return finish(g)


# ---------------------------------------------------------------------------
# Small objects (placed on supports)
# ---------------------------------------------------------------------------


def build_laptop(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A base with a keyboard deck and a screen: raised (open) or folded flat (closed).

    The screen hinges at the back edge (-x); open, it leans back 20 degrees
    from vertical so the display faces +x.
    """
    s = scale_of(attrs)
    hx, hy, t = 0.12 * s, 0.17 * s, 0.01 * s
    shell = rgba(attrs.color, default="gray")
    geoms = [box("base", (hx, hy, t), (0, 0, t), shell, attrs.material),
             box("keyboard", (hx * 0.45, hy * 0.85, 0.002), (-0.025 * s, 0, 2 * t + 0.002), rgba("black"), "plastic"),
             box("touchpad", (hx * 0.2, hy * 0.25, 0.001), (hx * 0.68, 0, 2 * t + 0.001), shade(shell, 0.85), attrs.material)]
    if attrs.state == "closed":
        geoms.append(box("lid", (hx, hy, t * 0.6), (0, 0, 2 * t + 0.008), shell, attrs.material))
        return finish(geoms)
    tilt = math.radians(20.0)
    sh = 0.11 * s  # screen half height
    cx = -hx - math.sin(tilt) * sh + 0.005
    cz = 2 * t + math.cos(tilt) * sh
    q = quat_axis_angle((0, 1, 0), -tilt)
    geoms.append(box("screen", (0.006, hy, sh), (cx, 0, cz), shell, attrs.material, quat=q))
    geoms.append(box("display", (0.001, hy * 0.9, sh * 0.88), (cx + 0.007 * math.cos(tilt), 0, cz + 0.007 * math.sin(tilt)),
                     (0.15, 0.25, 0.45, 1.0), "glass", quat=q))
    return finish(geoms)


def build_book(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A hardback lying flat: two cover boards and a spine in its colour around a block of pages."""
    s = scale_of(attrs)
    hx, hy = 0.075 * s, 0.115 * s
    th = 0.03 * s * float(rng.uniform(0.7, 1.3))
    main = rgba(attrs.color, default="blue")
    c = 0.003
    g = [span("cover_bottom", (-hx, -hy, 0), (hx, hy, c), main, attrs.material),
         span("cover_top", (-hx, -hy, th - c), (hx, hy, th), main, attrs.material),
         span("spine", (-hx, -hy, c), (-hx + c, hy, th - c), shade(main, 0.85), attrs.material),
         span("pages", (-hx + c, -hy + 0.004, c), (hx - 0.004, hy - 0.004, th - c), (0.96, 0.94, 0.86, 1.0), "fabric")]
    return finish(g)


_BLOOMS = ("red", "yellow", "pink", "white", "purple", "orange")


def build_vase(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A vase of stacked forms (foot, bulbous body, neck, lip); full holds a bunch of flowers."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="blue")
    mat = attrs.material
    g = [disk("foot", 0.05 * s, 0.01 * s, (0, 0, 0.01 * s), shade(main, 0.85), mat),
         ellipsoid("body", (0.085 * s, 0.085 * s, 0.11 * s), (0, 0, 0.12 * s), main, mat),
         disk("neck", 0.035 * s, 0.05 * s, (0, 0, 0.25 * s), main, mat),
         disk("lip", 0.047 * s, 0.008 * s, (0, 0, 0.3 * s), shade(main, 0.9), mat)]
    if attrs.state == "full":
        top = np.array([0, 0, 0.3 * s])
        for k in range(5):
            a = 2 * math.pi * k / 5 + float(rng.uniform(-0.3, 0.3))
            lean = float(rng.uniform(0.15, 0.45))
            hgt = float(rng.uniform(0.16, 0.24)) * s
            tip = top + np.array([math.sin(lean) * math.cos(a), math.sin(lean) * math.sin(a), math.cos(lean)]) * hgt
            g.append(segment(f"stem{k}", top, tip, 0.004, (0.25, 0.5, 0.2, 1.0), "wood"))
            g.append(sphere(f"flower{k}", 0.03 * s, tuple(tip), rgba(_pick(rng, _BLOOMS)), "fabric"))
        for k in range(2):
            a = k * math.pi + 0.6
            g.append(ellipsoid(f"leaf{k}", (0.07 * s, 0.025 * s, 0.006), (0.05 * s * math.cos(a), 0.05 * s * math.sin(a), 0.34 * s),
                               (0.2, 0.55, 0.22, 1.0), "fabric",
                               quat=quat_mul(quat_axis_angle((0, 0, 1), a), quat_axis_angle((0, 1, 0), -0.5))))
    return finish(g)


def _dish(g: list, main, mat, radii: tuple[float, float, float], heights: tuple[float, float, float], inner) -> float:
    """Append a stepped bowl (foot, lower and upper walls) with a darker inside; returns its rim height."""
    z = 0.0
    for name, r, hz in zip(("foot", "lower", "upper"), radii, heights):
        g.append(disk(name, r, hz / 2, (0, 0, z + hz / 2), main if name != "foot" else shade(main, 0.85), mat))
        z += hz
    g.append(disk("inside", radii[2] * 0.9, 0.0008, (0, 0, z + 0.0008), inner, mat))
    return z


def build_bowl(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A small serving bowl (about 15 cm across); full shows a mound of food."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    g: list = []
    rim = _dish(g, main, attrs.material, (0.035 * s, 0.055 * s, 0.075 * s), (0.01 * s, 0.025 * s, 0.035 * s), shade(main, 0.8))
    if attrs.state == "full":
        food = rgba(_pick(rng, ("red", "green", "orange", "purple", "yellow")))
        for k in range(6):
            a = 2 * math.pi * k / 6 + float(rng.uniform(-0.2, 0.2))
            g.append(sphere(f"food{k}", 0.022 * s, (0.04 * s * math.cos(a), 0.04 * s * math.sin(a), rim + 0.008 * s),
                            shade(food, float(rng.uniform(0.85, 1.1))), "fabric"))
        g.append(sphere("food_top", 0.022 * s, (0, 0, rim + 0.03 * s), food, "fabric"))
    return finish(g)


def build_fruit_bowl(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A wide shallow bowl (about 30 cm across); full holds apples, oranges and a bunch of bananas."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    g: list = []
    rim = _dish(g, main, attrs.material, (0.06 * s, 0.11 * s, 0.15 * s), (0.015 * s, 0.025 * s, 0.03 * s), shade(main, 0.8))
    if attrs.state == "full":
        fruit = ((0.8, 0.1, 0.1, 1.0), (0.95, 0.55, 0.1, 1.0), (0.55, 0.8, 0.2, 1.0))
        for k in range(4):
            a = 2 * math.pi * k / 4 + float(rng.uniform(-0.3, 0.3))
            g.append(sphere(f"fruit{k}", 0.038 * s, (0.07 * s * math.cos(a), 0.07 * s * math.sin(a), rim + 0.02 * s),
                            fruit[int(rng.integers(len(fruit)))], "fabric"))
        g.append(sphere("fruit_top", 0.036 * s, (0, 0, rim + 0.06 * s), fruit[int(rng.integers(len(fruit)))], "fabric"))
        for k in range(3):
            q = quat_axis_angle((0, 0, 1), 0.3 * k - 0.3)
            g.append(capsule(f"banana{k}", 0.016 * s, 0.06 * s, (-0.02 * s + 0.02 * s * k, 0.02 * s * (k - 1), rim + 0.065 * s),
                             (0.95, 0.85, 0.25, 1.0), "fabric", quat=quat_mul(q, _AXIS_QUAT["x"])))
    return finish(g)


def build_cup(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tumbler cup without a handle, tapering out towards its rim (about 8 cm across, 10 cm tall)."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    g = [disk("lower", 0.03 * s, 0.025 * s, (0, 0, 0.025 * s), main, attrs.material),
         disk("middle", 0.034 * s, 0.025 * s, (0, 0, 0.075 * s - 0.001), main, attrs.material),
         disk("rim", 0.038 * s, 0.006 * s, (0, 0, 0.1 * s - 0.006 * s), shade(main, 0.92), attrs.material),
         disk("inside", 0.033 * s, 0.0008, (0, 0, 0.1 * s + 0.0008), shade(main, 0.6), attrs.material)]
    return finish(g)


def build_mug(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A mug: a straight cylinder with a looped handle and a dark opening."""
    s = scale_of(attrs)
    r, h = 0.042 * s, 0.1 * s
    main = rgba(attrs.color, default="white")
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, attrs.material),
         disk("inside", r * 0.85, 0.0008, (0, 0, h + 0.0008), (0.22, 0.13, 0.07, 1.0), attrs.material)]
    g += ring("handle", (0, r - 0.004, h / 2), (0.032 * s, 0.033 * s), 0.007 * s, 4, main, attrs.material, u=(0, 1, 0), v=(0, 0, 1),
              start=-math.pi / 2, stop=math.pi / 2)
    return finish(g)


def build_plate(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A dinner plate (about 26 cm across): a foot ring, a thin disc and a slightly raised well."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    g = [disk("foot", 0.07 * s, 0.003, (0, 0, 0.003), shade(main, 0.9), attrs.material),
         disk("plate", 0.13 * s, 0.005, (0, 0, 0.011), main, attrs.material),
         disk("rim_band", 0.128 * s, 0.0006, (0, 0, 0.0166), shade(main, 0.85), attrs.material),
         disk("well", 0.09 * s, 0.0008, (0, 0, 0.0172), main, attrs.material)]
    return finish(g)


def build_bottle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A water bottle: a body with a label band, a rounded shoulder, a neck and a cap."""
    s = scale_of(attrs)
    r = 0.035 * s
    main = rgba(attrs.color, default="blue", alpha=1.0)
    g = [disk("body", r, 0.085 * s, (0, 0, 0.085 * s), main, attrs.material),
         disk("label", r + 0.001, 0.03 * s, (0, 0, 0.09 * s), rgba("white"), "fabric"),
         ellipsoid("shoulder", (r, r, 0.035 * s), (0, 0, 0.17 * s), main, attrs.material),
         disk("neck", 0.014 * s, 0.02 * s, (0, 0, 0.215 * s), main, attrs.material),
         disk("cap", 0.016 * s, 0.01 * s, (0, 0, 0.24 * s), shade(main, 0.6), "plastic")]
    return finish(g)


def build_wine_bottle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A wine bottle: a dark glass body with a paper label, a sloping shoulder, a long neck and a foil capsule."""
    s = scale_of(attrs)
    r = 0.038 * s
    main = rgba(attrs.color, default="green")
    foil = rgba(_pick(rng, ("red", "yellow", "black", "purple")))
    g = [disk("body", r, 0.1 * s, (0, 0, 0.1 * s), main, attrs.material),
         disk("label", r + 0.001, 0.035 * s, (0, 0, 0.09 * s), (0.93, 0.9, 0.8, 1.0), "fabric"),
         ellipsoid("shoulder", (r, r, 0.05 * s), (0, 0, 0.2 * s), main, attrs.material),
         disk("neck", 0.014 * s, 0.045 * s, (0, 0, 0.275 * s), main, attrs.material),
         disk("foil", 0.0155 * s, 0.025 * s, (0, 0, 0.305 * s), foil, "metal")]
    return finish(g)


def build_table_lamp(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A bedside lamp: a base, a bulbous body, a neck and a drum shade (glowing, with a lit bulb below, when on)."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    on = attrs.state == "on"
    shade_c = glow(main) if on else mix(main, rgba("beige"), 0.25)
    g = [disk("base", 0.07 * s, 0.012 * s, (0, 0, 0.012 * s), shade(main, 0.8), attrs.material),
         ellipsoid("body", (0.065 * s, 0.065 * s, 0.09 * s), (0, 0, 0.1 * s), main, attrs.material),
         disk("neck", 0.01, 0.06 * s, (0, 0, 0.24 * s), tint("metal"), "metal"),
         disk("lamp_shade", 0.14 * s, 0.09 * s, (0, 0, 0.33 * s), shade_c, "fabric"),
         disk("diffuser", 0.13 * s, 0.002, (0, 0, 0.24 * s - 0.003), LIGHT_ON if on else shade(shade_c, 0.7), "glass")]
    if on:
        g.append(sphere("bulb", 0.022 * s, (0, 0, 0.24 * s - 0.02 * s), LIGHT_ON, "glass"))
    return finish(g)


def build_candle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A pillar candle on a holder dish with a wick; on (lit) adds a flame."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    holder = tint(attrs.material or "metal")
    h = 0.12 * s
    g = [disk("holder", 0.045 * s, 0.005, (0, 0, 0.005), holder, attrs.material),
         disk("candle", 0.025 * s, h / 2, (0, 0, 0.01 + h / 2), main, "plastic"),
         segment("wick", (0, 0, 0.01 + h), (0, 0, 0.01 + h + 0.01), 0.0015, DARK)]
    if attrs.state == "on":
        g.append(ellipsoid("flame", (0.007, 0.007, 0.018), (0, 0, 0.01 + h + 0.025), FLAME, "glass"))
        g.append(ellipsoid("flame_core", (0.004, 0.004, 0.009), (0, 0, 0.01 + h + 0.02), LIGHT_ON, "glass"))
    return finish(g)


def build_alarm_clock(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A twin-bell alarm clock: a round body facing +x, a white dial with hands, two bells, a hammer and feet."""
    s = scale_of(attrs)
    r = 0.055 * s
    main = rgba(attrs.color, default="red")
    metal = tint("metal")
    zc = 0.012 + r
    g = [disk("body", r, 0.025 * s, (0, 0, zc), main, attrs.material, axis="x"),
         disk("dial", r * 0.85, 0.002, (0.025 * s + 0.002, 0, zc), rgba("white"), "plastic", axis="x")]
    hour, minute = float(rng.uniform(0, 2 * math.pi)), float(rng.uniform(0, 2 * math.pi))
    for name, a, ln in (("hour_hand", hour, 0.025 * s), ("minute_hand", minute, 0.038 * s)):
        g.append(box(name, (0.001, 0.0025, ln / 2), (0.025 * s + 0.005, -math.sin(a) * ln / 2, zc + math.cos(a) * ln / 2), DARK, "metal",
                     quat=quat_axis_angle((1, 0, 0), a)))
    for k, sy in enumerate((1, -1)):
        g.append(sphere(f"bell{k}", 0.024 * s, (0, sy * 0.035 * s, zc + r + 0.005 * s), main, attrs.material))
        g.append(segment(f"foot{k}", (0.0, sy * 0.03 * s, zc - r * 0.8), (0.0, sy * 0.045 * s, 0.006), 0.006, metal, "metal"))
    g.append(segment("hammer", (0, 0, zc + r), (0, 0, zc + r + 0.03 * s), 0.004, metal, "metal"))
    return finish(g)


def build_keyboard(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A computer keyboard: a slim tray with five rows of keys and a space bar."""
    s = scale_of(attrs)
    hx, hy = 0.07 * s, 0.22 * s
    main = rgba(attrs.color, default="black")
    keys = shade(main, 1.6) if max(main[:3]) < 0.3 else shade(main, 0.75)
    g = [span("tray", (-hx, -hy, 0), (hx, hy, 0.012), main, attrs.material)]
    pitch = (2 * hx - 0.02) / 6
    for k in range(5):
        x = hx - 0.01 - (k + 0.5) * pitch
        g.append(span(f"key_row{k}", (x - pitch * 0.4, -hy + 0.012, 0.012), (x + pitch * 0.4, hy - 0.012, 0.02), keys, "plastic"))
    x = hx - 0.01 - 5.5 * pitch
    g.append(span("space_bar", (x - pitch * 0.4, -hy * 0.35, 0.012), (x + pitch * 0.4, hy * 0.35, 0.02), keys, "plastic"))
    return finish(g)


def build_pot(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A cooking pot: a cylindrical body with a rolled rim, a lid with a knob and two side handles."""
    s = scale_of(attrs)
    r, h = 0.11 * s, 0.13 * s
    main = rgba(attrs.color, default="gray")
    metal = tint("metal")
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, attrs.material),
         disk("rim", r + 0.004, 0.005, (0, 0, h - 0.005), shade(main, 0.9), attrs.material),
         disk("lid", r - 0.002, 0.005, (0, 0, h + 0.005), shade(main, 1.1), attrs.material),
         sphere("knob", 0.016, (0, 0, h + 0.022), DARK, "plastic")]
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"handle{k}", (0, sy * (r - 0.005), h - 0.025), (0, sy * (r + 0.035), h - 0.02), 0.01, metal, "metal"))
    return finish(g)


def build_pan(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A frying pan: a shallow body with a dark non-stick inside and a long handle."""
    s = scale_of(attrs)
    r = 0.13 * s
    main = rgba(attrs.color, default="black")
    g = [disk("body", r, 0.02 * s, (0, 0, 0.02 * s), main, attrs.material),
         disk("inside", r * 0.9, 0.0008, (0, 0, 0.04 * s + 0.0008), (0.12, 0.12, 0.13, 1.0), attrs.material),
         segment("handle", (0, r - 0.01, 0.03 * s), (0, r + 0.2 * s, 0.05 * s), 0.012, DARK, "plastic")]
    return finish(g)


def build_cutting_board(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A chopping board with a handle tab and a hanging hole."""
    s = scale_of(attrs)
    hx, hy = 0.15 * s, 0.2 * s
    main = rgba(attrs.color, default="brown")
    g = [span("board", (-hx, -hy, 0), (hx, hy, 0.018), main, attrs.material),
         span("tab", (-hx * 0.4, hy, 0), (hx * 0.4, hy + 0.06 * s, 0.018), main, attrs.material),
         disk("hole", 0.012, 0.0006, (0, hy + 0.03 * s, 0.0186), DARK),
         span("groove", (-hx + 0.015, -hy + 0.015, 0.018), (hx - 0.015, -hy + 0.02, 0.0186), shade(main, 0.75), attrs.material)]
    return finish(g)


def build_pillow(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A square scatter cushion: a plump ellipsoid over a rounded-square core, with piping."""
    s = scale_of(attrs)
    a = 0.22 * s
    main = rgba(attrs.color, default="white")
    g = [box("core", (a * 0.9, a * 0.9, 0.045 * s), (0, 0, 0.06 * s), main, attrs.material),
         ellipsoid("puff", (a, a, 0.075 * s), (0, 0, 0.075 * s), main, attrs.material),
         box("piping", (a * 0.93, a * 0.93, 0.006), (0, 0, 0.075 * s), shade(main, 0.8), attrs.material)]
    return finish(g)


def build_teddy_bear(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A sitting teddy bear facing +x: body, head with ears and snout, arms, legs and eyes."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    light = mix(main, rgba("beige"), 0.5)
    k = s
    g = [ellipsoid("body", (0.065 * k, 0.075 * k, 0.085 * k), (0, 0, 0.09 * k), main, "fabric"),
         ellipsoid("belly", (0.02 * k, 0.05 * k, 0.06 * k), (0.052 * k, 0, 0.085 * k), light, "fabric"),
         sphere("head", 0.058 * k, (0.01 * k, 0, 0.215 * k), main, "fabric"),
         ellipsoid("snout", (0.025 * k, 0.028 * k, 0.02 * k), (0.06 * k, 0, 0.205 * k), light, "fabric"),
         sphere("nose", 0.008 * k, (0.085 * k, 0, 0.212 * k), DARK, "plastic")]
    for j, sy in enumerate((1, -1)):
        g.append(sphere(f"ear{j}", 0.022 * k, (0.0, sy * 0.045 * k, 0.265 * k), main, "fabric"))
        g.append(sphere(f"eye{j}", 0.007 * k, (0.058 * k, sy * 0.02 * k, 0.232 * k), DARK, "plastic"))
        g.append(ellipsoid(f"arm{j}", (0.022 * k, 0.022 * k, 0.055 * k), (0.025 * k, sy * 0.075 * k, 0.11 * k), main, "fabric",
                           quat=quat_axis_angle((1, 0, 0), sy * 0.35)))
        g.append(ellipsoid(f"leg{j}", (0.06 * k, 0.03 * k, 0.028 * k), (0.06 * k, sy * 0.045 * k, 0.028 * k), main, "fabric"))
        g.append(ellipsoid(f"paw{j}", (0.004 * k, 0.022 * k, 0.02 * k), (0.118 * k, sy * 0.045 * k, 0.03 * k), light, "fabric"))
    return finish(g)


def build_basket(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A woven carry basket: a tapered body with bands, a rim, a dark inside and an arched handle."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="beige")
    mat = attrs.material
    r0, r1, h = 0.12 * s, 0.15 * s, 0.14 * s
    g = [disk("lower", r0, h * 0.25, (0, 0, h * 0.25), shade(main, 0.9), mat),
         disk("upper", r1, h * 0.25, (0, 0, h * 0.75), main, mat),
         disk("rim", r1 + 0.006, 0.007, (0, 0, h - 0.007), shade(main, 0.75), mat),
         disk("inside", r1 - 0.01, 0.0008, (0, 0, h + 0.0008), (0.2, 0.15, 0.1, 1.0), mat),
         disk("band", r0 + 0.003, 0.005, (0, 0, h * 0.25), shade(main, 0.7), mat)]
    g += ring("handle", (0, 0, h), (r1, 0.14 * s), 0.009, 6, shade(main, 0.8), mat, u=(0, 1, 0), v=(0, 0, 1), start=0.0, stop=math.pi)
    return finish(g)


def build_picture_frame(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A standing photo frame leaning back on a kickstand; the photo (sky over ground) faces +x."""
    s = scale_of(attrs)
    hy, hz = 0.09 * s, 0.12 * s
    main = rgba(attrs.color, default="black")
    tilt = math.radians(12)
    q = quat_axis_angle((0, 1, 0), -tilt)
    up = np.array([-math.sin(tilt), 0, math.cos(tilt)])
    fwd = np.array([math.cos(tilt), 0, math.sin(tilt)])
    c = np.array([0.0, 0.0, 0.0]) + up * hz + fwd * 0.0
    sky = rgba(_pick(rng, ("blue", "white", "orange")))
    ground = rgba(_pick(rng, ("green", "beige", "gray", "brown")))
    g = [box("frame", (0.008, hy, hz), tuple(c), main, attrs.material, quat=q),
         box("photo_sky", (0.001, hy * 0.78, hz * 0.4), tuple(c + fwd * 0.009 + up * hz * 0.4), sky, "glass", quat=q),
         box("photo_ground", (0.001, hy * 0.78, hz * 0.4), tuple(c + fwd * 0.009 - up * hz * 0.4), ground, "glass", quat=q),
         segment("kickstand", c - fwd * 0.008, np.array([-0.09 * s, 0, 0.004]), 0.004, main, attrs.material)]
    return finish(g)


def build_soap_dispenser(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A pump soap bottle: a round body, a collar, a pump head with a spout pointing +x."""
    s = scale_of(attrs)
    r = 0.035 * s
    main = rgba(attrs.color, default="white")
    metal = tint("metal")
    g = [disk("body", r, 0.06 * s, (0, 0, 0.06 * s), main, attrs.material),
         disk("collar", 0.016 * s, 0.008, (0, 0, 0.12 * s + 0.008), metal, "metal"),
         disk("stem", 0.007, 0.012, (0, 0, 0.12 * s + 0.028), metal, "metal"),
         disk("pump_head", 0.014 * s, 0.008, (0, 0, 0.12 * s + 0.046), metal, "metal"),
         segment("spout", (0, 0, 0.12 * s + 0.046), (0.045 * s, 0, 0.12 * s + 0.04), 0.005, metal, "metal")]
    return finish(g)


def build_towel(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A stack of two folded bath towels with rounded folded edges."""
    s = scale_of(attrs)
    hx, hy, t = 0.14 * s, 0.2 * s, 0.025 * s
    main = rgba(attrs.color, default="white")
    g = []
    for k in range(2):
        dx = float(rng.uniform(-0.01, 0.01))
        z = k * 2 * t
        c = main if k == 0 else shade(main, 0.95)
        g.append(span(f"towel{k}", (-hx + dx, -hy, z), (hx - t + dx, hy, z + 2 * t), c, "fabric"))
        g.append(disk(f"fold{k}", t, hy, (hx - t + dx, 0, z + t), c, "fabric", axis="y"))
    return finish(g)


def build_tissue_box(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tissue box: a printed box with a dark slot and a tissue poking out of the top."""
    s = scale_of(attrs)
    hx, hy, h = 0.06 * s, 0.12 * s, 0.09 * s
    main = rgba(attrs.color, default="blue")
    g = [span("box", (-hx, -hy, 0), (hx, hy, h), main, attrs.material),
         ellipsoid("slot", (0.02 * s, 0.07 * s, 0.001), (0, 0, h + 0.0005), DARK),
         ellipsoid("tissue", (0.012 * s, 0.045 * s, 0.035 * s), (0, 0, h + 0.02 * s), rgba("white"), "fabric",
                   quat=quat_axis_angle((0, 0, 1), 0.2))]
    return finish(g)


def build_globe(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A desk globe: a base, a stem, a tilted half meridian and a sphere with continents."""
    s = scale_of(attrs)
    R = 0.15 * s
    ocean = rgba(attrs.color, default="blue")
    stand = tint(attrs.material or "wood")
    zc = 0.05 + R + 0.03
    tilt = math.radians(23.4)
    axis = np.array([math.sin(tilt), 0.0, math.cos(tilt)])
    side = np.array([math.cos(tilt), 0.0, -math.sin(tilt)])
    g = [disk("base", 0.085 * s, 0.012, (0, 0, 0.012), stand, attrs.material),
         disk("stem", 0.012, (zc - R - 0.024) / 2 + 0.01, (0, 0, 0.024 + (zc - R - 0.024) / 2), stand, attrs.material),
         sphere("globe", R, (0, 0, zc), ocean, "plastic")]
    g += ring("meridian", (0, 0, zc), R + 0.012, 0.005, 7, tint("metal"), "metal", u=axis, v=-side, start=0.0, stop=math.pi)
    land = ((0.35, 0.6, 0.25, 1.0), (0.7, 0.6, 0.35, 1.0))
    for k, (lat, lon) in enumerate(((0.6, 0.3), (0.0, 0.9), (-0.4, 0.4), (0.5, 2.4), (-0.3, 3.6), (0.9, 4.6))):
        lat += float(rng.uniform(-0.1, 0.1))
        n = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
        g.append(ellipsoid(f"land{k}", (0.5 * R, 0.35 * R, 0.06 * R), (0.0, 0.0, zc) + n * (R - 0.04 * R), land[k % 2], "plastic",
                           quat=quat_from_z(n)))
    return finish(g)


def build_sculpture(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An abstract sculpture on a plinth: a leaning column, a twisted block and a sphere."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    lean = float(rng.uniform(-0.25, 0.25))
    twist = float(rng.uniform(0, math.pi / 2))
    top = np.array([0.0, math.sin(lean) * 0.2 * s, 0.05 + math.cos(lean) * 0.2 * s])
    base = tint("stone") if mat != "stone" else shade(main, 0.7)
    g = [span("plinth", (-0.07 * s, -0.07 * s, 0), (0.07 * s, 0.07 * s, 0.04), base, "stone"),
         segment("column", (0, 0, 0.06), top, 0.025 * s, main, mat),
         box("block", (0.04 * s, 0.04 * s, 0.04 * s), tuple(top + np.array([0, 0, 0.04 * s])), main, mat,
             quat=quat_mul(quat_axis_angle((0, 0, 1), twist), quat_axis_angle((1, 0, 0), math.pi / 4))),
         sphere("orb", 0.035 * s, tuple(top + np.array([0, 0, 0.125 * s])), shade(main, 0.9), mat)]
    return finish(g)


def build_remote_control(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A TV remote: a slim rounded body with a red power button, a d-pad and rows of buttons."""
    s = scale_of(attrs)
    hx, hy = 0.09 * s, 0.024 * s
    main = rgba(attrs.color, default="black")
    btn = (0.6, 0.6, 0.62, 1.0) if max(main[:3]) < 0.5 else (0.2, 0.2, 0.22, 1.0)
    g = [box("body", (hx, hy, 0.009), (0, 0, 0.009), main, attrs.material),
         disk("power", 0.006, 0.0015, (hx - 0.015, hy * 0.5, 0.019), rgba("red"), "plastic"),
         disk("dpad", 0.013 * s, 0.0015, (hx * 0.25, 0, 0.019), btn, "plastic")]
    for k in range(3):
        x = -hx * 0.2 - k * 0.022 * s
        g.append(span(f"buttons{k}", (x - 0.005, -hy * 0.7, 0.018), (x + 0.005, hy * 0.7, 0.0205), btn, "plastic"))
    return finish(g)


def build_spray_bottle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A trigger spray bottle: a body with a label, a neck, a trigger head with a nozzle pointing +x and a trigger."""
    s = scale_of(attrs)
    r = 0.04 * s
    main = rgba(attrs.color, default="blue")
    head = rgba("white") if attrs.color != "white" else rgba("gray")
    h = 0.17 * s
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, attrs.material),
         disk("label", r + 0.001, 0.035 * s, (0, 0, h * 0.45), rgba("white") if attrs.color != "white" else rgba("yellow"), "fabric"),
         disk("neck", 0.016 * s, 0.015 * s, (0, 0, h + 0.015 * s), head, "plastic"),
         span("head", (-0.02 * s, -0.017 * s, h + 0.03 * s), (0.06 * s, 0.017 * s, h + 0.065 * s), head, "plastic"),
         disk("nozzle", 0.01 * s, 0.008 * s, (0.068 * s, 0, h + 0.05 * s), DARK, "plastic", axis="x"),
         segment("trigger", (0.035 * s, 0, h + 0.03 * s), (0.045 * s, 0, h - 0.02 * s), 0.007 * s, head, "plastic")]
    return finish(g)


def build_dish_rack(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A draining rack: a drip tray, a wire frame and a few plates standing in it beside a cup."""
    s = scale_of(attrs)
    hx, hy = 0.17 * s, 0.24 * s
    main = rgba(attrs.color, default="gray")
    mat = attrs.material
    g = [span("tray", (-hx, -hy, 0), (hx, hy, 0.012), shade(main, 0.85), mat)]
    for k, sx in enumerate((1, -1)):
        g.append(segment(f"rail{k}", (sx * (hx - 0.01), -hy + 0.01, 0.09 * s), (sx * (hx - 0.01), hy - 0.01, 0.09 * s), 0.004, main, mat))
        for j, sy in enumerate((1, -1)):
            x, y = sx * (hx - 0.01), sy * (hy - 0.01)
            g.append(segment(f"post{k}{j}", (x, y, 0.012), (x, y, 0.09 * s), 0.004, main, mat))
    n = int(rng.integers(2, 5))
    for k in range(n):
        y = -hy + 0.05 + k * 0.045 * s
        c = rgba(_pick(rng, ("white", "blue", "beige", "green")))
        g.append(disk(f"plate{k}", 0.1 * s, 0.005, (0.0, y, 0.012 + 0.1 * s), c, "ceramic", axis="y"))
    c = rgba(_pick(rng, ("red", "white", "yellow")))
    g.append(disk("cup", 0.035 * s, 0.045 * s, (0.0, hy - 0.06, 0.012 + 0.045 * s), c, "ceramic"))
    return finish(g)


def build_watering_can(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A watering can: a round body, a long spout with a rose pointing +x, and an arched top handle."""
    s = scale_of(attrs)
    r, h = 0.08 * s, 0.18 * s
    main = rgba(attrs.color, default="green")
    mat = attrs.material
    tip = np.array([0.27 * s, 0, 0.25 * s])
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, mat),
         disk("top", r * 0.9, 0.005, (0, 0, h + 0.005), shade(main, 0.85), mat),
         segment("spout", (r * 0.7, 0, 0.05 * s), tip, 0.011 * s, main, mat),
         segment("rose", tip, tip + np.array([0.02, 0, 0.015]) * s, 0.022 * s, shade(main, 0.8), mat, kind="cylinder")]
    g += ring("handle", (-0.02 * s, 0, h), (0.065 * s, 0.09 * s), 0.01 * s, 5, main, mat, u=(1, 0, 0), v=(0, 0, 1), start=0.0, stop=math.pi)
    return finish(g)


def build_tennis_racket(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tennis racket lying flat: an oval head frame with a string bed, a throat and a wrapped handle."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="blue")
    mat = attrs.material
    ax, ay, t = 0.15 * s, 0.12 * s, 0.011
    cx = 0.17 * s
    g = ring("head", (cx, 0, t), (ax, ay), t, 12, main, mat)
    g.append(ellipsoid("strings", (ax - 0.005, ay - 0.005, 0.0015), (cx, 0, t), (0.92, 0.92, 0.85, 1.0), "plastic"))
    throat = np.array([cx - ax, 0, t])
    neck = np.array([cx - ax - 0.08 * s, 0, t])
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"throat{k}", np.array([cx - ax * 0.8, sy * ay * 0.6, t]), neck, t * 0.8, main, mat))
    g.append(segment("shaft", neck, throat, t * 0.8, main, mat))
    g.append(segment("grip", neck, neck - np.array([0.19 * s, 0, 0]), 0.015, DARK, "leather"))
    return finish(g)


def build_baseball_bat(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A baseball bat lying along x: a knob, a thin handle tapering out to a thick barrel."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    L = 0.84 * s
    zc = 0.034 * s
    x0 = -L / 2
    grip = DARK if attrs.color != "black" else rgba("gray")
    g = [disk("knob", 0.022 * s, 0.006, (x0 + 0.006, 0, zc), shade(main, 0.8), mat, axis="x"),
         segment("handle", (x0 + 0.01, 0, zc), (x0 + 0.34 * L, 0, zc), 0.013 * s, grip, "leather"),
         segment("taper", (x0 + 0.3 * L, 0, zc), (x0 + 0.6 * L, 0, zc), 0.022 * s, main, mat),
         segment("barrel", (x0 + 0.6 * L, 0, zc), (L / 2 - 0.034 * s, 0, zc), 0.034 * s, main, mat)]
    return finish(g)


def build_headphones(attrs: Attributes, rng: np.random.Generator) -> Built:
    """Over-ear headphones standing on their ear cups: two cups with cushions joined by an arched headband."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="black")
    r = 0.045 * s
    w = 0.085 * s
    g = []
    for k, sy in enumerate((1, -1)):
        g.append(disk(f"cup{k}", r, 0.017 * s, (0, sy * w, r), main, attrs.material, axis="y"))
        g.append(disk(f"cushion{k}", r * 0.9, 0.008 * s, (0, sy * (w - 0.024 * s), r), DARK, "leather", axis="y"))
        g.append(segment(f"yoke{k}", (0, sy * (w + 0.005 * s), 2 * r - 0.005), (0, sy * w * 0.95, 2 * r + 0.03 * s), 0.005 * s, main,
                         attrs.material))
    g += ring("headband", (0, 0, 2 * r + 0.03 * s), (w * 0.95, 0.08 * s), 0.011 * s, 6, main, attrs.material, u=(0, 1, 0), v=(0, 0, 1),
              start=0.0, stop=math.pi)
    return finish(g)


# ---------------------------------------------------------------------------
# Placing built objects
# ---------------------------------------------------------------------------


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


# ---------------------------------------------------------------------------
# The registry
# ---------------------------------------------------------------------------

_ALL_COLORS = tuple(vocab.COLORS)
_NEUTRAL = ("white", "black", "gray", "brown", "beige")
_APPLIANCE = ("white", "gray", "black")
_COUNTERS = ("cabinet", "kitchen_island")
_ON_OFF = ("on", "off")
_OPEN_CLOSED = ("open", "closed")
_FULL_EMPTY = ("full", "empty")


def _spec(name: str, placement: str, rooms: Mapping[str, float], colors, materials, build: Builder, **kw) -> CategorySpec:
    return CategorySpec(name, placement, MappingProxyType(dict(rooms)), tuple(colors), tuple(materials), build, **kw)


_SPECS: tuple[CategorySpec, ...] = (
    # -- large furniture ---------------------------------------------------
    _spec("bed", "floor_wall", {"bedroom": 5}, _ALL_COLORS, ("wood", "metal", "fabric"), build_bed, states=("made", "unmade")),
    _spec("sofa", "floor_wall", {"living_room": 5, "office": 0.5, "bedroom": 0.3}, _ALL_COLORS, ("fabric", "leather"), build_sofa),
    _spec("armchair", "floor", {"living_room": 4, "bedroom": 1.5, "office": 1}, _ALL_COLORS, ("fabric", "leather"), build_armchair),
    _spec("chair", "floor", {"dining_room": 3, "kitchen": 1, "office": 1, "bedroom": 0.5, "living_room": 0.5},
          _ALL_COLORS, ("wood", "metal", "plastic"), build_chair),
    _spec("office_chair", "floor", {"office": 5, "bedroom": 0.7}, ("black", "gray", "blue", "red", "white", "green"),
          ("fabric", "leather", "plastic"), build_office_chair),
    _spec("stool", "floor", {"kitchen": 4, "garage": 1, "bathroom": 0.5, "dining_room": 0.5, "laundry_room": 0.5},
          ("brown", "black", "white", "gray", "red", "blue"), ("wood", "metal", "plastic"), build_stool),
    _spec("bench", "floor_wall", {"entryway": 4, "hallway": 2, "bedroom": 1, "garage": 0.5, "dining_room": 0.5, "closet": 0.5},
          ("brown", "white", "black", "gray", "beige"), ("wood", "metal"), build_bench),
    _spec("ottoman", "floor", {"living_room": 3, "bedroom": 1.5, "closet": 0.5}, _ALL_COLORS, ("fabric", "leather"), build_ottoman),
    _spec("dining_table", "floor", {"dining_room": 3, "kitchen": 1},
          ("brown", "white", "black", "gray"), ("wood", "stone", "glass"), build_dining_table),
    _spec("coffee_table", "floor", {"living_room": 5, "office": 0.3}, ("brown", "white", "black", "gray"),
          ("wood", "glass", "stone", "metal"), build_coffee_table),
    _spec("side_table", "floor", {"living_room": 3, "bedroom": 1, "office": 1, "hallway": 1.5, "entryway": 1.5},
          ("brown", "white", "black", "gray", "green", "blue"), ("wood", "metal", "glass", "stone"), build_side_table),
    _spec("desk", "floor_wall", {"office": 5, "bedroom": 2, "living_room": 0.5}, ("brown", "white", "black", "gray"),
          ("wood", "metal", "glass"), build_desk),
    _spec("nightstand", "floor_wall", {"bedroom": 5}, ("brown", "white", "black", "gray", "beige", "blue"), ("wood", "metal"),
          build_nightstand),
    _spec("dresser", "floor_wall", {"bedroom": 4, "closet": 1.5, "hallway": 0.5},
          ("brown", "white", "black", "gray", "beige", "blue", "green"), ("wood", "metal"), build_dresser, states=_OPEN_CLOSED),
    _spec("wardrobe", "floor_wall", {"bedroom": 3, "closet": 4, "hallway": 1, "entryway": 0.5},
          ("brown", "white", "black", "gray", "beige"), ("wood", "metal"), build_wardrobe, states=_OPEN_CLOSED),
    _spec("cabinet", "floor_wall", {"kitchen": 5, "laundry_room": 2, "garage": 1.5, "bathroom": 1, "office": 1, "living_room": 0.5,
                                    "dining_room": 0.5},
          ("white", "brown", "gray", "black", "beige", "blue", "green"), ("wood", "stone", "metal"), build_cabinet, states=_OPEN_CLOSED),
    _spec("bookshelf", "floor_wall", {"office": 4, "living_room": 3, "bedroom": 1, "hallway": 0.5},
          ("brown", "white", "black", "gray"), ("wood", "metal"), build_bookshelf, states=_FULL_EMPTY),
    _spec("shelf", "floor_wall", {"garage": 3, "laundry_room": 3, "closet": 2.5, "kitchen": 1, "office": 1, "bathroom": 1,
                                  "living_room": 0.5},
          ("gray", "white", "black", "brown"), ("metal", "wood", "plastic"), build_shelf),
    _spec("tv_stand", "floor_wall", {"living_room": 5, "bedroom": 1}, ("brown", "black", "white", "gray"), ("wood", "glass", "metal"),
          build_tv_stand),
    _spec("kitchen_island", "floor", {"kitchen": 5}, ("white", "gray", "brown", "black", "blue", "green"), ("stone", "wood"),
          build_kitchen_island),
    _spec("crib", "floor_wall", {"bedroom": 1.5}, ("white", "brown", "gray", "pink", "blue"), ("wood",), build_crib),
    _spec("dog_bed", "floor", {"living_room": 2, "bedroom": 1, "hallway": 0.5, "kitchen": 0.3, "entryway": 0.5},
          ("brown", "gray", "beige", "blue", "red", "green"), ("fabric",), build_dog_bed),
    # -- appliances and fixtures --------------------------------------------
    _spec("refrigerator", "floor_wall", {"kitchen": 5, "garage": 0.5}, ("white", "gray", "black", "beige", "red"), ("metal", "plastic"),
          build_refrigerator),
    _spec("stove", "floor_wall", {"kitchen": 5}, _APPLIANCE, ("metal",), build_stove, states=_ON_OFF),
    _spec("oven", "floor_wall", {"kitchen": 3}, _APPLIANCE, ("metal", "glass"), build_oven, states=_ON_OFF),
    _spec("dishwasher", "floor_wall", {"kitchen": 3}, _APPLIANCE, ("metal", "plastic"), build_dishwasher),
    _spec("washing_machine", "floor_wall", {"laundry_room": 5, "bathroom": 1, "kitchen": 0.5, "garage": 0.5}, _APPLIANCE,
          ("metal", "plastic"), build_washing_machine, states=_OPEN_CLOSED),
    _spec("dryer", "floor_wall", {"laundry_room": 5, "garage": 0.3, "closet": 0.3}, _APPLIANCE, ("metal", "plastic"), build_dryer,
          states=_OPEN_CLOSED),
    _spec("toilet", "floor_wall", {"bathroom": 6}, ("white", "beige", "black", "gray"), ("ceramic",), build_toilet, states=_OPEN_CLOSED),
    _spec("sink", "floor_wall", {"bathroom": 5, "laundry_room": 2, "kitchen": 1},
          ("white", "gray", "brown", "black", "beige", "blue", "green"), ("ceramic", "stone", "metal"), build_sink),
    _spec("bathtub", "floor_wall", {"bathroom": 4}, ("white", "beige", "gray", "black", "blue"), ("ceramic", "stone", "metal"),
          build_bathtub),
    _spec("shower", "floor_wall", {"bathroom": 3}, ("white", "gray", "beige", "blue", "black", "green"), ("ceramic", "stone", "glass"),
          build_shower),
    _spec("microwave", "on_support", {"kitchen": 5, "office": 0.3}, ("black", "white", "gray", "red"), ("metal", "plastic"),
          build_microwave, states=_ON_OFF, supports=_COUNTERS),
    _spec("toaster", "on_support", {"kitchen": 4}, ("gray", "white", "black", "red", "blue", "yellow", "green"), ("metal", "plastic"),
          build_toaster, supports=_COUNTERS + ("dining_table",)),
    _spec("kettle", "on_support", {"kitchen": 4, "office": 0.3}, ("white", "black", "gray", "red", "blue", "green", "yellow"),
          ("metal", "plastic", "glass"), build_kettle, supports=_COUNTERS + ("stove", "dining_table")),
    _spec("coffee_machine", "on_support", {"kitchen": 4, "office": 1}, ("black", "gray", "red", "white"), ("metal", "plastic"),
          build_coffee_machine, supports=_COUNTERS + ("shelf", "desk")),
    _spec("television", "on_support", {"living_room": 5, "bedroom": 2, "kitchen": 0.3, "office": 0.3}, ("black", "gray", "white"),
          ("plastic", "metal"), build_television, states=_ON_OFF, supports=("tv_stand", "dresser", "desk")),
    _spec("monitor", "on_support", {"office": 5, "bedroom": 1, "living_room": 0.3}, ("black", "gray", "white"), ("plastic", "metal"),
          build_monitor, states=_ON_OFF, supports=("desk",)),
    _spec("computer", "on_support", {"office": 4, "bedroom": 1}, ("black", "white", "gray"), ("metal", "plastic"), build_computer,
          supports=("desk", "shelf")),
    _spec("printer", "on_support", {"office": 4, "living_room": 0.3}, ("white", "black", "gray"), ("plastic",), build_printer,
          supports=("desk", "cabinet")),
    _spec("speaker", "floor_wall", {"living_room": 4, "office": 1, "bedroom": 0.5}, ("black", "white", "brown", "gray"),
          ("wood", "plastic"), build_speaker),
    _spec("fan", "floor", {"bedroom": 3, "living_room": 2, "office": 2, "garage": 0.5}, ("white", "black", "gray", "blue"),
          ("plastic", "metal"), build_fan),
    _spec("radiator", "floor_wall", {"bathroom": 2, "hallway": 2, "living_room": 1, "bedroom": 1, "office": 1, "entryway": 1,
                                     "kitchen": 0.5, "dining_room": 0.5},
          ("white", "gray", "black"), ("metal",), build_radiator),
    _spec("fireplace", "floor_wall", {"living_room": 3, "dining_room": 0.5, "bedroom": 0.3},
          ("white", "gray", "black", "beige", "red", "brown"), ("stone", "wood", "metal"), build_fireplace, states=_ON_OFF),
    _spec("piano", "floor_wall", {"living_room": 2, "office": 0.5}, ("black", "brown", "white"), ("wood",), build_piano),
    _spec("vacuum_cleaner", "floor", {"closet": 3, "hallway": 1, "laundry_room": 1, "living_room": 0.5, "garage": 0.5},
          ("red", "purple", "gray", "yellow", "black", "blue"), ("plastic", "metal"), build_vacuum_cleaner),
    _spec("safe", "floor_wall", {"closet": 2, "office": 2, "bedroom": 1, "garage": 0.5}, ("black", "gray", "green", "beige"), ("metal",),
          build_safe),
    # -- wall-mounted -------------------------------------------------------
    _spec("mirror", "wall", {"bathroom": 4, "entryway": 4, "bedroom": 2, "hallway": 2, "closet": 1.5},
          ("brown", "black", "white", "gray", "yellow"), ("wood", "metal", "plastic"), build_mirror, mount_height=1.05),
    _spec("painting", "wall", {"living_room": 3, "bedroom": 2, "hallway": 2, "dining_room": 2, "office": 1.5, "entryway": 1},
          _ALL_COLORS, ("wood", "metal"), build_painting, mount_height=1.2),
    _spec("wall_clock", "wall", {"kitchen": 3, "living_room": 2, "office": 2, "dining_room": 2, "hallway": 1, "bedroom": 0.5,
                                 "garage": 0.5},
          ("black", "white", "brown", "gray", "red", "blue"), ("wood", "metal", "plastic"), build_wall_clock, mount_height=1.75),
    _spec("curtain", "wall", {"bedroom": 4, "living_room": 3, "dining_room": 1, "office": 1, "bathroom": 0.3}, _ALL_COLORS,
          ("fabric",), build_curtain, states=_OPEN_CLOSED, mount_height=0.08),
    _spec("towel_rack", "wall", {"bathroom": 5, "kitchen": 1, "laundry_room": 0.5}, ("gray", "black", "white", "yellow"),
          ("metal", "wood"), build_towel_rack, mount_height=0.65),
    _spec("coat_rack", "floor", {"entryway": 5, "hallway": 2, "bedroom": 0.5, "closet": 0.5}, ("brown", "black", "white", "gray"),
          ("wood", "metal"), build_coat_rack),
    # -- floor objects ------------------------------------------------------
    _spec("shoe_rack", "floor_wall", {"entryway": 5, "closet": 3, "hallway": 2, "bedroom": 0.5}, ("brown", "black", "white", "gray"),
          ("wood", "metal", "plastic"), build_shoe_rack),
    _spec("potted_plant", "floor", {"living_room": 4, "office": 2, "hallway": 2, "entryway": 2, "bedroom": 1, "dining_room": 1,
                                    "bathroom": 0.5, "kitchen": 0.5},
          ("green",), ("ceramic", "plastic", "stone", "wicker"), build_potted_plant),
    _spec("floor_lamp", "floor", {"living_room": 4, "bedroom": 2, "office": 2, "hallway": 0.5},
          ("white", "beige", "black", "gray", "red", "blue", "green", "yellow", "orange"), ("metal", "wood"), build_floor_lamp,
          states=_ON_OFF),
    _spec("rug", "floor", {"living_room": 4, "bedroom": 3, "dining_room": 2, "hallway": 2, "entryway": 2, "office": 1, "bathroom": 1},
          _ALL_COLORS, ("fabric", "wicker"), build_rug),
    _spec("trash_can", "floor", {"kitchen": 4, "bathroom": 3, "office": 3, "garage": 3, "bedroom": 1, "laundry_room": 1,
                                 "living_room": 0.5},
          ("gray", "black", "white", "blue", "green", "red"), ("metal", "plastic"), build_trash_can),
    _spec("laundry_basket", "floor", {"laundry_room": 5, "closet": 3, "bedroom": 2, "bathroom": 2},
          ("beige", "white", "gray", "brown", "blue", "pink"), ("wicker", "plastic", "fabric"), build_laundry_basket, states=_FULL_EMPTY),
    _spec("workbench", "floor_wall", {"garage": 6, "laundry_room": 0.3}, ("gray", "red", "blue", "black", "green"), ("metal", "wood"),
          build_workbench),
    _spec("toolbox", "on_support", {"garage": 5, "laundry_room": 0.5, "closet": 0.5},
          ("red", "blue", "black", "gray", "yellow", "orange", "green"), ("metal", "plastic"), build_toolbox,
          supports=("workbench", "shelf", "cabinet")),
    _spec("bicycle", "floor", {"garage": 5, "entryway": 1, "hallway": 0.5}, _ALL_COLORS, ("metal",), build_bicycle),
    _spec("ladder", "floor", {"garage": 4, "laundry_room": 1, "closet": 1}, ("gray", "yellow", "orange", "red", "blue"),
          ("metal", "wood"), build_ladder),
    _spec("storage_box", "floor", {"closet": 4, "garage": 4, "bedroom": 1, "laundry_room": 1, "office": 0.5},
          ("blue", "white", "gray", "black", "green", "red", "beige", "pink", "brown"), ("plastic", "wood", "wicker", "fabric"),
          build_storage_box),
    _spec("dumbbell", "floor", {"garage": 3, "bedroom": 2, "living_room": 1, "office": 0.5},
          ("black", "gray", "red", "blue", "green", "pink", "purple", "yellow"), ("metal", "plastic"), build_dumbbell),
    _spec("basketball", "floor", {"garage": 3, "bedroom": 2, "hallway": 1, "closet": 1, "entryway": 1}, ("orange", "brown", "red", "blue"),
          ("leather", "plastic"), build_basketball),
    # -- small objects on supports ------------------------------------------
    _spec("laptop", "on_support", {"office": 3, "living_room": 1, "bedroom": 1, "dining_room": 0.5},
          ("gray", "black", "white", "blue", "pink"), ("metal", "plastic"), build_laptop,
          states=_OPEN_CLOSED, supports=("desk", "dining_table", "coffee_table", "bed", "side_table")),
    _spec("book", "on_support", {"office": 3, "living_room": 3, "bedroom": 3, "dining_room": 0.3, "hallway": 0.3}, _ALL_COLORS,
          ("fabric", "leather"), build_book,
          supports=("bookshelf", "shelf", "nightstand", "desk", "coffee_table", "side_table", "dining_table", "bed", "dresser")),
    _spec("vase", "on_support", {"living_room": 3, "dining_room": 3, "entryway": 2, "hallway": 1, "bedroom": 1, "kitchen": 0.5},
          _ALL_COLORS, ("ceramic", "glass", "metal", "stone"), build_vase, states=_FULL_EMPTY,
          supports=("dining_table", "coffee_table", "side_table", "tv_stand", "dresser", "fireplace", "shelf", "bookshelf", "piano",
                    "kitchen_island", "nightstand")),
    _spec("bowl", "on_support", {"kitchen": 4, "dining_room": 3, "living_room": 0.5},
          ("white", "beige", "blue", "green", "red", "black", "gray", "brown", "yellow"), ("ceramic", "glass", "wood", "plastic", "metal"),
          build_bowl, states=_FULL_EMPTY, supports=("dining_table", "kitchen_island", "cabinet", "coffee_table", "shelf")),
    _spec("cup", "on_support", {"kitchen": 3, "dining_room": 3, "office": 1, "living_room": 1, "bedroom": 0.5, "bathroom": 0.5},
          _ALL_COLORS, ("ceramic", "glass", "plastic"), build_cup,
          supports=("dining_table", "kitchen_island", "cabinet", "coffee_table", "desk", "side_table", "nightstand", "sink")),
    _spec("mug", "on_support", {"kitchen": 3, "office": 3, "dining_room": 1, "living_room": 1, "bedroom": 0.3}, _ALL_COLORS,
          ("ceramic",), build_mug,
          supports=("dining_table", "kitchen_island", "cabinet", "coffee_table", "desk", "side_table", "nightstand", "shelf")),
    _spec("plate", "on_support", {"dining_room": 4, "kitchen": 4, "living_room": 0.3},
          ("white", "beige", "blue", "green", "black", "gray", "red", "yellow"), ("ceramic", "glass", "plastic"), build_plate,
          supports=("dining_table", "kitchen_island", "cabinet", "coffee_table")),
    _spec("bottle", "on_support", {"kitchen": 3, "dining_room": 1, "office": 0.5, "garage": 0.5, "bathroom": 0.5, "bedroom": 0.5},
          ("blue", "green", "white", "gray", "red", "pink", "black", "orange"), ("plastic", "glass", "metal"), build_bottle,
          supports=("dining_table", "kitchen_island", "cabinet", "desk", "nightstand", "shelf", "workbench")),
    _spec("wine_bottle", "on_support", {"kitchen": 3, "dining_room": 4, "living_room": 0.5}, ("green", "black", "brown", "red", "white"),
          ("glass",), build_wine_bottle, supports=("dining_table", "kitchen_island", "cabinet", "shelf", "coffee_table")),
    _spec("table_lamp", "on_support", {"bedroom": 4, "living_room": 3, "office": 3, "hallway": 0.5, "entryway": 0.5},
          ("white", "beige", "black", "gray", "blue", "green", "red", "yellow"), ("ceramic", "metal", "glass"), build_table_lamp,
          states=_ON_OFF, supports=("nightstand", "side_table", "desk", "dresser")),
    _spec("candle", "on_support", {"dining_room": 3, "living_room": 2, "bathroom": 1, "bedroom": 1},
          ("white", "beige", "red", "yellow", "purple", "pink", "blue", "green", "orange"), ("metal", "glass", "ceramic"), build_candle,
          states=_ON_OFF, supports=("dining_table", "coffee_table", "side_table", "fireplace", "nightstand", "dresser", "sink", "shelf")),
    _spec("alarm_clock", "on_support", {"bedroom": 5, "office": 0.3}, ("red", "black", "white", "blue", "green", "yellow", "pink"),
          ("metal", "plastic"), build_alarm_clock, supports=("nightstand", "dresser", "desk")),
    _spec("keyboard", "on_support", {"office": 5, "bedroom": 0.5}, ("black", "white", "gray"), ("plastic",), build_keyboard,
          supports=("desk",)),
    _spec("pot", "on_support", {"kitchen": 5}, ("gray", "black", "red", "blue", "orange", "white"), ("metal", "ceramic", "stone"),
          build_pot, supports=("stove",) + _COUNTERS),
    _spec("pan", "on_support", {"kitchen": 5}, ("black", "gray", "red", "blue", "orange"), ("metal", "ceramic"), build_pan,
          supports=("stove",) + _COUNTERS),
    _spec("cutting_board", "on_support", {"kitchen": 5}, ("brown", "white", "beige", "green", "black", "blue", "red"),
          ("wood", "plastic", "stone"), build_cutting_board, supports=_COUNTERS + ("dining_table",)),
    _spec("pillow", "on_support", {"bedroom": 4, "living_room": 4, "office": 0.3}, _ALL_COLORS, ("fabric", "leather"), build_pillow,
          supports=("bed", "sofa", "armchair", "ottoman")),
    _spec("teddy_bear", "on_support", {"bedroom": 5, "living_room": 0.5}, ("brown", "beige", "white", "pink", "blue", "gray", "yellow"),
          ("fabric",), build_teddy_bear,
          supports=("bed", "crib", "sofa", "armchair", "shelf", "bookshelf", "dresser", "nightstand")),
    _spec("basket", "on_support", {"kitchen": 2, "living_room": 1.5, "dining_room": 1, "bathroom": 1, "laundry_room": 1, "entryway": 1},
          ("beige", "brown", "white", "black", "gray"), ("wicker", "fabric", "plastic", "metal"), build_basket,
          supports=("dining_table", "kitchen_island", "shelf", "bench", "coffee_table", "cabinet", "washing_machine", "dryer")),
    _spec("picture_frame", "on_support", {"living_room": 3, "bedroom": 3, "office": 2, "hallway": 0.5, "entryway": 0.5},
          ("black", "white", "brown", "gray", "yellow", "red", "blue"), ("wood", "metal", "plastic", "glass"), build_picture_frame,
          supports=("nightstand", "desk", "dresser", "side_table", "shelf", "bookshelf", "fireplace", "piano", "tv_stand")),
    _spec("soap_dispenser", "on_support", {"bathroom": 5, "kitchen": 2, "laundry_room": 0.5},
          ("white", "gray", "black", "green", "blue", "pink", "yellow", "beige"), ("ceramic", "glass", "plastic", "metal"),
          build_soap_dispenser, supports=("sink",) + _COUNTERS),
    _spec("towel", "on_support", {"bathroom": 5, "laundry_room": 2, "closet": 1, "kitchen": 0.5, "bedroom": 0.5}, _ALL_COLORS,
          ("fabric",), build_towel, supports=("shelf", "cabinet", "bench", "bed", "washing_machine", "dryer")),
    _spec("tissue_box", "on_support", {"bathroom": 2, "bedroom": 2, "living_room": 2, "office": 1}, _ALL_COLORS,
          ("plastic", "wood", "ceramic"), build_tissue_box,
          supports=("nightstand", "side_table", "coffee_table", "desk", "cabinet", "sink", "dresser")),
    _spec("globe", "on_support", {"office": 4, "bedroom": 1, "living_room": 1}, ("blue", "beige", "black", "green"),
          ("wood", "metal", "plastic"), build_globe, supports=("desk", "shelf", "side_table", "dresser")),
    _spec("sculpture", "on_support", {"living_room": 3, "entryway": 2, "hallway": 1, "office": 1, "dining_room": 0.5},
          ("white", "black", "gray", "beige", "brown", "yellow", "blue", "green", "red"), ("stone", "metal", "ceramic", "wood", "glass"),
          build_sculpture,
          supports=("coffee_table", "side_table", "shelf", "bookshelf", "fireplace", "tv_stand", "dresser", "piano")),
    _spec("remote_control", "on_support", {"living_room": 5, "bedroom": 1}, ("black", "gray", "white"), ("plastic",),
          build_remote_control, supports=("coffee_table", "sofa", "side_table", "tv_stand", "armchair", "nightstand", "bed")),
    _spec("spray_bottle", "on_support", {"laundry_room": 4, "kitchen": 2, "bathroom": 2, "garage": 1},
          ("blue", "green", "white", "yellow", "pink", "orange", "purple", "red"), ("plastic",), build_spray_bottle,
          supports=("shelf", "washing_machine", "dryer", "cabinet", "sink", "workbench")),
    _spec("dish_rack", "on_support", {"kitchen": 5}, ("gray", "white", "black", "green", "blue", "red"), ("metal", "plastic", "wood"),
          build_dish_rack, supports=_COUNTERS),
    _spec("fruit_bowl", "on_support", {"kitchen": 4, "dining_room": 4, "living_room": 0.5},
          ("white", "brown", "beige", "black", "gray", "blue", "green"), ("ceramic", "wood", "glass", "metal", "wicker"),
          build_fruit_bowl, states=_FULL_EMPTY, supports=("dining_table", "kitchen_island", "cabinet", "coffee_table")),
    _spec("watering_can", "on_support", {"garage": 2, "laundry_room": 2, "living_room": 1, "kitchen": 1},
          ("green", "red", "blue", "yellow", "gray", "orange", "white"), ("plastic", "metal"), build_watering_can,
          supports=("shelf", "cabinet", "workbench", "bench")),
    _spec("tennis_racket", "on_support", {"garage": 2, "bedroom": 2, "closet": 2, "entryway": 1, "hallway": 0.5}, _ALL_COLORS,
          ("metal", "plastic", "wood"), build_tennis_racket,
          supports=("shelf", "bench", "bed", "workbench", "storage_box", "dresser")),
    _spec("baseball_bat", "on_support", {"garage": 3, "bedroom": 1, "closet": 2, "entryway": 1},
          ("brown", "black", "beige", "gray", "red", "blue"), ("wood", "metal"), build_baseball_bat,
          supports=("bench", "bed", "workbench")),
    _spec("headphones", "on_support", {"office": 3, "bedroom": 3, "living_room": 1}, ("black", "white", "gray", "red", "blue", "pink"),
          ("plastic", "metal", "leather"), build_headphones,
          supports=("desk", "nightstand", "bed", "sofa", "side_table", "coffee_table", "shelf")),
    _spec("houseplant_small", "on_support", {"living_room": 2, "kitchen": 2, "bathroom": 2, "office": 2, "bedroom": 2, "dining_room": 1,
                                             "entryway": 1},
          ("red", "pink", "yellow", "purple", "white", "orange", "blue"), ("ceramic", "plastic", "stone", "wicker"),
          build_houseplant_small,
          supports=("desk", "side_table", "shelf", "bookshelf", "nightstand", "dining_table", "kitchen_island", "cabinet", "sink",
                    "dresser", "coffee_table", "tv_stand")),
)

CATALOGUE: Mapping[str, CategorySpec] = MappingProxyType({s.name: s for s in _SPECS})
"""Category name -> spec, for every category procedural houses can place."""
