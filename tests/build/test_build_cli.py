"""``python -m ignjax.build scenes`` and ``inspect`` run as a user runs them (subprocesses).

Generated houses are checked against the USD stage read with pxr directly,
third-party sources (../shared/data) against their own files, and bad input
must give exit status 2, one ``error:`` line naming the file, and no output.
"""

from __future__ import annotations

import collections
import hashlib
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

SUMMARY_KEYS = {"source", "up_axis", "meters_per_unit", "rooms", "instances"}


def run_build(*args, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "ignjax.build", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)


def inspect_json(path) -> dict:
    """``inspect PATH --json``: exit 0 and exactly one JSON object on stdout."""
    proc = run_build("inspect", path, "--json")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == 1, f"expected one line on stdout, got {len(lines)}"
    doc = json.loads(lines[0])
    assert isinstance(doc, dict)
    assert SUMMARY_KEYS <= set(doc)
    for r in doc["rooms"]:
        assert set(r) == {"id", "label"} and isinstance(r["id"], str) and isinstance(r["label"], str)
    for i in doc["instances"]:
        assert {"id", "category", "room", "position", "center", "size", "yaw"} <= set(i)
        assert isinstance(i["id"], str) and isinstance(i["category"], str)
        assert i["room"] is None or isinstance(i["room"], str)
        for key in ("position", "center", "size"):
            assert len(i[key]) == 3 and all(isinstance(v, float) and math.isfinite(v) for v in i[key]), (key, i)
        assert all(v >= 0 for v in i["size"]) and isinstance(i["yaw"], float) and math.isfinite(i["yaw"])
    return doc


def assert_one_line_error(proc: subprocess.CompletedProcess, *names: str) -> str:
    """Exit status 2, nothing on stdout, one ``error:`` line naming every given name, no traceback."""
    assert proc.returncode == 2, (proc.returncode, proc.stdout, proc.stderr)
    assert proc.stdout == ""
    assert "Traceback" not in proc.stderr
    errors = [line for line in proc.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1, proc.stderr
    for name in names:
        assert name in errors[0], (name, errors[0])
    return errors[0]


def listing(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else b"<dir>") for p in sorted(folder.rglob("*"))}


# ---------------------------------------------------------------------------
# scenes + inspect on generated houses
# ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def seed7(tmp_path_factory) -> dict:
    root = tmp_path_factory.mktemp("build_cli")
    out = root / "a"
    proc = run_build("scenes", "--out", out, "--count", 2, "--seed", 7, "--quiet")
    assert proc.returncode == 0, proc.stderr
    manifest = json.loads((out / "manifest.json").read_text())
    return {"root": root, "out": out, "proc": proc, "manifest": manifest,
            "houses": [out / e["file"] for e in manifest["scenes"]]}


def test_scenes_writes_houses_and_manifest(seed7):
    out, manifest = seed7["out"], seed7["manifest"]
    entries = manifest["scenes"]
    assert len(entries) == 2
    assert manifest["generator"]["seed"] == 7 and manifest["generator"]["count"] == 2
    on_disk = sorted(p.name for p in out.iterdir())
    assert on_disk == sorted(["manifest.json"] + [e["file"] for e in entries])
    for e in entries:
        f = out / e["file"]
        assert f.suffix == ".usda" and f.stat().st_size > 0
        assert e["sha256"] == hashlib.sha256(f.read_bytes()).hexdigest()
    assert f"wrote 2 houses ({sum(e['rooms'] for e in entries)} rooms" in seed7["proc"].stdout


