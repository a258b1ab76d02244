"""ProcTHOR import: asset table, frame conversion, both house schemas, errors.

Small houses are written by the tests themselves (Unity coordinates, both
schemas) so that every expected room, wall, door and object pose is known
exactly; the two shared houses check the importer on real data.
"""

from __future__ import annotations

import gzip
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ignjax.errors import SceneError
from ignjax.scenes.io import sources as scene_io
from ignjax.scenes.model import scene_to_json
from ignjax.scenes.io.procthor import house_to_scene, load_procthor, unity_to_world, unity_yaw
from ignjax.scenes.io.procthor_assets import DEFAULT_ASSET_TABLE, AssetInfo, derive_asset_table, load_asset_table, main

ROOT = Path(__file__).resolve().parents[2]

# Hand-made assets with round sizes (Unity x, y = height, z = forward).
ASSETS = {
    "TestTable": AssetInfo("DiningTable", (2.0, 0.8, 1.0)),
    "TestLaptop": AssetInfo("Laptop", (0.4, 0.3, 0.3)),
    "TestChair": AssetInfo("Chair", (0.5, 1.0, 0.6)),
    "TestBat": AssetInfo("BaseballBat", (0.1, 1.0, 0.1)),
    "TestLamp": AssetInfo("DeskLamp", (0.2, 0.5, 0.2)),
    "TestWindow": AssetInfo("Window", (1.0, 1.0, 0.2)),
    "Doorway_1": AssetInfo("Doorway", (1.0, 2.0, 0.2)),
    "Doorframe_1": AssetInfo("Doorframe", (1.0, 2.0, 0.2)),
}

H = 2.5  # wall height of the hand-made houses


def _wall(wid, room, a, b, exterior=False, schema="1.0.0"):
    (x0, z0), (x1, z1) = a, b
    if exterior:
        poly = [(x0, H, z0), (x1, H, z1), (x0, 0, z0), (x1, 0, z1)]
        room_id = "exterior" if schema == "1.0.0" else room
    else:
        poly = [(x0, 0, z0), (x1, 0, z1), (x0, H, z0), (x1, H, z1)]
        room_id = room
    w = {"id": wid, "roomId": room_id, "polygon": [{"x": x, "y": y, "z": z} for x, y, z in poly]}
    w["material"] = {"name": "PureWhite"} if schema == "1.0.0" else "PureWhite"
    return w


def _hole(schema, x0, x1, y0, y1):
    if schema == "1.0.0":
        return {"holePolygon": [{"x": x0, "y": y0, "z": 0}, {"x": x1, "y": y1, "z": 0}],
                "assetPosition": {"x": 0.5 * (x0 + x1), "y": 0.5 * (y0 + y1), "z": 0}}
    return {"boundingBox": {"min": {"x": x0, "y": y0, "z": 0}, "max": {"x": x1, "y": y1, "z": 0}},
            "assetOffset": {"x": -0.003, "y": 0.0, "z": 0.05}}


