"""``gta``: TANDEM's machinery with GTA's distinguishing parts, a place graph
from the agent's own odometry (nodes merged within 0.8 m, visit counts, a
loop alert) and a Planner that weighs directions before choosing
(:mod:`ignjax.agents.llm.graph_memory`, :mod:`ignjax.agents.llm.counterfactual`).

The graph is checked on positions built here; the requests of ``gta`` and
``tandem-no-spmem`` on the same decisions; the reply parsing on hand-written
replies; and both agents end to end in one ``python -m ignjax.evaluate`` (in
process) against the scripted server (a real HTTP server on 127.0.0.1; its
schema-valid replies are computed from the request text)."""

from __future__ import annotations

import json
from pathlib import Path

from ignjax.agents.llm.agent import MOVE, Decision
from ignjax.agents.llm.catalog import get_llm_agent
from ignjax.agents.llm.messages import ImagePart
from ignjax.agents.llm.graph_memory import LOOP_VISITS, MERGE_M, PlaceGraph, graph_text
from ignjax.agents.llm.parse import parse_reply
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.agents.llm.tandem import TandemMemory
from ignjax.evaluate.cli import main as evaluate
from ignjax.evaluate.outcomes import read_outcomes

ROOT = Path(__file__).resolve().parents[3]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
AGENTS = ("gta", "tandem-no-spmem")
PANEL = ImagePart(b"\x89PNG panel bytes", "image/png")
PATH = [(0.0, 0.0), (1.5, 0.0), (1.6, 0.4), (3.0, 0.0), (1.5, 0.1), (0.2, 0.1), (1.4, -0.2), (0.1, 0.0), (1.5, 0.0)]
"""Offsets (east, north) of nine decisions: out along a corridor and back and forth between two places."""


def _decision(step: int, offset=(0.0, 0.0), **percept) -> Decision:
    p = {"open": [1.0] * 8, "odometry": list(offset), "room": 2, "known": [False] * 4, "goal_room": -1,
         "confirm": -1, "follow_up": 0, "hint_active": False, "hint_progress": 0, "blocked": [False] * 8}
    p.update(percept)
    return Decision(episode="e", step=step, max_steps=20, goal="laptop", questions_left=5,
                    costs=(0.182, 0.162, 0.24, 0.103), answers=(), last_move="", n_views=8, panel=PANEL, percept=p,
                    offset=tuple(offset))


def _walk(agent, path=PATH, **percept) -> tuple[TandemMemory, Decision]:
    """The agent's memory after one decision at each offset of ``path`` (each folded in as the host loop does)."""
    m = agent.start("e")
    d = None
    for step, pos in enumerate(path):
        d = _decision(step, pos, **percept)
        agent._observe_outcome(m, d)
    return m, d


def _reply(direction="front", weighed=("front", "left"), action="move", **extra) -> dict:
    r = {"reasoning": "", "task_phase": "explore", "action": action, "direction": direction,
         "subgoal": "the open doorway", "purpose": "look", "question_type": 1, "question": "?",
         "belief_update": {"current_room": "hall", "target_description": "", "visited_areas": [],
                           "unexplored_areas": [], "key_observations": []}}
    if weighed is not None:
        r["counterfactuals"] = [{"direction": k, "expected": f"what lies {k}"} for k in weighed]
    r.update(extra)
    return r


# ---------------------------------------------------------------------------
# the place graph
# ---------------------------------------------------------------------------


def test_graph_merges_positions_within_the_radius_and_counts_entries():
    g = PlaceGraph()
    assert g.visit((0.0, 0.0)) == 0
    assert g.visit((MERGE_M, 0.0)) == 0  # at the radius: the same place (entering nothing new)
    assert g.visit((0.0, MERGE_M + 0.01)) == 1  # just past it: a new place
    assert g.visit((0.0, 2.0)) == 2
    assert g.visit((0.3, 1.1)) == 1  # nearest node within the radius (P2 at 0.32 m, P3 at 0.95 m)
    assert g.visit((0.1, 0.9)) == 1  # staying in P2: no new visit
    assert g.visit((0.4, -0.3)) == 0  # back to P1
    assert g.positions == [(0.0, 0.0), (0.0, MERGE_M + 0.01), (0.0, 2.0)]  # nodes keep where they were founded
    assert g.visits == [2, 2, 1] and g.path == [0, 0, 1, 2, 1, 1, 0]
    assert g.edges == {(0, 1), (1, 2)} and g.neighbours(1) == [0, 2]


