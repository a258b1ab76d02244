"""The observation: what a policy may see of one episode (free-space rays
per view, visible instances, the room it stands in, budgets and odometry;
never the target's identity, pose or distance), and the batched update
that recomputes the perception only for the rows that moved.
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import jax
import jax.numpy as jnp

from ignjax.scenes import vocab
from ignjax.sim import compact
from ignjax.sim import geometry as G
from ignjax.sim import types as T
from ignjax.sim.rays import queries as SR
from ignjax.sim.compact import masked_map
from ignjax.sim.queries import SIGHT_POINTS, instance_in_sight, room_at, sector_of, sight_lines, sight_samples
from ignjax.sim.world import World, first_occupied, free_of_index, march_free, packed_at


FIRST_PASS = 1 / 3
"""Share of a free-space ray's or a sight line's samples that
:func:`sight_batch` marches for every ray; only the rays with nothing in
the way within it (and, for a sight line, still short of the instance) march
the rest."""


class Sight(NamedTuple):
    """One pose's ray-cast perception, before any perception noise."""

    free_space: jax.Array  # (8, R) free-space rays, m
    nearest: jax.Array  # (K,) int32 the K nearest non-structural instances within range
    distance: jax.Array  # (K,) their horizontal distances, +inf beyond range
    in_sight: jax.Array  # (K,) bool nothing blocks every sight line to it (and it lies within range)


def _ray_headings(cfg: T.SimConfig, yaw):
    """(8, R) headings of the free-space rays of a pose with heading ``yaw``."""
    R = cfg.obs_rays_per_view
    half_fov = math.radians(cfg.hfov) / 2
    within = (jnp.arange(R, dtype=jnp.float32) + 0.5) / R * (2 * half_fov) - half_fov  # Shape: (R,)
    rel = (jnp.arange(8, dtype=jnp.float32) * (math.pi / 4))[:, None] + within[None]  # Shape: (8, R)
    return yaw + rel


def _free_occupied(world: World, s):
    """The free-space rays' test of sample points of scene ``s``: an obstacle at eye height or LOW_OBS_HEIGHT."""
    return lambda p: packed_at(world, world.packed_obs, 2, s, p) != 0


def _free_samples(world: World) -> tuple[float, int]:
    """(step, samples) of a free-space ray: every two navigation cells up to ``obs_range``."""
    step = 2 * world.bank.grid.resolution
    return step, int(math.ceil(world.config.obs_range / step))


def _first_pass(n: int) -> int:
    return max(1, min(n, int(round(n * FIRST_PASS))))


def _nearest(world: World, s, pose):
    """(K,) the K nearest non-structural instances within ``obs_range`` and their horizontal distances."""
    cfg = world.config
    inst = world.bank.instances
    cand = inst.valid[s] & ~inst.structural[s]
    d = jnp.linalg.norm(inst.center[s, :, :2] - pose[None, :2], axis=1)
    d = jnp.where(cand & (d <= cfg.obs_range), d, jnp.inf)
    K = min(cfg.max_visible, inst.valid.shape[1])
    neg, idx = jax.lax.top_k(-d, K)
    return idx, -neg


def _eye(cfg: T.SimConfig, pose):
    return jnp.array([pose[0], pose[1], cfg.eye_height], jnp.float32)


def sight_of(world: World, state: T.SimState) -> Sight:
    """One episode's :class:`Sight`: every ray marched to its end."""
    cfg = world.config
    s, pose = state.episode.scene, state.pose
    step, n = _free_samples(world)
    free_space = jax.vmap(jax.vmap(lambda h: march_free(_free_occupied(world, s), pose[:2], h, cfg.obs_range,
                                                        step)))(_ray_headings(cfg, pose[2]))
    idx, dist = _nearest(world, s, pose)
    eye = _eye(cfg, pose)
    seen = jax.vmap(lambda i: instance_in_sight(world, s, i, eye))(idx) & jnp.isfinite(dist)
    return Sight(free_space, idx, dist, seen)


