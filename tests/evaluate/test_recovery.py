"""Accounting and recovery of the MLLM host loop against the scripted server
(a real HTTP server on 127.0.0.1, a test double whose replies are computed
from the request; nothing in the client or the loop is replaced): the server
stopped mid-run ends every episode in flight with ``model_failure`` and the
command with exit status 3 and a summary line; with the server back, the
same command runs those episodes again, the replies they got answered from
the cache, to the outcomes of an uninterrupted run. Requests and retries
count attempts that got no response; the controller's own transcript
records name their rule; asks with no question left are counted and
corrected; the viewer reads the Grounder images a run writes."""

from __future__ import annotations

import csv
import json
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from ignjax.agents.llm.agent import NO_QUESTIONS_LEFT, VlmAgent
from ignjax.agents.llm.catalog import get_llm_agent
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.scripted import scripted_reply
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.cli import main as evaluate_main
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.evaluate.recovery import MODEL_FAILURE_EXIT
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
N = 4
SIM = T.SimConfig(max_steps=8, max_questions=2)
"""One simulator setting, one episode count and one batch size for every run here: the loop's programs compile once."""
SETS = [f"sim.max_steps={SIM.max_steps}", f"sim.max_questions={SIM.max_questions}", "views.size=64",
        "llm.max_retries=1", "llm.backoff_base_s=0.005", "llm.backoff_max_s=0.01", "llm.timeout_s=5.0"]


@pytest.fixture(scope="module")
def episodes():
    return load_benchmark(EPISODES, limit=N)


def _llm(srv, cache: Path, **kw) -> LLMConfig:
    return LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, cache_dir=str(cache), **kw)


def _planner_move(req: dict) -> str:
    """Every Planner request: move toward the front view (the Grounder and others: the server's own reply)."""
    fmt = req.get("response_format", {}).get("json_schema", {})
    if fmt.get("name") != "planner_decision":
        return scripted_reply(req)
    reply = {"reasoning": "", "task_phase": "explore", "action": "move", "direction": "front",
             "subgoal": "the open floor ahead", "purpose": "explore", "question_type": 1, "question": "",
             "belief_update": {"current_room": "hall", "target_description": "", "visited_areas": [],
                               "unexplored_areas": [], "key_observations": []}}
    if "col" in fmt["schema"]["properties"]:  # one-stage agents pick the cell themselves
        reply.update(col=4, row=2)
    return json.dumps(reply)


def _stop_after(srv: ScriptedServer, n: int) -> threading.Thread:
    """Stop ``srv`` (as a killed server: connections refused from then on) once it has received ``n`` requests."""
    def watch():
        deadline = time.monotonic() + 300  # a bound on waiting, not a measurement
        while srv.stats()["requests"] < n and time.monotonic() < deadline:
            time.sleep(0.005)
        srv.stop()

    t = threading.Thread(target=watch, daemon=True)
    t.start()
    return t


def _evaluate(out: Path, url: str, cache: Path) -> list[str]:
    return ["--episodes", str(EPISODES), "--agent", "navgpt", "--llm-endpoint", url, "--llm-model", "ignjax-scripted",
            "--llm-cache", str(cache), "--limit", str(N), "--llm-batch", str(N), "--out", str(out), "--quiet",
            *sum((["--set", s] for s in SETS), [])]


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _calls(out: Path, agent: str) -> list[dict]:
    return [json.loads(line) for line in (out / "transcripts" / f"{agent}.jsonl").read_text().splitlines()]


def _sent_line(err: str, agent: str) -> str:
    return next(line for line in err.splitlines() if line.startswith(f"{agent}: ") and "sent in this run" in line)


