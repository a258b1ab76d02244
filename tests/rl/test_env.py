"""The functional RL environment: spaces, shapes and dtypes, jit and vmap,
the batched step against the vmapped one, auto-reset, the mask, the reward
against the metrics' WSR, shaping, the cost distribution and bad parameters."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.errors import ConfigError
from ignjax.evaluate import metrics as M
from ignjax.protocol import LOCKED_COSTS, MAX_QUESTIONS
from ignjax.rl import actions as A
from ignjax.rl import make_params, obs_layout, obs_size
from ignjax.rl.params import draw_costs
from ignjax.sim import types as T
from ignjax.sim.env import check_action
from ignjax.sim.world import World

B = 4
STOP = 2 * T.N_VIEWS + 4
ASK = {t: 2 * T.N_VIEWS + t - 1 for t in (1, 2, 3, 4)}


def _keys(seed, n=B):
    return jax.random.split(jax.random.key(seed), n)


def _run(rl, params, policy, steps, seed=0):
    """Run the vmapped env for ``steps`` steps with ``policy(t) -> (B,) actions``; returns the per-step outputs."""
    obs, state = rl["reset"](_keys(seed), params)
    out = []
    for t in range(steps):
        obs, state, reward, done, info = rl["step"](_keys(1000 + t + 100 * seed), state, policy(t), params)
        out.append(jax.tree.map(np.asarray, (obs, reward, done, info)))
    return out, state


def test_spaces_shapes_and_dtypes(rl):
    env, params = rl["env"], rl["params"]
    obs, state = rl["reset"](_keys(0), params)
    assert obs.shape == (B, obs_size(env.config)) and obs.dtype == jnp.float32
    space = env.observation_space(params)
    assert space.shape == (obs_size(env.config),)
    assert all(space.contains(np.asarray(o)) for o in obs)
    assert env.action_space(params).n == A.n_actions(env.config) == 2 * 8 + 5 == len(A.action_names(env.config))
    layout = obs_layout(env.config)
    assert [s.start for s in layout] == list(np.cumsum([0] + [s.size for s in layout[:-1]]))
    obs, state, reward, done, info = rl["step"](_keys(1), state, jnp.zeros(B, jnp.int32), params)
    assert reward.shape == (B,) and reward.dtype == jnp.float32 and done.dtype == jnp.bool_
    assert info["action_mask"].shape == (B, A.n_actions(env.config)) and info["action_mask"].dtype == jnp.bool_
    assert int(env.action_space(params).sample(jax.random.key(0))) in range(A.n_actions(env.config))


def test_the_action_table_follows_the_protocol(rl):
    cfg = rl["env"].config
    table = A.action_table(cfg)
    a = A.decode(jnp.arange(A.n_actions(cfg)), cfg)
    assert np.all(np.asarray(a.kind[:16]) == T.MOVE) and np.all(np.asarray(a.kind[16:20]) == T.ASK)
    assert int(a.kind[STOP]) == T.STOP and np.all(np.asarray(a.candidate) == T.ANY_CANDIDATE)
    assert list(np.asarray(a.question[16:20])) == [1, 2, 3, 4]
    assert A.move_cells(cfg) == ((5, 1), (5, 3))
    assert list(table["direction"][:16]) == list(range(8)) * 2
    E = jax.tree.map(np.asarray, a)
    for k in range(A.n_actions(cfg)):  # every table action is in range (no clamping, no invalid count)
        check_action(jax.tree.map(lambda x: x[k], E))


def test_the_batched_step_equals_the_vmapped_one(rl):
    params = rl["params"]
    keys = _keys(5)
    obs_v, st_v = rl["reset"](keys, params)
    obs_b, st_b = rl["reset_batch"](keys, params)
    np.testing.assert_allclose(obs_v, obs_b, atol=1e-6)
    acts = [jnp.array([0, 9, ASK[1], STOP]), jnp.array([ASK[3], 3, 12, ASK[4]]), jnp.array([STOP, 1, ASK[2], 7])]
    for t, a in enumerate(acts):
        k = _keys(50 + t)
        ov, st_v, rv, dv, iv = rl["step"](k, st_v, a, params)
        ob, st_b, rb, db, ib = rl["step_batch"](k, st_b, a, params)
        np.testing.assert_array_equal(dv, db)
        np.testing.assert_allclose(rv, rb, atol=1e-6)
        np.testing.assert_allclose(ov, ob, atol=1e-5)
        np.testing.assert_array_equal(iv["action_mask"], ib["action_mask"])


def test_same_keys_give_the_same_bytes(rl):
    policy = lambda t: jnp.array([t % 21, (3 * t) % 21, ASK[1 + t % 4], (t * 7) % 21])  # noqa: E731
    a, _ = _run(rl, rl["params"], policy, 6, seed=2)
    b, _ = _run(rl, rl["params"], policy, 6, seed=2)
    for x, y in zip(jax.tree.leaves(a), jax.tree.leaves(b)):
        assert np.asarray(x).tobytes() == np.asarray(y).tobytes()


def test_stop_ends_the_episode_and_resets_from_the_pool(rl):
    params = rl["fixed"]
    obs, state = rl["reset"](_keys(7), params)
    assert not np.any(np.asarray(state.sim.done)) and np.all(np.asarray(state.sim.step) == 0)
    obs2, state2, reward, done, info = rl["step"](_keys(8), state, jnp.full(B, STOP), params)
    assert np.all(np.asarray(done))
    o = info["outcome"]
    assert np.all(np.asarray(o.stopped)) and np.all(np.asarray(o.steps) == 1)
    want = (np.asarray(o.final_distance) <= 1.5).astype(np.float32)  # no question asked: WSR = success
    np.testing.assert_allclose(reward, want)
    np.testing.assert_array_equal(info["episode"], state.episode)
    # the returned state is a fresh episode drawn by the step's key
    assert np.all(np.asarray(state2.sim.step) == 0) and not np.any(np.asarray(state2.sim.done))
    assert np.all((np.asarray(state2.episode) >= 0) & (np.asarray(state2.episode) < params.pool.scene.shape[0]))
    fresh_obs, fresh = rl["reset"](_keys(8), params)
    np.testing.assert_array_equal(state2.episode, fresh.episode)
    np.testing.assert_allclose(obs2, fresh_obs, atol=1e-6)


def test_questions_are_masked_once_the_budget_is_spent(rl):
    params = rl["fixed"]
    obs, state = rl["reset"](_keys(9), params)
    layout = {s.name: s for s in obs_layout(rl["env"].config)}
    for t in range(MAX_QUESTIONS):
        obs, state, reward, done, info = rl["step"](_keys(90 + t), state, jnp.full(B, ASK[1 + t % 4]), params)
        assert not np.any(np.asarray(done))
        asks = np.asarray(info["action_mask"])[:, 16:20]
        assert np.all(asks == (t + 1 < MAX_QUESTIONS))
    mask = np.asarray(info["action_mask"])
    assert np.all(mask[:, :16]) and np.all(mask[:, STOP])
    costs = np.asarray(obs)[:, layout["costs"].start:layout["costs"].start + 4]
    np.testing.assert_allclose(costs, np.broadcast_to(LOCKED_COSTS, (B, 4)), rtol=1e-6)


def _ended(out, costs_of_row=None):
    """The outcomes, rewards and costs of the episodes that ended in ``out`` (a list of per-step outputs)."""
    rows, rewards, costs = [], [], []
    for obs, reward, done, info in out:
        for i in np.flatnonzero(done):
            rows.append(jax.tree.map(lambda a: a[i], info["outcome"]))
            rewards.append(reward[i])
            costs.append(info["costs"][i])
    return jax.tree.map(lambda *x: np.stack(x), *rows), np.array(rewards), np.array(costs)


def _policy(t):
    """A fixed policy mixing every kind of action (episodes end by STOP and by the step budget)."""
    cycle = [ASK[1], 0, 8, ASK[3], 2, 9, ASK[4], 14, ASK[2], STOP]
    return jnp.array([cycle[(t + k) % len(cycle)] if k < 3 else (0 if t % 23 < 22 else STOP) for k in range(B)])


def test_terminal_rewards_are_the_metrics_wsr_of_the_same_outcomes(rl):
    out, _ = _run(rl, rl["fixed"], _policy, 45, seed=3)
    outcomes, rewards, _ = _ended(out)
    assert len(rewards) >= 8 and set(np.asarray(outcomes.stop_reason)) == {T.STOPPED, T.OUT_OF_STEPS}
    assert np.asarray(outcomes.n_questions).sum() > 0
    m = M.summarize(outcomes, thresholds=(1.5,), costs=LOCKED_COSTS)
    np.testing.assert_allclose(rewards.mean(), m["WSR"][0], rtol=1e-5)
    # the non-terminal steps pay nothing
    assert all(np.all(r[~d] == 0) for _, r, d, _ in out)


def test_drawn_costs_are_charged_per_episode(rl):
    out, _ = _run(rl, rl["params"], _policy, 30, seed=4)
    outcomes, rewards, costs = _ended(out)
    assert not np.allclose(costs, np.asarray(LOCKED_COSTS))
    success = M.episode_success(outcomes.final_distance, outcomes.stopped, (1.5,))
    want = [float(M.episode_wsr(success[i], outcomes.n_questions[i], costs[i])[0]) for i in range(len(rewards))]
    np.testing.assert_allclose(rewards, want, rtol=1e-5)


def test_shaping_is_potential_based(rl):
    """With gamma = 1 the shaped episode's return is the unshaped one plus lambda * min(d0, cap)."""
    lam = 0.5
    shaped = dataclasses.replace(rl["fixed"], shaping=jnp.float32(lam), gamma=jnp.float32(1.0))
    plain, _ = _run(rl, rl["fixed"], _policy, 22, seed=5)
    with_shaping, _ = _run(rl, shaped, _policy, 22, seed=5)
    _, s0 = rl["reset"](_keys(5), rl["fixed"])
    d0 = np.minimum(np.nan_to_num(np.asarray(s0.distance), posinf=10.0), 10.0)
    ends = np.stack([d for _, _, d, _ in plain])
    assert np.all(ends.any(0))
    first_done = np.argmax(ends, axis=0)
    for i in range(B):
        T_i = first_done[i] + 1
        gain = sum(with_shaping[t][1][i] - plain[t][1][i] for t in range(T_i))
        np.testing.assert_allclose(gain, lam * d0[i], rtol=1e-4, atol=1e-4)
        assert plain[first_done[i]][2][i]


