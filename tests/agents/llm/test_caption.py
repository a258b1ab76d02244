"""``navgpt`` perceives through a captioner (:mod:`ignjax.agents.llm.caption`):
end to end through the host loop against the scripted server (a real HTTP
server on 127.0.0.1, a test double whose replies here are scripted from the
request: a caption made from the image's bytes, a Planner that always moves
ahead), with rendered views. Every Planner request carries the captions of
its decision, one line per view name, and nothing of the simulator's
perception: no instance id, no metre figure besides the agent's own
odometry (its offset from the start, the distance its last move covered),
no room label the oracle did not say; one caption request per view per
Planner decision, counted in the accounting; a second run from the cache
sends nothing."""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import pytest

from ignjax.agents.llm.caption import CAPTION_SYSTEM, NO_CAPTION, caption_reply
from ignjax.agents.llm.catalog import get_llm_agent
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.scripted import request_text
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.scenes import vocab
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig
from ignjax.sim.views.compose import view_names

ROOT = Path(__file__).resolve().parents[3]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
SIM = T.SimConfig(max_steps=6)
VIEWS = ViewConfig(size=64)
COLOURS = ("grey", "white", "brown", "blue")
THINGS = ("fabric sofa", "wooden table", "open doorway", "tiled floor")

OBJECT_ID = re.compile(r"\bobject \d+")
METRES = re.compile(r"\d+(?:\.\d+)?\s*(?:m|metres?|meters?)\b")
OWN_ODOMETRY = re.compile(r"Offset from start: [^\n]*?of your start\.|you moved \d+\.\d m")
"""The agent's own odometry, which the paper's Planner gets: its offset from the start, what its last move covered."""
ORACLE_LINES = re.compile(r"^(- (appearance|location|last confirmation): |Active route hint: ).*$", re.MULTILINE)
"""Fact Base lines: the oracle's words (a region answer names the goal room)."""
ROOMS = [vocab.ROOM_DISPLAY[r] for r in vocab.ALL_ROOM_LABELS if r != "other"]


def _images(req: dict) -> list[str]:
    return [p["image_url"]["url"] for m in req["messages"] if isinstance(m["content"], list) for p in m["content"]
            if p.get("type") == "image_url"]


def _policy(seen: list):
    def reply(req: dict) -> str:
        seen.append(req)
        fmt = req["response_format"]["json_schema"]
        if fmt["name"] == "view_caption":  # a caption from the image's bytes: equal images, equal captions
            h = hashlib.sha256(_images(req)[0].encode()).digest()
            return json.dumps({"description": f"a {COLOURS[h[0] % 4]} {THINGS[h[1] % 4]}, a passage on the left"})
        return json.dumps({"reasoning": "", "task_phase": "explore", "action": "move", "direction": "front",
                           "subgoal": "the open floor ahead", "purpose": "explore", "question_type": 1,
                           "question": "", "col": 4, "row": 2,
                           "belief_update": {"current_room": "near a sofa", "target_description": "",
                                             "visited_areas": [], "unexplored_areas": [], "key_observations": []}})
    return reply


def _leaks(text: str) -> list[str]:
    """What of the simulator's perception a Planner text carries (empty: nothing)."""
    out = OBJECT_ID.findall(text) + METRES.findall(OWN_ODOMETRY.sub("", text))
    if "You seem to be in" in text:
        out.append("You seem to be in")
    rest = ORACLE_LINES.sub("", text).lower()
    return out + [r for r in ROOMS if re.search(rf"\b{r}\b", rest)]


@pytest.fixture(scope="module")
def episodes():
    return load_benchmark(EPISODES, limit=2)


def _llm(srv, cache: Path) -> LLMConfig:
    return LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, timeout_s=10.0,
                     cache_dir=str(cache))


def test_caption_reply_and_request_shape():
    assert caption_reply({"description": "  a grey\n sofa "}, None) == ("a grey sofa", None)
    assert caption_reply({"description": ""}, None)[0] is None and caption_reply(None, "bad")[1] == "bad"
    assert caption_reply({"description": "x" * 1000}, None)[0] == "x" * 300
    for word in ("distance", "measurement"):
        assert word in CAPTION_SYSTEM or word + "s" in CAPTION_SYSTEM


