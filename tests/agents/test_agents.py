"""The built-in agents on the shared small benchmark: the privileged upper
bound far above chance, the cost-aware agent asking less as its charged
costs rise and beating the free asker on WSR, determinism of the asking
agents, and privileged information reaching only the privileged agent.

Every rollout uses the whole 40-episode set as one batch (one compiled
shape per agent) with the per-episode keys of :func:`ignjax.sim.rollout.episode_keys`.
"""

from __future__ import annotations

import dataclasses
import math
from functools import partial

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.agents import Agent, get_agent, registry
from ignjax.agents import belief as B
from ignjax.agents.memory import N_ROOM_LABELS, Memory, candidate_relative, observe_memory, visit_index
from ignjax.evaluate import metrics as M
from ignjax.evaluate.runner import run_agent
from ignjax.protocol import CONFIRM_RANGE, LOCKED_COSTS
from ignjax.sim import env as E
from ignjax.sim import types as T
from ignjax.sim.rollout import (
    ROLLOUT_COMPILER_OPTIONS, episode_keys, pad_specs, rollout, rollout_episode, rollout_rows, rollout_sweep,
)
from ignjax.sim.types import Privileged

SEED = 0
SCALES = (0.25, 1.0, 4.0)  # the EIG agent's charged costs: locked costs x these


def _batch(es):
    """Specs and keys of every episode, as one batch (padded rows would be masked out)."""
    n = len(es)
    return pad_specs(es.specs, n), episode_keys(SEED, np.arange(n))


def _row(out) -> dict:
    return M.metric_row(out)  # the rollout's OutcomeRow is what the metrics take


@pytest.fixture(scope="module")
def runs(small_benchmark, small_world):
    """Outcomes (numpy) of random, shortest_path and naive_asker, and the EIG
    agent under three charged cost vectors in one vmapped call."""
    es = small_benchmark["set"]
    specs, keys = _batch(es)
    res = {}
    for name in ("random", "shortest_path", "naive_asker"):
        agent = get_agent(name)
        res[name] = jax.tree.map(np.asarray, rollout(small_world, specs, agent, agent.default_params(), keys))
    eig = get_agent("eig")
    base = eig.default_params()
    K = len(SCALES)
    params = jax.tree.map(lambda x: jnp.broadcast_to(x, (K,) + jnp.shape(x)), base)
    costs = jnp.asarray(LOCKED_COSTS, jnp.float32)[None] * jnp.asarray(SCALES, jnp.float32)[:, None]
    params = dataclasses.replace(params, costs=costs)
    res["eig_sweep"] = jax.tree.map(np.asarray, rollout_sweep(small_world, specs, eig, params, keys))
    res["eig_params"] = params
    return res


def _sweep_row(runs, k):
    """(outcomes, trajectory) of row k of the EIG cost sweep."""
    return jax.tree.map(lambda a: a[k], runs["eig_sweep"])


def test_privileged_shortest_path_far_above_random(runs):
    sp, rnd = _row(runs["shortest_path"][0]), _row(runs["random"][0])
    assert sp["episodes"] == rnd["episodes"] == 40
    assert sp["SR@1.5"] >= rnd["SR@1.5"] + 50, (sp["SR@1.5"], rnd["SR@1.5"])
    assert sp["|Q|"] == 0 and rnd["|Q|"] == 0  # neither asks


def test_eig_asks_less_as_charged_costs_rise(runs):
    out, traj = runs["eig_sweep"]
    q = np.asarray(out.n_questions).sum(-1).mean(-1)  # (K,) mean |Q| per episode
    assert np.all(np.diff(q) <= 0), dict(zip(SCALES, q))
    assert q[-1] < q[0], dict(zip(SCALES, q))
    # every charged question is an ASK step of its type in the trajectory (refused ones are not charged)
    asked = np.stack([((np.asarray(traj.kind) == T.ASK) & (np.asarray(traj.question) == t)).sum(-1)
                      for t in range(1, 5)], -1)
    assert np.all(asked >= np.asarray(out.n_questions))


