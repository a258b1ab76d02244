"""Shared fixtures.

``shared_data``: the folder ``../shared/data`` (real third-party data), or a
skip with the reason when it is absent. The core suite never needs it.

The session runs with two CPU devices (``ignjax.devices.configure_cpu_devices``,
set here before JAX starts; ``IGNJAX_CPU_DEVICES`` overrides the count), so
rollouts are sharded over two devices unless a test says otherwise. The
run shares one JAX persistent compilation cache and one ignjax cache folder
(scene files, grids, goal fields, probe maps) among its xdist workers and the
processes its tests start, kept between runs (see :func:`_suite_cache_folder`);
outputs never depend on whether they were hit.

``two_room_scene``: a small hand-built scene (living room + bedroom, one
door) with known instances, for tests that need exact expectations.

Optional parts: the tests that need the vLLM server environment
(``.ci/prepare-vllm``), a rendering backend (EGL or MuJoCo Warp), headless
Chromium and its driver, or ``../shared`` carry the markers ``vllm``,
``render``, ``browser`` and ``shared``. Outside CI such a test skips with the
reason when its part is missing. With ``CI=true`` (where every part is set
up) no test may skip: a skip is reported as a failure that quotes the skip's
reason, so a missing part cannot leave the run green. The summary ends with
how many tests of each optional part ran.
"""

from __future__ import annotations

import atexit
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
CACHE_MAX_BYTES = 4 << 30
"""Size bound of the suite's persistent compilation cache (oldest entries evicted first)."""


def _suite_cache_folder() -> str:
    """Where the suite keeps compiled programs and scene arrays between runs:
    ``IGNJAX_TEST_CACHE`` (a folder, or ``fresh`` for a throwaway folder
    removed when the run ends), by default ``tests/`` in the per-user ignjax
    cache folder, so a second run on the machine loads the programs the first
    compiled (as the vLLM environment, built once per machine)."""
    where = os.environ.get("IGNJAX_TEST_CACHE", "").strip()
    if where == "fresh":
        folder = tempfile.mkdtemp(prefix="ignjax-tests-cache-")
        atexit.register(shutil.rmtree, folder, True)
        return folder
    if where:
        return where
    import platformdirs

    return str(Path(platformdirs.user_cache_dir("ignjax", appauthor=False)) / "tests")


if "JAX_COMPILATION_CACHE_DIR" not in os.environ or "IGNJAX_CACHE_DIR" not in os.environ:
    # Set before JAX starts: the xdist workers and every process a test starts inherit them, so a program
    # compiled in one is loaded, not compiled again, by the others (and after jax.clear_caches below) and by
    # later runs; likewise the shipped scenes are gridded once. A size bound turns on JAX's file lock around
    # every read and write, so processes never read an entry another is still writing. Folders of your own in
    # JAX_COMPILATION_CACHE_DIR / IGNJAX_CACHE_DIR are used instead. Outputs never depend on a hit.
    _SUITE_CACHE = _suite_cache_folder()
    os.environ.setdefault("JAX_COMPILATION_CACHE_DIR", os.path.join(_SUITE_CACHE, "jax"))
    if "IGNJAX_NO_CACHE" not in os.environ:
        os.environ.setdefault("IGNJAX_CACHE_DIR", os.path.join(_SUITE_CACHE, "ignjax"))
os.environ.setdefault("JAX_COMPILATION_CACHE_MAX_SIZE", str(CACHE_MAX_BYTES))

from ignjax.devices import configure_cpu_devices  # noqa: E402

configure_cpu_devices(2)

if os.environ.get("IGNJAX_TEST_COMPILE_LOG"):
    # Where the suite's compile time goes: each program this process compiles or loads from the cache, one line
    # "test <tab> program <tab> seconds" in IGNJAX_TEST_COMPILE_LOG.<pid>, after a line with the program's argument
    # shapes (a diagnostic; off unless set).
    import jax  # noqa: E402

    def _log_compile(event, duration, **kw):
        if event == "/jax/core/compile/backend_compile_duration":
            test = os.environ.get("PYTEST_CURRENT_TEST", "-").rsplit(" ", 1)[0]
            with open(f"{os.environ['IGNJAX_TEST_COMPILE_LOG']}.{os.getpid()}", "a") as fh:
                fh.write(f"{test}\t{kw.get('fun_name', '?')}\t{duration:.3f}\n")

    jax.monitoring.register_event_duration_secs_listener(_log_compile)

    import hashlib  # noqa: E402
    import logging  # noqa: E402

    class _Shapes(logging.Handler):
        """Each program's argument shapes before it is compiled: a line "test <tab> shapes: program <tab> digest
        <tab> shapes", so programs that differ only by an input's shape can be found."""

        def emit(self, record):
            if not str(record.msg).startswith("Compiling"):
                return
            name, avals = record.args[0], str(record.args[1])
            test = os.environ.get("PYTEST_CURRENT_TEST", "-").rsplit(" ", 1)[0]
            with open(f"{os.environ['IGNJAX_TEST_COMPILE_LOG']}.{os.getpid()}", "a") as fh:
                fh.write(f"{test}\tshapes: {name}\t{hashlib.sha1(avals.encode()).hexdigest()[:10]}\t{avals[:4000]}\n")

    _pxla_log = logging.getLogger("jax._src.interpreters.pxla")
    _pxla_log.setLevel(logging.DEBUG)
    _pxla_log.addHandler(_Shapes(logging.DEBUG))

