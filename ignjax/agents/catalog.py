"""The registry of built-in agents: :data:`AGENTS` (name -> :class:`Agent`,
immutable) and :func:`get_agent`, the one lookup by name."""

from __future__ import annotations

from types import MappingProxyType
from typing import Mapping

from ignjax.agents.agent import Agent
from ignjax.agents.learned import LEARNED
from ignjax.agents.policies import DESCRIBED, EIG, EXPLORER, NAIVE_ASKER, RANDOM, SHORTEST_PATH
from ignjax.errors import ConfigError

AGENTS: Mapping[str, Agent] = MappingProxyType({a.name: a for a in (RANDOM, SHORTEST_PATH, EXPLORER, DESCRIBED, NAIVE_ASKER, EIG,
                                                                   LEARNED)})
"""Built-in agents by name (immutable)."""


def registry() -> Mapping[str, Agent]:
    """Immutable mapping of the built-in agents (name -> :class:`Agent`)."""
    return AGENTS


def get_agent(name: str) -> Agent:
    """The agent registered as ``name``.

    Raises:
        ConfigError: unknown name (the message lists the known ones).
    """
    if name not in AGENTS:
        raise ConfigError(None, "agent", f"unknown agent {name!r}; known agents: {sorted(AGENTS)}")
    return AGENTS[name]


__all__ = ["AGENTS", "get_agent", "registry"]