def test_loop_alert_exactly_when_the_visit_count_passes_the_threshold():
    g = PlaceGraph()
    a, b, c = (0.0, 0.0), (2.0, 0.0), (0.0, 2.0)
    seen = []
    for pos in (a, b, a, b, a, a, b, c):
        g.visit(pos)
        text = graph_text(g)
        seen.append((g.visits[g.current], "Loop alert" in text))
        assert ("Loop alert" in text) == g.loop == (g.visits[g.current] > LOOP_VISITS)
    assert LOOP_VISITS == 2
    assert seen == [(1, False), (1, False), (2, False), (2, False), (3, True), (3, True), (3, True), (1, False)]
    g.visit(a)  # a fourth entry into P1
    assert "Loop alert: you have entered P1 4 times" in graph_text(g) and "<- you are here" in graph_text(g)


def test_graph_lists_places_by_the_agents_own_offset_only():
    gta = get_llm_agent("gta")
    m, d = _walk(gta)
    text = gta.state_text(m, d)
    assert "Place graph" in text and "3 places, 2 links" in text
    assert m.graph.visits == [3, 4, 1] and m.graph.edges == {(0, 1), (1, 2)}
    assert "- P1: 0.0 m east, 0.0 m north of your start; visits 3; links P2" in text
    assert "- P2: 1.5 m east, 0.0 m north of your start; visits 4; links P1, P3  <- you are here" in text
    assert "- P3: 3.0 m east, 0.0 m north of your start; visits 1; links P2" in text
    assert "Loop alert: you have entered P2 4 times" in text
    # nothing of the scene: the same walk with other rooms, goal room and free space gives the same graph text
    m2, _ = _walk(gta, room=5, goal_room=3, open=[4.0] * 8)
    assert gta.memory_text(m2) == gta.memory_text(m)


# ---------------------------------------------------------------------------
# the requests of gta and tandem-no-spmem
# ---------------------------------------------------------------------------


def test_gta_and_tandem_without_spatial_memory_send_different_planner_requests():
    gta, spmem = (get_llm_agent(a) for a in AGENTS)
    (m1, d), (m2, _) = _walk(gta), _walk(spmem)
    r1, r2 = gta.planner_request(m1, d), spmem.planner_request(m2, d)
    assert r1.messages != r2.messages and r1.schema != r2.schema
    system1, system2 = (r.messages[0]["content"] for r in (r1, r2))
    user1, user2 = (r.messages[1]["content"][0] for r in (r1, r2))
    assert r1.messages[1]["content"][1] is r2.messages[1]["content"][1] is PANEL  # the same panel for both
    # GTA's parts: the place graph with its loop alert, and the counterfactual field and prompt block
    assert "Place graph" in user1 and "Loop alert" in user1 and "Place graph" not in user2
    assert "'counterfactuals'" in system1 and "counterfactuals" not in system2
    props, required = r1.schema["properties"], r1.schema["required"]
    assert "counterfactuals" in required and "counterfactuals" not in r2.schema["properties"]
    assert required.index("counterfactuals") < required.index("action")  # weighed before the choice
    assert list(props).index("counterfactuals") < list(props).index("action")
    item = props["counterfactuals"]["items"]
    assert props["counterfactuals"]["minItems"] == 2 and item["required"] == ["direction", "expected"]
    assert item["properties"]["direction"]["enum"] == props["direction"]["enum"]
    # what both share: the unified interface (Fact Base, runtime block, budgets, costs, the question types)
    for shared in ("Find the laptop.", "Fact Base:", "Offset from start: 1.5 m east", "questions left: 5",
                   "costs 0.240", "Movement history:"):
        assert shared in user1 + system1 and shared in user2 + system2
    assert {k: v for k, v in props.items() if k != "counterfactuals"} == r2.schema["properties"]
    naive = get_llm_agent("gta-naive")
    assert not naive.safeguards and not naive.show_costs and naive.counterfactual and naive.memory_style == "graph"