@pytest.mark.usefixtures("rendering")
def test_navgpt_plans_from_captions_without_ground_truth(episodes, tmp_path):
    seen: list = []
    agent = get_llm_agent("navgpt")
    with ScriptedServer(policy=_policy(seen)) as srv:
        res = run_llm_agent(episodes, agent, _llm(srv, tmp_path / "cache"), sim=SIM, views=VIEWS, batch=2)
        sent = srv.stats()["requests"]
        again = run_llm_agent(episodes, get_llm_agent("navgpt"), _llm(srv, tmp_path / "cache"), sim=SIM, views=VIEWS,
                              batch=2)
        assert srv.stats()["requests"] == sent  # the second run: every call from the cache, nothing sent
    names = view_names(SIM.n_views)
    planner = [r for r in seen if r["response_format"]["json_schema"]["name"] == "planner_decision"]
    captions = [r for r in seen if r["response_format"]["json_schema"]["name"] == "view_caption"]
    assert planner and len(captions) == len(names) * len(planner) and len(seen) == len(planner) + len(captions)
    # the Planner reads no image and no ground truth; the captioner one image each, the same prompt for every view
    assert all(not _images(r) for r in planner) and all(len(_images(r)) == 1 for r in captions)
    assert {request_text(r) for r in captions} == {f"{CAPTION_SYSTEM}\nDescribe this view."}
    assert not [(i, x) for i, r in enumerate(planner) for x in _leaks(request_text(r))]
    system = planner[0]["messages"][0]["content"]
    assert "captioning model" in system and "8x8 grid you do not see" in system
    # per Planner decision, one caption record per view before it; its lines are those captions, in view order
    calls = res.transcripts
    decided = {(c["episode"], c["step"]) for c in calls if c["role"] == "planner"}
    assert len(decided) == len(planner)
    for e, s in decided:
        caps = [c for c in calls if (c["episode"], c["step"]) == (e, s) and c["role"] == "caption"]
        plan = next(c for c in calls if (c["episode"], c["step"]) == (e, s) and c["role"] == "planner")
        assert len(caps) == len(names) and all(len(c["images"]) == 1 for c in caps)
        lines = "\n".join(f"- {n}: {c['parsed']['description']}" for n, c in zip(names, caps))
        assert f"What you see:\n{lines}" in plan["prompt"] and NO_CAPTION not in plan["prompt"]
    ruled = {(c["episode"], c["step"]) for c in calls if c["role"] == "controller"}
    assert ruled and not [c for c in calls if c["role"] == "caption" and (c["episode"], c["step"]) in ruled]
    # counted like every call: the episodes' requests are what the server received, captions included
    assert int(res.accounting["requests"].sum()) == sent == len(seen)
    assert int(res.accounting["invalid_replies"].sum()) == 0
    assert [c["role"] for c in again.transcripts] == [c["role"] for c in calls]
    assert int(again.accounting["requests"].sum()) == 0 and int(again.accounting["cache_hits"].sum()) == len(seen)
    assert again.outcomes.stop_reason.tolist() == res.outcomes.stop_reason.tolist()


def test_the_ground_truth_text_ablation_trips_the_same_checks(episodes, tmp_path):
    """The ``"text"`` observation (the simulator's perception in words, kept as an ablation) carries what the
    captions never do: the checks above would see it."""
    seen: list = []
    with ScriptedServer(policy=_policy(seen)) as srv:
        run_llm_agent(episodes, get_llm_agent("navgpt", observation="text"), _llm(srv, tmp_path / "c"), sim=SIM,
                      views=VIEWS, batch=2)  # the settings above: the loop's programs compile once
    leaks = [x for r in seen for x in _leaks(request_text(r))]
    assert "You seem to be in" in leaks and any(METRES.fullmatch(x) for x in leaks)
