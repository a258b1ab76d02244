"""Benchmark episodes: start rules, difficulty, balanced subset, determinism,
leak stripping, oracle-memory hints, loader validation and the episodes CLI.

Most checks run on the session's ``small_benchmark`` (two procedural houses,
every candidate episode in ``built["corpus"]``, a 40-episode subset written
to disk); the CLI builds the same houses once more from their USD files.
"""

from __future__ import annotations

import collections
import dataclasses
import gzip
import json
import math
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from ignjax.episodes.schema import (
    CONSTRUCTION_FIELDS, CONSTRUCTION_SCHEMA, LEAK_FIELDS, RELEASED_FIELDS, SCHEMA, read_episodes, strip_record,
    validate_record,
)
from ignjax.errors import ConfigError, EpisodeError

FACTORS = ("F_distractor", "F_room", "F_context", "F_start")


def run_build(*args, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "ignjax.build", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)


def raw_lines(path: Path) -> list[dict]:
    opener = gzip.open if path.name.endswith(".gz") else open
    with opener(path, "rt", encoding="utf-8") as f:
        return [json.loads(line) for line in f if line.strip()]


def write_lines(path: Path, records: list[dict]) -> Path:
    path.write_text("".join(json.dumps(r, allow_nan=True) + "\n" for r in records))
    return path


@pytest.fixture(scope="module")
def bench(small_benchmark):
    b = small_benchmark
    cons = {c["episode_id"]: c for c in b["built"]["corpus_construction"]}
    scenes = {h.id: h for h in b["houses"]}
    return {**b, "corpus": b["built"]["corpus"], "cons": cons, "scenes": scenes}


@pytest.fixture(scope="module")
def corpus_fields(bench):
    """Geodesic fields of every corpus target on the loader's grids (the
    scene bank of the scenes read back from their USD files), not on the
    builder's (both use :func:`ignjax.scenes.geodesic.goal_fields`)."""
    from ignjax.episodes.dataset import field_table

    bank = bench["set"].bank
    pairs = sorted({(bank.scene_index(r["scene_id"]), bank.instance_index(r["scene_id"], r["target_id"]))
                    for r in bench["corpus"]})
    fields = field_table(bank, pairs)
    return bank, {p: fields.field(k) for k, p in enumerate(pairs)}


# ---------------------------------------------------------------------------
# start rules
# ---------------------------------------------------------------------------


def test_starts_navigable_reachable_and_room_rules(bench, corpus_fields):
    bank, fields = corpus_fields
    kinds = collections.Counter()
    for rec in bench["corpus"]:
        c = bench["cons"][rec["episode_id"]]
        s = bank.scene_index(rec["scene_id"])
        grid = bank.navgrids[s]
        scene = bench["scenes"][rec["scene_id"]]
        field = fields[(s, bank.instance_index(s, rec["target_id"]))][:grid.shape[0], :grid.shape[1]]
        xy = np.array([rec["start"]["x"], rec["start"]["y"]])
        r, col = grid.world_to_cell(xy)
        assert grid.in_bounds(np.array([r, col])) and grid.navigable[r, col], rec["episode_id"]
        geo = float(field[r, col])
        assert math.isfinite(geo), rec["episode_id"]  # reachable
        assert geo == pytest.approx(c["start_distance"], abs=1e-3)
        assert c["start_distance"] >= 3.0 and geo >= 3.0 - 1e-3, rec["episode_id"]
        assert -math.pi <= rec["start"]["yaw"] <= math.pi
        start_room = scene.room_at(xy)
        assert start_room == c["start_room"]
        same = start_room == rec["goal_room"]["id"]
        kinds[(rec["difficulty"], same)] += 1
        if same and rec["difficulty"] != "easy":
            # medium/hard start in the target's room only when no other room offers a start >= 3 m away
            other = (np.isfinite(field) & grid.navigable & (field >= 3.0) & (grid.room >= 0)
                     & (grid.room != grid.room_index(rec["goal_room"]["id"])))
            assert not other.any(), rec["episode_id"]
    # both kinds of easy start occur, so the rules above were exercised
    assert kinds[("easy", True)] > 0 and kinds[("easy", False)] > 0
    assert kinds[("medium", False)] > 0 and kinds[("hard", False)] > 0