def test_server_killed_mid_run_then_the_same_command_retries_the_failures(rendering, tmp_path, capsys):
    with ScriptedServer(policy=_planner_move, latency=0.05) as srv:
        url, cache = srv.base_url, tmp_path / "cache"
        args = _evaluate(tmp_path / "run", url, cache)
        watcher = _stop_after(srv, 6)
        status = evaluate_main(args)
        watcher.join(30)
        first = capsys.readouterr()
        received = srv.stats()["requests"]
        # every episode was in flight when the server went: all ended by a model failure; the outputs are written
        assert status == MODEL_FAILURE_EXIT == 3, first.err[-3000:]
        rows = _rows(tmp_path / "run" / "outcomes.csv")
        assert [r["stop_reason"] for r in rows] == ["model_failure"] * N
        assert all("connection error" in r["failure"] for r in rows)
        assert f"navgpt: {N} of {N} episodes ended by a model failure" in first.err
        assert "run the same command again to run them again" in first.err
        # every attempt counts, answered or not: the server saw fewer than were sent (the refused connections)
        requests, retries = (sum(int(r[k]) for r in rows) for k in ("requests", "retries"))
        assert f"{requests} requests sent in this run ({retries} retries;" in _sent_line(first.err, "navgpt")
        assert requests > received and retries >= N  # each failed call: max_retries=1, two attempts
        answered = [c for c in _calls(tmp_path / "run", "navgpt") if c["request_hash"]]
        assert 0 < len(answered) <= received

        # the server is back: the same command runs the failed episodes again, the replies they got from the cache
        srv.start()
        srv.reset_stats()
        assert evaluate_main(args) == 0
        second = capsys.readouterr()
        rows = _rows(tmp_path / "run" / "outcomes.csv")
        assert {r["stop_reason"] for r in rows} <= {"stop", "step_budget"} and not any(r["failure"] for r in rows)
        again = _calls(tmp_path / "run", "navgpt")
        hits = [c["request_hash"] for c in again if c["cache_hit"]]
        assert sum(int(r["cache_hits"]) for r in rows) == len(hits)
        # every reply the first run got came from the cache; the other hits are requests this run sent once and met
        # again (a caption of a view equal to another: the captioner's prompt does not name the direction)
        assert {c["request_hash"] for c in answered} <= set(hits)
        assert set(hits) <= {c["request_hash"] for c in answered + again if c["request_hash"] and not c["cache_hit"]}
        assert sum(int(r["requests"]) for r in rows) == srv.stats()["requests"] > 0
        assert f"0 episodes kept from an earlier run, {N} run again after a model failure" in second.err
        assert "ended by a model failure (first" not in second.err

        # the outcomes are an uninterrupted run's
        assert evaluate_main(_evaluate(tmp_path / "clean", url, tmp_path / "cache_clean")) == 0
        capsys.readouterr()
        cols = lambda rs: [{k: r[k] for k in list(r)[:list(r).index("requests")]} for r in rs]  # noqa: E731
        assert cols(rows) == cols(_rows(tmp_path / "clean" / "outcomes.csv"))

        # once more: nothing to run, nothing sent, and the printed summary says so
        before = srv.stats()["requests"]
        assert evaluate_main(args) == 0
        third = capsys.readouterr()
        assert srv.stats()["requests"] == before
        assert f"navgpt: {N} episodes in" in third.err and "0 requests sent in this run" in third.err
        assert f"{N} episodes kept from an earlier run" in third.err
        assert "navgpt: in the outcomes (this run and the episodes kept from earlier ones): " in third.out


def test_controller_records_name_the_rule_and_what_it_asked(tmp_path, episodes):
    """``navgpt`` on the ground-truth text observation (its ``observation="text"`` ablation: no rendering, no
    captions) moving on every Planner reply: the controller asks the early questions
    of the schedule on its own (the region fact at turn 2, the appearance fact at turn 5, which spend this setting's
    two questions, so the recovery rule has none left to ask); each such decision's transcript record names the rule
    and what it asked."""
    with ScriptedServer(policy=_planner_move) as srv:
        res = run_llm_agent(episodes, get_llm_agent("navgpt", observation="text"), _llm(srv, tmp_path / "c"),
                            sim=SIM, views=ViewConfig(size=64), batch=N)
    ctrl = [c for c in res.transcripts if c["role"] == "controller"]
    assert len({c["episode"] for c in ctrl}) == N, [(c["role"], c.get("rule")) for c in res.transcripts]
    for c in ctrl:
        assert c["rule"] == "early question" and c["action"][0] == T.ASK and c["action"][4] in (1, 2), c
        assert f"ask it (type {c['action'][4]}" in c["text"] and f"turn {c['step'] + 1}" in c["text"], c
    assert sorted({c["step"] for c in ctrl}) == [1, 4]  # turns 2 and 5
    assert not any("rule" in c for c in res.transcripts if c["role"] != "controller")


def test_asks_with_no_question_left_are_counted_and_corrected(tmp_path, episodes):
    """A vlm agent that asks at every turn, with two questions allowed: the third and later asks are answered with
    a correction saying the budget is spent, counted in ``refused_asks`` (and ``invalid_replies``), and never
    reach the simulator; the prompts say no question is left."""
    ask = json.dumps({"action": "ask", "direction": 0, "col": 4, "row": 1, "question": 1, "reason": "unsure"})
    with ScriptedServer(policy=lambda req: ask) as srv:
        res = run_llm_agent(episodes, VlmAgent(observation="text", reasks=2), _llm(srv, tmp_path / "c"), sim=SIM,
                            views=ViewConfig(size=64), batch=N)
    acc, o = res.accounting, res.outcomes
    spent = SIM.max_steps - SIM.max_questions  # decisions with no question left: three replies each, all asks
    assert acc["refused_asks"].tolist() == [3 * spent] * N and acc["invalid_replies"].tolist() == [3 * spent] * N
    assert o.n_questions.sum(axis=-1).tolist() == [SIM.max_questions] * N and o.n_refused.tolist() == [0] * N
    late = [c for c in res.transcripts if c["step"] >= SIM.max_questions]
    assert all(c["action"][0] == T.MOVE for c in late)  # the default move after the corrections
    assert all("Your question budget is spent" in c["prompt"] and NO_QUESTIONS_LEFT in c["prompt"] for c in late)
    assert all(r["error"] == NO_QUESTIONS_LEFT for c in late for r in c["retries"])


