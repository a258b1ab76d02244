"""``llm.naive_unbudgeted``: the naive-QA rows run with no question budget
(the reading of the paper's naive rows whose |Q| exceeds the budget), every
other agent keeps it. A Planner that asks at every turn, against the
scripted server (a test double on 127.0.0.1 whose replies a policy
computes)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ignjax.agents.llm.catalog import get_llm_agent, sim_overrides
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.scripted import scripted_reply
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
STEPS = 13


def _always_ask(req: dict) -> str:
    """Every Planner decision asks a question (types 1, 2, 4 in turn); the rest the server's default."""
    if req["response_format"]["json_schema"]["name"] != "planner_decision":
        return scripted_reply(req)
    reply = json.loads(scripted_reply(req))
    n = len(json.dumps(req["messages"]))
    reply.update(action="ask", question_type=(1, 2, 4)[n % 3], question="Is this it?", subgoal="the object ahead")
    return json.dumps(reply)


def test_only_the_naive_rows_lose_the_budget(rendering):
    llm = LLMConfig(naive_unbudgeted=True)
    assert sim_overrides(get_llm_agent("tandem-naive"), llm) == {"question_budget": False}
    assert "question_budget" not in sim_overrides(get_llm_agent("tandem"), llm)
    assert sim_overrides(get_llm_agent("tandem-naive"), LLMConfig()) == {}
    es = load_benchmark(EPISODES, limit=1)
    charged = {}
    with ScriptedServer(policy=_always_ask) as srv:
        for flag in (False, True):
            cfg = LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, timeout_s=10.0,
                            naive_unbudgeted=flag)
            res = run_llm_agent(es, get_llm_agent("tandem-naive"), cfg, sim=T.SimConfig(max_steps=STEPS),
                                views=ViewConfig(size=64), batch=1)
            charged[flag] = int(np.asarray(res.outcomes.n_questions)[0].sum())
            refused = int(res.accounting["refused_asks"][0])
            assert (refused == 0) if flag else (refused >= STEPS - T.SimConfig().max_questions)
    # budgeted: the 10-question budget, the later asks refused (counted, never charged); unbudgeted: every turn
    assert charged == {False: T.SimConfig().max_questions, True: STEPS}
