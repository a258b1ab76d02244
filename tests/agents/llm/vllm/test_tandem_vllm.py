"""TANDEM and two baselines against the live vLLM server (random weights,
schema-constrained replies): a stress test of the agents' handling of
arbitrary but valid decisions — every episode finishes, every decision is
schema-valid or counted invalid, and the transcripts are complete."""

from __future__ import annotations

from pathlib import Path

import pytest

from ignjax.agents.llm.catalog import get_llm_agent
from ignjax.agents.llm.config import LLMConfig
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig

ROOT = Path(__file__).resolve().parents[4]

pytestmark = pytest.mark.vllm


@pytest.mark.parametrize("name", ["tandem", "coin", "navgpt"])
def test_tandem_and_baselines_against_vllm(vllm_server, rendering, tmp_path, name):
    es = load_benchmark(ROOT / "scenes" / "benchmark.jsonl.gz", limit=2)
    llm = LLMConfig(endpoints=(vllm_server.base_url,), model=vllm_server.model, api_key_env=None, max_tokens=700,
                    cache_dir=str(tmp_path / "cache"), concurrency=8, timeout_s=120.0)
    res = run_llm_agent(es, get_llm_agent(name), llm, sim=T.SimConfig(max_steps=4), views=ViewConfig(size=64),
                        batch=2, out=tmp_path / "run")
    o = res.outcomes
    assert set(o.stop_reason.tolist()) <= {T.STOPPED, T.OUT_OF_STEPS} and res.accounting["failure"] == [""] * 2
    # one decision record (its last call carries the action) per step taken, per episode
    for e, steps in zip(es.episode_ids, o.steps.tolist()):
        acted = [c for c in res.transcripts if c["episode"] == e and c["action"] is not None]
        assert len(acted) == steps
    for c in res.transcripts:
        assert c["role"] in ("planner", "grounder", "self-questioner", "controller", "caption")
        if c["role"] != "controller":
            assert c["request_hash"] and (c["parsed"] is not None or c["error"])
            assert len(c["images"]) == (0 if name == "navgpt" and c["role"] == "planner" else 1)
    # every attempt (a decision's re-asks included) was sent or answered from the cache (identical requests within
    # the run: the same view captioned twice, the front view grounded for a move and for a candidate)
    attempts = sum(1 + len(c["retries"]) for c in res.transcripts if c["role"] != "controller")
    acc = {k: int(res.accounting[k].sum()) for k in ("requests", "retries", "cache_hits")}
    assert acc["requests"] - acc["retries"] + acc["cache_hits"] == attempts
    assert (res.accounting["prompt_tokens"] > 0).all()
