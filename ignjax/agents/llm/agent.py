"""Agents driven by a multimodal model: what they read, what they may reply,
and the single-stage ``vlm`` agent.

An MLLM agent runs on the host, between the simulator's jitted steps
(:mod:`ignjax.evaluate.hostloop`). At each decision the loop gives it a
:class:`Decision` (everything the agent may read, all of it allowed to the
paper's Planner: the instruction, the remaining budgets, the question costs,
the oracle's answers so far as text, the executor's feedback on the last
move, and the Planner panel or the rendered views; the exception is the
``"text"`` observation, an ablation that reads the simulator's ground-truth
perception in words, which the paper's Planner never gets). The agent turns it into a :class:`~ignjax.agents.llm.client.ChatRequest`,
and the model's reply into an action. Nothing the paper withholds from the
Planner (world coordinates, path lengths, compass headings, target
distances) is in a :class:`Decision`.

The reply is one JSON object (:func:`decision_schema`)::

    {"action": "move" | "ask" | "stop",
     "direction": view index 0..N-1 (MOVE: the view to move in),
     "col": 1..8, "row": 1..8      (MOVE: the grid cell on that view;
                                    columns left to right, rows bottom to top;
                                    ASK type 4: the cell of the front view
                                    showing the object asked about),
     "question": 1..4              (ASK: the question type),
     "reason": short free text}

Every key is required (a schema-constrained server always fills them); the
keys an action does not use are ignored. A reply that does not parse, breaks
the schema or names a value out of range is answered with a short
correction and asked again (``reasks`` times); after that the agent takes
its default action (:meth:`LLMAgent.default_action`: a short move straight
ahead, the cell at column 4, row 1) and the reply counts as invalid.

A question asked when none is left (the budget spent) is such a reply: it is
answered with :data:`NO_QUESTIONS_LEFT` and asked again, never passed to the
simulator, and the host loop counts it in the episode's ``refused_asks``
(:mod:`ignjax.evaluate.accounting`); the prompt of a decision with no
question left says so.

The prompts are ours; they follow the paper's structure (role and task,
action rules, the grid convention, the question types and their costs, the
reply format; then the step's state and images).
"""

from __future__ import annotations

import math

from dataclasses import dataclass, field

from ignjax.agents.llm.messages import ChatRequest, ImagePart
from ignjax.protocol import view_hfov
from ignjax.sim.views.compose import view_names

MOVE, ASK, STOP = 0, 1, 2
"""Action kinds (the values of :data:`ignjax.sim.types.MOVE` etc.)."""

MOVED_M = 0.05
"""A MOVE that covered less than this (m) did not move: the way was blocked."""

NO_QUESTIONS_LEFT = "you have no questions left (your question budget is spent); choose move or stop"
"""The correction of a reply that asks with no question left (the host loop counts these as ``refused_asks``)."""

QUESTION_NAMES = {1: "appearance", 2: "region", 3: "route", 4: "confirmation"}
QUESTION_HELP = {
    1: "what the target looks like (colour, material, size, state, what it stands on or near)",
    2: "which room the target is in and what it is near",
    3: "which way to go from here (a coarse route hint toward the goal)",
    4: "whether one object in your front view is the target (the helper answers about that object only)",
}


def decision_schema(n_views: int) -> dict:
    """JSON schema of one decision (module docstring)."""
    i = lambda lo, hi: {"type": "integer", "minimum": lo, "maximum": hi}  # noqa: E731
    return {
        "type": "object",
        "properties": {
            "action": {"type": "string", "enum": ["move", "ask", "stop"]},
            "direction": i(0, n_views - 1),
            "col": i(1, 8),
            "row": i(1, 8),
            "question": i(1, 4),
            "reason": {"type": "string", "maxLength": 200},
        },
        "required": ["action", "direction", "col", "row", "question", "reason"],
        "additionalProperties": False,
    }


def compass_degrees(yaw: float) -> float:
    """A yaw (radians, counter-clockwise from the scene's +x axis, the
    simulator's convention) as a compass heading in degrees [0, 360): 0
    north (+y), 90 east (+x), 180 south, 270 west."""
    return float((90.0 - math.degrees(float(yaw))) % 360.0)


def offset_words(east: float, north: float) -> tuple[str, str]:
    """An offset from the start in words, its two axes: ``("2.3 m east", "1.0 m south")``."""
    return (f"{abs(east):.1f} m {'east' if east >= 0 else 'west'}",
            f"{abs(north):.1f} m {'north' if north >= 0 else 'south'}")


