"""What agents may receive (the allow-list), the paper-reading settings
(upfront description, unbudgeted questions) and the noisy-perception option."""

from __future__ import annotations

import dataclasses
import math

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.errors import ConfigError
from ignjax.evaluate import metrics as M
from ignjax.protocol import LOCKED_COSTS
from ignjax.sim import env as E
from ignjax.sim import types as T
from ignjax.sim.world import World


def _spec(es, k):
    return jax.tree.map(lambda a: a[k], es.specs)


def _world(small_world, **kw):
    return World(small_world.bank, small_world.fields, dataclasses.replace(small_world.config, **kw))


# ---------------------------------------------------------------------------
# the allow-list of what an agent receives
# ---------------------------------------------------------------------------


def test_every_field_an_agent_receives_has_an_allow_list_entry():
    fields = {f"{cls.__name__}.{f.name}" for cls in (T.Observation, T.Answer) for f in dataclasses.fields(cls)}
    missing = sorted(fields - set(T.AGENT_FIELDS))
    assert not missing, f"fields an agent receives without an entry (and reason) in T.AGENT_FIELDS: {missing}"
    stale = sorted(set(T.AGENT_FIELDS) - fields)
    assert not stale, f"allow-list entries for fields that no longer exist: {stale}"
    assert all(len(reason) > 15 for reason in T.AGENT_FIELDS.values())


def test_the_rl_observation_vector_reads_allow_listed_fields_only():
    """The RL environment's observation vector (:mod:`ignjax.rl.obs`) names
    the fields each slice is computed from: allow-listed ones, or the
    episode's costs (tests/rl/test_obs.py checks that nothing else enters it)."""
    from ignjax.rl.obs import COSTS_SOURCE, obs_layout

    sources = {src for s in obs_layout() for src in s.sources}
    assert sources - set(T.AGENT_FIELDS) == {COSTS_SOURCE}


def test_answers_carry_codes_only_and_no_world_point(small_benchmark, small_world):
    """Every answer leaf is an integer or boolean code after each question
    type (no float can carry a coordinate, distance or heading), and the
    route's world point stays in the state."""
    es = small_benchmark["set"]
    step = jax.jit(E.step)
    st = E.reset(small_world, _spec(es, 0))
    for q in (1, 2, 3, 4):
        st = step(small_world, st, T.Action.make(T.ASK, question=q))
        for f in dataclasses.fields(T.Answer):
            dtype = np.asarray(getattr(st.answers, f.name)).dtype
            assert dtype == bool or np.issubdtype(dtype, np.integer), (f.name, dtype)
    assert int(st.answers.hint_active) == 1
    assert float(jnp.linalg.norm(st.hint_point)) > 0  # the internal hint point was set
    assert "hint_point" not in {f.name for f in dataclasses.fields(T.Answer)}


def test_answers_do_not_depend_on_the_target_beyond_their_facts(small_benchmark, small_world):
    """Information flow through the answers: two episodes that differ only in
    the target's position (same facts) get the same Type-1/2 answers; the
    Type-3 answer changes only through its codes."""
    es = small_benchmark["set"]
    step = jax.jit(E.step)
    spec = _spec(es, 0)
    st = E.reset(small_world, spec)
    a1 = step(small_world, step(small_world, st, T.Action.make(T.ASK, question=1)), T.Action.make(T.ASK, question=2))
    other = dataclasses.replace(spec, target=jnp.int32((int(spec.target) + 1) % int(np.sum(es.bank.instances.valid[int(spec.scene)]))))
    b1 = step(small_world, step(small_world, E.reset(small_world, other), T.Action.make(T.ASK, question=1)),
              T.Action.make(T.ASK, question=2))
    for name in ("color", "material", "size", "state", "on_category", "near_categories", "room_label", "region_category"):
        np.testing.assert_array_equal(np.asarray(getattr(a1.answers, name)), np.asarray(getattr(b1.answers, name)))


# ---------------------------------------------------------------------------
# the paper-reading settings
# ---------------------------------------------------------------------------


