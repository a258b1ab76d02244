"""Where a decision step's time goes: the ``pieces`` block of ``python -m ignjax.bench``.

The rollout is one fused program, so XLA's profile cannot say how much of
a decision step each part of the simulator costs. This block cuts the step
into its pieces and runs each as a program of its own, driven by a host
loop over the steps of the same episodes the rollout runs:

* **agent** - the agent's decision for every row (``agent.act`` in chunks,
  as the rollout calls it);
* **waypoint** - the MOVEs' pixel rays, depth rays and waypoints
  (:func:`ignjax.sim.executor.move_waypoints`);
* **probes** - the controller's micro-steps and their collision and
  navigability probes (:func:`ignjax.sim.executor.micro_steps`);
* **oracle** - the answers of the ASKs (:func:`ignjax.sim.env.ask_rows`);
* **step_other** - the rest of :func:`ignjax.sim.env.step_batch` (route-hint
  progress, state bookkeeping): the whole step's time less the three above,
  each of which the step runs once more;
* **observation** - the perception of the rows that moved
  (:func:`ignjax.sim.observation.observe_batch`);
* **privileged** - shortest-path information, for agents that receive it.

Each figure is the piece's seconds summed over the steps, per decision
step (one MOVE, ASK or STOP of an unfinished episode), in microseconds.
The pieces run on one device, on the rows and at the vectorised widths
that device runs in the sharded rollout at the bench's batch size (at
B = 4096 over two CPU devices: 2048 rows in chunks of 512), so the figures
are one device's time per decision. ``whole`` is the fused rollout of the
same rows on that device, timed in the same run; ``sum`` exceeds it by what
fusing the pieces into one program saves (and by the three pieces the
step runs twice counted once here). ``decisions`` of the host loop and of
the rollout are both reported: the pieces are compiled apart, and a
float rounding that differs between programs can change a rare episode.
"""

from __future__ import annotations

import time
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.agents import get_agent
from ignjax.bench.timing import log
from ignjax.sim import env as E
from ignjax.sim import executor as X
from ignjax.sim import types as T
from ignjax.sim.compact import masked_map
from ignjax.sim.observation import observe_batch
from ignjax.sim.rollout import (ROLLOUT_COMPILER_OPTIONS, batch_parts, episode_keys, rollout, rollout_start,
                                shard_layout)

PIECES = ("agent", "waypoint", "probes", "oracle", "step_other", "observation", "privileged")
_jit = partial(jax.jit, compiler_options=ROLLOUT_COMPILER_OPTIONS)


@partial(_jit, static_argnames=("agent", "act_chunk"))
def _act(params, obs, answers, pstate, k, priv, *, agent, act_chunk):
    return jax.lax.map(lambda x: agent.act(*x), (params, obs, answers, pstate, k, priv), batch_size=act_chunk)


@partial(_jit, static_argnames=("chunk",))
def _waypoint(world, state, action, *, chunk):
    act, _, is_move, _ = E.step_kinds(world, state, action)
    return X.move_waypoints(world, state, act.direction, act.col, act.row, is_move, chunk)


@partial(_jit, static_argnames=("chunk",))
def _probes(world, state, action, wp, *, chunk):
    _, _, is_move, _ = E.step_kinds(world, state, action)
    return X.micro_steps(world, state, wp, is_move, chunk)


@partial(_jit, static_argnames=("chunk",))
def _oracle(world, state, action, *, chunk):
    act, _, _, is_ask = E.step_kinds(world, state, action)
    return E.ask_rows(world, state, act, is_ask, chunk)


@partial(_jit, static_argnames=("chunk",))
def _step(world, state, action, *, chunk):
    return E.step_batch(world, state, action, chunk)


@partial(_jit, static_argnames=("chunk",))
def _observe(world, state, obs, moved, *, chunk):
    return observe_batch(world, state, obs, moved, chunk)


@partial(_jit, static_argnames=("chunk",))
def _privileged(world, state, priv, *, chunk):
    return masked_map(lambda st: E.privileged_info(world, st), ~state.done, state, priv, chunk)


