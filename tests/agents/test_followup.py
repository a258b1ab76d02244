"""The Type-4 follow-up of the asking agents (paper §3.3 and the controller
safeguards): a yes at about 2.5 m gives exactly one MOVE toward the
confirmed instance and then STOP; a yes inside the stop radius gives STOP
at once. Built on real worlds and the real simulator."""

from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.agents import get_agent
from ignjax.sim import env as E
from ignjax.sim import oracle as O
from ignjax.sim import queries as Q
from ignjax.sim import types as T


def _facing_pose(world, es, k, distance, fns):
    """A navigable pose ``distance`` metres (Euclidean, to the footprint) from
    episode k's target, facing it with the target in sight of the oracle and
    of the agent; None if none."""
    spec = jax.tree.map(lambda a: a[k], es.specs)
    s, t = int(spec.scene), int(spec.target)
    c = np.asarray(world.bank.instances.center[s, t, :2])
    ang, r = np.meshgrid(np.linspace(0, 2 * math.pi, 48, endpoint=False), np.linspace(0.3, 4.0, 75))
    xy = c + np.stack([r.ravel() * np.cos(ang.ravel()), r.ravel() * np.sin(ang.ravel())], -1)
    poses = np.concatenate([xy, np.arctan2(c[1] - xy[:, 1:2], c[0] - xy[:, 0:1])], -1).astype(np.float32)
    dist, front = fns["probe"](spec, jnp.asarray(poses))
    grid = es.bank.navgrids[s]
    rc = grid.world_to_cell(xy)
    inside = (rc[:, 0] >= 0) & (rc[:, 0] < grid.navigable.shape[0]) & (rc[:, 1] >= 0) & (rc[:, 1] < grid.navigable.shape[1])
    nav = np.zeros(len(xy), bool)
    nav[inside] = grid.navigable[rc[inside, 0], rc[inside, 1]]
    for i in np.flatnonzero(nav & np.asarray(front) & (np.abs(np.asarray(dist) - distance) <= 0.08)):
        out = dataclasses.replace(spec, start=jnp.asarray(poses[i]))
        if t in np.asarray(fns["observe"](world, fns["reset"](world, out)).visible_handle):  # the agent sees it too
            return out
    return None


def _confirmed(world, agent, spec, fns):
    """State, observation and agent memory right after the agent asked Type 4
    about the target and the oracle said yes."""
    params = agent.default_params()
    st = fns["reset"](world, spec)
    obs = fns["observe"](world, st)
    mem = agent.init(params, obs, jax.random.key(0))
    slot = int(np.flatnonzero(np.asarray(mem.handle) == int(spec.target))[0])
    mem = dataclasses.replace(mem, last_asked=jnp.int32(4), asked_about=jnp.int32(slot))
    st = fns["step"](world, st, T.Action.make(T.ASK, question=4, candidate=int(spec.target)))
    assert int(st.answers.confirm) == 1
    return params, st, fns["observe"](world, st), mem


@pytest.fixture(scope="module")
def fns(small_world):
    def probe(spec, poses):
        one = lambda p: (Q.euclidean_to_target(small_world, spec, p[:2]), O.target_visible_front(small_world, spec, p))  # noqa: E731
        return jax.vmap(one)(poses)

    return {"step": jax.jit(E.step), "observe": jax.jit(E.observe), "reset": jax.jit(E.reset), "probe": jax.jit(probe),
            "act": {name: jax.jit(get_agent(name).act) for name in ("eig", "naive_asker")}}


@pytest.fixture(scope="module")
def poses(small_benchmark, small_world, fns):
    es = small_benchmark["set"]
    far = near = None
    for k in range(len(es)):
        far = far or _facing_pose(small_world, es, k, 2.5, fns)
        near = near or _facing_pose(small_world, es, k, 0.6, fns)
        if far is not None and near is not None:
            break
    assert far is not None and near is not None
    return {"far": far, "near": near}


@pytest.mark.parametrize("name", ["eig", "naive_asker"])
def test_yes_at_2_5_m_gives_one_closer_move_then_stop(small_world, poses, fns, name):
    agent = get_agent(name)
    act_fn = fns["act"][name]
    spec = poses["far"]
    params, st, obs, mem = _confirmed(small_world, agent, spec, fns)
    assert float(Q.geodesic_to_target(small_world, spec, st.pose[:2])) > small_world.config.stop_radius
    assert int(st.answers.follow_up) == T.FOLLOW_ONE_MOVE
    act, mem = act_fn(params, obs, st.answers, mem, jax.random.key(1), None)
    assert int(act.kind) == T.MOVE
    assert int(act.direction) in (0, 1, 7)  # toward the confirmed instance, which is straight ahead
    before = float(Q.euclidean_to_target(small_world, spec, st.pose[:2]))
    st = fns["step"](small_world, st, act)
    assert float(Q.euclidean_to_target(small_world, spec, st.pose[:2])) < before  # closer
    assert int(st.answers.follow_up) == T.FOLLOW_STOP_NOW
    act, _ = act_fn(params, fns["observe"](small_world, st), st.answers, mem, jax.random.key(2), None)
    assert int(act.kind) == T.STOP


@pytest.mark.parametrize("name", ["eig", "naive_asker"])
def test_yes_inside_the_stop_radius_stops_at_once(small_world, poses, fns, name):
    agent = get_agent(name)
    spec = poses["near"]
    params, st, obs, mem = _confirmed(small_world, agent, spec, fns)
    assert int(st.answers.follow_up) == T.FOLLOW_STOP_NOW
    act, _ = fns["act"][name](params, obs, st.answers, mem, jax.random.key(1), None)
    assert int(act.kind) == T.STOP


def test_no_confirmation_no_follow_up(small_world, poses, fns):
    """A "no" starts nothing: the agent does not stop because of it."""
    agent = get_agent("eig")
    spec = poses["far"]
    params = agent.default_params()
    st = fns["reset"](small_world, spec)
    mem = agent.init(params, fns["observe"](small_world, st), jax.random.key(0))
    st = fns["step"](small_world, st, T.Action.make(T.ASK, question=4, candidate=int(spec.target) + 1))
    assert int(st.answers.confirm) == 0 and int(st.answers.follow_up) == T.FOLLOW_NONE
    mem = dataclasses.replace(mem, last_asked=jnp.int32(4), asked_about=jnp.int32(-1))
    act, mem = fns["act"]["eig"](params, fns["observe"](small_world, st), st.answers, mem, jax.random.key(1), None)
    assert not bool(mem.pending_stop)


def test_follow_up_can_be_switched_off(small_world, poses, fns):
    """Safeguard 3 off: a yes is evidence for the belief, not a stop order."""
    agent = get_agent("eig")
    params, st, obs, mem = _confirmed(small_world, agent, poses["far"], fns)
    params = dataclasses.replace(params, follow_up=jnp.array(False))
    _, mem = fns["act"]["eig"](params, obs, st.answers, mem, jax.random.key(1), None)
    assert not bool(mem.pending_stop)