def test_upfront_description_is_given_and_charged_as_type1_plus_type2(small_benchmark, small_world):
    es = small_benchmark["set"]
    spec = _spec(es, 3)
    world = _world(small_world, upfront_description=True)
    st = E.reset(world, spec)
    np.testing.assert_array_equal(np.asarray(st.n_questions), [1, 1, 0, 0])
    np.testing.assert_array_equal(np.asarray(st.answers.known), [True, True, False, False])
    assert int(st.n_trace) == 0  # not a question the agent asked
    asked = E.reset(small_world, spec)
    asked = E.step(small_world, E.step(small_world, asked, T.Action.make(T.ASK, question=1)),
                   T.Action.make(T.ASK, question=2))
    for name in ("color", "material", "size", "state", "on_category", "near_categories", "room_label", "region_category"):
        np.testing.assert_array_equal(np.asarray(getattr(st.answers, name)), np.asarray(getattr(asked.answers, name)))
    obs = E.observe(world, st)
    assert int(obs.questions_left) == world.config.max_questions - 2
    # a no-question success is then worth exp(-(w1 + w2)) = 0.709: the paper's no-QA rows (WSR ~ 0.70 SR)
    disc = float(M.question_discount(np.asarray(st.n_questions), LOCKED_COSTS))
    assert disc == pytest.approx(math.exp(-(LOCKED_COSTS[0] + LOCKED_COSTS[1])))
    assert disc == pytest.approx(0.709, abs=1e-3)


@pytest.mark.slow  # about 2 minutes on a 2-core CPU (a rollout compiled for the unbudgeted protocol)
def test_unbudgeted_questions_are_never_refused(small_benchmark, small_world):
    es = small_benchmark["set"]
    spec = _spec(es, 1)
    ask = T.Action.make(T.ASK, question=3)
    for budget, charged, refused in ((True, 10, 2), (False, 12, 0)):
        world = _world(small_world, question_budget=budget)
        st = E.reset(world, spec)
        for _ in range(12):
            st = E.step(world, st, ask)
        assert int(np.sum(st.n_questions)) == charged and int(st.n_refused) == refused
        left = int(E.observe(world, st).questions_left)
        assert left == (0 if budget else world.config.max_steps - 12)


def test_sim_config_rejects_bad_protocol_values():
    for kw, key in (({"miss_rate": 1.5}, "sim.miss_rate"), ({"confusion_rate": -0.1}, "sim.confusion_rate"),
                    ({"upfront_description": 1}, "sim.upfront_description"), ({"question_budget": "no"}, "sim.question_budget"),
                    ({"collision_heights": (0.15, -1.0)}, "sim.collision_heights"), ({"image_size": (640,)}, "sim.image_size"),
                    ({"pullback": -0.1}, "sim.pullback"), ({"trace_len": 5}, "sim.trace_len")):
        with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
            T.SimConfig(**kw)
    with pytest.raises(ConfigError, match="unknown key"):
        T.SimConfig.from_values({"max_stepz": 3})
    assert T.SimConfig(max_steps=30).trace_slots == 30


# ---------------------------------------------------------------------------
# noisy perception
# ---------------------------------------------------------------------------


def _observations(world, es, key, n=6):
    obs = []
    step = jax.jit(E.step)
    for k in range(n):
        st = E.reset(world, _spec(es, k), key)
        for a in (T.Action.make(T.MOVE, 0, 4, 2), T.Action.make(T.MOVE, 2, 4, 2)):
            obs.append(E.observe(world, st))
            st = step(world, st, a)
    return jax.tree.map(lambda *x: np.stack(x), *obs)


