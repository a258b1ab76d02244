"""The ``learned`` agent: a policy trained by ``python -m ignjax.rl.train``, played inside the evaluation's rollouts.

Each decision it builds the RL environment's observation vector from what
every JAX agent sees (:func:`ignjax.agents.learned.obs.encode` of the
:class:`~ignjax.sim.types.Observation`, the oracle's
:class:`~ignjax.sim.types.Answer` and the costs it is charged; not
privileged), runs the network one step (:func:`ignjax.agents.learned.weights.forward`,
``jax.numpy`` only: no flax), masks the logits with
:func:`~ignjax.agents.learned.actions.action_mask`, picks an action and
decodes it (:func:`~ignjax.agents.learned.actions.decode`), exactly as a step
of :class:`ignjax.rl.env.Env` under the trainer's policy does (a test plays
both on the same episodes and compares their actions). Its state is the
GRU's memory and whether the next step is the episode's first (the memory is
zeroed then, as in training).

**Drawn by default.** ``greedy = false`` (the default) draws the action
from the masked softmax with the step's key, the behaviour PPO trained and
measured in its curve; like every random choice it follows the run's
``seed``, so a run is the same bytes every time. ``greedy = true`` takes the
most probable allowed action. Measured on the shipped benchmark (500
episodes, locked costs): the shipped policy scores WSR@1.5 46.2 drawn and
46.6 greedy; a 20 M-step policy trained with costs drawn from x0.25 20.2 and
17.8; a 2.1 M-step one 11.2 and 10.4.

**Cost-aware.** The vector carries the episode's question costs, so the
agent plans with the costs it is charged (``--costs``, ``eval.costs``, and
each setting of the in-the-loop cost study): its parameters'
``costs`` field (:data:`ignjax.agents.params.PLANNED_COSTS_FIELD`).

**Settings and parameters.** The configuration sets two plain values,
``checkpoint`` (the path, :mod:`ignjax.agents.learned.source`; empty: the
shipped policy) and ``greedy``; :class:`CheckpointSource` turns them into
:class:`LearnedParams`, whose ``weights`` are arrays (arguments of the
compiled rollout like any parameter, never constants closed over, so one
compiled program serves every checkpoint of a shape) and whose simulator
configuration, a static field, sets the vector's scales. What ``run.json``
records is the checkpoint's path and its weights' SHA-256
(:meth:`CheckpointSource.describe`), never the weights.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from types import MappingProxyType

import jax
import jax.numpy as jnp

from ignjax.agents.agent import Agent
from ignjax.agents.learned.actions import action_mask, decode
from ignjax.agents.learned.obs import encode
from ignjax.agents.learned.source import load, locate
from ignjax.agents.learned.weights import forward
from ignjax.arrays import pytree_dataclass
from ignjax.protocol import LOCKED_COSTS
from ignjax.sim import types as T

SETTINGS = MappingProxyType({"checkpoint": "", "greedy": False})
"""The agent's settings and their defaults (``[agents.learned]``)."""
SETTING_DOCS = MappingProxyType({
    "checkpoint": "the trained policy: a checkpoint folder RUN/checkpoints/<update>, a training run folder (its newest "
                  "checkpoint) or an exported policy folder; empty: the policy shipped with ignjax "
                  "(ignjax/data/policy). run.json records its path and the SHA-256 of its weights.",
    "greedy": "take the most probable allowed action; false (the default): draw it from the policy's distribution "
              "with the step's key, as in training.",
})


@pytree_dataclass(static=("config",))
class LearnedParams:
    """The ``learned`` agent's parameters.

    Attributes:
        costs: (4,) float32 the question costs the agent plans with (the charged costs).
        greedy: () bool argmax (true) or a draw (false).
        weights: ``name -> array`` the network (:mod:`ignjax.agents.learned.weights`).
        config: the simulator's configuration the observation vector is scaled by (static).
    """

    costs: jax.Array
    greedy: jax.Array
    weights: dict
    config: T.SimConfig = T.SimConfig()


