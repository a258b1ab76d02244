"""Counterfactual reasoning before a choice: the GTA-style option
``counterfactual`` of :class:`~ignjax.agents.llm.tandem.Tandem`.

GTA (Li et al., 2026, "One Agent to Guide Them All"; its counterfactual
reasoning "brain") has the model reason, through a structured prompt, about
what would follow from alternative choices before it commits to one. Here
that is one required field of the Planner's reply, placed before
``action`` so that a model writing its reply in schema order states the
alternatives first: ``counterfactuals``, a list of at least
:data:`MIN_OPTIONS` directions of the panel, each with what the Planner
expects to find or reach if it went there. Two checks the schema cannot
express (:func:`counterfactual_error`): the entries name at least
:data:`MIN_OPTIONS` different directions, and a move goes in a direction the
list considers. A reply that fails either is corrected and asked again, like
any other reply that breaks the format.
"""

from __future__ import annotations

from ignjax.agents.llm.controller import TEXT_CHARS

FIELD = "counterfactuals"
"""The reply's key."""
MIN_OPTIONS = 2
"""Different directions the list must weigh (the choice and at least one alternative)."""

PROMPT = (
    "Before you choose, weigh the alternatives in 'counterfactuals': for at least two directions you could take "
    "(the one you favour and the best alternatives), state in 'expected' what you think you would find or reach if "
    "you went there, given what you see, what the helper told you and where you have already been. Then choose; a "
    "move must go in one of the directions you weighed.")
"""The system prompt's block for the option (our words)."""


def counterfactual_property(names: tuple[str, ...]) -> dict:
    """The schema of the ``counterfactuals`` field for a panel whose directions are ``names``."""
    return {
        "type": "array",
        "minItems": MIN_OPTIONS,
        "maxItems": len(names),
        "items": {
            "type": "object",
            "properties": {"direction": {"type": "string", "enum": list(names)},
                           "expected": {"type": "string", "maxLength": TEXT_CHARS}},
            "required": ["direction", "expected"],
            "additionalProperties": False,
        },
    }


def with_counterfactuals(schema: dict, names: tuple[str, ...]) -> dict:
    """``schema`` (a Planner schema) with the required ``counterfactuals`` field placed before ``action``."""
    props, required = {}, []
    for key, value in schema["properties"].items():
        if key == "action":
            props[FIELD] = counterfactual_property(names)
        props[key] = value
    for key in schema["required"]:
        if key == "action":
            required.append(FIELD)
        required.append(key)
    return {**schema, "properties": props, "required": required}


def counterfactual_error(parsed: dict, names: tuple[str, ...]) -> str | None:
    """Why the reply's ``counterfactuals`` cannot be used, or None."""
    items = parsed.get(FIELD)
    if not isinstance(items, list):
        return (f"field '{FIELD}' is required: list at least {MIN_OPTIONS} directions, each with what you expect "
                "there, before choosing")
    weighed = {x.get("direction") for x in items if isinstance(x, dict) and str(x.get("expected") or "").strip()}
    weighed &= set(names)
    if len(weighed) < MIN_OPTIONS:
        return (f"field '{FIELD}' must weigh at least {MIN_OPTIONS} different directions, each with a non-empty "
                "'expected'")
    if parsed.get("action") == "move" and parsed.get("direction") in names and parsed["direction"] not in weighed:
        return (f"your move goes {parsed['direction']}, a direction '{FIELD}' does not weigh; state what you expect "
                "there, or choose a direction you weighed")
    return None


__all__ = ["FIELD", "MIN_OPTIONS", "PROMPT", "counterfactual_error", "counterfactual_property", "with_counterfactuals"]
