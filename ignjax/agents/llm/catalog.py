"""The MLLM agents by name: the single-stage ``vlm`` agent
(:mod:`ignjax.agents.llm.agent`), TANDEM, its ablations and the Table-1
baselines (:mod:`ignjax.agents.llm.tandem`)."""

from __future__ import annotations

from ignjax.agents.llm.agent import LLMAgent, VlmAgent
from ignjax.agents.llm.tandem import TANDEM_AGENTS

LLM_AGENTS = {"vlm": VlmAgent, **TANDEM_AGENTS}
"""Registry of MLLM agents: name -> factory taking keyword options (``.description`` for ``--help``)."""


def get_llm_agent(name: str, **options) -> LLMAgent:
    """The MLLM agent ``name`` (:data:`LLM_AGENTS`) with its options."""
    if name not in LLM_AGENTS:
        raise KeyError(name)
    return LLM_AGENTS[name](**options)


def sim_overrides(agent: LLMAgent, llm=None) -> dict:
    """The simulator settings ``agent`` runs under: its own (``agent.sim_overrides``: the observation ablation's
    view count, the no-QA variants' upfront description) and, with ``llm.naive_unbudgeted``, no question budget
    for a naive-QA row (name ending in ``-naive``)."""
    out = dict(getattr(agent, "sim_overrides", {}) or {})
    if llm is not None and llm.naive_unbudgeted and agent.name.endswith("-naive"):
        out["question_budget"] = False
    return out


__all__ = ["LLM_AGENTS", "get_llm_agent", "sim_overrides"]
