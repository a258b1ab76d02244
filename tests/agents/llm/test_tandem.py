"""TANDEM and the Table-1 baselines (:mod:`ignjax.agents.llm.tandem`).

The controller's rules are checked on hand-made decisions; the decision
paths end to end through the host loop against the scripted server (a real
HTTP server on 127.0.0.1; a test double whose replies are scripted from the
request text, here by a policy that plays a fixed script per turn); the
baselines' inputs against the server's schema-valid random replies; the
oracle's route hints over 10,000 answers across the shipped scenes."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.agents.llm.agent import ASK, MOVE, STOP, Decision, compass_degrees, orientation_text
from ignjax.agents.llm.catalog import LLM_AGENTS, get_llm_agent
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.scripted import request_text, scripted_reply
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.agents.llm.controller import CORRECTIONS
from ignjax.agents.llm.tandem import RECOVERY_MOVES, TandemMemory
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.scenes import vocab
from ignjax.sim import oracle_text as OT
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig

ROOT = Path(__file__).resolve().parents[3]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
VIEWS = ViewConfig(size=64)
render_ok = pytest.mark.usefixtures("rendering")


def _decision(step=3, questions_left=5, n_views=8, answers=(), last_move="", **percept):
    p = {"open": [1.0] * 8, "odometry": [0.0, 0.0], "room": 2, "known": [False] * 4, "goal_room": -1, "confirm": -1,
         "follow_up": 0, "hint_active": False, "hint_progress": 0, "blocked": [False] * 8}
    p.update(percept)
    return Decision(episode="e", step=step, max_steps=20, goal="laptop", questions_left=questions_left,
                    costs=(0.182, 0.162, 0.24, 0.103), answers=tuple(answers), last_move=last_move, n_views=n_views,
                    percept=p)


def _plan(action="move", direction="front", question_type=1, subgoal="the open doorway"):
    return {"reasoning": "", "task_phase": "explore", "action": action, "direction": direction, "subgoal": subgoal,
            "purpose": "look", "question_type": question_type, "question": "?",
            "belief_update": {"current_room": "hall", "target_description": "grey laptop", "visited_areas": ["hall"],
                              "unexplored_areas": ["left door"], "key_observations": ["a desk"]}}


# ---------------------------------------------------------------------------
# the controller's rules
# ---------------------------------------------------------------------------


def test_type1_and_type2_only_while_the_fact_is_missing():
    a = get_llm_agent("tandem")
    m = TandemMemory()
    assert a._check(m, _decision(), _plan("ask", question_type=1))[0] == (ASK, 0, 4, 1, 1)
    act, why = a._check(m, _decision(known=[True, False, False, False]), _plan("ask", question_type=1))
    assert act is None and "already in the Fact Base" in why
    assert a._check(m, _decision(known=[True, False, False, False]), _plan("ask", question_type=2))[0][4] == 2
    # the naive protocol has no such guard
    naive = get_llm_agent("tandem-naive")
    assert naive._check(m, _decision(known=[True] * 4), _plan("ask", question_type=1))[0] == (ASK, 0, 4, 1, 1)


KITCHEN, OFFICE = vocab.ROOM_LABEL_INDEX["kitchen"], vocab.ROOM_LABEL_INDEX["office"]


@pytest.mark.parametrize("percept, claim, allowed", [
    ({}, "", False),
    ({"open": [2.0, 2.0, 0.5, 0.5, 2.0, 0.5, 0.5, 0.5]}, "", True),  # branch: three open directions
    ({"open": [4.0, 0.5, 0.5, 0.5, 4.0, 0.5, 0.5, 0.5]}, "", True),  # long corridor
    ({"goal_room": OFFICE}, "", True),  # the oracle named the goal room; the agent does not say it is there
    ({"goal_room": OFFICE, "room": KITCHEN}, "a small study with a desk", False),  # it believes it is there
    # the gate reads the agent's belief, not the simulator's room code
    ({"goal_room": OFFICE, "room": OFFICE}, "the kitchen", True),
])
def test_route_questions_only_where_a_trigger_holds(percept, claim, allowed):
    a = get_llm_agent("tandem")
    act, why = a._check(TandemMemory(room_claim=claim), _decision(**percept), _plan("ask", question_type=3))
    assert (act is not None) == allowed, why
    if not allowed:
        assert why == CORRECTIONS["route"]


def test_route_question_after_a_loop():
    a = get_llm_agent("tandem")
    m = TandemMemory(positions=[(0.0, 0.0), (2.0, 0.0), (4.0, 0.0), (0.3, 0.2)])
    assert a._check(m, _decision(odometry=[0.3, 0.2]), _plan("ask", question_type=3))[0] == (ASK, 0, 4, 1, 3)


def test_follow_up_after_a_yes():
    a = get_llm_agent("tandem")
    m = TandemMemory()
    # "stop now": the controller stops without asking the model
    assert a._controller(m, _decision(confirm=1, follow_up=T.FOLLOW_STOP_NOW)) == (STOP, 0, 4, 1, 1)
    one = _decision(confirm=1, follow_up=T.FOLLOW_ONE_MOVE)
    assert a._controller(m, one) is None
    assert a._check(m, one, _plan("ask", question_type=2))[0] is None
    assert a._check(m, one, _plan("move", direction="rear"))[0] is None
    assert a._check(m, one, _plan("move", direction="front-left"))[0] == (MOVE, 1, 0, 0, 1)
    assert a._check(m, one, _plan("stop"))[0] == (STOP, 0, 4, 1, 1)  # confirmed: the stop has its evidence


def test_stop_policy_confirms_before_every_unconfirmed_stop():
    a = get_llm_agent("tandem")
    m = TandemMemory()
    assert a._check(m, _decision(), _plan("stop"))[0] == (ASK, 0, 4, 1, 4)
    assert a._check(m, _decision(hint_progress=T.HINT_STOP), _plan("stop"))[0] == (STOP, 0, 4, 1, 1)
    assert a._check(m, _decision(questions_left=0), _plan("stop"))[0] == (STOP, 0, 4, 1, 1)
    assert get_llm_agent("tandem-naive")._check(m, _decision(), _plan("stop"))[0] == (STOP, 0, 4, 1, 1)
    # after a "no": a stop at the same place is corrected (asking again would get the same answer) ...
    no = _decision(step=4, known=[True, True, False, True], confirm=0)
    m = TandemMemory(questions=[(3, 4, "")], moves=[(1, "front", "", False, "moved")])
    act, why = a._check(m, no, _plan("stop"))
    assert act is None and why == CORRECTIONS["stop_after_no"]
    m.moves.append((4, "left", "", False, "blocked"))  # a move that did not get anywhere changes nothing
    assert a._check(m, no, _plan("stop"))[0] is None
    # ... and after a move, the next stop is confirmed again: every stop, not only before the first Type 4
    m.moves.append((5, "front", "", False, "moved"))
    assert a._check(m, _decision(step=6, known=[True, True, False, True], confirm=0), _plan("stop"))[0] == (ASK, 0, 4, 1, 4)


def test_recovery_rule_asks_for_a_route_hint_when_far_by_what_the_agent_knows():
    a = get_llm_agent("tandem")
    m = TandemMemory(moves_since_hint=RECOVERY_MOVES - 1)
    assert a._controller(m, _decision(known=[True, True, False, False])) is None
    m.moves_since_hint = RECOVERY_MOVES
    d = _decision(known=[True, True, False, False], goal_room=OFFICE, room=OFFICE)
    assert a._controller(m, dataclasses.replace(d, percept={**d.percept, "hint_active": True})) is None
    assert a._controller(m, dataclasses.replace(d, questions_left=0)) is None
    # near the goal by what it knows: a confirmed target, a stop-eligible hint, or its own belief that it stands
    # in the goal room the oracle named (the simulator's room code above says so too, and is not what counts)
    assert a._controller(m, dataclasses.replace(d, percept={**d.percept, "confirm": 1})) is None
    assert a._controller(m, dataclasses.replace(d, percept={**d.percept, "hint_progress": T.HINT_STOP})) is None
    assert a._controller(TandemMemory(moves_since_hint=RECOVERY_MOVES, room_claim="the study"), d) is None
    assert a._controller(TandemMemory(moves_since_hint=RECOVERY_MOVES, room_claim="a hallway"), d) == (ASK, 0, 4, 1, 3)
    assert a._controller(m, d) == (ASK, 0, 4, 1, 3) and m.moves_since_hint == 0
    coin = get_llm_agent("coin")
    assert coin._controller(TandemMemory(moves_since_hint=RECOVERY_MOVES), _decision(known=[True] * 4)) is None


@pytest.mark.parametrize("turn, asked, costs, want", [
    (1, (), None, None),  # nothing is due at the first decision
    (2, (), None, 2),  # one of Type 1/2 by the second: the cheaper at the locked costs (Type 2)
    (2, (), (0.1, 0.2, 0.2, 0.1), 1),  # ... or under the costs in force
    (2, (1,), None, None),
    (4, (2,), None, None),
    (5, (2,), None, 1),  # both by the fifth
    (7, (1,), None, 2),  # still missing later: asked as soon as the controller may
    (5, (1, 2), None, None),
])
def test_early_question_schedule(turn, asked, costs, want):
    a = get_llm_agent("tandem")
    known = [t in asked for t in (1, 2)] + [False, False]
    d = _decision(step=turn - 1, known=known)
    if costs is not None:
        d = dataclasses.replace(d, costs=costs)
    assert a._controller(TandemMemory(), d) == (None if want is None else (ASK, 0, 4, 1, want))
    if want is not None:  # asked (a question in flight counts as asked), no budget, follow-up, naive, no QA: nothing
        assert a._controller(TandemMemory(questions=[(0, want, "")]), d) is None
        assert a._controller(TandemMemory(), dataclasses.replace(d, questions_left=0)) is None
        assert a._controller(TandemMemory(), dataclasses.replace(
            d, percept={**d.percept, "confirm": 1, "follow_up": T.FOLLOW_ONE_MOVE})) is None
        for name in ("tandem-naive", "tandem-no-qa"):
            assert get_llm_agent(name)._controller(TandemMemory(), d) is None


def _secret_checks(text: str) -> list[str]:
    """What a correction must not carry: a room's name, the agent's standing toward the goal room or the target,
    a distance, an instance id."""
    out = [f"room name {r!r}" for r in [vocab.ROOM_DISPLAY[label] for label in vocab.ROOM_LABELS] + ["study", "lounge"]
           if re.search(rf"\b{r}\b", text, re.I)]
    for name, pat in (("standing", r"\byou are (not |now |already )?(in|inside|near|close|far|next)\b|none applies|"
                                   r"not in it|elsewhere|\bin the goal room"),
                      ("distance", r"\d+(\.\d+)?\s*(m|cm|metres?|meters?)\b|\bmet(re|er)s?\b|distance|\bfar\b"),
                      ("instance id", r"\bobject \d|\binstance|\bid\b|\bhandle")):
        out += [f"{name}: {m.group(0)!r}" for m in re.finditer(pat, text, re.I)]
    return out


def test_corrections_tell_no_secrets():
    """Every correction the controller can say, produced by a decision that earns it, under percepts full of ground
    truth (the room the agent stands in, the goal room, free space, a position): the text is the catalogue's, says
    nothing the agent was not told, and a refused route question reads the same whatever the ground truth."""
    truth = {"room": OFFICE, "goal_room": OFFICE, "odometry": [3.5, -1.25], "open": [0.7] * 8}
    rear_last = TandemMemory(moves=[(2, "rear", "", True, "moved")])
    after_no = TandemMemory(questions=[(3, 4, "")])
    yes_closer = {"confirm": 1, "follow_up": T.FOLLOW_ONE_MOVE}
    cases = {
        "action": ("tandem", TandemMemory(), {}, _plan("wander")),
        "question_type": ("tandem", TandemMemory(), {}, _plan("ask", question_type=7)),
        "direction": ("tandem", TandemMemory(), {}, _plan("move", direction="up")),
        "subgoal": ("tandem", TandemMemory(), {}, _plan("move", subgoal="")),
        "no_questions": ("tandem-no-qa", TandemMemory(), {}, _plan("ask", question_type=1)),
        "no_route_questions": ("coin", TandemMemory(), {}, _plan("ask", question_type=3)),
        "budget": ("tandem", TandemMemory(), {"questions_left": 0}, _plan("ask", question_type=2)),
        "follow_up_ask": ("tandem", TandemMemory(), yes_closer, _plan("ask", question_type=4)),
        "known_fact": ("tandem", TandemMemory(), {"known": [False, True, False, False]}, _plan("ask", question_type=2)),
        "route": ("tandem", TandemMemory(room_claim="the office"), {}, _plan("ask", question_type=3)),
        "follow_up_rear": ("tandem", TandemMemory(), yes_closer, _plan("move", direction="rear")),
        "oscillation": ("tandem", rear_last, {}, _plan("move", direction="rear-right")),
        "stop_after_no": ("tandem", after_no, {"confirm": 0, "step": 4}, _plan("stop")),
    }
    assert set(cases) == set(CORRECTIONS), "give every correction a case here"
    for name, (agent, m, extra, plan) in cases.items():
        step, left = extra.pop("step", 3), extra.pop("questions_left", 5)
        act, why = get_llm_agent(agent)._check(m, _decision(step=step, questions_left=left, **{**truth, **extra}), plan)
        assert act is None and why.startswith(CORRECTIONS[name].split("{")[0]), (name, why)
        assert not _secret_checks(why), (name, why, _secret_checks(why))
    # the route refusal under other ground truth (another room, no goal room told, another place): the same words
    a = get_llm_agent("tandem")
    other = a._check(TandemMemory(), _decision(room=KITCHEN, odometry=[-2.0, 0.5]), _plan("ask", question_type=3))[1]
    assert other == CORRECTIONS["route"] == a._check(TandemMemory(room_claim="the office"), _decision(**truth),
                                                     _plan("ask", question_type=3))[1]
    # the checks catch what the old refusal said
    assert _secret_checks("when the goal room is known but you are not in it; none applies here")


def test_anti_oscillation():
    a = get_llm_agent("tandem")
    m = TandemMemory(moves=[(2, "rear", "", True, "moved")])
    act, why = a._check(m, _decision(), _plan("move", direction="rear-left"))
    assert act is None and "backward" in why
    assert a._check(m, _decision(), _plan("move", direction="left"))[0] == (MOVE, 2, 0, 0, 1)
    m.moves[-1] = (2, "rear", "", True, "blocked")
    assert a._check(m, _decision(), _plan("move", direction="rear-left"))[0] == (MOVE, 3, 0, 0, 1)
    # a move needs a place to go
    assert "subgoal" in a._check(m, _decision(), _plan("move", subgoal=""))[1]


def test_variants_restrict_what_may_be_asked():
    m = TandemMemory()
    trig = {"open": [2.0] * 8}
    assert "not available" in get_llm_agent("tandem-no-qa")._check(m, _decision(**trig), _plan("ask", question_type=1))[1]
    assert "route questions" in get_llm_agent("coin")._check(m, _decision(**trig), _plan("ask", question_type=3))[1]
    assert get_llm_agent("tandem-no-qa").sim_overrides == {"upfront_description": True}
    assert get_llm_agent("tandem-12v").sim_overrides == {"n_views": 12}
    assert set(LLM_AGENTS) >= {"vlm", "tandem", "tandem-no-spmem", "tandem-no-qa", "tandem-no-spmem-no-qa", "gta", "coin",
                               "mapgpt", "navgpt", "gta-naive", "coin-naive", "mapgpt-naive", "navgpt-naive",
                               "tandem-4v", "tandem-12v"}


def test_route_hint_mode_and_follow_up_reach_the_prompt():
    a = get_llm_agent("tandem")
    hint = "Take the way to your left; it leads toward the kitchen."
    # the hint as first spoken, where the hinted area lies now (the agent has turned: it said left, now right),
    # the progress, and the executor's report on the move itself
    d = _decision(answers=[(3, hint)], hint_active=True, hint_progress=T.HINT_CLOSER, hint_bearing=6,
                  last_move="you moved 1.2 m.")
    text = a.state_text(TandemMemory(), d)
    assert (f"Active route hint: {hint}\nWhere the hinted area lies now: to your right.\n"
            "Progress: You are getting closer to the area the last route hint pointed to.") in text
    assert "Last move: you moved 1.2 m." in text
    fresh = a.state_text(TandemMemory(), _decision(answers=[(3, hint)], hint_active=True, hint_bearing=2))
    assert "Where the hinted area lies now: to your left." in fresh and "Progress:" not in fresh
    reached = a.state_text(TandemMemory(), _decision(answers=[(3, hint)], hint_active=True,
                                                     hint_progress=T.HINT_REACHED, hint_bearing=4))
    assert "Where the hinted area lies now" not in reached and "Progress: You have reached" in reached
    for t in (text, fresh, reached):
        block = t.split("Active route hint: ")[1].split("\n\n")[0]
        assert not OT.route_leaks(block.replace(hint, "")), block
    # the single-stage VLM hears the same report as one line, beside the move's own
    vlm = get_llm_agent("vlm")
    report = OT.hint_report_text(T.HINT_CLOSER, 6)
    plain = vlm.state_text(vlm.start("e"), dataclasses.replace(d, hint_report=report))
    assert f"Last move: you moved 1.2 m.\n\nRoute hint: {report}" in plain and report.endswith("now to your right.")
    assert "Active route hint" not in a.state_text(TandemMemory(), _decision(answers=[(3, hint)]))  # expired hint
    follow = a.state_text(TandemMemory(), _decision(confirm=1, follow_up=T.FOLLOW_ONE_MOVE))
    assert "make one closer move, then stop" in follow


def test_spatial_memory_merges_belief_updates_unless_ablated():
    d = _decision()
    a = get_llm_agent("tandem")
    m = TandemMemory()
    a._merge(m, d, _plan())
    text = a.state_text(m, d)
    assert m.current_room == "hall" and m.visited == ["hall"] and "Spatial Memory" in text and "left door" in text
    b = get_llm_agent("tandem-no-spmem")
    m2 = TandemMemory()
    b._merge(m2, d, _plan())
    assert m2.current_room == "unknown" and "Spatial Memory" not in b.state_text(m2, d)
    assert m.room_claim == m2.room_claim == "hall"  # the controller reads where the agent thinks it is either way
    c = get_llm_agent("mapgpt")
    m3 = TandemMemory()
    c._merge(m3, d, _plan())
    assert "Places so far" in c.state_text(m3, d) and "step 3: hall" in c.state_text(m3, d)


# ---------------------------------------------------------------------------
# decision paths through the host loop
# ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def episodes():
    return load_benchmark(EPISODES, limit=2)


def _llm(srv, **kw):
    return LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, timeout_s=10.0, **kw)


SCRIPT = {1: _plan("ask", question_type=1), 2: _plan("ask", question_type=1),
          3: _plan("move", direction="left", subgoal="the open doorway"),
          4: _plan("move", direction="front-right", subgoal="the corner by the window"), 5: _plan("stop"), 6: _plan("stop")}
"""Planner replies per turn: T1; T1 again (refused by safeguard 1, corrected to T2); two moves; a stop without
evidence (turned into a confirmation); a stop right after the "no" (corrected, then a move)."""
CELLS = {"the open doorway": (1, 1), "the corner by the window": (8, 8), "the middle of the room": (4, 2)}
"""The Grounder's cells, by subgoal (grid corners)."""
CANDIDATE = (5, 4)
"""The Grounder's cell of a Type-4 question's candidate."""


