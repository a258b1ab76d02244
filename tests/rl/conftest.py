"""The RL environment's fixtures: the environment over a pool of a few of the
small benchmark's episodes, and its jitted functions (compiled once per module)."""

from __future__ import annotations

import jax
import pytest

from ignjax.rl import Env, make_params

POOL = 6
"""Episodes in the tests' pool."""


@pytest.fixture(scope="module")
def rl(small_benchmark, small_world):
    """(env, params with drawn costs, params with the locked costs fixed) and the jitted vmapped / batched functions."""
    es = small_benchmark["set"]
    pool = jax.tree.map(lambda a: a[:POOL], es.specs)
    env = Env(small_world.config)
    return {
        "env": env,
        "params": make_params(small_world, pool),
        "fixed": make_params(small_world, pool, sample_costs=False),
        "reset": jax.jit(jax.vmap(env.reset, in_axes=(0, None))),
        "step": jax.jit(jax.vmap(env.step, in_axes=(0, 0, 0, None))),
        "reset_batch": jax.jit(env.reset_batch),
        "step_batch": jax.jit(env.step_batch),
    }