def make_house(schema="1.0.0", empty_shared_wall=False):
    """Living room [0,4]x[0,3] and bedroom [4,7]x[0,3] (Unity x, z).

    * door|1|2: 1 m doorway in the shared wall x=4 at z in [1, 2];
    * door|0|1: closed front door in the living room's z=0 wall, x in [2.5, 3.5];
    * door|0|2: open exterior doorframe in the bedroom's x=7 wall, z in [1, 2];
    * window|2|0: bedroom window in the z=3 wall, x in [5, 6], y in [1, 2];
    * a table turned 90 degrees with a laptop on it, a red chair facing -x,
      a bat lying on the floor, a lamp that is on.
    """
    ext = "wall|exterior"
    walls = [
        _wall("wall|1|a", "room|1", (0, 0), (0, 3), schema=schema),
        _wall("wall|1|b", "room|1", (0, 3), (4, 3), schema=schema),
        _wall("wall|1|c", "room|1", (4, 3), (4, 0), schema=schema),
        _wall("wall|1|d", "room|1", (4, 0), (0, 0), schema=schema),
        _wall("wall|2|c", "room|2", (4, 0), (4, 3), schema=schema),
        _wall("wall|2|e", "room|2", (4, 3), (7, 3), schema=schema),
        _wall("wall|2|f", "room|2", (7, 3), (7, 0), schema=schema),
        _wall("wall|2|g", "room|2", (7, 0), (4, 0), schema=schema),
        _wall(f"{ext}|a", "room|1", (0, 3), (0, 0), exterior=True, schema=schema),
        _wall(f"{ext}|b", "room|1", (4, 3), (0, 3), exterior=True, schema=schema),
        _wall(f"{ext}|d", "room|1", (0, 0), (4, 0), exterior=True, schema=schema),
        _wall(f"{ext}|e", "room|2", (7, 3), (4, 3), exterior=True, schema=schema),
        _wall(f"{ext}|f", "room|2", (7, 0), (7, 3), exterior=True, schema=schema),
        _wall(f"{ext}|g", "room|2", (4, 0), (7, 0), exterior=True, schema=schema),
    ]
    if empty_shared_wall:
        for w in walls:
            if w["id"] in ("wall|1|c", "wall|2|c"):
                w["empty"] = True
    doors = [] if empty_shared_wall else [
        {"id": "door|1|2", "assetId": "Doorway_1", "openable": True, "openness": 1, "room0": "room|1",
         "room1": "room|2", "wall0": "wall|1|c", "wall1": "wall|2|c", **_hole(schema, 1.0, 2.0, 0.0, 2.0)},
    ]
    doors += [
        {"id": "door|0|1", "assetId": "Doorway_1", "openable": False, "openness": 0, "room0": "room|1",
         "room1": "room|1", "wall0": "wall|1|d", "wall1": f"{ext}|d", **_hole(schema, 0.5, 1.5, 0.0, 2.0)},
        {"id": "door|0|2", "assetId": "Doorframe_1", "openable": True, "openness": 1, "room0": "room|2",
         "room1": "room|2", "wall0": "wall|2|f", "wall1": f"{ext}|f", **_hole(schema, 1.0, 2.0, 0.0, 2.0)},
    ]
    windows = [{"id": "window|2|0", "assetId": "TestWindow", "room0": "room|2", "room1": "room|2",
                "wall0": "wall|2|e", "wall1": f"{ext}|e", **_hole(schema, 1.0, 2.0, 1.0, 2.0)}]
    floor_mat = {"name": "WornWood"} if schema == "1.0.0" else "WornWood"
    rooms = [
        {"id": "room|1", "roomType": "LivingRoom", "floorMaterial": floor_mat, "children": [], "ceilings": [],
         "floorPolygon": [{"x": x, "y": 0, "z": z} for x, z in [(0, 0), (0, 3), (4, 3), (4, 0)]]},
        {"id": "room|2", "roomType": "Bedroom", "floorMaterial": floor_mat, "children": [], "ceilings": [],
         "floorPolygon": [{"x": x, "y": 0, "z": z} for x, z in [(4, 0), (4, 3), (7, 3), (7, 0)]]},
    ]
    objects = [
        {"id": "DiningTable|1|0", "assetId": "TestTable", "kinematic": True,
         "position": {"x": 2.0, "y": 0.4, "z": 1.5}, "rotation": {"x": 0, "y": 90, "z": 0},
         "children": [
             {"id": "Laptop|1|1", "assetId": "TestLaptop", "openness": 1,
              "position": {"x": 2.0, "y": 0.95, "z": 1.5}, "rotation": {"x": 0, "y": 0, "z": 0}},
         ]},
        {"id": "Chair|2|0", "assetId": "TestChair", "position": {"x": 5.0, "y": 0.5, "z": 1.0},
         "rotation": {"x": 0, "y": 270, "z": 0}, "color": {"r": 0.8, "g": 0.1, "b": 0.1},
         "material": {"name": "DarkWoodSmooth"} if schema == "1.0.0" else "DarkWoodSmooth"},
        {"id": "BaseballBat|1|2", "assetId": "TestBat", "position": {"x": 1.0, "y": 0.05, "z": 2.5},
         "rotation": {"x": 0, "y": 0, "z": 90}},
        {"id": "DeskLamp|2|1", "assetId": "TestLamp", "isOn": True, "position": {"x": 6.5, "y": 0.25, "z": 2.5},
         "rotation": {"x": 0, "y": 180, "z": 0}},
    ]
    return {"metadata": {"schema": schema}, "rooms": rooms, "walls": walls, "doors": doors, "windows": windows,
            "objects": objects, "proceduralParameters": {}}


