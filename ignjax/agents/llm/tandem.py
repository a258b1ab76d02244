"""TANDEM, the paper's two-stage MLLM navigator, its ablations and the
baselines of Table 1 as configurations of one machinery.

One decision of :class:`Tandem`:

1. **Controller first** (host code, no model call) when a rule settles
   the decision (:mod:`ignjax.agents.llm.controller`): after a "yes" to a
   confirmation question with the follow-up "stop now", STOP; the paper's
   early-question schedule (one of Type 1/2 by the second decision, both by
   the fifth) asks a missing one; the recovery rule (several moves without
   a route hint while nothing the agent knows places it near the goal,
   questions left) asks a route question (Type 3).
2. **Planner** (one request): the instruction, the N-view panel (or, for the
   NavGPT-style baseline, each view described in words by a captioning
   request per view to the same model first: :mod:`ignjax.agents.llm.caption`),
   the Fact Base (the oracle's answers, by type), the active route hint
   (as first spoken, where the hinted area lies now relative to the agent's
   facing, and its progress: :func:`hint_block`), the follow-up state, the
   Spatial Memory (current place, target facts, visited areas, unexplored
   openings, route hints, blocked moves, candidate status), recent movement
   history, the steps and questions left and, in the cost-aware setting,
   each question's cost. It
   replies with one JSON decision (:func:`planner_schema`): ask (type and
   question), move (direction, a place-based subgoal, purpose) or stop
   (with its evidence), plus a belief update that the controller merges into
   Spatial Memory. The oracle answers a question by its type; the
   question's text goes to the decision's transcript record
   (``ctx.note_question``; none when the controller asks on its own), where
   the Type-3 content analysis reads it.
3. **Controller checks** on the Planner's decision
   (:mod:`ignjax.agents.llm.controller`); a decision that breaks a rule is
   answered with a correction (:data:`~ignjax.agents.llm.controller.CORRECTIONS`,
   which say only what the agent could know) and asked again (counted as an
   invalid reply, like a malformed one): a Type-1/2 question whose fact is
   already in the Fact Base (safeguard 1); a route question where none of
   its triggers holds (safeguard 2); any question, or a backward move,
   while the follow-up asks for "one closer move" (safeguard 3); a second
   backward move in a row when the last was not blocked (anti-oscillation).
   Every STOP without evidence (no confirmed target, no hint saying the
   target is near) is turned into a confirmation question when questions
   are left (the stop policy: confirm before stopping); right after a "no"
   with no move since, it is corrected instead.
4. **Grounder** (one request, MOVE only): the selected view alone with its
   numbered 8x8 grid, the subgoal and the purpose; the reply is one cell
   (columns left to right, rows bottom to top; rows 1-3 for floor targets),
   which the executor turns into a waypoint. An unusable Grounder reply
   falls back to the centre cell of row 2.

The prompts are ours, written to the paper's structure (role and
observation; memory and interaction; question, hint and recovery policies;
output contract; runtime state). Everything numeric the controller reads
(free space per sector, odometry for loops) comes from
:attr:`~ignjax.agents.llm.agent.Decision.percept` and never reaches the
model as a number; where the agent is by room, the controller takes from
the Planner's own belief updates, and the goal room from the oracle's
Type-2 answer. The numbers the model does see are its own: the front
view's heading, its offset from the start (:attr:`Decision.offset`) and,
with ``memory_style="graph"``, the place graph built from that offset.

Variants (:data:`TANDEM_AGENTS`, docs/agents.md "MLLM agents"): ``tandem``;
``tandem-no-spmem`` (no Spatial Memory: belief updates dropped, the memory
block not shown); ``tandem-no-qa`` (never asks; the target's full
description given at reset, as the paper's QA-off row); ``tandem-no-spmem-no-qa``;
``tandem-naive`` (no costs shown, no safeguards: the naive-QA protocol);
``tandem-4v`` / ``tandem-12v`` (the observation ablation: 4 views of 90
degrees or 12 narrow views of 30, each set tiling the circle;
:func:`ignjax.protocol.view_hfov`).
Baselines in the style of the paper's adaptations (our reading of each, on
this machinery; the paper's own code is not used): ``gta``
(Planner-Grounder; instead of Spatial Memory a topological graph of places
from the agent's own odometry, with visit counts and a loop alert, and a
Planner that weighs directions before choosing), ``coin`` (no route questions; a
self-check of each candidate before a confirmation or a stop, whose conflict
with the Fact Base skips the question: :mod:`ignjax.agents.llm.self_questioner`),
``mapgpt`` (one stage: the Planner picks the grid cell itself, with a
map-like text memory of places and their links), ``navgpt`` (one stage,
text only: the Planner reads a caption of each view, written by the same
model from the rendered view before the Planner request; it picks the cell
from the grid convention in words, without an image); each in a cost-aware
form (costs shown, safeguards on) and a naive-QA form (``-naive``). The
``"text"`` observation (each view described from the simulator's
ground-truth perception, instance ids, metres and the room label included)
is kept as an option for ablations and tests; no named agent uses it.
"""