def test_the_cost_distribution(rl):
    params = rl["params"]
    keys = jax.random.split(jax.random.key(11), 4000)
    costs = np.asarray(jax.vmap(lambda k: draw_costs(k, params))(keys))
    scale = costs / np.asarray(LOCKED_COSTS)
    assert scale.min() >= 0.25 * (1 - 1e-5) and scale.max() <= 8 * (1 + 1e-5)
    apart = ~np.isclose(scale.min(1), scale.max(1), rtol=1e-5)
    assert 0.2 < apart.mean() < 0.3  # per_type_prob = 0.25
    log = np.log(scale[~apart, 0])
    assert abs(log.mean() - np.log(np.sqrt(0.25 * 8))) < 0.1  # log-uniform: mean of the log in the middle
    fixed = np.asarray(jax.vmap(lambda k: draw_costs(k, rl["fixed"]))(keys[:10]))
    np.testing.assert_allclose(fixed, np.broadcast_to(LOCKED_COSTS, (10, 4)), rtol=1e-6)


@pytest.mark.parametrize("kw, where", [
    ({"costs": (0.1, -0.2, 0.1, 0.1)}, "rl.costs"), ({"costs": (0.1, 0.1, 0.1)}, "rl.costs"),
    ({"cost_scale": (2.0, 1.0)}, "rl.cost_scale"), ({"cost_scale": (0.0, 1.0)}, "rl.cost_scale"),
    ({"per_type_prob": 1.5}, "rl.per_type_prob"), ({"tau": 0.0}, "rl.tau"), ({"gamma": 1.5}, "rl.gamma"),
    ({"shaping": -1.0}, "rl.shaping"),
])
def test_bad_parameters_are_config_errors(rl, small_world, kw, where):
    with pytest.raises(ConfigError, match=where.replace(".", r"\.")):
        make_params(small_world, rl["params"].pool, **kw)


def test_an_empty_pool_zero_budgets_and_another_world_are_config_errors(rl, small_world):
    empty = jax.tree.map(lambda a: a[:0], rl["params"].pool)
    with pytest.raises(ConfigError, match="rl.pool.*empty"):
        make_params(small_world, empty)
    invalid = dataclasses.replace(rl["params"].pool, valid=jnp.zeros_like(rl["params"].pool.valid))
    with pytest.raises(ConfigError, match="rl.pool.*empty"):
        make_params(small_world, invalid)
    for name in ("max_steps", "max_questions"):
        with pytest.raises(ConfigError, match=f"sim.{name}"):
            T.SimConfig(**{name: 0})
    other = World(small_world.bank, small_world.fields, dataclasses.replace(small_world.config, max_steps=7),
                  small_world.fine, small_world.packed_obs)
    with pytest.raises(ConfigError, match="rl.world"):
        rl["env"].check(make_params(other, rl["params"].pool))
