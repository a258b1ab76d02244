"""The ``learned`` agent against the trainer's network and environment: the ``jax.numpy`` forward pass equals
``Policy.apply`` (GRU and MLP cores) and the flat weights convert both ways; inside a rollout the agent takes,
step for step, the actions the RL environment's steps take under the same greedy policy on the same episodes,
and ends them alike. Needs the rl extra (flax) for the trainer's network: without it these tests skip, naming
the extra (under ``CI=true`` a skip fails, tests/conftest.py)."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

pytest.importorskip("flax", reason='the trainer\'s network needs the rl extra: pip install "ignjax[rl]"')

from ignjax.agents.learned.agent import LEARNED, LearnedParams  # noqa: E402
from ignjax.agents.learned.weights import forward, from_flax, shape_of, to_flax  # noqa: E402
from ignjax.protocol import LOCKED_COSTS  # noqa: E402
from ignjax.rl import Env, make_params  # noqa: E402
from ignjax.rl import actions as A  # noqa: E402
from ignjax.rl.env import RESET_STREAMS  # noqa: E402
from ignjax.rl.obs import obs_size  # noqa: E402
from ignjax.rl.policy import Policy, init_params  # noqa: E402
from ignjax.sim import types as T  # noqa: E402
from ignjax.sim.rollout import rollout  # noqa: E402

B = 8
COSTS = 2.0 * np.asarray(LOCKED_COSTS, np.float32)


def _random_policy(core: str, hidden: int, layers: int, obs_dim: int, seed: int, logit_scale: float = 1.0):
    """A Policy and weights drawn by ``seed``: the trainer's initial ones with every array perturbed (biases
    are zero at init) and the logits scaled by ``logit_scale`` (far-apart logits: a greedy choice that float
    rounding cannot flip)."""
    pol = Policy(A.n_actions(T.SimConfig()), hidden, layers, core)
    params = init_params(pol, jax.random.key(seed), obs_dim)
    leaves, treedef = jax.tree.flatten(params)
    keys = jax.random.split(jax.random.key(seed + 1), len(leaves))
    params = jax.tree.unflatten(treedef, [x + 0.2 * jax.random.normal(k, x.shape) for x, k in zip(leaves, keys)])
    logits = f"Dense_{layers}"  # the encoder's layers are Dense_0 .. Dense_{layers - 1}
    params["params"][logits] = jax.tree.map(lambda a: a * logit_scale, params["params"][logits])
    return pol, params


@pytest.mark.parametrize("core", ["gru", "mlp"])
def test_jnp_forward_equals_the_flax_policy(core):
    pol, params = _random_policy(core, 24, 2, 37, seed=3)
    flat = from_flax(params)
    shape = shape_of(flat)
    assert (shape.core, shape.hidden, shape.layers, shape.obs_dim, shape.n_actions) == (core, 24, 2, 37, 21)
    k = jax.random.split(jax.random.key(9), 3)
    carry = jax.random.normal(k[0], (6, 24))
    obs = jax.random.normal(k[1], (6, 37))
    first = jnp.array([True, False, False, True, False, False])
    mask = jax.random.bernoulli(k[2], 0.6, (6, 21)).at[:, -1].set(True)
    want = pol.apply(params, carry, obs, first, mask)
    got = forward({n: jnp.asarray(a) for n, a in flat.items()}, carry, obs, first, mask)
    for w, g in zip(want, got):
        np.testing.assert_allclose(np.asarray(g), np.asarray(w), rtol=1e-6, atol=1e-6)
    one = forward(flat, carry[1], obs[1], first[1], mask[1])  # one episode, numpy weights: the agent's call
    for w, g in zip(want, one):
        np.testing.assert_allclose(np.asarray(g), np.asarray(w)[1], rtol=1e-6, atol=1e-6)
    back = pol.apply(to_flax(flat), carry, obs, first, mask)
    for w, g in zip(want, back):
        np.testing.assert_array_equal(np.asarray(g), np.asarray(w))


def _env_episodes(env: Env, envp, pol: Policy, params, keys):
    """Drive the environment with the greedy policy until every row's first episode ends: per row the decoded
    actions of that episode, and its outcome row (numpy)."""
    step = jax.jit(env.step_batch)
    obs, state = jax.jit(env.reset_batch)(keys, envp)
    episode = np.asarray(state.episode)
    mask = jax.vmap(env.action_mask)(state)
    carry, first = pol.initial_carry(B), jnp.ones(B, bool)
    actions = [[] for _ in range(B)]
    outcomes: list = [None] * B
    for t in range(env.config.max_steps):
        carry, logits, _ = pol.apply(params, carry, obs, first, mask)
        a = jnp.argmax(logits, -1).astype(jnp.int32)
        obs, state, _, done, info = step(jax.random.split(jax.random.key(100 + t), B), state, a, envp)
        first, mask = done, info["action_mask"]
        for i in range(B):
            if outcomes[i] is None:
                actions[i].append(int(a[i]))
                if bool(done[i]):
                    outcomes[i] = jax.tree.map(lambda x: np.asarray(x)[i], info["outcome"])
    assert all(o is not None for o in outcomes)  # the step budget ends every episode
    return episode, actions, outcomes


def _recorded(traj, i: int, n: int) -> list[tuple]:
    """(kind, direction, col, row, question) of the first ``n`` decisions of row ``i`` of a rollout's trajectory
    (direction, col and row for a MOVE only, the question for an ASK only, as the trajectory records them)."""
    out = []
    for t in range(n):
        kind = int(traj.kind[i, t])
        move = (int(traj.direction[i, t]), int(traj.col[i, t]), int(traj.row[i, t])) if kind == T.MOVE else ()
        out.append((kind,) + move + ((int(traj.question[i, t]),) if kind == T.ASK else ()))
    return out


def _decoded(a: int, cfg) -> tuple:
    act = jax.tree.map(int, A.decode(a, cfg))
    move = (act.direction, act.col, act.row) if act.kind == T.MOVE else ()
    return (act.kind,) + move + ((act.question,) if act.kind == T.ASK else ())


def test_agent_in_a_rollout_takes_the_environments_actions(small_benchmark, small_world):
    """The same greedy GRU policy: through ``Policy.apply`` stepping :class:`ignjax.rl.env.Env`, and as the
    ``learned`` agent inside :func:`ignjax.sim.rollout.rollout` on the episodes the environment drew (the
    episode's key is the one the environment's reset gives the simulator), charged the same costs."""
    cfg = small_world.config
    pol, params = _random_policy("gru", 32, 2, obs_size(cfg), seed=11, logit_scale=50.0)
    env = Env(cfg)
    envp = make_params(small_world, small_benchmark["set"].specs, costs=COSTS, sample_costs=False)
    keys = jax.random.split(jax.random.key(5), B)
    episode, actions, outcomes = _env_episodes(env, envp, pol, params, keys)

    specs = jax.tree.map(lambda a: a[episode], envp.pool)
    sim_keys = jax.vmap(lambda k: jax.random.fold_in(k, RESET_STREAMS[2]))(keys)
    weights = {n: jnp.asarray(a) for n, a in from_flax(params).items()}
    lp = LearnedParams(costs=jnp.asarray(COSTS), greedy=jnp.asarray(True), weights=weights, config=cfg)
    out, traj = jax.tree.map(np.asarray, rollout(small_world, specs, LEARNED, lp, sim_keys))
    kinds = set()
    for i in range(B):
        n = len(actions[i])
        assert int(out.steps[i]) == int(outcomes[i].steps) == n, i
        assert _recorded(traj, i, n) == [_decoded(a, cfg) for a in actions[i]], i
        kinds |= {_decoded(a, cfg)[0] for a in actions[i]}
        for field in ("final_distance", "path_length", "stop_reason", "n_questions", "n_refused", "stopped"):
            np.testing.assert_array_equal(getattr(out, field)[i], getattr(outcomes[i], field), err_msg=f"{i} {field}")
    assert {T.MOVE, T.ASK} <= kinds, kinds  # the policy moved and asked (a comparison with something to compare)
