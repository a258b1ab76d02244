"""JAX-native agents: pure ``init`` / ``act`` functions the rollout vmaps.

Modules, lowest first:

* :mod:`~ignjax.agents.agent`: the :class:`Agent` record (what an agent is);
* :mod:`~ignjax.agents.memory`: the scripted agents' per-episode
  :class:`~ignjax.agents.memory.Memory` (visit map, candidate slots) and
  how an observation is folded into it;
* :mod:`~ignjax.agents.motion`: MOVE toward a bearing, direction to explore;
* :mod:`~ignjax.agents.belief`: belief over target hypotheses, answer
  models, EIG of each question type (Eq. 1);
* :mod:`~ignjax.agents.policies`: the scripted built-in agents (``random``,
  ``shortest_path``, ``explorer``, ``described``, ``naive_asker``, ``eig``);
* :mod:`~ignjax.agents.learned`: the ``learned`` agent, a policy trained by
  ``python -m ignjax.rl.train`` (its observation vector, actions, weights and
  checkpoints, shared with :mod:`ignjax.rl`);
* :mod:`~ignjax.agents.catalog`: :data:`AGENTS`, the immutable registry by
  name, and :func:`get_agent`.

Adding an agent: write one module in this package that defines its
``init`` / ``act`` / ``default_params`` functions (composing memory, motion
and belief as needed) and one :class:`Agent` record, then add that record
to the tuple :data:`AGENTS` is built from in :mod:`~ignjax.agents.catalog`.
Nothing else changes: the evaluation, sweep and benchmark look agents up by
name through :func:`get_agent` / :func:`registry`.
"""

from ignjax.agents.agent import Agent
from ignjax.agents.catalog import AGENTS, get_agent, registry

__all__ = ["AGENTS", "Agent", "get_agent", "registry"]
