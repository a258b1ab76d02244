"""The simulator: pure ``reset`` / ``step`` / ``observe`` / ``outcome`` for ONE episode.

Batching is ``jax.vmap`` applied once, by the caller; the
:class:`~ignjax.sim.world.World` (scene bank + goal fields) is passed
unbatched. :func:`step_batch`, :func:`~ignjax.sim.executor.execute_moves`
and :func:`observe_batch` are the same transitions for a batch, organised so
that rows pay only for the work they need (used by
:func:`ignjax.sim.rollout.rollout_rows`); the one-episode :func:`step` is
:func:`step_batch` on a batch of one, so there is one executor.

This module is the simulator's public face (what a rollout calls); the
pieces live beside it: :mod:`ignjax.sim.world` (the World and its probe
map), :mod:`ignjax.sim.queries` (scene look-ups), :mod:`ignjax.sim.executor`
(MOVE), :mod:`ignjax.sim.oracle` (ASK; words in :mod:`ignjax.sim.oracle_text`),
:mod:`ignjax.sim.observation` (:func:`observe`, :func:`observe_batch`) and
:mod:`ignjax.sim.types` (the pytrees).

Protocol (paper §3.3, Appendix C; constants in :class:`~ignjax.sim.types.SimConfig`):

* Every decision is one planner step: MOVE, ASK or STOP. The episode ends
  on STOP or after ``max_steps`` steps; finished episodes stay finished.
* **MOVE** (view k, cell (col, row)) - the executor takes the cell's centre
  pixel (Eq. grid-to-pixel), casts the pixel's ray (voxel traversal with
  exact primitive tests, :func:`ignjax.sim.rays.queries.march`) and
  back-projects it with the view's intrinsics and the found depth
  (Eqs. camera-backproject / camera-to-world). A pixel with no valid depth
  within ``depth_range`` falls back to the floor-plane intersection (Eq.
  floor-intersection); a ray that meets neither (it points above the
  horizon into open space) uses its horizontal direction. The point is
  projected to the floor, pulled back ``pullback`` metres towards the agent
  when the ray hit an obstacle (not the floor), and clipped to ``horizon``.
  The local controller then moves toward that waypoint in micro-steps of at
  most ``micro_step``: before each, it recomputes distance and bearing to
  the waypoint (Eq. relative-target), turns toward it and casts forward
  rays at ``collision_heights``; an obstacle within ``collision_distance``
  makes it take the nearest collision-free neighbouring heading (45 degree
  steps, left first on ties) and record the blocked heading. A heading
  counts as free only when its rays are clear and its micro-step (or half
  of it) ends on a navigable cell, so the agent slides along walls instead
  of stopping at the edge of its clearance band, and it never ends inside
  an obstacle or outside the navigable area. With no free heading the MOVE
  ends. The agent faces its last direction of motion.
* **ASK** t - charged one type-t question unless ``max_questions`` have
  been charged (then refused: recorded, not charged). Type 1 and 2 answers
  are the episode's fixed facts (cached after the first ask; every repeat
  is charged again). Type 3 follows the target's geodesic field downhill
  for ``hint_lookahead`` metres from the agent and reports the room it
  leads toward, the egocentric sector of the way out (or of the route's
  end when it stays in the room) and a landmark near its end; it also
  activates a persistent hint whose qualitative progress (closer, farther,
  reached, stop-eligible) and current bearing (the sector, relative to the
  agent's new facing, in which the hinted point lies) are updated after
  every MOVE; the bearing is first set when the hint is given. Type 4 says yes only if the target (or the queried
  candidate, which must then be the target) is visible in the current
  front view within ``confirm_range`` metres; a yes starts the follow-up
  (stop now within ``stop_radius``, else one closer move then stop: the
  next MOVE turns the follow-up into "stop now"). Answers reach the agent
  as codes only (:data:`~ignjax.sim.types.AGENT_FIELDS`); the route's
  world point stays in the state (``SimState.hint_point``).
* **STOP** ends the episode.

Distances: the geodesic distance to the target is read from the target's
geodesic field (seeded around its footprint, :func:`ignjax.scenes.bank.target_field`);
success is judged on it by default (Habitat's convention). The Euclidean
distance to the footprint is reported too.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.errors import ConfigError
from ignjax.sim import types as T
from ignjax.sim.compact import masked_map
from ignjax.sim.executor import execute_moves, pixel_waypoint
from ignjax.sim.observation import observe, observe_all, observe_batch
from ignjax.sim.oracle import ask, describe_upfront, hint_bearing, hint_progress
from ignjax.sim.queries import euclidean_to_target, geodesic_to_target
from ignjax.sim.world import World


# ---------------------------------------------------------------------------
# reset
# ---------------------------------------------------------------------------


NOISE_STREAM = 0x6E6F
"""Folded into an episode's key for its perception noise (:func:`noise_key`),
so the noise is independent of the agent's randomness."""


def noise_key(key: jax.Array) -> jax.Array:
    """(2,) uint32 key data of an episode's perception noise, from the episode's key."""
    return jax.random.key_data(jax.random.fold_in(key, NOISE_STREAM)).reshape(-1)[:2].astype(jnp.uint32)