def sight_batch(world: World, states: T.SimState, mask, chunk: int | None = None) -> Sight:
    """The :class:`Sight` of the rows in ``mask`` of a batch (leading axis B;
    other rows' rays read 0 / False), the same values as :func:`sight_of`'s,
    marched in two passes. Every free-space ray and sight line takes its
    first :data:`FIRST_PASS` of the samples; only the rays still clear, and
    for a sight line still short of the instance's box, take the rest,
    compacted (:func:`ignjax.sim.compact.masked_map`); a sight line is not
    marched further when the instance's other sight line is already clear,
    nor at all for an instance out of range. Exact: each sample is the same
    computation, and a ray's answer is decided by its first occupied sample.
    Under :func:`ignjax.sim.compact.one_pass`, :func:`sight_of` of each selected row."""
    if compact.ONE_PASS:
        return _sight_one_pass(world, states, mask, chunk)
    cfg = world.config
    rays = world.bank.rays
    f_step, f_n = _free_samples(world)
    l_step, l_n = sight_samples(world)
    f_first, l_first = _first_pass(f_n), _first_pass(l_n)
    s, pose = states.episode.scene, states.pose
    B = s.shape[0]
    V, R = 8, cfg.obs_rays_per_view
    K = min(cfg.max_visible, world.bank.instances.valid.shape[1])

    def first_pass(a):
        s_, pose_ = a
        heads = _ray_headings(cfg, pose_[2])
        i1 = jax.vmap(jax.vmap(lambda h: first_occupied(_free_occupied(world, s_), pose_[:2], h, f_step, 0, f_first)))(heads)
        idx, dist = _nearest(world, s_, pose_)
        eye = _eye(cfg, pose_)
        u, limit = jax.vmap(lambda i: sight_lines(world, s_, i, eye))(idx)  # Shape: (K, 2, 3), (K, 2)
        b1 = jax.vmap(jax.vmap(lambda u_, l_: SR.segment_blocked(rays, s_, eye, u_, l_, l_step, 0, l_first,
                                                                 world.columns)))(u, limit)
        return heads, i1, idx, dist, u, limit, b1

    default = (jnp.zeros((B, V, R), jnp.float32), jnp.full((B, V, R), f_n, jnp.int32), jnp.zeros((B, K), jnp.int32),
               jnp.full((B, K), jnp.inf, jnp.float32), jnp.zeros((B, K, SIGHT_POINTS, 3), jnp.float32),
               jnp.zeros((B, K, SIGHT_POINTS), jnp.float32), jnp.zeros((B, K, SIGHT_POINTS), bool))
    heads, i1, idx, dist, u, limit, b1 = masked_map(first_pass, mask, (s, pose), default, chunk)

    # free-space rays with no obstacle in the first pass march the rest
    far = (mask[:, None, None] & (i1 == f_first)).reshape(-1)
    args = (jnp.repeat(s, V * R), jnp.repeat(pose[:, :2], V * R, axis=0), heads.reshape(-1))
    i = masked_map(lambda a: first_occupied(_free_occupied(world, a[0]), a[1], a[2], f_step, f_first, f_n), far, args,
                   i1.reshape(-1), None if chunk is None else chunk * V * R)
    free_space = jnp.where(mask[:, None, None], free_of_index(i.reshape(B, V, R), cfg.obs_range, f_step), 0.0)

    # sight lines still clear and short of the box march the rest, unless the other line is already clear
    live = (mask[:, None] & jnp.isfinite(dist))[..., None] & ~b1
    more = limit >= (jnp.arange(1, l_n + 1, dtype=jnp.float32) * l_step)[l_first]  # the next sample is checked
    clear = live & ~more
    need = live & more & ~jnp.any(clear, axis=-1, keepdims=True)
    P = K * SIGHT_POINTS
    eyes = jax.vmap(lambda p: _eye(cfg, p))(pose)
    args = (jnp.repeat(s, P), jnp.repeat(eyes, P, axis=0), u.reshape(-1, 3), limit.reshape(-1))
    b2 = masked_map(lambda a: SR.segment_blocked(rays, a[0], a[1], a[2], a[3], l_step, l_first, l_n, world.columns),
                    need.reshape(-1), args, jnp.zeros(B * P, bool), None if chunk is None else chunk * P)
    clear = clear | (need & ~b2.reshape(need.shape))
    valid = jax.vmap(lambda s_, i_: world.bank.instances.valid[s_, i_])(s, idx)
    in_sight = jnp.any(clear, axis=-1) & valid & jnp.isfinite(dist) & mask[:, None]
    return Sight(free_space, idx, dist, in_sight)


