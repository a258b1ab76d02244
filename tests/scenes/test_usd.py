"""USD export and import (ignjax.scenes.io.usd).

Every stage here is authored by the test with ``pxr`` into ``tmp_path``
(plus the shared usd-wg stage-configuration files, skipped when absent).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from pxr import Gf, Kind, Sdf, Usd, UsdGeom, UsdSemantics

from ignjax.errors import SceneError
from ignjax.scenes.model import points_in_polygon, polygon_area
from ignjax.scenes.io.usd import (
    ISAAC_DATA_ATTR,
    ISAAC_TYPE_ATTR,
    UsdImportWarning,
    load_usd,
    save_usd,
    triangulate_faces,
)

# ---------------------------------------------------------------------------
# Authoring helpers
# ---------------------------------------------------------------------------


def new_stage(path: Path, up: str | None = "Z", mpu: float | None = 1.0, default: str | None = "/World"):
    st = Usd.Stage.CreateNew(str(path))
    if up is not None:
        UsdGeom.SetStageUpAxis(st, up)
    if mpu is not None:
        UsdGeom.SetStageMetersPerUnit(st, mpu)
    if default:
        st.SetDefaultPrim(UsdGeom.Xform.Define(st, default).GetPrim())
    return st


def xform(st, path, translate=None, rotate_z=None, scale=None):
    x = UsdGeom.Xform.Define(st, path)
    if translate is not None:
        x.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*translate))
    if rotate_z is not None:
        x.AddRotateZOp().Set(rotate_z)
    if scale is not None:
        x.AddScaleOp().Set(Gf.Vec3f(*scale))
    return x


def cube(st, path, size=1.0, translate=None, scale=None):
    c = UsdGeom.Cube.Define(st, path)
    c.CreateSizeAttr(size)
    if translate is not None:
        c.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*translate))
    if scale is not None:
        c.AddScaleOp().Set(Gf.Vec3f(*scale))
    return c


def isaac_label(prim, label, kind="class"):
    prim.CreateAttribute(ISAAC_TYPE_ATTR, Sdf.ValueTypeNames.Token).Set(kind)
    prim.CreateAttribute(ISAAC_DATA_ATTR, Sdf.ValueTypeNames.String).Set(label)


def labels_api(prim, label):
    UsdSemantics.LabelsAPI.Apply(prim, "class").CreateLabelsAttr([label])


def by_id(scene):
    return {i.id: i for i in scene.instances}


def load_quiet(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UsdImportWarning)
        return load_usd(path, **kw)


def mesh_area(verts, faces):
    t = np.asarray(verts)[np.asarray(faces)]
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()


# ---------------------------------------------------------------------------
# Export and round trip
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".usda", ".usdc", ".usdz"])
def test_round_trip_is_lossless(two_room_scene, tmp_path, suffix):
    src = two_room_scene
    out = save_usd(src, tmp_path / f"house{suffix}")
    assert out == tmp_path / f"house{suffix}" and out.is_file()
    back = load_usd(out)
    assert back.id == src.id and back.wall_height == src.wall_height
    assert back.rooms == src.rooms  # ids, labels, names, exact polygons
    assert back.doors == src.doors
    assert back.walls == src.walls
    assert [i.id for i in back.instances] == [i.id for i in src.instances]
    for a, b in zip(src.instances, back.instances):
        assert (b.category, b.room, b.support, b.attributes, b.structural, b.name) == \
               (a.category, a.room, a.support, a.attributes, a.structural, a.name)
        np.testing.assert_allclose(b.position, a.position, atol=1e-3)
        np.testing.assert_allclose(b.bbox.center, a.bbox.center, atol=1e-3)
        np.testing.assert_allclose(b.bbox.half_extents, a.bbox.half_extents, atol=1e-3)
        assert b.yaw == pytest.approx(a.yaw) and b.bbox.yaw == pytest.approx(a.bbox.yaw)
        assert b.geoms == a.geoms  # kind, size, pose, rgba, part, material
    assert back.instances == src.instances  # in fact bit-exact
    assert back.meta.source == str(out) and back.meta.source_format == "usd"
    assert (back.meta.up_axis, back.meta.meters_per_unit) == ("Z", 1.0)
    assert (back.meta.seed, back.meta.params) == (src.meta.seed, src.meta.params)


def test_exported_stage_is_a_proper_usd_scene(two_room_scene, tmp_path):
    scene = two_room_scene
    insts = list(scene.instances)
    # ids that are not valid prim names, and a mesh geom with float64 vertices
    verts = np.array([[0, 0, 0], [0.1234567891, 0, 0], [0, 0.2, 0], [0, 0, 0.3]], dtype=np.float64)
    from ignjax.scenes.model import Geom, MeshData

    mesh = Geom("mesh", (1, 1, 1), (0, 0, 0.1), rgba=(0.2, 0.3, 0.4, 0.5), part="blob",
                mesh=MeshData(verts, np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])))
    insts[0] = dataclasses.replace(insts[0], id="bed 0/ä", geoms=insts[0].geoms + (mesh,))
    insts[1] = dataclasses.replace(insts[1], id="1-table")
    insts[2] = dataclasses.replace(insts[2], support="1-table", geoms=())  # known only by its box
    scene = scene.replace(instances=tuple(insts))
    out = save_usd(scene, tmp_path / "house.usda")
    st = Usd.Stage.Open(str(out))
    assert UsdGeom.GetStageUpAxis(st) == "Z" and UsdGeom.GetStageMetersPerUnit(st) == 1.0
    assert st.GetDefaultPrim().GetPath() == Sdf.Path("/World")
    objects = st.GetPrimAtPath("/World/Objects").GetChildren()
    assert len(objects) == len(scene.instances)
    for prim, inst in zip(objects, scene.instances):
        assert Sdf.Path.IsValidIdentifier(prim.GetName())
        assert prim.GetAttribute("ignjax:id").Get() == inst.id
        assert Usd.ModelAPI(prim).GetKind() == Kind.Tokens.component
        assert prim.GetAttribute(ISAAC_TYPE_ATTR).Get() == "class"
        assert prim.GetAttribute(ISAAC_DATA_ATTR).Get() == inst.category
        assert list(UsdSemantics.LabelsAPI(prim, "class").GetLabelsAttr().Get()) == [inst.category]
        geoms = [c for c in prim.GetChildren() if c.IsA(UsdGeom.Gprim)]
        assert len(geoms) == max(len(inst.geoms), 1)
        for child in geoms:
            assert UsdGeom.Gprim(child).GetDisplayColorAttr().Get() is not None
            assert UsdGeom.Boundable(child).GetExtentAttr().Get() is not None
    # real geometry of the right types; boxes are scaled cubes
    types = {str(p.GetTypeName()) for p in st.Traverse()}
    assert {"Cube", "Cylinder", "Sphere", "Mesh"} <= types
    bed = objects[0]
    assert any(str(c.GetTypeName()) == "Sphere" and c.GetAttribute("xformOp:scale") for c in bed.GetChildren())  # pillows
    floor = UsdGeom.Mesh(st.GetPrimAtPath("/World/Rooms/room_0/Floor"))
    assert list(floor.GetFaceVertexCountsAttr().Get()) == [4]
    assert floor.GetSubdivisionSchemeAttr().Get() == "none"
    assert st.GetRootLayer().customLayerData["ignjax"]["sceneId"] == scene.id
    from pxr import UsdValidation

    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    problems = UsdValidation.ValidationContext(validators).Validate(st)
    assert [e.GetMessage() for e in problems] == []  # USD's own validators find nothing
    back = load_usd(out)
    assert back.instances == scene.instances
    assert back.instance("1-table").id == "1-table" and back.instance("laptop_0").support == "1-table"


def test_save_refuses_bad_input_and_never_leaves_partial_files(two_room_scene, tmp_path):
    out = save_usd(two_room_scene, tmp_path / "h.usda")
    before = out.read_bytes()
    dup = two_room_scene.replace(instances=two_room_scene.instances + two_room_scene.instances[:1])
    with pytest.raises(SceneError, match="duplicate instance id"):
        save_usd(dup, out)
    assert out.read_bytes() == before
    with pytest.raises(SceneError, match="unsupported suffix"):
        save_usd(two_room_scene, tmp_path / "h.obj")
    save_usd(two_room_scene, out)  # overwrite in place
    save_usd(two_room_scene, tmp_path / "sub" / "dir" / "h.usdc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h.usda", "sub"]
    assert [p.name for p in (tmp_path / "sub" / "dir").iterdir()] == ["h.usdc"]


def test_object_moved_in_a_usd_editor_is_picked_up(two_room_scene, tmp_path):
    out = save_usd(two_room_scene, tmp_path / "h.usda")
    st = Usd.Stage.Open(str(out))
    chair = next(p for p in st.GetPrimAtPath("/World/Objects").GetChildren() if p.GetName() == "chair_0")
    chair.GetAttribute("xformOp:translate").Set(Gf.Vec3d(1.0, 3.0, 0.0))
    chair.GetAttribute("xformOp:rotateZ").Set(90.0)
    st.Save()
    orig = two_room_scene.instance("chair_0")
    moved = load_usd(out).instance("chair_0")
    assert moved.position == pytest.approx((1.0, 3.0, 0.0))
    assert moved.yaw == pytest.approx(math.pi / 2)
    assert moved.bbox.yaw == pytest.approx(orig.bbox.yaw + math.pi / 2)
    assert moved.bbox.half_extents == orig.bbox.half_extents
    assert moved.bbox.center == pytest.approx((1.0, 3.0, orig.bbox.center[2]))
    assert moved.geoms == orig.geoms


def test_exported_stage_imports_from_labels_alone(two_room_scene, tmp_path):
    """Without any ignjax: attribute, the stage is still read correctly from
    its semantic labels, kinds and geometry (the generic importer)."""
    out = save_usd(two_room_scene, tmp_path / "h.usda")
    layer = Sdf.Layer.FindOrOpen(str(out))

    def strip(spec):
        for prop in list(spec.properties):
            if prop.name.startswith("ignjax:"):
                spec.RemoveProperty(prop)
        for child in spec.nameChildren:
            strip(child)

    for root in layer.rootPrims:
        strip(root)
    layer.customLayerData = {}
    plain = tmp_path / "plain.usda"
    layer.Export(str(plain))
    scene = load_usd(plain)
    assert scene.id == "plain"
    assert {r.label for r in scene.rooms} == {"living_room", "bedroom"}
    for r in scene.rooms:
        src = next(s for s in two_room_scene.rooms if s.label == r.label)
        assert set(r.polygon) == set(src.polygon)
    got = by_id(scene)
    for inst in two_room_scene.instances:
        g = got[inst.id]
        assert g.category == inst.category and g.room == inst.room
        # measured from the geometry; the catalogue's own boxes are rounded by a few mm
        np.testing.assert_allclose(g.bbox.half_extents[2], inst.bbox.half_extents[2], atol=5e-3)
        assert abs(math.remainder(g.yaw - inst.yaw, 2 * math.pi)) < 1e-6  # the prim's heading
    assert sum(1 for i in scene.instances if i.category == "wall" and i.structural) == len(two_room_scene.walls)
    chair = got["chair_0"]
    np.testing.assert_allclose(chair.position, two_room_scene.instance("chair_0").position, atol=1e-3)
    assert chair.attributes.color == "red"


# ---------------------------------------------------------------------------
# Frames and units
# ---------------------------------------------------------------------------


def test_y_up_stage_is_converted_to_z_up(tmp_path):
    st = new_stage(tmp_path / "y.usda", up="Y", mpu=1.0)
    cube(st, "/World/Box", size=2.0, translate=(1.0, 2.0, 3.0))
    x = xform(st, "/World/Couch")
    x.AddTranslateOp().Set(Gf.Vec3d(-2.0, 0.0, 0.0))
    x.AddRotateYOp().Set(30.0)
    cube(st, "/World/Couch/Body", size=1.0, scale=(2.0, 0.5, 1.0), translate=(0, 0.25, 0))
    st.Save()
    scene = load_usd(tmp_path / "y.usda")
    assert scene.meta.up_axis == "Y"
    box = by_id(scene)["Box"]
    assert box.position == pytest.approx((1.0, -3.0, 1.0))  # (x, -z, y), lowest point
    assert box.bbox.center == pytest.approx((1.0, -3.0, 2.0))
    couch = by_id(scene)["Couch"]
    assert couch.category == "sofa"
    assert couch.yaw == pytest.approx(math.radians(30.0))  # a turn about Y-up is a yaw
    assert couch.bbox.half_extents == pytest.approx((1.0, 0.5, 0.25))
    assert couch.position == pytest.approx((-2.0, 0.0, 0.0))


def test_unauthored_meters_per_unit_means_centimetres(tmp_path):
    st = new_stage(tmp_path / "cm.usda", mpu=None)
    cube(st, "/World/Crate", size=100.0, translate=(200.0, 0.0, 50.0))
    st.Save()
    scene = load_usd(tmp_path / "cm.usda")
    assert scene.meta.meters_per_unit == 0.01
    crate = scene.instances[0]
    assert crate.category == "storage_box"
    assert crate.bbox.half_extents == pytest.approx((0.5, 0.5, 0.5))
    assert crate.position == pytest.approx((2.0, 0.0, 0.0))
    assert crate.geoms[0].kind == "box" and crate.geoms[0].size == pytest.approx((0.5, 0.5, 0.5))


def _unit_asset(path: Path, mpu: float, size: float, label: str = "chair"):
    st = new_stage(path, mpu=mpu, default="/Asset")
    Usd.ModelAPI(st.GetPrimAtPath("/Asset")).SetKind(Kind.Tokens.component)
    labels_api(st.GetPrimAtPath("/Asset"), label)
    cube(st, "/Asset/Geo", size=size, translate=(0.0, 0.0, size / 2))
    st.Save()


def test_referenced_layer_with_other_units_is_rescaled(tmp_path):
    _unit_asset(tmp_path / "chair_m.usda", mpu=1.0, size=0.5)  # a 0.5 m chair, in metres
    _unit_asset(tmp_path / "table_cm.usda", mpu=0.01, size=80.0, label="dining_table")  # 0.8 m, in cm
    st = new_stage(tmp_path / "room.usda", mpu=0.01)  # the stage is in centimetres
    a = xform(st, "/World/ChairA", translate=(300.0, 0.0, 0.0))
    a.GetPrim().GetReferences().AddReference("./chair_m.usda")
    b = xform(st, "/World/TableA", translate=(-100.0, 50.0, 0.0))
    b.GetPrim().GetReferences().AddReference("./table_cm.usda")
    cube(st, "/World/Box", size=40.0, translate=(0.0, 0.0, 20.0))
    st.Save()
    scene = load_usd(tmp_path / "room.usda")
    got = by_id(scene)
    assert got["ChairA"].bbox.half_extents == pytest.approx((0.25, 0.25, 0.25))
    assert got["ChairA"].position == pytest.approx((3.0, 0.0, 0.0))  # translate authored in cm
    assert got["TableA"].bbox.half_extents == pytest.approx((0.4, 0.4, 0.4))
    assert got["TableA"].position == pytest.approx((-1.0, 0.5, 0.0))
    assert got["Box"].bbox.half_extents == pytest.approx((0.2, 0.2, 0.2))
    # Plain USD semantics (no correction): the metre asset is read as centimetres.
    plain = by_id(load_usd(tmp_path / "room.usda", correct_layer_units=False))
    assert plain["ChairA"].bbox.half_extents == pytest.approx((0.0025, 0.0025, 0.0025))
    assert plain["TableA"].bbox.half_extents == pytest.approx((0.4, 0.4, 0.4))


def test_sublayer_with_other_units_is_rescaled(tmp_path):
    sub = new_stage(tmp_path / "props_m.usda", mpu=1.0)
    cube(sub, "/World/Cabinet", size=1.0)  # 1 m, defined in a metre layer
    sub.Save()
    st = new_stage(tmp_path / "main_cm.usda", mpu=0.01)
    st.GetRootLayer().subLayerPaths.append("./props_m.usda")
    over = st.OverridePrim("/World/Cabinet")
    UsdGeom.Xformable(over).AddTranslateOp().Set(Gf.Vec3d(200.0, 0.0, 50.0))  # authored in cm
    st.Save()
    cab = load_usd(tmp_path / "main_cm.usda").instances[0]
    assert cab.bbox.half_extents == pytest.approx((0.5, 0.5, 0.5))
    assert cab.bbox.center == pytest.approx((2.0, 0.0, 0.5))
    assert cab.category == "cabinet"


def test_unauthored_up_axis_is_y(tmp_path):
    st = new_stage(tmp_path / "noaxis.usda", up=None, mpu=1.0)
    cube(st, "/World/Box", size=2.0, translate=(0.0, 1.0, 5.0))
    st.Save()
    scene = load_usd(tmp_path / "noaxis.usda", scene_id="mine")
    assert scene.meta.up_axis == "Y" and scene.id == "mine"
    assert scene.instances[0].position == pytest.approx((0.0, -5.0, 0.0))


def test_payloads_are_loaded(tmp_path):
    _unit_asset(tmp_path / "lamp.usda", mpu=1.0, size=0.3, label="floor lamp")
    st = new_stage(tmp_path / "p.usda")
    p = xform(st, "/World/Lamp", translate=(1.0, 1.0, 0.0))
    p.GetPrim().GetPayloads().AddPayload("./lamp.usda")
    st.Save()
    scene = load_usd(tmp_path / "p.usda")
    lamp = by_id(scene)["Lamp"]
    assert lamp.category == "floor_lamp"
    assert lamp.position == pytest.approx((1.0, 1.0, 0.0))
    assert lamp.bbox.half_extents == pytest.approx((0.15, 0.15, 0.15))


def test_instanceable_prims_yield_every_instance(tmp_path):
    ast = new_stage(tmp_path / "armchair.usda", default="/Root")
    cube(ast, "/Root/Seat", size=0.6, translate=(0.0, 0.0, 0.3))
    ast.Save()
    st = new_stage(tmp_path / "inst.usda")
    n = 5
    for k in range(n):
        x = xform(st, f"/World/Xform_{k}", translate=(float(k), 2.0 * k, 0.0), rotate_z=10.0 * k)
        x.GetPrim().GetReferences().AddReference("./armchair.usda")
        x.GetPrim().SetInstanceable(True)
    st.Save()
    scene = load_usd(tmp_path / "inst.usda")
    assert len(scene.instances) == n
    for k in range(n):
        inst = by_id(scene)[f"Xform_{k}"]
        assert inst.category == "armchair"  # from the referenced asset's file name
        assert inst.position == pytest.approx((float(k), 2.0 * k, 0.0), abs=1e-9)
        assert inst.yaw == pytest.approx(math.radians(10.0 * k))
        assert inst.bbox.half_extents == pytest.approx((0.3, 0.3, 0.3))


def test_point_instancer_points_become_instances(tmp_path):
    st = new_stage(tmp_path / "pi.usda")
    pi = UsdGeom.PointInstancer.Define(st, "/World/Shelf_Items")
    book = xform(st, "/World/Shelf_Items/Protos/Book")
    labels_api(book.GetPrim(), "book")
    cube(st, "/World/Shelf_Items/Protos/Book/Geo", size=0.2, translate=(0, 0, 0.1))
    mug = UsdGeom.Cylinder.Define(st, "/World/Shelf_Items/Protos/Mug")
    mug.CreateRadiusAttr(0.05)
    mug.CreateHeightAttr(0.1)
    mug.AddTranslateOp().Set(Gf.Vec3d(0, 0, 0.05))
    pi.CreatePrototypesRel().SetTargets([book.GetPath(), mug.GetPath()])
    idx = [0, 1, 0, 1, 0, 0]
    pi.CreateProtoIndicesAttr(idx)
    pi.CreatePositionsAttr([Gf.Vec3f(float(k), 0.0, 1.0) for k in range(len(idx))])
    quat = Gf.Quath(math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4))  # 90 degrees about z
    pi.CreateOrientationsAttr([Gf.Quath(1, 0, 0, 0)] * 5 + [quat])
    st.Save()
    scene = load_usd(tmp_path / "pi.usda")
    assert len(scene.instances) == len(idx)  # prototypes are not imported on their own
    for k, proto in enumerate(idx):
        inst = by_id(scene)[f"Shelf_Items_{k}"]
        assert inst.category == ("book" if proto == 0 else "mug")
        assert inst.position == pytest.approx((float(k), 0.0, 1.0), abs=1e-6)
    assert by_id(scene)["Shelf_Items_5"].yaw == pytest.approx(math.pi / 2, abs=1e-3)
    assert by_id(scene)["Shelf_Items_1"].geoms[0].kind == "cylinder"
    pi.InvisId(2, Usd.TimeCode.Default())
    st.Save()
    assert len(load_usd(tmp_path / "pi.usda").instances) == len(idx) - 1


# ---------------------------------------------------------------------------
# Geometry
# ---------------------------------------------------------------------------

L_SHAPE = [(0, 0), (3, 0), (3, 1), (1, 1), (1, 2), (0, 2)]


def star(n=5, r_out=1.0, r_in=0.4):
    return [((r_out if k % 2 == 0 else r_in) * math.cos(math.pi * k / n),
             (r_out if k % 2 == 0 else r_in) * math.sin(math.pi * k / n)) for k in range(2 * n)]


@pytest.mark.parametrize("poly", [L_SHAPE, star(), list(reversed(star(7)))], ids=["L", "star", "star7_cw"])
def test_concave_face_triangulation(poly):
    p2 = np.asarray(poly, dtype=np.float64)
    # place the face in a tilted plane: the triangulator must find that plane
    rot = np.array(Gf.Matrix3d(Gf.Rotation(Gf.Vec3d(1, 2, 0.5), 37.0)))
    pts = np.concatenate([p2, np.zeros((len(p2), 1))], 1) @ rot + [5.0, -1.0, 2.0]
    tris = triangulate_faces(pts, [len(poly)], np.arange(len(poly)))
    assert len(tris) == len(poly) - 2
    assert mesh_area(pts, tris) == pytest.approx(abs(polygon_area(p2)))
    centroids = p2[tris].mean(axis=1)
    assert points_in_polygon(centroids, p2).all()
    # winding kept: every triangle has the face's orientation
    sign = np.sign(polygon_area(p2))
    a = p2[tris]
    cross = (a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1]) - (a[:, 1, 1] - a[:, 0, 1]) * (a[:, 2, 0] - a[:, 0, 0])
    assert (np.sign(cross) == sign).all()


def test_concave_quad_and_bad_indices():
    dart = np.array([[0, 0, 0], [2, 1, 0], [0, 0.5, 0], [-2, 1, 0]], float)  # reflex at vertex 2
    for start in range(4):
        ring = np.roll(np.arange(4), start)
        tris = triangulate_faces(dart, [4], ring)
        assert mesh_area(dart, tris) == pytest.approx(abs(polygon_area(dart[:, :2])))
    with pytest.raises(SceneError, match="faceVertexCounts sum"):
        triangulate_faces(dart, [4, 3], np.arange(4), path="f.usda", where="/M")
    with pytest.raises(SceneError, match="refer to vertex 7"):
        triangulate_faces(dart, [3], [0, 1, 7], path="f.usda", where="/M")


def test_ngon_mesh_prim_is_triangulated_on_import(tmp_path):
    st = new_stage(tmp_path / "m.usda")
    m = UsdGeom.Mesh.Define(st, "/World/Rug")
    pts = [(x, y, 0.01) for x, y in L_SHAPE] + [(x + 5, y, 0.01) for x, y in star()]
    m.CreatePointsAttr(pts)
    m.CreateFaceVertexCountsAttr([6, 10])
    m.CreateFaceVertexIndicesAttr(list(range(16)))
    st.Save()
    rug = load_usd(tmp_path / "m.usda").instances[0]
    assert rug.category == "rug"
    (g,) = rug.geoms
    assert g.kind == "mesh" and len(g.mesh.faces) == 4 + 8
    expected = abs(polygon_area(L_SHAPE)) + abs(polygon_area(star()))
    assert mesh_area(g.mesh.vertices, g.mesh.faces) == pytest.approx(expected)


def test_primitives_become_geoms_where_the_transform_allows(tmp_path):
    st = new_stage(tmp_path / "p.usda")
    s = UsdGeom.Sphere.Define(st, "/World/Egg")
    s.CreateRadiusAttr(0.5)
    s.AddScaleOp().Set(Gf.Vec3f(1.0, 2.0, 3.0))
    c = UsdGeom.Cylinder.Define(st, "/World/Pipe")
    c.CreateRadiusAttr(0.1)
    c.CreateHeightAttr(2.0)
    c.CreateAxisAttr("X")
    c.AddTranslateOp().Set(Gf.Vec3d(0, 3, 0.1))
    cap = UsdGeom.Capsule.Define(st, "/World/Pill")
    cap.AddTranslateOp().Set(Gf.Vec3d(3, 3, 0))
    cap.AddScaleOp().Set(Gf.Vec3f(2, 2, 2))
    sheared = xform(st, "/World/Slab", scale=(3.0, 1.0, 1.0))
    sheared.AddRotateZOp().Set(30.0)
    cube(st, "/World/Slab/Geo", size=1.0)
    UsdGeom.Cone.Define(st, "/World/Cone_1").AddTranslateOp().Set(Gf.Vec3d(-3, 0, 1))
    st.Save()
    got = by_id(load_usd(tmp_path / "p.usda"))
    egg = got["Egg"].geoms[0]
    assert egg.kind == "ellipsoid" and sorted(egg.size) == pytest.approx([0.5, 1.0, 1.5])
    assert got["Egg"].bbox.half_extents[2] == pytest.approx(1.5)
    pipe = got["Pipe"]
    assert pipe.geoms[0].kind == "cylinder" and pipe.geoms[0].size == pytest.approx((0.1, 1.0, 0.0))
    assert sorted(pipe.bbox.half_extents[:2]) == pytest.approx([0.1, 1.0])
    pill = got["Pill"].geoms[0]
    assert pill.kind == "capsule" and pill.size == pytest.approx((1.0, 1.0, 0.0))  # radius 0.5*2, half height 0.5*2
    assert got["Pill"].bbox.half_extents[2] == pytest.approx(2.0)
    assert got["Slab"].geoms[0].kind == "mesh"  # rotate-then-scale shears the cube
    assert got["Cone_1"].geoms[0].kind == "mesh" and got["Cone_1"].category == "unknown"


def test_colours_from_display_color_or_preview_surface(tmp_path):
    from pxr import UsdShade

    st = new_stage(tmp_path / "c.usda")
    a = cube(st, "/World/Chair_A", size=0.5)
    a.CreateDisplayColorPrimvar().Set([Gf.Vec3f(0.1, 0.2, 0.8)])
    b = cube(st, "/World/Chair_B", size=0.5, translate=(2, 0, 0))
    mat = UsdShade.Material.Define(st, "/World/Looks/Red")
    shader = UsdShade.Shader.Define(st, "/World/Looks/Red/Surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.8, 0.1, 0.1))
    shader.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(0.5)
    mat.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(b.GetPrim()).Bind(mat)
    cube(st, "/World/Chair_C", size=0.5, translate=(4, 0, 0))
    st.Save()
    got = by_id(load_usd(tmp_path / "c.usda"))
    assert got["Chair_A"].attributes.color == "blue"
    assert got["Chair_B"].attributes.color == "red"
    assert got["Chair_B"].geoms[0].rgba == pytest.approx((0.8, 0.1, 0.1, 0.5))
    assert got["Chair_C"].attributes.color is None  # nothing authored
    assert set(got) == {"Chair_A", "Chair_B", "Chair_C"}  # materials are not objects


# ---------------------------------------------------------------------------
# Which prims are instances, and their categories and rooms
# ---------------------------------------------------------------------------


def test_labels_kinds_names_and_assets_give_categories(tmp_path):
    vase = new_stage(tmp_path / "vase.usda", default="/V")
    cube(vase, "/V/Body", size=0.2)
    vase.Save()
    st = new_stage(tmp_path / "l.usda")
    isaac_label(xform(st, "/World/A", translate=(0, 0, 0)).GetPrim(), "sofa")
    cube(st, "/World/A/Geo")
    labels_api(xform(st, "/World/B", translate=(2, 0, 0)).GetPrim(), "Fridge")
    cube(st, "/World/B/Geo")
    c = xform(st, "/World/C", translate=(4, 0, 0)).GetPrim()
    c.CreateAttribute("ignjax:category", Sdf.ValueTypeNames.String).Set("laptop")
    cube(st, "/World/C/Geo")
    d = xform(st, "/World/Stuff/Desk_1", translate=(6, 0, 0)).GetPrim()
    Usd.ModelAPI(d).SetKind(Kind.Tokens.component)
    cube(st, "/World/Stuff/Desk_1/Top")
    cube(st, "/World/Stuff/Desk_1/Leg", translate=(0, 0, -1))
    e = xform(st, "/World/Stuff/Thing", translate=(8, 0, 0)).GetPrim()
    Usd.ModelAPI(e).SetKind("bookshelf")  # a custom, category-like kind
    cube(st, "/World/Stuff/Thing/Geo")
    xform(st, "/World/Television_2", translate=(10, 0, 0))
    cube(st, "/World/Television_2/Screen")
    g = xform(st, "/World/Xform_7", translate=(12, 0, 0))
    g.GetPrim().GetReferences().AddReference("./vase.usda")
    cube(st, "/World/Mesh_3", translate=(14, 0, 0))
    isaac_label(xform(st, "/World/F", translate=(16, 0, 0)).GetPrim(), "red", kind="color")  # not a class label
    cube(st, "/World/F/Geo")
    # a bed labelled on every part (merged), with a pillow of its own
    labels_api(xform(st, "/World/Bed", translate=(0, 5, 0)).GetPrim(), "bed")
    labels_api(cube(st, "/World/Bed/Frame", size=2.0).GetPrim(), "bed")
    labels_api(cube(st, "/World/Bed/Mattress", size=1.8, translate=(0, 0, 1)).GetPrim(), "Bed")
    isaac_label(cube(st, "/World/Bed/Pillow_01", size=0.3, translate=(0.5, 0, 2)).GetPrim(), "pillow")
    st.Save()
    scene = load_usd(tmp_path / "l.usda")
    cats = {i.id: i.category for i in scene.instances}
    assert cats == {
        "A": "sofa", "B": "refrigerator", "C": "laptop", "Desk_1": "desk", "Thing": "bookshelf",
        "Television_2": "television", "Xform_7": "vase", "Mesh_3": "unknown", "F": "unknown",
        "Bed": "bed", "Pillow_01": "pillow",
    }
    got = by_id(scene)
    assert got["Desk_1"].bbox.half_extents[2] == pytest.approx(1.0)  # both parts owned by the component
    assert len(got["Bed"].geoms) == 2
    assert got["Bed"].name == "/World/Bed"
    assert all(not i.structural for i in scene.instances)


def test_room_labels_define_rooms_and_instances_get_them(tmp_path):
    st = new_stage(tmp_path / "r.usda")
    k = xform(st, "/World/Kitchen_1").GetPrim()
    labels_api(k, "Kitchen")
    floor = UsdGeom.Mesh.Define(st, "/World/Kitchen_1/Floor")
    floor.CreatePointsAttr([(x, y, 0.0) for x, y in [(0, 0), (6, 0), (6, 2), (2, 2), (2, 5), (0, 5)]])
    floor.CreateFaceVertexCountsAttr([6])
    floor.CreateFaceVertexIndicesAttr(list(range(6)))
    lr = xform(st, "/World/Lounge").GetPrim()
    isaac_label(lr, "living room")
    cube(st, "/World/Lounge/FloorSlab", size=1.0, translate=(4.5, 4.0, -0.025), scale=(5.0, 4.0, 0.05))
    isaac_label(cube(st, "/World/Fridge", size=0.8, translate=(1, 4, 0.4)).GetPrim(), "refrigerator")
    isaac_label(cube(st, "/World/Couch", size=0.8, translate=(5, 4, 0.4)).GetPrim(), "sofa")
    isaac_label(cube(st, "/World/Loo", size=0.5, translate=(20, 20, 0.25)).GetPrim(), "toilet")  # object, not a room
    # unlabelled furniture inside a labelled room is still furniture
    cube(st, "/World/Kitchen_1/Table", size=0.8, translate=(4, 1, 0.4))
    # a room prim without a floor is outlined by the objects below it
    labels_api(xform(st, "/World/Study", translate=(30, 0, 0)).GetPrim(), "study")
    cube(st, "/World/Study/Desk", size=1.0, translate=(0, 0, 0.5))
    cube(st, "/World/Study/Office_Chair", size=0.5, translate=(2, 1, 0.25))
    st.Save()
    scene = load_usd(tmp_path / "r.usda")
    rooms = {r.id: r for r in scene.rooms}
    assert set(rooms) == {"Kitchen_1", "Lounge", "Study"}
    assert (rooms["Kitchen_1"].label, rooms["Lounge"].label, rooms["Study"].label) == ("kitchen", "living_room", "office")
    assert rooms["Kitchen_1"].area == pytest.approx(6 * 2 + 2 * 3)
    assert set(rooms["Kitchen_1"].polygon) == {(0, 0), (6, 0), (6, 2), (2, 2), (2, 5), (0, 5)}
    assert rooms["Lounge"].area == pytest.approx(20.0)
    got = by_id(scene)
    assert set(got) == {"Fridge", "Couch", "Loo", "Table", "Desk", "Office_Chair"}
    assert (got["Fridge"].room, got["Couch"].room, got["Loo"].room) == ("Kitchen_1", "Lounge", None)
    assert (got["Table"].category, got["Table"].room) == ("dining_table", "Kitchen_1")
    assert got["Desk"].room == got["Office_Chair"].room == "Study"
    assert rooms["Study"].contains(np.array([[30.0, 0.0], [32.0, 1.0]])).all()


def test_without_rooms_one_room_covers_everything(tmp_path):
    st = new_stage(tmp_path / "o.usda")
    for k, (x, y) in enumerate([(0, 0), (4, 1), (2, 5), (-1, 3)]):
        cube(st, f"/World/Chair_{k}", size=0.5, translate=(x, y, 0.25))
    st.Save()
    scene = load_usd(tmp_path / "o.usda")
    (room,) = scene.rooms
    assert (room.id, room.label) == ("room_0", "other")
    assert all(i.room == "room_0" for i in scene.instances)
    assert all(i.category == "chair" for i in scene.instances)
    assert room.area > 10


def floor_quad(st, path, x0, y0, x1, y1):
    m = UsdGeom.Mesh.Define(st, path)
    m.CreatePointsAttr([(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0)])
    m.CreateFaceVertexCountsAttr([4])
    m.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    return m


def test_rooms_from_prim_names_and_room_attributes(tmp_path):
    st = new_stage(tmp_path / "n.usda")
    # named like rooms, no label anywhere
    xform(st, "/World/Kitchen")
    floor_quad(st, "/World/Kitchen/Floor", 0, 0, 4, 3)
    cube(st, "/World/Kitchen/Table", size=0.8, translate=(2, 1.5, 0.4))
    cube(st, "/World/Kitchen/Stool", size=0.4, translate=(6, 1, 0.2))  # under Kitchen, over the bedroom's floor
    xform(st, "/World/Bedroom_2")
    floor_quad(st, "/World/Bedroom_2/Ground", 5, 0, 9, 3)
    cube(st, "/World/Bedroom_2/Bed", size=1.0, translate=(8, 1.5, 0.5))
    xform(st, "/World/LivingRoom")  # no floor: outlined by its objects
    cube(st, "/World/LivingRoom/Sofa", size=1.0, translate=(0, 10, 0.5))
    cube(st, "/World/LivingRoom/Armchair", size=0.8, translate=(3, 12, 0.4))
    xform(st, "/World/living_room")
    floor_quad(st, "/World/living_room/Floor", 10, 0, 14, 3)
    # rooms by attribute only (the names say nothing)
    a = xform(st, "/World/Zone_A").GetPrim()
    a.CreateAttribute("userProperties:roomType", Sdf.ValueTypeNames.String).Set("Bathroom")
    floor_quad(st, "/World/Zone_A/Floor", 0, 20, 3, 23)
    b = xform(st, "/World/Zone_B").GetPrim()
    b.SetCustomData({"semantic": {"room": "Garage"}})
    floor_quad(st, "/World/Zone_B/FloorSlab", 10, 20, 16, 26)
    c = xform(st, "/World/Zone_C").GetPrim()
    c.CreateAttribute("label", Sdf.ValueTypeNames.String).Set("Hall")
    floor_quad(st, "/World/Zone_C/Floor", 20, 20, 24, 22)
    # a generic label that names no room, and a room attribute on a labelled object: objects
    d = xform(st, "/World/Zone_D").GetPrim()
    d.CreateAttribute("label", Sdf.ValueTypeNames.String).Set("chair")
    cube(st, "/World/Zone_D/Geo", size=0.5, translate=(30, 30, 0.25))
    couch = cube(st, "/World/Couch", size=0.8, translate=(12, 1, 0.4)).GetPrim()
    isaac_label(couch, "sofa")
    couch.CreateAttribute("roomType", Sdf.ValueTypeNames.String).Set("kitchen")
    chair = xform(st, "/World/Chair_01").GetPrim()  # an object that records its room
    chair.CreateAttribute("room", Sdf.ValueTypeNames.String).Set("Bedroom")
    cube(st, "/World/Chair_01/Seat", size=0.5, translate=(6, 2, 0.25))
    # an object named after a room, and one under no room prim standing on the kitchen floor
    cube(st, "/World/Lamp_Kitchen", size=0.3, translate=(1, 2.5, 0.15))
    cube(st, "/World/Fridge", size=0.8, translate=(0.5, 0.5, 0.4))
    st.Save()
    scene = load_usd(tmp_path / "n.usda")
    rooms = {r.id: r.label for r in scene.rooms}
    assert rooms == {"Kitchen": "kitchen", "Bedroom_2": "bedroom", "LivingRoom": "living_room",
                     "living_room": "living_room", "Zone_A": "bathroom", "Zone_B": "garage", "Zone_C": "hallway"}
    got = by_id(scene)
    assert set(got) == {"Table", "Stool", "Bed", "Sofa", "Armchair", "Zone_D", "Couch", "Lamp_Kitchen", "Fridge", "Chair_01"}
    assert (got["Chair_01"].category, got["Chair_01"].room) == ("chair", "Bedroom_2")
    assert {k: got[k].room for k in ("Table", "Bed", "Sofa", "Armchair")} == \
        {"Table": "Kitchen", "Bed": "Bedroom_2", "Sofa": "LivingRoom", "Armchair": "LivingRoom"}
    assert got["Stool"].room == "Kitchen"  # the room prim it is under wins over the floor it is over
    assert got["Fridge"].room == "Kitchen" and got["Lamp_Kitchen"].room == "Kitchen"  # by the floor they stand on
    assert got["Couch"].room == "living_room" and got["Couch"].category == "sofa"
    assert got["Zone_D"].room is None
    assert {k: got[k].category for k in ("Table", "Bed", "Fridge", "Lamp_Kitchen")} == \
        {"Table": "dining_table", "Bed": "bed", "Fridge": "refrigerator", "Lamp_Kitchen": "lamp_kitchen"}
    kitchen = scene.room("Kitchen")
    assert set(kitchen.polygon) == {(0, 0), (4, 0), (4, 3), (0, 3)}
    assert scene.room("LivingRoom").contains(np.array([[0.0, 10.0], [3.0, 12.0]])).all()


def test_point_instancer_points_belong_to_the_room_prim_they_are_under(tmp_path):
    st = new_stage(tmp_path / "pi.usda")
    xform(st, "/World/Office")
    floor_quad(st, "/World/Office/Floor", 0, 0, 4, 4)
    pi = UsdGeom.PointInstancer.Define(st, "/World/Office/Chairs")
    cube(st, "/World/Office/Chairs/Proto/Chair", size=0.5)
    pi.CreatePrototypesRel().SetTargets(["/World/Office/Chairs/Proto/Chair"])
    pi.CreateProtoIndicesAttr([0, 0])
    pi.CreatePositionsAttr([(1, 1, 0.25), (9, 9, 0.25)])  # the second is outside the office floor
    st.Save()
    scene = load_usd(tmp_path / "pi.usda")
    assert [r.id for r in scene.rooms] == ["Office"] and scene.rooms[0].label == "office"
    assert [(i.category, i.room) for i in scene.instances] == [("chair", "Office"), ("chair", "Office")]


# ---------------------------------------------------------------------------
# Errors and warnings
# ---------------------------------------------------------------------------


def _text_stage(path: Path, header: str, body: str = 'def Cube "C" {}') -> Path:
    path.write_text(f"#usda 1.0\n(\n{header}\n)\n{body}\n")
    return path


@pytest.mark.parametrize("axis", ["X", "sideways"])
def test_unsupported_up_axis_is_an_error(tmp_path, axis):
    p = _text_stage(tmp_path / "a.usda", f'upAxis = "{axis}"\nmetersPerUnit = 1')
    with pytest.raises(SceneError) as e:
        load_usd(p)
    assert e.value.path == str(p) and e.value.where == "upAxis" and repr(axis) in e.value.reason


def test_files_that_are_not_usd(tmp_path):
    text = tmp_path / "notes.usda"
    text.write_text("this is not a stage\n")
    binary = tmp_path / "blob.usdc"
    binary.write_bytes(bytes(range(256)) * 8)
    for p in (text, binary):
        with pytest.raises(SceneError, match="not a readable USD file") as e:
            load_usd(p)
        assert e.value.path == str(p)
    with pytest.raises(SceneError, match="no such file"):
        load_usd(tmp_path / "missing.usda")


def test_stage_without_geometry(tmp_path):
    st = new_stage(tmp_path / "empty.usda")
    xform(st, "/World/Group/Empty")
    UsdGeom.BasisCurves.Define(st, "/World/Group/Curve")
    st.Save()
    with pytest.warns(UsdImportWarning, match="BasisCurves"):
        with pytest.raises(SceneError, match="has no geometry"):
            load_usd(tmp_path / "empty.usda")


def test_nan_transform_names_the_prim(tmp_path):
    st = new_stage(tmp_path / "nan.usda")
    xform(st, "/World/Table", translate=(float("nan"), 0.0, 0.0))
    cube(st, "/World/Table/Top")
    st.Save()
    with pytest.raises(SceneError, match="NaN") as e:
        load_usd(tmp_path / "nan.usda")
    assert e.value.where == "/World/Table"


def test_nan_points_name_the_prim(tmp_path):
    st = new_stage(tmp_path / "nanp.usda")
    m = UsdGeom.Mesh.Define(st, "/World/Blob")
    m.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (0, float("inf"), 0)])
    m.CreateFaceVertexCountsAttr([3])
    m.CreateFaceVertexIndicesAttr([0, 1, 2])
    st.Save()
    with pytest.raises(SceneError, match="NaN or infinite") as e:
        load_usd(tmp_path / "nanp.usda")
    assert e.value.where == "/World/Blob.points"


def test_missing_sublayer_and_reference_warn_and_continue(tmp_path):
    st = new_stage(tmp_path / "w.usda")
    st.GetRootLayer().subLayerPaths.append("./gone_sublayer.usda")
    cube(st, "/World/Stool", size=0.4, translate=(0, 0, 0.2))
    r = xform(st, "/World/Lamp")
    r.GetPrim().GetReferences().AddReference("./gone_lamp.usda")
    xform(st, "/World/Sofa").GetPrim().GetPayloads().AddPayload("./gone_sofa.usda")
    st.Save()
    with pytest.warns(UsdImportWarning) as record:
        scene = load_usd(tmp_path / "w.usda")
    messages = [str(w.message) for w in record]
    assert any("gone_sublayer.usda" in m and "w.usda" in m for m in messages)
    assert any("gone_lamp.usda" in m and "/World/Lamp" in m for m in messages)
    assert any("gone_sofa.usda" in m and "/World/Sofa" in m for m in messages)
    assert all(w.filename == __file__ for w in record)  # reported at the caller
    assert [i.category for i in scene.instances] == ["stool"]


# -- USD's own errors and warnings: one line of ours, never pxr internals ------

_INTERNAL = ("pxr", "Tf", "Traceback", "Error in", ".cpp", "_ReportErrors")


def _usd_file(tmp_path: Path, kind: str) -> Path:
    if kind == "empty":
        p = tmp_path / "empty.usda"
        p.write_text("")
    elif kind == "garbage":
        p = tmp_path / "garbage.usda"
        p.write_text("this is not a USD layer\n" * 40)
    else:  # a .usd whose only content is a sublayer that does not exist
        p = tmp_path / "shell.usd"
        p.write_text('#usda 1.0\n(\n    subLayers = [@./missing_layer.usda@]\n)\n')
    return p


@pytest.mark.parametrize("kind,reason", [("empty", "empty file"), ("garbage", "not a readable USD file (not a valid usda layer)"),
                                         ("sublayer", "no geometry")])
def test_usd_errors_are_one_short_line(tmp_path, capfd, kind, reason):
    p = _usd_file(tmp_path, kind)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        with pytest.raises(SceneError) as e:
            load_usd(p)
    message = str(e.value)
    assert "\n" not in message and message.startswith(str(p)) and reason in message
    assert len(message) < len(str(p)) + 200
    assert not any(bad in message for bad in _INTERNAL), message
    if kind != "sublayer":
        assert e.value.__suppress_context__  # no chained pxr exception in a traceback either
    err = capfd.readouterr().err
    assert not any(bad in err for bad in _INTERNAL), err  # nothing printed by USD itself
    if kind == "sublayer":
        assert "1 asset reference could not be resolved, e.g. sublayer missing_layer.usda of shell.usd" in message
        (w,) = [w for w in record if issubclass(w.category, UsdImportWarning)]
        assert "missing_layer.usda" in str(w.message) and "\n" not in str(w.message)


def test_many_unresolved_assets_are_one_summary_line(tmp_path, capfd):
    from pxr import UsdShade

    (tmp_path / "look.mtlx").write_text('<?xml version="1.0"?>\n<materialx version="1.38"></materialx>\n')
    st = new_stage(tmp_path / "busy.usda")
    st.GetRootLayer().subLayerPaths.append("./gone_layer.usda")
    cube(st, "/World/Stool", size=0.4, translate=(0, 0, 0.2))
    for k in range(5):
        xform(st, f"/World/Lamp_{k}").GetPrim().GetReferences().AddReference(f"./gone_lamp_{k}.usda")
    UsdShade.Material.Define(st, "/World/Looks/Look").GetPrim().GetReferences().AddReference("./look.mtlx", "/Look")
    st.Save()
    capfd.readouterr()  # what USD printed while the test authored the stage
    with pytest.warns(UsdImportWarning) as record:
        scene = load_usd(tmp_path / "busy.usda")
    assert [i.id for i in scene.instances] == ["Stool"]
    messages = [str(w.message) for w in record]
    assert len(messages) == 1, messages
    (summary,) = messages
    assert "7 asset references could not be resolved (imported without them), e.g. " in summary
    assert "and 4 more" in summary and "gone_lamp_0.usda (reference on /World/Lamp_0)" in summary
    assert "\n" not in summary and not any(bad in summary for bad in _INTERNAL)
    err = capfd.readouterr().err
    assert "gone_lamp" not in err and not any(bad in err for bad in _INTERNAL), err


def test_other_usd_warnings_are_trapped_and_summarized(capfd):
    from pxr import Tf

    from ignjax.scenes.io.usd.stage import usd_diagnostics, warn_usd_messages

    with usd_diagnostics() as messages:
        for k in range(6):
            Tf.Warn(f"odd value {k % 5}")
        Tf.Warn("Could not open asset @x.usda@ (already reported)")
    assert capfd.readouterr().err == ""  # USD printed nothing
    with pytest.warns(UsdImportWarning) as record:
        warn_usd_messages("s.usda", messages, known=["Could not open asset @x.usda@"])
    (w,) = record
    assert str(w.message).startswith("s.usda: USD reported: 5 further messages from USD, e.g. odd value 0; odd value 1; ")
    with pytest.warns(UsdImportWarning) as record:
        warn_usd_messages("s.usda", ["odd value 9"])
    assert [str(w.message) for w in record] == ["s.usda: USD reported: odd value 9"]


# ---------------------------------------------------------------------------
# The usd-wg stage-configuration files
# ---------------------------------------------------------------------------


@pytest.fixture()
def stage_config(shared_data):
    folder = shared_data / "usd-stage-config"
    if not folder.is_dir():
        pytest.skip(f"{folder} is absent")
    return folder


@pytest.mark.shared
@pytest.mark.parametrize("name,value", [("upAxis_X.usda", "X"), ("upAxis_invalid.usda", "invalid")])
def test_shared_unsupported_up_axis(stage_config, name, value):
    with pytest.raises(SceneError) as e:
        load_quiet(stage_config / name)
    assert e.value.where == "upAxis" and repr(value) in e.value.reason


@pytest.mark.shared
@pytest.mark.parametrize("name", ["upAxis_Y.usda", "upAxis_Z.usda"])
def test_shared_up_axis_stages_hold_only_a_missing_sublayer(stage_config, name):
    with pytest.warns(UsdImportWarning) as record:
        with pytest.raises(SceneError, match="has no geometry"):
            load_usd(stage_config / name)
    messages = [str(w.message) for w in record]
    assert any("axis.usda" in m for m in messages)  # the missing sublayer
    assert any("defaultPrim 'World'" in m for m in messages)  # World lived in that sublayer


@pytest.mark.shared
@pytest.mark.parametrize("name,mpu", [("metersPerUnit_1.usda", 1.0), ("metersPerUnit_10.usda", 10.0)])
def test_shared_meters_per_unit(stage_config, name, mpu):
    with pytest.warns(UsdImportWarning, match="axis.usda"):
        scene = load_usd(stage_config / name)
    assert (scene.meta.up_axis, scene.meta.meters_per_unit) == ("Y", mpu)
    (cube_,) = scene.instances
    assert cube_.bbox.half_extents == pytest.approx((mpu, mpu, mpu))  # a default Cube is 2 units wide
    assert cube_.geoms[0].kind == "box"


@pytest.mark.shared
def test_shared_meters_per_unit_mix(stage_config):
    scene = load_quiet(stage_config / "metersPerUnit_mix.usda")
    got = by_id(scene)
    assert scene.meta.meters_per_unit == 100.0
    # each cube in the units of the layer that defines it, placed by the root layer's overs
    assert {k: v.bbox.half_extents[0] for k, v in got.items()} == pytest.approx({"cube_1": 1.0, "cube_10": 10.0, "cube_100": 100.0})
    assert {k: v.bbox.center[0] for k, v in got.items()} == pytest.approx({"cube_1": 300.0, "cube_10": 600.0, "cube_100": 0.0})
    plain = by_id(load_quiet(stage_config / "metersPerUnit_mix.usda", correct_layer_units=False))
    assert {k: v.bbox.half_extents[0] for k, v in plain.items()} == pytest.approx({"cube_1": 100.0, "cube_10": 100.0, "cube_100": 100.0})


@pytest.mark.shared
@pytest.mark.parametrize("name", ["multiple_root_prims_no_defaultPrim.usda", "multiple_root_prims_with_defaultPrim.usda"])
def test_shared_multiple_root_prims(stage_config, name):
    scene = load_usd(stage_config / name)
    got = by_id(scene)
    assert set(got) == {"Cube", "Sphere"}
    assert got["Cube"].bbox.half_extents == pytest.approx((0.01, 0.01, 0.01))
    assert got["Sphere"].geoms[0].kind == "sphere" and got["Sphere"].geoms[0].size[0] == pytest.approx(0.01)
    assert got["Sphere"].bbox.center == pytest.approx((0.02, 0.0, 0.0))
    if "with" in name:
        assert scene.instances[0].id == "Sphere"  # the defaultPrim comes first


@pytest.mark.shared
def test_shared_invalid_default_prim(stage_config):
    with pytest.warns(UsdImportWarning, match="invalidDefaultPrim"):
        scene = load_usd(stage_config / "invalid_defaultPrim.usda")
    (cube_,) = scene.instances
    assert cube_.id == "Cube" and cube_.name == "/World/Cube"
    assert cube_.bbox.half_extents == pytest.approx((0.01, 0.01, 0.01))


def test_scene_io_dispatches_usd(two_room_scene, tmp_path):
    from ignjax.scenes.io.sources import load_scenes

    out = save_usd(two_room_scene, tmp_path / "h.usdc")
    (scene,) = load_scenes(out)
    assert scene.instances == two_room_scene.instances