def _stage_contents(path: Path):
    """Rooms and non-structural instances of an exported stage, read with pxr alone."""
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(path))
    cache = UsdGeom.XformCache()
    rooms, insts = [], []
    for prim in stage.Traverse():
        kind = prim.GetAttribute("ignjax:kind").Get() if prim.HasAttribute("ignjax:kind") else None
        labels = prim.GetAttribute("semantics:labels:class").Get() if prim.HasAttribute("semantics:labels:class") else None
        if prim.GetParent().GetName() == "Rooms":
            rooms.append((prim.GetName(), labels[0]))
        elif kind == "instance" and not prim.GetAttribute("ignjax:structural").Get():
            t = cache.GetLocalToWorldTransform(prim).ExtractTranslation()
            insts.append((prim.GetName(), labels[0], (t[0], t[1], t[2])))
    return stage, rooms, insts


def test_inspect_json_of_generated_houses(seed7):
    from pxr import UsdGeom

    by_file = {e["file"]: e for e in seed7["manifest"]["scenes"]}
    for house in seed7["houses"]:
        doc = inspect_json(house)
        assert Path(doc["source"]).name == house.name
        # the summary the issue asks for: a multi-room house with many, repeated categories
        cats = collections.Counter(i["category"] for i in doc["instances"])
        assert len(doc["rooms"]) >= 2
        assert len(doc["instances"]) >= 20
        assert len(cats) >= 10
        assert max(cats.values()) >= 3, cats
        room_ids = [r["id"] for r in doc["rooms"]]
        assert len(set(room_ids)) == len(room_ids)
        assert len({i["id"] for i in doc["instances"]}) == len(doc["instances"])
        assert all(i["room"] in room_ids for i in doc["instances"])
        # against the stage itself, read with pxr: units, rooms, instance ids, labels, world positions
        stage, rooms, insts = _stage_contents(house)
        assert doc["up_axis"] == UsdGeom.GetStageUpAxis(stage) == "Z"
        assert doc["meters_per_unit"] == UsdGeom.GetStageMetersPerUnit(stage) == 1.0
        assert [(r["id"], r["label"]) for r in doc["rooms"]] == rooms
        assert sorted((i["id"], i["category"]) for i in doc["instances"]) == sorted((n, c) for n, c, _ in insts)
        where = {n: p for n, _, p in insts}
        for i in doc["instances"]:
            assert i["position"] == pytest.approx(where[i["id"]], abs=2e-6), i["id"]
        # and against the manifest written with it
        e = by_file[house.name]
        assert (e["rooms"], e["instances"], e["categories"]) == (len(doc["rooms"]), len(doc["instances"]), len(cats))
        assert e["room_labels"] == [r["label"] for r in doc["rooms"]]