def test_eig_beats_naive_asker_on_wsr(runs):
    eig = _row(_sweep_row(runs, SCALES.index(1.0))[0])  # the sweep's x1 row: the EIG agent at the locked costs
    naive = _row(runs["naive_asker"][0])
    assert eig["WSR@1.5"] > naive["WSR@1.5"], (eig["WSR@1.5"], naive["WSR@1.5"])


def test_asking_agents_are_deterministic(small_benchmark, small_world, runs):
    """Same keys, same outcomes and trajectories: again through the same
    compiled call, and through :func:`run_agent` (same batch shape, so no
    new compile); other keys give other trajectories."""
    es = small_benchmark["set"]
    specs, keys = _batch(es)
    eig = get_agent("eig")
    again = jax.tree.map(np.asarray, rollout_sweep(small_world, specs, eig, runs["eig_params"], keys))
    chex.assert_trees_all_equal(again, runs["eig_sweep"])
    naive = run_agent(es, "naive_asker", batch=len(es), seed=SEED, world=small_world)
    chex.assert_trees_all_equal(naive, runs["naive_asker"])
    other = run_agent(es, "naive_asker", batch=len(es), seed=SEED + 1, world=small_world)
    assert not np.array_equal(other[1].pose, runs["naive_asker"][1].pose)


def test_only_the_privileged_agent_receives_privileged_information(small_benchmark, small_world):
    """The registry's flag, and what ``act`` is actually handed during a
    rollout (traced with ``eval_shape``: no compile)."""
    reg = registry()
    assert {n for n, a in reg.items() if a.privileged} == {"shortest_path"}
    es = small_benchmark["set"]
    spec = jax.tree.map(lambda a: a[0], es.specs)
    for name, agent in reg.items():
        seen = []

        def act(params, obs, answers, pstate, key, priv, _act=agent.act, _seen=seen):
            _seen.append(priv)
            return _act(params, obs, answers, pstate, key, priv)

        spy = Agent(name, agent.init, act, agent.default_params, agent.privileged, agent.asks, agent.description)
        jax.eval_shape(lambda k, spy=spy: rollout_episode(small_world, spec, spy, spy.default_params(), k)[:2],
                       jax.random.key(0))
        assert seen, name
        if agent.privileged:
            assert all(isinstance(p, Privileged) for p in seen), name
        else:
            assert all(p is None for p in seen), name


def _reference_likelihoods(mem, obs):
    """The EIG agent's answer models as explicit (A, hypotheses) likelihood
    matrices (see :mod:`ignjax.agents.belief`), for one episode."""
    L_, N_ = N_ROOM_LABELS, B.N_ATTR_ANSWERS
    U = L_ * 8
    M_ = mem.handle.shape[0]
    valid = (mem.handle >= 0) & ~mem.rejected
    # Type 1: one answer row per distinct observed attribute combination (its first slot), then every other
    # combination lumped into one row (each of them leaves the same posterior, so the EIG is unchanged)
    known = jnp.any(mem.attrs >= 0, axis=1)
    same = jnp.all(mem.attrs[:, None] == mem.attrs[None], axis=-1) & known[:, None] & known[None]
    first = known & ~jnp.any(same & (jnp.arange(M_)[None] < jnp.arange(M_)[:, None]), axis=1)
    G = jnp.sum(first)
    rows = jnp.where(first[:, None], jnp.where(known[None], same.astype(jnp.float32), 1.0 / N_), 0.0)
    rows = jnp.concatenate([rows, jnp.where(first[:, None], 1.0 / N_, 0.0) * jnp.ones((1, U))], axis=1)
    other = jnp.concatenate([jnp.where(known, 0.0, (N_ - G) / N_), jnp.full(U, 1.0) * (N_ - G) / N_])
    L1 = jnp.concatenate([rows, other[None]], axis=0)
    L2 = jnp.concatenate([jnp.where(mem.room[None] >= 0, (jnp.arange(L_)[:, None] == mem.room[None]).astype(jnp.float32),
                                    1.0 / L_),
                          (jnp.arange(L_)[:, None] == jnp.repeat(jnp.arange(L_), 8)[None]).astype(jnp.float32)], axis=1)
    dist, bearing = candidate_relative(mem, obs)
    cs = (jnp.round(bearing / (math.pi / 4)).astype(jnp.int32)) % 8
    u_rel = jnp.tile(B._abs_sector(obs), L_)
    a = jnp.arange(8)[:, None]
    L3 = jnp.concatenate([B._sector_likelihood(a, cs[None]), B._sector_likelihood(a, u_rel[None])], axis=1)
    L3 = L3 / L3.sum(0, keepdims=True)
    in_front = valid & (dist <= CONFIRM_RANGE) & (jnp.abs(bearing) <= math.pi / 4) \
        & jnp.isin(mem.handle, obs.visible_handle)
    return (L1, L2, L3), in_front


