"""The belief of the belief-based agents over where the target is, how
the oracle's answers update it, and the expected information gain of each
question type (Eq. 1).

Hypotheses are the candidate slots of :class:`~ignjax.agents.memory.Memory`
(instances of the instruction's category seen so far, minus those a
Type-4 answer rejected) plus one "not seen yet" hypothesis per (room label,
absolute direction sector), whose total prior weight is
``max(prior_count - seen, 0.25)``. Each hypothesis carries the
log-likelihood of the answers received so far.

Answer models (likelihood of answer a under hypothesis h):

* Type 1: a = the target's attributes (colour, material, size, state). A
  seen candidate answers the attributes it was seen with (uniformly when
  none was observed); "not seen" answers uniformly over the
  ``N_ATTR_ANSWERS`` combinations. A received answer: each said attribute
  a candidate was last seen with another value of costs it
  ``ATTR_MISMATCH_LOGLIK``; "not seen" pays ``-log(n)`` per said attribute
  with n values. Once the answer is known the question is worth 0.
* Type 2: a = the goal room label (12 labels). A candidate answers the
  room label the agent stood in at its nearest sighting within 3 m
  (uniform when unknown); "not seen" answers uniformly. Worth 0 once known.

The Type-1 and Type-2 facts are kept in memory when received (asked, or
given at reset with the upfront description) and their likelihood under a
candidate is recomputed from what memory holds about it at every decision
(:func:`~ignjax.agents.memory.fact_loglik`): a candidate's room label can
improve after its first sighting (a view through a doorway, then one from
inside), and the evidence follows it.
* Type 3: a = the sector (8) of the route's way out. A candidate answers
  the sector of its bearing with probability 0.6 and each neighbouring
  sector with 0.2 (routes bend); "not seen" answers uniformly.
* Type 4: about the most probable candidate in the front view within
  ``CONFIRM_RANGE`` (3 m): yes under that candidate, no under every other
  hypothesis. Worth 0 when no candidate is in front.
* The active route hint's progress report after a MOVE (with
  ``BeliefParams.hint_stop``): a MOVE that ends within ``HINT_REJECT_RANGE``
  of a candidate's estimated centre without the report "stop eligible"
  (the target within the stop radius) rejects that candidate.

EIG_t = H[b] - sum_a p(a) H[b | a] (nats) for each type, exactly on the
belief (:func:`question_eigs`; :func:`expected_information_gain` is the
general form on an explicit likelihood matrix).
"""

from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp

from ignjax.agents.memory import (
    N_ROOM_LABELS, Memory, candidate_relative, fact_loglik, observe_memory,
)
from ignjax.arrays import pytree_dataclass
from ignjax.protocol import CONFIRM_RANGE, LOCKED_COSTS
from ignjax.scenes import vocab
from ignjax.sim import types as T

N_COLORS = len(vocab.COLORS)
ATTR_VALUES = (len(vocab.COLORS), len(vocab.MATERIALS), len(vocab.SIZES), len(vocab.STATES))
N_ATTR_ANSWERS = math.prod(ATTR_VALUES)  # Type-1 answers: every (colour, material, size, state)
HINT_REJECT_RANGE = 0.8  # m: a MOVE ending this close to a candidate without "stop eligible" rejects it


def said_attributes(answers: T.Answer):
    """(4,) int32 attribute codes the Type-1 answer says (colour, material, size, state; -1 unsaid)."""
    return jnp.stack([answers.color, answers.material, answers.size, answers.state]).astype(jnp.int32)


