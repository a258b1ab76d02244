"""Import any USD stage into a :class:`~ignjax.scenes.model.Scene`.

The public entry point is :func:`ignjax.scenes.io.usd.load_usd`; this module
holds the machinery and documents the rules.

Opening
    ``Usd.Stage.Open(path, load=LoadAll)`` (payloads loaded). Every
    composition error (a missing sublayer, reference or payload) becomes a
    :class:`~ignjax.scenes.io.usd.UsdImportWarning` naming the missing asset
    and the layer or prim that refers to it; whatever composes is imported.
    An authored ``defaultPrim`` that names no prim is warned about and
    ignored (all root prims are imported anyway).

Frame and units
    ``upAxis`` ``Z`` is kept, ``Y`` is rotated to Z-up with
    (x, y, z) -> (x, -z, y); unauthored means USD's fallback (Y); anything
    else is an error. ``metersPerUnit`` is the stage's value, or USD's
    fallback 0.01 (centimetres) when unauthored. Everything is returned in
    metres; ``SceneMeta`` records the original axis and unit.

Layers with their own units (``correct_layer_units=True``, the default)
    Plain USD ignores ``metersPerUnit`` on sublayers and referenced or
    payloaded layers. We do not: when any layer used by the stage authors a
    ``metersPerUnit`` different from the stage's, every length is read in
    the units of the layer its value comes from. Precisely:

    * a translation (``translate*`` ops, and the translation part of
      ``transform`` ops, pivots included) is scaled by the unit of the layer
      holding the strongest opinion for that op's value;
    * a geometry prim's lengths (``points``, ``size``, ``radius``,
      ``height``, ...) by the unit of the layer holding its first authored
      geometry attribute; for unauthored (fallback) values, by the unit of
      the layer that defines the prim (the weakest ``def`` spec: for a
      referenced asset, the asset's layer);
    * PointInstancer ``positions`` by the unit of their layer;
    * rotations and scales are unitless and left alone.

    A layer's unit is its own authored ``metersPerUnit``, else that of the
    root layer of its layer stack (the referenced asset's root layer), else
    the stage's. So a centimetre stage that references a metre asset at
    ``translate = (300, 0, 0)`` puts the asset, at its true metre size,
    3 m from the origin. In ``metersPerUnit_mix.usda`` (stage 100 m/unit,
    cubes defined in sublayers of 1 and 10 m/unit, moved by overs in the
    root layer) the cubes are 2 m, 20 m and 200 m wide at x = 300 m,
    600 m and 0 m; with ``correct_layer_units=False`` all three are 200 m,
    as in a USD viewer. Differing ``upAxis`` in sublayers/references is
    not corrected (a warning is issued).

What is traversed
    Active, defined, loaded, non-abstract prims, through instance proxies
    (so every instance of an instanceable prim is seen). Subtrees that are
    ``invisible`` or whose ``purpose`` is ``guide`` or ``proxy`` are
    skipped, and so are PointInstancer prototypes (they appear once per
    point instead). Geometry: ``Mesh``, ``Cube``, ``Sphere``, ``Cylinder``,
    ``Capsule``, ``Cone``, ``Plane``, ``Cylinder_1``, ``Capsule_1``; other
    gprim types (curves, points, NURBS) are skipped with one warning.

Which prims are object instances (each geometry prim belongs to exactly one)
    1. ``ignjax:kind`` prims written by :func:`~ignjax.scenes.io.usd.save_usd`
       (rooms, walls, doors, instances) are restored exactly (an instance
       moved or turned about Z in a USD editor keeps its stored geometry
       and box, moved along; one scaled or tilted is measured again).
    2. A prim with a semantic class label (``ignjax:category``,
       ``semantics:labels:class`` or Isaac ``semantic:*:params:semanticData``
       with ``semanticType == "class"``) owns the geometry below it, down
       to the next labelled prim. A labelled prim below one with the same
       category is part of it (labels applied to every mesh of an object);
       below one with another category it is an object of its own.
    3. Geometry with no labelled ancestor belongs to its topmost ancestor
       whose model Kind is ``component`` (or derives from it, or is a
       custom, unregistered kind such as ``chair``).
    4. Otherwise to the child of its *container* that it lies under
       (``/World/Table`` for ``/World/Table/Leg``), or to the root prim
       itself when a root prim is a geometry prim. Containers are the
       root prims (all of them, the ``defaultPrim`` first) and room prims.
    5. Every point of a ``PointInstancer`` is its own instance, with the
       geometry of its prototype.

Rooms
    A prim whose label names a room (``Kitchen``, ``living room``; not an
    object category such as ``toilet``), or an ``ignjax`` room prim, is a
    room. It is a container: below it, floors (geometry named or labelled
    ``floor``/``ground``, or the room prim's own geometry) make the room's
    polygon, everything else is furniture by rules 2-4. The polygon is the
    ``ignjax:polygon`` when stored; else the outline of the floors'
    upward-facing faces when that is one simple loop; else the convex hull
    of the floors' footprint; else the convex hull of the boxes of the
    objects below the room prim. Without any room prim: one room
    ``room_0`` labelled ``other`` covering the convex hull of all boxes
    (and walls). ``Instance.room`` is the room whose polygon contains the
    centre of the instance's box footprint, else the room prim it lies
    under, else None; restored instances keep their stored room.

Categories
    From the label; else from a custom Kind; else from the prim name; else
    from the file stem of the asset the prim references or payloads; all
    through :func:`vocab.normalize_category`. Names that say nothing
    (``Mesh``, ``Cube``, ``Xform``, ``Geom`` ...) are skipped; the last
    resort is ``"unknown"``. For PointInstancer points: the prototype's
    label, the instancer's label, the prototype's kind, the prototype's
    name, the instancer's name, the prototype's asset. ``structural`` is
    :func:`vocab.is_structural` of the category. Ids are the prim names
    (``<instancer>_<k>`` for points), made unique with ``_2``, ``_3``...;
    ``Instance.name`` is the prim path.

Geometry and boxes
    World transforms come from ``UsdGeom.XformCache`` (or, with mixed
    layer units, from the per-op composition above). Mesh faces with more
    than three vertices are triangulated (quads along their inner
    diagonal, larger faces ear-clipped in their best-fit plane, concave
    ones included); meshes are cleaned with trimesh (merged vertices, no
    degenerate faces). ``Cube``, ``Sphere``, ``Cylinder`` and ``Capsule``
    become box/sphere/ellipsoid/cylinder/capsule geoms when the world
    transform is a rotation times a scale along the primitive's own axes
    (and, for cylinders, equal radial scales; for capsules and spheres,
    uniform scale; a non-uniformly scaled sphere is an ellipsoid); anything
    else becomes a mesh. The upright box is the minimum-area rectangle of
    the footprint, or the rectangle aligned with the object's own heading
    (its prim's x axis) when that is within 0.1 % of the minimum.
    ``position`` is the box's footprint centre at its lowest point, ``yaw``
    the prim's heading. Colours from ``primvars:displayColor`` /
    ``displayOpacity``, else the bound ``UsdPreviewSurface``'s
    ``diffuseColor``/``opacity``; the dominant one (by surface area) names
    the instance's colour attribute. Support relations are not inferred.

Scene
    Id: the ``scene_id`` argument, else the id stored by ``save_usd``, else
    the file stem. A stage without geometry, non-finite transforms,
    points, positions or sizes are errors naming the prim.
"""

from __future__ import annotations

import functools
import json
import math
import re
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np
from pxr import Kind, Pcp, Sdf, Usd, UsdGeom, UsdShade

from ignjax.errors import SceneError
from ignjax.scenes import vocab
from ignjax.scenes.model import (
    Attributes,
    Door,
    Geom,
    Instance,
    MeshData,
    OrientedBox,
    Room,
    Scene,
    SceneMeta,
    Wall,
    points_in_polygon,
    polygon_area,
    polygon_problem,
    validate_scene,
)
from ignjax.scenes.io.usd import (
    ATTR_ID,
    ATTR_KIND,
    NS,
    UsdImportWarning,
    open_stage,
    prim_semantic_label,
    stage_meters_per_unit,
    stage_up_axis,
    triangulate_faces,
)

TIME = Usd.TimeCode.EarliestTime()