# ---------------------------------------------------------------------------
# difficulty
# ---------------------------------------------------------------------------


def test_difficulty_recomputed_by_hand(bench):
    bins = collections.Counter()
    for rec in bench["corpus"]:
        c = bench["cons"][rec["episode_id"]]
        a, t, f = rec["alpha"], rec["thresholds"], rec["factors"]
        assert a == [0.35, 0.25, 0.15, 0.25] and t == [0.30, 0.60]
        assert set(f) == set(FACTORS)
        d = a[0] * f["F_distractor"] + a[1] * f["F_room"] + a[2] * f["F_context"] + a[3] * f["F_start"]
        assert rec["difficulty_score"] == pytest.approx(d, abs=1e-12)
        label = "easy" if d < t[0] else "medium" if d < t[1] else "hard"
        assert rec["difficulty"] == label, rec["episode_id"]
        bins[label] += 1
        # the factors themselves, from the construction record and the documented normalisations
        nd, nr = len(c["distractors"]), len(c["same_room_distractors"])
        assert f["F_distractor"] == pytest.approx(min(1.0, math.log(1 + nd) / math.log(17)), abs=1e-12)
        assert f["F_room"] == pytest.approx(min(1.0, math.log(1 + nr) / math.log(5)), abs=1e-12)
        assert f["F_context"] == pytest.approx(1.0 - c["rho"], abs=1e-12)
        assert f["F_start"] == pytest.approx(min(1.0, c["start_distance"] / 15.0), abs=1e-12)
        # the distractors are every other instance of the target's category, counted from the scene
        scene = bench["scenes"][rec["scene_id"]]
        target = scene.instance(rec["target_id"])
        same_cat = [i.id for i in scene.objects if i.category == target.category and i.id != target.id]
        assert c["distractors"] == same_cat
        assert c["same_room_distractors"] == [i for i in same_cat if scene.instance(i).room == target.room]
    assert all(bins[b] > 0 for b in ("easy", "medium", "hard"))


# ---------------------------------------------------------------------------
# balanced subset and determinism
# ---------------------------------------------------------------------------


def _within_one(counts: dict, n: int):
    for b, share in zip(("easy", "medium", "hard"), (0.3, 0.4, 0.3)):
        assert abs(counts.get(b, 0) - share * n) <= 1, (counts, n)


def test_subset_is_30_40_30_and_spread(bench):
    corpus, subset = bench["corpus"], bench["built"]["subset"]
    assert len(subset) == 40
    per_bin = collections.Counter(r["difficulty"] for r in corpus)
    assert per_bin["easy"] >= 12 and per_bin["medium"] >= 16 and per_bin["hard"] >= 12  # enough candidates
    _within_one(collections.Counter(r["difficulty"] for r in subset), 40)
    assert bench["built"]["subset_info"]["short"] == {}
    ids = [r["episode_id"] for r in subset]
    assert len(set(ids)) == 40
    by_id = {r["episode_id"]: r for r in corpus}
    assert all(by_id[r["episode_id"]] == r for r in subset)
    # spread: both houses, and no target twice while fresh targets remain
    assert {r["scene_id"] for r in subset} == set(bench["scenes"])
    assert len({(r["scene_id"], r["target_id"]) for r in subset}) == 40
    # the file on disk holds the subset in corpus order
    assert [r["episode_id"] for r in read_episodes(bench["path"])] == ids


@pytest.mark.parametrize("n", [10, 23, 37, 60])
def test_select_subset_other_sizes(bench, n):
    from ignjax.episodes.construct import select_subset

    corpus = bench["corpus"]
    idx, info = select_subset(corpus, n, seed=0)
    assert len(idx) == len(set(idx)) == n and idx == sorted(idx)
    _within_one(collections.Counter(corpus[i]["difficulty"] for i in idx), n)
    assert select_subset(corpus, n, seed=0)[0] == idx
    assert select_subset(corpus, n, seed=5)[0] != idx