def _grounded(req: dict, text: str) -> str | None:
    """The Grounder's reply: a navigation cell by subgoal, or the candidate cell; None for a Planner request."""
    name = req["response_format"]["json_schema"]["name"]
    if name == "candidate_cell":
        assert "Object to check:" in text
        return json.dumps({"col": CANDIDATE[0], "row": CANDIDATE[1], "rationale": "scripted"})
    if name == "grounder_cell":
        col, row = CELLS[re.search(r"Navigation instruction: (.*)", text).group(1).strip()]
        return json.dumps({"col": col, "row": row, "rationale": "scripted"})
    return None


def _script_policy(req: dict) -> str:
    text = request_text(req)
    if (grounded := _grounded(req, text)) is not None:
        return grounded
    turn = int(re.search(r"Turn (\d+) of", text).group(1))
    if "already in the Fact Base" in text:  # the correction after the repeated Type-1 question
        return json.dumps(_plan("ask", question_type=2))
    if CORRECTIONS["stop_after_no"] in text:  # the correction after a stop right after a "no"
        return json.dumps(_plan("move", direction="front", subgoal="the open doorway"))
    return json.dumps(SCRIPT[turn])


def test_compass_heading_and_offset_in_words():
    """The Planner's own heading (0 north = the scene's +y, 90 east = +x) and offset from the start, as the paper's
    runtime wrapper gives them; the simulator's yaw runs counter-clockwise from +x."""
    import math

    assert [compass_degrees(a) for a in (0.0, math.pi / 2, math.pi, -math.pi / 2)] == [90.0, 0.0, 270.0, 180.0]
    d = dataclasses.replace(_decision(), heading=compass_degrees(math.radians(-45.0)), offset=(2.26, -1.04))
    text = get_llm_agent("tandem").state_text(TandemMemory(), d)
    assert orientation_text(d) in text
    assert "Heading of your front view: 135 degrees (0 north, 90 east, 180 south, 270 west)" in text
    assert "Offset from start: 2.3 m east and 1.0 m south of your start." in text


