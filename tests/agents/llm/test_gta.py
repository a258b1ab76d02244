"""``gta`` is our reading of GTA: Planner and Grounder without Spatial
Memory, which is ``tandem-no-spmem``. README: "``gta`` therefore sends
exactly the requests of ``tandem-no-spmem`` (the response cache serves one
from the other)". Both agents run in one ``python -m ignjax.evaluate`` (in
process) against the scripted server (a real HTTP server on 127.0.0.1; its
schema-valid replies are computed from the request text), sharing the run's
response cache."""

from __future__ import annotations

import json
from pathlib import Path

from ignjax.agents.llm.serve import ScriptedServer
from ignjax.evaluate.cli import main as evaluate
from ignjax.evaluate.outcomes import read_outcomes

ROOT = Path(__file__).resolve().parents[3]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
AGENTS = ("gta", "tandem-no-spmem")
SAME = ("episode", "step", "role", "request_hash", "prompt", "images", "reply", "action", "error")
"""What each model call of the two transcripts must share (not the agent's name, latency or cache hit)."""


def _calls(out: Path, agent: str) -> list[dict]:
    lines = (out / "transcripts" / f"{agent}.jsonl").read_text().splitlines()
    return [{**{k: c[k] for k in SAME}, "retries": [r["request_hash"] for r in c["retries"]]}
            for c in map(json.loads, lines)]


def _outcome_rows(out: Path, agent: str) -> list[dict]:
    skip = {"agent", "requests", "cache_hits", "model_latency_s", "cost_usd"}  # cost: NaN without prices
    return [{k: v for k, v in r.items() if k not in skip} for r in read_outcomes(out / "outcomes.csv")
            if r["agent"] == agent]


def test_gta_sends_the_requests_of_tandem_without_spatial_memory(rendering, tmp_path):
    out = tmp_path / "run"
    argv = ["--episodes", str(EPISODES), "--limit", "2", "--llm-batch", "2", "--set", "sim.max_steps=4",
            "--set", "views.size=64", "--out", str(out), "--quiet"]
    with ScriptedServer() as srv:
        url = srv.base_url
        assert evaluate(argv + ["--llm-endpoint", url, "--llm-model", srv.model]
                        + [a for name in AGENTS for a in ("--agent", name)]) == 0
        sent = srv.stats()["requests"]
    gta, tandem = (_calls(out, a) for a in AGENTS)
    # the same requests, call for call (the hash covers model, settings, schema, messages and images)
    # (and the same decisions of the controller, such as the early-question schedule's, which send nothing)
    assert {"planner", "grounder"} <= {c["role"] for c in gta} <= {"planner", "grounder", "controller"} and gta == tandem
    # the first agent's requests reached the server; the second's were all answered from the cache
    run = json.loads((out / "run.json").read_text())
    assert run["image_size"] == 64  # the views the agents were shown (views.size)
    totals = run["model_totals"]
    assert totals["gta"]["requests"] == sent > 0 and totals["gta"]["cache_hits"] == 0
    assert totals["tandem-no-spmem"]["requests"] == 0 and totals["tandem-no-spmem"]["cache_hits"] == sent
    assert _outcome_rows(out, "gta") == _outcome_rows(out, "tandem-no-spmem")