_BUILTIN_KINDS = frozenset({"model", "group", "assembly", "component", "subcomponent"})
_GENERIC_NAMES = frozenset({
    "unknown", "xform", "mesh", "cube", "sphere", "cylinder", "capsule", "cone", "plane", "geom", "geometry",
    "geo", "object", "obj", "prim", "model", "root", "group", "scope", "node", "instance", "prototype",
    "proto", "default", "asset", "shape", "world", "scene", "body", "part", "component", "looks", "render",
    "primitive", "polygon", "poly", "poly_surface", "polysurface", "transform", "null", "empty", "item",
    "point_instancer", "instancer", "material", "visual", "visuals", "collision", "collisions", "main",
})
_SUPPORTED_GPRIMS = ("Mesh", "Cube", "Sphere", "Cylinder", "Capsule", "Cone", "Plane", "Cylinder_1", "Capsule_1")
_TRANSLATE_OPS = frozenset(
    getattr(UsdGeom.XformOp, n) for n in ("TypeTranslate", "TypeTranslateX", "TypeTranslateY", "TypeTranslateZ", "TypeTransform")
    if hasattr(UsdGeom.XformOp, n)
)
_Y_TO_Z = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
_AXIS_TO_Z = {  # rotation taking the canonical +z axis onto the primitive's axis
    "X": np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    "Y": np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
    "Z": np.eye(3),
}


# ---------------------------------------------------------------------------
# Small numeric helpers
# ---------------------------------------------------------------------------


def _col(gf_matrix) -> np.ndarray:
    """Gf (row-vector) 4x4 -> numpy column-vector convention."""
    return np.array(gf_matrix, dtype=np.float64).T


def _scale4(s: float) -> np.ndarray:
    return np.diag([s, s, s, 1.0])


def _pose(position, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:3, 3] = position
    return m


def _apply(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    # Shape: (N, 3) -> (N, 3)
    return pts @ m[:3, :3].T + m[:3, 3]


def _wrap(angle: float) -> float:
    a = math.remainder(angle, 2 * math.pi)
    return math.pi if a == -math.pi else a


def quat_from_matrix(r: np.ndarray) -> tuple[float, float, float, float]:
    """(w, x, y, z) unit quaternion of a 3x3 rotation matrix, w >= 0."""
    m = np.asarray(r, dtype=np.float64)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    q = np.asarray(q)
    q = q / np.linalg.norm(q)
    if q[0] < 0:
        q = -q
    return tuple(float(v) for v in q)


def min_area_rect(xy) -> tuple[np.ndarray, np.ndarray, float]:
    """Minimum-area enclosing rectangle of 2-D points.

    Returns:
        (center (2,), half extents (2,), yaw): the rectangle's x axis is at
        angle ``yaw`` in [0, pi/2).
    """
    from scipy.spatial import ConvexHull, QhullError

    p = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    try:
        h = p[ConvexHull(p).vertices]
    except (QhullError, ValueError):
        h = p
    e = np.roll(h, -1, axis=0) - h
    angles = np.mod(np.arctan2(e[:, 1], e[:, 0]), math.pi / 2)
    angles = np.unique(np.concatenate([[0.0], angles[np.hypot(e[:, 0], e[:, 1]) > 1e-12]]))
    lo, hi = _rect_extents(h, angles)
    area = np.prod(hi - lo, axis=1)
    k = int(np.argmin(area))
    return _rect_from(lo[k], hi[k], float(angles[k]))


def _rect_extents(h: np.ndarray, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    # Shape: h (P, 2), angles (A,) -> lo, hi (A, 2)
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    u = h[None, :, 0] * c + h[None, :, 1] * s
    v = -h[None, :, 0] * s + h[None, :, 1] * c
    return np.stack([u.min(1), v.min(1)], 1), np.stack([u.max(1), v.max(1)], 1)


def _rect_from(lo, hi, yaw: float) -> tuple[np.ndarray, np.ndarray, float]:
    cu, cv = (lo + hi) / 2
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([cu * c - cv * s, cu * s + cv * c]), (hi - lo) / 2, yaw


def _hull_polygon(xy: np.ndarray) -> list[tuple[float, float]] | None:
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(xy)
    except (QhullError, ValueError):
        return None
    poly = [tuple(map(float, xy[i])) for i in hull.vertices]
    return poly if polygon_problem(poly) is None else None


def _padded_rect(xy: np.ndarray, pad: float = 0.05) -> list[tuple[float, float]]:
    lo, hi = xy.min(0) - pad, xy.max(0) + pad
    return [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])]


# ---------------------------------------------------------------------------
# Canonical primitive meshes (surfaces of revolution about +z)
# ---------------------------------------------------------------------------


