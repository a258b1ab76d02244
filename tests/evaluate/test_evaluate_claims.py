"""``python -m ignjax.evaluate`` against what it promises, checked from its
output files alone:

* each episode's randomness does not depend on the batch size: the same
  episodes in batches of 4 and of 7 give the same outcome rows (the
  ``random`` agent's actions are drawn from the episode keys);
* every column of ``metrics.csv`` is what its definition gives on
  ``outcomes.csv`` (recomputed here with plain numpy, not with
  :mod:`ignjax.evaluate.metrics`), under either success rule, selected on the
  command line (``--require-stop`` / ``--no-require-stop``).

Both runs evaluate the same 12 episodes of the test benchmark (4 per
difficulty): the paper's rule with two agents, one that never asks
(``random``) and one that asks often (``naive_asker``); the STOP rule with
``random`` alone (each further agent and batch size is one more compiled
rollout).
"""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from ignjax.episodes.schema import read_episodes, write_records
from ignjax.evaluate.cli import build_parser, main

THRESHOLDS = (0.5, 1.5, 3.0)
COSTS = (0.182, 0.162, 0.240, 0.103)
BINS = ("easy", "medium", "hard")
RUNS = {  # name -> (batch, flag selecting the success rule, the rule: success requires a STOP, agents)
    "batch4_paper_rule": (4, "--no-require-stop", False, ("random", "naive_asker")),
    "batch7_require_stop": (7, "--require-stop", True, ("random",)),
}


@pytest.fixture(scope="module")
def runs(small_benchmark, tmp_path_factory):
    root = tmp_path_factory.mktemp("eval_claims")
    records = read_episodes(small_benchmark["path"])
    picked = sorted(i for b in BINS for i in [k for k, r in enumerate(records) if r["difficulty"] == b][:4])
    episodes = root / "episodes.jsonl.gz"
    write_records(episodes, [records[k] for k in picked])
    out = {}
    for name, (batch, flag, require_stop, agents) in RUNS.items():
        argv = ["--episodes", str(episodes), "--scenes-root", str(small_benchmark["root"]), "--out", str(root / name),
                "--batch", str(batch), "--parts", "1", "--quiet", flag,
                "--thresholds", ",".join(f"{t:g}" for t in THRESHOLDS), "--costs", ",".join(f"{c:g}" for c in COSTS)]
        for a in agents:
            argv += ["--agent", a]
        assert main(argv) == 0
        out[name] = {"dir": root / name, "require_stop": require_stop, "agents": agents, "n": len(picked)}
    return out


def _read_csv(path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_the_success_rule_flags_exist():
    flags = {s for a in build_parser()._actions for s in a.option_strings}
    assert {"--require-stop", "--no-require-stop"} <= flags


def test_outcomes_do_not_depend_on_the_batch_size(runs):
    """Batches of 4 and of 7 (one piece each) put the episodes at other
    positions of other batches; every outcome row of the random agent (whose
    actions are drawn from the episode keys) is the same, byte for byte."""
    a, b = ([r for r in _read_csv(run["dir"] / "outcomes.csv") if r["agent"] == "random"] for run in runs.values())
    assert len(a) == len(b) == next(iter(runs.values()))["n"]
    for ra, rb in zip(a, b):
        assert ra == rb
    assert len({r["final_distance"] for r in a}) == len(a)  # the random agent went its own way in each episode
    assert len({r["stop_reason"] for r in a}) == 2  # some episodes stopped at random, others ran out of steps


def _recompute(rows: list[dict], require_stop: bool) -> dict[str, float]:
    """Every metric of one agent from its outcome rows (plain numpy):
    SR@tau = mean(success), success = final_distance <= tau (and stopped when
    required); OSR@tau = mean(min_distance <= tau); WSR@tau = mean(success *
    exp(-sum_t w_t q_t)); NE, TL, Q1..Q4, |Q| means; percentages for the
    rates; the same per difficulty, prefixed with the bin's name."""
    def block(rs: list[dict]) -> dict[str, float]:
        d = np.array([float(r["final_distance"]) for r in rs])
        dmin = np.array([float(r["min_distance"]) for r in rs])
        stopped = np.array([r["stopped"] == "True" for r in rs])
        q = np.array([[int(r[f"q{t}"]) for t in range(1, 5)] for r in rs], float)
        discount = np.exp(-(q * np.array(COSTS)).sum(1))
        m = {"episodes": float(len(rs))}
        for tau in THRESHOLDS:
            success = (d <= tau) & (stopped if require_stop else True)
            m[f"SR@{tau:g}"] = 100 * success.mean()
            m[f"OSR@{tau:g}"] = 100 * (dmin <= tau).mean()
            m[f"WSR@{tau:g}"] = 100 * (success * discount).mean()
        m["NE"] = d.mean()
        m["TL"] = np.mean([float(r["path_length"]) for r in rs])
        for t in range(4):
            m[f"Q{t + 1}"] = q[:, t].mean()
        m["|Q|"] = q.sum(1).mean()
        return m

    out = block(rows)
    for b in BINS:
        sub = [r for r in rows if r["difficulty"] == b]
        assert sub, f"no {b} episode"
        out.update({f"{b}.{k}": v for k, v in block(sub).items()})
    return out


@pytest.mark.parametrize("name", list(RUNS))
def test_every_metric_column_recomputes_from_the_outcomes(runs, name):
    run = runs[name]
    record = json.loads((run["dir"] / "run.json").read_text())
    assert record["require_stop"] is run["require_stop"]
    outcomes = _read_csv(run["dir"] / "outcomes.csv")
    with open(run["dir"] / "metrics.csv", newline="") as fh:
        reader = csv.DictReader(fh)
        columns = [c for c in reader.fieldnames if c != "agent"]
        table = {r["agent"]: r for r in reader}
    assert set(table) == set(run["agents"])
    assert any(int(r["n_questions"]) > 0 for r in outcomes) == ("naive_asker" in run["agents"])
    for agent in run["agents"]:
        expected = _recompute([r for r in outcomes if r["agent"] == agent], run["require_stop"])
        assert set(columns) == set(expected), sorted(set(columns) ^ set(expected))
        for c in columns:
            got = float(table[agent][c])
            assert math.isfinite(got)
            assert got == pytest.approx(expected[c], rel=1e-4, abs=1e-9), (agent, c)


def test_the_two_rules_differ_on_these_episodes(runs):
    """The runs score the same outcomes; the random agent ends some episodes
    within 3 m by the step budget, not by STOP, so SR@3 differs between the
    rules (the recomputation above is exercised on both)."""
    sr = {name: {r["agent"]: float(r["SR@3"]) for r in _read_csv(run["dir"] / "metrics.csv")} for name, run in runs.items()}
    by_rule = {RUNS[name][2]: sr[name]["random"] for name in RUNS}  # require_stop -> SR@3
    assert by_rule[False] > by_rule[True]
