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
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable


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
    """

    name: str
    init: Callable
    act: Callable
    default_params: Callable[[], Any]
    privileged: bool = False
    asks: bool = False
    description: str = ""
    reads: tuple[str, ...] | None = None


__all__ = ["Agent"]