@pytree_dataclass
class LearnedState:
    """carry: (H,) float32 the core's memory; first: () bool the next step begins the episode."""

    carry: jax.Array
    first: jax.Array


def _hidden(params: LearnedParams) -> int:
    return int(jnp.shape(params.weights["encoder_0/kernel"])[-1])


def _check_layout(params: LearnedParams, obs: T.Observation) -> None:
    """The observation's shapes are the configuration's (trace time): the vector is laid out by the latter."""
    cfg = params.config
    if obs.free_space.shape != (cfg.n_views, cfg.obs_rays_per_view) or obs.visible_handle.shape != (cfg.max_visible,):
        raise ValueError(f"the learned agent's parameters were built for another SimConfig than the world's: "
                         f"observation shapes {obs.free_space.shape}, {obs.visible_handle.shape}; build them with "
                         "ignjax.agents.params.make_params(agent, config=world.config)")


def learned_init(params: LearnedParams, obs: T.Observation, key: jax.Array) -> LearnedState:
    """The state before the first step: zero memory, the next step is the first."""
    return LearnedState(carry=jnp.zeros(_hidden(params), jnp.float32), first=jnp.asarray(True))


def learned_act(params: LearnedParams, obs: T.Observation, answers: T.Answer, pstate: LearnedState, key: jax.Array,
                priv=None):
    """One decision (one episode; the rollout vmaps it): (Action, LearnedState)."""
    _check_layout(params, obs)
    cfg = params.config
    x = encode(obs, answers, params.costs, cfg)
    mask = action_mask(obs, cfg)
    carry, logits, _ = forward(params.weights, pstate.carry, x, pstate.first, mask)
    index = jnp.where(params.greedy, jnp.argmax(logits), jax.random.categorical(key, logits))
    return decode(index, cfg), LearnedState(carry=carry, first=jnp.asarray(False))


@dataclass(frozen=True)
class CheckpointSource:
    """The ``learned`` agent's settings layer (an :class:`~ignjax.agents.agent.ParamSource`): ``checkpoint`` and
    ``greedy`` in, :class:`LearnedParams` out; ``run.json`` gets the checkpoint's path and digest."""

    def settings(self):
        return SETTINGS

    def docs(self):
        return SETTING_DOCS

    def describe(self, values, config: T.SimConfig = T.SimConfig()) -> dict:
        """Load and check the checkpoint (numpy only; raises InputError); the record of what was loaded."""
        v = {**SETTINGS, **values}
        return {**load(locate(v["checkpoint"]), config).describe(), "greedy": bool(v["greedy"])}

    def build(self, values, config: T.SimConfig = T.SimConfig()) -> LearnedParams:
        """The parameters (weights as arrays), planning with the locked costs until the charged ones are set."""
        v = {**SETTINGS, **values}
        loaded = load(locate(v["checkpoint"]), config)
        with jax.ensure_compile_time_eval():  # concrete arrays also when first asked for under a trace (cached)
            return LearnedParams(costs=jnp.asarray(LOCKED_COSTS, jnp.float32),
                                 greedy=jnp.asarray(bool(v["greedy"])),
                                 weights={k: jnp.asarray(a) for k, a in loaded.weights.items()}, config=config)


SOURCE = CheckpointSource()


@functools.lru_cache(maxsize=1)
def _shipped() -> LearnedParams:
    return SOURCE.build(SETTINGS)


def default_params() -> LearnedParams:
    """The shipped policy, greedy, planning with the locked costs, under the default SimConfig."""
    return _shipped()


LEARNED = Agent("learned", learned_init, learned_act, default_params, asks=True,
                description="a policy trained by python -m ignjax.rl.train (agents.learned.checkpoint; default: a "
                            "small shipped one), reading the costs it is charged; greedy unless "
                            "agents.learned.greedy = false", source=SOURCE)


__all__ = ["CheckpointSource", "LEARNED", "LearnedParams", "LearnedState", "SETTINGS", "SOURCE", "default_params",
           "learned_act", "learned_init"]