def test_select_subset_reports_shortfall(bench):
    from ignjax.episodes.construct import select_subset

    corpus = bench["corpus"]
    per_bin = collections.Counter(r["difficulty"] for r in corpus)
    idx, info = select_subset(corpus, 200, seed=0)
    assert info["quota"] == {"easy": 60, "medium": 80, "hard": 60}
    assert info["short"] == {b: q - per_bin[b] for b, q in info["quota"].items() if per_bin[b] < q}
    assert len(idx) == sum(min(q, per_bin[b]) for b, q in info["quota"].items())


def test_same_seed_same_bytes_other_seed_differs(bench, tmp_path):
    from ignjax.episodes.construct import BuildConfig, build_benchmark
    from ignjax.episodes.schema import construction_path, write_records

    pairs = [(h, f"{h.id}.usda") for h in bench["houses"]]
    again = build_benchmark(pairs, BuildConfig(subset=40, starts_per_target=2))
    p = write_records(tmp_path / "again.jsonl.gz", again["subset"])
    write_records(construction_path(p), again["subset_construction"])
    assert p.read_bytes() == bench["path"].read_bytes()
    assert construction_path(p).read_bytes() == construction_path(bench["path"]).read_bytes()
    assert p.read_bytes()[4:8] == b"\0\0\0\0"  # no gzip timestamp
    other = build_benchmark(pairs, BuildConfig(seed=1, subset=40, starts_per_target=2))
    q = write_records(tmp_path / "other.jsonl.gz", other["subset"])
    assert q.read_bytes() != p.read_bytes()
    # the seed reaches the episodes themselves, not only the subset draw
    yaw0 = {r["episode_id"]: r["start"]["yaw"] for r in bench["corpus"]}
    yaw1 = {r["episode_id"]: r["start"]["yaw"] for r in other["corpus"]}
    common = set(yaw0) & set(yaw1)
    assert common and any(yaw0[k] != yaw1[k] for k in common)


# ---------------------------------------------------------------------------
# leak stripping
# ---------------------------------------------------------------------------


def _all_keys(obj) -> set[str]:
    if isinstance(obj, dict):
        return set(obj) | {k for v in obj.values() for k in _all_keys(v)}
    if isinstance(obj, list):
        return {k for v in obj for k in _all_keys(v)}
    return set()


def test_released_records_hold_no_construction_fields(bench):
    assert {"distractors", "same_room_distractors", "target_bbox", "target_attributes", "anchors"} <= LEAK_FIELDS
    released = raw_lines(bench["path"])
    cons = raw_lines(bench["path"].with_name("episodes.construction.jsonl.gz"))
    assert len(released) == len(cons) == 40
    for rec, c in zip(released, cons):
        assert set(rec) == set(RELEASED_FIELDS) and rec["schema"] == SCHEMA
        assert not _all_keys(rec) & LEAK_FIELDS, rec["episode_id"]
        assert set(c) == set(CONSTRUCTION_FIELDS) and c["schema"] == CONSTRUCTION_SCHEMA
        assert c["episode_id"] == rec["episode_id"]
        assert len(c["target_bbox"]["center"]) == 3 and set(c["target_attributes"]) >= {"color", "material"}
        merged = {**c, **rec}
        assert strip_record(merged) == rec
        with pytest.raises(EpisodeError, match="construction-only field"):
            validate_record(merged)


# ---------------------------------------------------------------------------
# oracle-memory hints
# ---------------------------------------------------------------------------


def _dist(scene, a, b) -> float:
    return float(np.linalg.norm(np.array(scene.instance(a).bbox.center[:2]) - np.array(scene.instance(b).bbox.center[:2])))


def test_memory_hints_follow_the_rule(bench):
    kinds = collections.Counter()
    for rec in bench["corpus"]:
        c = bench["cons"][rec["episode_id"]]
        scene = bench["scenes"][rec["scene_id"]]
        tid = rec["target_id"]
        hint = rec["memory_hint"]
        kinds[hint["kind"]] += 1
        if c["same_room_distractors"]:
            pool, kind = c["same_room_distractors"], "same_room_distractor"
        elif c["distractors"]:
            pool, kind = c["distractors"], "nearest_distractor"
        else:
            pool, kind = [], "offset"
        assert hint["kind"] == kind, rec["episode_id"]
        if pool:
            best = min(_dist(scene, tid, i) for i in pool)
            assert hint["instance_id"] in pool
            assert _dist(scene, tid, hint["instance_id"]) == pytest.approx(best)
            assert hint["position"] == pytest.approx(list(scene.instance(hint["instance_id"]).position))
        else:
            p = scene.instance(tid).position
            assert hint["instance_id"] is None
            assert 0.5 - 1e-9 <= math.hypot(hint["position"][0] - p[0], hint["position"][1] - p[1]) <= 1.5 + 1e-9
            assert hint["position"][2] == pytest.approx(p[2])
    assert all(kinds[k] > 0 for k in ("same_room_distractor", "nearest_distractor", "offset")), kinds