@pytree_dataclass
class BeliefParams:
    """Parameters of the belief-based agents.

    Attributes:
        costs: (4,) per-type question costs the agent is charged (EIG agent).
        threshold: () ask when max_t EIG_t / w_t exceeds this (EIG agent).
        commit: () posterior above which the agent walks to a candidate.
        p_stop: () posterior needed to stop at a candidate without asking.
        stop_range: () distance to a candidate at which the agent stops, m.
        prior_count: () prior expected number of instances of the category.
        decision_eig: () bool, the EIG agent values a question by what it
            tells about the agent's decision (which seen candidate, or which
            direction to explore): the "not seen yet" hypotheses count as one
            per direction, so the room label of an instance not seen yet is
            worth nothing until candidates in different rooms are seen.
            false: Eq. (1) on the full belief.
        type3_gate: () bool, safeguard 2: Type 3 only at a branch (three or
            more open directions), in a loop (this spot visited before), in a
            long corridor, or when the goal room is known but the agent is
            not in it and has seen no candidate there.
        recovery_steps: () safeguard 4: after this many decisions without a
            committed candidate and without any Type-3 answer, ask Type 3
            when its EIG / cost exceeds ``recovery_ratio`` x ``threshold``,
            in a passage (0: off).
        recovery_ratio: () safeguard 4's share of the asking threshold (it
            lowers the bar, so recovery still asks less as costs rise).
        recovery_wait: () safeguard 4 inside a closed room: decisions it
            waits for a passage before asking there anyway.
        cache_facts: () bool, safeguard 1: Type 1 and Type 2 only while the
            fact is missing (cached once answered). false: they stay on
            offer at their Eq. (1) value.
        follow_up: () bool, safeguard 3: after a yes to Type 4, STOP at once
            ("stop now") or exactly one MOVE toward the confirmed candidate
            and then STOP, with no question in between.
        hint_stop: () bool, an active route hint's report "stop eligible"
            (the target within the stop radius after a MOVE) stops the
            agent, and a MOVE that ends next to a candidate without that
            report rejects the candidate (the paper's stop policy).
        hint_follow: () weight of the active route hint's heading when
            exploring, until the hinted point is reached (0: off).
    """

    costs: jax.Array
    threshold: jax.Array
    commit: jax.Array
    p_stop: jax.Array
    stop_range: jax.Array
    prior_count: jax.Array
    decision_eig: jax.Array
    type3_gate: jax.Array
    recovery_steps: jax.Array
    recovery_ratio: jax.Array
    recovery_wait: jax.Array
    cache_facts: jax.Array
    follow_up: jax.Array
    hint_stop: jax.Array
    hint_follow: jax.Array


def default_belief_params(**kw) -> BeliefParams:
    base = dict(costs=jnp.asarray(LOCKED_COSTS, jnp.float32), threshold=jnp.float32(2.5), commit=jnp.float32(0.5),
                p_stop=jnp.float32(0.8), stop_range=jnp.float32(1.0), prior_count=jnp.float32(3.0),
                decision_eig=jnp.array(True), type3_gate=jnp.array(True),
                recovery_steps=jnp.float32(6.0), recovery_ratio=jnp.float32(0.5),
                recovery_wait=jnp.float32(6.0), cache_facts=jnp.array(True),
                follow_up=jnp.array(True), hint_stop=jnp.array(True), hint_follow=jnp.float32(2.0))
    base.update({k: jnp.asarray(v, base[k].dtype if k in base else jnp.float32) for k, v in kw.items()})
    return BeliefParams(**base)


def _abs_sector(obs: T.Observation):
    """(8,) relative sector (0..7) of each absolute world sector from the agent's heading."""
    head = (jnp.round(obs.heading / (math.pi / 4)).astype(jnp.int32)) % 8
    return (jnp.arange(8) - head) % 8


def _sector_likelihood(answer, sectors):
    """P(route answer sector | hypothesis sector): 0.6 same, 0.2 each neighbour."""
    diff = jnp.minimum((sectors - answer) % 8, (answer - sectors) % 8)
    return jnp.where(diff == 0, 0.6, jnp.where(diff == 1, 0.2, 1e-3))


