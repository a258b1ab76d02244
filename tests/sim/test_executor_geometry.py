"""The executor's geometry as the simulator's docstring states it, checked
with numbers computed in the test (pinhole rays, ``mujoco.mj_ray``, the
floor plane and the navigation grid) on a hand-made room:

* the waypoint is pulled back ``pullback`` (0.3 m) from a hit surface and
  clipped to ``horizon`` (3 m); a pixel with no valid depth falls back to the
  floor-plane intersection;
* the local controller moves in micro-steps of at most ``micro_step``
  (0.5 m); an obstacle within ``collision_distance`` (0.6 m) blocks a heading,
  which is recorded in ``SimState.blocked``, and one beyond it does not;
* the agent is on a navigable cell after every micro-step;
* the views' fields of view: 4 and 12 views tile the circle (90 and 30
  degrees, each edge ray shared with the neighbour), 8 views are 90 degrees
  wide and overlap by half; the oracle's "in the front view" test uses the
  front view's own width.

The room: 8 x 4 m (walls 0.1 m thick, inner faces at x = 0.05 / 7.95 and
y = 0.05 / 3.95), a low crate (top at 0.3 m) at x 3.8..4.2, y 1.6..2.4, a
tall cabinet in the north-east corner and a table (top at 0.74 m on four
thin legs) in the south-west. The controller tests run one micro-step per
MOVE (``max_micro_steps=1``), so each MOVE is one micro-step.
"""

from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
import pytest

from ignjax.errors import ConfigError
from ignjax.scenes.bank import SceneBank, target_fields
from ignjax.scenes.model import Geom, Instance, OrientedBox, Room, Scene, SceneMeta, Wall
from ignjax.sim import env as E
from ignjax.sim import executor as X
from ignjax.sim import geometry as G
from ignjax.sim import types as T
from ignjax.sim.world import World

WALL_T = 0.1
CRATE_FACE_X = 3.8  # west face of the crate; the crate spans y 1.6..2.4 and is 0.3 m tall
LANE_Y = 2.0  # the crate's centre line
EYE = 1.25
COL, ROW_UP = 4, 5  # a grid cell whose ray rises (row 5) and lies left of the optical axis (col 4)
ROWS = 32  # every batched call of the controller uses this many rows (one compiled program)


def _box(iid, category, cx, cy, parts, room="room_0"):
    """An instance made of box parts ``(hx, hy, hz, px, py, pz)`` in its own frame (origin on the floor)."""
    geoms = tuple(Geom("box", (hx, hy, hz), (px, py, pz)) for hx, hy, hz, px, py, pz in parts)
    lo = np.min([[px - hx, py - hy, pz - hz] for hx, hy, hz, px, py, pz in parts], 0)
    hi = np.max([[px + hx, py + hy, pz + hz] for hx, hy, hz, px, py, pz in parts], 0)
    c, h = (lo + hi) / 2, (hi - lo) / 2
    bbox = OrientedBox((cx + c[0], cy + c[1], c[2]), tuple(h), 0.0)
    return Instance(iid, category, (cx, cy, 0.0), 0.0, bbox, room=room, geoms=geoms)


def _room_scene() -> Scene:
    rooms = (Room("room_0", "living_room", ((0, 0), (8, 0), (8, 4), (0, 4)), "Room"),)
    walls = tuple(Wall(n, a, b, WALL_T, 2.5, 0, ("room_0",)) for n, a, b in (
        ("wall_s", (0, 0), (8, 0)), ("wall_n", (0, 4), (8, 4)), ("wall_w", (0, 0), (0, 4)), ("wall_e", (8, 0), (8, 4))))
    leg = 0.02
    table = [(0.5, 0.3, 0.02, 0.0, 0.0, 0.72)] + [(leg, leg, 0.35, sx * 0.46, sy * 0.26, 0.35)
                                                  for sx in (-1, 1) for sy in (-1, 1)]
    insts = (
        _box("crate_0", "box", 4.0, LANE_Y, [(0.2, 0.4, 0.15, 0.0, 0.0, 0.15)]),
        _box("cabinet_0", "wardrobe", 6.9, 3.4, [(0.4, 0.3, 0.9, 0.0, 0.0, 0.9)]),
        _box("table_0", "dining_table", 1.6, 0.9, table),
    )
    return Scene("executor_room", rooms, (), walls, insts, SceneMeta(source="tests/sim/test_executor_geometry.py",
                                                                     source_format="procgen"))


