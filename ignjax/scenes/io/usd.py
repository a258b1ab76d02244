"""USD stages: export a :class:`~ignjax.scenes.model.Scene` and import any stage.

Public API
    :func:`save_usd` writes a scene as a stage (``.usda``, ``.usdc``, ``.usd``
    or ``.usdz``); :func:`load_usd` reads any stage into a scene (the
    machinery lives in :mod:`ignjax.scenes.io.usd_import`). Small helpers:
    :func:`open_stage`, :func:`stage_up_axis`, :func:`stage_meters_per_unit`,
    :func:`prim_semantic_label`, :func:`triangulate_faces`.

Exported layout
    ``upAxis = "Z"``, ``metersPerUnit = 1``, ``defaultPrim = "World"``::

        /World                      Xform, kind assembly, ignjax:kind "scene"
          Rooms/<room>              Xform; child ``Floor``: the floor polygon
                                    as one Mesh face at z = 0
          Walls/<wall>              Xform (translate + rotateZ); child ``Box``:
                                    a Cube scaled to the wall segment
          Doors/<door>              Xform (translate + rotateZ); child
                                    ``Opening``: a guide-purpose translucent
                                    Cube showing the opening
          Objects/<instance>        Xform, kind component, translate
                                    (``position``) + rotateZ (``yaw``); one
                                    child per Geom: Cube (box, scaled), Sphere,
                                    Sphere scaled (ellipsoid), Cylinder or
                                    Capsule (axis Z), Mesh; or, for an instance
                                    without geoms, a ``BBox`` Cube

    Prim names are ``Tf.MakeValidIdentifier`` of the ids, made unique among
    siblings; the exact id is kept in ``ignjax:id``. Every geometry prim
    carries ``primvars:displayColor``/``displayOpacity`` from its rgba and
    an ``extent``; meshes have ``subdivisionScheme = "none"``.

    Semantic labels: instance prims (and, with their room label, room prims;
    walls with ``wall``) carry both Isaac-style attributes
    ``semantic:Semantics:params:semanticType = "class"`` /
    ``semantic:Semantics:params:semanticData = <category>`` and
    ``UsdSemantics.LabelsAPI`` ``semantics:labels:class = [<category>]``.

    ``ignjax:`` attributes hold everything else, in metres in the Z-up
    world frame, as doubles (see ``ATTR_*`` names below): scene id, wall
    height and the original :class:`SceneMeta` (JSON) on ``/World`` and in
    ``customLayerData["ignjax"]``; room id/label/name/polygon; wall
    id/start/end/thickness/height/bottom/rooms; door
    id/position/width/yaw/rooms/height/kind; instance
    id/category/position/yaw/bbox/room/support/structural/name and
    colour/material/size/state; per geom kind/size/pos/quat/rgba/part/
    material (and, when ``float`` points would round the vertices, the
    exact vertices as ``double3[]``).

Importing: see :func:`load_usd` and :mod:`ignjax.scenes.io.usd_import`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
import shutil
import tempfile
from pathlib import Path
from typing import Iterable

import numpy as np

from ignjax.errors import SceneError
from ignjax.scenes.model import Door, Geom, Instance, Room, Scene, Wall, validate_scene

USD_SUFFIXES: tuple[str, ...] = (".usd", ".usda", ".usdc", ".usdz")

USD_FORMAT = "ignjax-scene-usd"
"""Value of ``customLayerData["ignjax"]["format"]`` in exported stages."""
USD_FORMAT_VERSION = 1

NS = "ignjax:"
ATTR_KIND = NS + "kind"
"""Token naming what an ``ignjax`` prim is: scene, room, wall, door,
instance, geom or bbox."""
ATTR_ID = NS + "id"

ISAAC_TYPE_ATTR = "semantic:Semantics:params:semanticType"
ISAAC_DATA_ATTR = "semantic:Semantics:params:semanticData"
LABELS_TAXONOMY = "class"
LABELS_ATTR = f"semantics:labels:{LABELS_TAXONOMY}"


class UsdImportWarning(UserWarning):
    """Something in a stage was skipped or repaired on import (a missing
    sublayer, reference or payload, an invalid ``defaultPrim``, prims of
    unsupported types)."""


# ---------------------------------------------------------------------------
# Shared helpers (also used by the importer)
# ---------------------------------------------------------------------------


def open_stage(path: str | os.PathLike):
    """Open a stage with all payloads loaded.

    Raises:
        SceneError: the file is missing or is not a USD file USD can open.
    """
    from pxr import Tf, Usd

    p = Path(path)
    if not p.exists():
        raise SceneError(p, None, "no such file")
    if p.is_dir():
        raise SceneError(p, None, "is a directory, not a USD file")
    try:
        stage = Usd.Stage.Open(str(p), load=Usd.Stage.LoadAll)
    except Tf.ErrorException as e:
        reason = " ".join(str(e).split())
        raise SceneError(p, None, f"not a readable USD file ({reason[:300]})") from e
    if stage is None:
        raise SceneError(p, None, "not a readable USD file")
    return stage


def stage_up_axis(stage, path: str | os.PathLike | None = None) -> str:
    """The stage's ``upAxis``: ``"Y"`` or ``"Z"`` (unauthored: USD's fallback, Y).

    Raises:
        SceneError: any other authored value (``X``, or an invalid token),
            naming the file, ``upAxis`` and the value.
    """
    from pxr import UsdGeom

    if stage.HasAuthoredMetadata("upAxis"):
        value = str(stage.GetMetadata("upAxis"))
    else:
        value = str(UsdGeom.GetFallbackUpAxis())
    if value not in ("Y", "Z"):
        raise SceneError(path or stage.GetRootLayer().identifier, "upAxis",
                         f"unsupported upAxis {value!r}: USD stages must be Y-up or Z-up")
    return value


def stage_meters_per_unit(stage, path: str | os.PathLike | None = None) -> float:
    """The stage's ``metersPerUnit`` (unauthored: USD's fallback, 0.01).

    Raises:
        SceneError: the value is not a positive finite number.
    """
    from pxr import UsdGeom

    value = float(UsdGeom.GetStageMetersPerUnit(stage))
    if not math.isfinite(value) or value <= 0:
        raise SceneError(path or stage.GetRootLayer().identifier, "metersPerUnit",
                         f"metersPerUnit must be a positive number, got {value!r}")
    return value


_ISAAC_TYPE_RE = re.compile(r"^semantic:(?P<inst>[^:]+):params:semanticType$")


def prim_semantic_label(prim) -> str | None:
    """The class label authored on ``prim`` itself, or None.

    Looked up in this order: ``ignjax:category``; ``UsdSemantics.LabelsAPI``
    ``semantics:labels:class`` (first non-empty token); Isaac-style
    ``semantic:<name>:params:semanticType == "class"`` with its
    ``semanticData`` (the part before a comma when it lists several).
    """
    attr = prim.GetAttribute(NS + "category")
    if attr and attr.HasAuthoredValue():
        value = attr.Get()
        if value:
            return str(value)
    names = prim.GetAuthoredPropertyNames()
    for name in names:
        if name.startswith("semantics:labels:") and name.split(":", 2)[2].lower() == LABELS_TAXONOMY:
            value = prim.GetAttribute(name).Get()
            for token in (value or ()):
                if str(token).strip():
                    return str(token).strip()
    for name in names:
        m = _ISAAC_TYPE_RE.match(name)
        if not m:
            continue
        if str(prim.GetAttribute(name).Get() or "").strip().lower() != LABELS_TAXONOMY:
            continue
        data = prim.GetAttribute(f"semantic:{m.group('inst')}:params:semanticData")
        value = str(data.Get() or "").split(",")[0].strip() if data else ""
        if value:
            return value
    return None


def _newell_normal(p: np.ndarray) -> np.ndarray:
    # Shape: p (n, 3) -> (3,)
    q = np.roll(p, -1, axis=0)
    return np.array([
        np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
        np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
        np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1])),
    ])


def _earclip_face(points: np.ndarray, ring: np.ndarray) -> list[tuple[int, int, int]]:
    """Triangulate one polygon face (indices ``ring`` into ``points``)."""
    import mapbox_earcut

    p = points[ring]
    n = _newell_normal(p)
    norm = float(np.linalg.norm(n))
    if norm < 1e-300:
        return []
    n = n / norm
    # An orthonormal basis (u, v, n), right-handed, so that a face wound
    # counter-clockwise about its normal is counter-clockwise in (u, v).
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, n)
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    d = p - p[0]
    xy = np.stack([d @ u, d @ v], axis=1)
    tri = np.asarray(mapbox_earcut.triangulate_float64(xy, np.array([len(ring)], dtype=np.uint32)), dtype=np.int64)
    tri = tri.reshape(-1, 3)
    out = []
    for a, b, c in tri:
        area2 = (xy[b, 0] - xy[a, 0]) * (xy[c, 1] - xy[a, 1]) - (xy[b, 1] - xy[a, 1]) * (xy[c, 0] - xy[a, 0])
        if area2 < 0:
            b, c = c, b
        out.append((int(ring[a]), int(ring[b]), int(ring[c])))
    return out


def triangulate_faces(points, counts, indices, *, left_handed: bool = False,
                      holes: Iterable[int] = (), path=None, where: str | None = None) -> np.ndarray:
    """Triangulate USD polygon faces, concave ones included.

    Triangles pass through; quads are split along the diagonal that lies
    inside the face; faces with more vertices are projected onto their
    best-fit (Newell) plane and ear-clipped. Triangles keep the face's
    winding; ``left_handed`` flips it so the result is right-handed.
    Faces with fewer than three vertices and faces listed in ``holes``
    (USD ``holeIndices``) are dropped.

    Args:
        points: (V, 3) vertex positions.
        counts: (F,) ``faceVertexCounts``.
        indices: (sum(counts),) ``faceVertexIndices``.

    Returns:
        (T, 3) int64 vertex indices.

    Raises:
        SceneError: counts and indices disagree, or an index is out of range.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    counts = np.asarray(counts, dtype=np.int64).reshape(-1)
    idx = np.asarray(indices, dtype=np.int64).reshape(-1)
    if counts.size and counts.min() < 0:
        raise SceneError(path, where, "faceVertexCounts has negative entries")
    if int(counts.sum()) != idx.size:
        raise SceneError(path, where, f"faceVertexCounts sum to {int(counts.sum())} but there are {idx.size} faceVertexIndices")
    if idx.size and (idx.min() < 0 or idx.max() >= len(pts)):
        raise SceneError(path, where, f"faceVertexIndices refer to vertex {int(idx.max()) if idx.max() >= len(pts) else int(idx.min())} "
                                      f"but there are {len(pts)} points")
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]) if counts.size else np.zeros(0, np.int64)
    keep = np.ones(len(counts), dtype=bool)
    hole_list = [h for h in holes if 0 <= h < len(counts)]
    keep[hole_list] = False
    parts: list[np.ndarray] = []
    # Shape: (n3, 3)
    sel = keep & (counts == 3)
    if sel.any():
        s = starts[sel]
        parts.append(np.stack([idx[s], idx[s + 1], idx[s + 2]], axis=1))
    sel = keep & (counts == 4)
    if sel.any():
        s = starts[sel]
        q = np.stack([idx[s + k] for k in range(4)], axis=1)  # Shape: (n4, 4)
        P = pts[q]  # Shape: (n4, 4, 3)
        nq = _newell_batch(P)
        c1 = np.einsum("ij,ij->i", np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), nq)
        c2 = np.einsum("ij,ij->i", np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 0]), nq)
        ok = (c1 >= 0) & (c2 >= 0)
        a = np.where(ok[:, None], q[:, [0, 1, 2]], q[:, [1, 2, 3]])
        b = np.where(ok[:, None], q[:, [0, 2, 3]], q[:, [1, 3, 0]])
        parts += [a, b]
    big = np.nonzero(keep & (counts > 4))[0]
    if big.size:
        tris: list[tuple[int, int, int]] = []
        for f in big:
            ring = idx[starts[f]:starts[f] + counts[f]]
            tris += _earclip_face(pts, ring)
        if tris:
            parts.append(np.asarray(tris, dtype=np.int64))
    if not parts:
        return np.zeros((0, 3), dtype=np.int64)
    out = np.concatenate(parts).astype(np.int64)
    if left_handed:
        out = out[:, [0, 2, 1]]
    return out


