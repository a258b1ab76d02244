"""``python -m ignjax.evaluate``: outcome tables in both formats, metrics
recomputed offline from either file, the question trace, and bad input."""

from __future__ import annotations

import csv

import pytest

from ignjax.evaluate.cli import main
from ignjax.evaluate.outcomes import metric_rows, parse_trace, read_outcomes


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


def test_bad_input(capsys, tmp_path, small_benchmark):
    assert main(["--episodes", str(tmp_path / "none.jsonl.gz"), "--agent", "random", "--out", str(tmp_path / "o")]) == 2
    assert "none.jsonl.gz" in capsys.readouterr().err
    assert main(["--episodes", str(small_benchmark["path"]), "--agent", "random", "--costs", "0.1,-1,0.1,0.1",
                 "--out", str(tmp_path / "o")]) == 2
    assert "--costs" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--episodes", str(small_benchmark["path"]), "--agent"])
    assert not (tmp_path / "o").exists()