@render_ok
def test_each_decision_path_end_to_end(episodes, tmp_path):
    es = episodes.subset([0])
    with ScriptedServer(policy=_script_policy) as srv:
        res = run_llm_agent(es, get_llm_agent("tandem"), _llm(srv), sim=T.SimConfig(max_steps=6), views=VIEWS, batch=1,
                            out=tmp_path, save_images=1)
        bodies = srv.stats()["requests"]
    calls = res.transcripts
    acts = [(c["step"], c["role"], c["action"]) for c in calls if c["action"] is not None]
    kinds = [a[2][0] for a in acts]
    # T1, T2 (after the correction), move, move, confirmation (the unconfirmed stop), then the final decision
    assert [a[2][4] for a in acts[:2]] == [1, 2] and kinds[:2] == [ASK, ASK]
    assert acts[2][2][:4] == [MOVE, 2, 1, 1] and acts[3][2][:4] == [MOVE, 7, 8, 8]  # view and the Grounder's cells
    assert acts[4][2] == [ASK, 0, *CANDIDATE, 4]  # the confirmation names the Grounder's candidate cell
    # the Planner's question texts reach the transcript; the stop turned into a confirmation has none
    assert [c["question"] for c in calls if c["action"] and c["action"][0] == ASK] == ["?", "?", ""]
    assert all("question" not in c for c in calls if c["action"] and c["action"][0] != ASK)
    assert acts[5][2][:2] == [MOVE, 0]  # the stop right after the "no", corrected into a move
    assert res.accounting["invalid_replies"].tolist() == [2]  # the repeated Type-1 question, that stop
    roles = [c["role"] for c in calls]
    assert roles.count("grounder") == 4 and bodies == res.accounting["requests"].sum()
    # the Grounder saw one image (the selected view, the front view for the candidate) and the subgoal; the
    # Planner the panel
    g = [c for c in calls if c["role"] == "grounder"]
    assert [len(c["images"]) for c in g] == [1, 1, 1, 1] and "Object to check:" in g[2]["prompt"]
    assert "the open doorway" in g[0]["prompt"] and "the corner by the window" in g[1]["prompt"]
    p = [c for c in calls if c["role"] == "planner"]
    assert all(len(c["images"]) == 1 for c in p)
    # the answers reach the Fact Base of later turns; questions are charged once each
    later = [c["prompt"] for c in p if c["step"] >= 2]
    assert all("appearance:" in t and "location:" in t for t in later)
    assert res.outcomes.n_questions[0].tolist()[:2] == [1, 1] and res.outcomes.n_questions[0][3] == 1
    # the runtime wrapper's heading and offset from the start: the start pose's, then the agent's own odometry
    yaw = es.records[0]["start"]["yaw"]
    assert f"Heading of your front view: {round(compass_degrees(yaw)) % 360} degrees" in p[0]["prompt"]
    assert "Offset from start: at your start." in p[0]["prompt"]
    after = [c["prompt"] for c in p if c["step"] > acts[3][0]]  # after two moves
    assert after and all(re.search(r"Offset from start: \d+\.\d m (east|west) and \d+\.\d m (north|south) of your start",
                                   t) for t in after)
    # Grounder images were saved beside the panels
    saved = sorted(x.name for x in (tmp_path / "images" / "tandem").rglob("*.jpg"))
    moved = [step for step, _, act in acts if act[0] == MOVE]
    assert {f"{step:03d}_grounder.jpg" for step in moved} <= set(saved) and any("panel" in n for n in saved)


