"""A self-check of the candidate before the helper is asked about it: the
COIN-style option ``self_questions`` of :class:`~ignjax.agents.llm.tandem.Tandem`.

COIN (Taioli et al., 2025, "Collaborative Instance Object Navigation"; its
method AIUTA) puts two modules between detecting a candidate and talking to
the user. The **Self-Questioner** has the vision-language model describe
what it sees, pose attribute questions about the candidate to itself and
answer them from the image, keeping only the answers it is certain of (the
paper estimates that certainty from the normalized entropy of the model's
answer distribution), which yields a refined description. The
**Interaction Trigger** then weighs the refined description against the
facts known about the target and decides to ask the user, to go on
searching, or to stop.

Here, on the unified interface (one OpenAI-compatible model, the typed
oracle):

* **When.** The Planner's decision is a confirmation question (Type 4,
  also a stop that the stop policy turned into one) or a stop the oracle has
  not backed (no "yes" to a confirmation, no hint saying the target is
  near): :func:`due`.
* **Self-Questioner** (one request, role ``self-questioner``): the front
  view, the candidate the Planner named (its ``subgoal``) and the Fact
  Base's appearance answers (the oracle's Type-1 answers). The reply
  (:data:`SCHEMA`) is a detailed ``description`` and
  :data:`MIN_QUESTIONS`-:data:`MAX_QUESTIONS` ``self_questions``, each an
  attribute question with the ``answer`` read from the image, a
  ``certainty`` (``certain`` or ``unsure``) and whether the answer
  ``agrees`` with, ``contradicts`` or is ``not stated`` by the Fact Base.
  Unsure answers are dropped (:func:`refine`): the model states its own
  certainty in words, as a chat endpoint gives no answer distribution to
  take an entropy of.
* **Interaction Trigger** (host code, :func:`trigger`): the candidate is
  not the target when at least one *certain* answer contradicts the Fact
  Base, and the Fact Base holds an appearance answer at all (nothing stated
  cannot be contradicted). Then the question or stop is skipped: nothing is
  asked or charged, and the Planner is asked again with a correction
  (:func:`conflict_text`) that rules out a confirmation or a stop this turn.
  Otherwise the decision goes ahead as the Planner made it. The rule reads
  only the model's reply and the oracle's answers.
* **Memory.** The outcome goes to Spatial Memory's candidate status
  (:func:`status_text`), which the Planner sees on later turns.

Left out: the paper's third branch (stop without asking when the refined
description matches the facts well enough) would let the self-check replace
the oracle's confirmation; here a match only lets the Planner's own choice
stand, so confirmation stays the oracle's, as for every other agent.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

from ignjax.agents.llm.agent import ASK, STOP, Decision
from ignjax.agents.llm.messages import ChatRequest
from ignjax.agents.llm.controller import TEXT_CHARS, clip
from ignjax.sim import types as T
from ignjax.sim.oracle_text import refused_text

ROLE = "self-questioner"
"""The transcript role of the Self-Questioner's request."""
MIN_QUESTIONS, MAX_QUESTIONS = 2, 5
"""Attribute questions the model poses to itself."""
CERTAINTY = ("certain", "unsure")
RELATIONS = ("agrees", "contradicts", "not stated")
DESCRIPTION_CHARS = 400

SCHEMA = {
    "type": "object",
    "properties": {
        "description": {"type": "string", "maxLength": DESCRIPTION_CHARS},
        "self_questions": {
            "type": "array",
            "minItems": MIN_QUESTIONS,
            "maxItems": MAX_QUESTIONS,
            "items": {
                "type": "object",
                "properties": {"question": {"type": "string", "maxLength": TEXT_CHARS},
                               "answer": {"type": "string", "maxLength": TEXT_CHARS},
                               "certainty": {"type": "string", "enum": list(CERTAINTY)},
                               "fact_base": {"type": "string", "enum": list(RELATIONS)}},
                "required": ["question", "answer", "certainty", "fact_base"],
                "additionalProperties": False,
            },
        },
    },
    "required": ["description", "self_questions"],
    "additionalProperties": False,
}
"""JSON schema of the Self-Questioner's reply."""

SYSTEM = (
    "You check one object in a camera view before anyone is asked about it. First describe the object named below "
    "in detail as you see it (colour, material, shape, size, parts, what is on or next to it). Then pose yourself "
    f"{MIN_QUESTIONS} to {MAX_QUESTIONS} short questions about its attributes, choosing the attributes the known "
    "facts about the target mention, and answer each from the image alone. For each answer give 'certainty': "
    "'certain' only when the image clearly shows it, else 'unsure' (far away, dark, hidden, cut off, or you are "
    "guessing). Then compare the answer with the known facts: 'agrees', 'contradicts' (the facts say otherwise), or "
    "'not stated' (the facts say nothing about it). Reply with one JSON object: {\"description\": \"...\", "
    "\"self_questions\": [{\"question\": \"...\", \"answer\": \"...\", \"certainty\": \"certain | unsure\", "
    "\"fact_base\": \"agrees | contradicts | not stated\"}]}.")
"""The Self-Questioner's system prompt (our words)."""

PROMPT = (
    "Self-check: before a confirmation question (type 4) or a stop, you take a close look at the object you named "
    "in 'subgoal' and compare what you are certain of with the Fact Base. If it contradicts the Fact Base, the "
    "object is not the target: nothing is asked, and you are asked to choose again. The result appears as the "
    "candidate's status.")
"""The Planner's system-prompt block for the option (our words)."""