ROOT = Path(__file__).resolve().parents[1]
IN_CI = os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no")
"""``CI`` set to anything but empty/0/false/no: skips are failures."""
OPTIONAL_PARTS = {"vllm": "vLLM", "render": "render", "browser": "browser", "shared": "../shared"}
"""Marker -> name in the summary line of the optional parts."""
_PART_COUNTS: dict[str, dict[str, int]] = {m: {} for m in OPTIONAL_PARTS}


def _skip_reason(report) -> str:
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2]).removeprefix("Skipped: ")
    return str(longrepr)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Under CI a skip (not an expected failure) becomes a failure naming the skip's reason."""
    outcome = yield
    report = outcome.get_result()
    if IN_CI and report.skipped and not hasattr(report, "wasxfail"):
        parts = [OPTIONAL_PARTS[m] for m in OPTIONAL_PARTS if item.get_closest_marker(m)]
        need = f" ({', '.join(parts)})" if parts else ""
        report.outcome = "failed"
        report.longrepr = (f"CI=true and a part this test needs{need} is unavailable, so it fails instead of "
                           f"skipping: {_skip_reason(report)}")


FIXTURE_PARTS = {"vllm_server": "vllm", "rendering": "render", "browser": "browser", "shared_data": "shared"}
"""A test that uses one of these fixtures needs that optional part (its marker is added at collection)."""


VLLM_TESTS = "tests/agents/llm/vllm/"
"""The live vLLM server's tests: one unit of work, so one worker starts that server once."""


def work_unit(nodeid: str) -> str:
    """The unit of work of a test under pytest-xdist: its file, or the vLLM folder."""
    return VLLM_TESTS if nodeid.startswith(VLLM_TESTS) else nodeid.split("::", 1)[0]


HEAVY_UNITS = (
    "tests/agents/test_agents.py", "tests/sweep/test_sweep.py", "tests/agents/llm/test_tandem.py", VLLM_TESTS,
    "tests/sim/test_sim.py", "tests/evaluate/test_buckets.py", "tests/devices/test_processes.py",
    "tests/sweep/test_sweep_llm.py", "tests/evaluate/test_hostloop.py", "tests/evaluate/test_recovery.py",
    "tests/sim/test_sharding.py",
    "tests/test_notebooks.py", "tests/build/test_build_workers.py",
)
"""The units of work that take longest on the 2-core CI machine, longest
first: they are handed out before the others, so the run does not end with
one worker on a long file while the other waits."""


def pytest_collection_modifyitems(config, items):
    """Marks each test with the optional parts its fixtures need, and puts
    the tests of :data:`HEAVY_UNITS` first (in that order; the rest keep theirs)."""
    rank = {unit: i for i, unit in enumerate(HEAVY_UNITS)}
    items.sort(key=lambda item: rank.get(work_unit(item.nodeid), len(rank)))
    for item in items:
        for fixture, marker in FIXTURE_PARTS.items():
            if fixture in getattr(item, "fixturenames", ()) and not item.get_closest_marker(marker):
                item.add_marker(getattr(pytest.mark, marker))


def pytest_xdist_make_scheduler(config, log):
    """Whole files to a worker (:func:`work_unit`): a file's module fixtures
    and the programs its tests compile stay in one process. Units are handed
    out in collection order, the next to whichever worker runs short."""
    from xdist.scheduler import LoadScopeScheduling

    class FileScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return work_unit(nodeid)

    return FileScheduling(config, log)


def pytest_runtest_logreport(report):
    """Counts the outcome of every test of an optional part (in the controller under xdist too)."""
    if report.when == "call" or (report.when == "setup" and not report.passed):
        for marker in OPTIONAL_PARTS:
            if marker in report.keywords:
                outcome = "xfailed" if hasattr(report, "wasxfail") else report.outcome
                counts = _PART_COUNTS[marker]
                counts[outcome] = counts.get(outcome, 0) + 1


def pytest_terminal_summary(terminalreporter):
    """One line: how many tests of each optional part passed, failed or skipped."""
    if getattr(terminalreporter.config, "workerinput", None) is not None:
        return  # an xdist worker: the controller prints the line
    parts = []
    for marker, name in OPTIONAL_PARTS.items():
        counts = _PART_COUNTS[marker]
        text = ", ".join(f"{n} {k}" for k, n in sorted(counts.items())) or "none ran"
        parts.append(f"{name}: {text}")
    terminalreporter.write_line("optional parts" + (" (CI=true: skips fail)" if IN_CI else "") + ": "
                                + "; ".join(parts))
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
def rendering() -> tuple[str, ...]:
    """The rendering backends that work here (``"warp"``, ``"egl"``), or a
    skip naming why neither does (a failure under CI)."""
    from ignjax.sim.views.config import egl_available, warp_available

    problems = {"warp": warp_available(), "egl": egl_available()}
    backends = tuple(name for name, problem in problems.items() if problem is None)
    if not backends:
        pytest.skip("no rendering backend: " + "; ".join(f"{k}: {v}" for k, v in problems.items()))
    return backends


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
