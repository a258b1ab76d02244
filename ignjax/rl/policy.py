"""The policy-and-value network of the PPO trainer (flax.linen).

Input per step: the environment's observation vector (:mod:`ignjax.rl.obs`,
which carries the episode's question costs, so one network serves every cost
scale) and whether the step begins an episode. An encoder of ``layers``
dense layers (tanh, orthogonal initialisation) feeds the **core**:

* ``gru``: a GRU cell whose state is the policy's memory of the episode
  (the task is partially observable: what was seen, asked and where the
  agent went), zeroed at every episode's first step;
* ``mlp``: no memory (the state passes through unchanged, and is unused).

Two linear heads read the core's output: the logits over the 21 actions
(masked with the environment's action mask, disallowed actions at -1e9) and
the value. :meth:`Policy.__call__` runs one step for a batch;
:meth:`Policy.sequence` scans it over time (the update re-runs the rollout's
sequences from their stored first state).

:func:`ignjax.agents.learned.weights.forward` is the same step in plain
``jax.numpy`` on the weights exported as named arrays (``policy.npz``), which
the ``learned`` agent plays without flax; a test keeps the two equal.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.agents.learned.weights import MASKED_LOGIT
from ignjax.errors.extras import optional_module

nn = optional_module("flax.linen", "rl")


def _dense(features: int, scale: float):
    return nn.Dense(features, kernel_init=nn.initializers.orthogonal(scale), bias_init=nn.initializers.zeros)


def _module_base():
    """flax.linen's Module, or a placeholder base when the rl extra is absent (using it raises MissingExtra)."""
    try:
        return nn.Module
    except ImportError:
        return object


class Policy(_module_base()):
    """The network (a flax module; hashable, a jit's static argument).

    Attributes:
        n_actions: actions of the environment.
        hidden: width of the encoder's layers and of the core.
        layers: dense layers of the encoder.
        core: "gru" or "mlp" (:data:`ignjax.rl.trainconfig.CORES`).
    """

    n_actions: int
    hidden: int = 128
    layers: int = 2
    core: str = "gru"

    @nn.compact
    def __call__(self, carry, obs, first, mask):
        """One step of a batch: carry (B, H), obs (B, D), first (B,) bool, mask (B, A) bool ->
        (carry, logits (B, A) with masked entries at :data:`MASKED_LOGIT`, value (B,))."""
        x = obs
        for i in range(self.layers):
            x = jnp.tanh(_dense(self.hidden, np.sqrt(2))(x))
        if self.core == "gru":
            carry = jnp.where(first[:, None], 0.0, carry)
            carry, x = nn.GRUCell(self.hidden)(carry, x)
        logits = _dense(self.n_actions, 0.01)(x)
        value = _dense(1, 1.0)(x)[:, 0]
        return carry, jnp.where(mask, logits, MASKED_LOGIT), value

    def initial_carry(self, batch: int) -> jax.Array:
        """(batch, hidden) zeros: the state before any step."""
        return jnp.zeros((batch, self.hidden), jnp.float32)


def init_params(policy: Policy, key: jax.Array, obs_dim: int):
    """The network's initial weights drawn by ``key``."""
    B = 1
    return policy.init(key, policy.initial_carry(B), jnp.zeros((B, obs_dim)), jnp.ones((B,), bool),
                       jnp.ones((B, policy.n_actions), bool))


def sequence(policy: Policy, params, carry, obs, first, mask):
    """The network over time: obs (T, B, D), first (T, B), mask (T, B, A) from ``carry`` (B, H) ->
    (logits (T, B, A), values (T, B))."""

    def body(h, xs):
        h, logits, value = policy.apply(params, h, *xs)
        return h, (logits, value)

    _, (logits, values) = jax.lax.scan(body, carry, (obs, first, mask))
    return logits, values


__all__ = ["MASKED_LOGIT", "Policy", "init_params", "sequence"]
