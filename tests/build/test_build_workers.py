"""``--workers N`` of ``python -m ignjax.build scenes`` and ``episodes``.

Run as a user runs them (subprocesses): N worker processes must write the
same bytes as the serial default, refuse a bad count with one clear line,
and fail like the serial run when a scene fails in a worker (same error line,
same files left, no manifest or episode file, no staging leftovers).
"""

from __future__ import annotations

import json
import pickle

import pytest

from test_build_cli import assert_one_line_error, listing, run_build, stage_with_unresolved_assets


@pytest.fixture(scope="module")
def houses(tmp_path_factory) -> dict:
    """Three houses with maps, built with one and with two workers."""
    root = tmp_path_factory.mktemp("workers")
    procs = {}
    for n in (1, 2):
        procs[n] = run_build("scenes", "--out", root / f"s{n}", "--count", 3, "--seed", 11, "--maps",
                             "--workers", n, "--quiet")
        assert procs[n].returncode == 0, procs[n].stderr
    manifest = json.loads((root / "s1" / "manifest.json").read_text())
    return {"root": root, "procs": procs, "files": [root / "s1" / e["file"] for e in manifest["scenes"]]}


def test_scenes_two_workers_write_the_same_bytes(houses):
    one, two = listing(houses["root"] / "s1"), listing(houses["root"] / "s2")
    assert sorted(one) == sorted(two)  # every file, the manifest and maps included; no staging folder left
    assert "manifest.json" in one and sum(k.startswith("maps/") for k in one) == 3
    assert sum(k.endswith(".usda") for k in one) == 3
    assert one == two
    for n in (1, 2):
        assert "wrote 3 houses" in houses["procs"][n].stdout


def test_episodes_two_workers_write_the_same_bytes(houses):
    root = houses["root"]
    procs = {}
    for n in (1, 2):
        # sibling folders: the records store the scene files relative to their own folder
        procs[n] = run_build("episodes", "--scenes", root / "s1", "--out", root / f"e{n}" / "e.jsonl.gz",
                             "--subset", 12, "--seed", 3, "--starts", 2, "--workers", n, "--quiet")
        assert procs[n].returncode == 0, procs[n].stderr
    one, two = listing(root / "e1"), listing(root / "e2")
    assert sorted(one) == ["e.construction.jsonl.gz", "e.corpus.jsonl.gz", "e.jsonl.gz", "e.stats.png"]
    assert one == two  # the figure too
    assert procs[1].stdout.replace(str(root / "e1"), "E") == procs[2].stdout.replace(str(root / "e2"), "E")
    warn = [[ln for ln in procs[n].stderr.splitlines() if ln.startswith("warning: ")] for n in (1, 2)]
    assert warn[0] == warn[1]


def _stage_with_warnings(path):
    """A stage whose import warns (unresolved sublayer and references) and
    whose one room has no navigable cell (a warning of the build)."""
    return stage_with_unresolved_assets(path, 2)


def test_episodes_workers_warn_like_serial(tmp_path, houses):
    """Warnings raised in the workers (reading a scene, building its episodes)
    are printed by the command in scene order, as the serial run prints them."""
    odd = _stage_with_warnings(tmp_path / "busy.usda")
    procs = {}
    for n in (1, 2):
        procs[n] = run_build("episodes", "--scenes", odd, houses["files"][2], "--out", tmp_path / f"e{n}" / "e.jsonl.gz",
                             "--subset", 5, "--starts", 1, "--workers", n, "--quiet")
        assert procs[n].returncode == 0, procs[n].stderr
    assert "could not be resolved" in procs[1].stderr and "warning: scene busy:" in procs[1].stderr
    assert procs[1].stderr == procs[2].stderr
    assert listing(tmp_path / "e1") == listing(tmp_path / "e2")


@pytest.mark.parametrize("command", ["scenes", "episodes"])
@pytest.mark.parametrize("value", ["-1", "two"])
def test_bad_workers_is_one_clear_line(tmp_path, houses, command, value):
    out = tmp_path / "out"
    if command == "scenes":
        proc = run_build("scenes", "--out", out, "--count", 1, "--workers", value, "--quiet")
    else:
        proc = run_build("episodes", "--scenes", houses["files"][0], "--out", out / "e.jsonl.gz", "--workers", value,
                         "--quiet")
    if value == "two":  # argparse's own message: usage and one error line, status 2
        assert proc.returncode == 2 and "--workers" in proc.stderr and "invalid int value" in proc.stderr
    else:
        line = assert_one_line_error(proc, "--workers")
        assert "must be an integer >= 0" in line and "-1" in line
    assert not out.exists()


@pytest.mark.parametrize("bad_first", [False, True])
def test_episodes_worker_error_is_the_serial_error(tmp_path, houses, bad_first):
    """A scene file that fails to load (read in a worker) fails the command with
    the serial run's error; with two bad files, the first in order is named."""
    garbage = tmp_path / "broken.usda"
    garbage.write_text("this is not a USD layer\n")
    empty = tmp_path / "empty.usda"
    empty.write_text("")
    good = houses["files"]
    sources = [garbage, good[0], good[1], empty] if bad_first else [good[0], good[1], empty, good[2], garbage]
    first_bad = garbage if bad_first else empty
    before = listing(tmp_path)
    lines = {}
    for n in (1, 2):
        proc = run_build("episodes", "--scenes", *sources, "--out", tmp_path / f"e{n}" / "e.jsonl.gz",
                         "--subset", 5, "--workers", n, "--quiet")
        lines[n] = assert_one_line_error(proc, str(first_bad))
    assert lines[1] == lines[2]
    assert listing(tmp_path) == before  # nothing written, not even the output folders


def test_scenes_failure_leaves_what_the_serial_run_leaves(tmp_path):
    """House 1's file cannot be written (a folder holds its name): both runs
    fail naming it, keep house 0, write no manifest and leave no staging."""
    listings, lines = {}, {}
    for n in (1, 2):
        out = tmp_path / f"s{n}"
        (out / "house_4_001.usda").mkdir(parents=True)
        proc = run_build("scenes", "--out", out, "--count", 3, "--seed", 4, "--no-check", "--workers", n, "--quiet")
        lines[n] = assert_one_line_error(proc, str(out / "house_4_001.usda"), "cannot write")
        listings[n] = listing(out)
    assert sorted(listings[1]) == ["house_4_000.usda", "house_4_001.usda"]
    assert listings[1] == listings[2]


def test_input_errors_cross_processes_unchanged():
    from ignjax.errors import ConfigError, SceneError

    for e in (SceneError("/a/house.usda", "/World/Rooms", "bad floor"), ConfigError(None, "--workers", "must be >= 0")):
        back = pickle.loads(pickle.dumps(e))
        assert type(back) is type(e) and str(back) == str(e)
        assert (back.path, back.where, back.reason) == (e.path, e.where, e.reason)
