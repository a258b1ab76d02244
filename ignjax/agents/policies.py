"""The built-in JAX-native agents.

=================  =====  ==========  ======================================================
name               asks   privileged  behaviour
=================  =====  ==========  ======================================================
``random``         no     no          random MOVEs, STOP with a small probability per step
``shortest_path``  no     **yes**     follows the target's geodesic field; an upper bound,
                                      never a fair competitor
``explorer``       no     no          explores (free space, unvisited, not backwards), walks
                                      to the nearest instance of the goal category it has
                                      seen and stops there
``described``      no     no          never asks; the belief agent on what it sees and on the
                                      target description when the simulator gives it at
                                      reset (``SimConfig.upfront_description``): the paper's
                                      no-QA ablation
``naive_asker``    yes    no          asks freely, like the paper's unconstrained baselines:
                                      Type 1 and 2 first, Type 4 at every plausible candidate
                                      in front, Type 3 every third step otherwise
``eig``            yes    no          cost-aware: keeps a belief over target hypotheses and
                                      asks the question with the largest EIG / cost when that
                                      ratio exceeds a threshold (Eq. 1, computed exactly)
=================  =====  ==========  ======================================================

The belief-based agents (explorer, naive asker, EIG agent) keep a
:class:`~ignjax.agents.memory.Memory` and the belief of
:mod:`ignjax.agents.belief` (hypotheses, answer models, EIG per question
type). The EIG agent asks the type maximising EIG_t / w_t if that ratio
exceeds ``threshold`` and questions are left, with the paper's four
controller safeguards, each a parameter that can be switched off: Type 1
and 2 only while the fact is missing (``cache_facts``); Type 3 only where
space is uncertain (``type3_gate``, :func:`spatial_uncertainty`: branches
and corridors of passages, loops, a known goal room whose entry is not
seen); the Type-4 follow-up (``follow_up``); recovery, a Type-3 question
after ``recovery_steps`` decisions without a plausible candidate or any
route answer, at a lower bar (``recovery_ratio``) so that it too fades as
costs rise, in a passage or after ``recovery_wait`` more decisions. Its
EIG is taken on the decision's partition of the belief (``decision_eig``).
Otherwise a belief agent moves: to the most probable candidate when its
posterior exceeds ``commit`` (stopping there when closer than
``stop_range`` with posterior at least ``p_stop``), else it explores,
biased toward the belief's unseen mass and, until its point is reached,
toward the active route hint (``hint_follow``; the explorer is not
biased). An active route hint reporting "stop eligible" after a MOVE
stops the asking agents, and one that does not rejects a candidate the
MOVE ended next to (``hint_stop``; the paper's stop policy). In the last
``DEADLINE_STEPS`` planner steps every belief agent heads for its most
probable seen candidate and stops there, and its final step is always a
STOP (needed when success requires one, ``require_stop``). After a
positive Type-4 answer the asking agents follow the paper's follow-up:
STOP at once when the answer says "stop now", else exactly one MOVE toward
the confirmed candidate and then STOP. Because the costs w enter
only through EIG / w, raising a cost lowers the asking rate of that type.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp

from ignjax.agents.agent import Agent
from ignjax.agents.belief import (
    BeliefParams, decision_eigs, default_belief_params, question_eigs, unseen_direction, update_belief,
)
from ignjax.agents.memory import N_ROOM_LABELS, Memory, candidate_relative, observe_memory, visit_index
from ignjax.agents.motion import explore_direction, move_toward
from ignjax.arrays import pytree_dataclass
from ignjax.scenes import vocab
from ignjax.sim import types as T

DEADLINE_STEPS = 4  # belief agents commit to their best seen candidate this many steps before the end


# ---------------------------------------------------------------------------
# random
# ---------------------------------------------------------------------------


@pytree_dataclass
class RandomParams:
    """stop_prob: () probability of STOP at each decision."""

    stop_prob: jax.Array


def _random_init(params, obs, key):
    return jnp.int32(0)


def _random_act(params, obs, answers, pstate, key, priv):
    k1, k2, k3, k4 = jax.random.split(key, 4)
    stop = jax.random.uniform(k1) < params.stop_prob
    a = T.Action.make(jnp.where(stop, T.STOP, T.MOVE), jax.random.randint(k2, (), 0, 8),
                      jax.random.randint(k3, (), 2, 8), jax.random.randint(k4, (), 1, 4))
    return a, pstate + 1


RANDOM = Agent("random", _random_init, _random_act, lambda: RandomParams(jnp.float32(0.05)),
               description="random moves, stops with probability 0.05 per step")


# ---------------------------------------------------------------------------
# shortest path (privileged)
# ---------------------------------------------------------------------------


@pytree_dataclass
class PathParams:
    """stop_distance: () stop when the geodesic distance is below this, m."""

    stop_distance: jax.Array


def _path_act(params, obs, answers, pstate, key, priv):
    stop = (priv.geodesic <= params.stop_distance) | ~(priv.best_value < priv.geodesic)
    mv = T.Action.make(T.MOVE, priv.best_direction, priv.best_col, priv.best_row)
    return jax.tree.map(lambda s, m: jnp.where(stop, s, m), T.Action.make(T.STOP), mv), pstate + 1


SHORTEST_PATH = Agent("shortest_path", _random_init, _path_act, lambda: PathParams(jnp.float32(0.3)), privileged=True,
                      description="PRIVILEGED upper bound: follows the target's geodesic field")


# ---------------------------------------------------------------------------
# the step shared by the belief-based agents: explorer, naive asker and EIG agent
# ---------------------------------------------------------------------------


def _move_policy(mem: Memory, obs: T.Observation, answers: T.Answer, params: BeliefParams, b, key, hint_weight):
    """MOVE or STOP from the belief (shared by the belief-based agents).

    ``hint_weight`` biases exploration toward the belief's unseen mass;
    with an active route hint not yet reached, exploration also leans
    toward the hint's heading (``params.hint_follow``), and the hint's
    report "stop eligible" stops the agent (``params.hint_stop``)."""
    M = mem.handle.shape[0]
    dist, bearing = candidate_relative(mem, obs)
    bc = b[:M]
    j = jnp.argmax(bc)
    seen = jnp.any((mem.handle >= 0) & ~mem.rejected)
    # running out of planner steps: go for the most likely seen candidate, and make the last step a STOP
    # (under the STOP-required success rule, ending without one is a certain failure)
    late = (obs.steps_left <= DEADLINE_STEPS) & seen
    committed = (bc[j] >= params.commit) | late
    close = dist[j] <= params.stop_range
    stuck = (obs.last_move < 0.05) & (mem.t > 0) & (dist[j] <= params.stop_range + 0.8)  # furniture in the way
    eligible = params.hint_stop & answers.hint_active & (answers.hint_progress == T.HINT_STOP)
    stop = (committed & (close | stuck) & ((bc[j] >= params.p_stop) | late)) | (obs.steps_left <= 1) | eligible
    approach = move_toward(bearing[j], jnp.clip(dist[j] - 0.5, 0.5, 2.5))
    head, conc = unseen_direction(mem, b)
    # Shape: () the bias heading: the belief's unseen mass, and the route hint's heading while it is followed
    following = (hint_weight > 0) & mem.has_hint & ~mem.hint_done
    w_unseen, w_hint = hint_weight * conc, jnp.where(following, params.hint_follow, 0.0)
    bx = w_unseen * jnp.cos(head) + w_hint * jnp.cos(mem.hint_heading)
    by = w_unseen * jnp.sin(head) + w_hint * jnp.sin(mem.hint_heading)
    rel, free = explore_direction(mem, obs, bias=jnp.arctan2(by, bx), bias_weight=jnp.hypot(bx, by), rng=key)
    explore = move_toward(rel, jnp.clip(free - 0.4, 0.8, 2.5))
    move = jax.tree.map(lambda a, e: jnp.where(committed, a, e), approach, explore)
    act = jax.tree.map(lambda s, m: jnp.where(stop, s, m), T.Action.make(T.STOP), move)
    return act, j


def _belief_init(params, obs, key):
    return observe_memory(Memory.empty(), obs)


def _finish(mem: Memory, obs, answers, act: T.Action, asked_about, pending_stop=None):
    is_ask = act.kind == T.ASK
    return dataclasses.replace(
        mem, last_asked=jnp.where(is_ask, act.question, 0).astype(jnp.int32),
        asked_about=jnp.where(is_ask & (act.question == 4), asked_about, mem.asked_about).astype(jnp.int32),
        t=mem.t + 1, pending_stop=mem.pending_stop if pending_stop is None else pending_stop,
    )


def _follow_up(mem: Memory, obs: T.Observation, answers: T.Answer, act: T.Action, enabled=True):
    """The Type-4 follow-up (paper §3.3, Appendix safeguards): after a yes,
    STOP at once when the answer says "stop now"; when it says "one closer
    move then stop", exactly one MOVE toward the confirmed candidate, then
    STOP at the next decision (``enabled``: safeguard 3; when off, a yes
    is only evidence for the belief). Returns (action, pending_stop)."""
    yes = (answers.confirm == 1) & (mem.last_asked == 4) & ~answers.refused & (answers.last_type == 4) & enabled
    stop_now = (yes & (answers.follow_up == T.FOLLOW_STOP_NOW)) | mem.pending_stop
    one_move = yes & (answers.follow_up == T.FOLLOW_ONE_MOVE) & ~mem.pending_stop
    dist, bearing = candidate_relative(mem, obs)
    slot = jnp.maximum(mem.asked_about, 0)
    has = mem.asked_about >= 0
    closer = move_toward(jnp.where(has, bearing[slot], 0.0), jnp.where(has, jnp.clip(dist[slot] - 0.5, 0.5, 2.5), 1.0))
    act = jax.tree.map(lambda m, a: jnp.where(one_move, m, a), closer, act)
    act = jax.tree.map(lambda s, a: jnp.where(stop_now, s, a), T.Action.make(T.STOP), act)
    return act, one_move


# explorer -------------------------------------------------------------------

def _explorer_act(params, obs, answers, mem, key, priv):
    mem, _ = update_belief(params, obs, answers, mem)
    # no answers: every seen candidate is as likely as the others; commit to the nearest
    valid = (mem.handle >= 0) & ~mem.rejected
    dist, _ = candidate_relative(mem, obs)
    nearest = jnp.argmin(jnp.where(valid, dist, jnp.inf))
    U = N_ROOM_LABELS * 8
    b = jnp.concatenate([jnp.where(jnp.arange(valid.shape[0]) == nearest, 1.0, 0.0) * jnp.any(valid),
                         jnp.full(U, 1.0 / U) * (~jnp.any(valid))])
    act, _ = _move_policy(mem, obs, answers, dataclasses.replace(params, p_stop=jnp.float32(0.5)), b, key, 0.0)
    return act, _finish(mem, obs, answers, act, -1)


EXPLORER = Agent("explorer", _belief_init, _explorer_act, default_belief_params,
                 description="never asks: explores, then walks to the nearest instance of the goal category it has "
                             "seen and stops there",
                 # its belief is one-hot on the nearest seen instance, so only the stopping range matters
                 # (commit is always met, p_stop is fixed to 0.5; no answers, so no route hint to follow or stop on)
                 reads=("stop_range",))


# described (no questions, uses a description given at reset) -----------------

def _described_act(params, obs, answers, mem, key, priv):
    mem, b = update_belief(params, obs, answers, mem)
    act, _ = _move_policy(mem, obs, answers, params, b, key, 0.0)
    return act, _finish(mem, obs, answers, act, -1)


DESCRIBED = Agent("described", _belief_init, _described_act, default_belief_params,
                  description="never asks: the belief agent on what it sees plus the target description when it is "
                              "given at reset (sim.upfront_description); the paper's no-QA ablation",
                  reads=("commit", "p_stop", "stop_range", "prior_count"))  # no answers: no route hint


# naive asker ------------------------------------------------------------------

def _naive_act(params, obs, answers, mem, key, priv):
    mem, b = update_belief(params, obs, answers, mem)
    eigs, slot4 = question_eigs(mem, obs, answers, b)
    has_q = obs.questions_left > 0
    M = mem.handle.shape[0]
    committed = jnp.max(b[:M]) >= params.commit
    q = jnp.where(~answers.known[0], 1,
                  jnp.where(~answers.known[1], 2,
                            jnp.where(slot4 >= 0, 4, jnp.where((mem.t % 3 == 0) & ~committed, 3, 0))))
    ask = has_q & (q > 0) & ~mem.pending_stop
    move, _ = _move_policy(mem, obs, answers, params, b, key, 1.5)
    cand = jnp.where(slot4 >= 0, mem.handle[jnp.maximum(slot4, 0)], -1)
    act = jax.tree.map(lambda a, m: jnp.where(ask, a, m), T.Action.make(T.ASK, question=jnp.maximum(q, 1), candidate=cand), move)
    act, pending = _follow_up(mem, obs, answers, act, params.follow_up)
    return act, _finish(mem, obs, answers, act, slot4, pending)


NAIVE_ASKER = Agent("naive_asker", _belief_init, _naive_act, default_belief_params, asks=True,
                    description="asks freely, ignoring costs: Type 1 and 2 first, Type 4 at every plausible "
                                "candidate, Type 3 every third step",
                    reads=("commit", "p_stop", "stop_range", "prior_count", "follow_up", "hint_stop", "hint_follow"))


# EIG agent ------------------------------------------------------------------------

PASSAGE_LABELS = ("hallway",)  # room labels of passages (as the Type-3 location analysis counts them)
_PASSAGE_CODES = tuple(vocab.ALL_ROOM_LABELS.index(label) for label in PASSAGE_LABELS)


def in_passage(obs: T.Observation):
    """() bool: the agent stands in a passage (a room labelled as one, :data:`PASSAGE_LABELS`) or outside every room."""
    return (obs.room_label < 0) | jnp.any(obs.room_label == jnp.asarray(_PASSAGE_CODES, jnp.int32))


def spatial_uncertainty(mem: Memory, obs: T.Observation, answers: T.Answer):
    """() bool, safeguard 2's situations for a route question: in a passage
    (a room labelled as one, :data:`PASSAGE_LABELS`, or outside every room)
    at a branch (three or more separate open directions, 2 m free) or in a
    long corridor (open ahead or behind for 3 m, closed at both sides
    within 1.2 m); a loop (a MOVE back to a spot seen at two or more
    earlier decisions); or
    the goal room known while the agent stands elsewhere and has seen no
    candidate in it. Inside a closed room the agent searches by itself."""
    free = jnp.mean(obs.free_space, axis=1)  # Shape: (8,) views, relative to the heading
    open_ = free >= 2.0
    runs = jnp.sum(open_ & ~jnp.roll(open_, 1))  # separate open directions (circular runs)
    passage = in_passage(obs)
    branch = passage & ((runs >= 3) | ((jnp.sum(open_) >= 3) & ~jnp.all(open_)))
    ij = visit_index(obs.odometry[:2])
    moved_here = (mem.t > 0) & (mem.last_asked == 0) & (obs.last_move > 0.05)  # questions do not make a loop
    loop = moved_here & (mem.visits[ij[1], ij[0]] >= 3)
    corridor = passage & (jnp.maximum(free[0], free[4]) >= 3.0) & (free[2] < 1.2) & (free[6] < 1.2)
    valid = (mem.handle >= 0) & ~mem.rejected
    room_known = answers.known[1] & (answers.room_label >= 0)
    entry = room_known & (obs.room_label != answers.room_label) & ~jnp.any(valid & (mem.room == answers.room_label))
    return branch | loop | corridor | entry


def _eig_act(params, obs, answers, mem, key, priv):
    mem, b = update_belief(params, obs, answers, mem)
    exact, slot4 = question_eigs(mem, obs, answers, b, params.cache_facts)
    decided, _ = decision_eigs(mem, obs, answers, b, params.cache_facts)
    eigs = jnp.where(params.decision_eig, decided, exact)
    # safeguard 2: route questions where space is uncertain
    eigs = eigs.at[2].multiply(jnp.where(params.type3_gate & ~spatial_uncertainty(mem, obs, answers), 0.0, 1.0))
    ratio = eigs / jnp.maximum(params.costs, 1e-6)
    q = jnp.argmax(ratio) + 1
    has_q = (obs.questions_left > 0) & ~mem.pending_stop
    ask = (jnp.max(ratio) > params.threshold) & has_q
    # safeguard 4: moved for a while, no plausible candidate, never asked for spatial guidance: a route question
    # pays at a lower bar (still EIG / cost, so it too fades as costs rise)
    M = mem.handle.shape[0]
    route = decided[2] / jnp.maximum(params.costs[2], 1e-6)  # the ungated Type-3 value
    # (it waits for a passage, where a route answer is about the layout, for up to recovery_wait more decisions)
    where_ok = in_passage(obs) | (mem.t >= params.recovery_steps + params.recovery_wait)
    lost = (params.recovery_steps > 0) & (mem.t >= params.recovery_steps) & ~answers.known[2] & where_ok \
        & (jnp.max(b[:M]) < params.commit) & has_q & (route > params.recovery_ratio * params.threshold)
    q = jnp.where(ask, q, jnp.where(lost, 3, q))
    ask = ask | lost
    move, _ = _move_policy(mem, obs, answers, params, b, key, 2.0)
    cand = jnp.where(slot4 >= 0, mem.handle[jnp.maximum(slot4, 0)], -1)
    act = jax.tree.map(lambda a, m: jnp.where(ask, a, m), T.Action.make(T.ASK, question=q, candidate=cand), move)
    act, pending = _follow_up(mem, obs, answers, act, params.follow_up)
    return act, _finish(mem, obs, answers, act, slot4, pending)


EIG = Agent("eig", _belief_init, _eig_act, default_belief_params, asks=True,
            description="cost-aware: asks the question type with the largest expected information gain per unit "
                        "cost when that ratio exceeds `threshold`, else moves on its belief")


__all__ = ["DEADLINE_STEPS", "DESCRIBED", "EIG", "EXPLORER", "NAIVE_ASKER", "PASSAGE_LABELS", "PathParams", "RANDOM",
           "RandomParams", "SHORTEST_PATH", "in_passage", "spatial_uncertainty"]
