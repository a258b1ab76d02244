"""Shared fixtures.

``shared_data``: the folder ``../shared/data`` (real third-party data), or a
skip with the reason when it is absent. The core suite never needs it.

The session runs with two CPU devices (``ignjax.devices.configure_cpu_devices``,
set here before JAX starts; ``IGNJAX_CPU_DEVICES`` overrides the count), so
rollouts are sharded over two devices unless a test says otherwise.

``two_room_scene``: a small hand-built scene (living room + bedroom, one
door) with known instances, for tests that need exact expectations.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", "egl")

from ignjax.devices import configure_cpu_devices  # noqa: E402

configure_cpu_devices(2)

ROOT = Path(__file__).resolve().parents[1]
MAP_SHARE = 3
"""Compiled programs are dropped after a test file once the process holds
more than 1/MAP_SHARE of the kernel's memory-mapping limit (below)."""


def _map_counts() -> tuple[int, int] | None:
    """(memory mappings of this process, the kernel's limit), or None where /proc does not tell."""
    try:
        with open("/proc/self/maps", "rb") as f:
            n = sum(1 for _ in f)
        return n, int(Path("/proc/sys/vm/max_map_count").read_text())
    except (OSError, ValueError):
        return None


@pytest.fixture(scope="module", autouse=True)
def _drop_compiled_programs():
    """Every program XLA:CPU compiles holds about three memory mappings of
    its own (code, constants, data) for as long as JAX's caches keep it, and
    the whole suite compiles thousands in one process: past the kernel's
    ``vm.max_map_count`` (65,530 by default) the next compile's ``mmap``
    fails and the process dies with a segmentation fault. After a test file,
    once the mappings pass a third of the limit, JAX's caches are cleared
    (``jax.clear_caches``), which frees them; a later file compiles again what it needs."""
    yield
    counts = _map_counts()
    if counts and counts[0] * MAP_SHARE > counts[1]:
        import gc

        import jax

        jax.clear_caches()
        gc.collect()
SHARED_DATA = Path(os.environ.get("IGNJAX_SHARED_DATA", ROOT.parent / "shared" / "data"))


@pytest.fixture(scope="session")
def shared_data() -> Path:
    if not SHARED_DATA.is_dir():
        pytest.skip(f"third-party data folder {SHARED_DATA} is absent (set IGNJAX_SHARED_DATA to use another)")
    return SHARED_DATA


def make_two_room_scene():
    """Living room [0,5]x[0,4] and bedroom [5,9]x[0,4], a 1 m door at x=5, y=2.

    Instances (ids): ``bed_0`` (bedroom, against the east wall), ``table_0``
    (living room centre), ``laptop_0`` on the table, ``chair_0``/``chair_1``
    (living room, facing the table), ``chair_2`` (bedroom), ``painting_0``
    (living room north wall).
    """
    from ignjax.scenes.procgen import catalogue as cat
    from ignjax.scenes.model import Attributes, Door, Room, Scene, SceneMeta, Wall

    rng = np.random.default_rng(0)
    rooms = (
        Room("room_0", "living_room", ((0, 0), (5, 0), (5, 4), (0, 4)), "Living room"),
        Room("room_1", "bedroom", ((5, 0), (9, 0), (9, 4), (5, 4)), "Bedroom"),
    )
    t = 0.1
    walls = (
        Wall("wall_s", (0, 0), (9, 0), t, 2.5, 0, ("room_0", "room_1")),
        Wall("wall_n", (0, 4), (9, 4), t, 2.5, 0, ("room_0", "room_1")),
        Wall("wall_w", (0, 0), (0, 4), t, 2.5, 0, ("room_0",)),
        Wall("wall_e", (9, 0), (9, 4), t, 2.5, 0, ("room_1",)),
        Wall("wall_m0", (5, 0), (5, 1.5), t, 2.5, 0, ("room_0", "room_1")),
        Wall("wall_m1", (5, 2.5), (5, 4), t, 2.5, 0, ("room_0", "room_1")),
        Wall("wall_m_lintel", (5, 1.5), (5, 2.5), t, 0.4, 2.1, ("room_0", "room_1")),
    )
    doors = (Door("door_0", (5, 2), 1.0, math.pi / 2, ("room_0", "room_1")),)
    C = cat.CATALOGUE
    insts = []

    def add(iid, cat_name, attrs, pos, yaw, room, support=None):
        built = C[cat_name].build(attrs, rng)
        inst = cat.instantiate(iid, cat_name, attrs, built, pos, yaw, room, support)
        insts.append(inst)
        return inst, built

    add("bed_0", "bed", Attributes("blue", "wood", "medium", "made"), (7.9, 2.0, 0.0), math.pi, "room_1")
    table, tb = add("table_0", "dining_table", Attributes("brown", "wood", "medium", None), (2.5, 2.0, 0.0), 0.0, "room_0")
    top = tb.surfaces[0].height
    add("laptop_0", "laptop", Attributes("gray", "metal", "medium", "open"), (2.5, 2.0, top), 0.0, "room_0", "table_0")
    add("chair_0", "chair", Attributes("red", "wood", "medium", None), (1.3, 2.0, 0.0), 0.0, "room_0")
    add("chair_1", "chair", Attributes("green", "metal", "medium", None), (3.7, 2.0, 0.0), math.pi, "room_0")
    add("chair_2", "chair", Attributes("red", "wood", "medium", None), (6.0, 0.8, 0.0), math.pi / 2, "room_1")
    pattrs = Attributes("yellow", "wood", "medium", None)
    hx = C["painting"].build(pattrs, rng).half_extents[0]
    # back flush against the north wall's inner face (y = 4 - t/2), facing south into the room
    add("painting_0", "painting", pattrs, (2.5, 4.0 - t / 2 - hx, 1.2), -math.pi / 2, "room_0")
    return Scene("two_rooms", rooms, doors, walls, tuple(insts), SceneMeta(source="tests/conftest.py", source_format="procgen"))


@pytest.fixture(scope="session")
def two_room_scene():
    return make_two_room_scene()


@pytest.fixture(scope="session")
def small_benchmark(tmp_path_factory):
    """A small benchmark built end to end, shared by the simulator, agent and
    study tests: two procedural houses (3 and 5 rooms) written as USD, a
    40-episode balanced subset written as an episode file, and the loaded
    :class:`~ignjax.episodes.dataset.EpisodeSet`."""
    from ignjax.episodes.dataset import load_benchmark
    from ignjax.episodes.construct import BuildConfig, build_benchmark
    from ignjax.episodes.schema import construction_path, write_records
    from ignjax.scenes.procgen.generate import HouseParams, generate_house
    from ignjax.scenes.io.usd import save_usd

    root = tmp_path_factory.mktemp("bench")
    houses = [generate_house(11, HouseParams(n_rooms=3), "small_a"), generate_house(12, HouseParams(n_rooms=5), "small_b")]
    for h in houses:
        save_usd(h, root / f"{h.id}.usda")
    built = build_benchmark([(h, f"{h.id}.usda") for h in houses], BuildConfig(subset=40, starts_per_target=2))
    path = root / "episodes.jsonl.gz"
    write_records(path, built["subset"])
    write_records(construction_path(path), built["subset_construction"])
    es = load_benchmark(path)
    return {"root": root, "houses": houses, "built": built, "path": path, "set": es}


@pytest.fixture(scope="session")
def small_world(small_benchmark):
    from ignjax.sim.env import World
    from ignjax.sim.types import SimConfig

    es = small_benchmark["set"]
    return World(es.bank, es.fields, SimConfig())
