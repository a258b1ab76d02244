"""Metrics against a plain-Python reference on hand-built outcome tables."""

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.evaluate import metrics as M
from ignjax.sim.types import OutcomeRow


def _reference(rows, thresholds, costs, require_stop=False):
    """Straightforward per-episode loop, written independently of metrics.py
    (success by the paper's rule, the final distance alone, unless require_stop)."""
    out = {}
    n = len(rows)
    for t in thresholds:
        succ = [(r["d"] <= t) and (r["stop"] or not require_stop) for r in rows]
        out[f"SR@{t}"] = sum(succ) / n
        out[f"OSR@{t}"] = sum(r["dmin"] <= t for r in rows) / n
        tot = 0.0
        for r, s in zip(rows, succ):
            charge = 0.0
            for qtype, count in enumerate(r["q"]):
                for _ in range(count):  # every question charged, repeats included
                    charge += costs[qtype]
            tot += (1.0 if s else 0.0) * math.exp(-charge)
        out[f"WSR@{t}"] = tot / n
    out["NE"] = sum(r["d"] for r in rows) / n
    out["TL"] = sum(r["tl"] for r in rows) / n
    out["Q"] = [sum(r["q"][k] for r in rows) / n for k in range(4)]
    out["|Q|"] = sum(sum(r["q"]) for r in rows) / n
    return out


def _table(rows):
    return OutcomeRow.from_numpy(
        final_distance=np.array([r["d"] for r in rows]), min_distance=np.array([r["dmin"] for r in rows]),
        path_length=np.array([r["tl"] for r in rows]), stopped=np.array([r["stop"] for r in rows]),
        n_questions=np.array([r["q"] for r in rows]), difficulty=np.array([r["bin"] for r in rows]))


ROWS = [
    # success at all thresholds, no questions -> WSR = SR
    dict(d=0.3, dmin=0.2, tl=5.0, stop=True, q=[0, 0, 0, 0], bin=0),
    # success at 1.5/3, with repeated questions
    dict(d=1.2, dmin=0.4, tl=8.0, stop=True, q=[2, 1, 3, 1], bin=1),
    # close but did not stop -> not a success when STOP is required
    dict(d=0.1, dmin=0.1, tl=3.0, stop=False, q=[0, 1, 0, 0], bin=1),
    # failure with many questions -> 0 whatever it asked
    dict(d=6.0, dmin=2.5, tl=12.0, stop=True, q=[1, 1, 1, 7], bin=2),
    dict(d=2.9, dmin=2.9, tl=9.5, stop=True, q=[0, 0, 1, 0], bin=2),
]


@pytest.mark.parametrize("require_stop", [True, False])
def test_summary_equals_reference(require_stop):
    thr, costs = (0.5, 1.5, 3.0), M.LOCKED_COSTS
    ref = _reference(ROWS, thr, costs, require_stop)
    s = M.summarize(_table(ROWS), thr, costs, require_stop)
    for i, t in enumerate(thr):
        assert s["SR"][i] == pytest.approx(ref[f"SR@{t}"])
        assert s["OSR"][i] == pytest.approx(ref[f"OSR@{t}"])
        assert s["WSR"][i] == pytest.approx(ref[f"WSR@{t}"])
    assert s["NE"] == pytest.approx(ref["NE"]) and s["TL"] == pytest.approx(ref["TL"])
    np.testing.assert_allclose(s["Q"], ref["Q"])
    assert s["Q_total"] == pytest.approx(ref["|Q|"])


def test_wsr_reduces_to_sr_without_questions_and_lies_in_unit_interval():
    rows = [dict(r, q=[0, 0, 0, 0]) for r in ROWS]
    s = M.summarize(_table(rows))
    np.testing.assert_allclose(s["WSR"], s["SR"])
    s2 = M.summarize(_table(ROWS))
    assert np.all(s2["WSR"] <= s2["SR"]) and np.all(s2["WSR"] >= 0)


def test_groups_by_difficulty_equal_reference_on_subsets():
    s = M.summarize(_table(ROWS), groups=np.array([r["bin"] for r in ROWS]), n_groups=3)
    for g in range(3):
        sub = [r for r in ROWS if r["bin"] == g]
        ref = _reference(sub, (0.5, 1.5, 3.0), M.LOCKED_COSTS)
        assert s["count"][g] == len(sub)
        assert s["WSR"][g, 1] == pytest.approx(ref["WSR@1.5"])
        assert s["Q_total"][g] == pytest.approx(ref["|Q|"])


def test_masked_rows_are_ignored():
    t = _table(ROWS + [dict(d=0.0, dmin=0.0, tl=0.0, stop=True, q=[9, 9, 9, 9], bin=0)])
    t = dataclasses.replace(t, valid=np.array([True] * len(ROWS) + [False]))
    a, b = M.summarize(t), M.summarize(_table(ROWS))
    for k in a:
        np.testing.assert_allclose(a[k], b[k])


def test_batched_costs_under_vmap_match_loop():
    rng = np.random.default_rng(0)
    costs = rng.uniform(0, 0.5, (16, 4))
    tj = jax.tree.map(jnp.asarray, _table(ROWS))
    batched = jax.jit(jax.vmap(lambda w: M.summarize(tj, costs=w)["WSR"]))(jnp.asarray(costs, jnp.float32))
    for k in range(16):
        ref = _reference(ROWS, (0.5, 1.5, 3.0), costs[k])
        np.testing.assert_allclose(np.asarray(batched[k]), [ref["WSR@0.5"], ref["WSR@1.5"], ref["WSR@3.0"]], rtol=1e-5)
    # the (K, 4) cost form of question_discount gives the same numbers without vmap
    disc = M.question_discount(np.array([r["q"] for r in ROWS]), costs)
    assert disc.shape == (16, len(ROWS))


def test_table1_lists_every_paper_column():
    row = M.metric_row(_table(ROWS))
    text = M.table1({"agent": row})
    for col in M.TABLE1_COLUMNS:  # a "|" in a column name is escaped, so the table keeps its shape
        assert M.md_cell(col) in text
    assert all(line.count(" | ") == len(M.TABLE1_COLUMNS) for line in text.splitlines() if not line.startswith("|-"))
    assert f"{row['WSR@1.5']:.1f}" in text


def test_success_distance_option_switches_the_final_distance():
    """metric_rows(distance=...) judges success on the geodesic (default) or
    the Euclidean final distance; OSR keeps the geodesic minimum."""
    from ignjax.evaluate.outcomes import metric_rows

    base = dict(agent="a", episode_id="e", scene_id="s", difficulty="easy", min_distance=2.0, path_length=3.0, steps=5,
                stopped=True, stop_reason="stop", q1=0, q2=0, q3=0, q4=0, n_questions=0, n_refused=0, n_invalid=0, trace="")
    rows = [dict(base, final_distance=2.0, final_euclidean=1.0),  # around a wall: far by path, near in a line
            dict(base, final_distance=1.2, final_euclidean=1.1),
            dict(base, final_distance=4.0, final_euclidean=3.5)]
    geo = metric_rows(rows, thresholds=(1.5,))["a"]
    euc = metric_rows(rows, thresholds=(1.5,), distance="euclidean")["a"]
    assert geo["SR@1.5"] == pytest.approx(100 / 3) and euc["SR@1.5"] == pytest.approx(200 / 3)
    assert geo["NE"] == pytest.approx(7.2 / 3) and euc["NE"] == pytest.approx(5.6 / 3)
    assert geo["OSR@1.5"] == euc["OSR@1.5"] == 0.0
