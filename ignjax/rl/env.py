"""The functional RL environment (the gymnax / jumanji / brax shape).

::

    env, params = ignjax.rl.make()                      # the shipped benchmark, drawn costs
    obs, state = env.reset(key, params)                 # one episode
    obs, state, reward, done, info = env.step(key, state, action, params)
    jax.vmap(env.step, in_axes=(0, 0, 0, None))(keys, states, actions, params)   # a batch

``reset`` and ``step`` are pure, jittable and vmappable; :meth:`Env.step_batch`
and :meth:`Env.reset_batch` are the same transitions for a batch with a
leading axis B (row for row the same as the vmapped ones), organised like the
rollouts (:func:`ignjax.sim.env.step_batch`: the executor runs for the rows
that MOVE, the oracle for the rows that ASK; the perception is recomputed for
the rows that moved or reset, :func:`ignjax.sim.env.observe_batch`), so a
batch pays for the work its rows need. The one-episode ``step`` is
``step_batch`` on a batch of one: there is one transition.
:class:`ignjax.rl.vector.VecEnv` shards the batched functions over the
devices; a trainer's jitted ``lax.scan`` over env steps calls them inside its
own ``shard_map`` the same way.

**Observation**: the float32 vector of :func:`ignjax.rl.obs.encode` (what the
agents may see, :data:`ignjax.sim.types.AGENT_FIELDS`, and the episode's
costs). **Actions**: :mod:`ignjax.rl.actions` (2 MOVEs per view, ASK 1-4,
STOP; ``info["action_mask"]``).

**Reward**: 0 until the episode ends, then its WSR at ``params.tau``:
``1{d <= tau} * exp(-sum_t w_t n_t)``, with ``d`` the final geodesic distance
and ``w`` the episode's costs, the value :func:`ignjax.evaluate.metrics.episode_wsr`
gives its outcome (success by the paper's rule: STOP or the step budget both
end an episode). Optional shaping (``params.shaping`` = lambda > 0, off by
default) adds the potential-based term ``gamma Phi(s') - Phi(s)`` with
``Phi(s) = -lambda min(d_geo(s), 10 m)`` and ``Phi = 0`` at the end of an
episode, which leaves the optimal policy unchanged (Ng et al., 1999) for the
discount ``params.gamma``.

**Episode ends and auto-reset**: ``done`` is true on the step that ends an
episode (STOP or the step budget; both are terminations, since the step
budget is part of the task and observed as ``steps_left``). That step's
``obs`` and ``state`` already belong to a fresh episode drawn by the step's
key (:mod:`ignjax.rl.params`: uniform over the pool, costs drawn per
episode); ``info`` describes the episode that ended (its outcome row, WSR,
success, costs and pool index) and the mask of the new state.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property

import jax
import jax.numpy as jnp

from ignjax.arrays import pytree_dataclass
from ignjax.data.shipped import shipped_episodes
from ignjax.episodes.dataset import EpisodeSet, load_benchmark
from ignjax.errors import ConfigError
from ignjax.evaluate.runner import make_world
from ignjax.rl import actions as A
from ignjax.rl.obs import encode, obs_bounds, obs_size
from ignjax.rl.params import SHAPING_CAP, EnvParams, draw_costs, make_params
from ignjax.rl.spaces import Box, Discrete
from ignjax.sim import env as E
from ignjax.sim import types as T
from ignjax.sim.compact import masked_map
from ignjax.sim.queries import geodesic_to_target

RESET_STREAMS = (0x706F, 0x636F, 0x6E6F)
"""Folded into a reset's key for the pool index, the costs and the episode's own key (its perception noise)."""


@pytree_dataclass
class EnvState:
    """One episode of the environment (a leading axis B in a batch).

    Attributes:
        sim: the simulator's state (privileged: never observed directly).
        view: the simulator's observation of ``sim`` (kept so that a batched
            step recomputes the perception only for the rows that moved).
        costs: (4,) float32 this episode's question costs.
        episode: () int32 the episode's index in the pool.
        distance: () float32 geodesic distance to the target now
            (privileged: the shaping potential's input only).
    """

    sim: T.SimState
    view: T.Observation
    costs: jax.Array
    episode: jax.Array
    distance: jax.Array


@dataclass(frozen=True)
class Env:
    """The environment's static part (hashable: a jit's static argument).

    Attributes:
        config: the simulator's configuration; ``params.world.config`` must equal it.
    """

    config: T.SimConfig = T.SimConfig()

    # ------------------------------------------------------------------ spaces

    @property
    def num_actions(self) -> int:
        return A.n_actions(self.config)

    def observation_space(self, params: EnvParams | None = None) -> Box:
        low, high = obs_bounds(self.config)
        return Box(low, high, (obs_size(self.config),))

    def action_space(self, params: EnvParams | None = None) -> Discrete:
        return Discrete(self.num_actions)

    @cached_property
    def default_params(self) -> EnvParams:
        """Parameters over the shipped benchmark with the default settings (:func:`make_params`; loads it once)."""
        return make(config=self.config)[1]

    def check(self, params: EnvParams) -> None:
        """Reject parameters whose world was made under another simulator configuration."""
        if params.world.config != self.config:
            raise ConfigError(None, "rl.world", "was made under another SimConfig than the environment's")

    # ------------------------------------------------------------------ one episode

    def reset(self, key: jax.Array, params: EnvParams) -> tuple[jax.Array, EnvState]:
        """A fresh episode drawn by ``key``: (observation vector, state)."""
        state = self._fresh(key, params)
        view = E.observe(params.world, state.sim)
        state = dataclasses.replace(state, view=view)
        return self.get_obs(state), state

    def step(self, key: jax.Array, state: EnvState, action, params: EnvParams):
        """One decision: (obs, state, reward, done, info); see the module docstring."""
        out = self.step_batch(key[None], T.batch_of_one(state), jnp.asarray(action)[None], params)
        return T.only_row(out)

    def get_obs(self, state: EnvState) -> jax.Array:
        """The observation vector of a state: a function of ``state.view``, ``state.sim.answers`` and ``state.costs``."""
        return encode(state.view, state.sim.answers, state.costs, self.config)

    def action_mask(self, state: EnvState) -> jax.Array:
        """(n_actions,) bool the actions the protocol accepts in ``state`` (:func:`ignjax.rl.actions.action_mask`)."""
        return A.action_mask(state.view, self.config)

    # ------------------------------------------------------------------ a batch

    def reset_batch(self, keys: jax.Array, params: EnvParams, chunk: int | None = None):
        """:meth:`reset` of a batch of keys (B,): (obs (B, D), state), the perception marched together."""
        state = jax.vmap(lambda k: self._fresh(k, params))(keys)
        view = E.observe_all(params.world, state.sim, chunk)
        state = dataclasses.replace(state, view=view)
        return jax.vmap(self.get_obs)(state), state

    def step_batch(self, keys: jax.Array, state: EnvState, actions, params: EnvParams, chunk: int | None = None):
        """:meth:`step` of a batch (leading axis B): keys (B,), actions (B,) int.

        Returns:
            (obs (B, D), state, reward (B,), done (B,), info): ``info`` holds
            ``action_mask`` (B, n_actions) of the returned state, and for the
            episode a step ended: ``outcome`` (its :class:`~ignjax.sim.types.OutcomeRow`),
            ``wsr``, ``success``, ``costs`` and ``episode`` (pool index);
            for other rows those entries are the running episode's values
            and not final.
        """
        world = params.world
        act = A.decode(actions, self.config)
        before = state.sim
        sim = E.step_batch(world, before, act, chunk)
        done = sim.done & ~before.done
        outcome = jax.vmap(lambda st: E.outcome(world, st))(sim)
        success = outcome.final_distance <= params.tau
        wsr = jnp.where(success, jnp.exp(-jnp.sum(sim.n_questions.astype(jnp.float32) * state.costs, -1)), 0.0)
        distance = outcome.final_distance
        reward = jnp.where(done, wsr, 0.0) + self._shaping(state.distance, distance, done, params)

        fresh = masked_map(lambda k: self._fresh(k, params), done, keys,
                           dataclasses.replace(state, sim=sim, distance=distance), chunk)
        moved = (act.kind == T.MOVE) & ~before.done
        view = E.observe_batch(world, fresh.sim, state.view, moved | done, chunk)
        nxt = dataclasses.replace(fresh, view=view)
        info = {"action_mask": jax.vmap(self.action_mask)(nxt), "outcome": outcome, "wsr": wsr.astype(jnp.float32),
                "success": success, "costs": state.costs, "episode": state.episode}
        return jax.vmap(self.get_obs)(nxt), nxt, reward.astype(jnp.float32), done, info

    # ------------------------------------------------------------------ pieces

    def _fresh(self, key: jax.Array, params: EnvParams) -> EnvState:
        """A new episode's state from ``key`` (its ``view`` a placeholder the caller fills)."""
        k_pool, k_cost, k_episode = (jax.random.fold_in(key, s) for s in RESET_STREAMS)
        n = params.pool.scene.shape[0]
        i = jax.random.randint(k_pool, (), 0, n, dtype=jnp.int32)
        spec = jax.tree.map(lambda a: a[i], params.pool)
        sim = E.reset(params.world, spec, k_episode)
        view = jax.eval_shape(lambda: E.observe(params.world, sim))
        view = jax.tree.map(lambda s: jnp.zeros(s.shape, s.dtype), view)
        d = geodesic_to_target(params.world, spec, sim.pose[:2])
        return EnvState(sim=sim, view=view, costs=draw_costs(k_cost, params), episode=i, distance=d)

    @staticmethod
    def _shaping(d_before, d_after, done, params: EnvParams):
        """gamma Phi(s') - Phi(s), Phi(s) = -shaping min(d, cap), Phi = 0 once the episode has ended."""
        phi = lambda d: -params.shaping * jnp.minimum(jnp.nan_to_num(d, posinf=SHAPING_CAP), SHAPING_CAP)  # noqa: E731
        return jnp.where(done, 0.0, params.gamma * phi(d_after)) - phi(d_before)


def make(episodes=None, config: T.SimConfig = T.SimConfig(), **params_kw) -> tuple[Env, EnvParams]:
    """The environment and its parameters over an episode file or set.

    Args:
        episodes: an :class:`~ignjax.episodes.dataset.EpisodeSet`, a path to
            an episode file, or None for the shipped benchmark
            (:func:`ignjax.data.shipped.shipped_episodes`).
        config: the simulator's configuration.
        **params_kw: :func:`ignjax.rl.params.make_params`'s settings (costs,
            sample_costs, cost_scale, per_type_prob, tau, shaping, gamma).

    Raises:
        ConfigError: a setting out of range or an empty pool.
    """
    es = episodes if isinstance(episodes, EpisodeSet) else load_benchmark(episodes or shipped_episodes())
    world = make_world(es, config)
    return Env(config), make_params(world, es.specs, **params_kw)


__all__ = ["Env", "EnvState", "RESET_STREAMS", "make"]