def test_noisy_perception_is_seeded_and_only_removes_or_confuses(small_benchmark, small_world):
    es = small_benchmark["set"]
    clean = _observations(small_world, es, jax.random.key(0))
    zero = _observations(_world(small_world, miss_rate=0.0, confusion_rate=0.0), es, jax.random.key(5))
    chex.assert_trees_all_equal(clean, zero)  # rates 0: exactly the exact perception, whatever the key
    noisy_world = _world(small_world, miss_rate=0.6, confusion_rate=0.6)
    a = _observations(noisy_world, es, jax.random.key(1))
    b = _observations(noisy_world, es, jax.random.key(1))
    chex.assert_trees_all_equal(a, b)  # the same key gives the same bytes
    c = _observations(noisy_world, es, jax.random.key(2))
    assert not np.array_equal(a.visible_handle, c.visible_handle) or not np.array_equal(a.visible_attrs, c.visible_attrs)
    # detections are a subset of the exact ones; nothing else about the scene changes
    n_clean = n_noisy = confused = compared = 0
    for i in range(clean.visible_handle.shape[0]):
        exact = {int(h): j for j, h in enumerate(clean.visible_handle[i]) if h >= 0}
        seen = [int(h) for h in a.visible_handle[i] if h >= 0]
        assert set(seen) <= set(exact)
        n_clean += len(exact)
        n_noisy += len(seen)
        for j, h in enumerate(a.visible_handle[i]):
            if h < 0:
                continue
            ref = clean.visible_attrs[i, exact[int(h)]]
            got = a.visible_attrs[i, j]
            assert np.all((got >= 0) == (ref >= 0))  # an unknown attribute stays unknown
            confused += int(np.sum(got != ref))
            compared += int(np.sum(ref >= 0))
            assert a.visible_category[i, j] == clean.visible_category[i, exact[int(h)]]
    np.testing.assert_array_equal(a.free_space, clean.free_space)
    assert 0 < n_noisy < n_clean
    assert 0 < confused < compared


def test_misses_grow_with_distance_and_shrink_with_size(small_world):
    """The miss model on its own: many draws at two distances and two sizes."""
    from ignjax.sim.observation import perception_noise

    cfg = dataclasses.replace(small_world.config, miss_rate=0.3, confusion_rate=0.3)
    K = 4000
    idx = jnp.arange(K, dtype=jnp.int32)
    attrs = jnp.zeros((K, 4), jnp.int32)
    seen = jnp.ones(K, bool)
    key = E.noise_key(jax.random.key(3))
    pose = jnp.array([1.0, 2.0, 0.5], jnp.float32)

    def miss(d, size):
        s, a = perception_noise(cfg, key, pose, idx, jnp.full(K, d), jnp.full(K, size), seen, attrs)
        return 1 - float(jnp.mean(s)), float(jnp.mean(a != 0))

    near, far = miss(1.5, 0.5), miss(4.5, 0.5)
    big = miss(4.5, 1.5)
    assert near[0] == pytest.approx(0.15, abs=0.03) and far[0] == pytest.approx(0.45, abs=0.03)
    assert big[0] == pytest.approx(0.15, abs=0.03)
    assert near[1] < far[1] and big[1] < far[1]


@pytest.mark.slow  # about a minute on a 2-core CPU
def test_noisy_batch_observation_equals_observing_again(small_benchmark, small_world):
    """The batch step keeps a row's perception when it did not move: with the
    noise keyed on the (rounded) pose, that equals observing it again."""
    es = small_benchmark["set"]
    world = _world(small_world, miss_rate=0.5, confusion_rate=0.5)
    n = 8
    specs = jax.tree.map(lambda a: a[:n], es.specs)
    keys = jax.random.split(jax.random.key(4), n)
    states = jax.vmap(lambda s, k: E.reset(world, s, k))(specs, keys)
    obs = jax.vmap(lambda st: E.observe(world, st))(states)
    kinds = jnp.array([T.MOVE, T.ASK] * (n // 2), jnp.int32)
    for d in (0, 2, 6):
        actions = jax.vmap(lambda k: T.Action.make(k, d, 4, 2, 3))(kinds)
        states = E.step_batch(world, states, actions)
        obs = E.observe_batch(world, states, obs, kinds == T.MOVE)
        chex.assert_trees_all_equal(obs, jax.vmap(lambda st: E.observe(world, st))(states))