def orientation_text(d: "Decision") -> str:
    """The Planner's own heading and offset from the start, in words (the paper's runtime-wrapper fields)."""
    east, north = (float(v) for v in d.offset)
    parts = offset_words(east, north)
    where = "at your start" if max(abs(east), abs(north)) < 0.05 else " and ".join(parts) + " of your start"
    return (f"Heading of your front view: {round(d.heading) % 360} degrees (0 north, 90 east, 180 south, 270 west). "
            f"Offset from start: {where}.")


@dataclass(frozen=True)
class Decision:
    """Everything an MLLM agent may read at one decision.

    Attributes:
        episode: the episode id (for the request's tag).
        step: planner steps taken so far (0-based index of this decision).
        max_steps: the step budget.
        goal: the instruction's object ("laptop").
        questions_left: questions the agent may still ask.
        costs: the four question types' costs (the cost-aware setting shows them).
        answers: the oracle's answers so far, in order, as ``(type, text)``.
        last_move: what the executor reported about the last MOVE ("" at the
            start and after a question).
        hint_report: the controller's report on the active route hint after
            the last step: its progress and where the hinted area lies now,
            relative to the agent's current facing
            (:func:`ignjax.sim.oracle_text.hint_report_text`); "" while no
            Type-3 hint is active.
        n_views: views in the panel.
        view_fov: horizontal field of view of each view, degrees (the
            simulator's ``view_hfov``; 0: the default for ``n_views``, 90
            for 4 and 8 views, 30 for 12).
        panel: the Planner panel, encoded (None when nothing is rendered).
        observation: the symbolic observation as text (the ``"text"``
            observation: ground truth, with instance ids, metres and the room
            label); None otherwise (a ``"caption"`` agent fills in its own
            captions).
        views: the rendered views, (N, S, S, 3) uint8, for agents that show
            one view on its own (the Grounder, the captioner;
            :attr:`LLMAgent.uses_views`).
        percept: what the agent's controller may read besides the prompt
            (never shown to the model as numbers): ``open`` (8,) metres of free
            floor in each of the observation's 8 sectors (view layout of 8,
            whatever N), ``odometry`` (x, y) metres from the start (world
            axes), ``room`` the room label code the
            agent stands in (-1 unknown), ``known`` (4,) which answer types
            were received, ``goal_room`` the Type-2 room label code (-1),
            ``confirm`` the last Type-4 answer (1 yes, 0 no, -1 none),
            ``follow_up`` (1 stop now, 2 one closer move, 0 none),
            ``hint_active``, ``hint_progress`` (:data:`ignjax.sim.types.HINT_*`),
            ``hint_bearing`` the sector 0..7 (view layout of 8) in which the
            hinted area lies now, relative to the agent's facing (-1 no hint),
            ``blocked`` (8,) bool sectors blocked in the last move, ``moved``
            metres the last move covered.
        heading: the front view's compass heading, degrees in [0, 360): 0
            north (the scene's +y axis), 90 east (+x), 180 south, 270 west
            (:func:`compass_degrees` of the agent's yaw): the agent's own
            orientation, which the paper's runtime wrapper gives the Planner.
        offset: (east, north) metres the agent has moved since its start
            (its own odometry, "offset from start" in the paper's Planner
            inputs), not a coordinate of anything else.
    """

    episode: str
    step: int
    max_steps: int
    goal: str
    questions_left: int
    costs: tuple[float, ...]
    answers: tuple[tuple[int, str], ...]
    last_move: str
    n_views: int
    panel: ImagePart | None = None
    observation: str | None = None
    views: object = None
    percept: dict = field(default_factory=dict)
    view_fov: float = 0.0
    heading: float = 0.0
    offset: tuple[float, float] = (0.0, 0.0)
    hint_report: str = ""

    def __post_init__(self):
        if not self.view_fov:  # the panel's own width (:func:`ignjax.protocol.view_hfov`)
            object.__setattr__(self, "view_fov", view_hfov(self.n_views))


@dataclass
class EpisodeMemory:
    """What an agent keeps across one episode's decisions (host side)."""

    history: list = field(default_factory=list)


