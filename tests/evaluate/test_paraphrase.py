"""Oracle answers reworded by the model (``llm.paraphrase``), through the host
loop against the scripted server (a real HTTP server on 127.0.0.1; a test
double whose replies a policy scripts from the request text): the agent
reads the server's rewording; a rewording that leaks (a digit, a compass
word) is refused and the template shown; a second run is answered from the
cache; and the leak checks themselves on hand-written rewordings."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from ignjax.agents.llm.agent import VlmAgent
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.config import fingerprint, resolve
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.sim import oracle_text as OT
from ignjax.sim import types as T

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
SIM = T.SimConfig(max_steps=4)
REWORDED = "In other words:"
LEAKY_ROUTE = "Go north for about 3 metres."


def _decision(action="move", question=1):
    return json.dumps({"action": action, "direction": 0, "col": 4, "row": 1, "question": question, "reason": "scripted"})


def _user_text(req: dict) -> str:
    c = req["messages"][-1]["content"]
    return c if isinstance(c, str) else "\n".join(p.get("text", "") for p in c if p.get("type") == "text")


class Script:
    """The vlm agent asks a Type-1 question at turn 1 and a Type-3 question at
    turn 2, then moves. Paraphrase requests: a Type-1 answer comes back as
    ``REWORDED`` + the answer; a Type-3 answer as :data:`LEAKY_ROUTE`. The
    answers sent for rewording are kept by type."""

    def __init__(self):
        self.templates: dict[str, list[str]] = {}

    def __call__(self, req: dict) -> str:
        text = _user_text(req)
        if req["response_format"]["json_schema"]["name"] == "paraphrase":
            kind, answer = re.match(r"The helper's answer to an? (\w+) question:\n(.*)", text, re.S).groups()
            self.templates.setdefault(kind, []).append(answer)
            return json.dumps({"text": LEAKY_ROUTE if kind == "route" else f"{REWORDED} {answer}"})
        turn = int(re.search(r"Turn (\d+) of", text).group(1))
        return _decision("ask", 1) if turn == 1 else _decision("ask", 3) if turn == 2 else _decision("move")


@pytest.fixture(scope="module")
def episodes():
    return load_benchmark(EPISODES, limit=2)


def _llm(srv, cache, **kw):
    return LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, cache_dir=str(cache), timeout_s=10.0,
                     **kw)


def test_paraphrased_answers_reach_the_agent_leaks_are_refused_and_the_cache_replays(episodes, tmp_path):
    script = Script()
    agent = VlmAgent(observation="text")  # no rendering needed
    with ScriptedServer(policy=script) as srv:
        res = run_llm_agent(episodes, agent, _llm(srv, tmp_path / "cache", paraphrase=True), sim=SIM, batch=2)
        sent = srv.stats()["requests"]
        planner = [b for b in srv.requests if b["response_format"]["json_schema"]["name"] != "paraphrase"]
        # a second run with the same cache sends nothing and gives the same outcomes and accounting
        again = run_llm_agent(episodes, agent, _llm(srv, tmp_path / "cache", paraphrase=True), sim=SIM, batch=1)
        assert srv.stats()["requests"] == sent
        # without the switch, no answer is sent for rewording and the agent reads the templates
        plain = run_llm_agent(episodes, agent, _llm(srv, tmp_path / "cache"), sim=SIM, batch=2)
        plain_bodies = srv.requests[-int(plain.accounting["requests"].sum()):]
    calls = res.transcripts
    para = [c for c in calls if c["role"] == "paraphrase"]
    # one paraphrase per answer the agent reads: the Type-1 and the Type-3 answer of each episode
    assert len(para) == 2 * len(episodes) and res.stats["paraphrased"] == len(para)
    assert res.accounting["requests"].sum() == sent == len(calls)
    # Type 1: the rewording reached the agent's prompt in place of the template
    prompts = [_user_text(b) for b in planner]
    for answer in script.templates["appearance"]:
        assert any(f"(appearance) {REWORDED} {answer}" in p for p in prompts)
        assert not any(f"(appearance) {answer}" in p for p in prompts)
    # Type 3: the leaking rewording was refused, the template shown, the refusal counted and recorded
    assert OT.route_leaks(LEAKY_ROUTE)
    assert not any(LEAKY_ROUTE in p for p in prompts)
    for answer in script.templates["route"]:
        assert not OT.route_leaks(answer) and any(f"(route) {answer}" in p for p in prompts)
    assert res.accounting["paraphrase_rejected"].tolist() == [1] * len(episodes) and res.stats["paraphrase_rejected"] == 2
    refused = [c for c in para if c["error"]]
    assert len(refused) == len(episodes) and all("digit" in c["error"] and "compass" in c["error"] for c in refused)
    # the replayed run: all from the cache, same outcomes and counts
    assert again.accounting["requests"].sum() == 0 and again.accounting["cache_hits"].sum() == len(calls)
    assert again.accounting["paraphrase_rejected"].tolist() == res.accounting["paraphrase_rejected"].tolist()
    assert np.array_equal(again.outcomes.final_distance, res.outcomes.final_distance)
    # the switch off: no paraphrase request, the agent reads the templates
    assert plain.stats["paraphrased"] == 0
    assert all(b["response_format"]["json_schema"]["name"] != "paraphrase" for b in plain_bodies)
    assert any(f"(appearance) {script.templates['appearance'][0]}" in _user_text(b) for b in plain_bodies)


@pytest.mark.parametrize("question, template, rewording, ok", [
    (3, "Head to your left and go through toward the kitchen.", "Go left, through to the kitchen.", True),
    (3, "Head to your left and go through toward the kitchen.", "Go west to the kitchen.", False),
    (3, "Head to your left and go through toward the kitchen.", "Walk two steps to your left.", False),
    (4, "Yes, that is it. You can stop now.", "Yes, that's the one; stop here.", True),
    (4, "Yes, that is it. You can stop now.", "That is not it.", False),  # flipped
    (4, "Yes, that is it. You can stop now.", "That is the one; stop here.", False),  # the yes dropped
    (4, "Yes, that is the one. Move a little closer, then stop.", "Yes, it is. Stop.", False),  # the closer move dropped
    (4, "No, that is not the one you are looking for.", "No, that's a different one.", True),
    (4, "No, that is not the one you are looking for.", "Yes, but look elsewhere.", False),
    (4, "No, that is not the one you are looking for.", "It is another one, within 2 m.", False),
    (1, "a small gray metal lamp", "a little grey lamp made of metal", True),
    (1, "a small gray metal lamp", "a small gray metal lamp in the bedroom", False),  # a room named
    (2, "In the kitchen, near the sink.", "It is in the kitchen by the sink.", True),
    (2, "In the kitchen, near the sink.", "The red one in the kitchen, by the sink.", False),  # a colour added
    (2, "In the kitchen, near the sink.", "   ", False),
])
def test_paraphrase_checks(question, template, rewording, ok):
    leaks = OT.paraphrase_leaks(question, rewording, template)
    assert (not leaks) == ok, leaks


def test_paraphrase_is_a_setting_that_changes_the_run_and_the_dry_run(capsys):
    base = ["eval.agents=['vlm']", "llm.model='m'", "llm.endpoints=['http://10.0.0.1:8000/v1']"]
    assert fingerprint(resolve(None, base), ["eval"]) != fingerprint(resolve(None, base + ["llm.paraphrase=true"]),
                                                                     ["eval"])
    with pytest.raises(Exception, match="llm.paraphrase"):
        resolve(None, base + ["llm.paraphrase='yes'"])
    from ignjax.evaluate.cli import main

    argv = ["--episodes", str(EPISODES), "--limit", "3", "--llm-endpoint", "http://127.0.0.1:9/v1", "--llm-model", "m",
            "--set", "sim.max_steps=5", "--agent", "vlm", "--dry-run"]
    assert main(argv) == 0
    off = json.loads(capsys.readouterr().out)
    assert main(argv + ["--llm-paraphrase"]) == 0
    on = json.loads(capsys.readouterr().out)
    assert "paraphrase_requests" not in off and on["paraphrase_requests"] == 3 * 5
    assert on["requests"] == off["requests"] + 15 and on["prompt_tokens"] > off["prompt_tokens"]