def _sight_one_pass(world: World, states: T.SimState, mask, chunk: int | None) -> Sight:
    """:func:`sight_batch`'s one-pass form: :func:`sight_of` (every ray marched to its end) of the rows in ``mask``."""
    B = mask.shape[0]
    R, K = world.config.obs_rays_per_view, min(world.config.max_visible, world.bank.instances.valid.shape[1])
    default = Sight(jnp.zeros((B, 8, R), jnp.float32), jnp.zeros((B, K), jnp.int32),
                    jnp.full((B, K), jnp.inf, jnp.float32), jnp.zeros((B, K), bool))
    return masked_map(lambda st: sight_of(world, st), mask, states, default, chunk)


def observe(world: World, state: T.SimState, sight: Sight | None = None) -> T.Observation:
    """What the policy sees (no target identity, pose or distance inside).
    Perception is exact unless ``SimConfig.miss_rate`` / ``confusion_rate``
    make it noisy (:func:`perception_noise`). ``sight``: the pose's
    :class:`Sight` if already computed (:func:`sight_batch`), else :func:`sight_of`."""
    with jax.named_scope("observe"):
        cfg = world.config
        bank = world.bank
        s = state.episode.scene
        pose = state.pose
        free_space, idx, dist, seen = sight_of(world, state) if sight is None else sight
        # visible instances: K nearest non-structural instances, kept when in sight
        inst = bank.instances
        K = idx.shape[0]
        bearing = G.wrap_angle(jnp.arctan2(inst.center[s, idx, 1] - pose[1], inst.center[s, idx, 0] - pose[0]) - pose[2])
        attrs = jnp.stack([inst.color[s, idx], inst.material[s, idx], inst.size[s, idx], inst.state[s, idx]], -1)
        if cfg.miss_rate > 0 or cfg.confusion_rate > 0:
            seen, attrs = perception_noise(cfg, state.noise_key, pose, idx, dist, 2 * jnp.max(inst.half_extents[s, idx], axis=1),
                                           seen, attrs)
        handle = jnp.where(seen, idx, -1).astype(jnp.int32)
        pad = cfg.max_visible - K

        def padk(x, fill):
            return jnp.concatenate([x, jnp.full((pad,) + x.shape[1:], fill, x.dtype)]) if pad > 0 else x

        room = room_at(world, s, pose[:2])
        label = jnp.where(room >= 0, bank.rooms.label[s, jnp.maximum(room, 0)], -1)
        return T.Observation(
            free_space=free_space, visible_handle=padk(handle, -1),
            visible_category=padk(jnp.where(seen, inst.category[s, idx], -1).astype(jnp.int32), -1),
            visible_attrs=padk(jnp.where(seen[:, None], attrs, -1).astype(jnp.int32), -1),
            visible_range=padk(jnp.where(seen, dist, jnp.inf), jnp.inf),
            visible_bearing=padk(jnp.where(seen, bearing, 0.0), 0.0),
            visible_view=padk(jnp.where(seen, sector_of(bearing), -1), -1),
            room_label=label.astype(jnp.int32), **state_fields(world, state),
        )


NOISE_RANGE = 3.0
"""Distance (m) at which ``miss_rate`` / ``confusion_rate`` apply as given (to an object :data:`NOISE_SIZE` across)."""
NOISE_SIZE = 0.5
"""Object size (m, largest box extent) at which the noise rates apply as given."""
ATTRIBUTE_VALUES = (len(vocab.COLORS), len(vocab.MATERIALS), len(vocab.SIZES), len(vocab.STATES))
"""Number of values of each perceived attribute (colour, material, size, state)."""