HINT_SCRIPT = {1: _plan("ask", question_type=3), 2: _plan("move", direction="left"), 3: _plan("move", direction="left"),
               4: _plan("move", direction="front"), 5: _plan("move", direction="right")}
"""Planner replies per turn of a one-stage Planner that asks for a route hint, then turns and moves."""


def _hint_policy(req: dict) -> str:
    turn = int(re.search(r"Turn (\d+) of", request_text(req)).group(1))
    return json.dumps({**HINT_SCRIPT.get(turn, _plan("stop")), "col": 4, "row": 2})


def test_route_hint_direction_follows_the_agent_through_the_host_loop(episodes):
    """A text-only one-stage agent (no rendering) asks a route question, then turns and moves: each later Planner
    prompt shows the hint as first spoken and where the hinted area lies from the pose of that decision (the
    sector recomputed here from the trajectory's poses and the route's point, :func:`ignjax.sim.oracle.route_facts`),
    and the direction changes as the agent turns."""
    from ignjax.evaluate.runner import make_world
    from ignjax.sim import oracle as O

    es = episodes.subset([0])
    sim = T.SimConfig(max_steps=6)
    with ScriptedServer(policy=_hint_policy) as srv:
        res = run_llm_agent(es, get_llm_agent("navgpt-naive", observation="text"), _llm(srv), sim=sim, batch=1)
    acts = {c["step"]: c["action"] for c in res.transcripts if c["action"] is not None}
    assert acts[0][0] == ASK and acts[0][4] == 3 and [acts[s][0] for s in (1, 2, 3, 4)] == [MOVE] * 4
    pose = np.asarray(res.trajectories.pose[0], np.float64)
    spec = jax.tree.map(lambda a: a[0], es.specs)
    point = np.asarray(O.route_facts(make_world(es, sim), spec, jnp.asarray(pose[0], jnp.float32))[4], np.float64)
    prompts = {c["step"]: c["prompt"] for c in res.transcripts if c["role"] == "planner"}
    hint = prompts[1].split("Active route hint: ")[1].split("\n")[0]
    assert hint and "Active route hint" not in prompts[0]
    said = []
    for step in range(1, 6):
        rel = np.arctan2(point[1] - pose[step, 1], point[0] - pose[step, 0]) - pose[step, 2]
        sector = int(np.round(((rel + np.pi) % (2 * np.pi) - np.pi) / (np.pi / 4))) % 8
        progress = int(res.trajectories.hint_progress[0, step - 1])
        assert f"Active route hint: {hint}" in prompts[step]
        if progress in (T.HINT_REACHED, T.HINT_STOP):
            assert "Where the hinted area lies now" not in prompts[step]
            continue
        line = re.search(r"Where the hinted area lies now: (.*)\.", prompts[step]).group(1)
        assert line == OT.SECTOR_PHRASES[sector], (step, line, sector)
        said.append(line)
        if step > 1:
            assert f"Progress: {OT.hint_progress_text(progress)}" in prompts[step]
    assert len(said) >= 3 and len(set(said)) >= 2


