"""What a learned policy reads and does, shared by the RL environment and the agents.

* :mod:`~ignjax.agents.learned.obs`: the observation vector (``encode``, ``obs_layout``);
* :mod:`~ignjax.agents.learned.actions`: the discrete actions (``decode``, ``action_mask``);
* :mod:`~ignjax.agents.learned.record`: a checkpoint's record and its check.

They sit with the agents (layer 3), below :mod:`ignjax.rl` (layer 5), so
that an agent playing a trained policy can use the environment's own
encoding and action table (:mod:`ignjax.rl.obs` and :mod:`ignjax.rl.actions`
re-export them).
"""
