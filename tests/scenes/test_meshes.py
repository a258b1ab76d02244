"""glTF / GLB / OBJ import: categories, Y-up conversion, sidecars, errors.

Every file is written here with trimesh (or by hand for OBJ, to control
object and group names exactly), so the expected poses are known.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh
from trimesh.exchange.gltf import export_glb, export_gltf
from trimesh.transformations import rotation_matrix, translation_matrix

from ignjax.errors import SceneError
from ignjax.scenes.io import sources as scene_io
from ignjax.scenes.io.meshes import load_mesh_scene, read_sidecar, sidecar_path
from ignjax.scenes.model import scene_to_json


def _y_up_scene() -> trimesh.Scene:
    """A Y-up scene (glTF convention): 6 x 5 m floor, two chairs, a turned table.

    In ignjax's frame (x, -z, y): Chair_1 stands at (1, 2), chair_2 at
    (3, 1), the table at (2, 2) with its 2 m side along y.
    """
    s = trimesh.Scene()
    chair = trimesh.creation.box((0.5, 1.0, 0.5))
    chair.visual.face_colors = [200, 20, 20, 255]
    s.add_geometry(chair, node_name="Chair_1", geom_name="Chair_1", transform=translation_matrix([1, 0.5, -2]))
    # trimesh cylinders run along z; turn it upright (along y).
    cyl = trimesh.creation.cylinder(radius=0.3, height=0.9)
    s.add_geometry(cyl, node_name="chair_2", geom_name="chair_2_geo",
                   transform=translation_matrix([3, 0.45, -1]) @ rotation_matrix(math.pi / 2, [1, 0, 0]))
    s.add_geometry(trimesh.creation.box((2.0, 0.8, 1.0)), node_name="Table", geom_name="Table",
                   transform=translation_matrix([2, 0.4, -2]) @ rotation_matrix(math.pi / 2, [0, 1, 0]))
    s.add_geometry(trimesh.creation.box((6.0, 0.02, 5.0)), node_name="Floor", geom_name="Floor",
                   transform=translation_matrix([2, -0.01, -2]))
    return s


def _write_scene(scene: trimesh.Scene, path: Path) -> Path:
    if path.suffix == ".glb":
        path.write_bytes(export_glb(scene))
    else:
        files = export_gltf(scene, embed_buffers=True)
        path.write_bytes(files["model.gltf"])
    return path


def _obj_text(objects: dict[str, trimesh.Trimesh], keyword: str = "o") -> str:
    lines, offset = [], 1
    for name, mesh in objects.items():
        lines.append(f"{keyword} {name}")
        lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in mesh.vertices]
        lines += [f"f {a + offset} {b + offset} {c + offset}" for a, b, c in mesh.faces]
        offset += len(mesh.vertices)
    return "\n".join(lines) + "\n"


def _box_at(size, centre) -> trimesh.Trimesh:
    b = trimesh.creation.box(size)
    b.apply_translation(centre)
    return b


def _world_vertices(inst, geom) -> np.ndarray:
    c, s = math.cos(inst.yaw), math.sin(inst.yaw)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return geom.mesh.vertices @ rot.T + np.array(inst.position)


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_gltf_nodes_categories_and_y_up(tmp_path, suffix):
    path = _write_scene(_y_up_scene(), tmp_path / f"room{suffix}")
    s = load_mesh_scene(path)
    assert s.id == "room" and s.meta.source_format == "mesh" and s.meta.up_axis == "Y"
    by_id = {i.id: i for i in s.instances}
    assert {k: v.category for k, v in by_id.items()} == {
        "Chair_1": "chair", "chair_2": "chair", "Table": "dining_table", "Floor": "floor"}
    assert s.categories() == {"chair": 2, "dining_table": 1}
    assert by_id["Floor"].structural and not by_id["Chair_1"].structural

    chair = by_id["Chair_1"]
    assert np.allclose(chair.position, (1.0, 2.0, 0.0), atol=1e-6)
    assert np.allclose(chair.bbox.half_extents, (0.25, 0.25, 0.5), atol=1e-6)  # 1 m tall: glTF y is our z
    assert chair.yaw == 0.0 and chair.attributes.color == "red"
    assert np.allclose(by_id["chair_2"].position, (3.0, 1.0, 0.0), atol=1e-6)
    assert np.allclose(by_id["chair_2"].bbox.half_extents, (0.3, 0.3, 0.45), atol=1e-6)
    assert by_id["chair_2"].attributes.color is None  # no colour in the file, none guessed

    table = by_id["Table"]
    assert math.isclose(table.yaw, math.pi / 2, abs_tol=1e-9)  # turned +90 deg about glTF's up
    assert np.allclose(table.position, (2.0, 2.0, 0.0), atol=1e-6)
    corners = table.bbox.footprint()
    assert np.allclose(corners.max(0) - corners.min(0), (1.0, 2.0), atol=1e-6)  # long along y

    # Geometry: one mesh geom in the instance frame; maps back onto the world box.
    [g] = chair.geoms
    assert g.kind == "mesh" and len(g.mesh.faces) == 12
    assert math.isclose(g.mesh.vertices[:, 2].min(), 0.0, abs_tol=1e-6)
    w = _world_vertices(table, table.geoms[0])
    assert np.allclose(w.min(0), (1.5, 1.0, 0.0), atol=1e-6) and np.allclose(w.max(0), (2.5, 3.0, 0.8), atol=1e-6)

    # Default room: the convex hull of all geometry (here the floor), label "other".
    [room] = s.rooms
    assert room.id == "room_0" and room.label == "other"
    assert room.area == pytest.approx(30.0) and set(room.polygon) == {(-1, -0.5), (5, -0.5), (5, 4.5), (-1, 4.5)}
    assert all(i.room == "room_0" for i in s.instances)


def test_obj_objects_and_groups(tmp_path):
    objects = {
        "Chair_1": _box_at((0.5, 1.0, 0.5), (1, 0.5, -2)),
        "chair_2": _box_at((0.5, 1.0, 0.5), (3, 0.5, -1)),
        "Table": _box_at((2.0, 0.8, 1.0), (2, 0.4, -2)),
        "Floor": _box_at((6.0, 0.02, 5.0), (2, -0.01, -2)),
    }
    p = tmp_path / "flat.obj"
    p.write_text(_obj_text(objects))
    s = load_mesh_scene(p)
    by_id = {i.id: i for i in s.instances}
    assert sorted(by_id) == ["Chair_1", "Floor", "Table", "chair_2"]
    assert by_id["chair_2"].category == "chair" and by_id["Floor"].structural
    assert np.allclose(by_id["chair_2"].position, (3.0, 1.0, 0.0), atol=1e-6)  # Y-up -> Z-up
    assert np.allclose(by_id["Table"].bbox.half_extents, (1.0, 0.5, 0.4), atol=1e-6)
    # A file with only "g" groups is split by group.
    g = tmp_path / "groups.obj"
    g.write_text(_obj_text(objects, keyword="g"))
    assert sorted(i.id for i in load_mesh_scene(g).instances) == ["Chair_1", "Floor", "Table", "chair_2"]


def test_sidecar_next_to_file(tmp_path):
    # Z-up, centimetres.
    objects = {"Chair_1": _box_at((50, 50, 100), (100, 200, 50)), "Cube.003": _box_at((200, 100, 80), (500, 100, 40)),
               "Floor": _box_at((800, 400, 2), (400, 200, -1))}
    p = tmp_path / "flat.obj"
    p.write_text(_obj_text(objects))
    side = {"scene_id": "flat_01", "up_axis": "Z", "meters_per_unit": 0.01,
            "categories": {"Cube.003": "office desk", "Chair_1": "office chair"},
            "structural": ["Floor"],
            "rooms": [{"id": "r0", "label": "Living Room", "polygon": [[0, 0], [3, 0], [3, 4], [0, 4]]},
                      {"id": "r1", "label": "study", "polygon": [[3, 0], [8, 0], [8, 4], [3, 4]]}]}
    assert sidecar_path(p).name == "flat.obj.ignjax.json"
    sidecar_path(p).write_text(json.dumps(side))
    s = load_mesh_scene(p)
    assert s.id == "flat_01" and s.meta.up_axis == "Z" and s.meta.meters_per_unit == 0.01
    assert [(r.id, r.label, r.name) for r in s.rooms] == [("r0", "living_room", "Living Room"), ("r1", "office", "study")]
    by_id = {i.id: i for i in s.instances}
    assert by_id["Chair_1"].category == "office_chair" and by_id["Cube.003"].category == "office_desk"
    assert np.allclose(by_id["Chair_1"].position, (1.0, 2.0, 0.0), atol=1e-9)  # no axis swap, scaled
    assert np.allclose(by_id["Cube.003"].bbox.half_extents, (1.0, 0.5, 0.4), atol=1e-9)
    assert by_id["Chair_1"].room == "r0" and by_id["Cube.003"].room == "r1"
    assert by_id["Floor"].structural and by_id["Floor"].category == "floor"
    # The argument overrides the file next to it (a dict or a path).
    s2 = load_mesh_scene(p, sidecar={"up_axis": "Z", "meters_per_unit": 0.01, "structural": ["Chair_1"]})
    assert s2.id == "flat" and {i.id: i.structural for i in s2.instances}["Chair_1"]
    assert len(s2.rooms) == 1 and s2.rooms[0].label == "other"
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"up_axis": "Z", "meters_per_unit": 0.01, "scene_id": "x"}))
    assert load_mesh_scene(p, sidecar=other).id == "x"


def test_multi_primitive_gltf_node_is_one_instance(tmp_path):
    s = trimesh.Scene()
    seat = trimesh.creation.box((0.5, 0.1, 0.5))
    seat.visual.face_colors = [20, 20, 200, 255]
    back = _box_at((0.5, 0.6, 0.05), (0, 0.35, -0.225))
    back.visual.face_colors = [20, 20, 200, 255]
    s.add_geometry(seat, node_name="a", geom_name="seat")
    s.add_geometry(back, node_name="b", geom_name="back")
    doc = json.loads(export_gltf(s, embed_buffers=True)["model.gltf"])
    # One mesh with two primitives under a node "Chair_7" inside a group node.
    doc["meshes"][0]["primitives"] += doc["meshes"][1]["primitives"]
    doc["meshes"] = doc["meshes"][:1]
    doc["nodes"] = [{"name": "Furniture", "children": [1]}, {"name": "Chair_7", "mesh": 0, "translation": [1, 0.05, -1]}]
    doc["scenes"] = [{"nodes": [0]}]
    p = tmp_path / "chair.gltf"
    p.write_text(json.dumps(doc))
    sc = load_mesh_scene(p)
    [inst] = sc.instances
    assert inst.id == "Chair_7" and inst.category == "chair" and len(inst.geoms) == 2
    assert np.allclose(inst.position, (1.0, 1.0, 0.0), atol=1e-6)
    assert np.allclose(inst.bbox.half_extents, (0.25, 0.25, 0.35), atol=1e-6)  # seat + back
    assert inst.attributes.color == "blue"
    # Sidecar categories may name a group node.
    sc = load_mesh_scene(p, sidecar={"categories": {"Furniture": "stool"}})
    assert sc.instances[0].category == "stool"


def test_io_dispatch_and_determinism(tmp_path):
    p = _write_scene(_y_up_scene(), tmp_path / "room.glb")
    [a] = scene_io.load_scenes(p)
    b = load_mesh_scene(p)
    assert scene_to_json(a) == scene_to_json(b)


# ---------------------------------------------------------------------------
# Errors
# ---------------------------------------------------------------------------


def test_missing_file(tmp_path):
    with pytest.raises(SceneError, match="no such file") as e:
        load_mesh_scene(tmp_path / "nope.glb")
    assert e.value.path.endswith("nope.glb")


def test_garbage_glb(tmp_path):
    p = tmp_path / "junk.glb"
    p.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(SceneError, match="not a readable GLB") as e:
        load_mesh_scene(p)
    assert e.value.path == str(p)


def test_no_geometry(tmp_path):
    p = tmp_path / "empty.obj"
    p.write_text("# nothing here\n")
    with pytest.raises(SceneError, match="no triangle geometry"):
        load_mesh_scene(p)
    g = tmp_path / "empty.gltf"
    g.write_text(json.dumps({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"name": "Empty"}]}))
    with pytest.raises(SceneError, match="no triangle geometry"):
        load_mesh_scene(g)


def test_nan_vertices(tmp_path):
    p = tmp_path / "nan.obj"
    p.write_text("o Chair_1\nv nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(SceneError, match="NaN") as e:
        load_mesh_scene(p)
    assert "Chair_1" in e.value.where
    box = trimesh.creation.box((1, 1, 1))
    v = box.vertices.copy()
    v[3, 1] = np.inf
    sc = trimesh.Scene()
    sc.add_geometry(trimesh.Trimesh(v, box.faces, process=False), node_name="Table", geom_name="Table")
    g = tmp_path / "inf.glb"
    g.write_bytes(export_glb(sc))
    with pytest.raises(SceneError, match="NaN or infinite") as e:
        load_mesh_scene(g)
    assert "Table" in e.value.where


@pytest.mark.parametrize(
    "doc, where, reason",
    [
        ({"up_axis": "X"}, "up_axis", "\"Y\" or \"Z\""),
        ({"meters_per_unit": -1}, "meters_per_unit", "positive"),
        ({"meters_per_unit": "cm"}, "meters_per_unit", "positive"),
        ({"unit": 1}, "unit", "unknown sidecar field"),
        ({"categories": ["chair"]}, "categories", "mapping node names"),
        ({"categories": {"Chair_1": 3}}, "categories.Chair_1", "category name"),
        ({"categories": {"Sofa_9": "sofa"}}, "categories.Sofa_9", "no node or mesh named"),
        ({"structural": "Floor"}, "structural", "list of node names"),
        ({"rooms": [{"id": "r", "label": "kitchen", "polygon": [[0, 0], [1, 0], [2, 0]]}]}, "rooms[0].polygon", "zero area"),
        ({"rooms": [{"id": "r", "polygon": [[0, 0], [1, 0]]}]}, "rooms[0].polygon", "2 distinct points"),
        ({"rooms": [{"id": "r", "polygon": [[0, 0], [1, "a"], [1, 1]]}]}, "rooms[0].polygon", "number pairs"),
        ({"rooms": [{"id": "r", "polygon": [[0, 0], [1, 0], [1, 1]]}, {"id": "r", "polygon": [[0, 0], [1, 0], [1, 1]]}]},
         "rooms[1].id", "duplicate"),
    ],
)
def test_bad_sidecar(tmp_path, doc, where, reason):
    p = _write_scene(_y_up_scene(), tmp_path / "room.glb")
    side = sidecar_path(p)
    side.write_text(json.dumps(doc))
    with pytest.raises(SceneError) as e:
        load_mesh_scene(p)
    assert e.value.path == str(side) and e.value.where == where and reason in e.value.reason


def test_sidecar_not_json(tmp_path):
    p = _write_scene(_y_up_scene(), tmp_path / "room.glb")
    side = sidecar_path(p)
    side.write_text("{\n  'up_axis': 'Z'\n}")
    with pytest.raises(SceneError, match="invalid JSON") as e:
        load_mesh_scene(p)
    assert e.value.path == str(side) and e.value.where.startswith("line 2")
    with pytest.raises(SceneError, match="not found"):
        read_sidecar(tmp_path / "missing.json")