SCHEDULE_SCRIPT = {1: _plan("move", direction="front", subgoal="the open doorway"),
                   3: _plan("move", direction="front-right", subgoal="the corner by the window"),
                   4: _plan("move", direction="left", subgoal="the open doorway"), 6: _plan("stop"), 7: _plan("stop"),
                   8: _plan("stop")}
"""Planner replies per turn of a Planner that never asks: moves, then stops (turns 2 and 5 belong to the schedule)."""


def _schedule_policy(req: dict) -> str:
    text = request_text(req)
    if (grounded := _grounded(req, text)) is not None:
        return grounded
    if CORRECTIONS["stop_after_no"] in text:  # a move that gets somewhere on this episode
        return json.dumps(_plan("move", direction="right", subgoal="the middle of the room"))
    return json.dumps(SCHEDULE_SCRIPT[int(re.search(r"Turn (\d+) of", text).group(1))])


@render_ok
def test_early_questions_and_every_unconfirmed_stop_end_to_end(episodes):
    """Against the scripted server, a Planner that never asks and keeps stopping: the controller asks Type 2 at
    the second decision and Type 1 at the fifth (the early-question schedule), turns each stop without
    confirmation into a Type-4 question (twice: every time, not only before the first), and corrects the stop
    that comes right after a "no" with no move since; the correction carries no secret."""
    with ScriptedServer(policy=_schedule_policy) as srv:
        res = run_llm_agent(episodes.subset([0]), get_llm_agent("tandem"), _llm(srv), sim=T.SimConfig(max_steps=8),
                            views=VIEWS, batch=1)
    calls = res.transcripts
    acts = {c["step"]: c["action"] for c in calls if c["action"] is not None}
    assert [(c["step"], c["action"]) for c in calls if c["role"] == "controller"] == [(1, [ASK, 0, 4, 1, 2]),
                                                                                     (4, [ASK, 0, 4, 1, 1])]
    planner_steps = {c["step"] for c in calls if c["role"] == "planner"}
    assert planner_steps == {0, 2, 3, 5, 6, 7}  # the schedule's questions need no model call
    assert acts[5] == [ASK, 0, *CANDIDATE, 4] and acts[7] == [ASK, 0, *CANDIDATE, 4]  # each unconfirmed stop confirmed
    assert acts[6][:4] == [MOVE, 6, 4, 2]  # the stop right after the "no": corrected, then a move (to the right)
    step6 = [c for c in calls if c["step"] == 6 and c["role"] == "planner"][0]
    assert [r["error"] for r in step6["retries"]] == [CORRECTIONS["stop_after_no"]]
    assert res.outcomes.n_questions[0].tolist() == [1, 1, 0, 2] and res.accounting["invalid_replies"].tolist() == [1]
    # the "no" was heard, and both facts reached the Planner's Fact Base after the schedule asked them
    assert "last confirmation: No" in step6["prompt"] and "appearance:" in step6["prompt"]
    assert "location:" in [c for c in calls if c["step"] == 2 and c["role"] == "planner"][0]["prompt"]
    assert not [e for c in calls for r in c["retries"] for e in [r["error"]] if _secret_checks(e)]


