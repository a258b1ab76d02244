"""The environment for PyTorch users: a Gymnasium vector environment
(``gymnasium.vector.VectorEnv``; ``pip install "ignjax[rl]"``).

:class:`IgnjaxVectorEnv` runs ``num_envs`` episodes as one
:class:`ignjax.rl.vector.VecEnv` (jitted, sharded over the devices) and
speaks numpy: observations (B, D) float32, rewards (B,) float32,
terminations and truncations (B,) bool, actions (B,) integers in
``0 .. n_actions - 1`` (:mod:`ignjax.rl.actions`). Its spaces are the JAX
environment's (``single_observation_space`` a ``Box`` with the layout's
bounds, ``single_action_space`` a ``Discrete``), and CleanRL- or SB3-style
loops train on it as on any vector environment.

* **Auto-reset** is Gymnasium's ``SAME_STEP`` mode: the step that ends an
  episode returns the next episode's first observation. Every episode end is
  a termination (``truncations`` stay False): the step budget is part of the
  task and observed, and the reward is paid at the end either way, so there
  is nothing to bootstrap from a final observation (none is returned).
* **info**: ``action_mask`` (B, n_actions) bool every step (the mask of the
  returned observation); on the rows whose episode ended (Gymnasium's
  ``_name`` masks say which): ``wsr``, ``success``, ``final_distance``,
  ``steps``, ``stopped``, ``n_questions`` (B, 4), ``costs`` (B, 4) and
  ``pool_index``.
* **Keys**: ``reset(seed=s)`` (s = 0 when never given) sets the base key
  ``jax.random.key(s)``; the r-th reset since then (0 first) uses
  ``S = fold_in(base, r)``: the reset key ``fold_in(S, 0)`` and step t's key
  ``fold_in(S, t + 1)``, each given to :class:`~ignjax.rl.vector.VecEnv`
  (row i: ``split(key, B)[i]``). The same seed and actions give the same
  episodes, and the JAX environment reproduces them with those keys.
"""

from __future__ import annotations

import jax
import numpy as np

from ignjax.errors import ConfigError
from ignjax.errors.extras import MissingExtra, optional_module, require_extra
from ignjax.rl.env import Env, make
from ignjax.rl.params import EnvParams
from ignjax.rl.vector import VecEnv
from ignjax.sim import types as T

gymnasium = optional_module("gymnasium", "rl")
try:
    _VectorEnv = gymnasium.vector.VectorEnv
except MissingExtra:  # the core install: this module imports, the class refuses to start
    _VectorEnv = object

END_FIELDS = ("wsr", "success", "final_distance", "steps", "stopped", "n_questions", "costs", "pool_index")
"""The info entries of an episode that ended (each with its ``_name`` mask)."""


def _space(space, gym):
    """The Gymnasium space of an :mod:`ignjax.rl.spaces` space."""
    if hasattr(space, "n"):
        return gym.spaces.Discrete(int(space.n))
    return gym.spaces.Box(np.asarray(space.low, np.float32), np.asarray(space.high, np.float32), space.shape, np.float32)


class IgnjaxVectorEnv(_VectorEnv):
    """``num_envs`` ignjax episodes as a Gymnasium vector environment.

    Args:
        num_envs: rows B.
        env, params: the JAX environment and its parameters (default:
            :func:`ignjax.rl.env.make` over ``episodes``).
        episodes: an episode set or file for :func:`~ignjax.rl.env.make`
            when ``params`` is not given (None: the shipped benchmark).
        parts: devices to shard over (:class:`~ignjax.rl.vector.VecEnv`).
        **params_kw: :func:`~ignjax.rl.params.make_params`'s settings when ``params`` is not given.

    Raises:
        MissingExtra: gymnasium is not installed (``pip install "ignjax[rl]"``).
    """

    def __init__(self, num_envs: int, env: Env | None = None, params: EnvParams | None = None, episodes=None,
                 parts: int | None = None, **params_kw):
        require_extra("gymnasium", "rl")
        if params is None:
            env, params = make(episodes, **({"config": env.config} if env else {}), **params_kw)
        self.jax_env, self.params = env or Env(params.world.config), params
        self.vec = VecEnv(self.jax_env, num_envs, parts)
        self.num_envs = num_envs
        self.metadata = {"autoreset_mode": gymnasium.vector.AutoresetMode.SAME_STEP}
        self.single_observation_space = _space(self.jax_env.observation_space(params), gymnasium)
        self.single_action_space = _space(self.jax_env.action_space(params), gymnasium)
        self.observation_space = gymnasium.vector.utils.batch_space(self.single_observation_space, num_envs)
        self.action_space = gymnasium.vector.utils.batch_space(self.single_action_space, num_envs)
        self._base, self._resets, self._stream, self._t, self._state = jax.random.key(0), 0, None, 0, None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Fresh episodes in every row: (obs (B, D), info with ``action_mask``)."""
        if seed is not None:
            self._base, self._resets = jax.random.key(int(seed)), 0
        self._stream = jax.random.fold_in(self._base, self._resets)
        self._resets += 1
        self._t = 0
        obs, self._state = self.vec.reset(jax.random.fold_in(self._stream, 0), self.params)
        mask = jax.vmap(self.jax_env.action_mask)(self._state)
        return np.asarray(obs), {"action_mask": np.asarray(mask)}

    def step(self, actions):
        """One decision per row: (obs, rewards, terminations, truncations, info); see the module docstring."""
        if self._state is None:
            raise ConfigError(None, "rl.step", "call reset() before step()")
        a = np.asarray(actions)
        n = self.jax_env.num_actions
        if a.shape not in ((self.num_envs,), (self.num_envs, 1)) or not np.issubdtype(a.dtype, np.integer) \
                or np.any((a < 0) | (a >= n)):
            raise ConfigError(None, "rl.actions", f"must be {self.num_envs} integers in 0..{n - 1}, got "
                              f"{a.dtype} of shape {a.shape}")
        self._t += 1
        key = jax.random.fold_in(self._stream, self._t)
        obs, self._state, reward, done, info = self.vec.step(key, self._state, a.reshape(-1), self.params)
        done = np.asarray(done)
        return np.asarray(obs), np.asarray(reward), done, np.zeros_like(done), _info(info, done)

    def close(self, **kwargs):
        self._state = None


def _info(info: dict, done: np.ndarray) -> dict:
    """The numpy info of a step (module docstring)."""
    o: T.OutcomeRow = info["outcome"]
    values = {"wsr": info["wsr"], "success": info["success"], "final_distance": o.final_distance, "steps": o.steps,
              "stopped": o.stopped, "n_questions": o.n_questions, "costs": info["costs"], "pool_index": info["episode"]}
    out = {"action_mask": np.asarray(info["action_mask"])}
    if done.any():
        for name in END_FIELDS:
            out[name] = np.asarray(values[name])
            out[f"_{name}"] = done
    return out


__all__ = ["END_FIELDS", "IgnjaxVectorEnv"]
