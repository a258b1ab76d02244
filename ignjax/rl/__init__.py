"""Reinforcement learning on ignjax: a functional environment (the gymnax
shape: ``reset`` / ``step`` that jit and vmap, parameters as a pytree), its
observation vector and discrete actions, a batched form sharded over the
devices, and a Gymnasium vector-environment adapter (``pip install
"ignjax[rl]"``).

* :mod:`ignjax.rl.env` - :class:`Env`, :class:`EnvState`, :func:`make`.
* :mod:`ignjax.rl.params` - :class:`EnvParams`, the episode pool, the cost distribution.
* :mod:`ignjax.rl.obs` - the observation vector and its layout (:mod:`ignjax.agents.learned.obs`, shared with the
  ``learned`` agent).
* :mod:`ignjax.rl.actions` - the action set and its mask (:mod:`ignjax.agents.learned.actions`).
* :mod:`ignjax.rl.spaces` - :class:`Box`, :class:`Discrete`.
* :mod:`ignjax.rl.vector` - :class:`VecEnv`: B environments sharded over the devices.
* :mod:`ignjax.rl.gym` - :class:`IgnjaxVectorEnv` (Gymnasium's ``VectorEnv``).
* :mod:`ignjax.rl.train` - ``python -m ignjax.rl.train``, PPO (``trainconfig``, ``policy``, ``ppo``,
  ``checkpoint``, ``loop``; the ``rl`` extra's flax and optax).
* :mod:`ignjax.rl.export` - ``python -m ignjax.rl.export``: a checkpoint's weights as ``policy.npz``, which the
  ``learned`` agent (``--agent learned``) plays without flax.
"""

from ignjax.rl.actions import action_names, n_actions
from ignjax.rl.env import Env, EnvState, make
from ignjax.rl.obs import obs_layout, obs_size
from ignjax.rl.params import EnvParams, make_params
from ignjax.rl.spaces import Box, Discrete
from ignjax.rl.vector import VecEnv

__all__ = ["Box", "Discrete", "Env", "EnvParams", "EnvState", "VecEnv", "action_names", "make", "make_params",
           "n_actions", "obs_layout", "obs_size"]