def _newell_batch(P: np.ndarray) -> np.ndarray:
    # Shape: P (n, k, 3) -> (n, 3)
    Q = np.roll(P, -1, axis=1)
    return np.stack([
        np.sum((P[..., 1] - Q[..., 1]) * (P[..., 2] + Q[..., 2]), axis=1),
        np.sum((P[..., 2] - Q[..., 2]) * (P[..., 0] + Q[..., 0]), axis=1),
        np.sum((P[..., 0] - Q[..., 0]) * (P[..., 1] + Q[..., 1]), axis=1),
    ], axis=1)


# ---------------------------------------------------------------------------
# Export
# ---------------------------------------------------------------------------


def _unique_name(raw: str, used: set[str]) -> str:
    from pxr import Tf

    base = Tf.MakeValidIdentifier(raw or "_")
    name, k = base, 2
    while name in used:
        name = f"{base}_{k}"
        k += 1
    used.add(name)
    return name


def _set(prim, name: str, type_name, value) -> None:
    prim.CreateAttribute(name, type_name, custom=True).Set(value)


def _apply_labels(prim, label: str) -> None:
    from pxr import Sdf, UsdSemantics

    labels = UsdSemantics.LabelsAPI.Apply(prim, LABELS_TAXONOMY)
    labels.CreateLabelsAttr([label])
    # Isaac Sim's (older) SemanticsAPI, applied by name so Isaac tools see it.
    prim.AddAppliedSchema("SemanticsAPI:Semantics")
    prim.CreateAttribute(ISAAC_TYPE_ATTR, Sdf.ValueTypeNames.Token, custom=False).Set(LABELS_TAXONOMY)
    prim.CreateAttribute(ISAAC_DATA_ATTR, Sdf.ValueTypeNames.String, custom=False).Set(label)


