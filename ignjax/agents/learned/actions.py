"""The discrete actions of a learned policy and their mask: the RL
environment's action space (re-exported as :mod:`ignjax.rl.actions`) and
what the ``learned`` agent decodes its choice with.

With V views (``SimConfig.n_views``; 8 in the paper's setting) there are
``2 V + 5`` actions, in this order:

=====================  =========================================================
index                  action
=====================  =========================================================
``0 .. V-1``           MOVE toward view k, the short cell (:data:`SHORT_DISTANCE`)
``V .. 2V-1``          MOVE toward view k, the long cell (:data:`LONG_DISTANCE`)
``2V .. 2V+3``         ASK question type 1 (appearance), 2 (region), 3 (route),
                       4 (confirmation: "is it what is in front of me",
                       ``candidate = ANY_CANDIDATE``, as the scripted agents ask)
``2V+4``               STOP
=====================  =========================================================

A MOVE's cell is the grid cell whose executor waypoint lies straight ahead
in its view at about that distance on the floor
(:func:`ignjax.agents.motion.move_toward`: column 5, row 1 (about 1.4 m)
and row 3 (the executor's 3 m horizon) for the default camera).

The mask (:func:`action_mask`) follows the protocol: the executor never
refuses a MOVE (a heading blocked by an obstacle makes the local controller
slide along it or stop short, :mod:`ignjax.sim.executor`), so every MOVE
stays allowed; the questions are masked once the question budget is spent
(``questions_left == 0``), where the protocol would refuse them (a refused
question costs a step and is recorded, not charged); STOP is always
allowed. An action outside the mask is still executed as the protocol
says (a question is refused), so a policy that ignores the mask learns
nothing wrong.
"""

from __future__ import annotations

from functools import lru_cache

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.agents.motion import move_toward
from ignjax.sim import types as T

SHORT_DISTANCE = 1.4
"""Metres on the floor of the short MOVE's cell (row 1 of the default camera)."""
LONG_DISTANCE = 3.0
"""Metres on the floor of the long MOVE's cell (row 3: the executor's horizon)."""
QUESTION_TYPES = (1, 2, 3, 4)


def n_actions(config: T.SimConfig = T.SimConfig()) -> int:
    """How many discrete actions there are: 2 MOVEs per view, 4 questions, STOP."""
    return 2 * config.n_views + len(QUESTION_TYPES) + 1


@lru_cache(maxsize=16)
def move_cells(config: T.SimConfig = T.SimConfig()) -> tuple[tuple[int, int], tuple[int, int]]:
    """((col, row) of the short MOVE, (col, row) of the long MOVE)."""
    out = []
    with jax.ensure_compile_time_eval():  # constants of the action table, also when asked for under a trace
        for d in (SHORT_DISTANCE, LONG_DISTANCE):
            a = move_toward(0.0, d, config)
            out.append((int(a.col), int(a.row)))
    return tuple(out)


@lru_cache(maxsize=16)
def _table(config: T.SimConfig) -> dict[str, np.ndarray]:
    table = _build_table(config)
    for v in table.values():
        v.setflags(write=False)
    return table


def action_table(config: T.SimConfig = T.SimConfig()) -> dict[str, np.ndarray]:
    """Each action index's simulator action: ``kind``, ``direction``, ``col``, ``row``, ``question`` (int32 arrays, read-only)."""
    return _table(config)


def _build_table(config: T.SimConfig) -> dict[str, np.ndarray]:
    V = config.n_views
    (c1, r1), (c2, r2) = move_cells(config)
    n = n_actions(config)
    kind = np.full(n, T.MOVE, np.int32)
    kind[2 * V:2 * V + 4] = T.ASK
    kind[-1] = T.STOP
    direction = np.zeros(n, np.int32)
    direction[:2 * V] = np.tile(np.arange(V), 2)
    col = np.full(n, c1, np.int32)
    col[V:2 * V] = c2
    row = np.full(n, r1, np.int32)
    row[V:2 * V] = r2
    question = np.ones(n, np.int32)
    question[2 * V:2 * V + 4] = QUESTION_TYPES
    return {"kind": kind, "direction": direction, "col": col, "row": row, "question": question}


def action_names(config: T.SimConfig = T.SimConfig()) -> tuple[str, ...]:
    """A short name per action index (``move_short_0``, ``ask_3``, ``stop``)."""
    V = config.n_views
    return (tuple(f"move_short_{k}" for k in range(V)) + tuple(f"move_long_{k}" for k in range(V))
            + tuple(f"ask_{t}" for t in QUESTION_TYPES) + ("stop",))


def decode(index, config: T.SimConfig = T.SimConfig()) -> T.Action:
    """The simulator's :class:`~ignjax.sim.types.Action` of action indices (any shape; clipped into range)."""
    table = action_table(config)
    i = jnp.clip(jnp.asarray(index, jnp.int32), 0, n_actions(config) - 1)
    pick = lambda name: jnp.asarray(table[name])[i]  # noqa: E731
    return T.Action(pick("kind"), pick("direction"), pick("col"), pick("row"), pick("question"),
                    jnp.full(i.shape, T.ANY_CANDIDATE, jnp.int32))


def action_mask(obs: T.Observation, config: T.SimConfig = T.SimConfig()) -> jax.Array:
    """(n_actions,) bool: the actions the protocol accepts now (one episode; vmap for a batch).

    Reads the agent-visible ``questions_left`` only."""
    V = config.n_views
    ask = jnp.broadcast_to(obs.questions_left > 0, (len(QUESTION_TYPES),))
    return jnp.concatenate([jnp.ones(2 * V, bool), ask, jnp.ones(1, bool)])


__all__ = ["LONG_DISTANCE", "SHORT_DISTANCE", "action_mask", "action_names", "action_table", "decode", "move_cells",
           "n_actions"]
