"""TANDEM's controller: the host-side rules around the Planner and every
correction it says back to the model.

Two halves (:class:`TandemController`, mixed into
:class:`~ignjax.agents.llm.tandem.Tandem`):

* **Before the Planner** (:meth:`TandemController._controller`; no model
  call when it acts): after a "yes" to a confirmation with the follow-up
  "stop now", STOP; the paper's early-question schedule; the recovery rule.
* **On the Planner's decision** (:meth:`TandemController._check`): a
  decision that breaks a rule is answered with a correction
  (:data:`CORRECTIONS`) and asked again; a stop that lacks confirmation
  becomes a confirmation question.

Rules (with ``safeguards``; the naive protocol keeps only the checks of the
reply's form and of what the agent may ask at all):

1. Type 1/2 only while the fact is missing from the Fact Base (safeguard 1).
2. Type 3 only where a trigger holds (safeguard 2): a branch (three or more
   of the observation's 8 sectors open for :data:`OPEN_M`), a loop (back
   within :data:`LOOP_M` of a position of two or more decisions ago), a long
   corridor (front and rear open past :data:`CORRIDOR_M`, both sides
   closed), or the goal room named by the oracle while the agent, by its own
   latest belief (``belief_update.current_room``), is elsewhere.
3. Follow-up (safeguard 3): after a yes with "move closer", no question and
   no backward move; after a yes with "stop now", STOP.
4. Recovery (safeguard 4), the paper's "a light recovery rule triggers a
   Type-3 query when the agent has moved for several steps, remains far
   from the goal, and has not yet asked for spatial guidance":
   :data:`RECOVERY_MOVES` moves without a route hint, questions left, and
   nothing the agent knows places it near the goal (:meth:`_near_goal`: no
   confirmed target, no hint saying it is close enough to stop, not in the
   goal room the oracle named by its own belief). The simulator's distance
   to the target is never read.
5. Early questions, the paper's "ask at least one of Type 1/2 by step 2, and
   both by step 5 when questions remain": at the second decision with
   neither fact asked for, and from the fifth with one still missing, the
   controller asks the missing type itself (of two missing, the cheaper
   under the costs in force: Type 2 at the locked costs; ties go to Type 1).
6. Anti-oscillation: no second backward move in a row unless the last one
   was blocked.
7. Stop policy, the paper's "Confirm before stopping", every time: a stop
   without evidence (no confirmed target, no hint saying it is close enough)
   becomes a confirmation question while questions remain; right after a
   "no" to a confirmation with no move since (asking again would get the
   same answer), the stop is corrected instead.

What the rules read and what they say. The gates may read the simulator's
free space of the 8 sectors and odometry (the controller's ground truth,
never shown to the model as numbers), the oracle's answers the agent
received, the budgets and the agent's own record (moves, questions, its
belief updates). A correction carries only what the agent could know: the
reply format, its budgets, its own moves, and the answers it received. None
names a room, says whether the agent is in, near or far from the goal room
or the target, or carries a distance or an instance id; a refused route
question states which moments route questions are for, the same text
whichever trigger is missing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ignjax.agents.llm.agent import ASK, MOVE, NO_QUESTIONS_LEFT, QUESTION_HELP, QUESTION_NAMES, STOP, Decision
from ignjax.agents.llm.graph_memory import PlaceGraph
from ignjax.scenes import vocab
from ignjax.sim import types as T
from ignjax.sim.views.compose import view_names

OPEN_M = 1.5
"""A sector counts as an open direction when its free floor reaches this far (m)."""
LOOP_M = 1.0
"""Back within this distance of a position of two or more decisions ago: a loop (m)."""
CORRIDOR_M = 3.0
"""Long corridor: front and rear open past this, both sides closed (m)."""
RECOVERY_MOVES = 5
"""Moves without a route hint, far from the goal by what the agent knows, before the recovery rule asks one."""
EARLY_ONE_BY, EARLY_BOTH_BY = 2, 5
"""The early-question schedule: one of Type 1/2 by this decision (1-based), both by that one."""
TEXT_CHARS = 160
"""Longest text kept from one belief-update entry."""

CORRECTIONS = {
    "action": "field 'action' must be one of move, ask, stop",
    "question_type": "field 'question_type' must be an integer from 1 to 4",
    "direction": "field 'direction' must be one of {names}",
    "subgoal": "a move needs a subgoal naming a place in that view",
    "no_questions": "questions are not available to you; choose move or stop",
    "no_route_questions": "route questions (type 3) are not available to you; ask another type or move",
    "budget": NO_QUESTIONS_LEFT,
    "follow_up_ask": "the helper has confirmed the target; make one closer move toward it, then stop",
    "known_fact": "the {fact} fact is already in the Fact Base; use it instead of asking again",
    "route": ("a route question is for a junction with several plausible ways, a loop back to where you have been, a "
              "long corridor, or a goal room the helper has named whose way in you cannot see; the controller does not "
              "take one at this turn, so move or ask another type"),
    "follow_up_rear": "the helper has confirmed the target; move one step closer toward it, not backward",
    "oscillation": ("your last move already went backward; choose a front or side direction, or ask a route question "
                    "if you are unsure"),
    "stop_after_no": ("the helper's last confirmation said the object in front of you is not the target and you have "
                      "not moved since; a stop here would be unconfirmed, so move on or ask another question"),
}
"""Every correction the controller can say back to the Planner, by name
(``{...}``: filled from the reply format or the Fact Base's type names)."""


def correction(name: str, **fields) -> str:
    """The text of correction ``name`` (:data:`CORRECTIONS`)."""
    return CORRECTIONS[name].format(**fields)


@dataclass
class TandemMemory:
    """One episode's host-side state: Spatial Memory, Fact Base, history."""

    current_room: str = "unknown"
    target_description: str = "unknown"
    visited: list = field(default_factory=list)
    unexplored: list = field(default_factory=list)
    observations: list = field(default_factory=list)
    places: list = field(default_factory=list)  # map-like memory (mapgpt): "step k: place"
    graph: PlaceGraph = field(default_factory=PlaceGraph)  # graph memory (gta): places from the agent's odometry
    moves: list = field(default_factory=list)  # (step, direction name, subgoal, rear-family, outcome)
    history: list = field(default_factory=list)  # (step, kind, action, reason): LLMAgent's record
    positions: list = field(default_factory=list)  # odometry (x, y) per decision
    last_purpose: str = ""
    questions: list = field(default_factory=list)  # (step, type, question text)
    candidates: list = field(default_factory=list)  # Type-4 outcomes in words
    moves_since_hint: int = 0
    room_claim: str = ""  # the Planner's latest belief_update.current_room (kept with or without Spatial Memory)


def clip(text, n: int = TEXT_CHARS) -> str:
    """``text`` on one line, at most ``n`` characters."""
    return " ".join(str(text or "").split())[:n]


def rear(k: int, n: int) -> bool:
    """View ``k`` of ``n`` points backward (more than 90 degrees from the front)."""
    a = (360.0 * k / n) % 360.0
    return 90.0 < a < 270.0


class TandemController:
    """The controller's rules (module docstring), for :class:`~ignjax.agents.llm.tandem.Tandem`,
    which sets ``safeguards``, ``qa``, ``may_ask`` and ``route_questions``."""

    safeguards = True
    qa = True
    may_ask = True
    route_questions = True

    # -- what the agent knows ------------------------------------------------
    @staticmethod
    def _in_goal_room(m: TandemMemory, d: Decision) -> bool:
        """The oracle has named the goal room and the agent's latest belief
        (read with :func:`ignjax.scenes.vocab.normalize_room_label`) is that room."""
        goal = d.percept.get("goal_room", -1)
        if not 0 <= goal < len(vocab.ALL_ROOM_LABELS) or not m.room_claim:
            return False
        return vocab.normalize_room_label(m.room_claim) == vocab.ALL_ROOM_LABELS[goal]

    def _near_goal(self, m: TandemMemory, d: Decision) -> bool:
        """What the agent knows says it is near the goal: a confirmed target,
        a hint saying it is close enough to stop, or its own belief that it
        stands in the goal room the oracle named."""
        p = d.percept
        return p.get("confirm") == 1 or p.get("hint_progress") == T.HINT_STOP or self._in_goal_room(m, d)

    @staticmethod
    def _asked(m: TandemMemory, d: Decision) -> set:
        """Question types 1 and 2 asked or answered so far."""
        known = d.percept.get("known", [False] * 4)
        return {t for t in (1, 2) if known[t - 1] or any(q == t for _, q, _ in m.questions)}

    def _route_triggers(self, m: TandemMemory, d: Decision) -> list[str]:
        p = d.percept
        free = p.get("open", [])
        out = []
        if sum(float(x) >= OPEN_M for x in free) >= 3:
            out.append("branch")
        pos = p.get("odometry")
        if pos is not None and any(math.dist(pos, q) < LOOP_M for q in m.positions[:-2]):
            out.append("loop")
        if len(free) == 8 and min(free[0], free[4]) >= CORRIDOR_M and max(free[2], free[6]) < OPEN_M:
            out.append("corridor")
        if p.get("goal_room", -1) >= 0 and not self._in_goal_room(m, d):
            out.append("goal room elsewhere")
        return out

    # -- before the Planner --------------------------------------------------
    def _early_question(self, m: TandemMemory, d: Decision):
        """The missing Type 1/2 question the schedule asks now, or None (rule 5)."""
        have = self._asked(m, d)
        turn = d.step + 1
        if turn < EARLY_ONE_BY or len(have) == 2 or (have and turn < EARLY_BOTH_BY):
            return None
        missing = [t for t in (1, 2) if t not in have]
        return min(missing, key=lambda t: (d.costs[t - 1], t))

    def _controller(self, m: TandemMemory, d: Decision):
        """An action the controller takes without asking the model, or None."""
        ruled = self._controller_rule(m, d)
        return None if ruled is None else ruled[0]

    def _controller_rule(self, m: TandemMemory, d: Decision):
        """``(action, rule, what it did in words)`` when the controller decides without asking the model, or None
        (the words go to the transcript's ``controller`` record, never to the model)."""
        p = d.percept
        if not self.safeguards:
            return None
        if p.get("confirm") == 1 and p.get("follow_up") == T.FOLLOW_STOP_NOW:
            return (STOP, 0, 4, 1, 1), "stop after confirmation", "the helper confirmed the target and said to stop now: stop"
        if not self.qa or d.questions_left <= 0 or (p.get("confirm") == 1 and p.get("follow_up") == T.FOLLOW_ONE_MOVE):
            return None
        t = self._early_question(m, d)
        if t is not None:
            return (ASK, 0, 4, 1, t), "early question", (f"turn {d.step + 1} without the {QUESTION_NAMES[t]} fact: "
                                                         f"ask it (type {t}, {QUESTION_HELP[t]})")
        if (self.route_questions and m.moves_since_hint >= RECOVERY_MOVES and not p.get("hint_active")
                and not self._near_goal(m, d)):
            moves, m.moves_since_hint = m.moves_since_hint, 0
            return (ASK, 0, 4, 1, 3), "recovery", (f"{moves} moves without a route hint or a confirmed candidate: "
                                                   f"ask a route question (type 3, {QUESTION_HELP[3]})")
        return None

    # -- on the Planner's decision ---------------------------------------------
    def _check(self, m: TandemMemory, d: Decision, parsed: dict):
        """``(action, None)`` or ``(None, correction)`` for a Planner decision."""
        a = parsed.get("action")
        if a == "ask":
            return self._check_ask(m, d, parsed.get("question_type"))
        if a == "stop":
            return self._check_stop(m, d)
        if a == "move":
            return self._check_move(m, d, parsed)
        return None, correction("action")

    def _follow(self, d: Decision) -> bool:
        return d.percept.get("follow_up") == T.FOLLOW_ONE_MOVE and d.percept.get("confirm") == 1

    def _check_ask(self, m: TandemMemory, d: Decision, t):
        if not self.may_ask:
            return None, correction("no_questions")
        if not isinstance(t, int) or isinstance(t, bool) or not 1 <= t <= 4:
            return None, correction("question_type")
        if t == 3 and not self.route_questions:
            return None, correction("no_route_questions")
        if d.questions_left <= 0:
            return None, correction("budget")
        if self.safeguards:
            if self._follow(d):
                return None, correction("follow_up_ask")
            if t in (1, 2) and d.percept.get("known", [False] * 4)[t - 1]:
                return None, correction("known_fact", fact=QUESTION_NAMES[t])
            if t == 3 and not self._route_triggers(m, d):
                return None, correction("route")
        return (ASK, 0, 4, 1, t), None

    def _check_stop(self, m: TandemMemory, d: Decision):
        p = d.percept
        evidence = p.get("confirm") == 1 or p.get("hint_progress") == T.HINT_STOP
        if not self.safeguards or evidence or not self.may_ask or d.questions_left <= 0:
            return (STOP, 0, 4, 1, 1), None
        if p.get("confirm") == 0 and not self._moved_since_confirmation(m):
            return None, correction("stop_after_no")
        return (ASK, 0, 4, 1, 4), None  # confirm before stopping

    @staticmethod
    def _moved_since_confirmation(m: TandemMemory) -> bool:
        """The agent has moved since its last confirmation question (True when it asked none)."""
        asked = [s for s, t, _ in m.questions if t == 4]
        return not asked or any(s > asked[-1] and o == "moved" for s, _, _, _, o in m.moves)

    def _check_move(self, m: TandemMemory, d: Decision, parsed: dict):
        names = view_names(d.n_views)
        name = parsed.get("direction")
        if name not in names:
            return None, correction("direction", names=", ".join(names))
        k = names.index(name)
        if not clip(parsed.get("subgoal")):
            return None, correction("subgoal")
        if self.safeguards:
            follow = self._follow(d)
            if follow and rear(k, d.n_views):
                return None, correction("follow_up_rear")
            last = m.moves[-1] if m.moves else None
            if rear(k, d.n_views) and last is not None and last[3] and last[4] != "blocked" and not follow:
                return None, correction("oscillation")
        return (MOVE, k, 0, 0, 1), None


__all__ = ["CORRECTIONS", "CORRIDOR_M", "EARLY_BOTH_BY", "EARLY_ONE_BY", "LOOP_M", "OPEN_M", "RECOVERY_MOVES",
           "TandemController", "TandemMemory", "clip", "correction", "rear"]