@partial(_jit, static_argnames=("agent",))
def _start(world, specs, params, keys, *, agent):
    return rollout_start(world, specs, agent, params, keys)


def _pieces_loop(world, specs, agent, params, keys, widths, clock: dict | None):
    """Run the rollout's steps piece by piece; with ``clock``, add each
    piece's seconds to it. Returns the decision steps taken."""
    act_chunk, chunk, _ = widths
    state, obs, pstate, priv, step_keys = _start(world, specs, params, keys, agent=agent)

    def run(name, fn, *args, **kw):
        t = time.perf_counter()
        out = jax.block_until_ready(fn(*args, **kw))
        if clock is not None:
            clock[name] += time.perf_counter() - t
        return out

    decisions = 0
    for k in step_keys:
        live = ~np.asarray(state.done)
        if not live.any():
            break
        decisions += int(live.sum())
        action, pstate = run("agent", _act, params, obs, state.answers, pstate, k, priv, agent=agent,
                             act_chunk=act_chunk)
        wp = run("waypoint", _waypoint, world, state, action, chunk=chunk)
        run("probes", _probes, world, state, action, wp, chunk=chunk)
        run("oracle", _oracle, world, state, action, chunk=chunk)
        new = run("step", _step, world, state, action, chunk=chunk)
        moved = jnp.asarray(live & (np.clip(np.asarray(action.kind), 0, 2) == T.MOVE))
        obs = run("observation", _observe, world, new, obs, moved, chunk=chunk)
        if agent.privileged:
            priv = run("privileged", _privileged, world, new, priv, chunk=chunk)
        state = new
    return decisions


def bench_pieces(es, world, agents, batch: int, repeats: int = 2) -> dict:
    """Microseconds per decision step of each piece of the step (module
    docstring) for each agent, on the first device's share of a rollout of
    ``batch`` episodes of ``es``; the best of ``repeats`` host loops after a
    compiling one, and the fused rollout of the same rows beside them."""
    parts = batch_parts(batch)
    rows, widths = shard_layout(batch, parts)
    rows = min(rows, batch)
    dev = jax.local_devices()[0]
    idx = np.arange(rows) % len(es)
    specs = jax.device_put(jax.tree.map(lambda a: a[idx], es.specs), dev)
    keys = jax.device_put(episode_keys(0, np.arange(rows)), dev)
    world = jax.device_put(world, dev)
    out: dict = {"batch": batch, "rows": rows, "act_chunk": widths[0], "chunk": widths[1], "agents": {}}
    for name in agents:
        agent = get_agent(name)
        base = agent.default_params()
        params = jax.tree.map(lambda x: jnp.broadcast_to(x, (rows,) + jnp.shape(x)), base)
        _pieces_loop(world, specs, agent, params, keys, widths, None)  # compiles every piece
        best: dict = {}
        for _ in range(repeats):
            clock = dict.fromkeys(PIECES + ("step",), 0.0)
            decisions = _pieces_loop(world, specs, agent, params, keys, widths, clock)
            best = {p: min(best.get(p, np.inf), clock[p]) for p in clock}
        whole = lambda: jax.block_until_ready(rollout(world, specs, agent, base, keys,  # noqa: E731
                                                      chunk=widths[1], parts=1))
        res = whole()
        t_whole = np.inf
        for _ in range(repeats):
            t = time.perf_counter()
            whole()
            t_whole = min(t_whole, time.perf_counter() - t)
        rollout_decisions = int(np.asarray(res[0].steps).sum())
        us = {p: 1e6 * best[p] / decisions for p in best}
        us["step_other"] = us["step"] - us["waypoint"] - us["probes"] - us["oracle"]
        figures = {p: us[p] for p in PIECES if p != "privileged" or agent.privileged}
        figures["sum"] = sum(figures.values())
        figures["whole"] = 1e6 * t_whole / rollout_decisions
        out["agents"][name] = {"us_per_decision": figures, "decisions": decisions,
                               "rollout_decisions": rollout_decisions}
        log(f"  {name:14s} " + ", ".join(f"{p} {v:.1f}" for p, v in figures.items()) + " us per decision")
    return out
