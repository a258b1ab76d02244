"""What an agent is: the :class:`Agent` record of pure functions the rollout calls.

An :class:`Agent` is a pair of pure functions::

    init(params, obs, key) -> pstate
    act(params, obs, answers, pstate, key, priv) -> (Action, pstate)

written for one episode (vmapped by the rollout). ``obs`` is an
:class:`~ignjax.sim.types.Observation`, ``answers`` the oracle's
:class:`~ignjax.sim.types.Answer`; ``priv`` is
:class:`~ignjax.sim.types.Privileged` for agents with ``privileged=True`` and
None for every other agent. ``params`` is a pytree the rollout can vmap
over (e.g. per-type cost vectors for in-the-loop sweeps).

Most agents' parameters are plain values (:mod:`ignjax.agents.params` lists
them for the configuration and ``run.json``). An agent whose parameters are
loaded from a file instead (the ``learned`` agent's network weights) names
a :class:`ParamSource`: the plain values a user sets (the checkpoint's
path), how they become the parameter pytree (the weights as arrays, jit
arguments like any other parameter) and what ``run.json`` records of them
(the path and the weights' SHA-256, never the numbers).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping, Protocol


class ParamSource(Protocol):
    """Parameters built from settings that name files (hashable: part of the :class:`Agent` record).

    ``settings()``: ``key -> default`` of the plain values the configuration
    sets (``[agents.<name>]``, ``--set agents.<name>.<key>``), the only keys
    it accepts; ``docs()``: ``key -> description``; ``describe(values,
    config)``: load and check what ``values`` name under the simulator's
    ``config`` (host side, before any episode), returning the plain record
    ``run.json`` keeps (raises :class:`~ignjax.errors.InputError` on a bad
    file); ``build(values, config)``: the parameter pytree.
    """

    def settings(self) -> Mapping[str, Any]: ...

    def docs(self) -> Mapping[str, str]: ...

    def describe(self, values: Mapping[str, Any], config) -> dict: ...

    def build(self, values: Mapping[str, Any], config) -> Any: ...


@dataclass(frozen=True)
class Agent:
    """A registered agent.

    Attributes:
        name: registry name.
        init: ``(params, obs, key) -> pstate``.
        act: ``(params, obs, answers, pstate, key, priv) -> (Action, pstate)``.
        default_params: ``() -> params``.
        privileged: receives shortest-path information (an upper bound,
            never a fair competitor).
        asks: may ask questions.
        description: one line for ``--help`` and reports.
        reads: the parameters that change what the agent does, as its
            ``act`` uses them (the report's setup lists only these); None:
            all of its parameters. A belief agent shares
            :class:`~ignjax.agents.belief.BeliefParams` with the others but
            reads only some of its fields.
        source: a :class:`ParamSource` when the parameters are loaded from
            files named by the settings (the ``learned`` agent); None: the
            parameters' fields are the settings.
    """

    name: str
    init: Callable
    act: Callable
    default_params: Callable[[], Any]
    privileged: bool = False
    asks: bool = False
    description: str = ""
    reads: tuple[str, ...] | None = None
    source: ParamSource | None = None


__all__ = ["Agent", "ParamSource"]
