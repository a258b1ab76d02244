"""Geometry prims as parts of objects: a prim's raw geometry (:class:`Source`:
its mesh or primitive, colour and role) and that geometry placed in the world
(:class:`Part`: a box/sphere/ellipsoid/cylinder/capsule geom when the
transform allows, else a mesh); reading authored attribute values.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pxr import UsdGeom, UsdShade

from ignjax.errors import SceneError
from ignjax.scenes.io.usd.frames import TIME, apply, decompose
from ignjax.scenes.io.usd.mesh import canonical_mesh, triangulate_faces
from ignjax.scenes.io.usd.stage import ATTR_KIND

_SUPPORTED_GPRIMS = ("Mesh", "Cube", "Sphere", "Cylinder", "Capsule", "Cone", "Plane", "Cylinder_1", "Capsule_1")
_AXIS_TO_Z = {  # rotation taking the canonical +z axis onto the primitive's axis
    "X": np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    "Y": np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
    "Z": np.eye(3),
}


@dataclass
class Source:
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
class Part:
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


def _close(a: float, b: float, rtol: float = 1e-6) -> bool:
    return abs(a - b) <= rtol * max(abs(a), abs(b))


def place(src: Source, g: np.ndarray) -> Part | None:
    """Place raw geometry with ``g`` (raw primitive frame -> world metres)."""
    if src.usd_type != "Mesh" and src.axis != "Z":
        rot = np.eye(4)
        rot[:3, :3] = _AXIS_TO_Z[src.axis]
        g = g @ rot
    verts = apply(g, src.verts)
    part = Part("mesh", (1.0, 1.0, 1.0), None, verts, src.faces, src.rgba, src.has_color, src.role, src.prim_path)
    t = src.usd_type
    if t in ("Cube", "Sphere", "Cylinder", "Capsule"):
        d = decompose(g)
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


def token(prim, name: str, default: str) -> str:
    """The attribute's value as a string, or ``default`` when empty or unset."""
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
    import trimesh  # importing trimesh takes seconds; only stages with Mesh prims need it

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


GEOM_ATTRS = {
    "Mesh": ("points",), "Cube": ("size",), "Sphere": ("radius",), "Cylinder": ("radius", "height"),
    "Capsule": ("radius", "height"), "Cone": ("radius", "height"), "Plane": ("width", "length"),
    "Cylinder_1": ("radiusBottom", "radiusTop", "height"), "Capsule_1": ("radiusBottom", "radiusTop", "height"),
}


def gprim_type(prim) -> str | None:
    """The supported geometry type the prim is (by type name or schema), or None."""
    t = str(prim.GetTypeName())
    if t in _SUPPORTED_GPRIMS:
        return t
    for name in _SUPPORTED_GPRIMS:
        schema = getattr(UsdGeom, name, None)
        if schema is not None and prim.IsA(schema):
            return name
    return None


def read_source(prim, path: str) -> Source | None:
    """The raw geometry of a supported geometry prim; None for other prims and empty meshes."""
    t = gprim_type(prim)
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
        axis = token(prim, "axis", "Z") if t != "Cube" and t != "Sphere" else "Z"
        axis = axis if axis in _AXIS_TO_Z else "Z"
        verts, faces = canonical_mesh(t, params)
    if len(faces) == 0:
        return None
    rgba, has = _display_color(prim)
    role = "bbox" if token(prim, ATTR_KIND, "") == "bbox" else "geom"
    return Source(str(prim.GetPath()), t, params, axis, verts, faces, rgba, has, role)


def authored(prim, name: str):
    """The attribute's authored value, or None when it has none."""
    a = prim.GetAttribute(name)
    if not a or not a.HasAuthoredValue():
        return None
    return a.Get(TIME)