def test_memory_hint_prefers_a_same_room_distractor_over_a_nearer_one(two_room_scene):
    from ignjax.episodes.construct import _memory_hint
    from ignjax.episodes.inventory import build_inventory
    from ignjax.scenes.procgen import catalogue as cat
    from ignjax.scenes.model import Attributes

    attrs = Attributes("red", "wood", "medium", None)
    built = cat.CATALOGUE["chair"].build(attrs, np.random.default_rng(0))
    extra = cat.instantiate("chair_3", "chair", attrs, built, (5.45, 3.5, 0.0), 0.0, "room_1")
    scene = dataclasses.replace(two_room_scene, instances=two_room_scene.instances + (extra,))
    cands = {c.target_id: c for c in build_inventory(scene).candidates}
    c1 = cands["chair_1"]
    assert c1.same_room_distractors == ("chair_0",)
    assert _dist(scene, "chair_1", "chair_3") < _dist(scene, "chair_1", "chair_0")  # a nearer chair next door
    hint = _memory_hint(scene, c1, np.random.default_rng(0))
    assert (hint["kind"], hint["instance_id"]) == ("same_room_distractor", "chair_0")
    hint = _memory_hint(scene, cands["chair_2"], np.random.default_rng(0))  # bedroom: chair_3 shares it
    assert (hint["kind"], hint["instance_id"]) == ("same_room_distractor", "chair_3")
    # without chair_3 the bedroom chair has no same-room distractor: the nearest one anywhere
    plain = {c.target_id: c for c in build_inventory(two_room_scene).candidates}
    hint = _memory_hint(two_room_scene, plain["chair_2"], np.random.default_rng(0))
    assert (hint["kind"], hint["instance_id"]) == ("nearest_distractor", "chair_1")
    # no distractor at all: a point 0.5-1.5 m around the target, drawn from the rng
    laptop = scene.instance("laptop_0").position
    hints = [_memory_hint(scene, cands["laptop_0"], np.random.default_rng(s)) for s in range(20)]
    for h in hints:
        assert h["kind"] == "offset" and h["instance_id"] is None
        assert 0.5 <= math.hypot(h["position"][0] - laptop[0], h["position"][1] - laptop[1]) <= 1.5
        assert h["position"][2] == laptop[2]
    assert len({tuple(h["position"]) for h in hints}) == 20
    assert _memory_hint(scene, cands["laptop_0"], np.random.default_rng(3)) == hints[3]


def test_descriptions_relate_only_to_categories_the_checker_reads(two_room_scene):
    """A relation to a category outside the closed vocabulary cannot be read
    back, so the check would reject the text; such relations are not used."""
    from ignjax.episodes import describe as D
    from ignjax.episodes.inventory import build_inventory
    from ignjax.scenes.procgen import catalogue as cat
    from ignjax.scenes import vocab
    from ignjax.scenes.model import Attributes, Instance, OrientedBox

    assert "plunger" not in vocab.TARGET_WHITELIST_SET
    attrs = Attributes("red", "wood", "medium", None)
    built = cat.CATALOGUE["chair"].build(attrs, np.random.default_rng(0))
    twin = cat.instantiate("chair_9", "chair", attrs, built, (6.0, 3.5, 0.0), 0.0, "room_1")
    plunger = Instance("plunger_0", "plunger", (5.4, 0.3, 0.0), 0.0, OrientedBox((5.4, 0.3, 0.2), (0.1, 0.1, 0.2)), "room_1")
    scene = dataclasses.replace(two_room_scene, instances=two_room_scene.instances + (twin, plunger))
    inv = build_inventory(scene)
    c2 = next(c for c in inv.candidates if c.target_id == "chair_2")
    assert "plunger_0" in c2.unique_anchors  # the only thing that tells chair_2 from its twin
    described = 0
    for c in inv.candidates:
        t = scene.instance(c.target_id)
        ds = [scene.instance(i) for i in c.distractors]
        out = D.describe_target(scene, inv.anchors, t, ds, c.unique_anchors)
        if out is None:
            continue
        text, facts = out
        described += 1
        assert D.check_description(text, scene, inv.anchors, t, ds).ok, text
        assert D.read_facts(text) == facts, text
    assert described >= 5