@pytest.fixture(scope="module")
def room():
    """The room's bank, a world with one micro-step per MOVE, and the jitted functions every test shares."""
    bank = SceneBank.build([_room_scene()])
    fields = target_fields(bank, jnp.array([0]), jnp.array([0]))
    world = World(bank, fields, T.SimConfig(max_micro_steps=1))
    waypoints = jax.jit(jax.vmap(lambda w, pose, d, c, r: X.pixel_waypoint(w, jnp.int32(0), pose, d, c, r),
                                 in_axes=(None, 0, 0, 0, 0)))
    return {"bank": bank, "world": world, "waypoints": waypoints, "step": jax.jit(E.step_batch),
            "reset": jax.jit(jax.vmap(E.reset, in_axes=(None, 0)))}


def _specs(bank, poses) -> T.EpisodeSpec:
    """Episodes of the room starting at ``poses`` (N, 3), the crate as the target."""
    n = len(poses)
    i = lambda v: jnp.full(n, v, jnp.int32)  # noqa: E731
    return T.EpisodeSpec(scene=i(0), target=i(0), field=i(0), category=i(bank.category_index("box")),
                         start=jnp.asarray(poses, jnp.float32), difficulty=i(0), goal_room=i(0),
                         fact_attrs=jnp.full((n, 4), -1, jnp.int32), fact_on=i(-1),
                         fact_near=jnp.full((n, 3), -1, jnp.int32), region_category=i(-1), valid=jnp.ones(n, bool))


def _pad(a, n: int = ROWS) -> np.ndarray:
    """``a`` (k, ...) padded to n rows with copies of its last row."""
    a = np.asarray(a)
    return np.concatenate([a, np.repeat(a[-1:], n - len(a), 0)])


def _waypoints(room, world, poses, view, col, row):
    """pixel_waypoint for each row (numpy outputs), the rows padded to a multiple of 4 (few compiled shapes)."""
    k = len(poses)
    n = -(-k // 4) * 4
    out = room["waypoints"](world, jnp.asarray(_pad(poses, n), jnp.float32), *(jnp.asarray(_pad(v, n), jnp.int32)
                                                                              for v in (view, col, row)))
    return tuple(np.asarray(a)[:k] for a in out)


def _moves(direction, col, row) -> T.Action:
    d, c, r = (np.asarray(v, np.int32) for v in (direction, col, row))
    n = len(d)
    return T.Action(jnp.full(n, T.MOVE, jnp.int32), jnp.asarray(d), jnp.asarray(c), jnp.asarray(r),
                    jnp.ones(n, jnp.int32), jnp.full(n, -1, jnp.int32))


def _pixel_offset(cfg: T.SimConfig, col: int) -> float:
    """Horizontal angle of a grid column's centre pixel left of the optical axis (pinhole, square pixels)."""
    W = cfg.image_size[0]
    f = (W / 2) / math.tan(math.radians(cfg.hfov) / 2)
    u = (col - 0.5) * W / 8
    return math.atan2(W / 2 - u, f)


def _pixel_dirs(cfg: T.SimConfig, yaw, view, col, row) -> np.ndarray:
    """(N, 3) unit world directions of the cells' centre pixels (camera x right, y down, z forward)."""
    W, H = cfg.image_size
    f = (W / 2) / math.tan(math.radians(cfg.hfov) / 2)
    x = ((np.asarray(col) - 0.5) * W / 8 - W / 2) / f
    y = ((H - (np.asarray(row) - 0.5) * H / 8) - H / 2) / f
    a = np.asarray(yaw) + np.asarray(view) * math.pi / 4
    fwd = np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], -1)
    right = np.stack([np.sin(a), -np.cos(a), np.zeros_like(a)], -1)
    d = fwd + x[:, None] * right + y[:, None] * np.array([0.0, 0.0, -1.0])
    return d / np.linalg.norm(d, axis=1, keepdims=True)


# ---------------------------------------------------------------------------
# the waypoint
# ---------------------------------------------------------------------------