def test_question_eigs_equal_eq1_on_explicit_answer_models(small_benchmark, small_world):
    """The agent's structured EIG per question type equals Eq. (1),
    H[b] - E_a H[b | a], evaluated directly on the explicit likelihood
    matrices of its answer models, along real rollouts."""
    es = small_benchmark["set"]
    specs, keys = _batch(es)
    agent = get_agent("eig")
    params = agent.default_params()
    observe = jax.jit(jax.vmap(lambda st: E.observe(small_world, st)))
    state = jax.jit(jax.vmap(lambda s: E.reset(small_world, s)))(specs)
    obs = observe(state)
    pst = jax.jit(jax.vmap(lambda o, k: agent.init(params, o, k)))(obs, keys)
    act = jax.jit(jax.vmap(lambda o, a, p, k: agent.act(params, o, a, p, k, None)))
    step = jax.jit(jax.vmap(lambda st, a: E.step(small_world, st, a)))

    def check(o, ans, mem):
        mem, b = B.update_belief(params, o, ans, mem)
        got, slot = B.question_eigs(mem, o, ans, b)
        (L1, L2, L3), in_front = _reference_likelihoods(mem, o)
        M_ = mem.handle.shape[0]
        yes = jnp.concatenate([(jnp.arange(M_) == slot).astype(jnp.float32), jnp.zeros(b.shape[0] - M_)])
        L4 = jnp.stack([yes, 1.0 - yes])
        ref = jnp.stack([B.expected_information_gain(b, L) for L in (L1, L2, L3, L4)])
        ref = ref * jnp.stack([~ans.known[0], ~ans.known[1], jnp.array(True), jnp.any(in_front)])
        return got, jnp.maximum(ref, 0.0), slot, jnp.where(jnp.any(in_front), jnp.argmax(jnp.where(in_front, b[:M_], -1.0)), -1)

    check = jax.jit(jax.vmap(check))
    n_positive = 0
    for _ in range(8):
        got, ref, slot, ref_slot = (np.asarray(x) for x in check(obs, state.answers, pst))
        np.testing.assert_allclose(got, ref, atol=2e-5)
        np.testing.assert_array_equal(slot, ref_slot)
        n_positive += int((ref > 1e-3).sum())
        a, pst = act(obs, state.answers, pst, keys)
        state = step(state, a)
        obs = observe(state)
    assert n_positive > 50  # the comparison saw informative questions


def _rows_matching(got, want) -> np.ndarray:
    """(E,) bool: episodes whose discrete fields are equal and continuous ones
    equal to float32 rounding, over every leaf of (outcome, trajectory)."""
    ok = None
    for a, b in zip(jax.tree.leaves(got), jax.tree.leaves(want)):
        a, b = np.asarray(a), np.asarray(b)
        if a.dtype.kind == "f":
            same = np.isclose(a, b, atol=1e-4, rtol=1e-5) | (np.isinf(a) & (a == b))
        else:
            same = a == b
        same = same.reshape(a.shape[0], -1).all(1)
        ok = same if ok is None else ok & same
    return ok