def _revolve(profile, sections: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """Closed mesh of revolution about z of a profile [(r, z), ...] that runs
    from the bottom pole (r = 0) to the top pole (r = 0)."""
    prof = np.asarray(profile, dtype=np.float64)
    inner = prof[1:-1]
    phi = 2 * math.pi * np.arange(sections) / sections
    rings = np.stack([np.outer(inner[:, 0], np.cos(phi)), np.outer(inner[:, 0], np.sin(phi)),
                      np.repeat(inner[:, 1:2], sections, axis=1)], axis=-1).reshape(-1, 3)
    verts = np.concatenate([[[0.0, 0.0, prof[0, 1]]], rings, [[0.0, 0.0, prof[-1, 1]]]])
    top = len(verts) - 1
    j = np.arange(sections)
    jn = (j + 1) % sections
    faces = [np.stack([np.zeros(sections, int), 1 + jn, 1 + j], 1)]
    for k in range(len(inner) - 1):
        a, b = 1 + k * sections, 1 + (k + 1) * sections
        faces += [np.stack([a + j, a + jn, b + jn], 1), np.stack([a + j, b + jn, b + j], 1)]
    last = 1 + (len(inner) - 1) * sections
    faces.append(np.stack([np.full(sections, top), last + j, last + jn], 1))
    f = np.concatenate(faces)
    tri = verts[f]
    vol = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum()
    if vol < 0:
        f = f[:, [0, 2, 1]]
    return verts, f


def _arc(radius: float, z0: float, lower: bool, n: int = 8):
    t = np.linspace(0.0, math.pi / 2, n + 1)
    if lower:
        return [(radius * math.sin(a), z0 - radius * math.cos(a)) for a in t]
    return [(radius * math.cos(a), z0 + radius * math.sin(a)) for a in t]


@functools.lru_cache(maxsize=256)
def _canonical_mesh(kind: str, params: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of a USD primitive in its own frame with its axis on +z."""
    if kind == "Cube":
        h = params[0] / 2
        v = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])
        f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
        return v, f
    if kind == "Sphere":
        r = params[0]
        return _revolve(_arc(r, 0.0, True) + _arc(r, 0.0, False)[1:])
    if kind in ("Cylinder", "Cone"):
        r_bottom, r_top, height = params
        prof = [(0.0, -height / 2), (r_bottom, -height / 2)]
        prof += [(r_top, height / 2), (0.0, height / 2)] if r_top > 0 else [(0.0, height / 2)]
        return _revolve(prof)
    if kind == "Capsule":
        r_bottom, r_top, height = params
        if abs(r_bottom - r_top) <= 1e-12 * max(r_bottom, 1e-300):
            return _revolve(_arc(r_bottom, -height / 2, True) + _arc(r_top, height / 2, False))
        import trimesh

        a, _ = _canonical_mesh("Sphere", (r_bottom,))
        b, _ = _canonical_mesh("Sphere", (r_top,))
        hull = trimesh.convex.convex_hull(np.concatenate([a - [0, 0, height / 2], b + [0, 0, height / 2]]))
        return np.asarray(hull.vertices), np.asarray(hull.faces)
    if kind == "Plane":
        w, length = params[0] / 2, params[1] / 2
        v = np.array([[-w, -length, 0.0], [w, -length, 0.0], [w, length, 0.0], [-w, length, 0.0]])
        return v, np.array([[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]])
    raise ValueError(kind)


# ---------------------------------------------------------------------------
# Frames and units
# ---------------------------------------------------------------------------


def _authored_mpu(layer) -> float | None:
    root = layer.pseudoRoot
    if root is not None and root.HasInfo("metersPerUnit"):
        try:
            v = float(root.GetInfo("metersPerUnit"))
        except (TypeError, ValueError):
            return None
        return v if math.isfinite(v) and v > 0 else None
    return None


def _nodes(prim_index) -> list:
    """The prim index's nodes in strength order (strongest first)."""
    out = []

    def walk(node):
        out.append(node)
        for child in node.children:
            walk(child)

    if prim_index is not None and prim_index.IsValid():
        walk(prim_index.rootNode)
    return out


class _Frames:
    """World transforms in metres, Z up, and the unit of each length value.

    ``frame(prim)`` maps the prim's local space, measured in metres, to the
    world (metres, Z up); ``unit(...)`` is how many metres one raw unit of a
    value is. A prim's raw geometry maps to the world by
    ``frame(prim) @ diag(unit, unit, unit, 1)``.
    """

    def __init__(self, stage, path: str, up: str, mpu: float, correct: bool):
        self.stage, self.path, self.mpu = stage, path, mpu
        self.conv = _Y_TO_Z.copy() if up == "Y" else np.eye(4)
        self.cache = UsdGeom.XformCache(TIME)
        self._layer_mpu: dict[str, float | None] = {}
        for layer in stage.GetUsedLayers():
            self._layer_mpu[layer.identifier] = _authored_mpu(layer)
        self.mixed = correct and any(v is not None and abs(v / mpu - 1.0) > 1e-9 for v in self._layer_mpu.values())
        self._chain: dict = {}
        self._def_unit: dict = {}

    # -- units ------------------------------------------------------------------
    def layer_unit(self, layer, layer_stack=None) -> float:
        v = self._layer_mpu.get(layer.identifier)
        if v is None and layer.identifier not in self._layer_mpu:
            v = _authored_mpu(layer)
        if v is None and layer_stack is not None:
            root = layer_stack.identifier.rootLayer
            if root is not None:
                v = _authored_mpu(root)
        return self.mpu if v is None else v

    def defining_unit(self, prim) -> float:
        """Unit of the layer holding the weakest ``def`` of the prim."""
        if not self.mixed:
            return self.mpu
        key = prim.GetPath()
        if key not in self._def_unit:
            unit = self.mpu
            for node in reversed(_nodes(prim.GetPrimIndex())):
                found = False
                for layer in reversed(node.layerStack.layers):
                    spec = layer.GetPrimAtPath(node.path)
                    if spec is not None and spec.specifier == Sdf.SpecifierDef:
                        unit, found = self.layer_unit(layer, node.layerStack), True
                        break
                if found:
                    break
            self._def_unit[key] = unit
        return self._def_unit[key]

    def attr_unit(self, attr, prim) -> float:
        """Unit of the layer providing ``attr``'s value."""
        if not self.mixed:
            return self.mpu
        info = attr.GetResolveInfo(TIME)
        if info.GetSource() in (Usd.ResolveInfoSourceNone, Usd.ResolveInfoSourceFallback):
            return self.defining_unit(prim)
        node = info.GetNode()
        stack = node.layerStack if node else None
        for spec in attr.GetPropertyStack(TIME):
            if spec.HasDefaultValue() or spec.layer.GetNumTimeSamplesForPath(spec.path) > 0:
                return self.layer_unit(spec.layer, stack)
        return self.defining_unit(prim)

    def unit(self, prim, attr_names) -> float:
        """Unit of a prim's geometry: that of its first authored attribute
        among ``attr_names``, else of the layer that defines the prim."""
        if not self.mixed:
            return self.mpu
        for name in attr_names:
            attr = prim.GetAttribute(name)
            if attr and attr.HasAuthoredValue():
                return self.attr_unit(attr, prim)
        return self.defining_unit(prim)

    # -- transforms -------------------------------------------------------------
    def _local_m(self, prim) -> tuple[np.ndarray, bool]:
        xf = UsdGeom.Xformable(prim)
        if not xf:
            return np.eye(4), False
        m = np.eye(4)
        for op in xf.GetOrderedXformOps():
            om = _col(op.GetOpTransform(TIME))
            if op.GetOpType() in _TRANSLATE_OPS:
                om[:3, 3] *= self.attr_unit(op.GetAttr(), prim)
            m = m @ om
        return m, bool(xf.GetResetXformStack())

    def _chain_m(self, prim) -> np.ndarray:
        key = prim.GetPath()
        if key == Sdf.Path.absoluteRootPath:
            return np.eye(4)
        if key not in self._chain:
            local, reset = self._local_m(prim)
            self._chain[key] = local if reset else self._chain_m(prim.GetParent()) @ local
        return self._chain[key]

    def frame(self, prim) -> np.ndarray:
        if self.mixed:
            m = self.conv @ self._chain_m(prim)
        else:
            w = _col(self.cache.GetLocalToWorldTransform(prim))
            m = self.conv @ _scale4(self.mpu) @ w @ _scale4(1.0 / self.mpu)
        if not np.all(np.isfinite(m)):
            self._raise_nonfinite(prim)
        return m

    def relative(self, prim, ancestor) -> np.ndarray:
        """``prim``'s local space (metres) -> ``ancestor``'s local space (metres)."""
        if self.mixed:
            m = np.eye(4)
            p = prim
            while p.GetPath() != ancestor.GetPath() and p.GetPath() != Sdf.Path.absoluteRootPath:
                local, reset = self._local_m(p)
                m = local @ m
                if reset:
                    break
                p = p.GetParent()
        else:
            rel, _ = self.cache.ComputeRelativeTransform(prim, ancestor)
            m = _scale4(self.mpu) @ _col(rel) @ _scale4(1.0 / self.mpu)
        if not np.all(np.isfinite(m)):
            self._raise_nonfinite(prim)
        return m

    def _raise_nonfinite(self, prim):
        chain = []
        p = prim
        while p and p.GetPath() != Sdf.Path.absoluteRootPath:
            chain.append(p)
            p = p.GetParent()
        for p in reversed(chain):
            local, _ = self.cache.GetLocalTransformation(p)
            if not np.all(np.isfinite(np.array(local))):
                raise SceneError(self.path, str(p.GetPath()), "transform has NaN or infinite values")
        raise SceneError(self.path, str(prim.GetPath()), "transform has NaN or infinite values")


# ---------------------------------------------------------------------------
# Geometry parts
# ---------------------------------------------------------------------------


@dataclass
class _Source:
    """A geometry prim's raw geometry, before placing it in the world."""

    prim_path: str
    usd_type: str
    params: tuple[float, ...]
    axis: str
    verts: np.ndarray  # raw units, primitive frame (axis on +z for primitives)
    faces: np.ndarray
    rgba: tuple[float, float, float, float]
    has_color: bool
    role: str  # "geom" (a part of the object) or "bbox" (an exported stand-in box)


@dataclass
class _Part:
    """A geometry prim placed in the world (metres, Z up)."""

    kind: str
    size: tuple[float, float, float]
    pose: np.ndarray | None  # rigid 4x4 for primitives; None for meshes
    verts: np.ndarray  # world vertices (for boxes, footprints, meshes)
    faces: np.ndarray
    rgba: tuple[float, float, float, float]
    has_color: bool
    role: str
    prim_path: str

    @property
    def area(self) -> float:
        if len(self.faces) == 0:
            return 0.0
        t = self.verts[self.faces]
        return float(0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum())


def _decompose(g: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(R, s) with g[:3, :3] == R @ diag(s), R a proper rotation; None when the
    linear part has shear, a mirror or a zero scale."""
    a = g[:3, :3]
    s = np.linalg.norm(a, axis=0)
    if np.any(s <= 1e-12):
        return None
    r = a / s
    if not np.allclose(r.T @ r, np.eye(3), atol=1e-6) or np.linalg.det(r) <= 0:
        return None
    return r, s


def _close(a: float, b: float, rtol: float = 1e-6) -> bool:
    return abs(a - b) <= rtol * max(abs(a), abs(b))


def _place(src: _Source, g: np.ndarray) -> _Part | None:
    """Place raw geometry with ``g`` (raw primitive frame -> world metres)."""
    if src.usd_type != "Mesh" and src.axis != "Z":
        rot = np.eye(4)
        rot[:3, :3] = _AXIS_TO_Z[src.axis]
        g = g @ rot
    verts = _apply(g, src.verts)
    part = _Part("mesh", (1.0, 1.0, 1.0), None, verts, src.faces, src.rgba, src.has_color, src.role, src.prim_path)
    t = src.usd_type
    if t in ("Cube", "Sphere", "Cylinder", "Capsule"):
        d = _decompose(g)
        if d is None:
            return part
        r, s = d
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = r, g[:3, 3]
        p = src.params
        if t == "Cube":
            h = p[0] / 2
            kind, size = "box", (h * s[0], h * s[1], h * s[2])
        elif t == "Sphere":
            if _close(s[0], s[1]) and _close(s[1], s[2]):
                kind, size = "sphere", (p[0] * s[0], 0.0, 0.0)
            else:
                kind, size = "ellipsoid", (p[0] * s[0], p[0] * s[1], p[0] * s[2])
        elif t == "Cylinder":
            if not (_close(s[0], s[1]) and _close(p[0], p[1])):
                return part
            kind, size = "cylinder", (p[0] * s[0], p[2] / 2 * s[2], 0.0)
        else:
            if not (_close(s[0], s[1]) and _close(s[1], s[2]) and _close(p[0], p[1])):
                return part
            kind, size = "capsule", (p[0] * s[0], p[2] / 2 * s[2], 0.0)
        part.kind, part.size, part.pose = kind, size, pose
    return part


def _float(prim, name: str, default: float, path: str) -> float:
    attr = prim.GetAttribute(name)
    value = attr.Get(TIME) if attr else None
    v = float(default if value is None else value)
    if not math.isfinite(v) or v < 0:
        raise SceneError(path, f"{prim.GetPath()}.{name}", f"must be a finite non-negative number, got {v!r}")
    return v


def _token(prim, name: str, default: str) -> str:
    attr = prim.GetAttribute(name)
    value = attr.Get(TIME) if attr else None
    return str(value) if value else default


def _display_color(prim) -> tuple[tuple[float, float, float, float], bool]:
    pv = UsdGeom.PrimvarsAPI(prim)
    rgb, alpha, has = None, 1.0, False
    c = pv.FindPrimvarWithInheritance("displayColor")
    if c and c.HasAuthoredValue():
        vals = c.ComputeFlattened(TIME)
        if vals is not None and len(vals):
            arr = np.asarray(vals, dtype=np.float64).reshape(-1, 3)
            if np.all(np.isfinite(arr)):
                rgb, has = arr.mean(0), True
    o = pv.FindPrimvarWithInheritance("displayOpacity")
    if o and o.HasAuthoredValue():
        vals = o.ComputeFlattened(TIME)
        if vals is not None and len(vals) and np.all(np.isfinite(np.asarray(vals, dtype=np.float64))):
            alpha = float(np.mean(np.asarray(vals, dtype=np.float64)))
    if rgb is None:
        rgb, alpha_m, has = _material_color(prim)
        if alpha_m is not None:
            alpha = alpha_m
    rgba = tuple(float(np.clip(v, 0.0, 1.0)) for v in (*rgb, alpha))
    return rgba, has


def _material_color(prim):
    default = (np.array([0.7, 0.7, 0.7]), None, False)
    try:
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
    except Exception:  # noqa: BLE001 - exotic binding setups: fall back to grey
        return default
    if not material:
        return default
    shader, _, _ = material.ComputeSurfaceSource()
    if not shader or shader.GetIdAttr().Get() != "UsdPreviewSurface":
        return default
    color, alpha = None, None
    diffuse = shader.GetInput("diffuseColor")
    if diffuse and not diffuse.HasConnectedSource() and diffuse.Get() is not None:
        color = np.asarray(diffuse.Get(), dtype=np.float64)
    opacity = shader.GetInput("opacity")
    if opacity and not opacity.HasConnectedSource() and opacity.Get() is not None:
        alpha = float(opacity.Get())
    if color is None or not np.all(np.isfinite(color)):
        return (default[0], alpha, False)
    return color, alpha, True


def _mesh_source(prim, path: str) -> tuple[np.ndarray, np.ndarray]:
    import trimesh

    mesh = UsdGeom.Mesh(prim)
    where = str(prim.GetPath())
    pts = mesh.GetPointsAttr().Get(TIME)
    pts = np.zeros((0, 3)) if pts is None else np.asarray(pts, dtype=np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(pts)):
        raise SceneError(path, f"{where}.points", "points have NaN or infinite values")
    counts = mesh.GetFaceVertexCountsAttr().Get(TIME)
    indices = mesh.GetFaceVertexIndicesAttr().Get(TIME)
    counts = np.zeros(0, np.int64) if counts is None else np.asarray(counts, dtype=np.int64)
    indices = np.zeros(0, np.int64) if indices is None else np.asarray(indices, dtype=np.int64)
    holes = mesh.GetHoleIndicesAttr().Get(TIME) or ()
    left = mesh.GetOrientationAttr().Get(TIME) == UsdGeom.Tokens.leftHanded
    faces = triangulate_faces(pts, counts, indices, left_handed=left, holes=list(holes), path=path,
                              where=f"{where}.faceVertexIndices")
    if len(faces) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    tm = trimesh.Trimesh(vertices=pts, faces=faces, process=True, validate=False)
    tm.update_faces(tm.nondegenerate_faces())
    tm.remove_unreferenced_vertices()
    return np.asarray(tm.vertices, dtype=np.float64), np.asarray(tm.faces, dtype=np.int64)


_GEOM_ATTRS = {
    "Mesh": ("points",), "Cube": ("size",), "Sphere": ("radius",), "Cylinder": ("radius", "height"),
    "Capsule": ("radius", "height"), "Cone": ("radius", "height"), "Plane": ("width", "length"),
    "Cylinder_1": ("radiusBottom", "radiusTop", "height"), "Capsule_1": ("radiusBottom", "radiusTop", "height"),
}


def _gprim_type(prim) -> str | None:
    t = str(prim.GetTypeName())
    if t in _SUPPORTED_GPRIMS:
        return t
    for name in _SUPPORTED_GPRIMS:
        schema = getattr(UsdGeom, name, None)
        if schema is not None and prim.IsA(schema):
            return name
    return None


def _source(prim, path: str) -> _Source | None:
    t = _gprim_type(prim)
    axis = "Z"
    if t == "Mesh":
        verts, faces = _mesh_source(prim, path)
        params: tuple[float, ...] = ()
    else:
        if t == "Cube":
            params = (_float(prim, "size", 2.0, path),)
        elif t == "Sphere":
            params = (_float(prim, "radius", 1.0, path),)
        elif t in ("Cylinder", "Cone", "Capsule"):
            r = _float(prim, "radius", 1.0 if t != "Capsule" else 0.5, path)
            params = (r, 0.0 if t == "Cone" else r, _float(prim, "height", 2.0 if t != "Capsule" else 1.0, path))
        elif t in ("Cylinder_1", "Capsule_1"):
            d = 1.0 if t == "Cylinder_1" else 0.5
            params = (_float(prim, "radiusBottom", d, path), _float(prim, "radiusTop", d, path),
                      _float(prim, "height", 2.0 if t == "Cylinder_1" else 1.0, path))
            t = "Cylinder" if t == "Cylinder_1" else "Capsule"
        elif t == "Plane":
            params = (_float(prim, "width", 2.0, path), _float(prim, "length", 2.0, path))
        else:
            return None
        axis = _token(prim, "axis", "Z") if t != "Cube" and t != "Sphere" else "Z"
        axis = axis if axis in _AXIS_TO_Z else "Z"
        verts, faces = _canonical_mesh(t, params)
    if len(faces) == 0:
        return None
    rgba, has = _display_color(prim)
    role = "bbox" if _token(prim, ATTR_KIND, "") == "bbox" else "geom"
    return _Source(str(prim.GetPath()), t, params, axis, verts, faces, rgba, has, role)


# ---------------------------------------------------------------------------
# Owners (what becomes an instance or a room) and the traversal
# ---------------------------------------------------------------------------


@dataclass(eq=False)
class _Owner:
    prim: object
    role: str  # "instance" | "room" | "ignjax_instance" | "ignjax_room"
    label: str | None = None
    gprims: list = field(default_factory=list)
    room: "_Owner | None" = None  # the room prim this owner lies under, if any

    @functools.cached_property
    def is_floor(self) -> bool:
        """Named or labelled as a floor (``Floor``, ``FloorSlab``, ``ground_01``)."""
        text = self.label or self.prim.GetName()
        words = set(_snake(text).split("_"))
        return vocab.normalize_category(text) == "floor" or bool(words & {"floor", "ground", "flooring"})


class _Ctx(NamedTuple):
    label: _Owner | None = None  # nearest labelled (or ignjax instance) owner
    label_cat: str | None = None
    kind: _Owner | None = None  # topmost component-kind owner
    root: _Owner | None = None  # child of the nearest container
    room: _Owner | None = None  # nearest room prim
    container: bool = False  # children of this prim are objects (root prims, room prims)


def _snake(text: str) -> str:
    text = re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", text.strip())
    text = re.sub(r"([A-Z]+)([A-Z][a-z])", r"\1_\2", text)
    return re.sub(r"[^0-9A-Za-z]+", "_", text).strip("_").lower()


def room_label_of(text: str | None) -> str | None:
    """The room label that ``text`` names (``"Kitchen_2"`` -> ``kitchen``),
    or None when it names no room or names an object category."""
    if not text:
        return None
    label = vocab.normalize_room_label(text)
    if label == vocab.OTHER_ROOM or vocab.is_target_eligible(vocab.normalize_category(text)):
        return None
    key = re.sub(r"(_?\d+)+$", "", _snake(text))
    words = [w for w in key.split("_") if w]
    if not words:
        return None
    last = words[-1]
    if last == "room" or vocab.normalize_room_label(last) != vocab.OTHER_ROOM \
            or vocab.normalize_room_label(key.replace("_", "")) != vocab.OTHER_ROOM:
        return label
    return None


def _custom_kind(prim) -> str | None:
    kind = str(Usd.ModelAPI(prim).GetKind() or "")
    if not kind or kind in _BUILTIN_KINDS:
        return None
    if Kind.Registry.HasKind(kind):
        return None
    return kind


def _is_component(prim) -> bool:
    kind = str(Usd.ModelAPI(prim).GetKind() or "")
    if not kind:
        return False
    if kind in _BUILTIN_KINDS:
        return kind == "component"
    if Kind.Registry.HasKind(kind):
        return bool(Kind.Registry.IsA(kind, Kind.Tokens.component))
    return True


def _hidden(prim) -> bool:
    if not prim.IsA(UsdGeom.Imageable):
        return False
    img = UsdGeom.Imageable(prim)
    if img.GetVisibilityAttr().Get(TIME) == UsdGeom.Tokens.invisible:
        return True
    return img.GetPurposeAttr().Get(TIME) in (UsdGeom.Tokens.guide, UsdGeom.Tokens.proxy)


def _meaningful(category: str) -> str | None:
    """The category, or None for names that say nothing (generic or one or two letters)."""
    if category in _GENERIC_NAMES or category == vocab.UNKNOWN_CATEGORY or len(category) <= 2:
        return None
    return category


def _asset_stem(prim, stage) -> str | None:
    """File stem of the first asset the prim references or payloads."""
    root_id = stage.GetRootLayer().identifier
    for node in _nodes(prim.GetPrimIndex()):
        if node.arcType not in (Pcp.ArcTypeReference, Pcp.ArcTypePayload):
            continue
        layer = node.layerStack.identifier.rootLayer
        if layer is None or layer.identifier == root_id:
            continue
        ident = re.sub(r"\[.*\]$", "", layer.identifier)
        return Path(ident).stem
    return None


def _category_chain(*candidates) -> str:
    for c in candidates:
        if c:
            cat = _meaningful(vocab.normalize_category(c))
            if cat:
                return cat
    return vocab.UNKNOWN_CATEGORY


# ---------------------------------------------------------------------------
# The importer
# ---------------------------------------------------------------------------


def _attr(prim, name: str):
    a = prim.GetAttribute(name)
    if not a or not a.HasAuthoredValue():
        return None
    return a.Get(TIME)


def _upright_rigid(delta: np.ndarray) -> float | None:
    """Yaw of ``delta`` when it is a rotation about +Z plus a translation."""
    r = delta[:3, :3]
    if not np.allclose(r.T @ r, np.eye(3), atol=1e-6) or not np.allclose(r[:, 2], [0, 0, 1], atol=1e-6):
        return None
    return math.atan2(r[1, 0], r[0, 0])


class _Importer:
    def __init__(self, path: Path, scene_id: str | None, correct_layer_units: bool):
        self.path = path
        self.spath = str(path)
        self.scene_id = scene_id
        self.stage = open_stage(path)
        self.up = stage_up_axis(self.stage, self.spath)
        self.mpu = stage_meters_per_unit(self.stage, self.spath)
        self.correct = correct_layer_units
        self._warn_composition()
        self.frames = _Frames(self.stage, self.spath, self.up, self.mpu, correct_layer_units)
        self._sources: dict[str, _Source | None] = {}
        self._ids: set[str] = set()
        self.owners: list[_Owner] = []
        self.specials: list[tuple[str, object]] = []
        self.instancers: list[object] = []
        self.unsupported: dict[str, int] = {}
        self.n_parts = 0

    # -- diagnostics --------------------------------------------------------------
    def _warn(self, message: str) -> None:
        # Point the warning at the first caller outside ignjax.scenes.
        here = str(Path(__file__).parents[1])
        frame, level = sys._getframe(0), 1
        while frame is not None and frame.f_code.co_filename.startswith(here):
            frame, level = frame.f_back, level + 1
        warnings.warn(f"{self.spath}: {message}", UsdImportWarning, stacklevel=level)

    def _warn_composition(self) -> None:
        seen = set()
        for err in self.stage.GetCompositionErrors():
            msg = " ".join(str(err).split())
            if msg not in seen:
                seen.add(msg)
                self._warn(f"composition error, imported without it: {msg}")
        layer = self.stage.GetRootLayer()
        if layer.HasDefaultPrim() and not self.stage.GetDefaultPrim():
            self._warn(f"defaultPrim {layer.defaultPrim!r} names no prim; importing all root prims")
        for used in self.stage.GetUsedLayers():
            root = used.pseudoRoot
            if used is layer or root is None or not root.HasInfo("upAxis"):
                continue
            if str(root.GetInfo("upAxis")) != self.up:
                self._warn(f"layer {used.identifier} is {root.GetInfo('upAxis')}-up but the stage is {self.up}-up; "
                           "its geometry is not re-oriented")

    # -- traversal ----------------------------------------------------------------
    def _new_owner(self, prim, role: str, label: str | None = None) -> _Owner:
        o = _Owner(prim, role, label)
        self.owners.append(o)
        return o

    def traverse(self) -> None:
        pred = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
        proto_roots: set = set()
        for prim in self.stage.Traverse(pred):
            if prim.IsA(UsdGeom.PointInstancer):
                proto_roots.update(UsdGeom.PointInstancer(prim).GetPrototypesRel().GetForwardedTargets())
        roots = list(self.stage.GetPseudoRoot().GetFilteredChildren(pred))
        default = self.stage.GetDefaultPrim()
        if default:
            roots.sort(key=lambda p: p.GetPath() != default.GetPath())
        ctx: dict = {}
        for root in roots:
            it = iter(Usd.PrimRange(root, pred))
            for prim in it:
                p = prim.GetPath()
                if p in proto_roots or _hidden(prim):
                    it.PruneChildren()
                    continue
                parent = ctx.get(p.GetParentPath(), _Ctx(container=True))
                c = parent._replace(container=False)
                ikind = _token(prim, ATTR_KIND, "")
                if ikind in ("wall", "door"):
                    self.specials.append((ikind, prim))
                    it.PruneChildren()
                    continue
                gtype = _gprim_type(prim)
                room = None
                if ikind == "instance":
                    cat = _attr(prim, NS + "category")
                    c = c._replace(label=self._new_owner(prim, "ignjax_instance", cat), label_cat=cat)
                elif ikind == "room":
                    room = self._new_owner(prim, "ignjax_room")
                elif ikind not in ("scene", "geom", "bbox"):
                    label = prim_semantic_label(prim)
                    if label and room_label_of(label):
                        room = self._new_owner(prim, "room", label)
                    elif label:
                        cat = vocab.normalize_category(label)
                        if c.label is None or c.label_cat != cat:
                            c = c._replace(label=self._new_owner(prim, "instance", label), label_cat=cat)
                if room is not None:
                    # A room prim is a container: its floors make the room, its
                    # other children are objects.
                    c = _Ctx(room=room, container=True)
                else:
                    if c.kind is None and _is_component(prim):
                        c = c._replace(kind=self._new_owner(prim, "instance"))
                    if parent.container:
                        if p.pathElementCount == 1 and not gtype:
                            c = c._replace(root=None, container=True)
                        else:
                            c = c._replace(root=self._new_owner(prim, "instance"))
                if prim.IsA(UsdGeom.PointInstancer):
                    self.instancers.append(prim)
                    it.PruneChildren()
                    continue
                if gtype:
                    owner = c.label or c.kind or c.root
                    if owner is None or (c.room is not None and owner.is_floor):
                        owner = c.room
                    if owner is not None:
                        owner.gprims.append(prim)
                        if owner is not c.room:
                            owner.room = c.room
                elif prim.IsA(UsdGeom.Gprim):
                    t = str(prim.GetTypeName())
                    self.unsupported[t] = self.unsupported.get(t, 0) + 1
                ctx[p] = c
        if self.unsupported:
            listing = ", ".join(f"{k}: {v}" for k, v in sorted(self.unsupported.items()))
            self._warn(f"skipped prims of unsupported geometry types ({listing})")

    # -- parts --------------------------------------------------------------------
    def source(self, prim) -> _Source | None:
        key = str(prim.GetPath())
        if key not in self._sources:
            self._sources[key] = _source(prim, self.spath)
        return self._sources[key]

    def part(self, prim, to_world: np.ndarray | None = None) -> _Part | None:
        src = self.source(prim)
        if src is None:
            return None
        unit = self.frames.unit(prim, _GEOM_ATTRS.get(src.usd_type, ()))
        frame = self.frames.frame(prim) if to_world is None else to_world
        part = _place(src, frame @ _scale4(unit))
        if part is not None and len(part.faces):
            self.n_parts += 1
            return part
        return None

    def parts(self, owner: _Owner) -> list[_Part]:
        return [p for p in (self.part(g) for g in owner.gprims) if p is not None]

    # -- ids ----------------------------------------------------------------------
    def unique_id(self, base: str) -> str:
        base = base or "object"
        iid, k = base, 2
        while iid in self._ids:
            iid = f"{base}_{k}"
            k += 1
        self._ids.add(iid)
        return iid

    # -- instances ------------------------------------------------------------------
    def generic_instance(self, parts: list[_Part], heading: np.ndarray, iid: str, category: str, name: str,
                         extra: dict | None = None) -> Instance:
        verts = np.concatenate([p.verts for p in parts])
        zmin, zmax = float(verts[:, 2].min()), float(verts[:, 2].max())
        xy = verts[:, :2]
        x_axis = heading[:2, 0]
        yaw = math.atan2(x_axis[1], x_axis[0]) if np.hypot(*x_axis) > 1e-9 else 0.0
        yaw = _wrap(yaw)
        center, half, byaw = min_area_rect(xy)
        lo, hi = _rect_extents(xy, np.array([yaw]))
        if np.prod(hi[0] - lo[0]) <= np.prod(2 * half) * (1 + 1e-3) + 1e-12:
            center, half, byaw = _rect_from(lo[0], hi[0], yaw)
        bbox = OrientedBox((center[0], center[1], (zmin + zmax) / 2), (half[0], half[1], (zmax - zmin) / 2), byaw)
        position = (float(center[0]), float(center[1]), zmin)
        inv = np.linalg.inv(_pose(position, yaw))
        geoms = tuple(self.to_geom(p, inv) for p in parts if p.role == "geom")
        colored = [p for p in parts if p.has_color and p.role == "geom"]
        attrs = dict(color=None, material=None, size=None, state=None)
        if colored:
            weights = np.array([max(p.area, 1e-12) for p in colored])
            rgb = (np.array([p.rgba[:3] for p in colored]) * weights[:, None]).sum(0) / weights.sum()
            attrs["color"] = vocab.nearest_color(rgb)
        attrs.update({k: v for k, v in (extra or {}).items() if v is not None})
        return Instance(id=iid, category=category, position=position, yaw=yaw, bbox=bbox,
                        attributes=Attributes(**attrs), structural=vocab.is_structural(category), geoms=geoms, name=name)

    @staticmethod
    def to_geom(part: _Part, inv: np.ndarray) -> Geom:
        if part.pose is not None:
            local = inv @ part.pose
            return Geom(part.kind, part.size, tuple(local[:3, 3]), quat_from_matrix(local[:3, :3]), part.rgba)
        v = _apply(inv, part.verts)
        c = (v.min(0) + v.max(0)) / 2
        return Geom("mesh", (1.0, 1.0, 1.0), tuple(c), (1.0, 0.0, 0.0, 0.0), part.rgba,
                    mesh=MeshData(v - c, part.faces))

    def owner_category(self, owner: _Owner) -> str:
        prim = owner.prim
        if owner.label and vocab.normalize_category(owner.label) != vocab.UNKNOWN_CATEGORY:
            return vocab.normalize_category(owner.label)
        return _category_chain(owner.label, _custom_kind(prim), prim.GetName(), _asset_stem(prim, self.stage))

    def owner_extra(self, prim) -> dict:
        return {k: _attr(prim, NS + k) for k in ("color", "material", "size", "state")}

    def restore_geom(self, prim) -> Geom | None:
        kind = _attr(prim, NS + "geom:kind")
        size, pos, quat = _attr(prim, NS + "geom:size"), _attr(prim, NS + "geom:pos"), _attr(prim, NS + "geom:quat")
        if kind is None or size is None or pos is None or quat is None:
            return None
        rgba = _attr(prim, NS + "geom:rgba") or (0.7, 0.7, 0.7, 1.0)
        mesh = None
        if kind == "mesh":
            m = UsdGeom.Mesh(prim)
            exact = _attr(prim, NS + "geom:vertices")
            pts = m.GetPointsAttr().Get(TIME)
            verts = np.asarray(exact if exact is not None else pts, dtype=np.float64).reshape(-1, 3)
            if not np.all(np.isfinite(verts)):
                raise SceneError(self.spath, f"{prim.GetPath()}.points", "points have NaN or infinite values")
            faces = triangulate_faces(verts, m.GetFaceVertexCountsAttr().Get(TIME) or [],
                                      m.GetFaceVertexIndicesAttr().Get(TIME) or [], path=self.spath,
                                      where=f"{prim.GetPath()}.faceVertexIndices")
            mesh = MeshData(verts, faces)
        q = (quat[0], quat[1], quat[2], quat[3])
        return Geom(str(kind), tuple(size), tuple(pos), q, tuple(rgba[i] for i in range(4)),
                    str(_attr(prim, NS + "geom:part") or ""), _attr(prim, NS + "geom:material"), mesh)

    def ignjax_instance(self, owner: _Owner) -> Instance | None:
        prim = owner.prim
        iid = _attr(prim, ATTR_ID) or prim.GetName()
        category = _attr(prim, NS + "category") or self.owner_category(owner)
        pos, yaw = _attr(prim, NS + "position"), _attr(prim, NS + "yaw")
        bc, bh, by = _attr(prim, NS + "bbox:center"), _attr(prim, NS + "bbox:halfExtents"), _attr(prim, NS + "bbox:yaw")
        extra = self.owner_extra(prim)
        keep = dict(room=_attr(prim, NS + "room"), support=_attr(prim, NS + "support"),
                    structural=bool(_attr(prim, NS + "structural")) or vocab.is_structural(category),
                    name=str(_attr(prim, NS + "name") or prim.GetPath()))
        frame = self.frames.frame(prim)
        theta, moved, delta = None, False, np.eye(4)
        if None not in (pos, yaw, bc, bh, by):
            pos, bc, bh = tuple(map(float, pos)), tuple(map(float, bc)), tuple(map(float, bh))
            delta = frame @ np.linalg.inv(_pose(pos, float(yaw)))
            moved = not np.allclose(delta, np.eye(4), atol=1e-6)
            theta = _upright_rigid(delta) if moved else 0.0
        if theta is None:  # moved, scaled or sheared after export: measure it again
            parts = self.parts(owner)
            if not parts:
                return None
            inst = self.generic_instance(parts, frame, self.unique_id(str(iid)), str(category), keep["name"], extra)
            return _replace(inst, **{k: v for k, v in keep.items() if k != "name"})
        geoms, others = [], []
        for g in owner.gprims:
            kind = _token(g, ATTR_KIND, "")
            restored = self.restore_geom(g) if kind == "geom" else None
            if restored is not None:
                geoms.append((int(_attr(g, NS + "geom:index") or 0), restored))
            elif kind != "bbox":
                others.append(g)
        geoms = [g for _, g in sorted(geoms, key=lambda t: t[0])]
        position, iyaw, bbox = pos, float(yaw), OrientedBox(bc, bh, float(by))
        if moved:
            position = tuple(_apply(delta, np.array([pos]))[0])
            bcenter = tuple(_apply(delta, np.array([bc]))[0])
            iyaw, bbox = _wrap(iyaw + theta), OrientedBox(bcenter, bh, _wrap(float(by) + theta))
        if others:
            inv = np.linalg.inv(_pose(position, iyaw))
            geoms += [self.to_geom(p, inv) for p in (self.part(g) for g in others) if p is not None]
        self.n_parts += 1
        attrs = Attributes(**{k: (None if v is None else str(v)) for k, v in extra.items()})
        return Instance(id=self.unique_id(str(iid)), category=str(category), position=position, yaw=iyaw, bbox=bbox,
                        room=keep["room"], attributes=attrs, support=keep["support"], structural=keep["structural"],
                        geoms=tuple(geoms), name=keep["name"])

    def pointinstancer_instances(self, prim) -> list[Instance]:
        pi = UsdGeom.PointInstancer(prim)
        where = str(prim.GetPath())
        protos = [self.stage.GetPrimAtPath(t) for t in pi.GetPrototypesRel().GetForwardedTargets()]
        indices = pi.GetProtoIndicesAttr().Get(TIME)
        positions = pi.GetPositionsAttr().Get(TIME)
        if indices is None or len(indices) == 0:
            return []
        if positions is not None and not np.all(np.isfinite(np.asarray(positions, dtype=np.float64))):
            raise SceneError(self.spath, f"{where}.positions", "positions have NaN or infinite values")
        xforms = pi.ComputeInstanceTransformsAtTime(TIME, TIME, UsdGeom.PointInstancer.ExcludeProtoXform,
                                                    UsdGeom.PointInstancer.IgnoreMask)
        if xforms is None or len(xforms) != len(indices):
            raise SceneError(self.spath, where, "PointInstancer has inconsistent protoIndices, positions, "
                                                "orientations or scales")
        mask = list(pi.ComputeMaskAtTime(TIME) or [])
        unit = self.frames.attr_unit(pi.GetPositionsAttr(), prim)
        frame = self.frames.frame(prim)
        pred = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
        per_proto = []
        for proto in protos:
            if not proto or not proto.IsValid():
                per_proto.append(None)
                continue
            gprims = []
            it = iter(Usd.PrimRange(proto, pred))
            for g in it:
                if _hidden(g):
                    it.PruneChildren()
                    continue
                if _gprim_type(g) and self.source(g) is not None:
                    src = self.source(g)
                    rel = self.frames.relative(g, proto.GetParent())
                    gprims.append((g, rel @ _scale4(self.frames.unit(g, _GEOM_ATTRS.get(src.usd_type, ())))))
            root_rel = self.frames.relative(proto, proto.GetParent())
            category = _category_chain(prim_semantic_label(proto), prim_semantic_label(prim), _custom_kind(proto),
                                       proto.GetName(), prim.GetName(), _asset_stem(proto, self.stage))
            per_proto.append((gprims, root_rel, category))
        out = []
        for k, (pidx, m) in enumerate(zip(indices, xforms)):
            if mask and not mask[k]:
                continue
            if not (0 <= pidx < len(per_proto)) or per_proto[pidx] is None:
                self._warn(f"{where}: point {k} uses prototype index {pidx}, which does not exist; skipped")
                continue
            gprims, root_rel, category = per_proto[pidx]
            inst_m = _col(m)
            inst_m[:3, 3] *= unit
            if not np.all(np.isfinite(inst_m)):
                raise SceneError(self.spath, f"{where} (point {k})", "instance transform has NaN or infinite values")
            base = frame @ inst_m
            parts = []
            for g, rel in gprims:
                part = _place(self.source(g), base @ rel)
                if part is not None and len(part.faces):
                    parts.append(part)
            if not parts:
                continue
            self.n_parts += len(parts)
            out.append(self.generic_instance(parts, base @ root_rel, self.unique_id(f"{prim.GetName()}_{k}"),
                                             category, f"{where}[{k}]"))
        return out

    # -- rooms, walls, doors ---------------------------------------------------------
    def _planar(self, prim, expected: np.ndarray) -> tuple[np.ndarray | None, float]:
        delta = self.frames.frame(prim) @ np.linalg.inv(expected)
        if np.allclose(delta, np.eye(4), atol=1e-6):
            return None, 0.0
        theta = _upright_rigid(delta)
        if theta is None:
            self._warn(f"{prim.GetPath()} was scaled or tilted after export; its stored ignjax values are used as they are")
            return None, 0.0
        return delta, theta

    @staticmethod
    def room_from_parts(parts: list[_Part]) -> list[tuple[float, float]] | None:
        if not parts:
            return None
        verts = np.concatenate([p.verts for p in parts])
        poly = _outline(parts)
        if poly is None:
            poly = _hull_polygon(verts[:, :2])
        return poly

    def ignjax_room(self, owner: _Owner, members: list[Instance]) -> Room | None:
        prim = owner.prim
        rid = str(_attr(prim, ATTR_ID) or prim.GetName())
        label = str(_attr(prim, NS + "label") or vocab.normalize_room_label(prim.GetName()))
        name = str(_attr(prim, NS + "name") or "")
        poly = _attr(prim, NS + "polygon")
        if poly is not None:
            poly = [tuple(map(float, q)) for q in poly]
            delta, _ = self._planar(prim, np.eye(4))
            if delta is not None:
                poly = [tuple(_apply(delta, np.array([[x, y, 0.0]]))[0, :2]) for x, y in poly]
        else:
            poly = self.room_polygon(owner, members)
            if poly is None:
                self._warn(f"room prim {prim.GetPath()} has no polygon and no geometry; ignored")
                return None
        return Room(rid, label, tuple(poly), name)

    def wall(self, prim) -> Wall | None:
        vals = {k: _attr(prim, NS + k) for k in ("start", "end", "thickness", "height", "bottom", "rooms")}
        if any(vals[k] is None for k in ("start", "end", "thickness", "height")):
            self._warn(f"wall prim {prim.GetPath()} lacks ignjax wall attributes; ignored")
            return None
        start, end = tuple(map(float, vals["start"])), tuple(map(float, vals["end"]))
        h, bottom = float(vals["height"]), float(vals["bottom"] or 0.0)
        angle = math.atan2(end[1] - start[1], end[0] - start[0])
        delta, _ = self._planar(prim, _pose(((start[0] + end[0]) / 2, (start[1] + end[1]) / 2, bottom + h / 2), angle))
        if delta is not None:
            pts = _apply(delta, np.array([[*start, 0.0], [*end, 0.0]]))
            start, end = tuple(pts[0, :2]), tuple(pts[1, :2])
        return Wall(str(_attr(prim, ATTR_ID) or prim.GetName()), start, end, float(vals["thickness"]), h, bottom,
                    tuple(str(r) for r in (vals["rooms"] or ())))

    def door(self, prim) -> Door | None:
        vals = {k: _attr(prim, NS + k) for k in ("position", "width", "yaw", "rooms", "height", "doorKind")}
        if any(vals[k] is None for k in ("position", "width", "yaw")):
            self._warn(f"door prim {prim.GetPath()} lacks ignjax door attributes; ignored")
            return None
        pos, yaw = tuple(map(float, vals["position"])), float(vals["yaw"])
        delta, theta = self._planar(prim, _pose((pos[0], pos[1], 0.0), yaw))
        if delta is not None:
            pos, yaw = tuple(_apply(delta, np.array([[*pos, 0.0]]))[0, :2]), _wrap(yaw + theta)
        rooms = [str(r) or None for r in (vals["rooms"] or ())]
        rooms = (rooms + [None, None])[:2]
        return Door(str(_attr(prim, ATTR_ID) or prim.GetName()), pos, float(vals["width"]), yaw, tuple(rooms),
                    float(vals["height"]) if vals["height"] is not None else 2.1, str(vals["doorKind"] or "door"))

    # -- scene ----------------------------------------------------------------------
    def stored_scene(self) -> dict:
        for prim in self.stage.GetPseudoRoot().GetChildren():
            if _token(prim, ATTR_KIND, "") == "scene":
                return {"sceneId": _attr(prim, NS + "sceneId"), "wallHeight": _attr(prim, NS + "wallHeight"),
                        "meta": _attr(prim, NS + "meta")}
        data = self.stage.GetRootLayer().customLayerData.get("ignjax")
        return dict(data) if isinstance(data, dict) else {}

    def room_polygon(self, owner: _Owner, members: list[Instance]) -> list[tuple[float, float]] | None:
        """A room prim's floor polygon: from its floor geometry, else the
        hull of the objects below it."""
        poly = self.room_from_parts(self.parts(owner))
        if poly is None and members:
            poly = _hull_polygon(np.concatenate([m.bbox.footprint() for m in members]))
        return poly

    def run(self) -> Scene:
        self.traverse()
        # (instance, restored from ignjax attributes, room prim it lies under)
        records: list[tuple[Instance, bool, _Owner | None]] = []
        # Restored instances first, so that their ids win over generated ones.
        for owner in sorted(self.owners, key=lambda o: o.role != "ignjax_instance"):
            if owner.role == "ignjax_instance":
                inst = self.ignjax_instance(owner)
                if inst is not None:
                    records.append((inst, True, owner.room))
            elif owner.role == "instance" and owner.gprims:
                parts = self.parts(owner)
                if parts:
                    prim = owner.prim
                    records.append((self.generic_instance(
                        parts, self.frames.frame(prim), self.unique_id(prim.GetName()), self.owner_category(owner),
                        str(prim.GetPath()), self.owner_extra(prim)), False, owner.room))
        for prim in self.instancers:
            records += [(inst, False, None) for inst in self.pointinstancer_instances(prim)]
        walls = [w for w in (self.wall(p) for k, p in self.specials if k == "wall") if w is not None]
        doors = [d for d in (self.door(p) for k, p in self.specials if k == "door") if d is not None]
        room_owners = [o for o in self.owners if o.role in ("room", "ignjax_room")]
        if self.n_parts == 0 and not walls and not any(o.gprims for o in room_owners):
            raise SceneError(self.spath, None, "the stage has no geometry (no meshes or geometric primitives to import)")
        rooms: list[Room] = []
        room_of_owner: dict[int, str] = {}
        room_ids: set[str] = set()
        pending = []
        for owner in room_owners:
            members = [inst for inst, _, r in records if r is owner]
            if owner.role == "ignjax_room":
                room = self.ignjax_room(owner, members)
                if room is not None:
                    rooms.append(room)
                    room_ids.add(room.id)
                    room_of_owner[id(owner)] = room.id
            else:
                pending.append((owner, members))
        for owner, members in pending:
            poly = self.room_polygon(owner, members)
            if poly is None:
                self._warn(f"room prim {owner.prim.GetPath()} has no usable floor or objects to outline it; ignored")
                continue
            base = rid = owner.prim.GetName()
            k = 2
            while rid in room_ids:
                rid, k = f"{base}_{k}", k + 1
            room_ids.add(rid)
            room_of_owner[id(owner)] = rid
            rooms.append(Room(rid, room_label_of(owner.label) or vocab.OTHER_ROOM, tuple(poly), owner.prim.GetName()))
        instances = [inst for inst, _, _ in records]
        if not rooms:
            cover = self._cover(instances, walls)
            if cover is None:
                raise SceneError(self.spath, None, "the stage has no geometry outside room prims with unusable footprints")
            rooms.append(Room("room_0", vocab.OTHER_ROOM, tuple(cover), "all geometry"))
            room_ids.add("room_0")
        scene_rooms = tuple(rooms)
        ids = {i.id for i in instances}
        fixed = []
        for inst, restored, under in records:
            if restored and (inst.room is None or inst.room in room_ids):
                room = inst.room
            else:
                room = _room_at(scene_rooms, inst.bbox.center[:2]) or room_of_owner.get(id(under))
            support = inst.support if inst.support in ids else None
            fixed.append(_replace(inst, room=room, support=support))
        stored = self.stored_scene()
        meta = {}
        if stored.get("meta"):
            try:
                meta = json.loads(stored["meta"])
            except (TypeError, ValueError):
                meta = {}
        params = meta.get("params") if isinstance(meta.get("params"), str) else json.dumps(
            {"importer": "usd", "correct_layer_units": self.correct}, sort_keys=True)
        scene = Scene(
            id=self.scene_id or stored.get("sceneId") or self.path.stem,
            rooms=scene_rooms,
            doors=tuple(doors),
            walls=tuple(walls),
            instances=tuple(fixed),
            meta=SceneMeta(source=self.spath, source_format="usd", up_axis=self.up, meters_per_unit=self.mpu,
                           seed=meta.get("seed") if isinstance(meta.get("seed"), int) else None, params=params),
            wall_height=float(stored["wallHeight"]) if stored.get("wallHeight") is not None else 2.5,
        )
        return validate_scene(scene, self.spath)

    @staticmethod
    def _cover(instances: list[Instance], walls: list[Wall]) -> list[tuple[float, float]] | None:
        pts = [i.bbox.footprint() for i in instances]
        pts += [np.array([w.start, w.end]) for w in walls]
        if not pts:
            return None
        xy = np.concatenate(pts)
        poly = _hull_polygon(xy)
        return poly if poly is not None else _padded_rect(xy)


def _replace(inst: Instance, **changes) -> Instance:
    import dataclasses

    return dataclasses.replace(inst, **changes)


def _room_at(rooms, xy) -> str | None:
    p = np.asarray(xy, dtype=np.float64)[None]
    for r in rooms:
        if bool(points_in_polygon(p, r.polygon)[0]):
            return r.id
    return None


def _outline(parts: list[_Part]) -> list[tuple[float, float]] | None:
    """The outline of the upward- (else downward-) facing triangles of the
    parts, projected on the floor, when it is one simple loop."""
    tris = np.concatenate([p.verts[p.faces] for p in parts])  # Shape: (T, 3, 3)
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    norm = np.linalg.norm(n, axis=1)
    ok = norm > 1e-12
    up = ok & (n[:, 2] >= 0.9 * norm)
    sel = up if up.any() else ok & (n[:, 2] <= -0.9 * norm)
    if not sel.any():
        return None
    xy = tris[sel][:, :, :2].reshape(-1, 2)
    keys = np.round(xy / 1e-6).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1, 3)
    pts = xy[first]
    edges = np.concatenate([inverse[:, [0, 1]], inverse[:, [1, 2]], inverse[:, [2, 0]]])
    edges = edges[edges[:, 0] != edges[:, 1]]
    und = np.sort(edges, axis=1)
    uniq, counts = np.unique(und, axis=0, return_counts=True)
    boundary = uniq[counts == 1]
    if len(boundary) < 3:
        return None
    adj: dict[int, list[int]] = {}
    for a, b in boundary:
        adj.setdefault(int(a), []).append(int(b))
        adj.setdefault(int(b), []).append(int(a))
    if any(len(v) != 2 for v in adj.values()):
        return None
    start = int(boundary[0, 0])
    loop, prev, cur = [start], None, start
    while True:
        nxt = adj[cur][0] if adj[cur][0] != prev else adj[cur][1]
        if nxt == start:
            break
        loop.append(nxt)
        prev, cur = cur, nxt
        if len(loop) > len(adj):
            return None
    if len(loop) != len(adj):
        return None  # several loops (holes, separate pieces)
    poly = [tuple(map(float, pts[i])) for i in loop]
    # drop collinear points
    arr = np.asarray(poly)
    prev_p, next_p = np.roll(arr, 1, 0), np.roll(arr, -1, 0)
    cross = (arr[:, 0] - prev_p[:, 0]) * (next_p[:, 1] - prev_p[:, 1]) - (arr[:, 1] - prev_p[:, 1]) * (next_p[:, 0] - prev_p[:, 0])
    poly = [p for p, c in zip(poly, cross) if abs(c) > 1e-12]
    if polygon_problem(poly) is not None:
        return None
    if polygon_area(poly) < 0:
        poly = poly[::-1]
    return poly


def import_stage(path, *, scene_id: str | None = None, correct_layer_units: bool = True) -> Scene:
    """Implementation of :func:`ignjax.scenes.io.usd.load_usd` (see there)."""
    return _Importer(Path(path), scene_id, correct_layer_units).run()