def perception_noise(cfg: T.SimConfig, key_data, pose, idx, dist, size, seen, attrs):
    """Noisy perception of the K nearest instances: each instance in sight is
    missed with probability ``miss_rate * (d / 3 m) * (0.5 m / size)`` and
    each of its attributes replaced by another value with probability
    ``confusion_rate`` times the same factor (clipped to [0, 1]).

    The draws are a pure function of the episode's noise key, the instance
    and the pose rounded to 1 cm and 0.01 rad: the same view gives the same
    detections (an agent that does not move sees the same thing), and every
    batch layout the same.

    Returns:
        (seen (K,) bool, attrs (K, 4) int32).
    """
    factor = (dist / NOISE_RANGE) * (NOISE_SIZE / jnp.maximum(size, 0.05))
    key = jax.random.wrap_key_data(key_data)
    # keyed on the pose rounded to 1 cm and 0.01 rad: float rounding of the pose (which can differ
    # between batch layouts) does not redraw the noise
    for v in jnp.round(pose * 100.0).astype(jnp.int32):
        key = jax.random.fold_in(key, v.astype(jnp.uint32))
    keys = jax.vmap(lambda i: jax.random.fold_in(key, i))(idx)
    u = jax.vmap(lambda k: jax.random.uniform(k, (9,)))(keys)  # Shape: (K, 9): miss, 4 confusions, 4 replacements
    p_miss = jnp.clip(cfg.miss_rate * factor, 0.0, 1.0)
    seen = seen & (u[:, 0] >= jnp.where(jnp.isfinite(factor), p_miss, 1.0))
    n = jnp.asarray(ATTRIBUTE_VALUES, jnp.int32)
    p_conf = jnp.clip(cfg.confusion_rate * factor, 0.0, 1.0)[:, None]
    shift = 1 + jnp.floor(u[:, 5:] * (n - 1)).astype(jnp.int32)  # another value: 1..n-1 steps along the list
    confused = (u[:, 1:5] < p_conf) & (attrs >= 0) & (n > 1)
    attrs = jnp.where(confused, (attrs + shift) % n, attrs)
    return seen, attrs.astype(jnp.int32)


def state_fields(world: World, state: T.SimState) -> dict:
    """The observation's fields read from the state alone (heading, odometry, budgets, last MOVE)."""
    cfg = world.config
    pose, start = state.pose, state.episode.start
    return dict(
        heading=pose[2], odometry=jnp.stack([pose[0] - start[0], pose[1] - start[1], G.wrap_angle(pose[2] - start[2])]),
        goal_category=state.episode.category, steps_left=jnp.int32(cfg.max_steps) - state.step,
        questions_left=(jnp.int32(cfg.max_questions) - jnp.sum(state.n_questions)) if cfg.question_budget
        else jnp.int32(cfg.max_steps) - state.step,
        n_questions=state.n_questions, blocked=state.blocked, last_move=state.last_move,
    )


def observe_all(world: World, states: T.SimState, chunk: int | None = None) -> T.Observation:
    """:func:`observe` of every row of a batch (leading axis B), the rays
    marched together in two passes (:func:`sight_batch`)."""
    sight = sight_batch(world, states, jnp.ones(states.pose.shape[0], bool), chunk)
    return jax.vmap(lambda st, si: observe(world, st, si))(states, sight)


def observe_batch(world: World, states: T.SimState, previous: T.Observation, moved, chunk: int | None = None) -> T.Observation:
    """:func:`observe` of a batch (leading axis B) after a step: the
    perception (rays, visible instances, room) is recomputed for the rows in
    ``moved`` only; every other row's pose is unchanged, so it keeps
    ``previous``'s perception with its state fields refreshed. The free-space
    rays and sight lines of the moved rows are marched together first (:func:`sight_batch`).
    Row for row the same as ``vmap(observe)``."""
    sight = sight_batch(world, states, moved, chunk)
    # gathered back: faster here than writing into ``previous`` in the loop (docs/performance.md)
    obs = masked_map(lambda a: observe(world, *a), moved, (states, sight), previous, chunk, gather_back=True)
    return dataclasses.replace(obs, **jax.vmap(lambda st: state_fields(world, st))(states))