class LLMAgent:
    """Base of the agents the host loop drives.

    Attributes:
        name: registry name.
        description: one line for ``--help``.
        observation: ``"panel"`` (rendered images), ``"caption"`` (rendered
            views, each described by the model before the decision:
            :mod:`ignjax.agents.llm.caption`) or ``"text"`` (the simulator's
            ground-truth perception in words: an ablation, never a camera's).
        reasks: corrections before the default action.
        show_costs: the prompt lists the question costs (the cost-aware setting).
        may_ask: the agent may ask questions at all.
        uses_views: decisions carry the rendered views (:attr:`Decision.views`).
        writes_questions: an ASK decision carries the question's text, written
            by the model (``decide`` hands it to ``ctx.note_question``); False:
            the agent names the question type only (the oracle answers by type
            either way).
    """

    name = "llm"
    description = ""
    observation = "panel"
    reasks = 2
    show_costs = True
    may_ask = True
    uses_views = False
    writes_questions = False

    @property
    def renders(self) -> bool:
        """The host loop renders this agent's views (every observation but ``"text"``)."""
        return self.observation != "text"

    def start(self, episode: str) -> EpisodeMemory:
        return EpisodeMemory()

    def request(self, memory: EpisodeMemory, d: Decision) -> ChatRequest:
        raise NotImplementedError

    async def decide(self, ctx, memory: EpisodeMemory, d: Decision):
        """The action ``(kind, direction, col, row, question)`` of one
        decision. ``ctx`` (given by the host loop) sends model calls with
        re-asks (``await ctx.query(request, parse, role)``) and gives the
        Grounder image of a view (``ctx.view_image(k)``). This single-stage
        form: one planner request, parsed by :meth:`action`, the default
        action when no reply is usable."""
        act = await ctx.query(self.request(memory, d), lambda parsed, err: self.action(memory, d, parsed, err))
        return act if act is not None else ctx.default(self.default_action(memory, d))

    def correction(self, memory: EpisodeMemory, d: Decision, previous: ChatRequest, reply: str, error: str) -> ChatRequest:
        """The same request with the faulty reply and a short correction appended."""
        msgs = list(previous.messages) + [
            {"role": "assistant", "content": reply or "(empty reply)"},
            {"role": "user", "content": f"That reply cannot be used: {error}. Answer again with one JSON object "
                                        "that follows the format exactly."},
        ]
        return ChatRequest(messages=msgs, schema=previous.schema, schema_name=previous.schema_name, tag=previous.tag)

    def action(self, memory: EpisodeMemory, d: Decision, parsed: dict | None, error: str | None):
        """``(kind, direction, col, row, question)`` from a parsed reply, or
        ``(None, reason)`` when it cannot be used."""
        if parsed is None:
            return None, error or "the reply is not a JSON object"
        a = parsed.get("action")
        if a not in ("move", "ask", "stop"):
            return None, "field 'action' must be one of move, ask, stop"

        def integer(name, lo, hi):
            v = parsed.get(name)
            if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
                raise ValueError(f"field '{name}' must be an integer from {lo} to {hi}")
            return v

        try:
            if a == "move":
                act = (MOVE, integer("direction", 0, d.n_views - 1), integer("col", 1, 8), integer("row", 1, 8), 1)
            elif a == "ask":
                if not self.may_ask:
                    return None, "this agent may not ask questions; choose move or stop"
                if d.questions_left <= 0:
                    return None, NO_QUESTIONS_LEFT
                q = integer("question", 1, 4)
                # type 4 names its candidate by a cell of the front view (ignjax.evaluate.candidates)
                act = (ASK, 0, integer("col", 1, 8), integer("row", 1, 8), 4) if q == 4 else (ASK, 0, 4, 1, q)
            else:
                act = (STOP, 0, 4, 1, 1)
        except ValueError as e:
            return None, str(e)
        memory.history.append((d.step, a, act, str(parsed.get("reason", ""))[:120]))
        return act, None

    def default_action(self, memory: EpisodeMemory, d: Decision):
        """The safe action after the re-asks are spent: a short move straight ahead."""
        act = (MOVE, 0, 4, 1, 1)
        memory.history.append((d.step, "move", act, "(default after invalid replies)"))
        return act


def _history_text(memory: EpisodeMemory, names, limit: int = 6) -> str:
    lines = []
    for step, a, act, reason in memory.history[-limit:]:
        if a == "move":
            lines.append(f"step {step}: moved toward the {names[act[1]]} view, cell column {act[2]} row {act[3]}")
        elif a == "ask":
            lines.append(f"step {step}: asked a {QUESTION_NAMES[act[4]]} question")
    return "\n".join(lines) if lines else "(none yet)"


