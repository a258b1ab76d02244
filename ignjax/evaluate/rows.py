"""The rows of the MLLM host loop (:mod:`ignjax.evaluate.hostloop`): the
jitted programs over chosen rows of the batch, and what the host keeps of
the episode each row holds.

The programs (:func:`reset_rows`, :func:`step_rows`, :func:`abort_rows`,
:func:`observe_rows`, :func:`outcome_rows`) take the world as an argument
(its configuration is static), so every loop over the same world shapes
reuses one compilation; a row outside the mask is left as it is.
:class:`EpisodeState` is one running episode's host side (agent memory,
answers in words, transcript, accounting), :class:`RunState` one run's
queue and slots, and :func:`settings_hash` the key of the progress file
(:mod:`ignjax.evaluate.recovery`): what a resumed run must share with the
run it continues.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field

import jax
import jax.numpy as jnp

from ignjax.agents.llm.agent import LLMAgent
from ignjax.agents.llm.config import LLMConfig
from ignjax.episodes.dataset import EpisodeSet
from ignjax.evaluate import accounting as A
from ignjax.sim import env as E
from ignjax.sim import types as T
from ignjax.sim.rollout import step_record
from ignjax.sim.views import ViewConfig


@dataclass
class EpisodeState:
    """The host side of one running episode (a slot of the loop): its index in the file, the agent's memory, the
    oracle's answers in words, transcript records, accounting, the failure that ended it, the active route hint's
    report, images to write, answers still to paraphrase and what the pending decision showed of its front view."""

    index: int
    memory: object
    answers: list = field(default_factory=list)
    calls: list = field(default_factory=list)
    acc: dict = field(default_factory=A.new_accounting)
    failure: str = ""
    progress: str = ""  # the active route hint's report after the last step (Decision.hint_report)
    images: list = field(default_factory=list)
    unread: list = field(default_factory=list)  # indices into answers still to paraphrase (llm.paraphrase)
    front: tuple | None = None  # what the pending decision showed of its front view, to resolve a Type-4 cell


@dataclass
class RunState:
    """The state of one :meth:`~ignjax.evaluate.hostloop.HostLoop.run`: episodes still queued (popped from the
    end), the episode in each row, each running episode's trajectory rows, the finished episodes' records, and the
    decisions applied."""

    queue: list
    slots: list
    traj_rows: dict = field(default_factory=dict)
    records: dict = field(default_factory=dict)
    decisions: int = 0


def settings_hash(es: EpisodeSet, agent: LLMAgent, llm: LLMConfig, sim: T.SimConfig, views: ViewConfig, seed: int,
                  costs) -> str:
    """The key of a run's progress file: the episodes, the agent and its options, the request settings that change
    replies (not endpoints, concurrency, cache or replay), simulator and view settings, seed and costs."""
    blob = json.dumps({"episodes": es.episode_ids, "agent": agent.name, "agent_options": vars(agent),
                       "llm": {k: v for k, v in llm.public_dict().items() if k not in ("endpoints", "concurrency",
                                                                                         "cache_dir", "replay")},
                       "sim": sim.to_dict(), "views": dataclasses.asdict(views.replace(workers=1)), "seed": seed,
                       "costs": [float(c) for c in costs]}, sort_keys=True, default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


@jax.jit
def reset_rows(world, specs, keys, mask, states):
    """Start the episodes ``specs`` in the rows of ``mask``."""
    new = jax.vmap(lambda s, k: E.reset(world, s, k))(specs, keys)
    return T.tree_select(mask, new, states)


@jax.jit
def reset_all(world, specs, keys):
    """Start the episodes ``specs`` in every row."""
    return jax.vmap(lambda s, k: E.reset(world, s, k))(specs, keys)


@jax.jit
def step_rows(world, states, actions, mask):
    """Step the rows in ``mask`` (the others stay as they are) and their trajectory records."""
    obs = E.observe_all(world, states)
    after = T.tree_select(mask, E.step_batch(world, states, actions), states)
    kind = jnp.where(states.done | ~mask, -1, jnp.clip(actions.kind, 0, 2))
    return after, step_record(obs, actions, kind, states, after, world.config.n_views)


@jax.jit
def abort_rows(states, mask):
    """End the running episodes of the rows in ``mask`` with stop reason ``ABORTED`` (a model failure)."""
    return dataclasses.replace(states, done=states.done | mask,
                               stop_reason=jnp.where(mask & ~states.done, T.ABORTED, states.stop_reason))


@jax.jit
def observe_rows(world, states):
    """Every row's observation."""
    return E.observe_all(world, states)


@jax.jit
def outcome_rows(world, states):
    """Every row's outcome."""
    return jax.vmap(lambda s: E.outcome(world, s))(states)


__all__ = ["EpisodeState", "RunState", "abort_rows", "observe_rows", "outcome_rows", "reset_all", "reset_rows",
           "settings_hash", "step_rows"]