def _display(gprim, rgba) -> None:
    from pxr import Gf, UsdGeom

    gprim.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set([Gf.Vec3f(*(float(c) for c in rgba[:3]))])
    gprim.CreateDisplayOpacityPrimvar(UsdGeom.Tokens.constant).Set([float(rgba[3])])


def _set_extent(gprim) -> None:
    from pxr import Usd, UsdGeom

    ext = UsdGeom.Boundable.ComputeExtentFromPlugins(gprim, Usd.TimeCode.Default())
    if ext is not None:
        gprim.CreateExtentAttr(ext)


def _place(xformable, translate, yaw: float) -> None:
    from pxr import Gf, UsdGeom

    xformable.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*translate))
    xformable.AddRotateZOp(UsdGeom.XformOp.PrecisionDouble).Set(math.degrees(yaw))


def _mesh_prim(stage, path, vertices: np.ndarray, faces: np.ndarray, counts=None):
    from pxr import UsdGeom, Vt

    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(vertices, dtype=np.float32)))
    f = np.asarray(faces, dtype=np.int32)
    if counts is None:
        counts = np.full(len(f), 3, dtype=np.int32)
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.asarray(counts, dtype=np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(f.reshape(-1)))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    return mesh


def _author_geom(stage, parent_path, name: str, g: Geom, index: int):
    from pxr import Gf, Sdf, UsdGeom, Vt

    path = parent_path.AppendChild(name)
    k = g.kind
    if k == "box":
        prim = UsdGeom.Cube.Define(stage, path)
        prim.CreateSizeAttr(2.0)
        scale = g.size
    elif k == "sphere":
        prim = UsdGeom.Sphere.Define(stage, path)
        prim.CreateRadiusAttr(g.size[0])
        scale = None
    elif k == "ellipsoid":
        prim = UsdGeom.Sphere.Define(stage, path)
        prim.CreateRadiusAttr(1.0)
        scale = g.size
    elif k in ("cylinder", "capsule"):
        prim = (UsdGeom.Cylinder if k == "cylinder" else UsdGeom.Capsule).Define(stage, path)
        prim.CreateRadiusAttr(g.size[0])
        prim.CreateHeightAttr(2.0 * g.size[1])
        prim.CreateAxisAttr(UsdGeom.Tokens.z)
        scale = None
    elif k == "mesh":
        prim = _mesh_prim(stage, path, g.mesh.vertices, g.mesh.faces)
        scale = None
    else:  # validate_scene rejects other kinds before we get here
        raise SceneError(None, str(path), f"unknown geom kind {k!r}")
    prim.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*g.pos))
    if g.quat != (1.0, 0.0, 0.0, 0.0):
        w, x, y, z = g.quat
        prim.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(w, Gf.Vec3d(x, y, z)))
    if scale is not None:
        prim.AddScaleOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*scale))
    _display(prim, g.rgba)
    _set_extent(prim)
    p = prim.GetPrim()
    T = Sdf.ValueTypeNames
    _set(p, ATTR_KIND, T.Token, "geom")
    _set(p, NS + "geom:index", T.Int, index)
    _set(p, NS + "geom:kind", T.Token, k)
    _set(p, NS + "geom:size", T.Double3, Gf.Vec3d(*g.size))
    _set(p, NS + "geom:pos", T.Double3, Gf.Vec3d(*g.pos))
    _set(p, NS + "geom:quat", T.Double4, Gf.Vec4d(*g.quat))
    _set(p, NS + "geom:rgba", T.Double4, Gf.Vec4d(*g.rgba))
    _set(p, NS + "geom:part", T.String, g.part)
    if g.material is not None:
        _set(p, NS + "geom:material", T.String, g.material)
    if k == "mesh":
        v = g.mesh.vertices
        if not np.array_equal(v.astype(np.float32).astype(np.float64), v):
            _set(p, NS + "geom:vertices", T.Double3Array, Vt.Vec3dArray.FromNumpy(v))
    return prim


