"""The shipped benchmark (``scenes/benchmark.jsonl.gz``) is what the docs
(docs/getting-started.md, docs/scenes.md) say it is: 500 episodes in 12
houses, 150 / 200 / 150 easy / medium / hard (the protocol's 30:40:30), and every episode's difficulty score and bin are
:mod:`ignjax.episodes.difficulty` of its stored factors under the
protocol's alpha and thresholds; the factors themselves follow from the
construction file's counts, rho and start distance."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from ignjax.episodes import difficulty as dif
from ignjax.episodes.schema import construction_path, iter_records, read_episodes
from ignjax.protocol import BIN_INDEX, BIN_NAMES, DIFFICULTY_ALPHA, DIFFICULTY_THRESHOLDS, FACTOR_NAMES, SUBSET_PROPORTIONS

SCENES = Path(__file__).resolve().parents[2] / "scenes"
SHIPPED = SCENES / "benchmark.jsonl.gz"


@pytest.fixture(scope="module")
def records() -> list[dict]:
    assert SHIPPED.is_file(), f"the shipped benchmark {SHIPPED} is missing"
    return read_episodes(SHIPPED)


def test_size_split_and_houses(records):
    assert len(records) == 500
    counts = Counter(r["difficulty"] for r in records)
    assert counts == {"easy": 150, "medium": 200, "hard": 150}
    assert [counts[b] for b in BIN_NAMES] == [round(500 * p) for p in SUBSET_PROPORTIONS]
    scenes = {r["scene_id"]: r["scene_file"] for r in records}
    assert len(scenes) == 12
    for sid, name in scenes.items():
        assert (SCENES / name).is_file(), (sid, name)


def test_difficulty_recomputes_from_the_stored_factors(records):
    for r in records:
        assert tuple(r["alpha"]) == DIFFICULTY_ALPHA and tuple(r["thresholds"]) == DIFFICULTY_THRESHOLDS
    factors = np.array([[r["factors"][name] for name in FACTOR_NAMES] for r in records], np.float64)
    assert np.all((factors >= 0) & (factors <= 1))
    score = dif.difficulty_score(factors, DIFFICULTY_ALPHA)
    np.testing.assert_allclose(score, [r["difficulty_score"] for r in records], rtol=0, atol=1e-12)
    bins = dif.difficulty_bin(score, DIFFICULTY_THRESHOLDS)
    np.testing.assert_array_equal(bins, [BIN_INDEX[r["difficulty"]] for r in records])
    # the bins as docs/scenes.md ("Benchmark construction") words them: easy D < 0.30, medium < 0.60, hard otherwise
    manual = np.where(score < 0.30, 0, np.where(score < 0.60, 1, 2))
    np.testing.assert_array_equal(bins, manual)


def test_factors_recompute_from_the_construction_file(records):
    construction = {rec["episode_id"]: rec for _, rec in iter_records(construction_path(SHIPPED))}
    assert set(construction) == {r["episode_id"] for r in records}
    c = [construction[r["episode_id"]] for r in records]
    factors = dif.difficulty_factors(np.array([len(x["distractors"]) for x in c]),
                                     np.array([len(x["same_room_distractors"]) for x in c]),
                                     np.array([x["rho"] for x in c], np.float64),
                                     np.array([x["start_distance"] for x in c], np.float64))
    stored = np.array([[r["factors"][name] for name in FACTOR_NAMES] for r in records], np.float64)
    np.testing.assert_allclose(factors, stored, rtol=0, atol=1e-9)
