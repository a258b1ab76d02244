"""The ``learned`` agent: a policy trained by ``python -m ignjax.rl.train``
played in the evaluation's rollouts, and the interface it shares with the RL
environment.

* :mod:`~ignjax.agents.learned.obs`: the observation vector (``encode``, ``obs_layout``);
* :mod:`~ignjax.agents.learned.actions`: the discrete actions (``decode``, ``action_mask``);
* :mod:`~ignjax.agents.learned.record`: a checkpoint's record and its check;
* :mod:`~ignjax.agents.learned.weights`: the weights file (``policy.npz``) and the
  network's forward pass in ``jax.numpy``;
* :mod:`~ignjax.agents.learned.source`: the checkpoint a setting names, loaded and checked;
* :mod:`~ignjax.agents.learned.agent`: the :class:`~ignjax.agents.Agent` ``learned``.

They sit with the agents (layer 3), below :mod:`ignjax.rl` (layer 5), so
that the agent and the environment use one encoding and one action table
(:mod:`ignjax.rl.obs` and :mod:`ignjax.rl.actions` re-export them), and
evaluating a policy needs neither the trainer nor flax.
"""

from ignjax.agents.learned.agent import LEARNED, LearnedParams

__all__ = ["LEARNED", "LearnedParams"]