def _write(path: Path, doc) -> Path:
    path.write_text(json.dumps(doc))
    return path


def _scene(house, **kw):
    return house_to_scene(house, source="test.json", scene_id="test", assets=ASSETS, **kw)


def _close(a, b, tol=1e-9):
    return np.allclose(np.asarray(a, dtype=float), np.asarray(b, dtype=float), atol=tol)


# ---------------------------------------------------------------------------
# Frame conversion
# ---------------------------------------------------------------------------


def test_unity_point_and_yaw_conversion():
    assert _close(unity_to_world([1.0, 2.0, 3.0]), [1.0, 3.0, 2.0])
    # Forward (+z_u) of an asset at rotation.y = t points along (sin t, cos t) in our xy.
    for t in (0.0, 30.0, 90.0, 180.0, 270.0, -45.0):
        yaw = unity_yaw(t)
        assert _close([math.cos(yaw), math.sin(yaw)], [math.sin(math.radians(t)), math.cos(math.radians(t))])
        assert -math.pi < yaw <= math.pi


def test_box_long_along_unity_x_turned_90_is_long_along_our_y():
    house = make_house()
    house["objects"] = [{"id": "T", "assetId": "TestTable", "position": {"x": 2.0, "y": 0.4, "z": 1.5},
                         "rotation": {"x": 0, "y": 90, "z": 0}}]
    t = _scene(house).instance("T")
    corners = t.bbox.footprint()
    extent = corners.max(0) - corners.min(0)
    assert _close(extent, [1.0, 2.0])  # 2 m Unity-x edge now along our y
    # And unturned it stays along our x.
    house["objects"][0]["rotation"]["y"] = 0
    corners = _scene(house).instance("T").bbox.footprint()
    assert _close(corners.max(0) - corners.min(0), [2.0, 1.0])


# ---------------------------------------------------------------------------
# Hand-made houses, both schemas
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("schema", ["1.0.0", "0.0.1"])
def test_hand_house_rooms_walls_doors(schema):
    s = _scene(make_house(schema))
    assert [(r.id, r.label, r.name) for r in s.rooms] == [("room|1", "living_room", "LivingRoom"),
                                                         ("room|2", "bedroom", "Bedroom")]
    assert set(s.rooms[0].polygon) == {(0, 0), (0, 3), (4, 3), (4, 0)}
    assert s.rooms[0].area == pytest.approx(12.0)
    assert s.meta.source_format == "procthor" and s.meta.up_axis == "Y"
    assert json.loads(s.meta.params)["schema"] == schema
    assert s.wall_height == pytest.approx(H)

    doors = {d.id: d for d in s.doors}
    assert set(doors) == {"door|1|2", "door|0|2"}  # the closed front door is not an opening
    d = doors["door|1|2"]
    assert _close(d.position, (4.0, 1.5)) and d.width == pytest.approx(1.0) and d.height == pytest.approx(2.0)
    assert d.rooms == ("room|1", "room|2") and d.kind == "door"
    assert math.isclose(abs(math.cos(d.yaw)), 0.0, abs_tol=1e-9)  # the wall runs along y
    e = doors["door|0|2"]
    assert _close(e.position, (7.0, 1.5)) and e.rooms == ("room|2", None) and e.kind == "opening"

    walls = {w.id: w for w in s.walls}
    # 7 distinct segments (copies per side and exterior copies merged); two are cut by doors.
    assert set(walls) == {"wall|1|a", "wall|1|b", "wall|1|d", "wall|2|e", "wall|2|g",
                          "wall|1|c#0", "wall|1|c#1", "wall|1|c#2", "wall|2|f#0", "wall|2|f#1", "wall|2|f#2"}
    assert walls["wall|1|c#0"].rooms == ("room|1", "room|2")
    assert walls["wall|1|a"].rooms == ("room|1",)
    assert _close(walls["wall|1|c#0"].start + walls["wall|1|c#0"].end, (4, 3, 4, 2))
    lintel = walls["wall|1|c#1"]
    assert _close(lintel.start + lintel.end, (4, 2, 4, 1))
    assert lintel.bottom == pytest.approx(2.0) and lintel.height == pytest.approx(0.5)
    assert _close(walls["wall|1|c#2"].start + walls["wall|1|c#2"].end, (4, 1, 4, 0))
    assert walls["wall|1|c#2"].bottom == 0 and walls["wall|1|c#2"].height == pytest.approx(H)
    assert all(w.thickness == pytest.approx(0.04) for w in s.walls)

    front = s.instance("door|0|1")
    assert front.structural and front.category == "door" and front.room == "room|1"
    assert _close(front.position, (3.0, 0.0, 0.0))
    win = s.instance("window|2|0")
    assert win.structural and win.category == "window" and win.room == "room|2"
    assert _close(win.bbox.center, (5.5, 3.0, 1.5))
    assert _close(win.bbox.half_extents, (0.1, 0.5, 0.5))
    assert math.isclose(win.yaw, -math.pi / 2)  # faces into the bedroom (-y)