def reset(world: World, episode: T.EpisodeSpec, key: jax.Array | None = None) -> T.SimState:
    """Initial state of one episode. Deterministic but for the perception
    noise (``SimConfig.miss_rate``, ``confusion_rate``), drawn from ``key``
    (the episode's key; None: a fixed key). With
    ``SimConfig.upfront_description`` the Type-1 and Type-2 facts are given
    and charged here."""
    cfg = world.config
    start = episode.start.astype(jnp.float32)
    d0 = geodesic_to_target(world, episode, start[:2])
    nk = noise_key(jax.random.key(0) if key is None else key)
    state = T.SimState(
        episode=episode, pose=start, step=jnp.int32(0), n_questions=jnp.zeros(4, jnp.int32), n_refused=jnp.int32(0),
        n_invalid=jnp.int32(0), trace_type=jnp.zeros(cfg.trace_slots, jnp.int32),
        trace_step=jnp.full(cfg.trace_slots, -1, jnp.int32), trace_charged=jnp.zeros(cfg.trace_slots, bool),
        n_trace=jnp.int32(0), path_length=jnp.float32(0.0), min_distance=d0.astype(jnp.float32),
        done=~episode.valid, stop_reason=jnp.int32(T.RUNNING), blocked=jnp.zeros(8, bool), last_move=jnp.float32(0.0),
        waypoint=start[:2], moves_since_confirm=jnp.int32(0), hint_point=jnp.zeros(2, jnp.float32), noise_key=nk,
        answers=T.Answer.empty(),
    )
    return describe_upfront(world, state) if cfg.upfront_description else state


# ---------------------------------------------------------------------------
# step
# ---------------------------------------------------------------------------


def sanitize_action(action: T.Action, n_views: int = T.N_VIEWS) -> tuple[T.Action, jax.Array]:
    """Clamp an action into range (direction: view 0..n_views-1); returns
    (clamped action, was_invalid)."""
    kind = jnp.clip(action.kind, 0, 2)
    d = jnp.clip(action.direction, 0, n_views - 1)
    c = jnp.clip(action.col, 1, 8)
    r = jnp.clip(action.row, 1, 8)
    q = jnp.clip(action.question, 1, 4)
    bad = (kind != action.kind) | ((kind == T.MOVE) & ((d != action.direction) | (c != action.col) | (r != action.row))) \
        | ((kind == T.ASK) & (q != action.question))
    return T.Action(kind, d, c, r, q, action.candidate), bad


def step_batch(world: World, states: T.SimState, actions: T.Action, chunk: int | None = None) -> T.SimState:
    """One planner step of a batch of episodes (leading axis B); finished episodes stay put.

    Row for row the same as :func:`step`; the executor runs for the rows that
    MOVE and the oracle for the rows that ASK only (:func:`~ignjax.sim.executor.execute_moves`,
    :func:`ignjax.sim.compact.masked_map`)."""
    with jax.named_scope("sim_step"):
        cfg = world.config
        act, bad, is_move, is_ask = step_kinds(world, states, actions)
        is_stop = act.kind == T.STOP

        # MOVE
        pose, moved, dmin, blocked, wp = execute_moves(world, states, act.direction, act.col, act.row, is_move, chunk)
        a = states.answers
        progress = jax.vmap(lambda e, ans, hp, p0, p1: hint_progress(world, e, ans, hp, p0, p1))(
            states.episode, a, states.hint_point, states.pose[:, :2], pose[:, :2])
        bearing = jax.vmap(hint_bearing)(states.hint_point, pose, a.hint_active)
        # the Type-4 follow-up: after the one closer move, "stop now"
        follow = jnp.where(a.follow_up == T.FOLLOW_ONE_MOVE, T.FOLLOW_STOP_NOW, a.follow_up).astype(jnp.int32)
        moved_state = dataclasses.replace(
            states, pose=pose, path_length=states.path_length + moved, min_distance=dmin, blocked=blocked,
            last_move=moved, waypoint=wp, moves_since_confirm=states.moves_since_confirm + 1,
            answers=dataclasses.replace(a, hint_progress=progress, hint_bearing=bearing, follow_up=follow),
        )
        # ASK
        asked_state = ask_rows(world, states, act, is_ask, chunk)
        nxt = T.tree_select(is_move, moved_state, T.tree_select(is_ask, asked_state, states))
        n_step = states.step + 1
        stop_reason = jnp.where(is_stop, T.STOPPED, jnp.where(n_step >= cfg.max_steps, T.OUT_OF_STEPS, T.RUNNING))
        nxt = dataclasses.replace(
            nxt, step=n_step, n_invalid=states.n_invalid + bad.astype(jnp.int32),
            done=stop_reason != T.RUNNING, stop_reason=stop_reason.astype(jnp.int32),
        )
        return T.tree_select(states.done, states, nxt)