def test_waypoint_is_pulled_back_from_a_wall_straight_ahead(room):
    """Facing the east wall (inner face 1.95 m ahead): the pixel's ray meets
    it 1.95 / cos(theta) m out along its horizontal direction theta (7.1
    degrees left of the axis for column 4), and the waypoint lies on that ray
    0.3 m short of the hit."""
    cfg = room["world"].config
    x0, y0 = 6.0, 2.0
    theta = _pixel_offset(cfg, COL)
    wp, hit, depth, floor = _waypoints(room, room["world"], [[x0, y0, 0.0]], [0], [COL], [ROW_UP])
    assert bool(hit[0]) and bool(depth[0]) and not bool(floor[0])
    hit_distance = ((8.0 - WALL_T / 2) - x0) / math.cos(theta)
    r = hit_distance - cfg.pullback
    np.testing.assert_allclose(np.asarray(wp[0]), [x0 + r * math.cos(theta), y0 + r * math.sin(theta)], atol=2e-3)


def test_waypoint_of_an_axis_aligned_pixel_ray_is_pulled_back_from_the_wall(room):
    """The same wall with the pixel's ray turned exactly onto +x (yaw =
    -theta): the waypoint should be 1.95 - 0.3 = 1.65 m straight ahead."""
    cfg = room["world"].config
    x0, y0 = 6.0, 2.0
    wp, hit, _, _ = _waypoints(room, room["world"], [[x0, y0, -_pixel_offset(cfg, COL)]], [0], [COL], [ROW_UP])
    assert bool(hit[0])
    np.testing.assert_allclose(np.asarray(wp[0]), [(8.0 - WALL_T / 2) - cfg.pullback, y0], atol=2e-3)


def test_waypoints_of_every_cell_follow_the_rules(room):
    """Every cell of every view from four poses: the waypoint lies on the
    pixel ray's horizontal direction at ``min(hit - pullback, horizon)`` for
    a surface above the floor, at ``min(floor distance, horizon)`` when the
    ray meets the floor first or has no valid depth in reach (the
    floor-plane fallback), and at ``horizon`` for a ray that meets neither.
    The hit distances come from ``mujoco.mj_ray`` and the floor plane."""
    world = room["world"]
    cfg = world.config
    compiled = room["bank"].compiled[0]
    res = room["bank"].grid.resolution
    poses = np.array([[1.2, 2.6, 0.3], [3.0, 3.3, -2.0], [5.2, 1.0, 1.9], [6.8, 2.2, math.pi]])
    view, col, row = (a.ravel() for a in np.meshgrid(np.arange(8), np.arange(1, 9), np.arange(1, 9), indexing="ij"))
    P = np.repeat(poses, len(view), 0)
    V, C, R = (np.tile(a, len(poses)) for a in (view, col, row))
    wp, hit, depth, floor = _waypoints(room, world, P, V, C, R)

    dirs = _pixel_dirs(cfg, P[:, 2], V, C, R)
    horiz = np.linalg.norm(dirs[:, :2], axis=1)
    # what the executor follows the ray for: a surface farther than horizon + pullback gives the clipped waypoint anyway
    reach = np.minimum((cfg.horizon + cfg.pullback + res) / horiz,
                       min(cfg.depth_range, (cfg.horizon + cfg.pullback + res) / math.cos(X.DEPTH_ELEVATION)))
    groups = np.array([0, 1, 1, 1, 0, 0], np.uint8)  # walls and objects (the floor is the plane z = 0)
    gid = np.zeros(1, np.int32)
    t_obj = np.array([mujoco.mj_ray(compiled.model, compiled.data, np.array([x, y, EYE]), d, groups, 1, -1, gid)
                      for (x, y, _), d in zip(P, dirs)])
    t_obj = np.where(t_obj >= 0, t_obj, np.inf)
    t_floor = np.where(dirs[:, 2] < 0, EYE / np.maximum(-dirs[:, 2], 1e-12), np.inf)

    obstacle = (t_obj < t_floor) & (t_obj <= reach)
    expected = np.where(obstacle, np.minimum(np.maximum(t_obj * horiz - cfg.pullback, 0.0), cfg.horizon),
                        np.where(np.isfinite(t_floor), np.minimum(t_floor * horiz, cfg.horizon), cfg.horizon))
    ray_xy = dirs[:, :2] / horiz[:, None]
    got = wp - P[:, :2]
    dist = np.linalg.norm(got, axis=1)
    # on the pixel ray's horizontal direction
    along = np.einsum("ij,ij->i", got, ray_xy)
    assert np.all(np.abs(along - dist) <= 1e-4)
    # never beyond the horizon
    assert dist.max() <= cfg.horizon + 1e-4
    # the distance: within one grid cell of the independent expectation (the depth ray marches voxels)
    close = np.abs(dist - expected) <= res
    assert close.mean() >= 0.99, (close.mean(), np.c_[P, V, C, R, dist, expected][~close][:5])
    # the executor's own account of each case agrees with the independent one
    assert np.mean(hit == obstacle) >= 0.99
    assert obstacle.sum() >= 200 and (~obstacle & np.isfinite(t_floor)).sum() >= 200
    # pixels without valid depth fell back to the floor plane (their floor points lie beyond the horizon here)
    fell_back = floor & ~depth
    assert fell_back.sum() >= 50
    np.testing.assert_allclose(dist[fell_back], np.minimum(t_floor[fell_back] * horiz[fell_back], cfg.horizon), atol=1e-4)
    # far targets are clipped: the horizon is reached exactly for every far surface
    far = expected >= cfg.horizon - 1e-6
    assert far.sum() >= 100
    np.testing.assert_allclose(dist[far & close], cfg.horizon, atol=1e-4)


