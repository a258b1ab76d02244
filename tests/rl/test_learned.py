"""The learned policy's weights against the trainer's network: the ``jax.numpy`` forward pass equals
``Policy.apply`` (GRU and MLP cores) and the flat weights convert both ways. Needs the rl extra (flax) for the
trainer's network: without it these tests skip, naming the extra (under ``CI=true`` a skip fails,
tests/conftest.py)."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

pytest.importorskip("flax", reason='the trainer\'s network needs the rl extra: pip install "ignjax[rl]"')

from ignjax.agents.learned.weights import forward, from_flax, shape_of, to_flax  # noqa: E402
from ignjax.rl import actions as A  # noqa: E402
from ignjax.rl.policy import Policy, init_params  # noqa: E402
from ignjax.sim import types as T  # noqa: E402


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
