"""Categories and room labels from names (ignjax.scenes.io.names), the one
rule every importer uses: unit tests of the functions, then a USD stage and
a glTF scene named the same way, imported with the same categories.
"""

from __future__ import annotations

import pytest
import trimesh
from pxr import Gf, Usd, UsdGeom
from trimesh.exchange.gltf import export_glb
from trimesh.transformations import translation_matrix

from ignjax.scenes.io.meshes import load_mesh_scene
from ignjax.scenes.io.names import category_from_name, room_label_from_name
from ignjax.scenes.io.usd import load_usd

# ---------------------------------------------------------------------------
# category_from_name
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name,category", [
    # side suffixes: CamelCase capital after a lower-case letter, or after a separator
    ("BishopL", "bishop"), ("BishopR", "bishop"), ("Bishop_L", "bishop"), ("bishop.R", "bishop"),
    ("Bishop-l", "bishop"), ("bishop.L.001", "bishop"), ("PillowR_2", "pillow"),
    ("LampLeft", "table_lamp"), ("lamp_left", "table_lamp"), ("Lamp.RIGHT", "table_lamp"),
    # index suffixes: digits glued on or after a separator, Blender's .001
    ("light0", "light"), ("light3", "light"), ("Chair_01", "chair"), ("chair.002", "chair"),
    ("Table2", "dining_table"), ("Chairs", "chair"), ("/World/Chair_03", "chair"), ("Laptop_5.usd", "laptop"),
    # a final letter that is part of the word stays
    ("Bowl", "bowl"), ("Bell", "bell"), ("Chair", "chair"), ("Shelf", "shelf"), ("Mirror", "mirror"),
    ("BOWL", "bowl"), ("CHAIR", "chair"), ("Copyright", "copyright"), ("Upright", "upright"),
    # nothing left to strip to: kept as it is
    ("L", "l"), ("Left", "left"), ("001", "unknown"), ("", "unknown"), (None, "unknown"),
    # index letters are not side suffixes
    ("Chair_A", "chair_a"),
])
def test_category_from_name(name, category):
    assert category_from_name(name) == category


def test_names_of_one_object_family_share_a_category():
    families = [["BishopL", "BishopR", "Bishop_L", "bishop.r"], [f"light{k}" for k in range(4)],
                ["Chair_01", "chair.002", "Chair", "CHAIR_7"]]
    for names in families:
        assert len({category_from_name(n) for n in names}) == 1, names


# ---------------------------------------------------------------------------
# room_label_from_name
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name,label", [
    ("Kitchen", "kitchen"), ("Bedroom_2", "bedroom"), ("living_room", "living_room"), ("LivingRoom", "living_room"),
    ("Livingroom", "living_room"), ("Kitchen01", "kitchen"), ("Living_Room_02", "living_room"),
    ("Master_Bedroom", "bedroom"), ("powder_room", "bathroom"), ("Guest_Bedroom", "bedroom"), ("Foyer", "entryway"),
    ("Kitchen_Dining", "dining_room"), ("GameRoom", "other"), ("Room_3", "other"),
    # objects and parts that mention a room
    ("Lamp_Kitchen", None), ("Floor_Kitchen", None), ("Kitchen_Floor", None), ("KitchenIsland", None),
    ("LivingRoomSofa", None), ("Hallway_Light", None), ("Toilet", None), ("Office_Chair", None),
    # names that are no rooms at all
    ("World", None), ("Rooms", None), ("Mushroom", None), ("Broom", None), ("Looks", None), ("123", None), ("", None),
])
def test_room_label_from_name(name, label):
    assert room_label_from_name(name) == label


# ---------------------------------------------------------------------------
# The same names in a USD stage and in a glTF scene
# ---------------------------------------------------------------------------

NAMES = ["BishopL", "BishopR", "light0", "light1", "light2", "light3", "Chair_01", "chair.002", "Bowl", "Shelf"]
EXPECTED = {"bishop": 2, "light": 4, "chair": 2, "bowl": 1, "shelf": 1}


def _count(categories) -> dict[str, int]:
    out: dict[str, int] = {}
    for c in categories:
        out[c] = out.get(c, 0) + 1
    return out


def test_usd_prim_names_and_asset_stems_share_the_rule(tmp_path):
    # USD prim names cannot hold a dot: "chair.002" is the stem of a referenced asset
    asset = Usd.Stage.CreateNew(str(tmp_path / "chair.002.usda"))
    asset.SetDefaultPrim(UsdGeom.Xform.Define(asset, "/A").GetPrim())
    UsdGeom.Cube.Define(asset, "/A/Geo").CreateSizeAttr(0.5)
    asset.Save()
    st = Usd.Stage.CreateNew(str(tmp_path / "pieces.usda"))
    UsdGeom.SetStageUpAxis(st, "Z")
    UsdGeom.SetStageMetersPerUnit(st, 1.0)
    st.SetDefaultPrim(UsdGeom.Xform.Define(st, "/World").GetPrim())
    for k, name in enumerate(NAMES):
        x = UsdGeom.Xform.Define(st, f"/World/{name if '.' not in name else 'Xform_9'}")
        x.AddTranslateOp().Set(Gf.Vec3d(2.0 * k, 0.0, 0.25))
        if "." in name:
            x.GetPrim().GetReferences().AddReference("./chair.002.usda")
        else:
            UsdGeom.Cube.Define(st, x.GetPath().AppendChild("Geo")).CreateSizeAttr(0.5)
    st.Save()
    scene = load_usd(tmp_path / "pieces.usda")
    assert _count(i.category for i in scene.instances) == EXPECTED
    assert {i.id: i.category for i in scene.instances}["Xform_9"] == "chair"


@pytest.mark.parametrize("suffix", [".glb", ".obj"])
def test_mesh_node_names_share_the_rule(tmp_path, suffix):
    if suffix == ".glb":
        s = trimesh.Scene()
        for k, name in enumerate(NAMES):
            s.add_geometry(trimesh.creation.box((0.5, 0.5, 0.5)), node_name=name, geom_name=f"{name}_mesh",
                           transform=translation_matrix([2.0 * k, 0.25, 0.0]))
        path = tmp_path / "pieces.glb"
        path.write_bytes(export_glb(s))
    else:
        lines, offset = [], 1
        for k, name in enumerate(NAMES):
            box = trimesh.creation.box((0.5, 0.5, 0.5))
            box.apply_translation([2.0 * k, 0.25, 0.0])
            lines.append(f"o {name}")
            lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in box.vertices]
            lines += [f"f {a + offset} {b + offset} {c + offset}" for a, b, c in box.faces]
            offset += len(box.vertices)
        path = tmp_path / "pieces.obj"
        path.write_text("\n".join(lines) + "\n")
    scene = load_mesh_scene(path)
    assert sorted(i.id for i in scene.instances) == sorted(NAMES)
    assert _count(i.category for i in scene.instances) == EXPECTED