def test_pixel_without_valid_depth_falls_back_to_the_floor_plane(room):
    """With ``depth_range`` shorter than the floor is far along the ray, a
    downward pixel has no valid depth: the waypoint is the floor-plane
    intersection (here 1.44 m out, within the horizon, so not clipped)."""
    world = room["world"]
    short = World(world.bank, world.fields, dataclasses.replace(world.config, depth_range=1.0), fine=world.fine,
                  packed_obs=world.packed_obs)
    cfg = short.config
    x0, y0, yaw = 3.0, 3.0, 0.2
    cells = np.array([(COL, 1), (7, 1), (2, 2)])
    d = _pixel_dirs(cfg, np.full(3, yaw), np.zeros(3), cells[:, 0], cells[:, 1])
    s = EYE / -d[:, 2]  # along the unit rays to z = 0
    assert np.all(s > cfg.depth_range)
    floor_pt = np.array([x0, y0]) + s[:, None] * d[:, :2]
    assert np.all(np.linalg.norm(floor_pt - [x0, y0], axis=1) < cfg.horizon)
    wp, hit, depth, floor = _waypoints(room, short, np.tile([x0, y0, yaw], (3, 1)), np.zeros(3), cells[:, 0], cells[:, 1])
    assert not depth.any() and floor.all() and not hit.any()
    np.testing.assert_allclose(wp, floor_pt, atol=1e-4)


# ---------------------------------------------------------------------------
# the local controller
# ---------------------------------------------------------------------------


def test_obstacle_blocks_only_within_collision_distance(room):
    """Facing the crate (0.3 m tall: only the 0.15 m collision ray meets it)
    with the waypoint beyond it: at 0.4 / 0.5 m the front heading is refused
    and recorded in ``state.blocked``, and the agent takes the heading 45
    degrees to its left; at 0.7 / 0.8 / 1 m (beyond ``collision_distance``
    = 0.6 m) nothing is blocked and it moves straight on (a full 0.5 m
    micro-step where the step ends clear of the crate's clearance band)."""
    world = room["world"]
    cfg = world.config
    assert cfg.collision_distance == pytest.approx(0.6) and cfg.micro_step == pytest.approx(0.5)
    gaps = np.array([0.4, 0.5, 0.7, 0.8, 1.0])
    blocks = gaps < cfg.collision_distance
    yaw = 1e-3 - _pixel_offset(cfg, COL)  # the desired heading is (almost exactly) +x, straight at the crate
    starts = np.c_[CRATE_FACE_X - gaps, np.full(len(gaps), LANE_Y), np.full(len(gaps), yaw)]
    st = room["reset"](world, _specs(room["bank"], _pad(starts)))
    nxt = room["step"](world, st, _moves(*(np.full(ROWS, v) for v in (0, COL, ROW_UP))))
    k = len(gaps)
    wp = np.asarray(nxt.waypoint)[:k]
    blocked = np.asarray(nxt.blocked)[:k]
    pose = np.asarray(nxt.pose)[:k]
    move = pose[:, :2] - starts[:, :2]
    assert np.all(wp[:, 0] > CRATE_FACE_X + 0.5)  # the waypoint lies beyond the crate (the rising ray passes over it)
    # blocked: the front heading (and only it) recorded; the nearest free heading, left first
    assert np.all(blocked[blocks, 0]) and np.all(blocked[blocks].sum(1) == 1)
    np.testing.assert_allclose(pose[blocks, 2], math.pi / 4, atol=3e-3)
    assert np.all(np.linalg.norm(move[blocks], axis=1) > 0.1)
    np.testing.assert_allclose(np.arctan2(move[blocks, 1], move[blocks, 0]), math.pi / 4, atol=3e-3)
    # not blocked: straight on
    assert not blocked[~blocks].any()
    np.testing.assert_allclose(pose[~blocks, 2], 0.0, atol=3e-3)
    assert np.all(np.abs(move[~blocks, 1]) < 2e-3) and np.all(move[~blocks, 0] > 0.2)
    full = gaps >= 0.8
    np.testing.assert_allclose(move[full, 0], cfg.micro_step, atol=1e-4)


