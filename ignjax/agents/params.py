"""Agent parameters as plain values: what the configuration can set.

An agent's parameters are a pytree dataclass of arrays
(``Agent.default_params()``). :func:`param_values` lists them as Python
values (floats, bools, ints, tuples for arrays), the form the sweep's
``[agents.<name>]`` tables, ``--set agents.<name>.<key>=...`` and
``run.json`` use; :func:`make_params` builds the pytree back from such
values, checked against the defaults' shapes.

Costs are not an agent setting: a cost-aware agent plans with the costs it
is charged. Its ``costs`` field is always set from the evaluation's charged
costs (``eval.costs`` of the sweep, ``--costs`` of ``python -m
ignjax.evaluate``), never from ``[agents.<name>]``.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Mapping

import jax.numpy as jnp
import numpy as np

from ignjax.agents.agent import Agent
from ignjax.arrays import field_docs
from ignjax.errors import ConfigError

PLANNED_COSTS_FIELD = "costs"
"""The params field a cost-aware agent plans with; set from the charged costs."""


def _python(value) -> Any:
    a = np.asarray(value)
    if a.ndim:
        return tuple(_python(v) for v in a)
    if a.dtype == bool:
        return bool(a)
    if np.issubdtype(a.dtype, np.integer):
        return int(a)
    if a.dtype == np.float32:  # the shortest decimal that reads back as the same float32 (0.3, not 0.30000001...)
        return float(np.format_float_positional(a[()], unique=True))
    return float(a)


def param_values_of(params, include_costs: bool = True) -> dict[str, Any]:
    """``field -> Python value`` of a parameter pytree (run.json records these)."""
    if not dataclasses.is_dataclass(params):
        return {}
    return {f.name: _python(getattr(params, f.name)) for f in dataclasses.fields(params)
            if include_costs or f.name != PLANNED_COSTS_FIELD}


def param_values(agent: Agent, include_costs: bool = False) -> dict[str, Any]:
    """``field -> Python value`` of the agent's default parameters (no
    ``costs`` unless asked: those are the charged costs)."""
    return param_values_of(agent.default_params(), include_costs)


def param_docs(agent: Agent) -> dict[str, str]:
    """``field -> description`` from the params class' docstring."""
    return field_docs(type(agent.default_params()))


def check_param_value(agent: Agent, key: str, value: Any, where: str | None = None) -> Any:
    """``value`` for field ``key`` of ``agent``'s parameters, checked against the default's type and shape.

    Raises:
        ConfigError: unknown key, ``costs`` (set by the charged costs), or a
            value of the wrong type or shape (naming ``agents.<name>.<key>``).
    """
    name = f"agents.{agent.name}.{key}"
    if key == PLANNED_COSTS_FIELD:
        raise ConfigError(where, name, "a cost-aware agent plans with the costs it is charged: set eval.costs "
                                       "(python -m ignjax.evaluate: --costs) instead")
    defaults = param_values(agent)
    if key not in defaults:
        raise ConfigError(where, name, f"unknown parameter; known: {', '.join(defaults) or '(none)'}")
    default = defaults[key]

    def scalar(v, d):
        if isinstance(d, bool):
            if not isinstance(v, bool):
                raise ConfigError(where, name, f"expected true or false, got {v!r}")
            return v
        if isinstance(d, int):
            if isinstance(v, bool) or not isinstance(v, int):
                raise ConfigError(where, name, f"expected an integer, got {v!r}")
            return v
        if isinstance(v, bool) or not isinstance(v, (int, float)) or math.isnan(v):
            raise ConfigError(where, name, f"expected a number, got {v!r}")
        return float(v)

    if isinstance(default, tuple):
        if not isinstance(value, (list, tuple)) or len(value) != len(default):
            raise ConfigError(where, name, f"expected a list of {len(default)} values, got {value!r}")
        return tuple(scalar(v, d) for v, d in zip(value, default))
    return scalar(value, default)


def make_params(agent: Agent, values: Mapping[str, Any] | None = None, costs=None):
    """The agent's parameter pytree: defaults, with ``values`` (field -> Python
    value, checked by :func:`check_param_value`) and, for a cost-aware agent,
    the charged ``costs`` as the costs it plans with."""
    params = agent.default_params()
    if not dataclasses.is_dataclass(params):
        if values:
            raise ConfigError(None, f"agents.{agent.name}", "this agent has no parameters")
        return params
    changes = {}
    for key, value in (values or {}).items():
        value = check_param_value(agent, key, value)
        old = getattr(params, key)
        changes[key] = jnp.asarray(value, dtype=jnp.asarray(old).dtype).reshape(jnp.shape(old))
    if costs is not None and hasattr(params, PLANNED_COSTS_FIELD):
        old = getattr(params, PLANNED_COSTS_FIELD)
        changes[PLANNED_COSTS_FIELD] = jnp.asarray(costs, dtype=old.dtype).reshape(old.shape)
    return dataclasses.replace(params, **changes)


def plans_with_costs(agent: Agent) -> bool:
    """The agent is cost-aware: its parameters hold the costs it plans with."""
    params = agent.default_params()
    return dataclasses.is_dataclass(params) and hasattr(params, PLANNED_COSTS_FIELD)


__all__ = ["PLANNED_COSTS_FIELD", "check_param_value", "make_params", "param_docs", "param_values", "param_values_of",
           "plans_with_costs"]
