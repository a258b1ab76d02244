"""What a learned policy reads and does, shared by the RL environment and the agents.

* :mod:`~ignjax.agents.learned.obs`: the observation vector (``encode``, ``obs_layout``);
* :mod:`~ignjax.agents.learned.actions`: the discrete actions (``decode``, ``action_mask``);
* :mod:`~ignjax.agents.learned.record`: a checkpoint's record and its check;
* :mod:`~ignjax.agents.learned.weights`: the weights file (``policy.npz``) and the
  network's forward pass in ``jax.numpy``;
* :mod:`~ignjax.agents.learned.source`: the checkpoint a setting names, loaded and checked.

They sit with the agents (layer 3), below :mod:`ignjax.rl` (layer 5), so
that an agent playing a trained policy can use the environment's own
encoding and action table (:mod:`ignjax.rl.obs` and :mod:`ignjax.rl.actions`
re-export them) and needs neither the trainer nor flax.
"""
