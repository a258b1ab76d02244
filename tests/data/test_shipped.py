"""The shipped benchmark as package data (ignjax.data.shipped): every file
matches its recorded hash, the repository's scenes/ is the same files, and a
damaged default stops a command with one line naming the file and the
rebuilding command (exit status 2), before any run folder is written."""

from __future__ import annotations

import gzip
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from ignjax.data import shipped
from ignjax.errors import InputError

ROOT = Path(__file__).resolve().parents[2]


def test_every_shipped_file_matches_its_recorded_hash_and_nothing_is_unrecorded():
    hashes = shipped.recorded_hashes()
    assert set(hashes) == {p.name for p in shipped.FOLDER.iterdir()}
    assert shipped.mismatches(shipped.FOLDER, hashes) == []
    assert {"benchmark.jsonl.gz", "manifest.json"} <= set(hashes)
    assert sum(name.endswith(".usda") for name in hashes) == shipped.SCENE_COUNT
    assert shipped.shipped_episodes() == shipped.EPISODES


def test_the_repository_scenes_folder_holds_the_package_data_byte_for_byte():
    repo = ROOT / "scenes"
    assert sorted(p.name for p in repo.iterdir()) == sorted(shipped.recorded_hashes())
    for name, digest in shipped.recorded_hashes().items():
        assert shipped.file_sha256(repo / name) == digest, name


@pytest.fixture
def damaged(tmp_path, monkeypatch):
    """A copy of the shipped benchmark standing in for the package data."""
    folder = tmp_path / "benchmark"
    shutil.copytree(shipped.FOLDER, folder)
    monkeypatch.setattr(shipped, "FOLDER", folder)
    monkeypatch.setattr(shipped, "EPISODES", folder / shipped.EPISODES.name)
    shipped._checked.cache_clear()
    yield folder
    shipped._checked.cache_clear()


def test_a_truncated_file_is_named_with_the_rebuilding_command(damaged):
    f = damaged / "house_0_003.usda"
    f.write_bytes(f.read_bytes()[:1000])
    with pytest.raises(InputError) as e:
        shipped.shipped_episodes()
    msg = str(e.value)
    assert "the shipped benchmark (package data)" in msg and "house_0_003.usda" in msg
    assert "truncated" in msg and shipped.REBUILD in msg and "\n" not in msg


def test_a_missing_episode_file_is_named(damaged):
    (damaged / "benchmark.jsonl.gz").unlink()
    with pytest.raises(InputError, match=r"benchmark\.jsonl\.gz: missing"):
        shipped.shipped_episodes()


def test_an_episode_file_from_another_version_differs(damaged):
    other = damaged / "benchmark.jsonl.gz"
    shutil.copy(damaged / "benchmark.corpus.jsonl.gz", other)  # a valid episode file, not the recorded one
    assert [m.partition(":")[0] for m in shipped.mismatches(damaged, shipped.recorded_hashes())] == ["benchmark.jsonl.gz"]


SWEEP_WITH_DAMAGED_DEFAULT = """
import sys
from pathlib import Path
from ignjax.data import shipped
folder = Path(sys.argv[1])
shipped.FOLDER, shipped.EPISODES = folder, folder / "benchmark.jsonl.gz"
from ignjax.sweep.cli import main
sys.exit(main(["--study", "eval", "--quick", "--out", sys.argv[2]]))
"""


def test_the_main_job_stops_on_a_damaged_default_before_writing_anything(damaged, tmp_path):
    (damaged / "benchmark.jsonl.gz").write_bytes(b"\x1f\x8b")  # a truncated gzip file
    out = tmp_path / "run"
    proc = subprocess.run([sys.executable, "-c", SWEEP_WITH_DAMAGED_DEFAULT, str(damaged), str(out)],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: the shipped benchmark (package data)"), proc.stderr
    assert "benchmark.jsonl.gz" in lines[0] and shipped.REBUILD in lines[0]
    assert not out.exists()


def _rewrite_episodes(src: Path, dst: Path, change) -> None:
    with gzip.open(src, "rt") as f:
        records = [json.loads(line) for line in f]
    change(records)
    with gzip.open(dst, "wt") as f:
        f.writelines(json.dumps(r) + "\n" for r in records)


def _first_float(record: dict) -> str:
    return next(k for k, v in record.items() if isinstance(v, float))


def test_a_rebuild_differing_only_by_rounding_holds_the_same_episodes(tmp_path):
    def round_off(records):
        k = _first_float(records[3])
        records[3][k] = records[3][k] * (1 + 1e-15) + 1e-300
    ours = tmp_path / "benchmark.jsonl.gz"
    _rewrite_episodes(shipped.EPISODES, ours, round_off)
    assert shipped.episode_differences(ours) == ([], 1)


def test_a_rebuild_with_another_target_differs(tmp_path):
    def retarget(records):
        records[7]["target_id"] = records[7]["target_id"] + "_other"
    ours = tmp_path / "benchmark.jsonl.gz"
    _rewrite_episodes(shipped.EPISODES, ours, retarget)
    diffs, _ = shipped.episode_differences(ours)
    assert len(diffs) == 1 and diffs[0].startswith("episode 7.target_id:")


@pytest.mark.slow
def test_build_default_writes_the_shipped_benchmark_again(tmp_path):
    """About 1.5 minutes on two cores: the 12 houses and 500 episodes, rebuilt and compared."""
    proc = subprocess.run([sys.executable, "-m", "ignjax.build", "default", "--out", str(tmp_path / "d"), "--workers",
                           "2", "--quiet"], capture_output=True, text=True, timeout=1200)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "holds the shipped benchmark" in proc.stdout