def _author_instance(stage, path, inst: Instance) -> None:
    from pxr import Gf, Kind, Sdf, Usd, UsdGeom

    T = Sdf.ValueTypeNames
    xf = UsdGeom.Xform.Define(stage, path)
    Usd.ModelAPI(xf.GetPrim()).SetKind(Kind.Tokens.component)
    _place(xf, inst.position, inst.yaw)
    p = xf.GetPrim()
    _set(p, ATTR_KIND, T.Token, "instance")
    _set(p, ATTR_ID, T.String, inst.id)
    _set(p, NS + "category", T.String, inst.category)
    _set(p, NS + "position", T.Double3, Gf.Vec3d(*inst.position))
    _set(p, NS + "yaw", T.Double, inst.yaw)
    _set(p, NS + "bbox:center", T.Double3, Gf.Vec3d(*inst.bbox.center))
    _set(p, NS + "bbox:halfExtents", T.Double3, Gf.Vec3d(*inst.bbox.half_extents))
    _set(p, NS + "bbox:yaw", T.Double, inst.bbox.yaw)
    _set(p, NS + "structural", T.Bool, bool(inst.structural))
    _set(p, NS + "name", T.String, inst.name)
    if inst.room is not None:
        _set(p, NS + "room", T.String, inst.room)
    if inst.support is not None:
        _set(p, NS + "support", T.String, inst.support)
    for key, value in inst.attributes.as_dict().items():
        if value is not None:
            _set(p, NS + key, T.String, value)
    _apply_labels(p, inst.category)
    used: set[str] = set()
    for i, g in enumerate(inst.geoms):
        _author_geom(stage, path, _unique_name(f"g{i:02d}_{g.part or g.kind}", used), g, i)
    if not inst.geoms:
        # The box is the geometry: show it, marked so import does not make it a geom.
        b = inst.bbox
        c, s = math.cos(-inst.yaw), math.sin(-inst.yaw)
        dx, dy = b.center[0] - inst.position[0], b.center[1] - inst.position[1]
        local = (c * dx - s * dy, s * dx + c * dy, b.center[2] - inst.position[2])
        cube = UsdGeom.Cube.Define(stage, path.AppendChild(_unique_name("BBox", used)))
        cube.CreateSizeAttr(2.0)
        _place(cube, local, b.yaw - inst.yaw)
        cube.AddScaleOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*b.half_extents))
        _display(cube, (0.7, 0.7, 0.7, 1.0))
        _set_extent(cube)
        _set(cube.GetPrim(), ATTR_KIND, T.Token, "bbox")


