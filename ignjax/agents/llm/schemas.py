"""The JSON schemas of the Planner's and the Grounder's replies (TANDEM and
the baselines built on it), and the parse of a reply's grid cell."""

from __future__ import annotations

from ignjax.agents.llm.controller import TEXT_CHARS

PHASES = ("explore", "verify", "approach", "recover")
MEMORY_ITEMS = 6
"""Entries kept per Spatial Memory list."""


def planner_schema(names: tuple[str, ...], actions=("move", "ask", "stop"), questions=(1, 2, 3, 4)) -> dict:
    """JSON schema of one Planner decision (every key required; the ones an
    action does not use are ignored): ``actions`` the agent may take,
    ``questions`` the types it may ask."""
    s = {"type": "string", "maxLength": TEXT_CHARS}
    lst = {"type": "array", "items": s, "maxItems": MEMORY_ITEMS}
    return {
        "type": "object",
        "properties": {
            "reasoning": {"type": "string", "maxLength": 400},
            "task_phase": {"type": "string", "enum": list(PHASES)},
            "belief_update": {
                "type": "object",
                "properties": {"current_room": s, "target_description": s, "visited_areas": lst,
                               "unexplored_areas": lst, "key_observations": lst},
                "required": ["current_room", "target_description", "visited_areas", "unexplored_areas",
                             "key_observations"],
                "additionalProperties": False,
            },
            "action": {"type": "string", "enum": list(actions)},
            "direction": {"type": "string", "enum": list(names)},
            "subgoal": s,
            "purpose": s,
            "question_type": {"type": "integer", "enum": list(questions)},
            "question": s,
        },
        "required": ["reasoning", "task_phase", "belief_update", "action", "direction", "subgoal", "purpose",
                     "question_type", "question"],
        "additionalProperties": False,
    }


def one_stage_schema(names: tuple[str, ...], actions=("move", "ask", "stop"), questions=(1, 2, 3, 4)) -> dict:
    """The Planner schema plus the grid cell (one-stage baselines pick it themselves)."""
    s = planner_schema(names, actions, questions)
    s["properties"].update({"col": {"type": "integer", "minimum": 1, "maximum": 8},
                            "row": {"type": "integer", "minimum": 1, "maximum": 8}})
    s["required"] = s["required"] + ["col", "row"]
    return s


GROUNDER_SCHEMA = {
    "type": "object",
    "properties": {"col": {"type": "integer", "minimum": 1, "maximum": 8},
                   "row": {"type": "integer", "minimum": 1, "maximum": 8},
                   "rationale": {"type": "string", "maxLength": 200}},
    "required": ["col", "row", "rationale"],
    "additionalProperties": False,
}


def parse_cell(parsed, err):
    """``((col, row), None)`` from a reply's grid cell, or ``(None, why)``."""
    if parsed is None:
        return None, err or "the reply is not a JSON object"
    for key in ("col", "row"):
        v = parsed.get(key)
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= 8:
            return None, f"field '{key}' must be an integer from 1 to 8"
    return (parsed["col"], parsed["row"]), None


__all__ = ["GROUNDER_SCHEMA", "MEMORY_ITEMS", "PHASES", "one_stage_schema", "parse_cell", "planner_schema"]