def _one_program(agents: list[Agent]) -> Agent:
    """One agent that acts as ``agents[i]`` where its parameters are
    ``(i, (every agent's parameters))``: every agent's state is carried and
    the selected one's ``act`` is applied (``lax.switch``), so one compiled
    reference program (one copy of the simulator) serves them all; the
    privileged information reaches the privileged agent only."""

    def init(params, obs, key):
        return tuple(a.init(p, obs, key) for a, p in zip(agents, params[1]))

    def act(params, obs, answers, pstate, key, priv):
        i, ps = params

        def branch(j):
            def run(_):
                a = agents[j]
                action, new = a.act(ps[j], obs, answers, pstate[j], key, priv if a.privileged else None)
                action = jax.tree.map(lambda x: jnp.asarray(x, jnp.int32), action)
                return action, tuple(new if k == j else pstate[k] for k in range(len(agents)))
            return run

        return jax.lax.switch(i, [branch(j) for j in range(len(agents))], None)

    return Agent("one_program", init, act, lambda: None, privileged=any(a.privileged for a in agents))


def _params_of(name, runs):
    """The parameters the batch rollout of ``name`` ran with (eig: the cost sweep's x1 row)."""
    if name == "eig":
        return jax.tree.map(lambda a: a[SCALES.index(1.0)], runs["eig_params"])
    return get_agent(name).default_params()


@pytest.fixture(scope="module")
def references(small_benchmark, small_world, runs):
    """Every registered agent's episodes through the one-episode reference
    ``rollout_episode`` under vmap, compiled with the rollout's options, as
    one program (:func:`_one_program`): {name: (outcomes, trajectory)}."""
    es = small_benchmark["set"]
    specs, keys = _batch(es)
    names = sorted(registry())
    n = keys.shape[0]
    multi = _one_program([get_agent(a) for a in names])
    every = tuple(_params_of(a, runs) for a in names)
    rows = np.repeat(np.arange(len(names)), n)
    params = (jnp.asarray(rows, jnp.int32),
              jax.tree.map(lambda x: jnp.broadcast_to(x, (rows.size,) + jnp.shape(x)), every))
    tile = np.tile(np.arange(n), len(names))
    ref = jax.jit(jax.vmap(lambda p, s, key: rollout_episode(small_world, s, multi, p, key)[:2]),
                  compiler_options=ROLLOUT_COMPILER_OPTIONS)(params, jax.tree.map(lambda a: a[tile], specs), keys[tile])
    ref = jax.tree.map(np.asarray, ref)
    return {a: jax.tree.map(lambda x: x[j * n:(j + 1) * n], ref) for j, a in enumerate(names)}


@pytest.mark.parametrize("name", sorted(registry()))
def test_batched_rollout_equals_one_episode_rollout(small_benchmark, small_world, runs, references, name):
    """The batch rollout (executor for the movers only, oracle for the askers
    only, nothing for finished rows; rollout_sweep's K x E rows) gives row for
    row what the one-episode reference ``rollout_episode`` gives under vmap,
    compiled with the same options. Vectorising over other widths changes the
    last bits of float32 results, and the protocol's thresholds (waypoint
    reached, heading free, EIG / cost above the threshold) can turn that into
    another decision in a rare episode, so up to 1 in 20 episodes may differ;
    a change of behaviour would show in most of them. Every agent of the
    registry; the module's runs where they exist."""
    es = small_benchmark["set"]
    specs, keys = _batch(es)
    agent = get_agent(name)
    if name == "eig":
        got = _sweep_row(runs, SCALES.index(1.0))
    else:
        got = runs[name] if name in runs else jax.tree.map(
            np.asarray, rollout(small_world, specs, agent, _params_of(name, runs), keys))
    same = _rows_matching(got, references[name])
    assert same.mean() >= 0.95, f"{name}: {int((~same).sum())} of {same.size} episodes differ: {np.flatnonzero(~same)}"


