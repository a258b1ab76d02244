"""Candidate memory and the Type-1 / Type-2 facts: the facts weigh a
candidate by what memory holds about it now (every room label it was seen
from within 3 m), not by what it held when the candidate was first seen."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.agents import get_agent
from ignjax.agents.belief import belief
from ignjax.agents.memory import ROOM_MISMATCH_LOGLIK, Memory, fact_loglik, observe_memory
from ignjax.sim import types as T

GOAL_LABEL = 3  # the description's goal room label
HALL_LABEL = 0  # the room next to it


def _obs(room=0, visible=()):
    """An observation at the odometry origin, 2 m free in every view, standing in a room of label ``room``;
    ``visible``: (handle, category, range, bearing, colour) of each instance in sight (goal category 7)."""
    K = 16
    handle, cat = np.full(K, -1, np.int32), np.full(K, -1, np.int32)
    rng, bearing, attrs = np.full(K, np.inf, np.float32), np.zeros(K, np.float32), np.full((K, 4), -1, np.int32)
    for k, (h, c, r, b, colour) in enumerate(visible):
        handle[k], cat[k], rng[k], bearing[k], attrs[k, 0] = h, c, r, b, colour
    return T.Observation(
        heading=jnp.float32(0.0), odometry=jnp.zeros(3, jnp.float32), free_space=jnp.full((8, 3), 2.0, jnp.float32),
        visible_handle=jnp.asarray(handle), visible_category=jnp.asarray(cat), visible_attrs=jnp.asarray(attrs),
        visible_range=jnp.asarray(rng), visible_bearing=jnp.asarray(bearing), visible_view=jnp.zeros(K, jnp.int32),
        room_label=jnp.int32(room), goal_category=jnp.int32(7), steps_left=jnp.int32(20),
        questions_left=jnp.int32(10), n_questions=jnp.zeros(4, jnp.int32), blocked=jnp.zeros(8, bool),
        last_move=jnp.float32(1.0))


def _told_room():
    """The Type-2 fact known (as the upfront description gives it at reset)."""
    return dataclasses.replace(T.Answer.empty(), known=jnp.array([False, True, False, False]),
                               room_label=jnp.int32(GOAL_LABEL))


def _slots(mem):
    return {int(h): i for i, h in enumerate(np.asarray(mem.handle)) if h >= 0}


def test_a_doorway_sighting_is_corrected_from_inside_the_room():
    """The target (5) is first seen at 2.5 m through a doorway while the agent
    stands in the hall; a distractor (9) is seen from inside the goal room.
    Once the agent stands inside and sees 5 at 1 m, 5 carries the goal room's
    label and no Type-2 penalty: it is as likely as the distractor, where a
    label fixed at the first sighting kept it e^4 times less likely."""
    agent = get_agent("described")
    params = agent.default_params()
    told, key = _told_room(), jax.random.key(0)
    mem = agent.init(params, _obs(room=HALL_LABEL), key)
    _, mem = agent.act(params, _obs(room=HALL_LABEL, visible=[(5, 7, 2.5, 0.2, 1)]), told, mem, key, None)
    s = _slots(mem)
    assert int(mem.room[s[5]]) == HALL_LABEL
    assert float(fact_loglik(mem)[s[5]]) == ROOM_MISMATCH_LOGLIK  # the doorway view: evidence against
    _, mem = agent.act(params, _obs(room=GOAL_LABEL, visible=[(5, 7, 1.0, 0.2, 1), (9, 7, 2.0, -0.5, 1)]), told, mem,
                       key, None)
    s = _slots(mem)
    assert int(mem.room[s[5]]) == GOAL_LABEL and float(mem.room_range[s[5]]) == 1.0
    assert float(fact_loglik(mem)[s[5]]) == 0.0
    b = np.asarray(belief(mem, params))
    np.testing.assert_allclose(b[s[5]], b[s[9]], rtol=1e-6)


def test_a_sighting_from_the_goal_room_clears_the_room_penalty():
    """The room label of the nearest sighting is kept (the Type-2 answer
    model), but the Type-2 fact is weighed on every label the agent stood in
    when it saw the candidate within 3 m: seen at 2.5 m from inside the goal
    room and at 1 m from the hall (an object by a doorway or an opening), the
    candidate is consistent with the goal room; seen only from the hall, it
    is not; beyond 3 m a sighting says nothing about its room."""
    goal = jnp.asarray([-1, -1, -1, -1, GOAL_LABEL], jnp.int32)
    both = observe_memory(Memory.empty(), _obs(room=GOAL_LABEL, visible=[(5, 7, 2.5, 0.0, 1)]))
    both = dataclasses.replace(observe_memory(both, _obs(room=HALL_LABEL, visible=[(5, 7, 1.0, 0.0, 1)])), facts=goal)
    hall = dataclasses.replace(observe_memory(Memory.empty(), _obs(room=HALL_LABEL, visible=[(5, 7, 1.0, 0.0, 1)])),
                               facts=goal)
    far = dataclasses.replace(observe_memory(Memory.empty(), _obs(room=HALL_LABEL, visible=[(5, 7, 3.5, 0.0, 1)])),
                              facts=goal)
    assert int(both.room[_slots(both)[5]]) == HALL_LABEL  # the nearest sighting's label
    assert float(fact_loglik(both)[_slots(both)[5]]) == 0.0
    assert float(fact_loglik(hall)[_slots(hall)[5]]) == ROOM_MISMATCH_LOGLIK
    assert int(far.room[_slots(far)[5]]) == -1 and float(fact_loglik(far)[_slots(far)[5]]) == 0.0


def test_facts_weigh_candidates_seen_before_and_after_they_are_known():
    """A Type-1 fact known at the first decision (the upfront description)
    weighs a candidate seen at reset exactly as one seen afterwards."""
    agent = get_agent("described")
    params = agent.default_params()
    told = dataclasses.replace(T.Answer.empty(), known=jnp.array([True, False, False, False]), color=jnp.int32(1))
    key = jax.random.key(0)
    mem = agent.init(params, _obs(visible=[(5, 7, 2.0, 0.3, 2)]), key)  # seen at reset, colour 2
    _, mem = agent.act(params, _obs(visible=[(5, 7, 2.0, 0.3, 2), (9, 7, 2.0, -0.3, 2)]), told, mem, key, None)
    s = _slots(mem)
    lw = np.asarray(fact_loglik(mem))
    assert lw[s[5]] == lw[s[9]] < 0.0
    assert bool(mem.consumed[0]) and int(mem.facts[0]) == 1
