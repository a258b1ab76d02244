"""Export a :class:`~ignjax.scenes.model.Scene` as a USD stage
(:func:`save_usd`, :func:`scene_to_stage`); :func:`~ignjax.scenes.io.usd.load_usd`
reads it back without loss.

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
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np
from pxr import Gf, Kind, Sdf, Tf, Usd, UsdGeom, UsdSemantics, UsdUtils, Vt

from ignjax.errors import SceneError
from ignjax.scenes.io.formats import USD_SUFFIXES
from ignjax.scenes.io.usd.stage import ATTR_ID, ATTR_KIND, ISAAC_DATA_ATTR, ISAAC_TYPE_ATTR, LABELS_TAXONOMY, NS
from ignjax.scenes.model import Door, Geom, Instance, Room, Scene, Wall
from ignjax.scenes.model.validation import validate_scene

USD_FORMAT = "ignjax-scene-usd"
"""Value of ``customLayerData["ignjax"]["format"]`` in exported stages."""
USD_FORMAT_VERSION = 1


def _unique_name(raw: str, used: set[str]) -> str:
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
    labels = UsdSemantics.LabelsAPI.Apply(prim, LABELS_TAXONOMY)
    labels.CreateLabelsAttr([label])
    # Isaac Sim's (older) SemanticsAPI, applied by name so Isaac tools see it.
    prim.AddAppliedSchema("SemanticsAPI:Semantics")
    prim.CreateAttribute(ISAAC_TYPE_ATTR, Sdf.ValueTypeNames.Token, custom=False).Set(LABELS_TAXONOMY)
    prim.CreateAttribute(ISAAC_DATA_ATTR, Sdf.ValueTypeNames.String, custom=False).Set(label)


def _display(gprim, rgba) -> None:
    gprim.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set([Gf.Vec3f(*(float(c) for c in rgba[:3]))])
    gprim.CreateDisplayOpacityPrimvar(UsdGeom.Tokens.constant).Set([float(rgba[3])])


def _set_extent(gprim) -> None:
    ext = UsdGeom.Boundable.ComputeExtentFromPlugins(gprim, Usd.TimeCode.Default())
    if ext is not None:
        gprim.CreateExtentAttr(ext)


def _place(xformable, translate, yaw: float) -> None:
    xformable.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*translate))
    xformable.AddRotateZOp(UsdGeom.XformOp.PrecisionDouble).Set(math.degrees(yaw))


def _mesh_prim(stage, path, vertices: np.ndarray, faces: np.ndarray, counts=None):
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
