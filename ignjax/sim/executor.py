"""The executor of a MOVE: a view's grid cell -> a waypoint (pixel ray,
depth, back-projection) -> the local controller's micro-steps with
collision probes (the MOVE rules of :mod:`ignjax.sim.env`'s docstring).

:func:`execute_moves` runs it for the moving rows of a batch (its two
halves: :func:`move_waypoints`, then :func:`micro_steps`);
:func:`execute_move` is the same on a batch of one.
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp

from ignjax.sim import compact
from ignjax.sim import geometry as G
from ignjax.sim import types as T
from ignjax.sim.compact import chunk_size, masked_map
from ignjax.sim.queries import geodesic_to_target, navigable_at, sector_of
from ignjax.sim.rays import queries as SR
from ignjax.sim.world import FINE, World, packed_at, probe_free


DEPTH_ELEVATION = math.radians(55.0)  # steepest pixel ray followed to the full waypoint range
DEPTH_EXACT_PRIMS = 8  # primitives tested exactly per occupied voxel by the depth ray
DEPTH_ITERATIONS = 64  # traversal steps of the depth ray (free space is crossed several voxels at a time)


def view_camera(cfg: T.SimConfig, pose, direction):
    """The pinhole camera of view ``direction`` at ``pose``: the view's own
    field of view (``cfg.view_hfov``: 90 degrees for 4 and 8 views, 30 for
    12) on a ``cfg.image_size`` image with square pixels, looking along
    ``yaw + direction * 360 / n_views``, eye at ``eye_height``, pitch 0 (the
    renderers' camera, :mod:`ignjax.sim.views.cameras`); the camera of
    :func:`cell_ray`.

    Returns:
        (K, R_wc, t_wc): intrinsics (3, 3), camera-to-world rotation (3, 3), eye (3,).
    """
    K, _, R_wc, t_wc, _ = cell_ray(cfg, pose, jnp.asarray(direction), 1, 1)
    return K, R_wc, t_wc


def cell_ray(cfg: T.SimConfig, pose, direction, col, row):
    """The executor's pixel ray of a grid cell of view ``direction``: the
    ray through the cell's centre pixel (Eq. app:grid-to-pixel) of the
    view's camera (:func:`view_camera`).

    Returns:
        (K, uv, R_wc, t_wc, d_w): intrinsics, centre pixel, camera-to-world
        rotation, eye (3,), and the world direction ``R_wc K^-1 [u, v, 1]``
        (3,), whose projection on the optical axis is 1.
    """
    W, H = cfg.image_size
    K = G.intrinsics(float(W), float(H), math.radians(cfg.view_hfov))
    yaw = pose[2] + direction.astype(jnp.float32) * (2 * math.pi / cfg.n_views)
    uv = G.grid_to_pixel(col, row, float(W), float(H))
    R_wc = G.view_rotation(yaw)
    t_wc = jnp.array([pose[0], pose[1], cfg.eye_height], jnp.float32)
    return K, uv, R_wc, t_wc, G.matvec3(R_wc, G.pixel_ray(K, uv))


def _depth_ray(world: World, pose, direction, col, row):
    """The depth ray of a grid cell: (eye (3,), unit direction (3,), range (), the pixel ray's length per unit
    of z-depth ()), and the march's static arguments."""
    cfg = world.config
    _, _, _, t_wc, d_w = cell_ray(cfg, pose, direction, col, row)
    norm = jnp.sqrt(d_w[0] * d_w[0] + d_w[1] * d_w[1] + d_w[2] * d_w[2])
    u = d_w / norm
    horiz = jnp.sqrt(u[0] * u[0] + u[1] * u[1])
    reach = (cfg.horizon + cfg.pullback + world.bank.grid.resolution) / jnp.maximum(horiz, 1e-3)
    static = min(cfg.depth_range, (cfg.horizon + cfg.pullback + world.bank.grid.resolution) / math.cos(DEPTH_ELEVATION))
    statics = dict(static_range=static, outside_hits=False, exact=DEPTH_EXACT_PRIMS, iterations=DEPTH_ITERATIONS)
    return (t_wc, u, jnp.minimum(jnp.minimum(reach, static), cfg.depth_range), norm), statics


def _depth_of(cfg: T.SimConfig, dist, norm):
    valid = jnp.isfinite(dist) & (dist <= cfg.depth_range)
    return jnp.where(valid, dist / norm, 0.0), valid  # d_w has unit projection on the optical axis


def cell_depth(world: World, s, pose, direction, col, row):
    """The executor's depth of a grid cell: z-depth along the optical axis
    of the first surface on the cell's pixel ray, by ray casting (voxel
    traversal with exact primitive tests, :func:`ignjax.sim.rays.queries.march`).
    A surface whose horizontal distance exceeds ``horizon + pullback``
    yields the same clipped waypoint as no surface, so the ray is followed
    only that far (as a 3-D range, for rays up to :data:`DEPTH_ELEVATION` steep).

    Returns:
        (z (), valid ()): ``valid`` is false when no surface lies within range.
    """
    (t_wc, u, max_dist, norm), statics = _depth_ray(world, pose, direction, col, row)
    return _depth_of(world.config, SR.march(world.bank.rays, s, t_wc, u, max_dist, **statics), norm)


DEPTH_FIRST = 16
"""Traversal steps every depth ray of :func:`cell_depth_batch` takes; only
the rays they do not settle (about one in fifteen on the shipped houses) take the rest."""


def cell_depth_batch(world: World, s, pose, direction, col, row, mask, chunk: int | None = None):
    """:func:`cell_depth` of the rows in ``mask`` of a batch (others 0,
    False), in two passes: every ray takes the first :data:`DEPTH_FIRST`
    traversal steps (:func:`ignjax.sim.rays.queries.march_begin`), and only
    the rays those leave open take the rest of the traversal and its exact
    rounds, compacted (:func:`ignjax.sim.compact.masked_map`, chunks of a
    quarter of ``chunk``), instead of every ray taking all of them. Each step
    is the same computation, so the depths are :func:`cell_depth`'s (one
    march per ray under :func:`ignjax.sim.compact.one_pass`)."""
    cfg = world.config
    B = mask.shape[0]
    args = (s, pose, direction, col, row)
    if compact.ONE_PASS:
        return masked_map(lambda a: cell_depth(world, *a), mask, args, (jnp.zeros(B, jnp.float32), jnp.zeros(B, bool)),
                          chunk)

    def begin(a):
        (t_wc, u, max_dist, norm), statics = _depth_ray(world, *a[1:])
        st = SR.march_begin(world.bank.rays, a[0], t_wc, u, max_dist, steps=DEPTH_FIRST, **statics)
        return st, _depth_of(cfg, st.value, norm)

    def resume(a):
        (t_wc, u, max_dist, norm), statics = _depth_ray(world, *a[1:5])
        return _depth_of(cfg, SR.march_resume(world.bank.rays, a[0], t_wc, u, max_dist, a[5], steps=DEPTH_FIRST,
                                              **statics), norm)

    shapes = jax.eval_shape(begin, jax.tree.map(lambda x: x[0], args))
    st, (z, valid) = masked_map(begin, mask, args, jax.tree.map(lambda x: jnp.zeros((B,) + x.shape, x.dtype), shapes),
                                chunk)
    rest = mask & ~st.done
    c = chunk_size(B) if chunk is None else chunk
    return masked_map(resume, rest, args + (st,), (z, valid), max(1, c // 4))


def pixel_waypoint(world: World, s, pose, direction, col, row, depth=None):
    """The executor's waypoint for a grid cell of a view (before the controller);
    ``depth``: the cell's ``(z, valid)`` if already cast (:func:`cell_depth_batch`).

    Returns:
        (waypoint (2,), hit_obstacle (), used_depth (), used_floor ()).
    """
    cfg = world.config
    K, uv, R_wc, t_wc, d_w = cell_ray(cfg, pose, direction, col, row)
    yaw = pose[2] + direction.astype(jnp.float32) * (2 * math.pi / cfg.n_views)
    u = d_w / jnp.sqrt(d_w[0] * d_w[0] + d_w[1] * d_w[1] + d_w[2] * d_w[2])
    z, valid_depth = cell_depth(world, s, pose, direction, col, row) if depth is None else depth
    x_c = G.backproject(K, uv, z)
    x_w = G.camera_to_world(R_wc, t_wc, x_c)
    floor_pt, floor_ok = G.floor_intersection(t_wc, d_w)
    hit_floor_surface = valid_depth & (x_w[2] < 0.02)
    use_depth = valid_depth
    point = jnp.where(use_depth, x_w, jnp.where(floor_ok, floor_pt, t_wc + u * cfg.horizon))
    wp = point[:2]
    delta = wp - pose[:2]
    r = jnp.linalg.norm(delta)
    dir_xy = jnp.where(r > 1e-6, delta / jnp.maximum(r, 1e-6), jnp.stack([jnp.cos(yaw), jnp.sin(yaw)]))
    hit_obstacle = use_depth & ~hit_floor_surface
    r = jnp.where(hit_obstacle, jnp.maximum(r - cfg.pullback, 0.0), r)
    r = jnp.where(~use_depth & ~floor_ok, cfg.horizon, r)
    r = jnp.minimum(r, cfg.horizon)
    return pose[:2] + r * dir_xy, hit_obstacle, use_depth, ~use_depth & floor_ok


def forward_free(world: World, s, xy, heading):
    """() free distance ahead at the collision heights (all heights at once, probe map)."""
    cfg = world.config
    res = world.bank.grid.resolution
    mask = (1 << len(cfg.collision_heights)) - 1
    return probe_free(world, s, xy, heading, mask, cfg.collision_distance + res, res / FINE)


def _probe(world: World, s, xy, h, length):
    """One candidate heading of a micro-step: (free, full) - whether the heading
    is free (collision rays clear and its full or half step navigable) and
    whether its full step is navigable.

    One march over the probe map answers the collision rays at every height;
    the samples within the step's length check the navigability of every cell
    along it (no hopping over a thin gap into another component)."""
    cfg = world.config
    res = world.bank.grid.resolution
    spacing = res / FINE  # one sample per fine cell: nothing thicker than a fine cell is skipped
    n_samples = int(math.ceil((cfg.collision_distance + res) / spacing))
    t = jnp.arange(1, n_samples + 1, dtype=jnp.float32) * spacing  # Shape: (n,)
    n_nav = min(int(math.ceil(cfg.micro_step / spacing)), n_samples)  # samples a micro-step can reach
    t_nav = t[:n_nav]
    u = jnp.stack([jnp.cos(h), jnp.sin(h)])
    pts = xy[None] + t[:, None] * u[None]
    hit = packed_at(world, world.packed_col, 1, s, pts) != 0  # any collision height (World.packed_col)
    free = jnp.where(jnp.any(hit), t[jnp.argmax(hit)] - spacing, jnp.float32(cfg.collision_distance + res))
    nav = navigable_at(world, s, jnp.concatenate([pts[:n_nav], (xy + length * u)[None], (xy + 0.5 * length * u)[None]]))
    along = nav[:n_nav]
    full = jnp.all(jnp.where(t_nav <= length, along, True)) & nav[n_nav]
    half = jnp.all(jnp.where(t_nav <= 0.5 * length, along, True)) & nav[n_nav + 1]
    return (free >= cfg.collision_distance) & (full | half), full


_OFFSETS = (0.0, 1.0, -1.0, 2.0, -2.0, 3.0, -3.0, 4.0)  # candidate headings, x 45 degrees: desired first, left first


def first_free_alternative(world: World, s, xy, h0, need, chunk: int | None = None):
    """The first free alternative heading of each row in ``need`` (rows whose
    desired heading ``h0`` is blocked), probing :data:`_OFFSETS` ``[1:]`` in
    order and only for the rows still without a free one: the same answer as
    probing all seven for every such row and taking the first free, with
    about a third of the probes (a row stops at its first free heading).

    Args:
        s, xy, h0: (B,) scene, (B, 2) position, (B,) desired heading.
        need: (B,) bool rows to probe.

    Returns:
        (k (B,) int32, full (B,) bool): the index into :data:`_OFFSETS` of the
        first free alternative (0 where none is free or the row is not in
        ``need``) and whether its full micro-step is navigable.
    """
    if compact.ONE_PASS:
        return _every_alternative(world, s, xy, h0, need, chunk)
    cfg = world.config
    B = need.shape[0]
    offsets = jnp.array(_OFFSETS, jnp.float32) * (math.pi / 4)
    step = jnp.float32(cfg.micro_step)

    def cond(carry):
        j, left = carry[0], carry[1]
        return (j < len(_OFFSETS)) & jnp.any(left)

    def body(carry):
        j, left, k, full = carry
        ok_j, full_j = masked_map(lambda a: _probe(world, a[0], a[1], a[2] + offsets[j], step), left, (s, xy, h0),
                                  (jnp.zeros(B, bool), jnp.zeros(B, bool)), chunk)
        return j + 1, left & ~ok_j, jnp.where(ok_j, j, k), jnp.where(ok_j, full_j, full)

    init = (jnp.int32(1), need, jnp.zeros(B, jnp.int32), jnp.zeros(B, bool))
    _, _, k, full = jax.lax.while_loop(cond, body, init)
    return k, full


def _every_alternative(world: World, s, xy, h0, need, chunk: int | None):
    """:func:`first_free_alternative`'s one-pass form (:func:`ignjax.sim.compact.one_pass`):
    all seven alternatives probed for every row in ``need``, the first free one taken."""
    B = need.shape[0]
    offsets = jnp.array(_OFFSETS, jnp.float32) * (math.pi / 4)
    step = jnp.float32(world.config.micro_step)
    probe = jax.vmap(lambda s_, p, h: _probe(world, s_, p, h, step), in_axes=(None, None, 0))
    ok, full = masked_map(lambda a: probe(a[0], a[1], a[2] + offsets[1:]), need, (s, xy, h0),
                          (jnp.zeros((B, 7), bool), jnp.zeros((B, 7), bool)), chunk)
    k = jnp.where(ok.any(1), jnp.argmax(ok, 1) + 1, 0).astype(jnp.int32)
    return k, jnp.take_along_axis(full, jnp.maximum(k - 1, 0)[:, None], 1)[:, 0] & (k > 0)


def execute_moves(world: World, states: T.SimState, direction, col, row, mask, chunk: int | None = None):
    """Run the executor for the MOVEs of a batch (leading axis B).

    The controller of :mod:`ignjax.sim.env`'s docstring (one episode's :func:`execute_move`
    is this function on a batch of one), organised so a batch pays only for
    the work its episodes need (:func:`ignjax.sim.compact.masked_map`):
    waypoints are cast for the rows in ``mask`` only (their depth rays in two
    passes, :func:`cell_depth_batch`), micro-steps run while
    any row is still moving, each micro-step probes the desired heading of
    the moving rows and then the neighbouring headings in :data:`_OFFSETS`
    order, each only for the rows still without a free one
    (:func:`first_free_alternative`); each row takes the first free heading,
    so a row's result does not depend on the others.

    Args:
        states: (B,) SimState.
        direction, col, row: (B,) int32 the MOVE's view and grid cell.
        mask: (B,) bool rows that execute a MOVE; the other rows' outputs
            are their current pose, no motion, their minimum distance, no
            blocked heading and their pose as the waypoint.
        chunk: rows per vectorised call (:func:`ignjax.sim.compact.chunk_size` by default).

    Returns:
        (pose (B, 3), moved (B,), min_distance (B,), blocked (B, 8), waypoint (B, 2)).
    """
    wp = move_waypoints(world, states, direction, col, row, mask, chunk)
    return micro_steps(world, states, wp, mask, chunk) + (wp,)


def move_waypoints(world: World, states: T.SimState, direction, col, row, mask, chunk: int | None = None):
    """The first half of :func:`execute_moves`: the waypoints (B, 2) of the
    rows in ``mask`` (their depth rays in two passes, :func:`cell_depth_batch`);
    the other rows' are their positions."""
    s, pose0 = states.episode.scene, states.pose
    depth = cell_depth_batch(world, s, pose0, direction, col, row, mask, chunk)
    return masked_map(lambda a: pixel_waypoint(world, *a[:5], depth=a[5])[0], mask,
                      (s, pose0, direction, col, row, depth), pose0[:, :2], chunk)


def micro_steps(world: World, states: T.SimState, wp, mask, chunk: int | None = None):
    """The second half of :func:`execute_moves`: the controller's micro-steps
    towards the waypoints ``wp`` (B, 2) of the rows in ``mask``.

    Returns:
        (pose (B, 3), moved (B,), min_distance (B,), blocked (B, 8)).
    """
    cfg = world.config
    ep = states.episode
    s = ep.scene
    pose0 = states.pose
    B = mask.shape[0]
    yaw0 = pose0[:, 2]
    offsets = jnp.array(_OFFSETS, jnp.float32) * (math.pi / 4)

    def cond(carry):
        i, active = carry[0], carry[-1]
        return (i < cfg.max_micro_steps) & jnp.any(active)

    def micro(carry):
        i, pose, moved, dmin, blocked, active = carry
        r, beta = jax.vmap(G.relative_target)(pose[:, :2], pose[:, 2], wp)
        active = active & (r > cfg.waypoint_tolerance)
        h0 = pose[:, 2] + beta
        len0 = jnp.minimum(cfg.micro_step, r)
        ok0, full0 = masked_map(lambda a: _probe(world, *a), active, (s, pose[:, :2], h0, len0),
                                (jnp.zeros(B, bool), jnp.zeros(B, bool)), chunk)
        k, full_k = first_free_alternative(world, s, pose[:, :2], h0, active & ~ok0, chunk)
        any_ok = ok0 | (k > 0)
        full_k = jnp.where(ok0, full0, full_k)
        sec = sector_of(h0 - yaw0)
        blocked = blocked | ((sec[:, None] == jnp.arange(8)) & (~ok0 & active)[:, None])  # no scatter
        heading = h0 + offsets[k]
        lengths = jnp.where(k == 0, len0, jnp.float32(cfg.micro_step))
        length = jnp.where(full_k, lengths, 0.5 * lengths)
        new_xy = pose[:, :2] + length[:, None] * jnp.stack([jnp.cos(heading), jnp.sin(heading)], 1)
        can = active & any_ok
        pose = jnp.where(can[:, None], jnp.concatenate([new_xy, heading[:, None]], 1), pose)
        moved = moved + jnp.where(can, length, 0.0)
        d_new = jax.vmap(lambda e, xy: geodesic_to_target(world, e, xy))(ep, new_xy)
        dmin = jnp.where(can, jnp.minimum(dmin, d_new), dmin)
        return i + 1, pose, moved, dmin, blocked, can

    init = (jnp.int32(0), pose0, jnp.zeros(B, jnp.float32), states.min_distance, jnp.zeros((B, 8), bool), mask)
    _, pose, moved, dmin, blocked, _ = jax.lax.while_loop(cond, micro, init)
    pose = jnp.where(mask[:, None], pose.at[:, 2].set(G.wrap_angle(pose[:, 2])), pose)
    return pose, moved, dmin, blocked


def execute_move(world: World, state: T.SimState, direction, col, row):
    """Run the executor for one MOVE of one episode (:func:`execute_moves` on a batch of one).

    Returns the updated pose, path length moved, minimum geodesic distance,
    blocked mask and waypoint."""
    args = T.batch_of_one((state, direction, col, row, jnp.array(True)))
    return T.only_row(execute_moves(world, *args))
