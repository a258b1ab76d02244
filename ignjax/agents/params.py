"""Agent parameters as plain values: what the configuration can set.

An agent's parameters are a pytree dataclass of arrays
(``Agent.default_params()``). :func:`param_values` lists them as Python
values (floats, bools, ints, tuples for arrays), the form the sweep's
``[agents.<name>]`` tables, ``--set agents.<name>.<key>=...`` and
``run.json`` use; :func:`make_params` builds the pytree back from such
values, checked against the defaults' shapes.

An agent whose parameters are loaded from files (an
:class:`~ignjax.agents.agent.ParamSource`, the ``learned`` agent's
checkpoint) lists its source's settings instead (``checkpoint``,
``greedy``): :func:`make_params` has the source build the pytree (the
weights as arrays) and :func:`param_record` gives what ``run.json`` keeps
(the checkpoint's path and its weights' digest, never the numbers). Both
take the simulator's configuration, which such a source may check the
files against (the learned policy's observation layout).

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
from ignjax.sim.types import SimConfig

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
    ``costs`` unless asked: those are the charged costs); for an agent with
    a :class:`~ignjax.agents.agent.ParamSource`, its settings' defaults."""
    if agent.source is not None:
        return dict(agent.source.settings())
    return param_values_of(agent.default_params(), include_costs)


def param_docs(agent: Agent) -> dict[str, str]:
    """``field -> description`` from the params class' docstring (a source's own descriptions)."""
    if agent.source is not None:
        return dict(agent.source.docs())
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
        if isinstance(d, str):
            if not isinstance(v, str):
                raise ConfigError(where, name, f"expected a string (quote it: \"{v}\"), got {v!r}")
            return v
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


def make_params(agent: Agent, values: Mapping[str, Any] | None = None, costs=None, config: SimConfig | None = None):
    """The agent's parameter pytree: defaults, with ``values`` (field -> Python
    value, checked by :func:`check_param_value`) and, for a cost-aware agent,
    the charged ``costs`` as the costs it plans with. An agent with a
    :class:`~ignjax.agents.agent.ParamSource` has it build the pytree under
    the simulator's ``config`` (default ``SimConfig()``; it may raise
    :class:`~ignjax.errors.InputError` on the files ``values`` name)."""
    if agent.source is not None:
        checked = {k: check_param_value(agent, k, v) for k, v in (values or {}).items()}
        params = agent.source.build({**agent.source.settings(), **checked}, config or SimConfig())
        values = None
    else:
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


def param_record(agent: Agent, values: Mapping[str, Any] | None = None, config: SimConfig | None = None,
                 params=None) -> dict[str, Any]:
    """What ``run.json`` records of an agent's parameters: every field's value
    (of ``params``, default those :func:`make_params` builds from ``values``);
    for an agent with a :class:`~ignjax.agents.agent.ParamSource`, the
    source's record of what ``values`` name (the checkpoint's path and its
    weights' SHA-256, checked under ``config``), with the ``costs`` it plans
    with when ``params`` are given.

    Raises:
        InputError: a source's file is missing or does not fit ``config``.
    """
    if agent.source is None:
        params = make_params(agent, values, config=config) if params is None else params
        return param_values_of(params)
    checked = {k: check_param_value(agent, k, v) for k, v in (values or {}).items()}
    out = agent.source.describe({**agent.source.settings(), **checked}, config or SimConfig())
    if params is not None and hasattr(params, PLANNED_COSTS_FIELD):
        out[PLANNED_COSTS_FIELD] = _python(getattr(params, PLANNED_COSTS_FIELD))
    return out


def plans_with_costs(agent: Agent) -> bool:
    """The agent is cost-aware: its parameters hold the costs it plans with."""
    params = agent.default_params()
    return dataclasses.is_dataclass(params) and hasattr(params, PLANNED_COSTS_FIELD)


__all__ = ["PLANNED_COSTS_FIELD", "check_param_value", "make_params", "param_docs", "param_record", "param_values",
           "param_values_of", "plans_with_costs"]