# ---------------------------------------------------------------------------
# loader validation
# ---------------------------------------------------------------------------


def _set(path, value):
    def f(rec):
        obj = rec
        for k in path[:-1]:
            obj = obj[k]
        if value is _DELETE:
            del obj[path[-1]]
        else:
            obj[path[-1]] = value
    return f


_DELETE = object()


def _relabel(rec):
    rec["difficulty"] = "hard" if rec["difficulty"] != "hard" else "easy"


def _shift_score(rec):
    rec["difficulty_score"] += 0.01


def _leak(rec):
    rec["distractors"] = ["chair_1"]


SCHEMA_CASES = [
    ("missing", _set(["instruction"], _DELETE), "instruction", "missing field"),
    ("missing_nested", _set(["factors", "F_room"], _DELETE), "factors: F_room", "missing field"),
    ("mistyped_start", _set(["start", "x"], "1.5"), "start: x", "expected number"),
    ("mistyped_score", _set(["difficulty_score"], "0.4"), "difficulty_score", "expected number"),
    ("mistyped_room", _set(["goal_room"], "kitchen"), "goal_room", "expected dict"),
    ("version_2", _set(["version"], 2), "version", "unknown schema version 2"),
    ("version_bool", _set(["version"], True), "version", "unknown schema version True"),
    ("version_str", _set(["version"], "1"), "version", "unknown schema version '1'"),
    ("schema", _set(["schema"], "habitat-episode"), "schema", "expected 'ignjax-episode'"),
    ("alpha_negative", _set(["alpha"], [0.5, 0.5, 0.15, -0.15]), "alpha", "negative"),
    ("alpha_nan", _set(["alpha"], [0.35, 0.25, float("nan"), 0.25]), "alpha", "finite"),
    ("alpha_short", _set(["alpha"], [0.5, 0.5]), "alpha", "list of 4"),
    ("thresholds_order", _set(["thresholds"], [0.6, 0.3]), "thresholds", "increasing"),
    ("factor_range", _set(["factors", "F_start"], 1.5), "factors.F_start", "[0, 1]"),
    ("label", _relabel, "difficulty", "does not match"),
    ("score", _shift_score, "difficulty_score", "differs from alpha . factors"),
    ("leak", _leak, "distractors", "construction-only"),
    ("hint_kind", _set(["memory_hint", "kind"], "psychic"), "memory_hint.kind", "unknown kind"),
]


@pytest.mark.parametrize("name,mutate,field,reason", SCHEMA_CASES, ids=[c[0] for c in SCHEMA_CASES])
def test_record_errors_name_file_line_episode_and_field(bench, tmp_path, name, mutate, field, reason):
    good = read_episodes(bench["path"])
    bad = json.loads(json.dumps(good[1]))
    mutate(bad)
    path = write_lines(tmp_path / "e.jsonl", [good[0], bad, good[2]])
    with pytest.raises(EpisodeError) as e:
        read_episodes(path)
    msg = str(e.value)
    assert msg.startswith(str(path) + ": ")
    assert f"line 2 (episode {good[1]['episode_id']})" in msg
    assert f": {field}" in msg and reason in msg, msg


