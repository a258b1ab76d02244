"""``coin`` and ``coin-naive``: TANDEM's machinery with COIN's distinguishing
parts, a self-check of the candidate (the Self-Questioner) and a rule that
skips the question when the self-check contradicts the Fact Base (the
Interaction Trigger; :mod:`ignjax.agents.llm.self_questioner`); ``coin``
without route questions, ``coin-naive`` with them.

The question types, the requests of ``coin-naive`` and ``tandem-naive`` and
the trigger's rule are checked on decisions and replies built here; the
decision paths end to end through the host loop against the scripted server
(a real HTTP server on 127.0.0.1; its replies are computed from the request
text by a policy that plays a fixed script per turn)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from ignjax.agents.llm import self_questioner as SQ
from ignjax.agents.llm.agent import ASK, MOVE, QUESTION_HELP, STOP, Decision
from ignjax.agents.llm.catalog import get_llm_agent
from ignjax.agents.llm.messages import ImagePart
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.controller import CORRECTIONS
from ignjax.agents.llm.scripted import request_text
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.agents.llm.tandem import Tandem, TandemMemory
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.sim import oracle_text as OT
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig

ROOT = Path(__file__).resolve().parents[3]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
VIEWS = ViewConfig(size=64)
PANEL = ImagePart(b"\x89PNG panel bytes", "image/png")
FRONT = ImagePart(b"\x89PNG front view", "image/png")
APPEARANCE = "A red fabric armchair with wooden legs, next to a floor lamp."


def _decision(step=3, answers=(), **percept) -> Decision:
    p = {"open": [1.0] * 8, "odometry": [0.0, 0.0], "room": 2, "known": [False] * 4, "goal_room": -1, "confirm": -1,
         "follow_up": 0, "hint_active": False, "hint_progress": 0, "blocked": [False] * 8}
    p.update(percept)
    return Decision(episode="e", step=step, max_steps=20, goal="armchair", questions_left=5,
                    costs=(0.182, 0.162, 0.24, 0.103), answers=tuple(answers), last_move="", n_views=8, panel=PANEL,
                    percept=p)


def _plan(action="move", direction="front", question_type=1, subgoal="the open doorway"):
    return {"reasoning": "", "task_phase": "explore", "action": action, "direction": direction, "subgoal": subgoal,
            "purpose": "look", "question_type": question_type, "question": "?",
            "belief_update": {"current_room": "hall", "target_description": "", "visited_areas": [],
                              "unexplored_areas": [], "key_observations": []}}


def _self_reply(*items) -> dict:
    """A Self-Questioner reply with ``items`` of (answer, certainty, relation)."""
    return {"description": "an armchair by the window",
            "self_questions": [{"question": f"q{i}", "answer": a, "certainty": c, "fact_base": r}
                               for i, (a, c, r) in enumerate(items)]}


# ---------------------------------------------------------------------------
# the question types of coin and coin-naive
# ---------------------------------------------------------------------------


def test_coin_forbids_route_questions_and_coin_naive_offers_them():
    coin, naive = get_llm_agent("coin"), get_llm_agent("coin-naive")
    assert coin.self_questions and naive.self_questions
    assert not coin.route_questions and coin.safeguards and coin.show_costs
    assert naive.route_questions and not naive.safeguards and not naive.show_costs
    m, d = TandemMemory(), _decision()
    enum = {name: a.planner_request(m, d).schema["properties"]["question_type"]["enum"]
            for name, a in (("coin", coin), ("coin-naive", naive))}
    assert enum == {"coin": [1, 2, 4], "coin-naive": [1, 2, 3, 4]}
    assert QUESTION_HELP[3] in naive.planner_system(d) and QUESTION_HELP[3] not in coin.planner_system(d)
    # a Type-3 ask: corrected for coin, taken by coin-naive (the naive protocol gates nothing)
    act, why = coin._check(m, d, _plan("ask", question_type=3))
    assert act is None and why == CORRECTIONS["no_route_questions"]
    assert naive._check(m, d, _plan("ask", question_type=3)) == ((ASK, 0, 4, 1, 3), None)


def test_coin_naive_and_tandem_naive_send_different_planner_requests():
    coin, tandem = get_llm_agent("coin-naive"), get_llm_agent("tandem-naive")
    m, d = TandemMemory(), _decision()
    r1, r2 = coin.planner_request(m, d), tandem.planner_request(m, d)
    assert r1.messages != r2.messages
    system1, system2 = r1.messages[0]["content"], r2.messages[0]["content"]
    # the one difference: COIN's self-check block in the system prompt; same state, panel and schema
    assert SQ.PROMPT in system1 and SQ.PROMPT not in system2
    assert system1.replace("\n\n" + SQ.PROMPT, "") == system2
    assert r1.messages[1] == r2.messages[1] and r1.schema == r2.schema
    assert get_llm_agent("coin").planner_request(m, d).messages != get_llm_agent("tandem").planner_request(m, d).messages
    with pytest.raises(ValueError, match="self_questions"):
        Tandem(self_questions=True, observation="text")


# ---------------------------------------------------------------------------
# the Self-Questioner and the Interaction Trigger
# ---------------------------------------------------------------------------


def test_self_check_runs_before_a_confirmation_or_an_unbacked_stop():
    d = _decision()
    assert SQ.due((ASK, 0, 4, 1, 4), d) and SQ.due((STOP, 0, 4, 1, 1), d)
    assert not SQ.due((ASK, 0, 4, 1, 1), d) and not SQ.due((ASK, 0, 4, 1, 3), d) and not SQ.due((MOVE, 2, 4, 2, 1), d)
    # a stop the oracle backed: a "yes" to a confirmation, or a hint saying the target is near
    assert not SQ.due((STOP, 0, 4, 1, 1), _decision(confirm=1))
    assert not SQ.due((STOP, 0, 4, 1, 1), _decision(hint_progress=T.HINT_STOP))


def test_the_request_carries_the_front_view_the_candidate_and_the_fact_base():
    d = _decision(answers=[(1, APPEARANCE), (2, "In the living room."), (1, OT.refused_text())])
    req = SQ.request(d, FRONT, "the armchair by the window")
    text, image = req.messages[1]["content"]
    assert image is FRONT and req.schema is SQ.SCHEMA and req.schema_name == "self_questions"
    assert "Object to check: the armchair by the window" in text and APPEARANCE in text
    assert "living room" not in text and OT.refused_text() not in text  # appearance answers only, no refusal
    assert "none yet" in SQ.request(_decision(), FRONT, "x").messages[1]["content"][0]
    items = SQ.SCHEMA["properties"]["self_questions"]["items"]
    assert items["required"] == ["question", "answer", "certainty", "fact_base"]  # answered before compared


def test_trigger_skips_only_on_a_certain_contradiction_of_a_stated_fact():
    facts = _decision(answers=[(1, APPEARANCE)])
    check, err = SQ.refine(_self_reply(("blue", "certain", "contradicts"), ("wooden legs", "certain", "agrees"),
                                       ("leather", "unsure", "contradicts")), None)
    assert err is None and check.dropped == 1  # the unsure answer is dropped
    assert check.kept == [("q0", "blue", "contradicts"), ("q1", "wooden legs", "agrees")]
    assert SQ.trigger(check, facts) == ["blue"]
    # an unsure contradiction alone does not count; nor does any while the Fact Base has no appearance answer
    unsure, _ = SQ.refine(_self_reply(("leather", "unsure", "contradicts"), ("red", "certain", "agrees")), None)
    assert SQ.trigger(unsure, facts) == []
    assert SQ.trigger(check, _decision()) == [] and SQ.trigger(check, _decision(answers=[(2, "kitchen")])) == []
    assert "not the target (blue)" in SQ.status_text(4, "the chair", check, ["blue"])
    assert "no conflict (red)" in SQ.status_text(4, "the chair", unsure, [])
    # unusable replies are corrected
    for bad, says in (({"description": "", "self_questions": []}, "description"),
                      ({"description": "a chair", "self_questions": [{"question": "q"}] * 2}, "certainty"),
                      (_self_reply(("red", "certain", "agrees")), "2 to 5")):
        assert SQ.refine(bad, None)[0] is None and says in SQ.refine(bad, None)[1]


# ---------------------------------------------------------------------------
# end to end
# ---------------------------------------------------------------------------

SCRIPT = {1: _plan("ask", question_type=1), 2: _plan("ask", question_type=3),
          3: _plan("stop", subgoal="the blue chair"), 4: _plan("ask", question_type=4, subgoal="the blue chair"),
          5: _plan("ask", question_type=4, subgoal="the red chair")}
"""Planner replies per turn: Type 1, Type 3, a stop at a candidate the self-check rules out, a confirmation of it
(also ruled out), a confirmation of a candidate the self-check finds consistent."""
SELF_CHECK = {"the blue chair": _self_reply(("it is blue", "certain", "contradicts"), ("metal", "unsure", "not stated")),
              "the red chair": _self_reply(("it is red", "certain", "agrees"), ("it has legs", "certain", "agrees"))}
CONFLICT = "so it is not the target; do not ask a confirmation question or stop here"


def _policy(req: dict) -> str:
    text, name = request_text(req), req["response_format"]["json_schema"]["name"]
    if name == "self_questions":
        return json.dumps(SELF_CHECK[re.search(r"Object to check: (.*)", text).group(1).strip()])
    if name in ("candidate_cell", "grounder_cell"):
        return json.dumps({"col": 4, "row": 2, "rationale": "scripted"})
    if CONFLICT in text:  # the Planner corrected after a self-check that ruled its candidate out
        return json.dumps(_plan("move", direction="left", subgoal="the open doorway"))
    return json.dumps(SCRIPT[int(re.search(r"Turn (\d+) of", text).group(1))])


@pytest.fixture(scope="module")
def episodes():
    return load_benchmark(EPISODES, limit=1)


def _run(episodes, name):
    with ScriptedServer(policy=_policy) as srv:
        llm = LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, timeout_s=10.0)
        res = run_llm_agent(episodes.subset([0]), get_llm_agent(name), llm, sim=T.SimConfig(max_steps=5), views=VIEWS,
                            batch=1)
        return res, srv.stats()["requests"]


@pytest.mark.usefixtures("rendering")
def test_coin_naive_end_to_end(episodes):
    res, bodies = _run(episodes, "coin-naive")
    calls = res.transcripts
    by_step = {s: [c for c in calls if c["step"] == s] for s in range(5)}
    acts = {s: [c["action"] for c in cs if c["action"] is not None][-1] for s, cs in by_step.items()}
    # Type 1 and Type 3 asked and charged; the stop and the first confirmation skipped (not charged), the second asked
    assert acts[0][::4] == [ASK, 1] and acts[1][::4] == [ASK, 3]
    assert acts[2] == acts[3] == [MOVE, 2, 4, 2, 1]  # the Planner's corrected choice: a move left, grounded
    assert acts[4] == [ASK, 0, 4, 2, 4]
    assert res.outcomes.n_questions[0].tolist() == [1, 0, 1, 1]
    # the self-questioner's request comes after the Planner's and before anything else of the decision
    roles = {s: [c["role"] for c in cs] for s, cs in by_step.items()}
    assert roles[2] == roles[3] == ["planner", "self-questioner", "planner", "grounder"]
    assert roles[4] == ["planner", "self-questioner", "grounder"]
    assert roles[0] == roles[1] == ["planner"]
    assert all(len(c["images"]) == 1 for s in (2, 3, 4) for c in by_step[s] if c["role"] == "self-questioner")
    assert bodies == res.accounting["requests"].sum() == 13  # every self-check and correction counted
    assert res.accounting["invalid_replies"].tolist() == [0]
    # the trigger's decision in the transcript; the Fact Base reached the self-check; the status reached the Planner
    assert [c.get("rule") for c in by_step[2] if c.get("rule")] == ["interaction trigger"]
    sq = [c for c in by_step[2] if c["role"] == "self-questioner"][0]
    planner2 = [c["prompt"] for c in by_step[2] if c["role"] == "planner"][0]
    fact = re.search(r"- appearance: (.*)", planner2).group(1)  # the oracle's Type-1 answer, as the Planner saw it
    assert f"Known facts about the target's appearance: {fact}" in sq["prompt"]
    later = [c["prompt"] for c in by_step[4] if c["role"] == "planner"][0]
    assert "step 2: the blue chair: own check says not the target (it is blue)" in later
    assert "step 3: the blue chair: own check says not the target" in later


@pytest.mark.usefixtures("rendering")
def test_tandem_naive_has_no_self_check_end_to_end(episodes):
    """The same script under ``tandem-naive``: no self-questioner request; the stop at the blue chair ends the
    episode."""
    res, bodies = _run(episodes, "tandem-naive")
    calls = res.transcripts
    assert "self-questioner" not in {c["role"] for c in calls} and bodies == res.accounting["requests"].sum() == 3
    assert [c["action"][0] for c in calls if c["action"]] == [ASK, ASK, STOP]
    assert res.outcomes.n_questions[0].tolist() == [1, 0, 1, 0]


def test_dry_run_counts_one_self_check_per_decision():
    from ignjax.evaluate.dryrun import dry_run

    coin, tandem = (dry_run(get_llm_agent(a), 2, sim=T.SimConfig(max_steps=5), views=VIEWS) for a in ("coin", "tandem"))
    assert coin["self_questioner_requests"] == 10 and tandem["self_questioner_requests"] == 0
    assert coin["requests"] == 30 and coin["images"] == 30 and tandem["requests"] == 20
    assert coin["prompt_tokens_per_self_questioner_request"] > 0
    assert coin["prompt_tokens"] == tandem["prompt_tokens"] + 10 * coin["prompt_tokens_per_self_questioner_request"] \
        + 10 * (coin["prompt_tokens_per_planner_request"] - tandem["prompt_tokens_per_planner_request"])