def test_one_program_reference_is_each_agents_own(small_benchmark, small_world, references):
    """The combined reference program runs each agent as its own reference
    would: checked against ``rollout_episode`` of one agent alone (the cheapest), exactly."""
    es = small_benchmark["set"]
    specs, keys = _batch(es)
    agent = get_agent("random")
    alone = jax.jit(jax.vmap(lambda s, key: rollout_episode(small_world, s, agent, agent.default_params(), key)[:2]),
                    compiler_options=ROLLOUT_COMPILER_OPTIONS)(specs, keys)
    same = _rows_matching(jax.tree.map(np.asarray, alone), references["random"])
    assert same.all(), np.flatnonzero(~same)


def test_sweep_simulates_each_distinct_trajectory_once_with_the_same_result(small_benchmark, small_world, runs):
    """rollout_sweep simulates the settings of an episode that act alike once
    (group mode); the result equals every row simulated on its own, exactly
    (same chunk width in both, so the same vectorised code runs per row)."""
    es = small_benchmark["set"]
    specs, keys = _batch(es)
    eig, params = get_agent("eig"), runs["eig_params"]
    n, K = specs.scene.shape[0], len(SCALES)

    @partial(jax.jit, compiler_options=ROLLOUT_COMPILER_OPTIONS)
    def each_row(specs, params, keys):
        tile = jnp.tile(jnp.arange(n), K)
        rows = jax.tree.map(lambda x: jnp.repeat(x, n, axis=0), params)
        out = rollout_rows(small_world, jax.tree.map(lambda a: a[tile], specs), eig, rows, keys[tile], 8)[:2]
        return jax.tree.map(lambda a: a.reshape((K, n) + a.shape[1:]), out)

    want = jax.tree.map(np.asarray, each_row(specs, params, keys))
    got = jax.tree.map(np.asarray, rollout_sweep(small_world, specs, eig, params, keys, chunk=8))
    chex.assert_trees_all_equal(got, want)
    # the settings do share work: in most episodes two settings take the same first actions
    first = want[1].kind[:, :, :2] * 5 + want[1].question[:, :, :2]
    shared = np.any([np.all(first[i] == first[j], axis=1) for i in range(K) for j in range(i)], axis=0)
    assert shared.mean() > 0.5, shared.mean()


def test_visit_counts_saturate_instead_of_wrapping(small_benchmark, small_world):
    spec = jax.tree.map(lambda a: a[0], small_benchmark["set"].specs)
    obs = jax.jit(lambda sp: E.observe(small_world, E.reset(small_world, sp)))(spec)
    ij = np.asarray(visit_index(obs.odometry[:2]))
    mem = Memory.empty()
    once = observe_memory(mem, obs)
    assert int(once.visits[ij[1], ij[0]]) == 1 and int(once.visits.sum()) == 1
    full = dataclasses.replace(mem, visits=mem.visits.at[ij[1], ij[0]].set(254))
    for _ in range(2):
        full = observe_memory(full, obs)
    assert int(full.visits[ij[1], ij[0]]) == 255


def test_rollout_on_one_device_gives_each_episode_the_same_result(small_benchmark, small_world, runs):
    """The rollouts above are sharded over every device (two in the test
    session); on one device each episode's result is the same, exactly, and
    repeats exactly."""
    es = small_benchmark["set"]
    specs, keys = _batch(es)
    agent = get_agent("naive_asker")
    got = jax.tree.map(np.asarray, rollout(small_world, specs, agent, agent.default_params(), keys, parts=1))
    again = jax.tree.map(np.asarray, rollout(small_world, specs, agent, agent.default_params(), keys, parts=1))
    chex.assert_trees_all_equal(got, again)
    chex.assert_trees_all_equal(got, runs["naive_asker"])