def test_same_seed_same_bytes_other_seed_other_houses(seed7):
    again = seed7["root"] / "b"
    proc = run_build("scenes", "--out", again, "--count", 2, "--seed", 7, "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert listing(again) == listing(seed7["out"])
    other = seed7["root"] / "c"
    proc = run_build("scenes", "--out", other, "--count", 1, "--seed", 8, "--quiet", "--no-check")
    assert proc.returncode == 0, proc.stderr
    (entry,) = json.loads((other / "manifest.json").read_text())["scenes"]
    first = inspect_json(seed7["houses"][0])
    mine = inspect_json(other / entry["file"])
    assert [(i["category"], i["position"]) for i in mine["instances"]] != \
        [(i["category"], i["position"]) for i in first["instances"]]


# ---------------------------------------------------------------------------
# inspect on third-party data
# ---------------------------------------------------------------------------


@pytest.fixture()
def stage_config(shared_data) -> Path:
    folder = shared_data / "usd-stage-config"
    if not folder.is_dir():
        pytest.skip(f"{folder} is absent")
    return folder


@pytest.fixture()
def procthor_houses(shared_data) -> Path:
    folder = shared_data / "procthor" / "houses"
    if not folder.is_dir():
        pytest.skip(f"{folder} is absent")
    return folder


GEOMETRY_STAGES = ["metersPerUnit_1.usda", "metersPerUnit_10.usda", "metersPerUnit_mix.usda",
                   "multiple_root_prims_no_defaultPrim.usda", "multiple_root_prims_with_defaultPrim.usda",
                   "invalid_defaultPrim.usda"]


@pytest.mark.shared
@pytest.mark.parametrize("name", GEOMETRY_STAGES)
def test_inspect_json_usd_stage_config(stage_config, name):
    from pxr import Usd, UsdGeom

    path = stage_config / name
    doc = inspect_json(path)  # the importer's warnings (missing sublayer, bad defaultPrim) must stay off stdout
    assert doc["source"] == str(path)
    stage = Usd.Stage.Open(str(path))
    assert doc["up_axis"] == UsdGeom.GetStageUpAxis(stage)
    assert doc["meters_per_unit"] == UsdGeom.GetStageMetersPerUnit(stage)
    gprims = sorted(p.GetName() for p in stage.Traverse() if p.IsA(UsdGeom.Gprim))
    assert gprims and sorted(i["id"] for i in doc["instances"]) == gprims
    assert len(doc["rooms"]) == 1  # no floor plan in these stages: one room covering everything
    assert all(i["room"] == doc["rooms"][0]["id"] for i in doc["instances"])


@pytest.mark.shared
@pytest.mark.parametrize("name,reason", [("upAxis_X.usda", "upAxis"), ("upAxis_invalid.usda", "upAxis"),
                                         ("upAxis_Y.usda", "no geometry"), ("upAxis_Z.usda", "no geometry")])
def test_inspect_refuses_unusable_usd_stages(stage_config, name, reason):
    path = stage_config / name
    line = assert_one_line_error(run_build("inspect", path, "--json"), str(path))
    assert reason in line


def _point_in_polygon(x: float, y: float, poly: list[tuple[float, float]]) -> bool:
    inside = False
    for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]):
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def _snake(name: str) -> str:
    return re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", name).lower()


@pytest.mark.shared
@pytest.mark.parametrize("name", ["train_4", "house2"])
def test_inspect_json_procthor_house(shared_data, procthor_houses, name):
    from ignjax.scenes import vocab

    path = procthor_houses / f"{name}.json"
    raw = json.loads(path.read_text())
    db = json.loads((shared_data / "procthor" / "asset-database.json").read_text())
    object_type = {a["assetId"]: t for t, assets in db.items() for a in assets}
    size = {a["assetId"]: a["boundingBox"] for assets in db.values() for a in assets}

    def walk(objs):
        for o in objs:
            yield o
            yield from walk(o.get("children") or [])

    objects = list(walk(raw["objects"]))
    doc = inspect_json(path)
    assert doc["source"] == str(path)
    assert (doc["up_axis"], doc["meters_per_unit"]) == ("Y", 1.0)
    assert [(r["id"], r["label"]) for r in doc["rooms"]] == [(r["id"], _snake(r["roomType"])) for r in raw["rooms"]]
    # every object of the file, children included, and nothing else; categories from the asset database
    expected = {o["id"]: vocab.normalize_category(object_type[o["assetId"]]) for o in objects}
    expected = {k: c for k, c in expected.items() if not vocab.is_structural(c)}
    got = {i["id"]: i for i in doc["instances"]}
    assert len(got) == len(doc["instances"]) == len(expected) > 20
    assert {k: i["category"] for k, i in got.items()} == expected
    polys = {r["id"]: [(p["x"], p["z"]) for p in r["floorPolygon"]] for r in raw["rooms"]}
    checked = 0
    for o in objects:
        i = got[o["id"]]
        u = o["position"]
        # Unity (x, y, z) -> ours (x, z, y); the position is the footprint centre at the object's lowest point
        assert i["position"][:2] == pytest.approx([u["x"], u["z"]], abs=1e-5), o["id"]
        rot = o.get("rotation") or {}
        if abs(rot.get("x", 0.0)) < 1e-9 and abs(rot.get("z", 0.0)) < 1e-9:
            assert i["position"][2] == pytest.approx(u["y"] - size[o["assetId"]]["y"] / 2, abs=1e-5), o["id"]
        inside = [rid for rid, poly in polys.items() if _point_in_polygon(u["x"], u["z"], poly)]
        if len(inside) == 1:
            assert i["room"] == inside[0], o["id"]
            checked += 1
    assert checked > len(objects) // 2


