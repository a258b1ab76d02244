"""What an MLLM agent's model calls cost, episode by episode, and the
transcript records of those calls (:mod:`ignjax.evaluate.hostloop` keeps
one of each per episode).

Counting (the outcome table's accounting columns,
:data:`ignjax.evaluate.outcomes.ACCOUNTING_COLUMNS`):

* ``requests``: every HTTP attempt sent to a server, whether a reply came
  back or not. A call answered at its k-th attempt counts k requests and
  ``k - 1`` retries; a call whose attempts all failed (timeouts, refused or
  dropped connections, error statuses; the client's retry caps spent) counts
  its attempts and ``attempts - 1`` retries. A call answered from the reply
  cache counts in ``cache_hits`` and sends nothing. So the ``requests`` of
  the episodes a run played sum to what its client sent.
* ``prompt_tokens``, ``completion_tokens``: as the server counted them,
  cache hits included (a replayed run costs what the original did).
* ``invalid_replies``: replies that could not be used (answered with a
  correction, or the agent's default action taken).
* ``refused_asks``: replies that asked a question when none was left (the
  question budget spent). They are answered with a correction saying so
  (:data:`ignjax.agents.llm.agent.NO_QUESTIONS_LEFT`) and asked again, so
  the question never reaches the simulator; each is an invalid reply too.
* ``model_latency_s``: seconds waited on replies sent in this run.

Transcript records (:func:`call_record`; the viewer's schema,
:mod:`ignjax.view`): one per model call, plus one with role
``"controller"`` for a decision the agent's controller took without a
model call, carrying ``rule`` (which rule fired) and ``text`` (what it
did: the question it asked, the action it took, in words). A model call
whose decision a rule changed (TANDEM's stop turned into a confirmation
question) carries the same two keys.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from ignjax.agents.llm.agent import ASK, NO_QUESTIONS_LEFT, Decision
from ignjax.agents.llm.messages import ChatResult, ImagePart, LLMRequestError
from ignjax.evaluate.outcomes import ACCOUNTING_COLUMNS
from ignjax.fileio import atomic_write

ACCOUNTING = tuple(c for c in ACCOUNTING_COLUMNS if c != "failure")
"""Per-episode counters of an MLLM agent (:data:`ignjax.evaluate.outcomes.ACCOUNTING_COLUMNS`;
``failure`` is kept beside them as text)."""


def new_accounting() -> dict:
    """An episode's counters, all zero."""
    return {k: 0 for k in ACCOUNTING}


def count_reply(acc: dict, res: ChatResult) -> None:
    """Add one answered call to ``acc`` (module docstring)."""
    sent = 0 if res.cache_hit else 1 + int(res.retries)
    acc["requests"] += sent
    acc["cache_hits"] += int(res.cache_hit)
    acc["prompt_tokens"] += res.prompt_tokens
    acc["completion_tokens"] += res.completion_tokens
    acc["retries"] += 0 if res.cache_hit else int(res.retries)
    acc["model_latency_s"] += 0.0 if res.cache_hit else res.latency_s


def count_failed_call(acc: dict, err: LLMRequestError) -> None:
    """Add one call whose attempts all failed to ``acc``: each attempt is a request, all but the first a retry."""
    acc["requests"] += int(err.attempts)
    acc["retries"] += max(0, int(err.attempts) - 1)


def count_unusable(acc: dict, error: str | None) -> None:
    """Add one reply the agent could not use (an invalid reply; a refused ask when it asked with none left)."""
    acc["invalid_replies"] += 1
    acc["refused_asks"] += int(error == NO_QUESTIONS_LEFT)


def _prompt_text(msgs) -> str:
    return "\n\n".join(p if isinstance(p, str) else p.get("text", "") if isinstance(p, dict) else f"[image {p.sha256[:12]}]"
                       for m in msgs for p in ([m["content"]] if isinstance(m["content"], str) else m["content"]))


def call_record(agent: str, d: Decision, req, res: ChatResult | None, act, earlier: list, error: str | None,
                role: str = "planner") -> dict:
    """The transcript record of one model call (``req`` None: no request was sent)."""
    msgs = req.messages if req is not None else []
    images = [p.sha256 for m in msgs if not isinstance(m["content"], str) for p in m["content"]
              if isinstance(p, ImagePart)]
    return {"agent": agent, "episode": d.episode, "step": d.step, "role": role, "prompt": _prompt_text(msgs),
            "reply": res.text if res else "", "parsed": res.parsed if res else None, "retries": earlier,
            "error": error, "action": list(act) if act else None,
            "request_hash": res.request_hash if res else None, "images": images,
            "prompt_tokens": res.prompt_tokens if res else 0, "completion_tokens": res.completion_tokens if res else 0,
            "latency_s": round(res.latency_s, 4) if res else 0.0, "cache_hit": bool(res.cache_hit) if res else False,
            "http_retries": res.retries if res else 0}


def controller_record(agent: str, d: Decision, act, rule: str, text: str) -> dict:
    """The transcript record of a decision the controller took without a model call: the rule and what it did."""
    return {**call_record(agent, d, None, None, act, [], None, role="controller"), "rule": rule, "text": text}


def question_texts(calls: list) -> list[dict]:
    """The question texts of transcript records (``calls``: :attr:`~ignjax.evaluate.hostloop.LoopResult.transcripts`
    or the lines of ``transcripts/<agent>.jsonl``): one ``{"episode": id, "step": s,
    "type": t, "text": str}`` per ASK decision of an agent that writes its questions
    ("" where it asked without one)."""
    return [{"episode": c["episode"], "step": int(c["step"]), "type": int(c["action"][4]), "text": c["question"]}
            for c in calls if "question" in c and c.get("action") and c["action"][0] == ASK]


def write_transcripts(folder: str | os.PathLike, agent: str, calls: list) -> Path:
    """``<folder>/transcripts/<agent>.jsonl``: one record per model call, sorted by
    episode (file order) and step (:mod:`ignjax.view`'s transcript schema plus
    request hash, image hashes, tokens, latency, cache hit; the controller's
    records with ``rule`` and ``text``)."""
    path = Path(folder) / "transcripts" / f"{agent}.jsonl"
    atomic_write(path, "".join(json.dumps(c, sort_keys=True) + "\n" for c in calls))
    return path


def run_line(agent: str, episodes: int, seconds: float, stats: dict) -> str:
    """The line a command prints when an MLLM agent's run ends: what was sent in this run (not what the
    outcome table records, which includes the episodes kept from earlier runs), and what was kept or run again."""
    kept = f"{stats['resumed']} episodes kept from an earlier run"
    again = f", {stats['rerun']} run again after a model failure" if stats.get("rerun") else ""
    return (f"{agent}: {episodes} episodes in {seconds:.1f} s, {stats['requests']} requests sent in this run "
            f"({stats['retries']} retries; {kept}{again})")


__all__ = ["ACCOUNTING", "call_record", "controller_record", "count_failed_call", "count_reply", "count_unusable",
           "new_accounting", "question_texts", "run_line", "write_transcripts"]