def test_file_level_errors(bench, tmp_path):
    good = read_episodes(bench["path"])
    dup = json.loads(json.dumps(good[0]))
    path = write_lines(tmp_path / "dup.jsonl", [good[0], good[1], dup])
    with pytest.raises(EpisodeError, match=r"line 3: episode_id: duplicate id .* \(first on line 1\)"):
        read_episodes(path)
    broken = tmp_path / "broken.jsonl"
    broken.write_text(json.dumps(good[0]) + "\n{not json\n")
    with pytest.raises(EpisodeError, match=r"broken.jsonl: line 2: invalid JSON"):
        read_episodes(broken)
    empty = tmp_path / "empty.jsonl.gz"
    with gzip.open(empty, "wt") as f:
        f.write("\n")
    with pytest.raises(EpisodeError, match="holds no episodes"):
        read_episodes(empty)
    with pytest.raises(EpisodeError, match="no such file"):
        read_episodes(tmp_path / "absent.jsonl")


def _one_scene_records(bench, n=2):
    recs = [r for r in read_episodes(bench["path"]) if r["scene_id"] == "small_a"]
    return [json.loads(json.dumps(r)) for r in recs[:n]]


def test_loader_rejects_unknown_scene_and_missing_scene_file(bench, tmp_path):
    from ignjax.episodes.dataset import load_benchmark

    recs = _one_scene_records(bench)
    recs[1]["scene_id"] = "no_such_house"
    path = write_lines(tmp_path / "e.jsonl", recs)
    with pytest.raises(EpisodeError) as e:
        load_benchmark(path, scenes_root=bench["root"])
    msg = str(e.value)
    assert msg.startswith(str(path)) and f"episode {recs[1]['episode_id']}: scene_id" in msg
    assert "'no_such_house' not found" in msg and "small_a.usda" in msg
    recs = _one_scene_records(bench)
    recs[1]["scene_file"] = "gone.usda"
    path = write_lines(tmp_path / "f.jsonl", recs)
    with pytest.raises(EpisodeError) as e:
        load_benchmark(path, scenes_root=bench["root"])
    assert f"episode {recs[1]['episode_id']}: scene_file" in str(e.value) and "gone.usda" in str(e.value)
    # files are read side by side: of two bad ones, the first in path order is named, whatever the records' order
    recs = _one_scene_records(bench)
    recs[0]["scene_file"], recs[1]["scene_file"] = "z_gone.usda", "a_gone.usda"
    path = write_lines(tmp_path / "g.jsonl", recs)
    with pytest.raises(EpisodeError) as e:
        load_benchmark(path, scenes_root=bench["root"])
    assert f"episode {recs[1]['episode_id']}: scene_file" in str(e.value) and "a_gone.usda" in str(e.value)


