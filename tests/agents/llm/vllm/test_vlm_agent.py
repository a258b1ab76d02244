"""The project's client and the ``vlm`` agent against the live vLLM server
(random weights, schema-constrained replies): a stress test of the loop's
handling of arbitrary but valid decisions, with the real server's
structured output, image handling and batching."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ignjax.agents.llm.agent import VlmAgent
from ignjax.agents.llm.config import LLMConfig
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig

ROOT = Path(__file__).resolve().parents[4]

pytestmark = pytest.mark.vllm


def test_vlm_agent_against_vllm(vllm_server, rendering, tmp_path):
    es = load_benchmark(ROOT / "scenes" / "benchmark.jsonl.gz", limit=3)
    llm = LLMConfig(endpoints=(vllm_server.base_url,), model=vllm_server.model, api_key_env=None, max_tokens=96,
                    cache_dir=str(tmp_path / "cache"), concurrency=8, timeout_s=120.0)
    sim = T.SimConfig(max_steps=5)
    res = run_llm_agent(es, VlmAgent(), llm, sim=sim, views=ViewConfig(size=64), batch=3, out=tmp_path / "run")
    o = res.outcomes
    # every episode finished; every decision was schema-valid or counted invalid
    assert set(o.stop_reason.tolist()) <= {T.STOPPED, T.OUT_OF_STEPS} and res.accounting["failure"] == [""] * 3
    assert len(res.transcripts) == int(o.steps.sum())
    for c in res.transcripts:
        assert c["action"] is not None and c["request_hash"] and len(c["images"]) == 1
        assert c["parsed"] is not None or c["error"]
    defaults = sum(c["error"] == "invalid replies: default action taken" for c in res.transcripts)
    assert int(res.accounting["requests"].sum()) == \
        len(res.transcripts) + int(res.accounting["invalid_replies"].sum()) - defaults
    assert (res.accounting["prompt_tokens"] > 0).all()
    # again from the cache: no request, the same outcomes
    again = run_llm_agent(es, VlmAgent(), llm, sim=sim, views=ViewConfig(size=64), batch=2)
    assert int(again.accounting["requests"].sum()) == 0
    assert np.array_equal(again.outcomes.final_distance, o.final_distance)
    assert np.array_equal(again.outcomes.steps, o.steps)
