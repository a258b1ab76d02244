"""The cost-aware agent's controller safeguards and its decision EIG, on
constructed observations (pure functions: no world needed), and the
no-QA-with-description baseline on the real simulator."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.agents import get_agent
from ignjax.agents.belief import belief, decision_eigs, default_belief_params, question_eigs
from ignjax.agents.memory import Memory, observe_memory
from ignjax.agents.policies import spatial_uncertainty
from ignjax.scenes import vocab
from ignjax.sim import types as T
from ignjax.sim.world import World


def _obs(free=2.0, room=0, steps_left=20, questions_left=10, visible=()):
    """An observation with ``free`` metres of free space in every view (or an (8,) array)."""
    K = 16
    free = np.broadcast_to(np.asarray(free, np.float32), (8,))
    handle = np.full(K, -1, np.int32)
    cat = np.full(K, -1, np.int32)
    rng = np.full(K, np.inf, np.float32)
    bearing = np.zeros(K, np.float32)
    attrs = np.full((K, 4), -1, np.int32)
    for k, (h, c, r, b, colour) in enumerate(visible):
        handle[k], cat[k], rng[k], bearing[k], attrs[k, 0] = h, c, r, b, colour
    return T.Observation(
        heading=jnp.float32(0.0), odometry=jnp.zeros(3, jnp.float32), free_space=jnp.asarray(np.repeat(free[:, None], 3, 1)),
        visible_handle=jnp.asarray(handle), visible_category=jnp.asarray(cat), visible_attrs=jnp.asarray(attrs),
        visible_range=jnp.asarray(rng), visible_bearing=jnp.asarray(bearing), visible_view=jnp.zeros(K, jnp.int32),
        room_label=jnp.int32(room), goal_category=jnp.int32(7), steps_left=jnp.int32(steps_left),
        questions_left=jnp.int32(questions_left), n_questions=jnp.zeros(4, jnp.int32), blocked=jnp.zeros(8, bool),
        last_move=jnp.float32(1.0))


def test_decision_eig_gives_an_unseen_room_label_no_value():
    """Before any candidate is seen, the goal room's label cannot change
    what the agent does: Eq. (1) on the full belief values it, the decision
    EIG does not. Once candidates are seen in rooms of different labels, it does."""
    params = default_belief_params()
    obs = _obs()
    answers = T.Answer.empty()
    mem = observe_memory(Memory.empty(), obs)
    b = belief(mem, params)
    exact, _ = question_eigs(mem, obs, answers, b)
    decided, _ = decision_eigs(mem, obs, answers, b)
    assert float(exact[1]) > 1.0 and float(decided[1]) < 1e-5
    np.testing.assert_allclose(np.asarray(decided)[[0, 2, 3]], np.asarray(exact)[[0, 2, 3]], atol=1e-6)
    # two candidates seen, standing in rooms with labels 0 and 3
    mem = observe_memory(mem, _obs(room=0, visible=[(5, 7, 2.0, 0.3, 1)]))
    mem = observe_memory(mem, _obs(room=3, visible=[(9, 7, 2.5, -0.4, 2)]))
    b = belief(mem, params)
    decided, _ = decision_eigs(mem, obs, answers, b)
    assert float(decided[1]) > 0.1


def test_route_questions_only_where_space_is_uncertain():
    mem = Memory.empty()
    answers = T.Answer.empty()
    room = _obs(free=[1.0, 0.8, 0.9, 0.7, 1.0, 0.8, 0.9, 0.7])  # a closed spot, nothing open
    assert not bool(spatial_uncertainty(observe_memory(mem, room), room, answers))
    hallway = vocab.ALL_ROOM_LABELS.index("hallway")
    branch = _obs(free=[3.0, 0.5, 3.0, 0.5, 3.0, 0.5, 0.5, 0.5], room=hallway)
    assert bool(spatial_uncertainty(observe_memory(mem, branch), branch, answers))
    corridor = _obs(free=[4.0, 0.9, 0.6, 0.9, 1.0, 0.9, 0.6, 0.9], room=hallway)
    assert bool(spatial_uncertainty(observe_memory(mem, corridor), corridor, answers))
    outside = _obs(free=[4.0, 0.9, 0.6, 0.9, 1.0, 0.9, 0.6, 0.9], room=-1)  # outside every room: a passage too
    assert bool(spatial_uncertainty(observe_memory(mem, outside), outside, answers))
    # the same geometry inside a closed room (a bedroom): the agent searches the room by itself
    for free in ([3.0, 0.5, 3.0, 0.5, 3.0, 0.5, 0.5, 0.5], [4.0, 0.9, 0.6, 0.9, 1.0, 0.9, 0.6, 0.9]):
        inside_room = _obs(free=free, room=0)
        assert not bool(spatial_uncertainty(observe_memory(mem, inside_room), inside_room, answers))
    loop = mem
    for _ in range(3):
        loop = observe_memory(loop, room)
    loop = dataclasses.replace(loop, t=jnp.int32(3))  # a MOVE (last_move 1 m) back to a spot seen at earlier decisions
    assert bool(spatial_uncertainty(loop, room, answers))
    # standing on the spot while asking is no loop
    assert not bool(spatial_uncertainty(dataclasses.replace(loop, last_asked=jnp.int32(1)), room, answers))
    # goal room known (label 4), standing in a room labelled 0, no candidate seen there: the entry is unclear
    told = dataclasses.replace(answers, known=answers.known.at[1].set(True), room_label=jnp.int32(4))
    assert bool(spatial_uncertainty(observe_memory(mem, room), room, told))
    inside = _obs(free=[1.0, 0.8, 0.9, 0.7, 1.0, 0.8, 0.9, 0.7], room=4)
    assert not bool(spatial_uncertainty(observe_memory(mem, inside), inside, told))


def test_gate_and_recovery_decide_the_route_question():
    """With the gate, the EIG agent does not ask Type 3 in a closed spot;
    after ``recovery_steps`` decisions without a plausible candidate and no
    route answer it asks Type 3 anyway (in a passage at once, inside a
    closed room after twice as many decisions), unless the costs make even
    the lowered bar unreachable; both can be switched off."""
    eig = get_agent("eig")
    closed = [1.0, 0.8, 0.9, 0.7, 1.0, 0.8, 0.9, 0.7]
    room = _obs(free=closed)
    hall = _obs(free=closed, room=vocab.ALL_ROOM_LABELS.index("hallway"))
    answers = T.Answer.empty()
    key = jax.random.key(0)

    def act(params, t, obs=room):
        mem = dataclasses.replace(eig.init(params, obs, key), t=jnp.int32(t))
        a, _ = eig.act(params, obs, answers, mem, key, None)
        return int(a.kind), int(a.question)

    base = eig.default_params()
    assert act(base, 1) != (T.ASK, 3)
    assert act(base, 6, hall) == (T.ASK, 3)  # recovery in a passage
    assert act(base, 6) != (T.ASK, 3)  # inside a closed room it waits
    assert act(base, 12) == (T.ASK, 3)  # ... for recovery_steps more decisions
    assert act(dataclasses.replace(base, recovery_steps=jnp.float32(0.0)), 12) != (T.ASK, 3)
    assert act(dataclasses.replace(base, costs=base.costs * 8.0), 12, hall) != (T.ASK, 3)  # too dear even so
    open_gate = dataclasses.replace(base, type3_gate=jnp.array(False), threshold=jnp.float32(0.1))
    assert act(open_gate, 1) == (T.ASK, 3)


def test_described_agent_never_asks_and_uses_the_description(small_benchmark, small_world):
    from ignjax.evaluate.runner import run_agent

    es = small_benchmark["set"]
    world = World(small_world.bank, small_world.fields, dataclasses.replace(small_world.config, upfront_description=True))
    out, traj = run_agent(es, "described", batch=len(es), world=world, parts=1)
    assert not np.any(traj.kind == T.ASK)
    np.testing.assert_array_equal(out.n_questions, np.tile([1, 1, 0, 0], (len(es), 1)))  # the description's charge
    # the description is folded into the belief at the first decision: a candidate of another colour is unlikely
    agent = get_agent("described")
    params = agent.default_params()
    answers = dataclasses.replace(T.Answer.empty(), known=jnp.array([True, False, False, False]), color=jnp.int32(1))
    obs = _obs(visible=[(5, 7, 2.0, 0.3, 1), (9, 7, 2.0, -0.3, 2)])
    mem = agent.init(params, obs, jax.random.key(0))
    _, mem = agent.act(params, obs, answers, mem, jax.random.key(0), None)
    b = np.asarray(belief(mem, params))
    slot = {int(h): i for i, h in enumerate(np.asarray(mem.handle)) if h >= 0}
    assert b[slot[5]] > 10 * b[slot[9]]
    assert bool(mem.consumed[0])


def test_type1_and_type2_only_while_the_fact_is_missing():
    """Safeguard 1: once the Type-1 / Type-2 answer is known it is worth
    nothing (cached); with ``cache_facts`` off the answer model still
    values it, so the agent may ask again."""
    params = default_belief_params()
    obs = _obs(visible=[(5, 7, 2.0, 0.3, 1), (9, 7, 2.5, -0.4, 2)])
    mem = observe_memory(Memory.empty(), obs)
    b = belief(mem, params)
    told = dataclasses.replace(T.Answer.empty(), known=jnp.array([True, False, False, False]), color=jnp.int32(1))
    fresh, _ = question_eigs(mem, obs, T.Answer.empty(), b)
    cached, _ = question_eigs(mem, obs, told, b)
    uncached, _ = question_eigs(mem, obs, told, b, cached=False)
    assert float(fresh[0]) > 0.3
    assert float(cached[0]) == 0.0 and float(uncached[0]) == float(fresh[0])


def test_type1_answer_checks_every_said_attribute():
    """A Type-1 answer rules out a candidate seen with another value of any
    attribute it says (colour, material, size or state), not only colour."""
    agent = get_agent("eig")
    params = agent.default_params()
    obs = _obs(visible=[(5, 7, 2.0, 0.3, 1), (9, 7, 2.0, -0.3, 1)])  # same colour
    attrs = np.asarray(obs.visible_attrs).copy()
    attrs[0, 1], attrs[1, 1] = 0, 1  # materials differ
    obs = dataclasses.replace(obs, visible_attrs=jnp.asarray(attrs))
    answers = dataclasses.replace(T.Answer.empty(), known=jnp.array([True, False, False, False]), color=jnp.int32(1),
                                  material=jnp.int32(1))
    mem = agent.init(params, obs, jax.random.key(0))
    _, mem = agent.act(params, obs, answers, mem, jax.random.key(0), None)
    b = np.asarray(belief(mem, params))
    slot = {int(h): i for i, h in enumerate(np.asarray(mem.handle)) if h >= 0}
    assert b[slot[9]] > 100 * b[slot[5]]