def step_kinds(world: World, states: T.SimState, actions: T.Action):
    """The actions of a batch made valid (:func:`sanitize_action`) and which
    unfinished rows MOVE and which ASK: (action, invalid (B,), is_move (B,), is_ask (B,))."""
    act, bad = jax.vmap(lambda a: sanitize_action(a, world.config.n_views))(actions)
    live = ~states.done
    return act, bad, (act.kind == T.MOVE) & live, (act.kind == T.ASK) & live


def ask_rows(world: World, states: T.SimState, act: T.Action, is_ask, chunk: int | None = None) -> T.SimState:
    """The oracle's answers for the rows in ``is_ask`` (the others' states unchanged)."""
    return masked_map(lambda x: ask(world, *x), is_ask, (states, act.question, act.candidate), states, chunk)


def step(world: World, state: T.SimState, action: T.Action) -> T.SimState:
    """One planner step of one episode (pure). Finished episodes stay put."""
    return T.only_row(step_batch(world, T.batch_of_one(state), T.batch_of_one(action)))


# ---------------------------------------------------------------------------
# outcomes and privileged information
# ---------------------------------------------------------------------------


def outcome(world: World, state: T.SimState) -> T.OutcomeRow:
    """The outcome row of a (finished) episode."""
    ep = state.episode
    xy = state.pose[:2]
    return T.OutcomeRow(
        final_distance=geodesic_to_target(world, ep, xy), final_euclidean=euclidean_to_target(world, ep, xy),
        min_distance=state.min_distance, path_length=state.path_length, steps=state.step,
        stopped=state.stop_reason == T.STOPPED, stop_reason=state.stop_reason, n_questions=state.n_questions,
        n_refused=state.n_refused, n_invalid=state.n_invalid, trace_type=state.trace_type, trace_step=state.trace_step,
        trace_charged=state.trace_charged, difficulty=ep.difficulty, valid=ep.valid,
    )


def privileged_info(world: World, state: T.SimState) -> T.Privileged:
    """Planning information for privileged agents (never for others): the
    executor's waypoint of every candidate cell, scored by the target's
    geodesic field."""
    ep = state.episode
    views, cols, rows = jnp.meshgrid(jnp.arange(8), jnp.array([3, 4, 5, 6]), jnp.array([1, 2, 3]), indexing="ij")
    views, cols, rows = views.reshape(-1), cols.reshape(-1), rows.reshape(-1)
    wps = jax.vmap(lambda d, c, r: pixel_waypoint(world, ep.scene, state.pose, d, c, r)[0])(views, cols, rows)
    vals = jax.vmap(lambda xy: geodesic_to_target(world, ep, xy))(wps)
    moved = jnp.linalg.norm(wps - state.pose[None, :2], axis=1)
    vals = jnp.where(moved > 0.2, vals, jnp.inf)  # a cell that goes nowhere is no plan
    k = jnp.argmin(vals)
    return T.Privileged(geodesic=geodesic_to_target(world, ep, state.pose[:2]), best_direction=views[k].astype(jnp.int32),
                        best_col=cols[k].astype(jnp.int32), best_row=rows[k].astype(jnp.int32), best_value=vals[k])



# ---------------------------------------------------------------------------
# API-boundary checks (host)
# ---------------------------------------------------------------------------


def check_action(action: T.Action, n_views: int = T.N_VIEWS) -> None:
    """Reject out-of-range actions at the API boundary (host side); a MOVE's
    direction is a view 0..n_views-1.

    Raises:
        ConfigError: naming the field and the allowed range.
    """
    a = jax.tree.map(np.asarray, action)
    for name, lo, hi in (("kind", 0, 2), ("direction", 0, n_views - 1), ("col", 1, 8), ("row", 1, 8), ("question", 1, 4)):
        v = getattr(a, name)
        if np.any((v < lo) | (v > hi)):
            raise ConfigError(None, f"action.{name}", f"must lie in {lo}..{hi}, got {v.tolist()}")


def check_specs(world: World, specs: T.EpisodeSpec) -> None:
    """Reject a batch whose scene, target or field indices do not exist in
    ``world`` (host side, before anything is traced).

    Raises:
        ConfigError: naming the first offending episode row and index.
    """
    scene = np.asarray(specs.scene)
    target = np.asarray(specs.target)
    fld = np.asarray(specs.field)
    n_scenes = len(world.bank.scene_ids)
    n_inst = np.asarray(world.bank.instances.valid)
    n_fields = len(world.fields)
    for k in range(scene.shape[0]):
        if not 0 <= scene[k] < n_scenes:
            raise ConfigError(None, f"episodes[{k}].scene", f"scene index {int(scene[k])} is not in the bank ({n_scenes} scenes)")
        if not (0 <= target[k] < n_inst.shape[1] and n_inst[scene[k], target[k]]):
            raise ConfigError(None, f"episodes[{k}].target", f"instance index {int(target[k])} is not in scene {world.bank.scene_ids[scene[k]]!r}")
        if not 0 <= fld[k] < n_fields:
            raise ConfigError(None, f"episodes[{k}].field", f"field index {int(fld[k])} does not exist ({n_fields} fields)")


__all__ = [
    "reset", "step", "step_batch", "sanitize_action", "observe", "observe_all", "observe_batch", "outcome", "privileged_info", "check_action",
    "check_specs",
]