def _author_room(stage, path, room: Room) -> None:
    from pxr import Gf, Sdf, UsdGeom, Vt

    T = Sdf.ValueTypeNames
    xf = UsdGeom.Xform.Define(stage, path)
    p = xf.GetPrim()
    _set(p, ATTR_KIND, T.Token, "room")
    _set(p, ATTR_ID, T.String, room.id)
    _set(p, NS + "label", T.String, room.label)
    _set(p, NS + "name", T.String, room.name)
    _set(p, NS + "polygon", T.Double2Array, Vt.Vec2dArray([Gf.Vec2d(*q) for q in room.polygon]))
    _apply_labels(p, room.label)
    poly = np.asarray(room.polygon, dtype=np.float64)
    verts = np.concatenate([poly, np.zeros((len(poly), 1))], axis=1)
    floor = _mesh_prim(stage, path.AppendChild("Floor"), verts, np.arange(len(poly)), counts=[len(poly)])
    floor.CreateDoubleSidedAttr(True)
    _display(floor, (0.82, 0.80, 0.76, 1.0))
    _set_extent(floor)


def _author_wall(stage, path, wall: Wall) -> None:
    from pxr import Gf, Sdf, UsdGeom

    T = Sdf.ValueTypeNames
    xf = UsdGeom.Xform.Define(stage, path)
    (x0, y0), (x1, y1) = wall.start, wall.end
    angle = math.atan2(y1 - y0, x1 - x0)
    _place(xf, ((x0 + x1) / 2, (y0 + y1) / 2, wall.bottom + wall.height / 2), angle)
    p = xf.GetPrim()
    _set(p, ATTR_KIND, T.Token, "wall")
    _set(p, ATTR_ID, T.String, wall.id)
    _set(p, NS + "start", T.Double2, Gf.Vec2d(*wall.start))
    _set(p, NS + "end", T.Double2, Gf.Vec2d(*wall.end))
    _set(p, NS + "thickness", T.Double, wall.thickness)
    _set(p, NS + "height", T.Double, wall.height)
    _set(p, NS + "bottom", T.Double, wall.bottom)
    _set(p, NS + "rooms", T.StringArray, list(wall.rooms))
    _apply_labels(p, "wall")
    cube = UsdGeom.Cube.Define(stage, path.AppendChild("Box"))
    cube.CreateSizeAttr(2.0)
    cube.AddScaleOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(wall.length / 2, wall.thickness / 2, wall.height / 2))
    _display(cube, (0.93, 0.92, 0.88, 1.0))
    _set_extent(cube)