from __future__ import annotations

import dataclasses

from ignjax.agents.llm.agent import (ASK, MOVE, MOVED_M, QUESTION_HELP, QUESTION_NAMES, STOP, Decision, LLMAgent,
                                     orientation_text)
from ignjax.agents.llm.caption import describe_views
from ignjax.agents.llm.messages import ChatRequest
from ignjax.agents.llm.controller import RECOVERY_MOVES, TandemController, TandemMemory, clip, rear
from ignjax.agents.llm.counterfactual import PROMPT as COUNTERFACTUAL_PROMPT
from ignjax.agents.llm.counterfactual import counterfactual_error, with_counterfactuals
from ignjax.agents.llm.graph_memory import MERGE_M, graph_text
from ignjax.agents.llm.schemas import (GROUNDER_SCHEMA, MEMORY_ITEMS, PHASES, one_stage_schema, parse_cell,
                                       planner_schema)
from ignjax.agents.llm.self_questioner import PROMPT as SELF_CHECK_PROMPT
from ignjax.agents.llm.self_questioner import candidate_of, self_check
from ignjax.sim import oracle_text as OT
from ignjax.sim import types as T
from ignjax.sim.views.compose import view_names

GROUNDER_FALLBACK = (4, 2)
"""Cell taken when no Grounder reply is usable: centre column, near floor."""
CANDIDATE_FALLBACK = (4, 4)
"""Candidate cell of a Type-4 question when no Grounder reply is usable: the front view's middle."""


def hint_block(hint: str, progress: int, bearing: int) -> str:
    """The Planner's "Active route hint" block: the hint as the oracle first
    spoke it, where the hinted area lies now relative to the agent's current
    facing (``Decision.percept["hint_bearing"]``, recomputed by the simulator
    after every move, so "on your left" does not outlive a turn) and the
    progress since the last move (:mod:`ignjax.sim.oracle_text` words both)."""
    lines = [f"Active route hint: {hint}"]
    way = OT.hint_bearing_phrase(progress, bearing)
    if way:
        lines.append(f"Where the hinted area lies now: {way}.")
    if said := OT.hint_progress_text(progress):
        lines.append(f"Progress: {said}")
    return "\n".join(lines)