def _fold_answers(mem: Memory, obs: T.Observation, answers: T.Answer, hint_stop=False) -> Memory:
    """Fold the answers into the belief: the Type-1 and Type-2 facts once,
    when they first become known (asked, or given at reset with the upfront
    description): into the unseen hypotheses, and kept in ``mem.facts`` for
    the candidates (:func:`belief` weighs them by what memory holds now);
    the answer to last step's Type-3 or Type-4 question; with ``hint_stop``,
    the active hint's progress report after last step's MOVE."""
    q = mem.last_asked
    fresh = (q > 0) & ~answers.refused & (answers.last_type == q)
    new1 = answers.known[0] & ~mem.consumed[0]
    new2 = answers.known[1] & ~mem.consumed[1]
    M = mem.handle.shape[0]
    labels = jnp.arange(N_ROOM_LABELS)[:, None]
    rel = _abs_sector(obs)[None, :]
    # Type 1: attributes (the candidates' side: fact_loglik on mem.facts)
    said = said_attributes(answers)
    u1 = jnp.full((N_ROOM_LABELS, 8), -jnp.sum(jnp.where(said >= 0, jnp.log(jnp.asarray(ATTR_VALUES, jnp.float32)), 0.0)))
    # Type 2: room label (likewise)
    u2 = jnp.where((answers.room_label >= 0) & (labels != answers.room_label), -30.0, 0.0) * jnp.ones((1, 8))
    # Type 3: route sector (relative at asking time = now)
    _, bearing = candidate_relative(mem, obs)
    cs = (jnp.round(bearing / (math.pi / 4)).astype(jnp.int32)) % 8
    d3 = jnp.log(_sector_likelihood(answers.hint_sector, cs))
    u3 = jnp.log(_sector_likelihood(answers.hint_sector, rel)) * jnp.ones((N_ROOM_LABELS, 1))
    # Type 4
    yes = answers.confirm == 1
    slot = mem.asked_about
    onehot = jnp.arange(M) == slot
    d4 = jnp.where(yes, jnp.where(onehot, 0.0, -jnp.inf), 0.0)
    rej4 = jnp.where(~yes & (slot >= 0), onehot, False)
    u4 = jnp.where(yes, -jnp.inf, 0.0) * jnp.ones((N_ROOM_LABELS, 8))
    # the active hint's progress after last step's MOVE: a candidate reached without "stop eligible" is not the target
    dist, _ = candidate_relative(mem, obs)
    moved = (q == 0) & (mem.t > 0) & answers.hint_active & (answers.hint_progress != T.HINT_NONE)
    rej_hint = hint_stop & moved & (answers.hint_progress != T.HINT_STOP) & (mem.handle >= 0) & (dist <= HINT_REJECT_RANGE)
    f3, f4 = fresh & (q == 3), fresh & (q == 4)
    d = jnp.where(f3, d3, 0.0) + jnp.where(f4, d4, 0.0)
    facts = jnp.concatenate([jnp.where(new1, said, mem.facts[:4]), jnp.where(new2, answers.room_label, mem.facts[4:])])
    u = jnp.where(new1, u1, 0.0) + jnp.where(new2, u2, 0.0) + jnp.where(f3, u3, 0.0) + jnp.where(f4, u4, 0.0)
    return dataclasses.replace(
        mem,
        logw=mem.logw + d,
        unseen_logw=mem.unseen_logw + u,
        rejected=mem.rejected | (f4 & rej4) | rej_hint,
        hint_heading=jnp.where(f3, obs.heading + answers.hint_sector.astype(jnp.float32) * (math.pi / 4), mem.hint_heading),
        has_hint=mem.has_hint | f3,
        hint_done=(mem.hint_done | (answers.hint_progress == T.HINT_REACHED)) & ~f3,
        consumed=mem.consumed | jnp.stack([new1, new2, f3, f4]),
        facts=facts.astype(jnp.int32),
    )


def belief(mem: Memory, params: BeliefParams):
    """Posterior over hypotheses: (M,) candidate slots followed by
    (L * 8,) "not seen yet, room label l, absolute sector s" (row-major)."""
    valid = (mem.handle >= 0) & ~mem.rejected
    n_seen = jnp.sum(valid)
    lw = jnp.where(valid, mem.logw + fact_loglik(mem), -jnp.inf)
    n_unseen = N_ROOM_LABELS * 8
    lu = jnp.log(jnp.maximum(params.prior_count - n_seen, 0.25)) - math.log(n_unseen) + mem.unseen_logw.reshape(-1)
    logits = jnp.concatenate([lw, lu])
    logits = jnp.where(jnp.all(jnp.isneginf(logits)), jnp.zeros_like(logits), logits)
    return jax.nn.softmax(logits)