# ---------------------------------------------------------------------------
# inspect on stages written here: the box in the JSON, USD's messages
# ---------------------------------------------------------------------------


def _tilted_box_stage(path: Path) -> Path:
    from pxr import Gf, Usd, UsdGeom

    st = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(st, "Z")
    UsdGeom.SetStageMetersPerUnit(st, 0.01)  # centimetres: the JSON is in metres
    st.SetDefaultPrim(UsdGeom.Xform.Define(st, "/World").GetPrim())
    x = UsdGeom.Xform.Define(st, "/World/Desk")
    x.AddTranslateOp().Set(Gf.Vec3d(300.0, 400.0, 25.0))
    x.AddRotateZOp().Set(30.0)
    c = UsdGeom.Cube.Define(st, "/World/Desk/Top")
    c.CreateSizeAttr(1.0)
    c.AddScaleOp().Set(Gf.Vec3f(200.0, 100.0, 50.0))
    c2 = UsdGeom.Cube.Define(st, "/World/Stool")
    c2.CreateSizeAttr(40.0)
    c2.AddTranslateOp().Set(Gf.Vec3d(-100.0, 0.0, 20.0))
    st.Save()
    return path


def test_inspect_json_gives_the_box_center_and_size(tmp_path):
    doc = inspect_json(_tilted_box_stage(tmp_path / "desk.usda"))
    got = {i["id"]: i for i in doc["instances"]}
    desk, stool = got["Desk"], got["Stool"]
    assert desk["center"] == pytest.approx([3.0, 4.0, 0.25], abs=1e-6)
    assert desk["size"] == pytest.approx([2.0, 1.0, 0.5], abs=1e-6)  # along the box's own x and y, then height
    assert desk["yaw"] == pytest.approx(math.radians(30.0), abs=1e-6)
    assert desk["position"] == pytest.approx([3.0, 4.0, 0.0], abs=1e-6)  # the bottom centre of the box
    assert stool["center"] == pytest.approx([-1.0, 0.0, 0.2], abs=1e-6)
    assert stool["size"] == pytest.approx([0.4, 0.4, 0.4], abs=1e-6)
    assert stool["position"] == pytest.approx([-1.0, 0.0, 0.0], abs=1e-6)


_USD_INTERNALS = ("pxr", "Tf", "Traceback", "Error in", ".cpp", "_ReportErrors")


@pytest.mark.parametrize("kind,reason", [("empty", "empty file"), ("garbage", "not a readable USD file"),
                                         ("sublayer", "1 asset reference could not be resolved")])
def test_inspect_usd_errors_are_one_line_without_internals(tmp_path, kind, reason):
    p = {"empty": tmp_path / "empty.usda", "garbage": tmp_path / "garbage.usda", "sublayer": tmp_path / "shell.usd"}[kind]
    p.write_text({"empty": "", "garbage": "this is not a USD layer\n" * 40,
                  "sublayer": "#usda 1.0\n(\n    subLayers = [@./missing_layer.usda@]\n)\n"}[kind])
    proc = run_build("inspect", p, "--json")
    line = assert_one_line_error(proc, str(p))
    assert reason in line and len(line) < len(str(p)) + 220, line
    assert not any(bad in proc.stderr for bad in _USD_INTERNALS), proc.stderr


def stage_with_unresolved_assets(path, references: int):
    """A stage of one cube (``Stool``) with an unresolved sublayer and
    ``references`` lamps referencing files that do not exist (its import
    warns about each)."""
    from pxr import Gf, Usd, UsdGeom

    st = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(st, "Z")
    st.SetDefaultPrim(UsdGeom.Xform.Define(st, "/World").GetPrim())
    st.GetRootLayer().subLayerPaths.append("./gone_layer.usda")
    UsdGeom.Cube.Define(st, "/World/Stool").AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, 1.0))
    for k in range(references):
        UsdGeom.Xform.Define(st, f"/World/Lamp_{k}").GetPrim().GetReferences().AddReference(f"./gone_{k}.mtlx")
    st.Save()
    return path