# ---------------------------------------------------------------------------
# reading the Planner's reply
# ---------------------------------------------------------------------------


def test_reply_parsing_accepts_a_gta_reply_and_corrects_one_without_counterfactuals():
    gta, spmem = (get_llm_agent(a) for a in AGENTS)
    m, d = _walk(gta, PATH[:1])
    schema = gta.planner_request(m, d).schema
    good = json.dumps(_reply("left", weighed=("front", "left", "right")))
    parsed, err = parse_reply(good, schema)
    assert err is None
    (act, _), why = gta._parse_plan(m, d, parsed, err)
    assert why is None and act[:2] == (MOVE, 2)  # a move to the left view
    # missing the field: the schema check names it, the agent answers with a correction that says so
    bad = json.dumps(_reply(weighed=None))
    parsed, err = parse_reply(bad, schema)
    assert parsed is None and "counterfactuals" in err
    value, why = gta._parse_plan(m, d, parsed, err)
    assert value is None and "counterfactuals" in why
    again = gta.correction(m, d, gta.planner_request(m, d), bad, why)
    assert again.schema == schema and "counterfactuals" in again.messages[-1]["content"]
    assert again.messages[-2] == {"role": "assistant", "content": bad}
    # what the schema cannot say: two different directions, and a move in a direction weighed
    for reply, says in ((_reply(weighed=("front", "front")), "at least 2 different directions"),
                        (_reply("rear", weighed=("front", "left")), "your move goes rear")):
        parsed, err = parse_reply(json.dumps(reply), schema)
        assert err is None and says in gta._parse_plan(m, d, parsed, err)[1]
    # an ask need not go in a weighed direction; the same reply without the field suits tandem-no-spmem
    parsed, err = parse_reply(json.dumps(_reply("rear", action="ask", question_type=2)), schema)
    assert gta._parse_plan(m, d, parsed, err)[1] is None
    plain = spmem.planner_request(m, d).schema
    parsed, err = parse_reply(bad, plain)
    assert err is None and spmem._parse_plan(m, d, parsed, err)[1] is None


# ---------------------------------------------------------------------------
# end to end
# ---------------------------------------------------------------------------


def _calls(out: Path, agent: str) -> list[dict]:
    return [json.loads(line) for line in (out / "transcripts" / f"{agent}.jsonl").read_text().splitlines()]


def test_gta_and_tandem_without_spatial_memory_end_to_end(rendering, tmp_path):
    out = tmp_path / "run"
    argv = ["--episodes", str(EPISODES), "--limit", "2", "--llm-batch", "2", "--set", "sim.max_steps=4",
            "--set", "views.size=64", "--out", str(out), "--quiet"]
    with ScriptedServer() as srv:
        assert evaluate(argv + ["--llm-endpoint", srv.base_url, "--llm-model", srv.model]
                        + [a for name in AGENTS for a in ("--agent", name)]) == 0
    gta, spmem = (_calls(out, a) for a in AGENTS)
    plan_gta, plan_spmem = ([c for c in calls if c["role"] == "planner"] for calls in (gta, spmem))
    assert plan_gta and plan_spmem
    # no Planner request of one is a request of the other; gta's carry its place graph and counterfactual block
    assert not {c["request_hash"] for c in plan_gta} & {c["request_hash"] for c in plan_spmem}
    assert all("Place graph" in c["prompt"] and "'counterfactuals'" in c["prompt"] for c in plan_gta)
    assert not any("Place graph" in c["prompt"] or "counterfactuals" in c["prompt"] for c in plan_spmem)
    assert "P1: 0.0 m east, 0.0 m north of your start" in plan_gta[0]["prompt"]
    run = json.loads((out / "run.json").read_text())
    assert run["model_totals"]["gta"]["requests"] > 0 and run["model_totals"]["tandem-no-spmem"]["requests"] > 0
    rows = [r for r in read_outcomes(out / "outcomes.csv") if r["agent"] == "gta"]
    assert len(rows) == 2  # both episodes ran to their end under gta
