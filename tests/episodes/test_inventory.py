"""Inventory, candidates, anchors, rho and descriptions on hand-built scenes."""

import dataclasses
import math

import numpy as np
import pytest

from ignjax.episodes import describe as D
from ignjax.episodes.inventory import InventoryConfig, build_inventory
from ignjax.errors import ConfigError
from ignjax.scenes.procgen import catalogue as cat
from ignjax.scenes.model import Attributes, Instance, OrientedBox


def _with(scene, *extra):
    return dataclasses.replace(scene, instances=scene.instances + tuple(extra))


def _chair(iid, xy, room, color="red"):
    built = cat.CATALOGUE["chair"].build(Attributes(color, "wood", "medium", None), np.random.default_rng(0))
    return cat.instantiate(iid, "chair", Attributes(color, "wood", "medium", None), built, (*xy, 0.0), 0.0, room)


def test_candidates_distractors_anchors_and_rho(two_room_scene):
    inv = build_inventory(two_room_scene, InventoryConfig(anchor_radius=1.0))
    by = {c.target_id: c for c in inv.candidates}
    assert set(by) == {"bed_0", "table_0", "laptop_0", "chair_0", "chair_1", "chair_2", "painting_0"}
    c0 = by["chair_0"]
    assert c0.distractors == ("chair_1", "chair_2")
    assert c0.same_room_distractors == ("chair_1",)
    # anchors: other-category objects within 1 m; same-category chairs are never anchors
    assert c0.anchors == ("table_0", "laptop_0")
    # chair_1 has the same anchors, so none of chair_0's anchors is unique -> rho = 0
    assert c0.unique_anchors == () and c0.rho == 0.0
    c2 = by["chair_2"]
    assert c2.same_room_distractors == () and c2.anchors == ("bed_0",) and c2.unique_anchors == ("bed_0",)
    assert c2.rho == 1.0
    # the laptop's support is an anchor at distance 0, and the laptop is an anchor of its support
    assert "table_0" in by["laptop_0"].anchors and "laptop_0" in by["table_0"].anchors
    assert by["laptop_0"].distractors == () and by["laptop_0"].rho == 1.0


def test_structural_and_unknown_never_targets(two_room_scene):
    box = OrientedBox((1, 1, 1), (0.1, 0.1, 1), 0)
    extra = [Instance("door_x", "door", (1, 1, 0), 0, box, "room_0", structural=True),
             Instance("thing_0", "unknown", (4, 3, 0), 0, OrientedBox((4, 3, 0.2), (0.1, 0.1, 0.2)), "room_0"),
             Instance("wall_x", "wall", (0.5, 3, 0), 0, box, "room_0", structural=True)]
    inv = build_inventory(_with(two_room_scene, *extra))
    ids = {c.target_id for c in inv.candidates}
    assert not ids & {"door_x", "thing_0", "wall_x"}
    with pytest.raises(ConfigError, match="whitelist"):
        InventoryConfig(whitelist=("chair", "wall"))


def test_frequent_category_capped_round_robin_over_rooms(two_room_scene):
    # 6 extra chairs in the living room, 2 in the bedroom -> 11 chairs in all
    extra = [_chair(f"chair_x{k}", (0.6 + 0.5 * k, 0.6), "room_0") for k in range(6)]
    extra += [_chair(f"chair_y{k}", (6.0 + 0.6 * k, 3.4), "room_1") for k in range(2)]
    scene = _with(two_room_scene, *extra)
    inv = build_inventory(scene, InventoryConfig(category_cap=4))
    chairs = [c for c in inv.candidates if c.category == "chair"]
    assert len(chairs) == 4
    rooms = [scene.instance(c.target_id).room for c in chairs]
    assert rooms.count("room_0") == 2 and rooms.count("room_1") == 2  # alternating rooms
    assert inv.capped["chair"] == 11 - 4
    # capped chairs still count as distractors
    assert all(len(c.distractors) == 10 for c in chairs)


def test_generated_descriptions_pass_the_check_and_never_name_rooms(two_room_scene):
    inv = build_inventory(two_room_scene)
    for c in inv.candidates:
        t = two_room_scene.instance(c.target_id)
        ds = [two_room_scene.instance(d) for d in c.distractors]
        text, facts = D.describe_target(two_room_scene, inv.anchors, t, ds, c.unique_anchors)
        assert D.check_description(text, two_room_scene, inv.anchors, t, ds).ok, text
        assert D.names_room(text) is None
        assert D.read_facts(text) == facts
        assert two_room_scene.room(t.room).label.replace("_", " ") not in text.lower()
    # deterministic
    again = build_inventory(two_room_scene)
    assert again == inv


@pytest.mark.parametrize("text,reason", [
    ("", "empty"), ("   ", "empty"),
    ("A red chair in the living room.", "names a room"),
    ("The red chair by the kitchen door.", "names a room"),
    ("A red sofa next to a dining table.", "wrong category"),
    ("A red chair.", "does not separate"),
    ("A blue chair next to a dining table.", "not true"),
    ("Something red.", "no object category"),
])
def test_description_rejections(two_room_scene, text, reason):
    inv = build_inventory(two_room_scene)
    t = two_room_scene.instance("chair_0")
    ds = [two_room_scene.instance("chair_1"), two_room_scene.instance("chair_2")]
    res = D.check_description(text, two_room_scene, inv.anchors, t, ds)
    assert not res.ok and reason in res.reason


def test_category_names_containing_room_words_are_not_leaks(two_room_scene):
    assert D.names_room("A black office chair next to a dining table and a laundry basket.") is None
    assert D.names_room("It stands in the hallway.") == "hallway"


def test_inseparable_target_gets_no_description(two_room_scene):
    # a twin of chair_2: same attributes, same place relations -> cannot be separated
    twin = _chair("chair_9", (6.0, 1.5), "room_1", color="red")
    scene = _with(two_room_scene, twin)
    inv = build_inventory(scene)
    t = scene.instance("chair_2")
    ds = [scene.instance(i) for i in ("chair_0", "chair_1", "chair_9")]
    assert D.describe_target(scene, inv.anchors, t, ds) is None


def test_instruction_and_region(two_room_scene):
    inv = build_inventory(two_room_scene)
    assert D.instruction_text("laptop") == "Find a laptop."
    assert D.instruction_text("office_chair") == "Find an office chair."
    region = D.region_text(two_room_scene, inv.anchors, two_room_scene.instance("laptop_0"))
    assert region == "It is in the living room, on the dining table."
    # Type 2 carries no appearance detail of the target
    assert "gray" not in region and "metal" not in region