class Tandem(TandemController, LLMAgent):
    """TANDEM and its variants (module docstring).

    Args:
        spatial_memory: keep and show Spatial Memory (belief updates merged).
        qa: the agent may ask questions (False: the target's full description
            is given at reset, ``sim.upfront_description``).
        cost_aware: the prompt shows each question type's cost.
        safeguards: the controller's four safeguards, the early-question
            schedule, anti-oscillation and the stop policy
            (:mod:`ignjax.agents.llm.controller`; False: the naive protocol,
            every decision the model's).
        two_stage: a Grounder picks the cell (False: the Planner picks it).
        route_questions: Type 3 may be asked (False: COIN-style).
        memory_style: ``"spatial"`` (the paper's fields), ``"map"``
            (MapGPT-style: places visited and how they connect) or
            ``"graph"`` (GTA-style: a topological graph of places from the
            agent's own odometry, with visit counts and a loop alert;
            :mod:`ignjax.agents.llm.graph_memory`).
        counterfactual: the Planner's reply weighs directions before choosing
            (GTA-style; :mod:`ignjax.agents.llm.counterfactual`).
        self_questions: a self-check of the candidate before a confirmation
            or a stop (COIN-style; :mod:`ignjax.agents.llm.self_questioner`;
            needs the panel observation).
        observation: ``"panel"``, ``"caption"`` (NavGPT-style: one
            captioning request per view, then the Planner reads the captions;
            :mod:`ignjax.agents.llm.caption`) or ``"text"`` (the simulator's
            ground-truth perception in words: an ablation).
        n_views: views of the panel (4, 8 or 12; the observation ablation).
        reasks: corrections before the default action.
    """

    name = "tandem"
    description = "TANDEM: Planner + Grounder, Spatial Memory, Fact Base, cost-aware typed questions, safeguards"
    uses_views = True

    def __init__(self, spatial_memory: bool = True, qa: bool = True, cost_aware: bool = True, safeguards: bool = True,
                 two_stage: bool = True, route_questions: bool = True, memory_style: str = "spatial",
                 counterfactual: bool = False, self_questions: bool = False, observation: str = "panel",
                 n_views: int | None = None, reasks: int = 2):
        if observation not in ("panel", "caption", "text"):
            raise ValueError(f"observation must be 'panel', 'caption' or 'text', got {observation!r}")
        if memory_style not in ("spatial", "map", "graph"):
            raise ValueError(f"memory_style must be 'spatial', 'map' or 'graph', got {memory_style!r}")
        if self_questions and observation != "panel":
            raise ValueError("self_questions reads the front view: it needs observation='panel'")
        if n_views not in (None, 4, 8, 12):
            raise ValueError(f"n_views must be 4, 8 or 12, got {n_views!r}")
        self.spatial_memory, self.qa, self.show_costs = bool(spatial_memory), bool(qa), bool(cost_aware)
        self.safeguards, self.two_stage, self.route_questions = bool(safeguards), bool(two_stage), bool(route_questions)
        self.memory_style, self.observation, self.n_views, self.reasks = memory_style, observation, n_views, int(reasks)
        self.counterfactual, self.self_questions = bool(counterfactual), bool(self_questions)
        self.may_ask = self.qa
        self.uses_views = ((self.two_stage or self.self_questions) and observation == "panel") or observation == "caption"

    @property
    def writes_questions(self) -> bool:
        """The Planner writes each question's text (field ``question``) whenever it may ask."""
        return self.qa

    @property
    def sim_overrides(self) -> dict:
        """Simulator settings this agent runs under (applied by the host loop)."""
        out = {}
        if not self.qa:
            out["upfront_description"] = True
        if self.n_views is not None:
            out["n_views"] = self.n_views
        return out

    def start(self, episode: str) -> TandemMemory:
        return TandemMemory()

    # -- prompts -----------------------------------------------------------
    def planner_system(self, d: Decision) -> str:
        names = view_names(d.n_views)
        qtypes = [t for t in (1, 2, 3, 4) if self.route_questions or t != 3]
        costs = (lambda t: f" (costs {d.costs[t - 1]:.3f})") if self.show_costs else (lambda t: "")
        see = (f"one image of {d.n_views} camera views around you, each {d.view_fov:g} degrees wide and labelled with its "
               f"direction ({', '.join(names)}), arranged as a map around a centre cell: front is up, left is left"
               if self.observation == "panel" else
               f"a written description of what each of your {d.n_views} directions shows ({', '.join(names)}); each "
               f"was written by a captioning model that looked at that direction's camera view ({d.view_fov:g} degrees "
               "wide) and may miss or misname things; you do not see the images"
               if self.observation == "caption" else
               f"a written description of what each of your {d.n_views} directions shows ({', '.join(names)}); the "
               "descriptions come from the simulator's perception, not from a camera")
        blocks = [
            # block 1: role, environment, observation
            "You are the planner of a robot searching a house for one particular object. Several objects of the "
            "same kind may be there; only one is the target. You decide what to do next and why; a separate module "
            "turns your choice of direction and place into motion, and obstacle avoidance is handled for you. Stay "
            f"indoors.\nEach turn you receive {see}.",
        ]
        if self.qa:
            blocks.append(
                # block 2: memory and interaction
                self.memory_intro(detail=True)
                + "You may ask a helper who knows the house. Question types:\n"
                + "\n".join(f"  {t} ({QUESTION_NAMES[t]}): {QUESTION_HELP[t]}{costs(t)}" for t in qtypes)
                + "\nEvery question lowers the final score" + (" by its cost" if self.show_costs else "")
                + "; ask only when the answer changes your next decision, and never ask what the Fact Base already "
                "says.")
            blocks.append(self.policies_text())  # block 3: question, hint and recovery policies
        else:
            blocks.append(
                self.memory_intro(detail=False)
                + "You cannot ask questions: the target's description is given in the Fact Base. Stop when you are "
                "next to the target. Avoid going back and forth.")
        cell = (" and 'col', 'row': the cell of the grid on that view to walk toward (" + (
                "the view is divided into an 8x8 grid you do not see; " if self.observation != "panel" else "")
                + "columns 1-8 left to right, rows 1-8 bottom to top; rows 1-3 are the floor ahead, higher rows lie "
                "further away or on walls); for a confirmation question (type 4), the cell of your front view that "
                "shows the object you ask about" if not self.two_stage else
                "; for a confirmation question (type 4), 'subgoal' names the object you ask about, which must be in "
                "your front view (a stop without confirmation becomes such a question about your subgoal)")
        weigh = ("'counterfactuals' (the directions you weighed, each with 'direction' and 'expected'), "
                 if self.counterfactual else "")
        if self.counterfactual:
            blocks.append(COUNTERFACTUAL_PROMPT)  # GTA-style: weigh alternatives before choosing
        if self.self_questions:
            blocks.append(SELF_CHECK_PROMPT)  # COIN-style: a self-check before a confirmation or a stop
        blocks.append(
            # block 4: output contract
            "Reply with one JSON object and nothing else, with every key present: 'reasoning' (short), 'task_phase' "
            f"({' | '.join(PHASES)}), 'belief_update' (current_room, target_description, visited_areas, "
            f"unexplored_areas, key_observations), {weigh}'action' (move | ask | stop), 'direction' (one of "
            f"{', '.join(names)}), 'subgoal' (the place to reach in that view, e.g. 'the centre of the open doorway', "
            "not an action like 'explore'), 'purpose' (why), 'question_type' (1-4) and 'question' (the question's "
            f"text){cell}. Keys your action does not use are ignored.")
        return "\n\n".join(blocks)

    def memory_intro(self, detail: bool) -> str:
        """The system prompt's sentence on the agent's memory ("" without one)."""
        if not self.spatial_memory:
            return ""
        if self.memory_style == "graph":
            return ("Each turn you also get a graph of the places you have been, built from your own odometry: each "
                    "place with its position in metres from your start, how many times you have entered it and which "
                    f"places it links to (positions within {MERGE_M:g} m count as one place). Use it to keep track of "
                    "where you have been; when it shows a loop alert, re-plan and head for a place you have not "
                    "been.\n")
        if not detail:
            return "You keep a memory of the search (given back to you each turn) and update it in 'belief_update'.\n"
        return ("You keep a memory of the search (given back to you each turn) and update it in 'belief_update': "
                "the room you think you are in, what you know about the target, areas you have visited and what "
                "was there, openings you have not explored yet, and anything else worth remembering.\n")

    def policies_text(self) -> str:
        """Block 3 of the Planner's system prompt: question, hint, stop and recovery policies."""
        by_you = " (otherwise the controller asks for you)" if self.safeguards else ""
        return (
            "Policies:\n"
            "- Early questions: while the Fact Base lacks the target's appearance or room, ask for them early: one of "
            f"the two by your second turn and both by your fifth while questions remain{by_you}. Once the Fact Base "
            "holds them, do not ask them again.\n"
            + ("- A route question fits a junction with several plausible ways, a loop (you are back where you "
               "were), a long corridor, or a known goal room whose way in is unclear. While a route hint is "
               "active, use it as your main bias and choose short, reachable places on the hinted side (after each "
               "move you are told where the hinted area lies now, relative to your new facing: follow that side, "
               "not the words first spoken); trust what you see if it contradicts the hint.\n"
               if self.route_questions else "")
            + "- Ask for a confirmation when an object in front of you might be the target. After a yes with "
            "'move closer', make exactly one move toward it and then stop; after a plain yes, stop.\n"
            "- Stop only when the target is confirmed or a hint says you are close enough to it"
            + ("; a stop without that is turned into a confirmation question while questions remain" if self.safeguards
               else "") + ".\n"
            "- Avoid going back and forth: backward directions are for recovery (dead end, wrong room); after one "
            "backward move prefer a new front or side way.")

    def memory_text(self, m: TandemMemory) -> str:
        if self.memory_style == "graph":
            return graph_text(m.graph)
        if self.memory_style == "map":
            return ("Places so far (in order; each reached from the one before):\n"
                    + ("\n".join(f"- {p}" for p in m.places[-MEMORY_ITEMS * 2:]) or "- (start)"))
        lines = [f"Current place: {m.current_room}", f"Target facts: {m.target_description}",
                 "Visited areas: " + ("; ".join(m.visited) or "none yet"),
                 "Unexplored openings: " + ("; ".join(m.unexplored) or "none noted"),
                 "Key observations: " + ("; ".join(m.observations) or "none"),
                 "Blocked or failed moves: " + ("; ".join(f"step {s}: {n}" for s, n, _, _, o in m.moves[-MEMORY_ITEMS:]
                                                        if o == "blocked") or "none"),
                 "Candidate status: " + ("; ".join(m.candidates[-3:]) or "no candidate checked")]
        return "\n".join(lines)

    def state_text(self, m: TandemMemory, d: Decision) -> str:
        facts = {t: [x for q, x in d.answers if q == t] for t in (1, 2, 3, 4)}
        fb = []
        if facts[1]:
            fb.append(f"- appearance: {facts[1][-1]}")
        if facts[2]:
            fb.append(f"- location: {facts[2][-1]}")
        if facts[4]:
            fb.append(f"- last confirmation: {facts[4][-1]}")
        parts = [f"Find the {d.goal}.", "Fact Base:\n" + ("\n".join(fb) or "(empty)")]
        if m.questions:
            parts.append("Questions asked: " + "; ".join(f"step {s}: type {t}" for s, t, _ in m.questions[-8:]))
        p = d.percept
        if p.get("hint_active") and facts[3]:
            parts.append(hint_block(facts[3][-1], p.get("hint_progress", T.HINT_NONE), p.get("hint_bearing", -1)))
        if p.get("confirm") == 1 and p.get("follow_up") == T.FOLLOW_ONE_MOVE:
            parts.append("Follow-up: the target is confirmed; make one closer move, then stop.")
        if self.spatial_memory:
            parts.append(self.memory_text(m) if self.memory_style == "graph" else
                         "Spatial Memory:\n" + self.memory_text(m))
            if m.last_purpose:
                parts.append(f"Last purpose: {m.last_purpose}")
        hist = [f"step {s}: {n}" + (f" toward {g}" if g else "") + (f" ({o})" if o else "") for s, n, g, _, o in m.moves[-6:]]
        parts.append("Movement history: " + ("; ".join(hist) or "none yet"))
        if d.last_move:
            parts.append(f"Last move: {d.last_move}")
        parts.append(orientation_text(d))
        parts.append(f"Turn {d.step + 1} of at most {d.max_steps}; questions left: {d.questions_left if self.qa else 0}.")
        parts.append("Your views follow." if self.observation == "panel" else f"What you see:\n{d.observation}")
        return "\n\n".join(parts)

    def planner_request(self, m: TandemMemory, d: Decision) -> ChatRequest:
        names = view_names(d.n_views)
        content: list = [self.state_text(m, d)]
        if self.observation == "panel":
            if d.panel is None:
                raise ValueError(f"the {self.name} agent reads the panel, but the decision carries none")
            content.append(d.panel)
        actions = ("move", "ask", "stop") if self.may_ask else ("move", "stop")
        questions = (1, 2, 3, 4) if self.route_questions else (1, 2, 4)
        schema = (planner_schema if self.two_stage else one_stage_schema)(names, actions, questions)
        if self.counterfactual:
            schema = with_counterfactuals(schema, names)
        return ChatRequest(messages=[{"role": "system", "content": self.planner_system(d)},
                                     {"role": "user", "content": content}],
                           schema=schema, schema_name="planner_decision", tag=d.episode)

    def grounder_request(self, d: Decision, image, subgoal: str, purpose: str) -> ChatRequest:
        system = ("You ground a navigation instruction in one camera view covered by a numbered 8x8 grid. Columns 1-8 "
                  "run left to right (4 and 5 are the centre); rows 1-8 run from the bottom edge up: row 1 is the floor "
                  "just ahead, rows 1-2 are near floor targets, row 3 is for farther targets such as a doorway or the "
                  "end of a corridor, rows 4-8 usually hit walls, furniture tops or the ceiling. First find the place "
                  "the instruction names in the image, then pick the cell on the floor at it; for a doorway or passage "
                  "pick its centre, not its edge; use row 3 only when the way there is clearly open, else row 2. "
                  'Reply with one JSON object: {"col": 1-8, "row": 1-8, "rationale": "<a few words>"}.')
        text = f"Navigation instruction: {subgoal}" + (f"\nPurpose: {purpose}" if purpose else "") + "\nCurrent view:"
        return ChatRequest(messages=[{"role": "system", "content": system}, {"role": "user", "content": [text, image]}],
                           schema=GROUNDER_SCHEMA, schema_name="grounder_cell", tag=d.episode)

    def candidate_request(self, d: Decision, image, what: str) -> ChatRequest:
        """The Grounder's request for the cell of the object a confirmation question asks about."""
        system = ("You locate one object in one camera view covered by a numbered 8x8 grid. Columns 1-8 run left to "
                  "right, rows 1-8 from the bottom edge up. Find the object described and pick the cell that shows "
                  "the object itself (its middle, not the floor in front of it or the wall behind it). Reply with one "
                  'JSON object: {"col": 1-8, "row": 1-8, "rationale": "<a few words>"}.')
        text = f"Object to check: {what}\nCurrent front view:"
        return ChatRequest(messages=[{"role": "system", "content": system}, {"role": "user", "content": [text, image]}],
                           schema=GROUNDER_SCHEMA, schema_name="candidate_cell", tag=d.episode)

    # -- memory updates ------------------------------------------------------
    def _merge(self, m: TandemMemory, d: Decision, parsed: dict) -> None:
        m.last_purpose = clip(parsed.get("purpose"))
        b = parsed.get("belief_update")
        if isinstance(b, dict) and clip(b.get("current_room"), 80):
            m.room_claim = clip(b.get("current_room"), 80)  # the controller's reading of where the agent thinks it is
        if self.memory_style == "graph":
            return  # the graph is built from odometry (_observe_outcome), not from the model's words
        if self.memory_style == "map":
            b = parsed.get("belief_update") or {}
            place = clip(b.get("current_room") if isinstance(b, dict) else "", 80)
            if place:
                m.places.append(f"step {d.step}: {place}")
            return
        if not self.spatial_memory:
            return
        b = parsed.get("belief_update")
        if not isinstance(b, dict):
            return
        if clip(b.get("current_room")):
            m.current_room = clip(b.get("current_room"))
        if clip(b.get("target_description")):
            m.target_description = clip(b.get("target_description"))

        def items(key):
            v = b.get(key)
            return [clip(x) for x in v if clip(x)] if isinstance(v, list) else []

        m.visited = list(dict.fromkeys(m.visited + items("visited_areas")))[-MEMORY_ITEMS:]
        m.unexplored = items("unexplored_areas")[-MEMORY_ITEMS:] or m.unexplored
        m.observations = (m.observations + items("key_observations"))[-MEMORY_ITEMS:]

    def _observe_outcome(self, m: TandemMemory, d: Decision) -> None:
        """Fold the last step's outcome (executor feedback, answers) into memory."""
        p = d.percept
        if m.moves and m.moves[-1][4] == "" and m.history and m.history[-1][1] == "move":
            moved_blocked = "blocked" if p.get("moved", 1.0) < MOVED_M else "moved"
            s, n, g, r, _ = m.moves[-1]
            m.moves[-1] = (s, n, g, r, moved_blocked)
        if m.questions and m.questions[-1][1] == 4 and m.questions[-1][0] == d.step - 1:
            m.candidates.append(f"step {d.step - 1}: " + ("confirmed" if p.get("confirm") == 1 else "rejected"))
        m.positions.append(tuple(p.get("odometry", (0.0, 0.0))))
        if self.memory_style == "graph":
            m.graph.visit(d.offset)  # the agent's own offset from its start, as shown in the runtime block

    # -- one decision ------------------------------------------------------
    async def decide(self, ctx, m: TandemMemory, d: Decision):
        self._observe_outcome(m, d)
        question = ""  # the Planner's question text; none when the controller asks (recovery, confirm before stop)
        ruled = self._controller_rule(m, d)
        if ruled is not None:
            act = ruled[0]
            ctx.note_rule(*ruled[1:])
        else:
            if self.observation == "caption":  # the captioner first: one request per view (ignjax.agents.llm.caption)
                d = dataclasses.replace(d, observation=await describe_views(ctx, d))
            req = self.planner_request(m, d)
            plan = await ctx.query(req, lambda parsed, err: self._parse_plan(m, d, parsed, err))
            if plan is not None and self.self_questions:
                plan = await self_check(self, ctx, m, d, req, plan)
            if plan is None:
                act = ctx.default(self.default_action(m, d))
                m.history.append((d.step, "move", act, "(default after invalid replies)"))
            else:
                act, parsed = plan
                self._merge(m, d, parsed)
                if act[0] == MOVE:
                    act = await self._ground(ctx, m, d, act, parsed)
                elif act[0] == ASK:
                    if act[4] == 4:  # the candidate's cell on the front view
                        act = await self._ground_candidate(ctx, d, act, parsed)
                    if parsed.get("action") == "ask":  # not a stop turned into a confirmation
                        question = clip(parsed.get("question"))
                    else:
                        ctx.note_rule("confirm before stop", "the Planner chose stop without evidence (no confirmed "
                                      "target, no hint that it is near): ask a confirmation question (type 4) "
                                      "instead")
        self._record(m, d, act, question)
        if act[0] == ASK and question:
            ctx.note_question(question)
        return act

    def _parse_plan(self, m: TandemMemory, d: Decision, parsed, err):
        if parsed is None:
            return None, err or "the reply is not a JSON object"
        if self.counterfactual:
            why = counterfactual_error(parsed, view_names(d.n_views))
            if why is not None:
                return None, why
        act, why = self._check(m, d, parsed)
        if act is None:
            return None, why
        if not self.two_stage and (act[0] == MOVE or (act[0] == ASK and act[4] == 4)):
            cell, why = parse_cell(parsed, None)
            if cell is None:
                return None, why
            act = (MOVE, act[1], *cell, 1) if act[0] == MOVE else (ASK, 0, *cell, 4)
        return (act, parsed), None

    async def _ground(self, ctx, m: TandemMemory, d: Decision, act, parsed):
        if not self.two_stage:
            return act
        k = act[1]
        req = self.grounder_request(d, ctx.view_image(k), clip(parsed.get("subgoal")), clip(parsed.get("purpose")))
        got = await ctx.query(req, parse_cell, role="grounder")
        col, row = got if got is not None else GROUNDER_FALLBACK
        return (MOVE, k, col, row, 1)

    async def _ground_candidate(self, ctx, d: Decision, act, parsed):
        """A Type-4 question's candidate cell on the front view (:mod:`ignjax.evaluate.candidates`): the
        Grounder finds the object the Planner named ('subgoal', else its question, else the goal); one-stage
        agents named the cell themselves."""
        if not self.two_stage:
            return act
        what = candidate_of(parsed, d)
        got = await ctx.query(self.candidate_request(d, ctx.view_image(0), what), parse_cell, role="grounder")
        col, row = got if got is not None else CANDIDATE_FALLBACK
        return (ASK, 0, col, row, 4)

    def _record(self, m: TandemMemory, d: Decision, act, question: str = "") -> None:
        names = view_names(d.n_views)
        kind = {MOVE: "move", ASK: "ask", STOP: "stop"}[act[0]]
        if not m.history or m.history[-1][0] != d.step:
            m.history.append((d.step, kind, act, ""))
        if act[0] == MOVE:
            m.moves.append((d.step, names[act[1]], m.last_purpose and clip(m.last_purpose, 60), rear(act[1], d.n_views), ""))
            m.moves_since_hint = 0 if d.percept.get("hint_active") else m.moves_since_hint + 1
        elif act[0] == ASK:
            m.questions.append((d.step, act[4], question))
            if act[4] == 3:
                m.moves_since_hint = 0

    def default_action(self, memory, d: Decision):
        """After unusable Planner replies: a short move toward the front view's centre."""
        return (MOVE, 0, 4, 2, 1)


