"""B environments as one jitted program sharded over the devices.

:class:`VecEnv` runs :meth:`ignjax.rl.env.Env.reset_batch` and
:meth:`~ignjax.rl.env.Env.step_batch` with the rows split over a 1-D mesh of
this process's devices (:func:`ignjax.sim.rollout.device_mesh`: one CPU
device per core, :func:`ignjax.devices.configure_cpu_devices`, or GPUs) and
the world copied once to each (:func:`ignjax.sim.rollout.replicate_world`),
compiled with the rollouts' compiler options. Its keys follow one rule: a
call with key ``k`` gives row ``i`` the key ``jax.random.split(k, B)[i]``,
so ``VecEnv.step(k, ...)`` equals ``jax.vmap(env.step)(jax.random.split(k, B), ...)``
row for row (up to float rounding at other vectorised widths).

:meth:`VecEnv.random_steps` is the bench's program: ``n`` steps of random
valid actions (uniform over each row's mask) with auto-reset, one
``lax.scan``, the shape a trainer's loop has (a policy in place of the
random draw).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import partial

import jax
import jax.numpy as jnp
from jax.sharding import PartitionSpec as P

from ignjax.errors import ConfigError
from ignjax.rl.env import Env, EnvState
from ignjax.rl.params import EnvParams
from ignjax.sim.rollout import AXIS, ROLLOUT_COMPILER_OPTIONS, batch_parts, device_mesh, replicate_world


@partial(jax.jit, static_argnames=("fn", "mesh"), compiler_options=ROLLOUT_COMPILER_OPTIONS)
def _run(params, rows, *, fn, mesh):
    """``fn(params, rows)`` with ``rows``' leading axis (and the outputs') split over ``mesh``."""
    return jax.shard_map(fn, mesh=mesh, in_specs=(P(), P(AXIS)), out_specs=P(AXIS), check_vma=False)(params, rows)


@dataclass(frozen=True)
class _Reset:
    env: Env
    chunk: int | None

    def __call__(self, params, rows):
        (keys,) = rows
        return self.env.reset_batch(keys, params, self.chunk)


@dataclass(frozen=True)
class _Step:
    env: Env
    chunk: int | None

    def __call__(self, params, rows):
        keys, state, actions = rows
        return self.env.step_batch(keys, state, actions, params, self.chunk)


@dataclass(frozen=True)
class _RandomSteps:
    env: Env
    chunk: int | None
    n: int

    def __call__(self, params, rows):
        keys, state = rows
        env = self.env

        def body(carry, t):
            state, mask, totals = carry
            k = jax.vmap(lambda key: jax.random.split(jax.random.fold_in(key, t)))(keys)
            logits = jnp.where(mask, 0.0, -jnp.inf)
            actions = jax.vmap(jax.random.categorical)(k[:, 0], logits).astype(jnp.int32)
            obs, state, reward, done, info = env.step_batch(k[:, 1], state, actions, params, self.chunk)
            totals = {"reward": totals["reward"] + reward, "episodes": totals["episodes"] + done.astype(jnp.int32),
                      "obs": totals["obs"] + jnp.sum(obs, -1)}  # the observation is used, so it is computed
            return (state, info["action_mask"], totals), None

        B = keys.shape[0]
        zeros = {"reward": jnp.zeros(B, jnp.float32), "episodes": jnp.zeros(B, jnp.int32), "obs": jnp.zeros(B)}
        mask = jax.vmap(env.action_mask)(state)
        (state, _, totals), _ = jax.lax.scan(body, (state, mask, zeros), jnp.arange(self.n, dtype=jnp.uint32))
        return state, totals


def env_parts(num_envs: int, parts: int | None) -> int:
    """Devices to shard ``num_envs`` rows over: ``parts`` (it must divide them), or the most devices that divide them."""
    if parts:
        p = batch_parts(num_envs, parts)
        if num_envs % p:
            raise ConfigError(None, "rl.parts", f"{p} devices do not divide {num_envs} environments")
        return p
    available = batch_parts(num_envs, None)
    return max(p for p in range(1, available + 1) if num_envs % p == 0)


class VecEnv:
    """``num_envs`` environments sharded over ``parts`` devices (None: as many as divide ``num_envs``).

    Args:
        env: the environment.
        num_envs: rows B.
        parts: devices (:func:`ignjax.sim.rollout.batch_parts`); must divide B.
        chunk: rows per vectorised call of the simulator on each device (default: an eighth of its rows).

    Raises:
        ConfigError: ``num_envs`` < 1 or ``parts`` out of range or not dividing it.
    """

    def __init__(self, env: Env, num_envs: int, parts: int | None = None, chunk: int | None = None):
        if isinstance(num_envs, bool) or not isinstance(num_envs, int) or num_envs < 1:
            raise ConfigError(None, "rl.num_envs", f"must be a positive integer, got {num_envs!r}")
        self.env, self.num_envs, self.chunk = env, num_envs, chunk
        self.parts = env_parts(num_envs, parts)
        self.mesh = device_mesh(self.parts)

    def _params(self, params: EnvParams) -> EnvParams:
        self.env.check(params)
        return dataclasses.replace(params, world=replicate_world(params.world, self.mesh))

    def _keys(self, key: jax.Array) -> jax.Array:
        return jax.random.split(key, self.num_envs)

    def reset(self, key: jax.Array, params: EnvParams) -> tuple[jax.Array, EnvState]:
        """(obs (B, D), state) of B fresh episodes; row i drawn by ``split(key, B)[i]``."""
        return _run(self._params(params), (self._keys(key),), fn=_Reset(self.env, self.chunk), mesh=self.mesh)

    def step(self, key: jax.Array, state: EnvState, actions, params: EnvParams):
        """(obs, state, reward, done, info) of one step of every row (:meth:`ignjax.rl.env.Env.step_batch`)."""
        actions = jnp.asarray(actions, jnp.int32)
        return _run(self._params(params), (self._keys(key), state, actions), fn=_Step(self.env, self.chunk),
                    mesh=self.mesh)

    def random_steps(self, key: jax.Array, state: EnvState, params: EnvParams, n: int):
        """``n`` steps of random valid actions with auto-reset: (state, per-row totals ``reward``, ``episodes``, ``obs``)."""
        return _run(self._params(params), (self._keys(key), state), fn=_RandomSteps(self.env, self.chunk, int(n)),
                    mesh=self.mesh)


__all__ = ["VecEnv", "env_parts"]
