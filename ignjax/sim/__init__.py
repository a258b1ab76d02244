"""The simulator: the paper's protocol as pure JAX functions for one episode,
and the rollouts that batch them.

* :mod:`~ignjax.sim.types`: the codes, state, actions, observations, answers (the
  pytrees of each step), re-exporting :mod:`~ignjax.sim.simconfig`'s configuration
  (:class:`~ignjax.sim.simconfig.SimConfig`) and :mod:`~ignjax.sim.records`' outcomes,
  trajectories and privileged information: every pytree the simulator passes.
* :mod:`~ignjax.sim.world`: the :class:`World` every episode shares (scene bank,
  goal fields, probe map).
* :mod:`~ignjax.sim.env`: ``reset`` / ``step`` / ``observe`` / ``outcome``, built from
  :mod:`~ignjax.sim.executor` (MOVE), :mod:`~ignjax.sim.oracle` (ASK, words in
  :mod:`~ignjax.sim.oracle_text`), :mod:`~ignjax.sim.observation` and
  :mod:`~ignjax.sim.queries`; geometry in :mod:`~ignjax.sim.geometry`, rays in
  :mod:`ignjax.sim.rays`.
* :mod:`~ignjax.sim.rollout`: one jitted ``lax.scan`` per batch of episodes
  (and per sweep of agent parameters), with :mod:`~ignjax.sim.compact`'s masked maps.

Imports :mod:`ignjax.scenes` only (agents are passed in as values).
"""