@dataclass
class SelfCheck:
    """One Self-Questioner reply: the description and the answers kept (certain) or dropped (unsure)."""

    description: str
    kept: list = field(default_factory=list)  # (question, answer, relation) of certain answers
    dropped: int = 0


def due(act, d: Decision) -> bool:
    """The decision is a confirmation question, or a stop the oracle has not backed."""
    if act[0] == ASK:
        return act[4] == 4
    if act[0] == STOP:
        p = d.percept
        return not (p.get("confirm") == 1 or p.get("hint_progress") == T.HINT_STOP)
    return False


def appearance_facts(d: Decision) -> list[str]:
    """The Fact Base's appearance answers (the oracle's Type-1 answers, refusals left out), each once."""
    return list(dict.fromkeys(text for q, text in d.answers if q == 1 and text != refused_text()))


def candidate_of(parsed: dict, d: Decision) -> str:
    """The object the Planner's decision is about: its subgoal, else its question, else the goal."""
    return clip(parsed.get("subgoal")) or clip(parsed.get("question")) or f"the {d.goal}"


def request(d: Decision, image, candidate: str) -> ChatRequest:
    """The Self-Questioner's request: the front view, the candidate and the Fact Base's appearance answers."""
    facts = appearance_facts(d)
    text = (f"Target: a {d.goal}.\nObject to check: {candidate}\nKnown facts about the target's appearance: "
            + ("; ".join(facts) if facts else "none yet") + "\nCurrent front view:")
    return ChatRequest(messages=[{"role": "system", "content": SYSTEM}, {"role": "user", "content": [text, image]}],
                       schema=SCHEMA, schema_name="self_questions", tag=d.episode)


def refine(parsed, err):
    """``(SelfCheck, None)`` from a reply, unsure answers dropped, or ``(None, why)``."""
    if parsed is None:
        return None, err or "the reply is not a JSON object"
    description = clip(parsed.get("description"), DESCRIPTION_CHARS)
    items = parsed.get("self_questions")
    if not description:
        return None, "field 'description' must describe the object"
    if not isinstance(items, list) or not MIN_QUESTIONS <= len(items) <= MAX_QUESTIONS:
        return None, f"field 'self_questions' must list {MIN_QUESTIONS} to {MAX_QUESTIONS} questions"
    out = SelfCheck(description)
    for x in items:
        ok = (isinstance(x, dict) and clip(x.get("question")) and clip(x.get("answer"))
              and x.get("certainty") in CERTAINTY and x.get("fact_base") in RELATIONS)
        if not ok:
            return None, ("each self-question needs a 'question', an 'answer', 'certainty' (certain | unsure) and "
                          "'fact_base' (agrees | contradicts | not stated)")
        if x["certainty"] == "certain":
            out.kept.append((clip(x["question"]), clip(x["answer"]), x["fact_base"]))
        else:
            out.dropped += 1
    return out, None


def trigger(check: SelfCheck, d: Decision) -> list[str]:
    """The Interaction Trigger: the certain answers that contradict the Fact Base (empty: go ahead). None count
    while the Fact Base holds no appearance answer."""
    if not appearance_facts(d):
        return []
    return [answer for _, answer, relation in check.kept if relation == "contradicts"]


def status_text(step: int, candidate: str, check: SelfCheck, conflicts: list[str]) -> str:
    """The candidate-status entry of one self-check."""
    if conflicts:
        return clip(f"step {step}: {candidate}: own check says not the target ({'; '.join(conflicts)})", TEXT_CHARS)
    seen = "; ".join(a for _, a, _ in check.kept) or check.description
    return clip(f"step {step}: {candidate}: own check found no conflict ({seen})", TEXT_CHARS)


def conflict_text(candidate: str, conflicts: list[str]) -> str:
    """The correction after a self-check that rules the candidate out."""
    return (f"your own close look at {candidate} found {'; '.join(conflicts)}, which contradicts the Fact Base, so it "
            "is not the target; do not ask a confirmation question or stop here, move on (or ask another type)")


async def self_check(agent, ctx, m, d: Decision, planner_req: ChatRequest, plan):
    """Run the self-check on the Planner's accepted ``plan`` (``(action, parsed)``) when it is due; returns the plan
    to carry out: the same one, or, after a conflict, the Planner's corrected one (None when no reply was usable)."""
    act, parsed = plan
    if not due(act, d):
        return plan
    candidate = candidate_of(parsed, d)
    check = await ctx.query(request(d, ctx.view_image(0), candidate), refine, role=ROLE)
    if check is None:
        return plan  # no usable self-check: the decision stands
    conflicts = trigger(check, d)
    m.candidates.append(status_text(d.step, candidate, check, conflicts))
    if not conflicts:
        return plan
    why = conflict_text(candidate, conflicts)
    ctx.note_rule("interaction trigger", f"the self-check of {candidate} contradicts the Fact Base "
                                         f"({'; '.join(conflicts)}): no confirmation or stop, the Planner chooses again")

    def parse(parsed2, err):
        value, error = agent._parse_plan(m, d, parsed2, err)
        if value is not None and (value[0][0] == STOP or (value[0][0] == ASK and value[0][4] == 4)):
            return None, why
        return value, error

    again = agent.correction(m, d, planner_req, json.dumps(parsed), why)
    return await ctx.query(again, parse)


__all__ = ["CERTAINTY", "MAX_QUESTIONS", "MIN_QUESTIONS", "PROMPT", "RELATIONS", "ROLE", "SCHEMA", "SelfCheck",
           "appearance_facts", "candidate_of", "conflict_text", "due", "refine", "request", "self_check",
           "status_text", "trigger"]
