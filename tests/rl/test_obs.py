"""The observation vector reads what the agents may see and nothing else:
every slice's sources are allow-listed, and changing any privileged part of
the state (target, its field, the route's point, distances, the start, the
pose behind the perception) leaves the vector unchanged."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.rl.obs import COSTS_SOURCE, SLOT_FEATURES, obs_layout, obs_size
from ignjax.sim import types as T

ALLOWED_STATE = ("view", "costs", "sim.answers")
"""The parts of :class:`ignjax.rl.EnvState` the observation may read."""


def test_every_slice_names_allow_listed_sources(rl):
    cfg = rl["env"].config
    for s in obs_layout(cfg):
        assert s.sources and s.meaning, s
        for src in s.sources:
            assert src in T.AGENT_FIELDS or src == COSTS_SOURCE, (s.name, src)
    visible = {s.name: s for s in obs_layout(cfg)}["visible"]
    assert visible.size == cfg.max_visible * len(SLOT_FEATURES)
    assert sum(s.size for s in obs_layout(cfg)) == obs_size(cfg)


def _perturb(leaf):
    x = np.asarray(leaf)
    if x.dtype == bool:
        return jnp.asarray(~x)
    if np.issubdtype(x.dtype, np.integer):
        return jnp.asarray(x + 1, x.dtype)
    if np.issubdtype(x.dtype, np.floating):
        return jnp.asarray(x + 0.731, x.dtype)
    return leaf  # key data


def test_the_observation_is_a_function_of_the_agent_visible_fields_only(rl):
    env, params = rl["env"], rl["params"]
    obs, state = rl["reset"](jax.random.split(jax.random.key(1), 2), params)
    obs, state, *_ = rl["step"](jax.random.split(jax.random.key(2), 2), state, jnp.array([19, 18]), params)
    state = jax.tree.map(lambda a: a[0], state)
    base = np.asarray(env.get_obs(state))
    np.testing.assert_allclose(base, np.asarray(obs[0]), atol=1e-6)  # the jitted step computed it
    paths = jax.tree_util.tree_flatten_with_path(state)[0]
    changed = 0
    for path, leaf in paths:
        name = jax.tree_util.keystr(path, simple=True, separator=".")
        if name.startswith(ALLOWED_STATE):
            continue
        leaves = [(_perturb(x) if p == path else x) for p, x in paths]
        other = jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(state), leaves)
        np.testing.assert_array_equal(np.asarray(env.get_obs(other)), base, err_msg=name)
        changed += 1
    assert changed >= 25  # the whole simulator state but its answers: episode, pose, hint point, distances ...
    # and the target itself: another target in the same scene gives the same vector
    other = dataclasses.replace(state, sim=dataclasses.replace(
        state.sim, episode=dataclasses.replace(state.sim.episode, target=state.sim.episode.target + 1),
        hint_point=state.sim.hint_point + 3.0), distance=state.distance + 2.0)
    np.testing.assert_array_equal(np.asarray(env.get_obs(other)), base)


def test_the_observation_changes_with_what_the_agent_sees(rl):
    env, params = rl["env"], rl["params"]
    _, state = rl["reset"](jax.random.split(jax.random.key(3), 2), params)
    state = jax.tree.map(lambda a: a[0], state)
    base = np.asarray(env.get_obs(state))
    layout = {s.name: s for s in obs_layout(env.config)}
    for part, field in (("view", "steps_left"), ("costs", None)):
        if field is None:
            other = dataclasses.replace(state, costs=state.costs * 2)
            sl = layout["costs"]
        else:
            other = dataclasses.replace(state, view=dataclasses.replace(state.view, steps_left=state.view.steps_left - 1))
            sl = layout["budget"]
        diff = np.flatnonzero(np.asarray(env.get_obs(other)) != base)
        assert diff.size and np.all((diff >= sl.start) & (diff < sl.start + sl.size)), (part, diff)