@render_ok
@pytest.mark.parametrize("name", ["tandem", "tandem-no-qa", "navgpt", "mapgpt", "gta", "tandem-4v", "tandem-12v"])
def test_baselines_send_what_they_should(episodes, name):
    """Schema-valid random replies from the scripted server: every episode
    finishes and each agent's requests carry its inputs."""
    seen = []

    def policy(req):
        seen.append(req)
        return scripted_reply(req)  # the server's default: a schema-valid instance

    with ScriptedServer(policy=policy) as srv:
        res = run_llm_agent(episodes.subset([1]), get_llm_agent(name), _llm(srv), sim=T.SimConfig(max_steps=4),
                            views=VIEWS, batch=1)
    assert set(res.outcomes.stop_reason.tolist()) <= {T.STOPPED, T.OUT_OF_STEPS}
    images = [sum(p.get("type") == "image_url" for m in r["messages"] if isinstance(m["content"], list)
                  for p in m["content"]) for r in seen]
    kinds = [r["response_format"]["json_schema"]["name"] for r in seen]
    planner = [r for r, k in zip(seen, kinds) if k == "planner_decision"]
    system = planner[0]["messages"][0]["content"]
    if name == "navgpt":  # text only: the Planner reads captions, each from one view's image (test_caption)
        assert [n for n, k in zip(images, kinds) if k == "planner_decision"] == [0] * len(planner)
        assert all(n == 1 for n, k in zip(images, kinds) if k == "view_caption") and "captioning model" in system
    else:
        assert all(n == 1 for n in images)
    if name in ("navgpt", "mapgpt"):
        assert "grounder_cell" not in kinds  # one stage: no Grounder
        assert "col" in planner[0]["response_format"]["json_schema"]["schema"]["properties"]
    if name == "gta":  # the place graph in every Planner request, the counterfactual field in its schema
        assert all("Place graph" in request_text(r) for r in planner)
        assert "counterfactuals" in planner[0]["response_format"]["json_schema"]["schema"]["required"]
    if name == "tandem-no-qa":
        enum = planner[0]["response_format"]["json_schema"]["schema"]["properties"]["action"]["enum"]
        assert "ask" not in enum and "cannot ask" in system
        assert all(k != ASK for k in res.trajectories.kind.ravel().tolist())
        assert (res.outcomes.n_questions[:, :2] == 1).all()  # the description, given at reset and charged
    views = {"tandem-4v": 4, "tandem-12v": 12}.get(name, 8)
    assert f"{views} camera views" in system or f"your {views} directions" in system
    if name != "navgpt":  # each view's own width: 90 degrees for 4 and 8 views, 30 for the 12 narrow ones
        assert f"each {30 if views == 12 else 90} degrees wide" in system