def test_requests_and_retries_count_attempts_without_a_response(tmp_path, episodes):
    """A server that drops every connection: no reply ever comes, yet each attempt is a request and every attempt
    after the first a retry."""
    with ScriptedServer(faults="drop:1") as srv:
        llm = _llm(srv, tmp_path / "c", max_retries=2, backoff_base_s=0.005, backoff_max_s=0.01, timeout_s=5.0)
        res = run_llm_agent(episodes, VlmAgent(observation="text"), llm, sim=SIM, views=ViewConfig(size=64), batch=N)
        received = srv.stats()["requests"]
    assert res.outcomes.stop_reason.tolist() == [T.ABORTED] * N
    assert res.accounting["requests"].tolist() == [3] * N and res.accounting["retries"].tolist() == [2] * N
    assert res.stats["requests"] == received == 3 * N and res.stats["retries"] == 2 * N and res.stats["failures"] == N
    # no episode stepped: their trajectories are those of episodes that ended before their first step
    tr = res.trajectories
    assert (tr.kind == -1).all() and (tr.question == 0).all() and (tr.candidate == -1).all()
    assert tr.n_questions.shape == (N, SIM.max_steps, 4) and (tr.n_questions == 0).all()
    assert tr.visible.shape == (N, SIM.max_steps, SIM.max_visible) and (tr.visible == -1).all()
    assert tr.visible_attrs.shape == (N, SIM.max_steps, SIM.max_visible, 4) and tr.blocked.shape[2] == 8
    np.testing.assert_allclose(tr.waypoint[:, 0], np.asarray(episodes.specs.start)[:, :2], atol=1e-5)


def test_the_viewer_reads_the_grounder_images_the_run_writes(rendering, tmp_path):
    from ignjax.view.runfolder import read_run

    with ScriptedServer(policy=_planner_move) as srv:
        args = ["--episodes", str(EPISODES), "--agent", "tandem", "--llm-endpoint", srv.base_url, "--llm-model",
                srv.model, "--llm-cache", str(tmp_path / "c"), "--limit", "1", "--llm-batch", "1", "--out",
                str(tmp_path / "run"), "--quiet", "--save-images", "1", "--set", "sim.max_steps=3",
                "--set", "views.size=64"]
        assert evaluate_main(args) == 0
    eid = load_benchmark(EPISODES, limit=1).episode_ids[0]
    written = sorted(p.name for p in (tmp_path / "run" / "images" / "tandem" / eid).iterdir())
    assert "000_grounder.jpg" in written and "000_panel.jpg" in written
    run = read_run(tmp_path / "run", episodes=1)
    steps = run.images[("tandem", eid)]
    moves = np.flatnonzero(run.trajectories["tandem"]["kind"][0] == T.MOVE)
    assert moves.size and all("grounder" in steps[int(t)] and "panel" in steps[int(t)] for t in moves)
    # the name earlier runs wrote (the view's index added) is read too
    folder = tmp_path / "run" / "images" / "tandem" / eid
    (folder / "000_grounder.jpg").rename(folder / "000_grounder_0.jpg")
    assert read_run(tmp_path / "run", episodes=1).images[("tandem", eid)][0]["grounder"].name == "000_grounder_0.jpg"


def test_sweep_exits_3_on_model_failures_and_resume_retries_them(rendering, tmp_path, capsys):
    from ignjax.sweep.cli import main as sweep_main

    agent = "navgpt"
    with ScriptedServer(policy=_planner_move, latency=0.05) as srv:
        sets = [f"benchmark.episodes='{EPISODES}'", f"benchmark.limit={N}", f"run.out='{tmp_path}'",
                f"eval.agents=['{agent}']", f"eval.batch={N}", f"llm.endpoints=['{srv.base_url}']",
                f"llm.model='{srv.model}'", "llm.api_key_env=''", f"llm.cache_dir='{tmp_path / 'cache'}'", *SETS]
        argv = ["--study", "eval", "--quiet", "--out", str(tmp_path / "s")] + sum((["--set", s] for s in sets), [])
        watcher = _stop_after(srv, 6)
        assert sweep_main(argv) == 3
        watcher.join(30)
        err = capsys.readouterr().err
        assert f"{agent}: {N} of {N} episodes ended by a model failure" in err
        assert "run the same command again with --resume" in err
        rows = _rows(tmp_path / "s" / "outcomes.csv")
        assert [r["stop_reason"] for r in rows] == ["model_failure"] * N and (tmp_path / "s" / "report.md").is_file()

        srv.start()
        assert sweep_main(argv + ["--resume"]) == 0, capsys.readouterr().err[-3000:]
        rows = _rows(tmp_path / "s" / "outcomes.csv")
        assert not any(r["failure"] for r in rows) and sum(int(r["cache_hits"]) for r in rows) > 0