def _entropy(p, axis=-1):
    return -jnp.sum(jnp.where(p > 0, p * jnp.log(jnp.where(p > 0, p, 1.0)), 0.0), axis=axis)


def expected_information_gain(b, L):
    """Eq. (1): H[b] - E_{a ~ p(a)} H[b | a] for a likelihood matrix L (A, Hyp),
    the general form (:func:`question_eigs` computes the same quantity from
    the structure of each answer model; tests check one against the other)."""
    pa = L @ b  # Shape: (A,)
    post = L * b[None] / jnp.where(pa > 0, pa, 1.0)[:, None]
    return _entropy(b) - jnp.sum(pa * _entropy(post, axis=1))


def _attribute_eig(attrs, bc, unseen):
    """EIG of the Type-1 question: I(hypothesis; answer) = H[p(a)] - u log N
    with u the mass answering uniformly over the N = ``N_ATTR_ANSWERS``
    combinations; the N - G answers no candidate gives share u / N each."""
    M = attrs.shape[0]
    known = jnp.any(attrs >= 0, axis=1)
    same = jnp.all(attrs[:, None] == attrs[None], axis=-1) & known[:, None] & known[None]  # Shape: (M, M)
    first = known & ~jnp.any(same & (jnp.arange(M)[None] < jnp.arange(M)[:, None]), axis=1)
    u = unseen + jnp.sum(jnp.where(known, 0.0, bc))
    pa = jnp.where(first, same.astype(bc.dtype) @ bc + u / N_ATTR_ANSWERS, 0.0)  # Shape: (M,) one answer per group
    n_other = N_ATTR_ANSWERS - jnp.sum(first)
    p_other = u / N_ATTR_ANSWERS
    h_other = jnp.where(p_other > 0, -n_other * p_other * jnp.log(jnp.where(p_other > 0, p_other, 1.0)), 0.0)
    return _entropy(pa) + h_other - u * math.log(N_ATTR_ANSWERS)


def question_eigs(mem: Memory, obs: T.Observation, answers: T.Answer, b, cached=True):
    """(4,) EIG of each question type on belief ``b``; also the Type-4 slot.
    With ``cached`` (safeguard 1) a Type-1 or Type-2 fact already received
    is worth 0; without it the answer model values it as if unknown.

    Eq. (1) through the mutual-information identity
    H[b] - E_a H[b | a] = H[p(a)] - sum_h b_h H[p(a | h)], on the structure
    of each type's answer model: only the (A,) answer distribution p(a) and
    the answer entropy of each hypothesis are needed."""
    M = mem.handle.shape[0]
    valid = (mem.handle >= 0) & ~mem.rejected
    bc, bu = b[:M], b[M:].reshape(N_ROOM_LABELS, 8)  # Shape: (M,), (L, 8)
    # Type 1: attributes; a candidate answers the combination it was seen with (one answer per distinct
    # combination, the first slot holding it), candidates seen with none and unseen hypotheses answer uniformly
    e1 = _attribute_eig(mem.attrs, bc, jnp.sum(bu))
    # Type 2: room label; an unseen hypothesis answers its own label
    uniform2 = jnp.sum(jnp.where(mem.room < 0, bc, 0.0))
    pa2 = jnp.sum(jnp.where(jnp.arange(N_ROOM_LABELS)[:, None] == mem.room[None], bc[None], 0.0), axis=1) \
        + jnp.sum(bu, axis=1) + uniform2 / N_ROOM_LABELS
    e2 = _entropy(pa2) - uniform2 * math.log(N_ROOM_LABELS)
    # Type 3: sector; every hypothesis answers a rotation of the same distribution
    dist, bearing = candidate_relative(mem, obs)
    cs = (jnp.round(bearing / (math.pi / 4)).astype(jnp.int32)) % 8
    sectors = jnp.arange(8)[:, None]
    mass = jnp.sum(jnp.where(sectors == cs[None], bc[None], 0.0), axis=1) \
        + jnp.sum(jnp.where(sectors == _abs_sector(obs)[None], jnp.sum(bu, axis=0)[None], 0.0), axis=1)  # Shape: (8,)
    L3 = _sector_likelihood(sectors, jnp.arange(8)[None])
    L3 = L3 / L3.sum(0, keepdims=True)  # Shape: (A, 8) answer given the hypothesis' sector
    e3 = _entropy(L3 @ mass) - jnp.sum(mass) * _entropy(L3[:, 0])
    # Type 4: the most probable candidate in front within 3 m; the answer is certain under every hypothesis
    in_front = valid & (dist <= CONFIRM_RANGE) & (jnp.abs(bearing) <= math.pi / 4) \
        & jnp.any(mem.handle[:, None] == obs.visible_handle[None, :], axis=1)
    slot = jnp.argmax(jnp.where(in_front, bc, -1.0))
    has = jnp.any(in_front)
    e4 = _entropy(jnp.stack([bc[slot], jnp.sum(b) - bc[slot]]))
    e = jnp.stack([e1, e2, e3, e4])
    cached = jnp.asarray(cached)
    e = e * jnp.stack([~(answers.known[0] & cached), ~(answers.known[1] & cached), jnp.array(True), has])
    return jnp.maximum(e, 0.0), jnp.where(has, slot, -1)