def test_inspect_summarizes_unresolved_assets_in_one_line(tmp_path):
    path = stage_with_unresolved_assets(tmp_path / "busy.usda", 6)
    proc = run_build("inspect", path, "--json")
    assert proc.returncode == 0, proc.stderr
    assert [i["id"] for i in json.loads(proc.stdout)["instances"]] == ["Stool"]
    lines = [ln for ln in proc.stderr.splitlines() if "could not be resolved" in ln]
    assert len(lines) == 1 and "7 asset references could not be resolved" in lines[0], proc.stderr
    assert not any(bad in proc.stderr for bad in _USD_INTERNALS), proc.stderr
    assert "gone_5.mtlx" not in proc.stderr  # past the examples: counted, not listed


# ---------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------


def _make_bad(folder: Path, kind: str) -> Path:
    if kind == "missing":
        return folder / "no_such_house.usda"
    if kind == "text":
        p = folder / "notes.txt"
        p.write_text("a shopping list\n")
    elif kind == "garbage_usda":
        p = folder / "broken.usda"
        p.write_text("this is not a USD layer\n")
    elif kind == "garbage_glb":
        p = folder / "broken.glb"
        p.write_bytes(bytes(range(256)))
    elif kind == "json_not_a_house":
        p = folder / "config.json"
        p.write_text('{"learning_rate": 0.1}\n')
    elif kind == "empty_folder":
        p = folder / "nothing_here"
        p.mkdir()
    return p


BAD_KINDS = ["missing", "text", "garbage_usda", "garbage_glb", "json_not_a_house", "empty_folder"]


@pytest.mark.parametrize("kind", BAD_KINDS)
def test_inspect_bad_input(tmp_path, kind):
    bad = _make_bad(tmp_path, kind)
    before = listing(tmp_path)
    assert_one_line_error(run_build("inspect", bad, "--json"), str(bad))
    assert listing(tmp_path) == before


@pytest.mark.parametrize("kind", ["missing", "text", "garbage_usda"])
def test_episodes_build_bad_scene_source_writes_nothing(tmp_path, kind):
    bad = _make_bad(tmp_path, kind)
    before = listing(tmp_path)
    out = tmp_path / "bench" / "e.jsonl.gz"
    assert_one_line_error(run_build("episodes", "--scenes", bad, "--out", out, "--quiet"), str(bad))
    assert listing(tmp_path) == before  # not even the output folder


def test_episodes_build_repeated_scene_ids_writes_nothing(seed7, tmp_path):
    out = tmp_path / "bench" / "e.jsonl.gz"
    proc = run_build("episodes", "--scenes", seed7["out"], seed7["houses"][0], "--out", out, "--quiet")
    line = assert_one_line_error(proc, "repeated", seed7["houses"][0].stem)
    assert "unique" in line
    assert list(tmp_path.iterdir()) == []


def test_scenes_bad_out_and_count_write_nothing(tmp_path):
    not_a_folder = tmp_path / "houses"
    not_a_folder.write_text("keep me\n")
    assert_one_line_error(run_build("scenes", "--out", not_a_folder, "--count", 1, "--quiet"), str(not_a_folder))
    assert not_a_folder.read_text() == "keep me\n"
    fresh = tmp_path / "fresh"
    assert_one_line_error(run_build("scenes", "--out", fresh, "--count", -1, "--quiet"), "count")
    assert_one_line_error(run_build("scenes", "--out", fresh, "--min-rooms", 6, "--max-rooms", 2, "--quiet"), "min_rooms")
    assert not fresh.exists()