class VlmAgent(LLMAgent):
    """``vlm``: one request per decision (single stage, no memory beyond
    the recent moves): the instruction, the Planner panel (or, with
    ``observation="text"``, the simulator's ground-truth perception as text,
    instance ids, metres and room label included: an ablation with perception
    an oracle), the answers so far, the budgets; the reply is one JSON
    decision (module docstring)."""

    name = "vlm"
    description = "single-stage MLLM agent: one request per decision with the panel, answers and budgets"

    def __init__(self, observation: str = "panel", reasks: int = 2, show_costs: bool = True):
        if observation not in ("panel", "text"):
            raise ValueError(f"observation must be 'panel' or 'text', got {observation!r}")
        self.observation, self.reasks, self.show_costs = observation, int(reasks), bool(show_costs)

    def system_text(self, d: Decision) -> str:
        names = view_names(d.n_views)
        views = ", ".join(f"{k} = {n}" for k, n in enumerate(names))
        qs = "\n".join(f"  {t} ({QUESTION_NAMES[t]}): {QUESTION_HELP[t]}"
                       + (f"; costs {d.costs[t - 1]:.3f}" if self.show_costs else "") for t in range(1, 5))
        see = ("a panel of the views around you, each labelled with its name and covered by a numbered 8x8 grid"
               if self.observation == "panel" else "a text list of what each view around you shows")
        return (
            "You control a robot in a house. Your task is to find one particular object and stop next to it. "
            "Several objects of the same kind may be present; only one is the target.\n"
            f"Each turn you see {see}. Views are numbered counter-clockwise: {views}.\n"
            "Each turn choose exactly one action:\n"
            "- move: pick a view (direction) and a cell of its grid to walk toward. Columns 1-8 run left to right, "
            "rows 1-8 run bottom to top; rows 1-3 are the floor in front of you, higher rows lie further away.\n"
            "- ask: put one question to a helper who knows where the target is. Question types:\n"
            f"{qs}\n"
            "  For type 4, 'col' and 'row' name the cell of your front view (view 0) that shows the object you "
            "ask about; the helper answers about that object only.\n"
            "  Every question lowers your final score" + (" by its cost" if self.show_costs else "")
            + ", so ask only when the answer will change what you do.\n"
            "- stop: end the episode when you are next to the target (within about a metre and a half).\n"
            "Reply with one JSON object and nothing else: "
            '{"action": "move"|"ask"|"stop", "direction": <view number>, "col": <1-8>, "row": <1-8>, '
            '"question": <1-4>, "reason": "<a few words>"}. Fill every key; keys your action does not use are ignored.'
        )

    def state_text(self, memory: EpisodeMemory, d: Decision) -> str:
        answers = "\n".join(f"- ({QUESTION_NAMES[t]}) {text}" for t, text in d.answers) or "(no questions asked yet)"
        parts = [
            f"Find the {d.goal}.",
            f"Turn {d.step + 1} of at most {d.max_steps}. Questions left: {d.questions_left}."
            + (" Your question budget is spent: do not ask; choose move or stop." if d.questions_left <= 0 else ""),
            f"What the helper has told you:\n{answers}",
            f"Your recent actions:\n{_history_text(memory, view_names(d.n_views))}",
        ]
        if d.last_move:
            parts.append(f"Last move: {d.last_move}")
        if d.hint_report:
            parts.append(f"Route hint: {d.hint_report}")
        if self.observation == "text":
            parts.append(f"What you see:\n{d.observation}")
        else:
            parts.append("The panel of your views follows.")
        return "\n\n".join(parts)

    def request(self, memory: EpisodeMemory, d: Decision) -> ChatRequest:
        content: list = [self.state_text(memory, d)]
        if self.observation == "panel":
            if d.panel is None:
                raise ValueError("the vlm agent reads the panel, but the decision carries none")
            content.append(d.panel)
        return ChatRequest(messages=[{"role": "system", "content": self.system_text(d)},
                                     {"role": "user", "content": content}],
                           schema=decision_schema(d.n_views), tag=d.episode)


__all__ = ["ASK", "Decision", "EpisodeMemory", "LLMAgent", "MOVE", "MOVED_M", "NO_QUESTIONS_LEFT", "QUESTION_NAMES",
           "STOP", "VlmAgent", "decision_schema"]