def decision_eigs(mem: Memory, obs: T.Observation, answers: T.Answer, b, cached=True):
    """:func:`question_eigs` on the decision's partition of the belief: the
    "not seen yet" hypotheses of one direction sector count as one (the agent
    cannot act on the room label of an instance it has not seen), so Type 2
    loses the information it gives about those labels,
    ``sum_s B_s H[label | unseen, s]`` with ``B_s`` the unseen mass of
    sector s. Types 1, 3 and 4 answer alike under every unseen hypothesis of
    a sector, so their EIG does not change."""
    e, slot = question_eigs(mem, obs, answers, b, cached)
    M = mem.handle.shape[0]
    bu = b[M:].reshape(N_ROOM_LABELS, 8)
    mass = jnp.sum(bu, axis=0)  # Shape: (8,)
    within = jnp.sum(mass * _entropy((bu / jnp.maximum(mass, 1e-12)[None]).T, axis=1))
    e = e.at[1].set(jnp.maximum(e[1] - within, 0.0))
    return e, slot


def unseen_direction(mem: Memory, b):
    """(heading, concentration): circular mean of the unseen mass over
    absolute sectors, and its resultant length in [0, 1]."""
    M = mem.handle.shape[0]
    mass = b[M:].reshape(N_ROOM_LABELS, 8).sum(0)
    ang = jnp.arange(8) * (math.pi / 4)
    x, y = jnp.sum(mass * jnp.cos(ang)), jnp.sum(mass * jnp.sin(ang))
    total = jnp.maximum(jnp.sum(mass), 1e-9)
    return jnp.arctan2(y, x), jnp.hypot(x, y) / total


def update_belief(params: BeliefParams, obs: T.Observation, answers: T.Answer, mem: Memory):
    """Fold last step's answer and the new observation into memory.

    Returns:
        (memory, belief): the updated memory and :func:`belief` on it.
    """
    mem = _fold_answers(mem, obs, answers, params.hint_stop)
    mem = observe_memory(mem, obs)
    return mem, belief(mem, params)


__all__ = ["ATTR_VALUES", "BeliefParams", "HINT_REJECT_RANGE", "N_ATTR_ANSWERS", "N_COLORS", "belief", "decision_eigs",
           "default_belief_params", "expected_information_gain", "question_eigs", "said_attributes", "unseen_direction",
           "update_belief"]
