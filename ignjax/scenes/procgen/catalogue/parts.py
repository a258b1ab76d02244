"""Parts and geometry helpers shared by the catalogue's builders.

Owns what a builder returns (:class:`Built` with its support surfaces,
:class:`Surface`; the :data:`Builder` signature), the palette and material
tints, the primitive part constructors (:func:`box`, :func:`cylinder`,
:func:`segment`, :func:`ring`, ...), exact part bounds (:func:`geom_aabb`),
the quaternion helpers and :func:`finish`, which centres a builder's parts on
their tight box. The builder frame is described in
:mod:`ignjax.scenes.procgen.catalogue`.

The quaternion helpers stay hand-written: ``scipy.spatial.transform.Rotation``
gives the same rotations but not the same bits (it normalises and composes
in another order, 1e-16..1e-14 apart), and houses must stay byte-identical.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from types import MappingProxyType
from typing import Callable, Sequence

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes, Geom


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
        geoms: parts in the builder frame (see :mod:`ignjax.scenes.procgen.catalogue`).
        half_extents: (hx, hy, hz) of the object's box; the box is centred
            at (0, 0, hz) in the builder frame.
        surfaces: support surfaces (tables, shelves, beds, counters).
    """

    geoms: tuple[Geom, ...]
    half_extents: tuple[float, float, float]
    surfaces: tuple[Surface, ...] = ()


Builder = Callable[[Attributes, np.random.Generator], Built]


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


AXIS_QUAT = {"z": (1.0, 0.0, 0.0, 0.0), "x": quat_axis_angle((0, 1, 0), math.pi / 2), "y": quat_axis_angle((1, 0, 0), math.pi / 2)}


def disk(part: str, radius: float, half_length: float, pos, color, material=None, axis: str = "z") -> Geom:
    """A cylinder whose axis is the frame's ``axis`` (``"x"``, ``"y"`` or ``"z"``)."""
    return cylinder(part, radius, half_length, pos, color, material, quat=AXIS_QUAT[axis])


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


def pick(rng: np.random.Generator, options: Sequence[str]) -> str:
    """One name of ``options`` drawn with ``rng``."""
    names = tuple(options)
    return str(names[int(rng.integers(len(names)))])


def doors_front(g: list, x: float, y0: float, y1: float, z0: float, z1: float, n: int, color, mat, opened: bool) -> None:
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
