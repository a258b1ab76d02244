"""The ``llm`` block of ``python -m ignjax.bench --llm`` (:mod:`ignjax.bench.llm`):
every figure it documents, and the arithmetic of the derived ones.

The block runs as the command runs it, only small: 4 episodes of the
shipped benchmark, 2 server slots (so 4 episodes in flight), 64 px views and
a 10 ms scripted server (a real HTTP server on 127.0.0.1). The ``vllm``
figures need the vLLM environment, so their arithmetic is checked on given
numbers (:func:`ignjax.bench.llm.vllm_figures`), as is the scripted runs'
(:func:`ignjax.bench.llm.scripted_figures`) on both sides of ``limited_by``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from ignjax.bench.llm import DECISIONS, EPISODES_PER_SLOT, bench_llm, scripted_figures, vllm_figures
from ignjax.episodes.dataset import load_benchmark

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
CONCURRENCY, LATENCY, SIZE = 2, 0.01, 64
RUNS = ("host", "batched", "sequential")


def _close(a, b) -> bool:
    return math.isclose(a, b, rel_tol=1e-12)


@pytest.fixture(scope="module")
def block(rendering):
    es = load_benchmark(EPISODES, limit=2 * CONCURRENCY)
    return bench_llm(es, quick=True, latency=LATENCY, concurrency=CONCURRENCY, size=SIZE, vllm=False)


def test_block_fields(block):
    """Each documented figure, with the run's settings and counts: every
    episode is DECISIONS decisions long, in every run."""
    assert block["concurrency"] == CONCURRENCY and block["latency_s"] == LATENCY
    assert block["views"] == 8 and block["size"] == SIZE and block["decisions_per_episode"] == DECISIONS
    episodes = {"batched": 2 * CONCURRENCY, "sequential": 1}  # quick: two episodes per slot, one alone
    assert block["episodes"] == episodes
    assert block["episodes_in_flight"] == {"batched": EPISODES_PER_SLOT * CONCURRENCY, "sequential": 1}
    assert block["decisions"] == {"host": episodes["batched"] * DECISIONS, "batched": episodes["batched"] * DECISIONS,
                                  "sequential": DECISIONS}
    assert set(block["wall_s"]) == set(RUNS) and all(block["wall_s"][k] > 0 for k in RUNS)
    assert set(block["episodes_per_hour"]) == {"batched", "sequential"}
    assert 1 <= block["max_in_flight"] <= CONCURRENCY
    # mean requests in flight over the concurrency: above 0, and at most the most in flight
    assert 0 < block["utilisation"] <= block["max_in_flight"] / CONCURRENCY
    assert block["limited_by"] in ("server", "host")
    assert set(block["vllm"]) == {"skipped"}
    assert json.loads(json.dumps(block)) == block  # plain JSON values


def test_block_arithmetic(block):
    """Episodes per hour, the speedup, host milliseconds per decision and
    ``limited_by`` follow from the block's own episodes, decisions and wall times."""
    wall, eph = block["wall_s"], block["episodes_per_hour"]
    for k in ("batched", "sequential"):
        assert _close(eph[k], 3600.0 * block["episodes"][k] / wall[k]), k
    assert _close(block["speedup_vs_sequential"], eph["batched"] / eph["sequential"])
    assert _close(block["host_ms_per_decision"], 1000.0 * wall["host"] / block["decisions"]["host"])
    host_rate, server_rate = 1000.0 / block["host_ms_per_decision"], CONCURRENCY / LATENCY
    assert block["limited_by"] == ("server" if host_rate >= server_rate else "host")


def test_scripted_figures_on_given_numbers():
    """200 decisions in 4 s of host time: 50 decisions/s, so 64 slots at 4 s
    (16/s) limit the run and 64 slots at 1 s (64/s) do not."""
    episodes, wall = {"batched": 128, "sequential": 1}, {"host": 4.0, "batched": 60.0, "sequential": 30.0}
    fig = scripted_figures(episodes, wall, {"host": 200}, concurrency=64, latency=4.0)
    assert fig["episodes_per_hour"] == {"batched": 7680.0, "sequential": 120.0}
    assert fig["speedup_vs_sequential"] == 64.0 and fig["host_ms_per_decision"] == 20.0
    assert fig["limited_by"] == "server"
    assert scripted_figures(episodes, wall, {"host": 200}, concurrency=64, latency=1.0)["limited_by"] == "host"
    assert scripted_figures(episodes, wall, {"host": 200}, concurrency=64, latency=0.0)["limited_by"] == "host"


def test_vllm_figures_on_given_numbers():
    """Decisions per second, their ratio and the mean seconds a request
    waited; a run without requests waited 0 s a request."""
    fig = vllm_figures({"batched": 60, "sequential": 8}, {"batched": 64, "sequential": 0},
                       {"batched": 32.0, "sequential": 0.0}, {"batched": 30.0, "sequential": 16.0})
    assert fig == {"request_s": {"batched": 0.5, "sequential": 0.0},
                   "decisions_per_s": {"batched": 2.0, "sequential": 0.5}, "speedup": 4.0}
