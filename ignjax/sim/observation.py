"""The observation: what a policy may see of one episode (free-space rays
per view, visible instances, the room it stands in, budgets and odometry;
never the target's identity, pose or distance), and the batched update
that recomputes the perception only for the rows that moved.
"""

from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp

from ignjax.scenes import vocab
from ignjax.sim import geometry as G
from ignjax.sim import types as T
from ignjax.sim.compact import masked_map
from ignjax.sim.queries import instance_in_sight, room_at, sector_of
from ignjax.sim.world import World, first_occupied, free_of_index, march_free, packed_at


FREE_FIRST = 1 / 3
"""Share of a free-space ray's samples that :func:`observe_batch` marches
for every ray; only the rays with no obstacle within it march the rest."""


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


def _free_samples(world: World) -> int:
    return int(math.ceil(world.config.obs_range / (2 * world.bank.grid.resolution)))


def free_space_batch(world: World, states: T.SimState, mask, chunk: int | None = None):
    """(B, 8, R) free-space rays of the rows in ``mask`` (others 0): the same
    values as :func:`observe`'s, in two passes. Every ray marches its first
    :data:`FREE_FIRST` of the samples; the rays with no obstacle there
    (most meet one within 2 m) march the rest, compacted
    (:func:`ignjax.sim.compact.masked_map`), instead of every ray taking
    every sample. Exact: each sample is the same computation."""
    cfg = world.config
    step = 2 * world.bank.grid.resolution
    n = _free_samples(world)
    first = max(1, min(n, int(round(n * FREE_FIRST))))
    s, pose = states.episode.scene, states.pose
    heads = jax.vmap(lambda yaw: _ray_headings(cfg, yaw))(pose[:, 2])  # Shape: (B, 8, R)
    B, V, R = heads.shape

    def near(a):
        s_, xy, h = a
        return jax.vmap(jax.vmap(lambda h_: first_occupied(_free_occupied(world, s_), xy, h_, step, 0, first)))(h)

    i1 = masked_map(near, mask, (s, pose[:, :2], heads), jnp.full((B, V, R), n, jnp.int32), chunk)
    far = (mask[:, None, None] & (i1 == first)).reshape(-1)
    rays = (jnp.repeat(s, V * R), jnp.repeat(pose[:, :2], V * R, axis=0), heads.reshape(-1))
    i = masked_map(lambda a: first_occupied(_free_occupied(world, a[0]), a[1], a[2], step, first, n), far, rays,
                   i1.reshape(-1), None if chunk is None else chunk * V * R)
    return jnp.where(mask[:, None, None], free_of_index(i.reshape(B, V, R), cfg.obs_range, step), 0.0)


def observe(world: World, state: T.SimState, free_space=None) -> T.Observation:
    """What the policy sees (no target identity, pose or distance inside).
    Perception is exact unless ``SimConfig.miss_rate`` / ``confusion_rate``
    make it noisy (:func:`perception_noise`). ``free_space``: the (8, R)
    free-space rays if already computed (:func:`free_space_batch`)."""
    with jax.named_scope("observe"):
        cfg = world.config
        bank = world.bank
        ep = state.episode
        s = ep.scene
        pose = state.pose
        res = bank.grid.resolution
        if free_space is None:
            free_space = jax.vmap(jax.vmap(lambda h: march_free(_free_occupied(world, s), pose[:2], h, cfg.obs_range,
                                                                2 * res)))(_ray_headings(cfg, pose[2]))
        # visible instances: K nearest non-structural instances, kept when in sight
        inst = bank.instances
        cand = inst.valid[s] & ~inst.structural[s]
        d = jnp.linalg.norm(inst.center[s, :, :2] - pose[None, :2], axis=1)
        d = jnp.where(cand & (d <= cfg.obs_range), d, jnp.inf)
        K = min(cfg.max_visible, inst.valid.shape[1])
        neg, idx = jax.lax.top_k(-d, K)
        dist = -neg
        eye = jnp.array([pose[0], pose[1], cfg.eye_height], jnp.float32)
        seen = jax.vmap(lambda i: instance_in_sight(world, s, i, eye))(idx) & jnp.isfinite(dist)
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


def observe_batch(world: World, states: T.SimState, previous: T.Observation, moved, chunk: int | None = None) -> T.Observation:
    """:func:`observe` of a batch (leading axis B) after a step: the
    perception (rays, visible instances, room) is recomputed for the rows in
    ``moved`` only; every other row's pose is unchanged, so it keeps
    ``previous``'s perception with its state fields refreshed. The free-space
    rays of the moved rows are marched together first (:func:`free_space_batch`).
    Row for row the same as ``vmap(observe)``."""
    free = free_space_batch(world, states, moved, chunk)
    obs = masked_map(lambda a: observe(world, *a), moved, (states, free), previous, chunk)
    return dataclasses.replace(obs, **jax.vmap(lambda st: state_fields(world, st))(states))
