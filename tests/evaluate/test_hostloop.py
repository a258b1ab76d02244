"""The MLLM host loop against the scripted server (a real HTTP server on
127.0.0.1, a test double whose replies are computed from the request text;
nothing in the client or the loop is replaced): the vlm agent end to end,
cache hits on a re-run, independence of the batch size, faults retried or
recorded, bad replies re-asked then defaulted, replay misses, and a run
killed with SIGKILL that resumes to the same outcomes."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import jax
import numpy as np
import pytest

from ignjax.agents.llm.agent import VlmAgent
from ignjax.agents.llm.messages import ReplayMissError
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.cli import main as evaluate_main
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.evaluate.outcomes import read_outcomes
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
SIM = T.SimConfig(max_steps=8)
VIEWS = ViewConfig(size=64)
N = 4


@pytest.fixture(scope="module")
def episodes():
    return load_benchmark(EPISODES, limit=N)


def _llm(srv, cache, **kw):
    base = dict(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, cache_dir=str(cache), timeout_s=5.0,
                backoff_base_s=0.005, backoff_max_s=0.05)
    base.update(kw)
    return LLMConfig(**base)


def _same(a, b):
    return all(np.array_equal(x, y) for x, y in zip(jax.tree.leaves(a), jax.tree.leaves(b)))


def test_vlm_end_to_end_cache_and_batch_independence(rendering, tmp_path, episodes):
    with ScriptedServer() as srv:
        res = run_llm_agent(episodes, VlmAgent(), _llm(srv, tmp_path / "cache"), sim=SIM, views=VIEWS, batch=3,
                            out=tmp_path / "a", save_images=1)
        sent = srv.stats()["requests"]
        body = srv.last_request
        # every episode ended by STOP or the step budget; one decision per step
        o = res.outcomes
        assert set(o.stop_reason.tolist()) <= {T.STOPPED, T.OUT_OF_STEPS}
        steps_per_episode = [sum(1 for c in res.transcripts if c["episode"] == e) for e in episodes.episode_ids]
        assert steps_per_episode == o.steps.tolist()
        assert res.accounting["requests"].sum() == sent == len(res.transcripts)
        assert (res.accounting["prompt_tokens"] > 0).all() and res.accounting["failure"] == [""] * N
        # the request carried the Planner panel as a data URL and the decision schema
        parts = body["messages"][-1]["content"]
        assert any(p.get("type") == "image_url" and p["image_url"]["url"].startswith("data:image/jpeg;base64,")
                   for p in parts)
        assert body["response_format"]["type"] == "json_schema"
        # the transcripts name the request and image hashes; images of the first episode were written
        assert all(len(c["request_hash"]) == 64 and len(c["images"]) == 1 for c in res.transcripts)
        first = episodes.episode_ids[0]
        assert len(list((tmp_path / "a" / "images" / "vlm" / first).glob("*_panel.jpg"))) == o.steps[0]
        # the trajectory replays the decisions: kinds as the transcripts' actions
        for i, e in enumerate(episodes.episode_ids):
            kinds = [c["action"][0] for c in res.transcripts if c["episode"] == e]
            assert res.trajectories.kind[i, : len(kinds)].tolist() == kinds
            assert (res.trajectories.kind[i, len(kinds):] == -1).all()

        # the same run again (another batch size, another folder, same cache): no request, same outcomes
        again = run_llm_agent(episodes, VlmAgent(), _llm(srv, tmp_path / "cache"), sim=SIM, views=VIEWS, batch=2,
                              out=tmp_path / "b")
        assert srv.stats()["requests"] == sent
        assert again.accounting["requests"].sum() == 0 and again.accounting["cache_hits"].sum() == sent
        assert _same(again.outcomes, res.outcomes) and _same(again.trajectories, res.trajectories)


def test_faults_are_retried_and_change_nothing(tmp_path, episodes):
    """429 (with Retry-After), 500, dropped connections and malformed bodies
    on a third of the requests: every request is retried until it succeeds,
    the retries are counted, and the outcomes equal a fault-free run (the
    replies depend on the request text only)."""
    with ScriptedServer() as clean:
        ref = run_llm_agent(episodes, VlmAgent(observation="text"), _llm(clean, tmp_path / "c0"), sim=SIM,
                            views=VIEWS, batch=4)
    with ScriptedServer(faults="429:0.1,500:0.1,drop:0.05,malformed:0.05", seed=3) as srv:
        res = run_llm_agent(episodes, VlmAgent(observation="text"), _llm(srv, tmp_path / "c1", max_retries=12),
                            sim=SIM, views=VIEWS, batch=4)
        faults = srv.stats()["faults"]
    assert sum(faults.values()) > 0 and res.accounting["retries"].sum() == sum(faults.values())
    assert _same(res.outcomes, ref.outcomes)


def test_requests_that_keep_failing_end_the_episode_not_the_run(tmp_path, episodes):
    from ignjax.evaluate import metrics as M

    with ScriptedServer(faults="500:1") as srv:
        res = run_llm_agent(episodes, VlmAgent(observation="text"),
                            _llm(srv, tmp_path / "c", max_retries=2, max_retries_per_episode=100), sim=SIM,
                            views=VIEWS, batch=2)
    assert res.outcomes.stop_reason.tolist() == [T.ABORTED] * N
    assert all("500" in f for f in res.accounting["failure"])
    summary = M.summarize(res.outcomes)
    assert float(np.asarray(summary["SR"]).max()) == 0.0


def test_bad_replies_are_re_asked_then_defaulted(tmp_path, episodes):
    agent = VlmAgent(observation="text", reasks=2)
    with ScriptedServer(policy=lambda req: "I would rather not say.") as srv:
        res = run_llm_agent(episodes.subset([0]), agent, _llm(srv, tmp_path / "c", structured="none"), sim=SIM,
                            views=VIEWS, batch=1)
    o = res.outcomes
    assert o.stop_reason.tolist() == [T.OUT_OF_STEPS]
    # every decision: one request and two corrections, then the default move straight ahead
    assert res.accounting["invalid_replies"].tolist() == [3 * SIM.max_steps]
    assert res.accounting["requests"].tolist() == [3 * SIM.max_steps]
    calls = res.transcripts
    # the transcript keeps the last reply and the two earlier attempts
    assert all(c["action"] == [T.MOVE, 0, 4, 1, 1] and len(c["retries"]) == 2 for c in calls)
    assert all(r["error"] for r in calls[0]["retries"])
    # the last request of a decision carried the two corrections
    assert calls[0]["prompt"].count("That reply cannot be used") == 2


def test_replay_miss_names_the_request(tmp_path, episodes):
    with ScriptedServer() as srv:
        with pytest.raises(ReplayMissError, match="[0-9a-f]{64}"):
            run_llm_agent(episodes.subset([0]), VlmAgent(observation="text"),
                          _llm(srv, tmp_path / "empty", replay=True), sim=SIM, views=VIEWS, batch=1)
        assert srv.stats()["requests"] == 0


def _evaluate(out: Path, url: str, cache: Path) -> list[str]:
    """The arguments of ``python -m ignjax.evaluate`` for 3 vlm episodes."""
    return ["--episodes", str(EPISODES), "--agent", "vlm", "--llm-endpoint", url, "--llm-model", "ignjax-scripted",
            "--llm-cache", str(cache), "--limit", "3", "--llm-batch", "2", "--set", "sim.max_steps=8",
            "--set", "views.size=64", "--out", str(out), "--quiet"]


def _outcome_columns(path: Path) -> list[list[str]]:
    rows = [line.split(",") for line in path.read_text().splitlines()]
    n = rows[0].index("requests")
    return [r[:n] for r in rows]


def _run_killed_after_first_episode(args: list[str], progress: Path) -> None:
    """Run ``python -m ignjax.evaluate ARGS`` in a subprocess and SIGKILL it
    once its progress file holds a finished episode (the kill is placed by
    what the run writes, not by time)."""
    proc = subprocess.Popen([sys.executable, "-m", "ignjax.evaluate", *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 600  # a bound on waiting, not a measurement
    while time.monotonic() < deadline and proc.poll() is None:
        if progress.exists() and len(progress.read_text().splitlines()) >= 2:  # header + one episode
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before it could be killed: " + proc.stderr.read()[-3000:]
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=30)
    assert proc.returncode == -signal.SIGKILL


def test_resume_after_sigkill(rendering, tmp_path, capsys):
    """A run killed with SIGKILL after its first finished episode resumes
    from its checkpoint and cache to the outcomes of an uninterrupted run;
    a finished run started again sends no request. The killed and the
    resumed run are processes of their own (sharing their compiled programs
    through the run's persistent compilation cache, tests/conftest.py); the
    uninterrupted run and the repeat run in this process."""
    with ScriptedServer(latency=0.4) as srv:
        url = srv.base_url
        assert evaluate_main(_evaluate(tmp_path / "full", url, tmp_path / "cache_full")) == 0
        n_full = srv.stats()["requests"]

        out = tmp_path / "killed"
        _run_killed_after_first_episode(_evaluate(out, url, tmp_path / "cache"), out / "llm" / "vlm.progress.jsonl")
        n_killed = srv.stats()["requests"] - n_full
        assert 0 < n_killed < n_full

        resumed = subprocess.run([sys.executable, "-m", "ignjax.evaluate", *_evaluate(out, url, tmp_path / "cache")],
                                 capture_output=True, text=True, timeout=900)
        assert resumed.returncode == 0, resumed.stderr[-3000:]
        assert "from an earlier run" in resumed.stderr
        n_resumed = srv.stats()["requests"] - n_full - n_killed
        # what the killed run got answered is not asked again (at most the requests in flight at the kill)
        assert n_resumed + n_killed <= n_full + 2
        assert _outcome_columns(out / "outcomes.csv") == _outcome_columns(tmp_path / "full" / "outcomes.csv")

        before = srv.stats()["requests"]
        capsys.readouterr()
        assert evaluate_main(_evaluate(out, url, tmp_path / "cache")) == 0
        again = capsys.readouterr()
        assert srv.stats()["requests"] == before and "0 requests sent" in again.err
        run = json.loads((out / "run.json").read_text())
        assert run["model_totals"]["vlm"]["requests"] + run["model_totals"]["vlm"]["cache_hits"] > 0
        # the printed summary's per-episode figures are those of the outcome rows (calls answered from the cache
        # count: their tokens do); no prices given, so no cost
        rows = read_outcomes(out / "outcomes.csv")
        calls, pt, ct = ([r[k] + (r["cache_hits"] if k == "requests" else 0) for r in rows]
                         for k in ("requests", "prompt_tokens", "completion_tokens"))
        assert (f"vlm: per episode (mean / max over 3): {np.mean(calls):.1f} / {max(calls)} model calls, "
                f"{np.mean(pt):.0f} / {max(pt)} prompt tokens, {np.mean(ct):.0f} / {max(ct)} completion tokens\n"
                in again.out), again.out
        assert run["model_totals"]["vlm"]["per_episode"]["calls"]["max"] == max(calls)
        assert all(np.isnan(r["cost_usd"]) for r in rows)