# ---------------------------------------------------------------------------
# the oracle's route hints in words
# ---------------------------------------------------------------------------


def test_route_hints_never_leak_over_10000_answers_across_the_shipped_scenes():
    from ignjax.episodes.schema import read_episodes
    from ignjax.evaluate.runner import make_world
    from ignjax.sim import oracle as O

    records = read_episodes(EPISODES)
    first = {}
    for i, r in enumerate(records):
        first.setdefault(r["scene_id"], i)
    es = load_benchmark(EPISODES, indices=sorted(first.values()))
    assert len(es.bank.scene_ids) == len(first) >= 10
    world = make_world(es, T.SimConfig())
    facts = jax.jit(jax.vmap(lambda spec, pose: O.route_facts(world, spec, pose)[:4]))
    rng = np.random.default_rng(0)
    texts = []
    n = len(es)
    free = [es.bank.navgrids[int(s)].navigable_points() for s in np.asarray(es.specs.scene)]
    k = np.repeat(np.arange(n), 256)
    specs = jax.tree.map(lambda a: a[k], es.specs)
    while len(texts) < 10_000:
        xy = np.stack([free[i][rng.integers(len(free[i]))] for i in k])
        poses = np.column_stack([xy, rng.uniform(-np.pi, np.pi, len(k))]).astype(np.float32)
        label, sector, landmark, in_room = jax.tree.map(np.asarray, facts(specs, poses))
        for j in range(len(k)):
            texts.append(OT.route_text(int(label[j]), int(sector[j]), int(landmark[j]), bool(in_room[j]),
                                       es.bank.categories, key=f"{len(texts)}"))
    leaks = [(t, OT.route_leaks(t)) for t in texts if OT.route_leaks(t)]
    assert not leaks, leaks[:3]
    assert len(set(texts)) > 100  # varied wording and facts, not one template