def test_every_micro_step_is_short_and_ends_navigable(room):
    """32 episodes from random navigable starts take 12 random MOVEs of one
    micro-step each: every step is a straight segment of at most 0.5 m along
    the new heading, and every pose lies on a navigable cell."""
    world = room["world"]
    bank = room["bank"]
    grid = bank.navgrids[0]
    rng = np.random.default_rng(0)
    pts = grid.navigable_points()
    n = ROWS
    starts = np.c_[pts[rng.integers(len(pts), size=n)], rng.uniform(-math.pi, math.pi, n)]
    st = room["reset"](world, _specs(bank, starts))
    lengths, n_blocked = [], 0
    for _ in range(12):
        before = np.asarray(st.pose)
        st = room["step"](world, st, _moves(rng.integers(0, 8, n), rng.integers(1, 9, n), rng.integers(1, 9, n)))
        after = np.asarray(st.pose)
        step = after[:, :2] - before[:, :2]
        length = np.linalg.norm(step, axis=1)
        assert length.max() <= world.config.micro_step + 1e-4
        np.testing.assert_allclose(np.asarray(st.last_move), length, atol=1e-4)
        moved = length > 1e-3
        heading = np.arctan2(step[moved, 1], step[moved, 0])
        turn = np.angle(np.exp(1j * (heading - after[moved, 2])))
        assert np.all(np.abs(turn) <= 1e-3)  # the agent faces its direction of motion
        rc = grid.world_to_cell(after[:, :2])
        assert np.all(grid.navigable[rc[:, 0], rc[:, 1]])
        lengths.append(length)
        n_blocked += int(np.asarray(st.blocked).any(1).sum())
    lengths = np.concatenate(lengths)
    assert (lengths > 1e-3).mean() >= 0.5  # most MOVEs did move
    assert np.isclose(lengths, world.config.micro_step, atol=1e-4).sum() >= 50  # full micro-steps are common
    assert n_blocked >= 5  # and obstacles were met on the way


@pytest.mark.parametrize("chunk", [None, 5])
def test_alternatives_probed_in_order_equal_probing_all_seven(room, chunk):
    """The controller probes a blocked row's alternative headings in order,
    stopping at the first free one: from 256 random navigable positions and
    headings (many near a wall, the crate or the table), the first free
    alternative and its full-step flag equal those of probing all seven for
    every row, and rows outside the mask get none."""
    world = room["world"]
    grid = room["bank"].navgrids[0]
    rng = np.random.default_rng(1)
    pts = grid.navigable_points()
    n = 256
    xy = jnp.asarray(pts[rng.integers(len(pts), size=n)], jnp.float32)
    h0 = jnp.asarray(rng.uniform(-math.pi, math.pi, n), jnp.float32)
    s = jnp.zeros(n, jnp.int32)
    need = jnp.asarray(rng.random(n) < 0.8)
    k, full = jax.jit(lambda *a: X.first_free_alternative(world, *a, chunk))(s, xy, h0, need)

    offsets = jnp.array(X._OFFSETS[1:], jnp.float32) * (math.pi / 4)
    step = jnp.float32(world.config.micro_step)
    every = jax.jit(jax.vmap(lambda s_, p, h: jax.vmap(lambda o: X._probe(world, s_, p, h + o, step))(offsets)))
    ok, full_all = (np.asarray(a) for a in every(s, xy, h0))
    want_k = np.where(ok.any(1) & np.asarray(need), ok.argmax(1) + 1, 0)
    want_full = np.where(want_k > 0, full_all[np.arange(n), np.maximum(want_k - 1, 0)], False)
    assert (want_k > 1).sum() >= 10 and (np.asarray(need) & ~ok.any(1)).sum() >= 1  # later alternatives, and none
    np.testing.assert_array_equal(np.asarray(k), want_k)
    np.testing.assert_array_equal(np.asarray(full), want_full)