@pytest.mark.parametrize("schema", ["1.0.0", "0.0.1"])
def test_hand_house_objects(schema):
    s = _scene(make_house(schema))
    assert [i.id for i in s.objects] == ["DiningTable|1|0", "Laptop|1|1", "Chair|2|0", "BaseballBat|1|2",
                                         "DeskLamp|2|1"]
    table = s.instance("DiningTable|1|0")
    assert table.category == "dining_table" and table.name == "TestTable"
    assert _close(table.position, (2.0, 1.5, 0.0))
    assert math.isclose(table.yaw, 0.0, abs_tol=1e-12)
    assert _close(table.bbox.center, (2.0, 1.5, 0.4)) and _close(table.bbox.half_extents, (0.5, 1.0, 0.4))
    assert table.room == "room|1" and table.support is None
    assert len(table.geoms) == 1 and table.geoms[0].kind == "box"
    assert _close(table.geoms[0].size, (0.5, 1.0, 0.4)) and _close(table.geoms[0].pos, (0, 0, 0.4))

    laptop = s.instance("Laptop|1|1")
    assert laptop.support == "DiningTable|1|0" and laptop.room == "room|1"
    assert _close(laptop.position, (2.0, 1.5, 0.8))
    assert math.isclose(laptop.yaw, math.pi / 2)
    assert laptop.attributes.state == "open"

    chair = s.instance("Chair|2|0")
    assert chair.room == "room|2" and _close(chair.position, (5.0, 1.0, 0.0))
    assert math.isclose(abs(chair.yaw), math.pi)  # rotation.y = 270 faces -x
    assert _close(chair.bbox.half_extents, (0.3, 0.25, 0.5))
    assert chair.attributes.color == "red" and chair.attributes.material == "wood"
    assert chair.attributes.size is None and chair.attributes.state is None
    assert _close(chair.geoms[0].rgba, (0.8, 0.1, 0.1, 1.0))

    bat = s.instance("BaseballBat|1|2")  # lying: its 1 m Unity-y edge now along our x
    assert _close(bat.position, (1.0, 2.5, 0.0)) and _close(bat.bbox.half_extents, (0.05, 0.5, 0.05))
    assert bat.attributes == table.attributes.__class__()  # nothing in the JSON, nothing guessed

    lamp = s.instance("DeskLamp|2|1")
    assert lamp.category == "table_lamp" and lamp.attributes.state == "on"
    assert math.isclose(lamp.yaw, -math.pi / 2)

    # Default colours are per category, stable, and differ between categories.
    assert table.geoms[0].rgba == _scene(make_house(schema)).instance("DiningTable|1|0").geoms[0].rgba
    assert table.geoms[0].rgba != laptop.geoms[0].rgba


