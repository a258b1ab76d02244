"""``python -m ignjax.evaluate``: outcome tables in both formats, metrics
recomputed offline from either file, the question trace, and bad input."""

from __future__ import annotations

import csv
import dataclasses
import json
import math

import pytest

from ignjax.evaluate.cli import main
from ignjax.evaluate.outcomes import metric_rows, parse_trace, read_outcomes
from ignjax.sim.types import SimConfig


@pytest.fixture(scope="module")
def evaluated(small_benchmark, tmp_path_factory):
    out = tmp_path_factory.mktemp("eval")
    rc = main(["--episodes", str(small_benchmark["path"]), "--agent", "naive_asker", "--out", str(out),
               "--batch", "40", "--quiet"])
    assert rc == 0
    return out


def test_outcome_tables_agree_and_metrics_recompute(evaluated):
    rows_pq = read_outcomes(evaluated / "outcomes.parquet")
    rows_csv = read_outcomes(evaluated / "outcomes.csv")
    assert len(rows_pq) == len(rows_csv) == 40
    for a, b in zip(rows_pq, rows_csv):
        assert a["episode_id"] == b["episode_id"] and a["trace"] == b["trace"]
        assert a["final_distance"] == pytest.approx(b["final_distance"], abs=1e-5)
    with open(evaluated / "metrics.csv") as fh:
        table = {r["agent"]: r for r in csv.DictReader(fh)}
    for rows in (rows_pq, rows_csv):
        again = metric_rows(rows)["naive_asker"]
        for key in ("SR@1.5", "OSR@1.5", "WSR@1.5", "WSR@3", "|Q|", "NE", "TL", "easy.SR@1.5", "hard.|Q|"):
            assert float(table["naive_asker"][key]) == pytest.approx(again[key], rel=1e-4, abs=1e-4), key


def test_trace_matches_counts(evaluated):
    for r in read_outcomes(evaluated / "outcomes.csv"):
        events = parse_trace(r["trace"])
        charged = [t for t, _, ok in events if ok]
        assert [charged.count(t) for t in (1, 2, 3, 4)] == [r["q1"], r["q2"], r["q3"], r["q4"]]
        assert sum(1 for *_, ok in events if not ok) == r["n_refused"]
        steps = [s for _, s, _ in events]
        assert steps == sorted(steps) and all(0 <= s < r["steps"] for s in steps)


DOUBLE = "0.364,0.324,0.48,0.206"  # the locked costs x 2


@pytest.fixture(scope="module")
def configured(small_benchmark, tmp_path_factory):
    """eig and naive_asker charged twice the locked costs, eig with another
    threshold, success requiring a STOP; then the paper-reading settings."""
    out = tmp_path_factory.mktemp("eval_set")
    argv = ["--episodes", str(small_benchmark["path"]), "--batch", "40", "--quiet"]
    assert main(argv + ["--agent", "eig", "--agent", "naive_asker", "--out", str(out / "a"), "--costs", DOUBLE,
                        "--set", "agents.eig.threshold=2.0", "--require-stop"]) == 0
    assert main(argv + ["--agent", "explorer", "--agent", "naive_asker", "--out", str(out / "b"),
                        "--set", "sim.upfront_description=true", "--set", "sim.question_budget=false"]) == 0
    return out


def test_cost_aware_agent_plans_with_the_charged_costs(configured):
    run = json.loads((configured / "a" / "run.json").read_text())
    costs = [float(c) for c in DOUBLE.split(",")]
    assert run["costs"] == costs
    assert run["agents"]["eig"]["costs"] == pytest.approx(costs)  # planned = charged
    assert run["agents"]["eig"]["threshold"] == 2.0 and run["agents"]["naive_asker"]["threshold"] == 2.5
    assert run["require_stop"] is True and "explicit STOP" in run["success_rule"]
    assert set(run["sim"]) == {f.name for f in dataclasses.fields(SimConfig)}


def test_success_rule_both_ways(configured):
    """--require-stop counts only stopped episodes; the default (the paper's
    rule) counts every episode that ends close enough."""
    rows = read_outcomes(configured / "a" / "outcomes.csv")
    with open(configured / "a" / "metrics.csv") as fh:
        table = {r["agent"]: r for r in csv.DictReader(fh)}
    for agent in ("eig", "naive_asker"):
        mine = [r for r in rows if r["agent"] == agent]
        stop = 100 * sum(r["final_distance"] <= 1.5 and r["stopped"] for r in mine) / len(mine)
        paper = 100 * sum(r["final_distance"] <= 1.5 for r in mine) / len(mine)
        assert float(table[agent]["SR@1.5"]) == pytest.approx(stop, abs=1e-3)
        assert metric_rows(mine)[agent]["SR@1.5"] == pytest.approx(paper, abs=1e-6)
        assert metric_rows(mine, require_stop=True)[agent]["SR@1.5"] == pytest.approx(stop, abs=1e-6)


def test_paper_reading_settings(configured):
    """The description given and charged at reset (WSR = SR x exp(-(w1 + w2)))
    and an unbudgeted question protocol (nothing refused)."""
    rows = read_outcomes(configured / "b" / "outcomes.csv")
    run = json.loads((configured / "b" / "run.json").read_text())
    assert run["sim"]["upfront_description"] is True and run["sim"]["question_budget"] is False
    explorer = [r for r in rows if r["agent"] == "explorer"]
    assert all((r["q1"], r["q2"], r["q3"], r["q4"], r["trace"]) == (1, 1, 0, 0, "") for r in explorer)
    m = metric_rows(explorer)["explorer"]
    assert m["WSR@1.5"] == pytest.approx(m["SR@1.5"] * math.exp(-(0.182 + 0.162)), abs=1e-6)
    naive = [r for r in rows if r["agent"] == "naive_asker"]
    assert all(r["n_refused"] == 0 for r in naive) and all(r["q1"] >= 1 and r["q2"] >= 1 for r in naive)


def test_set_items_are_checked(capsys, small_benchmark, tmp_path):
    argv = ["--episodes", str(small_benchmark["path"]), "--agent", "eig", "--out", str(tmp_path / "o")]
    for item, words in (("eval.costs=[1,1,1,1]", "sweep's"), ("sim.nope=1", "sim.nope: unknown key"),
                        ("sim.miss_rate=2", "sim.miss_rate"), ("agents.eig.costs=[1,1,1,1]", "plans with the costs"),
                        ("agents.random.stop_prob=0.1", "not evaluated"), ("agents.eig.threshold=x", "expected a number")):
        assert main(argv + ["--set", item]) == 2
        assert words in capsys.readouterr().err, item
    assert not (tmp_path / "o").exists()


def test_bad_input(capsys, tmp_path, small_benchmark):
    assert main(["--episodes", str(tmp_path / "none.jsonl.gz"), "--agent", "random", "--out", str(tmp_path / "o")]) == 2
    assert "none.jsonl.gz" in capsys.readouterr().err
    assert main(["--episodes", str(small_benchmark["path"]), "--agent", "random", "--costs", "0.1,-1,0.1,0.1",
                 "--out", str(tmp_path / "o")]) == 2
    assert "--costs" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--episodes", str(small_benchmark["path"]), "--agent"])
    assert not (tmp_path / "o").exists()
