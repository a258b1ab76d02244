"""The report's sentences (:mod:`ignjax.sweep.sections`) are computed from
the tables: change the numbers and the sentence changes. Pure functions on
small made-up tables; the generated report is checked in test_sweep.py."""

from __future__ import annotations

import numpy as np

from ignjax.agents import registry
from ignjax.agents.params import param_values
from ignjax.evaluate.metrics import md_cell, md_table
from ignjax.sweep import sections as S


def _row(sr, wsr):
    return {"SR@1.5": sr, "WSR@1.5": wsr, "SR@0.5": sr / 2, "NE": 1.0}


def test_eval_finding_follows_the_numbers():
    m = {"a": _row(50.0, 20.0), "b": _row(30.0, 25.0), "oracle": _row(99.0, 99.0)}
    text = S.eval_finding(m, privileged={"oracle"})
    assert text.startswith("`a` has the highest SR@1.5 (50.0%), `b` the highest WSR@1.5 (25.0%)")
    assert "privileged `oracle` reaches 99.0%" in text
    m["b"] = _row(60.0, 25.0)
    assert S.eval_finding(m, privileged={"oracle"}).startswith("`b` has both the highest SR@1.5 (60.0%)")


def test_in_loop_findings_flag_a_type_whose_asking_rises():
    header = ["setting", "w1", "w2", "w3", "w4", "|Q|", "Q1", "Q2", "Q3", "Q4", "SR@1.5", "WSR@1.5"]
    rows = [["all x1", 0, 0, 0, 0, 2.0, 1.0, 0.5, 0.3, 0.2, 40.0, 30.0],
            ["all x2", 0, 0, 0, 0, 1.5, 0.2, 0.4, 0.3, 0.6, 35.0, 28.0],
            ["all x4", 0, 0, 0, 0, 0.0, 0.0, 0.0, 0.0, 0.0, 20.0, 20.0]]
    first, rise = S.in_loop_findings(header, rows, "eig")
    assert first.startswith("`eig` asks 2.00 questions per episode at x1") and "falling at every step" in first
    assert "Type 4 (confirmation) from 0.2 at x1 to 0.6 at x2" in rise and "Type 1" not in rise
    rows[1][5] = 2.5
    assert "not falling at every step" in S.in_loop_findings(header, rows, "eig")[0]
    rows[1][9] = 0.1
    assert len(S.in_loop_findings(header, rows, "eig")) == 1


def test_difficulty_derive_and_delta_u_sentences_follow_the_numbers():
    bins = [["a", 50.0, 40.0, 30.0], ["b", 20.0, 30.0, 10.0]]
    assert "1 of 2 agents are ordered" in S.difficulty_finding(0.25, 100, bins)
    bins[1][2] = 15.0
    assert "2 of 2 agents are ordered" in S.difficulty_finding(0.25, 100, bins)
    rows = [["locked", "", "", "", 0.182, 0.162, 0.24, 0.103, "3124", 0.0],
            ["given", 0.3, 0.3, 0.3, 0.2, 0.15, 0.24, 0.103, "3124", 0.02]]
    assert "keep the locked order" in S.derive_finding(rows) and "Type 3 route hint > Type 1" in S.derive_finding(rows)
    rows[1][8] = "1324"
    assert "do not all keep" in S.derive_finding(rows)
    du = {"delta_u": np.array([-0.5, 0.1, np.nan]), "area_before": np.array([4.0, 10.0, np.nan]),
          "area_after": np.array([6.0, 9.0, np.nan]), "mean_all": -0.2, "n_kept": 2}
    neg = S.delta_u_note(du)
    assert "7.0 m^2 before and 7.5 m^2 after" in neg and "unbounded below" in neg
    du["delta_u"], du["mean_all"] = np.array([0.5, 0.1, np.nan]), 0.3
    assert "unbounded below" not in S.delta_u_note(du)


def test_agents_list_only_the_parameters_they_read():
    """An agent that never asks lists no asking parameter; a declared parameter exists; an agent without a
    declaration lists all of its parameters."""
    for name, agent in registry().items():
        values = param_values(agent)
        assert agent.reads is None or set(agent.reads) <= set(values), name
        line = S.agent_line(name, values)
        assert line.startswith(f"- Agent `{name}`: {agent.description.rstrip('.')}.")
        shown = {k for k in values if f" {k}=" in line}
        assert shown == (set(values) if agent.reads is None else set(agent.reads)), name
    explorer = S.agent_line("explorer", param_values(registry()["explorer"]))
    assert "threshold" not in explorer and "recovery" not in explorer and "stop_range=1.0" in explorer
    assert "threshold" not in S.agent_line("naive_asker", param_values(registry()["naive_asker"]))


def test_markdown_cells_escape_pipes():
    assert md_cell("|Q|") == "\\|Q\\|" and md_cell(md_cell("|Q|")) == "\\|Q\\|" and md_cell(0.123456) == "0.1235"
    table = md_table(["a", "|Q|"], [["x|y", 1.0]])
    assert all(len(line.replace("\\|", "").split("|")) == 4 for line in table.splitlines())