def test_loader_rejects_unknown_target_and_starts_off_the_navigable_area(bench, tmp_path):
    from ignjax.episodes.dataset import episode_specs, load_benchmark

    bank = bench["set"].bank
    grid = bank.navgrids[bank.scene_index("small_a")]
    blocked = np.argwhere(~grid.navigable)
    bx, by = grid.cell_to_world(blocked[len(blocked) // 2])
    cases = [(["target_id"], "ghost_0", "target_id", "not in scene 'small_a'"),
             (["target_category"], "giraffe", "target_category", "'giraffe' but instance"),
             (["start", "x"], -500.0, "start", "off the navigable area"),
             (["start"], {"x": float(bx), "y": float(by), "yaw": 0.0}, "start", "off the navigable area")]
    for keys, value, field, reason in cases:
        recs = _one_scene_records(bench)
        _set(keys, value)(recs[1])
        with pytest.raises(EpisodeError) as e:
            episode_specs(recs, bank, tmp_path / "e.jsonl")
        msg = str(e.value)
        assert f"e.jsonl: episode {recs[1]['episode_id']}: {field}: " in msg and reason in msg, msg
    # the same through the loader, end to end
    recs = _one_scene_records(bench)
    recs[1]["start"] = {"x": float(bx), "y": float(by), "yaw": 0.0}
    path = write_lines(tmp_path / "g.jsonl", recs)
    with pytest.raises(EpisodeError, match=rf"g.jsonl: episode {recs[1]['episode_id']}: start: .*off the navigable area"):
        load_benchmark(path, scenes_root=bench["root"])


@pytest.mark.parametrize("kw,field", [
    ({"alpha": (0.5, 0.5, 0.15, -0.15)}, "alpha"), ({"alpha": (0.35, 0.25, float("nan"), 0.4)}, "alpha"),
    ({"thresholds": (0.6, 0.3)}, "thresholds"), ({"thresholds": (0.3, 0.3)}, "thresholds"),
    ({"proportions": (0.5, 0.5, 0.5)}, "proportions"), ({"seed": -1}, "seed"), ({"starts_per_target": 0}, "starts_per_target"),
])
def test_build_config_rejects_bad_settings(kw, field):
    from ignjax.episodes.construct import BuildConfig

    with pytest.raises(ConfigError) as e:
        BuildConfig(**kw)
    assert e.value.where == field


def _bare(two_room_scene, sid="bare"):
    return dataclasses.replace(two_room_scene, id=sid, instances=tuple(i for i in two_room_scene.instances if i.structural))


def test_scene_without_eligible_target_is_skipped_with_a_warning(two_room_scene):
    from ignjax.episodes.construct import BuildConfig, build_benchmark

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        built = build_benchmark([(_bare(two_room_scene), "bare.usda")], BuildConfig(subset=0))
    assert [str(w.message) for w in caught] == ["scene bare: skipped (no eligible target)"]
    (rep,) = built["reports"]
    assert rep.skipped == "no eligible target" and rep.candidates == 0 and rep.episodes == 0
    assert built["corpus"] == [] and built["subset"] == []


# ---------------------------------------------------------------------------
# ProcTHOR houses (third-party)
# ---------------------------------------------------------------------------


@pytest.mark.shared
def test_procthor_episode_distractors_match_the_house_files(shared_data):
    from ignjax.episodes.construct import BuildConfig, build_benchmark
    from ignjax.scenes import vocab
    from ignjax.scenes.io.procthor import load_procthor

    folder = shared_data / "procthor" / "houses"
    if not folder.is_dir():
        pytest.skip(f"{folder} is absent")
    db = json.loads((shared_data / "procthor" / "asset-database.json").read_text())
    object_type = {a["assetId"]: t for t, assets in db.items() for a in assets}

    def walk(objs):
        for o in objs:
            yield o
            yield from walk(o.get("children") or [])

    files = {p.stem: p for p in sorted(folder.glob("*.json"))}
    scenes = [s for p in files.values() for s in load_procthor(p)]
    built = build_benchmark([(s, files[s.id].name) for s in scenes], BuildConfig(subset=0, starts_per_target=1))
    cons = {c["episode_id"]: c for c in built["corpus_construction"]}
    assert len(built["corpus"]) >= 40
    # a generated description is always read back the way it was meant
    for rep in built["reports"]:
        assert not rep.skipped and not rep.unreachable_rooms
        assert not [k for k in rep.dropped if k.startswith("description rejected")], rep.dropped
    by_house = {}
    for sid, p in files.items():
        raw = json.loads(p.read_text())
        groups = collections.defaultdict(list)
        for o in walk(raw["objects"]):
            groups[vocab.normalize_category(object_type[o["assetId"]])].append(o["id"])
        by_house[sid] = groups
    counts = collections.Counter()
    for rec in built["corpus"]:
        c = cons[rec["episode_id"]]
        same = by_house[rec["scene_id"]][rec["target_category"]]
        assert rec["target_id"] in same
        assert sorted(c["distractors"]) == sorted(i for i in same if i != rec["target_id"]), rec["episode_id"]
        assert set(c["same_room_distractors"]) <= set(c["distractors"])
        counts[len(c["distractors"])] += 1
    assert counts[0] > 0 and sum(v for k, v in counts.items() if k >= 2) > 0  # unique and repeated categories


# ---------------------------------------------------------------------------
# CLI
# ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def cli_build(bench, two_room_scene, tmp_path_factory):
    from ignjax.scenes.io.usd import save_usd

    root = tmp_path_factory.mktemp("episodes_cli")
    scenes = root / "scenes"
    scenes.mkdir()
    for h in bench["houses"]:
        shutil.copy(bench["root"] / f"{h.id}.usda", scenes / f"{h.id}.usda")
    extra = root / "extra"
    extra.mkdir()
    save_usd(_bare(two_room_scene), extra / "bare.usda")
    out = root / "out" / "e.jsonl.gz"
    proc = run_build("episodes", "--scenes", scenes, extra / "bare.usda", "--out", out,
                     "--subset", 40, "--seed", 0, "--starts", 2, "--quiet")
    assert proc.returncode == 0, proc.stderr
    return {"root": root, "out": out, "proc": proc}


def test_cli_build_writes_files_and_summary(bench, cli_build):
    out, proc = cli_build["out"], cli_build["proc"]
    folder = out.parent
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        ["e.jsonl.gz", "e.construction.jsonl.gz", "e.corpus.jsonl.gz", "e.stats.png"])
    assert (folder / "e.stats.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "evaluation subset: 40 episodes" in proc.stdout
    assert "difficulty: easy 12, medium 16, hard 12" in proc.stdout
    assert "scenes: 3 read, 1 skipped (no eligible target): bare" in proc.stdout
    assert "warning: scene bare: skipped (no eligible target)" in proc.stderr
    # the same houses read back from USD give the library's episodes; scene files are relative to the output
    released = raw_lines(out)
    assert [r["scene_file"] for r in released] == [f"../scenes/{r['scene_id']}.usda" for r in released]
    assert all((folder / r["scene_file"]).is_file() for r in released)
    strip = [{k: v for k, v in r.items() if k != "scene_file"} for r in released]
    assert strip == [{k: v for k, v in r.items() if k != "scene_file"} for r in bench["built"]["subset"]]
    corpus = raw_lines(folder / "e.corpus.jsonl.gz")
    assert len(corpus) == len(bench["corpus"]) and not any(_all_keys(r) & LEAK_FIELDS for r in corpus)
    cons = raw_lines(folder / "e.construction.jsonl.gz")
    assert [c["episode_id"] for c in cons] == [r["episode_id"] for r in released]


def test_cli_check_and_schema_only(cli_build, tmp_path):
    out = cli_build["out"]
    proc = run_build("episodes", "--check", out)
    assert proc.returncode == 0, proc.stderr
    assert "checked 40 episodes against 2 scenes" in proc.stdout
    assert "40 episodes, 40 targets in 2 scenes" in proc.stdout and "difficulty: easy 12, medium 16, hard 12" in proc.stdout
    # a copy away from its scenes: the schema checks still pass, the scene checks cannot
    moved = tmp_path / "e.jsonl.gz"
    shutil.copy(out, moved)
    proc = run_build("episodes", "--check", moved, "--schema-only")
    assert proc.returncode == 0, proc.stderr
    assert "checked" not in proc.stdout and "difficulty: easy 12, medium 16, hard 12" in proc.stdout
    proc = run_build("episodes", "--check", moved)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    (err,) = [line for line in proc.stderr.splitlines() if line.startswith("error: ")]
    assert str(moved) in err and "scene_file" in err and "small_a.usda" in err


def test_cli_check_rejects_a_bad_record(cli_build, tmp_path):
    recs = raw_lines(cli_build["out"])
    recs[2]["version"] = 2
    bad = write_lines(tmp_path / "bad.jsonl", recs)
    proc = run_build("episodes", "--check", bad, "--schema-only")
    assert proc.returncode == 2 and proc.stdout == ""
    (err,) = [line for line in proc.stderr.splitlines() if line.startswith("error: ")]
    assert str(bad) in err and f"line 3 (episode {recs[2]['episode_id']}): version" in err


@pytest.mark.parametrize("opt,value,field,reason", [
    ("--alpha", "0.5,0.5,0.15,-0.15", "--alpha", "negative"),
    ("--alpha", "0.35,0.25,nan,0.25", "--alpha", "NaN"),
    ("--thresholds", "0.6,0.3", "--thresholds", "0 <= easy/medium < medium/hard"),
])
def test_cli_rejects_bad_difficulty_settings(cli_build, tmp_path, opt, value, field, reason):
    out = tmp_path / "x" / "e.jsonl.gz"
    proc = run_build("episodes", "--scenes", cli_build["root"] / "scenes", "--out", out, opt, value, "--quiet")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    (err,) = [line for line in proc.stderr.splitlines() if line.startswith("error: ")]
    assert field in err and reason in err
    assert list(tmp_path.iterdir()) == []