def _author_door(stage, path, door: Door) -> None:
    from pxr import Gf, Sdf, UsdGeom

    T = Sdf.ValueTypeNames
    xf = UsdGeom.Xform.Define(stage, path)
    _place(xf, (door.position[0], door.position[1], 0.0), door.yaw)
    p = xf.GetPrim()
    _set(p, ATTR_KIND, T.Token, "door")
    _set(p, ATTR_ID, T.String, door.id)
    _set(p, NS + "position", T.Double2, Gf.Vec2d(*door.position))
    _set(p, NS + "width", T.Double, door.width)
    _set(p, NS + "yaw", T.Double, door.yaw)
    _set(p, NS + "rooms", T.StringArray, ["" if r is None else r for r in door.rooms])
    _set(p, NS + "height", T.Double, door.height)
    _set(p, NS + "doorKind", T.String, door.kind)
    cube = UsdGeom.Cube.Define(stage, path.AppendChild("Opening"))
    cube.CreateSizeAttr(2.0)
    cube.CreatePurposeAttr(UsdGeom.Tokens.guide)
    cube.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(0.0, 0.0, door.height / 2))
    cube.AddScaleOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(door.width / 2, 0.02, door.height / 2))
    _display(cube, (0.3, 0.6, 0.9, 0.3))
    _set_extent(cube)


def scene_to_stage(scene: Scene):
    """Author ``scene`` into a new in-memory stage (see the module docstring
    for the layout) and return the stage."""
    from pxr import Kind, Sdf, Usd, UsdGeom

    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    Usd.ModelAPI(world.GetPrim()).SetKind(Kind.Tokens.assembly)
    meta_json = json.dumps(dataclasses.asdict(scene.meta), sort_keys=True)
    T = Sdf.ValueTypeNames
    w = world.GetPrim()
    _set(w, ATTR_KIND, T.Token, "scene")
    _set(w, NS + "sceneId", T.String, scene.id)
    _set(w, NS + "wallHeight", T.Double, float(scene.wall_height))
    _set(w, NS + "meta", T.String, meta_json)
    stage.GetRootLayer().customLayerData = {
        "ignjax": {"format": USD_FORMAT, "version": USD_FORMAT_VERSION, "sceneId": scene.id,
                   "wallHeight": float(scene.wall_height), "meta": meta_json}
    }
    groups = {}
    for name in ("Rooms", "Walls", "Doors", "Objects"):
        g = UsdGeom.Xform.Define(stage, f"/World/{name}")
        Usd.ModelAPI(g.GetPrim()).SetKind(Kind.Tokens.group)
        groups[name] = g.GetPath()
    for group, items, author in (("Rooms", scene.rooms, _author_room), ("Walls", scene.walls, _author_wall),
                                 ("Doors", scene.doors, _author_door), ("Objects", scene.instances, _author_instance)):
        used: set[str] = set()
        for item in items:
            author(stage, groups[group].AppendChild(_unique_name(item.id, used)), item)
    return stage


