"""The sharded batch of environments: device counts and the bench's random-action program."""

from __future__ import annotations

import jax
import numpy as np
import pytest

from ignjax.errors import ConfigError
from ignjax.rl import VecEnv


def test_devices_divide_the_rows(rl):
    env = rl["env"]
    assert VecEnv(env, 4).parts == min(2, jax.local_device_count())
    assert VecEnv(env, 3).parts == 1  # the most devices that divide 3 rows
    with pytest.raises(ConfigError, match="rl.parts"):
        VecEnv(env, 3, parts=2)
    with pytest.raises(ConfigError, match="rl.num_envs"):
        VecEnv(env, 0)


def test_random_valid_steps_with_auto_reset(rl):
    vec = VecEnv(rl["env"], 4)
    params = rl["params"]
    obs, state = vec.reset(jax.random.key(0), params)
    out = [vec.random_steps(jax.random.key(1), state, params, 25) for _ in range(2)]
    state2, totals = out[0]
    assert all(np.asarray(a).tobytes() == np.asarray(b).tobytes() for a, b in zip(jax.tree.leaves(out[0]),
                                                                                    jax.tree.leaves(out[1])))
    assert np.all(np.asarray(totals["episodes"]) >= 1)  # 25 steps > the step budget: every row ended an episode
    assert np.all(np.asarray(totals["reward"]) >= 0) and np.all(np.asarray(totals["reward"]) <= np.asarray(totals["episodes"]))
    assert not np.any(np.asarray(state2.sim.done))