def test_dry_run_counts_before_sending(capsys):
    """``--dry-run`` answers from the episode file alone: no scene is loaded, no request sent (the endpoint does
    not even exist)."""
    from ignjax.evaluate.cli import main

    argv = ["--episodes", str(EPISODES), "--limit", "10", "--llm-endpoint", "http://127.0.0.1:9/v1", "--llm-model", "m",
            "--set", "sim.max_steps=5", "--set", "llm.prices={prompt = 1.0, completion = 2.0}", "--dry-run"]
    for a in ("tandem", "navgpt", "tandem-12v", "random"):
        argv += ["--agent", a]
    assert main(argv) == 0
    rows = {r["agent"]: r for r in map(json.loads, capsys.readouterr().out.splitlines())}
    t, n, v12 = rows["tandem"], rows["navgpt"], rows["tandem-12v"]
    assert t["planner_requests"] == t["grounder_requests"] == 50 and t["images"] == 100
    # navgpt: no Grounder, one caption request (and image) per view per decision
    assert n["grounder_requests"] == 0 and n["caption_requests"] == n["images"] == 400 and n["requests"] == 450
    assert n["prompt_tokens_per_caption_request"] > 0 and t["caption_requests"] == 0
    assert v12["prompt_tokens_per_planner_request"] > t["prompt_tokens_per_planner_request"]  # a larger panel
    assert t["cost_usd_at_most"] == pytest.approx((t["prompt_tokens"] + 2 * t["completion_tokens_at_most"]) / 1e6)
    assert rows["random"]["requests"] == 0