def _variant(name: str, description: str, **options):
    def make(**overrides):
        agent = Tandem(**{**options, **overrides})
        agent.name, agent.description = name, description
        return agent

    make.description = description
    return make


TANDEM_AGENTS = {
    "tandem": _variant("tandem", "TANDEM: Planner + Grounder, Spatial Memory, Fact Base, cost-aware questions, "
                                 "safeguards"),
    "tandem-no-spmem": _variant("tandem-no-spmem", "TANDEM without Spatial Memory", spatial_memory=False),
    "tandem-no-qa": _variant("tandem-no-qa", "TANDEM without questions (description given at reset)", qa=False),
    "tandem-no-spmem-no-qa": _variant("tandem-no-spmem-no-qa", "TANDEM without Spatial Memory and questions",
                                      spatial_memory=False, qa=False),
    "tandem-naive": _variant("tandem-naive", "TANDEM, naive-QA protocol (no costs shown, no safeguards)",
                             cost_aware=False, safeguards=False),
    "tandem-4v": _variant("tandem-4v", "TANDEM with 4 views (observation ablation)", n_views=4),
    "tandem-12v": _variant("tandem-12v", "TANDEM with 12 views (observation ablation)", n_views=12),
    "gta": _variant("gta", "GTA-style: Planner + Grounder, a place graph from odometry with a loop alert, "
                           "counterfactual reasoning, cost-aware", memory_style="graph", counterfactual=True),
    "gta-naive": _variant("gta-naive", "GTA-style, naive-QA", memory_style="graph", counterfactual=True,
                          cost_aware=False, safeguards=False),
    "coin": _variant("coin", "COIN-style: no route questions, a self-check of each candidate against the Fact Base "
                             "before a confirmation or a stop, cost-aware", route_questions=False, self_questions=True),
    "coin-naive": _variant("coin-naive", "COIN-style, naive-QA (route questions allowed)", self_questions=True,
                           cost_aware=False, safeguards=False),
    "mapgpt": _variant("mapgpt", "MapGPT-style: one stage, map-like text memory, cost-aware", two_stage=False,
                       memory_style="map"),
    "mapgpt-naive": _variant("mapgpt-naive", "MapGPT-style, naive-QA", two_stage=False, memory_style="map",
                             cost_aware=False, safeguards=False),
    "navgpt": _variant("navgpt", "NavGPT-style: one stage, text only: each view captioned by the model first, "
                                 "cost-aware", two_stage=False, observation="caption"),
    "navgpt-naive": _variant("navgpt-naive", "NavGPT-style, naive-QA", two_stage=False, observation="caption",
                             cost_aware=False, safeguards=False),
}
"""The MLLM agents of Table 1 and the ablations, by name (module docstring)."""


__all__ = ["GROUNDER_SCHEMA", "RECOVERY_MOVES", "TANDEM_AGENTS", "Tandem", "TandemMemory", "one_stage_schema",
           "planner_schema"]