def save_usd(scene: Scene, path: str | os.PathLike) -> Path:
    """Write ``scene`` as a USD stage (Z-up, metres, ``defaultPrim`` /World).

    The format follows the suffix: ``.usda`` text, ``.usdc``/``.usd``
    binary, ``.usdz`` a package. The file is written to a temporary file in
    the same folder and moved into place, so it is never half-written.
    :func:`load_usd` reads it back without loss (see the module docstring).

    Args:
        scene: a valid scene.
        path: the file to write; missing parent folders are created.

    Returns:
        The path written.

    Raises:
        SceneError: the scene is invalid, the suffix is not a USD suffix, or
            the file cannot be written.
    """
    out = Path(path)
    suffix = out.suffix.lower()
    if suffix not in USD_SUFFIXES:
        raise SceneError(out, None, f"unsupported suffix {suffix or '(none)'!r}: expected one of {USD_SUFFIXES}")
    validate_scene(scene)
    stage = scene_to_stage(scene)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmpdir = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    except OSError as e:
        raise SceneError(out, None, f"cannot write: {e}") from e
    try:
        if suffix == ".usdz":
            from pxr import UsdUtils

            inner = tmpdir / (out.stem + ".usdc")
            if not stage.GetRootLayer().Export(str(inner)):
                raise SceneError(out, None, "USD could not write the layer")
            tmp = tmpdir / out.name
            if not UsdUtils.CreateNewUsdzPackage(str(inner), str(tmp)):
                raise SceneError(out, None, "USD could not write the .usdz package")
        else:
            tmp = tmpdir / out.name
            if not stage.GetRootLayer().Export(str(tmp)):
                raise SceneError(out, None, "USD could not write the layer")
        os.replace(tmp, out)
    except OSError as e:
        raise SceneError(out, None, f"cannot write: {e}") from e
    finally:
        shutil.rmtree(tmpdir, ignore_errors=True)
    return out


# ---------------------------------------------------------------------------
# Import entry point
# ---------------------------------------------------------------------------


def load_usd(path: str | os.PathLike, *, scene_id: str | None = None, correct_layer_units: bool = True) -> Scene:
    """Read any USD stage into a :class:`Scene` (Z-up, metres).

    Stages written by :func:`save_usd` come back without loss; any other
    stage is converted by the rules in :mod:`ignjax.scenes.io.usd_import`
    (which prims are objects, their categories, rooms, units).

    Args:
        path: a ``.usd``/``.usda``/``.usdc``/``.usdz`` file.
        scene_id: the scene's id; default: the id stored by :func:`save_usd`,
            else the file stem.
        correct_layer_units: rescale geometry and translations that come from
            layers whose own ``metersPerUnit`` differs from the stage's
            (plain USD ignores such layer metadata; see
            :mod:`ignjax.scenes.io.usd_import`).

    Returns:
        A validated scene; ``meta.up_axis`` and ``meta.meters_per_unit``
        record the stage's original up axis and unit.

    Raises:
        SceneError: not a USD file, unsupported ``upAxis``, no geometry,
            NaN/inf transforms or points, malformed meshes, or a scene that
            fails :func:`~ignjax.scenes.model.validate_scene`.

    Warns:
        UsdImportWarning: missing sublayers/references/payloads (the rest is
            imported), an invalid ``defaultPrim``, skipped prims.
    """
    from ignjax.scenes.io.usd_import import import_stage

    return import_stage(path, scene_id=scene_id, correct_layer_units=correct_layer_units)