def test_both_schemas_give_the_same_building():
    a, b = _scene(make_house("1.0.0")), _scene(make_house("0.0.1"))
    assert a.rooms == b.rooms and a.walls == b.walls and a.doors == b.doors
    assert [(i.id, i.position, i.bbox) for i in a.instances] == [(i.id, i.position, i.bbox) for i in b.instances]


def test_empty_wall_becomes_an_opening():
    s = _scene(make_house(empty_shared_wall=True))
    op = [d for d in s.doors if d.kind == "opening" and d.rooms == ("room|1", "room|2")]
    assert len(op) == 1
    assert _close(op[0].position, (4.0, 1.5)) and op[0].width == pytest.approx(3.0)
    assert not any(w.id.startswith("wall|1|c") for w in s.walls)


def test_load_file_and_io_dispatch(tmp_path):
    p = _write(tmp_path / "my_house.json", make_house())
    [s] = load_procthor(p, assets=ASSETS)
    assert s.id == "my_house" and s.meta.source == str(p)
    # Deterministic: the same file gives the same scene, byte for byte.
    assert scene_to_json(s) == scene_to_json(load_procthor(p, assets=ASSETS)[0])
    # The generic reader dispatches ProcTHOR JSON here (shipped asset table: unknown test assets fail).
    with pytest.raises(SceneError, match=r"objects\[0\]\.assetId"):
        scene_io.load_scenes(p)


def test_jsonl_and_gz(tmp_path):
    h = make_house()
    lines = [json.dumps(h), "", json.dumps(make_house("0.0.1"))]
    p = tmp_path / "houses.jsonl"
    p.write_text("\n".join(lines) + "\n")
    scenes = load_procthor(p, assets=ASSETS)
    assert [s.id for s in scenes] == ["houses_0", "houses_2"]
    gz = tmp_path / "train.jsonl.gz"
    with gzip.open(gz, "wt") as f:
        f.write("\n".join(lines) + "\n")
    assert [s.id for s in load_procthor(gz, assets=ASSETS)] == ["train_0", "train_2"]
    # A JSON list of houses.
    lst = _write(tmp_path / "many.json", [h, h])
    assert [s.id for s in load_procthor(lst, assets=ASSETS)] == ["many_0", "many_1"]


# ---------------------------------------------------------------------------
# Bad input
# ---------------------------------------------------------------------------


def test_missing_file_and_not_json(tmp_path):
    with pytest.raises(SceneError, match="no such file") as e:
        load_procthor(tmp_path / "nope.json")
    assert "nope.json" in str(e.value)
    bad = tmp_path / "bad.json"
    bad.write_text('{"rooms": [\n  {"id": 1,,}\n]}')
    with pytest.raises(SceneError, match="invalid JSON") as e:
        load_procthor(bad)
    assert e.value.where.startswith("line 2")
    binary = tmp_path / "bin.json"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(SceneError):
        load_procthor(binary)


@pytest.mark.parametrize("rooms", [[], None])
def test_house_without_rooms(tmp_path, rooms):
    h = make_house()
    if rooms is None:
        del h["rooms"]
    else:
        h["rooms"] = rooms
    p = _write(tmp_path / "h.json", h)
    with pytest.raises(SceneError, match="no rooms") as e:
        load_procthor(p, assets=ASSETS)
    assert e.value.where == "rooms" and e.value.path == str(p)


def test_unknown_asset_names_object_index_and_id(tmp_path):
    h = make_house()
    h["objects"][1]["assetId"] = "Chair_999_nope"
    p = _write(tmp_path / "h.json", h)
    with pytest.raises(SceneError) as e:
        load_procthor(p, assets=ASSETS)
    assert e.value.where == "objects[1].assetId"
    assert "Chair_999_nope" in e.value.reason and "Chair|2|0" in e.value.reason
    h = make_house()
    h["objects"][0]["children"][0]["assetId"] = "Nope"
    with pytest.raises(SceneError) as e:
        _scene(h)
    assert e.value.where == "objects[0].children[0].assetId"