# ---------------------------------------------------------------------------
# the views' fields of view
# ---------------------------------------------------------------------------


def _edge_rays(cfg: T.SimConfig, yaw: float, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit world directions of the left and right image edges of view ``k``
    (pixel columns u = 0 and u = W at the optical centre's row), through the
    executor's own camera (:func:`ignjax.sim.executor.view_camera`)."""
    W, H = cfg.image_size
    K, R_wc, _ = X.view_camera(cfg, jnp.array([0.0, 0.0, yaw], jnp.float32), jnp.int32(k))
    rays = []
    for u in (0.0, float(W)):
        d = np.asarray(G.matvec3(R_wc, G.pixel_ray(K, jnp.array([u, H / 2], jnp.float32))), np.float64)
        rays.append(d / np.linalg.norm(d))
    return rays[0], rays[1]


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return math.degrees(math.acos(float(np.clip(a @ b, -1.0, 1.0))))


@pytest.mark.parametrize("n_views, fov", [(4, 90.0), (12, 30.0)])
def test_four_and_twelve_views_tile_the_circle(n_views, fov):
    """Each view is 360 / n degrees wide, the widths sum to 360, and the left
    edge ray of view k (views run counter-clockwise) is the right edge ray of
    view k + 1: no overlap and no gap between neighbours."""
    cfg = T.SimConfig(n_views=n_views)
    assert cfg.view_hfov == fov
    yaw = 0.4
    widths = []
    for k in range(n_views):
        left, right = _edge_rays(cfg, yaw, k)
        widths.append(_angle(left, right))
        _, right_of_next = _edge_rays(cfg, yaw, (k + 1) % n_views)
        np.testing.assert_allclose(left, right_of_next, atol=1e-6)
    np.testing.assert_allclose(widths, fov, atol=1e-3)
    assert sum(widths) == pytest.approx(360.0, abs=1e-2)


def test_eight_views_stay_ninety_degrees_and_overlap_by_half():
    """The paper's main setting, unchanged: 90-degree views 45 degrees apart,
    so the right edge of view k + 1 lies on view k's optical axis."""
    cfg = T.SimConfig()
    assert cfg.n_views == 8 and cfg.view_hfov == cfg.hfov == 90.0
    for k in range(8):
        left, right = _edge_rays(cfg, -1.1, k)
        assert _angle(left, right) == pytest.approx(90.0, abs=1e-3)
        _, right_of_next = _edge_rays(cfg, -1.1, (k + 1) % 8)
        axis = np.array([math.cos(-1.1 + k * math.pi / 4), math.sin(-1.1 + k * math.pi / 4), 0.0])
        np.testing.assert_allclose(right_of_next, axis, atol=1e-6)


def test_the_hfov_setting_belongs_to_the_eight_views():
    with pytest.raises(ConfigError, match="sim.hfov"):
        T.SimConfig(n_views=12, hfov=80.0)
    assert T.SimConfig(hfov=80.0).view_hfov == 80.0 and T.SimConfig(n_views=4).view_hfov == 90.0


def test_the_oracle_sees_in_front_with_the_front_views_width(room):
    """The crate 2 m ahead, 25 degrees left of the heading: in the front view
    of 8 (90 degrees wide) but not of 12 (30 degrees); 10 degrees left: in both."""
    from types import SimpleNamespace

    from ignjax.sim.oracle import target_visible_front

    bank = room["bank"]
    ep = SimpleNamespace(scene=jnp.int32(0), target=jnp.int32(0))
    seen = {}
    for n_views in (8, 12):
        world = World(bank, room["world"].fields, T.SimConfig(n_views=n_views))
        for deg in (25.0, 10.0):
            pose = jnp.array([2.0, LANE_Y, -math.radians(deg)], jnp.float32)
            seen[n_views, deg] = bool(target_visible_front(world, ep, pose))
    assert seen == {(8, 25.0): True, (8, 10.0): True, (12, 25.0): False, (12, 10.0): True}
