"""The Gymnasium vector-environment adapter: numpy in and out, the JAX
environment's spaces, masks in ``info``, and the same episodes as the JAX
environment for the same keys and actions."""

from __future__ import annotations

import sys

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.errors import ConfigError
from ignjax.errors.extras import MissingExtra
from ignjax.rl.gym import END_FIELDS, IgnjaxVectorEnv

gymnasium = pytest.importorskip("gymnasium")

N_ENVS = 4
STEPS = 24
SEED = 7


@pytest.fixture(scope="module")
def played(rl):
    """A short run of random valid actions through the adapter: (adapter, reset output, per-step outputs, actions)."""
    vec = IgnjaxVectorEnv(N_ENVS, env=rl["env"], params=rl["params"])
    first = vec.reset(seed=SEED)
    rng = np.random.default_rng(0)
    mask = first[1]["action_mask"]
    steps, actions = [], []
    for _ in range(STEPS):
        a = np.array([rng.choice(np.flatnonzero(m)) for m in mask], np.int64)
        out = vec.step(a)
        steps.append(out)
        actions.append(a)
        mask = out[4]["action_mask"]
    return vec, first, steps, actions


def test_spaces_types_and_masks(played, rl):
    vec, (obs, info), steps, actions = played
    env = rl["env"]
    assert isinstance(vec, gymnasium.vector.VectorEnv)
    assert vec.single_action_space == gymnasium.spaces.Discrete(env.num_actions)
    assert vec.single_observation_space.shape == env.observation_space().shape
    assert vec.observation_space.shape == (N_ENVS,) + env.observation_space().shape
    assert vec.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.SAME_STEP
    assert isinstance(obs, np.ndarray) and obs.dtype == np.float32 and vec.observation_space.contains(obs)
    assert info["action_mask"].shape == (N_ENVS, env.num_actions) and info["action_mask"].dtype == bool
    ended = 0
    for o, r, term, trunc, inf in steps:
        assert vec.observation_space.contains(o)
        assert r.dtype == np.float32 and term.dtype == bool and not trunc.any()
        if term.any():
            ended += int(term.sum())
            for name in END_FIELDS:
                np.testing.assert_array_equal(inf[f"_{name}"], term)
            np.testing.assert_allclose(r[term], inf["wsr"][term], rtol=1e-6)
    assert ended >= 2
    assert vec.action_space.contains(np.stack(actions)[0])


def test_the_adapter_equals_the_jax_environment_for_the_same_keys_and_actions(played, rl):
    vec, (obs0, _), steps, actions = played
    params = rl["params"]
    stream = jax.random.fold_in(jax.random.key(SEED), 0)  # the first reset since the seed
    obs, state = rl["reset"](jax.random.split(jax.random.fold_in(stream, 0), N_ENVS), params)
    np.testing.assert_allclose(obs, obs0, atol=1e-5)
    for t, (a, (o, r, term, _, inf)) in enumerate(zip(actions, steps)):
        keys = jax.random.split(jax.random.fold_in(stream, t + 1), N_ENVS)
        obs, state, reward, done, info = rl["step"](keys, state, jnp.asarray(a, jnp.int32), params)
        np.testing.assert_array_equal(np.asarray(done), term, err_msg=f"step {t}")
        np.testing.assert_allclose(np.asarray(reward), r, atol=1e-5, err_msg=f"step {t}")
        np.testing.assert_allclose(np.asarray(obs), o, atol=1e-4, err_msg=f"step {t}")
        if term.any():
            np.testing.assert_allclose(np.asarray(info["outcome"].final_distance)[term], inf["final_distance"][term],
                                       atol=1e-4)
            np.testing.assert_array_equal(np.asarray(info["outcome"].n_questions)[term], inf["n_questions"][term])


def test_reset_with_the_same_seed_gives_the_same_bytes(played):
    vec, (obs0, info0), _, _ = played
    obs, info = vec.reset(seed=SEED)
    assert obs.tobytes() == obs0.tobytes()
    obs2, _ = vec.reset()  # the next reset of the stream draws other episodes
    assert obs2.tobytes() != obs0.tobytes()


def test_bad_actions_are_config_errors(played):
    vec = played[0]
    vec.reset(seed=1)
    for bad in (np.full(N_ENVS, vec.single_action_space.n), np.zeros(N_ENVS - 1, np.int64), np.zeros(N_ENVS) + 0.5):
        with pytest.raises(ConfigError, match="rl.actions"):
            vec.step(bad)


def test_without_gymnasium_the_adapter_names_the_extra(rl, monkeypatch):
    monkeypatch.setitem(sys.modules, "gymnasium", None)  # what `import gymnasium` meets without the rl extra
    with pytest.raises(MissingExtra, match=r'ignjax\[rl\]'):
        IgnjaxVectorEnv(N_ENVS, env=rl["env"], params=rl["params"])