@pytest.mark.parametrize(
    "points, reason",
    [
        ([(0, 0), (4, 0)], "2 distinct points"),  # an open polyline, not a closed ring
        ([(0, 0), (4, 0), (0, 0)], "2 distinct points"),  # closes on itself with 2 points
        ([(0, 0), (2, 0), (4, 0)], "zero area"),
        ([(4, 0), (7, 3), (7, 0), (4, 2)], "self-intersecting"),
    ],
)
def test_bad_floor_polygons(points, reason):
    h = make_house()
    h["rooms"][1]["floorPolygon"] = [{"x": x, "y": 0, "z": z} for x, z in points]
    with pytest.raises(SceneError, match=reason) as e:
        _scene(h)
    assert e.value.where == "rooms[1].floorPolygon"


def test_explicitly_closed_floor_polygon_is_accepted():
    h = make_house()
    h["rooms"][0]["floorPolygon"].append(dict(h["rooms"][0]["floorPolygon"][0]))
    assert len(_scene(h).rooms[0].polygon) == 4


@pytest.mark.parametrize("value", [float("nan"), float("inf"), float("-inf")])
def test_non_finite_positions(tmp_path, value):
    h = make_house()
    h["objects"][2]["position"]["z"] = value
    p = tmp_path / "h.json"
    p.write_text(json.dumps(h))  # Python's json writes NaN / Infinity, and reads them back
    assert ("NaN" in p.read_text()) or ("Infinity" in p.read_text())
    with pytest.raises(SceneError, match="finite") as e:
        load_procthor(p, assets=ASSETS)
    assert e.value.where == "objects[2].position.z"


def test_non_finite_polygon_and_missing_coordinate():
    h = make_house()
    h["rooms"][0]["floorPolygon"][2]["x"] = float("nan")
    with pytest.raises(SceneError) as e:
        _scene(h)
    assert e.value.where == "rooms[0].floorPolygon[2].x"
    h = make_house()
    del h["objects"][0]["position"]["y"]
    with pytest.raises(SceneError, match="missing") as e:
        _scene(h)
    assert e.value.where == "objects[0].position.y"


def test_bad_door_references():
    h = make_house()
    h["doors"][0]["wall0"] = "wall|9|zz"
    with pytest.raises(SceneError, match="unknown wall") as e:
        _scene(h)
    assert e.value.where == "doors[0].wall0"
    h = make_house()
    h["doors"][0]["holePolygon"][1]["x"] = 7.5
    with pytest.raises(SceneError, match="extends past") as e:
        _scene(h)
    assert e.value.where == "doors[0]"


def test_malformed_jsonl_line(tmp_path):
    p = tmp_path / "h.jsonl"
    p.write_text(json.dumps(make_house()) + "\n" + '{"rooms": [' + "\n")
    with pytest.raises(SceneError, match="invalid JSON") as e:
        load_procthor(p, assets=ASSETS)
    assert e.value.where == "line 2"
    bad = make_house()
    bad["objects"][0]["assetId"] = "Nope"
    p.write_text(json.dumps(make_house()) + "\n" + json.dumps(bad) + "\n")
    with pytest.raises(SceneError) as e:
        load_procthor(p, assets=ASSETS)
    assert e.value.where == "line 2, objects[0].assetId"


# ---------------------------------------------------------------------------
# Shipped asset table
# ---------------------------------------------------------------------------


def test_shipped_asset_table_is_small_and_complete():
    assert DEFAULT_ASSET_TABLE.is_file() and DEFAULT_ASSET_TABLE.stat().st_size < 200_000
    table = load_asset_table()
    assert len(table) == 1653
    assert len({a.object_type for a in table.values()}) == 109
    fridge = table["Fridge_1"]
    assert fridge.object_type == "Fridge" and _close(fridge.size, (1.01300, 1.96681, 0.72421), 1e-5)


@pytest.mark.shared
def test_shipped_asset_table_equals_fresh_derivation(shared_data, tmp_path):
    db = shared_data / "procthor" / "asset-database.json"
    out = tmp_path / "assets.json.gz"
    doc = derive_asset_table(db, out)
    with gzip.open(DEFAULT_ASSET_TABLE, "rt") as f:
        shipped = json.load(f)
    assert shipped == doc
    assert out.read_bytes() == DEFAULT_ASSET_TABLE.read_bytes()  # reproducible bytes


@pytest.mark.shared
def test_derive_assets_command(shared_data, tmp_path, capsys):
    db = shared_data / "procthor" / "asset-database.json"
    out = tmp_path / "t.json.gz"
    assert main(["derive-assets", str(db), "--out", str(out)]) == 0
    assert "1653 assets of 109 object types" in capsys.readouterr().out
    assert load_asset_table(out)["Fridge_1"] == load_asset_table()["Fridge_1"]
    r = subprocess.run([sys.executable, "-m", "ignjax.scenes.io.procthor_assets", "derive-assets", "--help"],
                       capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 0 and "--out" in r.stdout
    r = subprocess.run([sys.executable, "-m", "ignjax.scenes.io.procthor_assets", "derive-assets", str(tmp_path / "x.json")],
                       capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 2 and "x.json" in r.stderr


# ---------------------------------------------------------------------------
# Shared houses
# ---------------------------------------------------------------------------


def _count_objects(objs):
    return sum(1 + _count_objects(o.get("children") or []) for o in objs)


@pytest.mark.shared
@pytest.mark.parametrize("name, schema", [("train_4", "1.0.0"), ("house2", "0.0.1")])
def test_shared_houses(shared_data, name, schema):
    path = shared_data / "procthor" / "houses" / f"{name}.json"
    raw = json.loads(path.read_text())
    assert raw["metadata"]["schema"] == schema
    [s] = load_procthor(path)
    assert s.id == name
    assert scene_to_json(scene_io.load_scene(path)) == scene_to_json(s)  # the generic reader dispatches here
    assert [(r.id, r.label) for r in s.rooms] == [("room|4", "bedroom"), ("room|5", "bathroom"),
                                                  ("room|6", "kitchen"), ("room|7", "living_room")]
    assert len(s.objects) == _count_objects(raw["objects"])
    assert [i.id for i in s.objects] == [i.id for i in s.instances if not i.structural]
    # Every object lies inside the house and has a room; floor objects stand on the floor.
    xs = [p["x"] for r in raw["rooms"] for p in r["floorPolygon"]]
    zs = [p["z"] for r in raw["rooms"] for p in r["floorPolygon"]]
    for inst in s.objects:
        assert inst.room is not None, inst.id
        x, y, z = inst.position
        assert min(xs) - 0.05 <= x <= max(xs) + 0.05 and min(zs) - 0.05 <= y <= max(zs) + 0.05, inst.id
        assert -0.01 <= z <= s.wall_height, inst.id
    top = {o["id"] for o in raw["objects"]}
    on_floor = [i for i in s.objects if i.id in top and i.category not in ("painting", "television", "baseball_bat")]
    assert on_floor and all(abs(i.position[2]) < 2e-3 for i in on_floor)
    # Support relations mirror the JSON nesting.
    for o in raw["objects"]:
        for ch in o.get("children") or []:
            assert s.instance(ch["id"]).support == o["id"]
    # Interior doors connect two rooms; all rooms are reachable through doors/openings.
    interior = [d for d in s.doors if d.rooms[1] is not None]
    assert len(interior) >= 2
    from ignjax.scenes.graph import rooms_unreachable_by_doors

    assert rooms_unreachable_by_doors(s) == []
    # Wall decorations face into their room.
    for inst in s.objects:
        if inst.category == "painting":
            front = np.array(inst.position[:2]) + 0.1 * np.array([math.cos(inst.yaw), math.sin(inst.yaw)])
            assert s.room_at(front) == inst.room, inst.id
