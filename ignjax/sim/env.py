"""The simulator: pure ``reset`` / ``step`` / ``observe`` / ``outcome`` for ONE episode.

Batching is ``jax.vmap`` applied once, by the caller; the :class:`World`
(scene bank + goal fields) is passed unbatched. :func:`step_batch`,
:func:`execute_moves` and :func:`observe_batch` are the same transitions for
a batch, organised so that rows pay only for the work they need (used by
:func:`ignjax.sim.rollout.rollout_rows`); the one-episode :func:`step` is
:func:`step_batch` on a batch of one, so there is one executor.

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
  activates a persistent hint whose qualitative progress is updated after
  every MOVE. Type 4 says yes only if the target (or the queried
  candidate, which must then be the target) is visible in the current
  front view within ``confirm_range`` metres; a yes starts the follow-up
  (stop now within ``stop_radius``, else one closer move then stop).
* **STOP** ends the episode.

Distances: the geodesic distance to the target is read from the target's
geodesic field (seeded around its footprint, :func:`ignjax.scenes.bank.target_field`);
success is judged on it by default (Habitat's convention). The Euclidean
distance to the footprint is reported too.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.errors import ConfigError
from ignjax.scenes.bank import SceneBank
from ignjax.sim import geometry as G
from ignjax.sim.rays import queries as SR
from ignjax.sim import types as T
from ignjax.sim.compact import masked_map

_TWO_PI = 2.0 * math.pi


@partial(jax.tree_util.register_dataclass, data_fields=["bank", "fields", "fine", "packed_obs"], meta_fields=["config"])
@dataclass(frozen=True)
class World:
    """Everything a rollout reads that is shared by all episodes.

    Attributes:
        bank: the scene bank.
        fields: (F, H, W) float32 geodesic fields of the episodes' targets
            (on the bank's padded grid); episodes index them by ``field``.
        config: static simulator configuration.
        fine: (S, FINE * H, FINE * W) uint8 probe map on cells of
            ``resolution / FINE`` (:data:`FINE` = 4), one bit per probe
            height (:func:`probe_heights`: the collision heights, then the
            eye height and :data:`LOW_OBS_HEIGHT` for free-space
            observations), set when the cell's centre at that height lies
            inside a primitive (exact point-in-primitive tests of the
            voxel's column segment), so rays that graze a partly occupied
            voxel are not stopped by it; one gather answers every height of
            a probe sample. Derived from the bank when not given.
        packed_obs: (S, H, W) uint32 the probe map's observation heights
            packed per navigation cell (:func:`pack_probe_map`): bits
            ``2 (4 i + j)`` and ``2 (4 i + j) + 1`` are fine cell (i, j) of the
            cell at eye height and at :data:`LOW_OBS_HEIGHT`. The
            observation's long free-space rays read it: the same answers as
            :attr:`fine` from a table a quarter its size (6x faster under
            ``vmap`` on CPU, where those rays miss the cache). Derived when
            not given.
    """

    bank: SceneBank
    fields: jax.Array
    config: T.SimConfig = T.SimConfig()
    fine: jax.Array | None = None
    packed_obs: jax.Array | None = None

    def __post_init__(self):
        if self.fine is None:
            object.__setattr__(self, "fine", probe_map(self.bank, self.config))
        n_col = len(self.config.collision_heights)
        if self.packed_obs is None:
            object.__setattr__(self, "packed_obs", pack_probe_map(self.fine, (1 << n_col, 1 << (n_col + 1))))


LOW_OBS_HEIGHT = 0.45
DEPTH_ELEVATION = math.radians(55.0)  # steepest pixel ray followed to the full waypoint range
DEPTH_EXACT_PRIMS = 8  # primitives tested exactly per occupied voxel by the depth ray
DEPTH_ITERATIONS = 64  # traversal steps of the depth ray (free space is crossed several voxels at a time)


def probe_heights(config: T.SimConfig) -> tuple[float, ...]:
    """Heights of the bits of :attr:`World.fine` (collision heights, eye height, low observation height)."""
    hs = tuple(config.collision_heights) + (config.eye_height, LOW_OBS_HEIGHT)
    if len(hs) > 8:
        raise ConfigError(None, "collision_heights", f"at most 6 heights are supported, got {len(hs) - 2}")
    return hs


FINE = 4  # fine probe cells per navigation cell, along each axis
_FINE_SHIFT = FINE.bit_length() - 1  # log2(FINE): packed-map indices by shifts and masks (also below 0)
assert 1 << _FINE_SHIFT == FINE, "FINE must be a power of two"
FINE_GROW = 0.35  # fine cells test primitives grown by this many fine cells (no ray slips past a corner)


def _inside_prims(prims: np.ndarray, pts: np.ndarray, grow: float = 0.0) -> np.ndarray:
    """(N, K) bool: point n lies inside primitive row k (``prims`` (N, K, 18), ``pts`` (N, 3)),
    grown sideways by ``grow`` metres (local x/y half extents and quadric radii)."""
    c = prims[..., 0:3]
    R = prims[..., 3:12].reshape(prims.shape[:-1] + (3, 3))
    h0 = prims[..., 12:15]
    g = np.array([grow, grow, 0.0])  # grown sideways only: a probe at height h must not see a top just below h
    h = np.where(h0 >= 0, h0 + g, h0)
    q0 = prims[..., 15:18]
    q = np.where(q0 > 0, q0 / (1.0 + g * np.sqrt(np.maximum(q0, 0.0))) ** 2, 0.0)  # 1/r^2 -> 1/(r+grow)^2
    d = pts[:, None, :] - c
    local = np.einsum("nkij,nki->nkj", R, d)  # R^T d
    in_box = np.all(np.abs(local) <= h, axis=-1) & (h0[..., 0] >= 0)
    return in_box & ((q * local * local).sum(-1) <= 1.0)


def probe_map(bank: SceneBank, config: T.SimConfig) -> jax.Array:
    """(S, FINE H, FINE W) uint8 probe bits on fine cells (see :class:`World`).

    A fine cell's bit for height h is set when its centre at height h lies
    inside a primitive of its voxel's column segment grown by
    ``FINE_GROW`` fine cells (voxels entirely inside
    a primitive, and segments with more primitives than the ray grid lists
    or marked approximate, count as occupied); cells outside the ray grid
    are free."""
    g, r = bank.grid, bank.rays
    S, H, W = np.asarray(g.navigable).shape
    vox = np.asarray(r.voxcode)
    seg_start, seg_count = np.asarray(r.seg_start), np.asarray(r.seg_count)
    seg_prims, approx, prims = np.asarray(r.seg_prims), np.asarray(r.approx), np.asarray(r.prims)
    fr = g.resolution / FINE
    rows, cols = np.meshgrid(np.arange(H * FINE), np.arange(W * FINE), indexing="ij")
    out = np.zeros((S, H * FINE, W * FINE), np.uint8)
    maxc = max(int(seg_count.max(initial=0)), 1)
    for si in range(S):
        x = float(np.asarray(g.origin[si, 0])) + (cols + 0.5) * fr
        y = float(np.asarray(g.origin[si, 1])) + (rows + 0.5) * fr
        vc = np.floor((x - float(np.asarray(r.origin[si, 0]))) / r.resolution).astype(np.int64)
        vr = np.floor((y - float(np.asarray(r.origin[si, 1]))) / r.resolution).astype(np.int64)
        wv, hv, zv = (int(v) for v in np.asarray(r.dims[si]))
        inside = (vc >= 0) & (vc < wv) & (vr >= 0) & (vr < hv)
        vcc, vrr = np.clip(vc, 0, vox.shape[3] - 1), np.clip(vr, 0, vox.shape[2] - 1)
        bits = np.zeros(rows.shape, np.uint8)
        for j, h in enumerate(probe_heights(config)):
            k = int(math.floor(h / r.slice_height + 1e-6))
            if k >= zv:
                occ = np.zeros(rows.shape, bool)
            else:
                code = vox[si, k, vrr, vcc]
                occ = code == 1
                part = np.nonzero((code == 0) & inside)
                if len(part[0]):
                    band = min(k // r.slices_per_band, seg_start.shape[3] - 1)
                    pr, pc = vrr[part], vcc[part]
                    st = seg_start[si, pr, pc, band]
                    cnt = seg_count[si, pr, pc, band].astype(np.int64)
                    rough = approx[si, pr, pc, band]
                    idx = np.clip(st[:, None] + np.arange(maxc)[None], 0, seg_prims.shape[1] - 1)
                    ids = seg_prims[si, idx]
                    use = (np.arange(maxc)[None] < cnt[:, None]) & (ids >= 0)
                    rows_p = prims[si][:, np.clip(ids, 0, prims.shape[2] - 1)].transpose(1, 2, 0)  # (n, maxc, 18)
                    pts = np.stack([x[part], y[part], np.full(len(pr), h)], 1)
                    hit = np.any(_inside_prims(rows_p, pts, FINE_GROW * fr) & use, axis=1) | rough
                    occ = occ.copy()
                    occ[part] = hit
            bits |= (np.where(inside, occ, False).astype(np.uint8) << j)
        out[si] = bits
    return jnp.asarray(out)


def _fine_index(world: World, s, xy):
    """(row, col, inside): the fine probe cell of ``xy`` (..., 2) and whether it lies in the grid."""
    g = world.bank.grid
    fr = g.resolution / FINE
    col = jnp.floor((xy[..., 0] - g.origin[s, 0]) / fr).astype(jnp.int32)
    row = jnp.floor((xy[..., 1] - g.origin[s, 1]) / fr).astype(jnp.int32)
    inside = (row >= 0) & (col >= 0) & (row < g.shape[s, 0] * FINE) & (col < g.shape[s, 1] * FINE)
    return row, col, inside


def fine_at(world: World, s, xy):
    """() int32 fine probe bits at ``xy`` (``xy`` (..., 2)); outside the grid (open space beyond an
    outside door, as ``mj_ray`` sees it) nothing is occupied: the navigable mask keeps the agent in."""
    row, col, inside = _fine_index(world, s, xy)
    b = world.fine[s, jnp.clip(row, 0, world.fine.shape[1] - 1), jnp.clip(col, 0, world.fine.shape[2] - 1)]
    return jnp.where(inside, b.astype(jnp.int32), 0)


def pack_probe_map(fine, groups: tuple[int, ...]) -> jax.Array:
    """(S, H, W) uint32 probe bits packed per navigation cell.

    Fine cell (i, j) of a navigation cell (i, j in 0..FINE-1, row and column
    within the cell) owns bits ``len(groups) * (FINE i + j) + g``; bit g is set
    when the fine cell has any of the probe bits in ``groups[g]``.

    Args:
        fine: (S, FINE H, FINE W) uint8 probe map (:attr:`World.fine`).
        groups: probe-bit masks, at most 32 / FINE^2 of them.
    """
    n = len(groups)
    if n * FINE * FINE > 32:
        raise ValueError(f"{n} groups of {FINE * FINE} fine cells do not fit in 32 bits")
    f = np.asarray(fine)
    S, FH, FW = f.shape
    blocks = f.reshape(S, FH // FINE, FINE, FW // FINE, FINE)
    out = np.zeros((S, FH // FINE, FW // FINE), np.uint32)
    for i in range(FINE):
        for j in range(FINE):
            for g, m in enumerate(groups):
                bit = ((blocks[:, :, i, :, j] & m) != 0).astype(np.uint32)
                out |= bit << np.uint32(n * (FINE * i + j) + g)
    return jnp.asarray(out)


def packed_at(world: World, table, n_groups: int, s, xy):
    """(...) uint32 group bits of a packed probe map (:func:`pack_probe_map`)
    at ``xy`` (..., 2); 0 outside the grid, as :func:`fine_at`."""
    row, col, inside = _fine_index(world, s, xy)
    w = table[s, jnp.clip(row >> _FINE_SHIFT, 0, table.shape[1] - 1), jnp.clip(col >> _FINE_SHIFT, 0, table.shape[2] - 1)]
    sub = (((row & (FINE - 1)) << _FINE_SHIFT) | (col & (FINE - 1))).astype(jnp.uint32)
    bits = (w >> (jnp.uint32(n_groups) * sub)) & jnp.uint32((1 << n_groups) - 1)
    return jnp.where(inside, bits, jnp.uint32(0))


def _march(occupied, xy, heading, max_dist: float, step: float):
    """Free distance along a horizontal ray: the distance of the last sample
    before the first one where ``occupied`` ((n, 2) points -> (n,) bool) holds
    (``max_dist`` when none is within range); fixed steps of ``step``."""
    n = int(math.ceil(max_dist / step))
    t = jnp.arange(1, n + 1, dtype=jnp.float32) * step
    pts = xy[None] + t[:, None] * jnp.stack([jnp.cos(heading), jnp.sin(heading)])[None]
    hit = occupied(pts)
    return jnp.where(jnp.any(hit), t[jnp.argmax(hit)] - step, jnp.float32(max_dist))


def probe_free(world: World, s, xy, heading, mask: int, max_dist: float, step: float):
    """Free distance along a horizontal ray over the fine probe map: the
    distance of the last sample before the first one whose bits in ``mask``
    are set (``max_dist`` when none is within range). Fixed-step (``step``)
    march over cells of ``resolution / FINE``. At the collision heights and
    the controller's range (``collision_distance`` plus one cell) within one
    navigation cell of ``mj_ray`` on >= 99.5% of random rays (tested); the
    observation reads the same bits from :attr:`World.packed_obs`."""
    return _march(lambda p: (fine_at(world, s, p) & mask) != 0, xy, heading, max_dist, step)


# ---------------------------------------------------------------------------
# small helpers (one episode)
# ---------------------------------------------------------------------------


def _cell(world: World, s, xy):
    g = world.bank.grid
    col = jnp.floor((xy[..., 0] - g.origin[s, 0]) / g.resolution).astype(jnp.int32)
    row = jnp.floor((xy[..., 1] - g.origin[s, 1]) / g.resolution).astype(jnp.int32)
    return row, col


def navigable_at(world: World, s, xy):
    """(...) bool: the cell containing ``xy`` (..., 2) is navigable in scene ``s``."""
    g = world.bank.grid
    row, col = _cell(world, s, xy)
    inside = (row >= 0) & (col >= 0) & (row < g.shape[s, 0]) & (col < g.shape[s, 1])
    return inside & g.navigable[s, jnp.clip(row, 0, g.navigable.shape[1] - 1), jnp.clip(col, 0, g.navigable.shape[2] - 1)]


def room_at(world: World, s, xy):
    """() int32 room index at ``xy`` (-1 outside rooms)."""
    g = world.bank.grid
    row, col = _cell(world, s, xy)
    inside = (row >= 0) & (col >= 0) & (row < g.shape[s, 0]) & (col < g.shape[s, 1])
    r = g.room[s, jnp.clip(row, 0, g.room.shape[1] - 1), jnp.clip(col, 0, g.room.shape[2] - 1)]
    return jnp.where(inside, r, -1)


def geodesic_to_target(world: World, ep: T.EpisodeSpec, xy):
    """() float32 geodesic distance from ``xy`` to the episode's target."""
    g = world.bank.grid
    row, col = _cell(world, ep.scene, xy)
    inside = (row >= 0) & (col >= 0) & (row < g.shape[ep.scene, 0]) & (col < g.shape[ep.scene, 1])
    # index the field stack directly: `fields[ep.field]` under vmap would copy a whole field per episode
    val = world.fields[ep.field, jnp.clip(row, 0, world.fields.shape[1] - 1), jnp.clip(col, 0, world.fields.shape[2] - 1)]
    return jnp.where(inside, val, jnp.inf)


def euclidean_to_target(world: World, ep: T.EpisodeSpec, xy):
    """() float32 2-D distance from ``xy`` to the target's floor footprint."""
    inst = world.bank.instances
    c = inst.center[ep.scene, ep.target]
    h = inst.half_extents[ep.scene, ep.target]
    yaw = inst.yaw[ep.scene, ep.target]
    d = xy - c[:2]
    cy, sy = jnp.cos(yaw), jnp.sin(yaw)
    lx = d[0] * cy + d[1] * sy
    ly = -d[0] * sy + d[1] * cy
    return jnp.hypot(jnp.maximum(jnp.abs(lx) - h[0], 0.0), jnp.maximum(jnp.abs(ly) - h[1], 0.0))


def _sector(rel):
    """Sector 0..7 (view layout) of a relative angle."""
    return (jnp.round(G.wrap_angle(rel) / (math.pi / 4)).astype(jnp.int32)) % 8


# ---------------------------------------------------------------------------
# reset
# ---------------------------------------------------------------------------


def reset(world: World, episode: T.EpisodeSpec, key: jax.Array | None = None) -> T.SimState:
    """Initial state of one episode (deterministic; ``key`` is accepted for
    API symmetry with stochastic environments and unused)."""
    del key
    cfg = world.config
    start = episode.start.astype(jnp.float32)
    d0 = geodesic_to_target(world, episode, start[:2])
    return T.SimState(
        episode=episode, pose=start, step=jnp.int32(0), n_questions=jnp.zeros(4, jnp.int32), n_refused=jnp.int32(0),
        n_invalid=jnp.int32(0), trace_type=jnp.zeros(cfg.trace_len, jnp.int32),
        trace_step=jnp.full(cfg.trace_len, -1, jnp.int32), trace_charged=jnp.zeros(cfg.trace_len, bool),
        n_trace=jnp.int32(0), path_length=jnp.float32(0.0), min_distance=d0.astype(jnp.float32),
        done=~episode.valid, stop_reason=jnp.int32(T.RUNNING), blocked=jnp.zeros(8, bool), last_move=jnp.float32(0.0),
        waypoint=start[:2], moves_since_confirm=jnp.int32(0), answers=T.Answer.empty(),
    )


# ---------------------------------------------------------------------------
# executor
# ---------------------------------------------------------------------------


def pixel_waypoint(world: World, s, pose, direction, col, row):
    """The executor's waypoint for a grid cell of a view (before the controller).

    Returns:
        (waypoint (2,), hit_obstacle (), used_depth (), used_floor ()).
    """
    cfg = world.config
    W, H = cfg.image_size
    K = G.intrinsics(float(W), float(H), math.radians(cfg.hfov))
    yaw = pose[2] + direction.astype(jnp.float32) * (math.pi / 4)
    uv = G.grid_to_pixel(col, row, float(W), float(H))
    d_c = G.pixel_ray(K, uv)  # z component 1
    R_wc = G.view_rotation(yaw)
    t_wc = jnp.array([pose[0], pose[1], cfg.eye_height], jnp.float32)
    d_w = G.matvec3(R_wc, d_c)
    norm = jnp.sqrt(d_w[0] * d_w[0] + d_w[1] * d_w[1] + d_w[2] * d_w[2])
    u = d_w / norm
    # depth by ray casting: voxel traversal with exact primitive tests (SR.march). A surface whose
    # horizontal distance exceeds horizon + pullback yields the same clipped waypoint as no surface,
    # so the ray is followed only that far (as a 3-D range, for rays up to DEPTH_ELEVATION steep).
    horiz = jnp.sqrt(u[0] * u[0] + u[1] * u[1])
    reach = (cfg.horizon + cfg.pullback + world.bank.grid.resolution) / jnp.maximum(horiz, 1e-3)
    static = min(cfg.depth_range, (cfg.horizon + cfg.pullback + world.bank.grid.resolution) / math.cos(DEPTH_ELEVATION))
    dist = SR.march(world.bank.rays, s, t_wc, u, jnp.minimum(jnp.minimum(reach, static), cfg.depth_range),
                    static_range=static, outside_hits=False, exact=DEPTH_EXACT_PRIMS,
                    iterations=DEPTH_ITERATIONS)
    valid_depth = jnp.isfinite(dist) & (dist <= cfg.depth_range)
    z = jnp.where(valid_depth, dist / norm, 0.0)  # z-depth along the optical axis (d_c has z = 1)
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
    col_mask = (1 << len(cfg.collision_heights)) - 1
    n_nav = min(int(math.ceil(cfg.micro_step / spacing)), n_samples)  # samples a micro-step can reach
    t_nav = t[:n_nav]
    u = jnp.stack([jnp.cos(h), jnp.sin(h)])
    pts = xy[None] + t[:, None] * u[None]
    hit = (fine_at(world, s, pts) & col_mask) != 0
    free = jnp.where(jnp.any(hit), t[jnp.argmax(hit)] - spacing, jnp.float32(cfg.collision_distance + res))
    nav = navigable_at(world, s, jnp.concatenate([pts[:n_nav], (xy + length * u)[None], (xy + 0.5 * length * u)[None]]))
    along = nav[:n_nav]
    full = jnp.all(jnp.where(t_nav <= length, along, True)) & nav[n_nav]
    half = jnp.all(jnp.where(t_nav <= 0.5 * length, along, True)) & nav[n_nav + 1]
    return (free >= cfg.collision_distance) & (full | half), full


_OFFSETS = (0.0, 1.0, -1.0, 2.0, -2.0, 3.0, -3.0, 4.0)  # candidate headings, x 45 degrees: desired first, left first


def execute_moves(world: World, states: T.SimState, direction, col, row, mask, chunk: int | None = None):
    """Run the executor for the MOVEs of a batch (leading axis B).

    The controller of the module docstring (one episode's :func:`execute_move`
    is this function on a batch of one), organised so a batch pays only for
    the work its episodes need (:func:`ignjax.sim.compact.masked_map`):
    waypoints are cast for the rows in ``mask`` only, micro-steps run while
    any row is still moving, each micro-step probes the desired heading of
    the moving rows and the seven neighbouring headings only of the rows
    whose desired heading is blocked; each row takes the first free heading in
    :data:`_OFFSETS` order, so a row's result does not depend on the others.

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
    cfg = world.config
    ep = states.episode
    s = ep.scene
    pose0 = states.pose
    B = mask.shape[0]
    wp = masked_map(lambda a: pixel_waypoint(world, *a)[0], mask, (s, pose0, direction, col, row), pose0[:, :2], chunk)
    yaw0 = pose0[:, 2]
    offsets = jnp.array(_OFFSETS, jnp.float32) * (math.pi / 4)
    rows = jnp.arange(B)

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
        alt = jax.vmap(lambda s_, xy, h: _probe(world, s_, xy, h, jnp.float32(cfg.micro_step)), in_axes=(None, None, 0))
        ok_alt, full_alt = masked_map(lambda a: alt(a[0], a[1], a[2] + offsets[1:]), active & ~ok0, (s, pose[:, :2], h0),
                                      (jnp.zeros((B, 7), bool), jnp.zeros((B, 7), bool)), chunk)
        ok = jnp.concatenate([ok0[:, None], ok_alt], 1)
        full = jnp.concatenate([full0[:, None], full_alt], 1)
        k = jnp.argmax(ok, axis=1)
        any_ok = jnp.any(ok, axis=1)
        sec = _sector(h0 - yaw0)
        blocked = blocked.at[rows, sec].set(blocked[rows, sec] | (~ok0 & active))
        heading = h0 + offsets[k]
        lengths = jnp.where(k == 0, len0, jnp.float32(cfg.micro_step))
        length = jnp.where(full[rows, k], lengths, 0.5 * lengths)
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
    return pose, moved, dmin, blocked, wp


def _one(tree):
    return jax.tree.map(lambda x: x[None], tree)


def _unone(tree):
    return jax.tree.map(lambda x: x[0], tree)


def execute_move(world: World, state: T.SimState, direction, col, row):
    """Run the executor for one MOVE of one episode (:func:`execute_moves` on a batch of one).

    Returns the updated pose, path length moved, minimum geodesic distance,
    blocked mask and waypoint."""
    args = _one((state, direction, col, row, jnp.array(True)))
    return _unone(execute_moves(world, *args))


# ---------------------------------------------------------------------------
# oracle
# ---------------------------------------------------------------------------


def target_visible_front(world: World, ep: T.EpisodeSpec, pose):
    """() bool: the target is in the front view's field of view, within
    ``confirm_range`` and in line of sight."""
    cfg = world.config
    inst = world.bank.instances
    c = inst.center[ep.scene, ep.target]
    rel = jnp.arctan2(c[1] - pose[1], c[0] - pose[0]) - pose[2]
    in_fov = jnp.abs(G.wrap_angle(rel)) <= math.radians(cfg.hfov) / 2
    close = euclidean_to_target(world, ep, pose[:2]) <= cfg.confirm_range
    eye = jnp.array([pose[0], pose[1], cfg.eye_height], jnp.float32)
    seen = instance_in_sight(world, ep.scene, ep.target, eye)
    return in_fov & close & seen


def instance_in_sight(world: World, s, i, eye):
    """() bool: nothing blocks the view from ``eye`` to instance i's box
    (its centre or top centre) before the ray enters the box."""
    cfg = world.config
    inst = world.bank.instances
    c = inst.center[s, i]
    h = inst.half_extents[s, i]
    yaw = inst.yaw[s, i]
    pts = jnp.stack([c, c.at[2].set(c[2] + h[2] * 0.9)])

    def one(p):
        d = p - eye
        L = jnp.linalg.norm(d)
        u = d / jnp.maximum(L, 1e-6)
        t_in = SR.box_entry(eye, u, c, h, yaw)
        before = L - jnp.minimum(t_in, L) + 0.06
        return SR.segment_clear(world.bank.rays, s, eye, p, before, cfg.obs_range + 1.0, world.bank.grid.resolution * 2)

    return jnp.any(jax.vmap(one)(pts)) & inst.valid[s, i]


def route_facts(world: World, ep: T.EpisodeSpec, pose):
    """Type-3 facts: follow the target's geodesic field downhill from the
    agent for ``hint_lookahead`` metres.

    Returns:
        (room_label, sector, landmark_category, in_room, hint_point (2,)).
    """
    cfg = world.config
    bank = world.bank
    g = bank.grid
    s = ep.scene
    fi = ep.field
    res = g.resolution
    n = int(math.ceil(cfg.hint_lookahead / res))
    row0, col0 = _cell(world, s, pose[:2])
    Hh, Ww = world.fields.shape[1:]
    nbr = jnp.array([[-1, -1], [-1, 0], [-1, 1], [0, -1], [0, 1], [1, -1], [1, 0], [1, 1]], jnp.int32)
    cost = jnp.where(jnp.all(nbr != 0, axis=1), res * math.sqrt(2), res).astype(jnp.float32)
    room0 = room_at(world, s, pose[:2])

    def walk(_, carry):
        r, c, travelled, exit_r, exit_c, left = carry
        rr = jnp.clip(r + nbr[:, 0], 0, Hh - 1)
        cc = jnp.clip(c + nbr[:, 1], 0, Ww - 1)
        vals = world.fields[fi, rr, cc]
        here = world.fields[fi, jnp.clip(r, 0, Hh - 1), jnp.clip(c, 0, Ww - 1)]
        k = jnp.argmin(vals)
        better = (vals[k] < here) & (travelled < cfg.hint_lookahead)
        nr = jnp.where(better, rr[k], r)
        nc = jnp.where(better, cc[k], c)
        travelled = travelled + jnp.where(better, cost[k], 0.0)
        room_here = g.room[s, nr, nc]
        newly = better & ~left & (room_here != room0) & (room_here >= 0)
        exit_r = jnp.where(newly, nr, exit_r)
        exit_c = jnp.where(newly, nc, exit_c)
        left = left | newly
        return nr, nc, travelled, exit_r, exit_c, left

    r, c, _, er, ec, left = jax.lax.fori_loop(0, n, walk, (row0, col0, jnp.float32(0.0), row0, col0, jnp.array(False)))
    to_world = lambda rr, cc: jnp.stack([g.origin[s, 0] + (cc + 0.5) * res, g.origin[s, 1] + (rr + 0.5) * res])  # noqa: E731
    end = to_world(r, c)
    exit_pt = to_world(er, ec)
    aim = jnp.where(left, exit_pt, end)
    sector = _sector(jnp.arctan2(aim[1] - pose[1], aim[0] - pose[0]) - pose[2])
    room_end = g.room[s, r, c]
    room_next = jnp.where(left, g.room[s, er, ec], room_end)
    label = jnp.where(room_next >= 0, bank.rooms.label[s, jnp.maximum(room_next, 0)], -1)
    # landmark: a sizeable object near the route's end (not of the goal category)
    inst = bank.instances
    big = inst.valid[s] & ~inst.structural[s] & (inst.half_extents[s, :, 0] * inst.half_extents[s, :, 1] > 0.04) \
        & (inst.category[s] != ep.category) & (inst.support[s] < 0)
    dist = jnp.linalg.norm(inst.center[s, :, :2] - end[None], axis=1)
    dist = jnp.where(big, dist, jnp.inf)
    j = jnp.argmin(dist)
    landmark = jnp.where(dist[j] <= 1.5, inst.category[s, j], -1)
    return label.astype(jnp.int32), sector, landmark.astype(jnp.int32), ~left, end


def ask(world: World, state: T.SimState, qtype, candidate) -> T.SimState:
    """Apply one question (charging, budget, caching, facts, follow-up)."""
    cfg = world.config
    ep = state.episode
    a = state.answers
    charged_so_far = jnp.sum(state.n_questions)
    allowed = charged_so_far < cfg.max_questions
    q = jnp.clip(qtype, 1, 4)
    n_q = state.n_questions.at[q - 1].add(jnp.where(allowed, 1, 0))
    slot = jnp.minimum(state.n_trace, cfg.trace_len - 1)
    trace_type = state.trace_type.at[slot].set(q)
    trace_step = state.trace_step.at[slot].set(state.step)
    trace_charged = state.trace_charged.at[slot].set(allowed)

    # Type 1 / Type 2 facts (cached; charged every time)
    t1 = dict(color=ep.fact_attrs[0], material=ep.fact_attrs[1], size=ep.fact_attrs[2], state=ep.fact_attrs[3],
              on_category=ep.fact_on, near_categories=ep.fact_near)
    goal_label = jnp.where(ep.goal_room >= 0, world.bank.rooms.label[ep.scene, jnp.maximum(ep.goal_room, 0)], -1)
    # Type 3
    label3, sector3, land3, inroom3, point3 = route_facts(world, ep, state.pose)
    # Type 4
    vis = target_visible_front(world, ep, state.pose)
    yes = vis & ((candidate < 0) | (candidate == ep.target))
    close = geodesic_to_target(world, ep, state.pose[:2]) <= cfg.stop_radius
    follow = jnp.where(yes, jnp.where(close, T.FOLLOW_STOP_NOW, T.FOLLOW_ONE_MOVE), T.FOLLOW_NONE)

    is1, is2, is3, is4 = (allowed & (q == k) for k in (1, 2, 3, 4))
    new = dataclasses.replace(
        a,
        known=a.known.at[q - 1].set(a.known[q - 1] | allowed),
        last_type=jnp.where(allowed, q, a.last_type),
        refused=~allowed,
        color=jnp.where(is1, t1["color"], a.color), material=jnp.where(is1, t1["material"], a.material),
        size=jnp.where(is1, t1["size"], a.size), state=jnp.where(is1, t1["state"], a.state),
        on_category=jnp.where(is1, t1["on_category"], a.on_category),
        near_categories=jnp.where(is1, t1["near_categories"], a.near_categories),
        room_label=jnp.where(is2, goal_label, a.room_label),
        region_category=jnp.where(is2, ep.region_category, a.region_category),
        hint_room_label=jnp.where(is3, label3, a.hint_room_label), hint_sector=jnp.where(is3, sector3, a.hint_sector),
        hint_landmark=jnp.where(is3, land3, a.hint_landmark), hint_in_room=jnp.where(is3, inroom3, a.hint_in_room),
        hint_point=jnp.where(is3, point3, a.hint_point), hint_active=a.hint_active | is3,
        hint_progress=jnp.where(is3, T.HINT_NONE, a.hint_progress),
        confirm=jnp.where(is4, yes.astype(jnp.int32), a.confirm),
        follow_up=jnp.where(is4, follow, a.follow_up),
    )
    return dataclasses.replace(
        state, n_questions=n_q, n_refused=state.n_refused + jnp.where(allowed, 0, 1), trace_type=trace_type,
        trace_step=trace_step, trace_charged=trace_charged, n_trace=state.n_trace + 1, answers=new,
        moves_since_confirm=jnp.where(is4 & yes, 0, state.moves_since_confirm),
    )


def _hint_progress(world: World, ep, a: T.Answer, old_xy, new_xy):
    cfg = world.config
    d_old = jnp.linalg.norm(old_xy - a.hint_point)
    d_new = jnp.linalg.norm(new_xy - a.hint_point)
    prog = jnp.where(d_new < d_old - 0.1, T.HINT_CLOSER, jnp.where(d_new > d_old + 0.1, T.HINT_FARTHER, T.HINT_SAME))
    prog = jnp.where(d_new <= cfg.hint_reached, T.HINT_REACHED, prog)
    prog = jnp.where(geodesic_to_target(world, ep, new_xy) <= cfg.stop_radius, T.HINT_STOP, prog)
    return jnp.where(a.hint_active, prog, T.HINT_NONE).astype(jnp.int32)


# ---------------------------------------------------------------------------
# step
# ---------------------------------------------------------------------------


def sanitize_action(action: T.Action) -> tuple[T.Action, jax.Array]:
    """Clamp an action into range; returns (clamped action, was_invalid)."""
    kind = jnp.clip(action.kind, 0, 2)
    d = jnp.clip(action.direction, 0, 7)
    c = jnp.clip(action.col, 1, 8)
    r = jnp.clip(action.row, 1, 8)
    q = jnp.clip(action.question, 1, 4)
    bad = (kind != action.kind) | ((kind == T.MOVE) & ((d != action.direction) | (c != action.col) | (r != action.row))) \
        | ((kind == T.ASK) & (q != action.question))
    return T.Action(kind, d, c, r, q, action.candidate), bad


def step_batch(world: World, states: T.SimState, actions: T.Action, chunk: int | None = None) -> T.SimState:
    """One planner step of a batch of episodes (leading axis B); finished episodes stay put.

    Row for row the same as :func:`step`; the executor runs for the rows that
    MOVE and the oracle for the rows that ASK only (:func:`execute_moves`,
    :func:`ignjax.sim.compact.masked_map`)."""
    with jax.named_scope("sim_step"):
        cfg = world.config
        act, bad = jax.vmap(sanitize_action)(actions)
        live = ~states.done
        is_move = (act.kind == T.MOVE) & live
        is_ask = (act.kind == T.ASK) & live
        is_stop = act.kind == T.STOP

        # MOVE
        pose, moved, dmin, blocked, wp = execute_moves(world, states, act.direction, act.col, act.row, is_move, chunk)
        a = states.answers
        progress = jax.vmap(lambda e, ans, p0, p1: _hint_progress(world, e, ans, p0, p1))(
            states.episode, a, states.pose[:, :2], pose[:, :2])
        moved_state = dataclasses.replace(
            states, pose=pose, path_length=states.path_length + moved, min_distance=dmin, blocked=blocked,
            last_move=moved, waypoint=wp, moves_since_confirm=states.moves_since_confirm + 1,
            answers=dataclasses.replace(a, hint_progress=progress),
        )
        # ASK
        asked_state = masked_map(lambda x: ask(world, *x), is_ask, (states, act.question, act.candidate), states, chunk)
        nxt = T.tree_select(is_move, moved_state, T.tree_select(is_ask, asked_state, states))
        n_step = states.step + 1
        stop_reason = jnp.where(is_stop, T.STOPPED, jnp.where(n_step >= cfg.max_steps, T.OUT_OF_STEPS, T.RUNNING))
        nxt = dataclasses.replace(
            nxt, step=n_step, n_invalid=states.n_invalid + bad.astype(jnp.int32),
            done=stop_reason != T.RUNNING, stop_reason=stop_reason.astype(jnp.int32),
        )
        return T.tree_select(states.done, states, nxt)


def step(world: World, state: T.SimState, action: T.Action) -> T.SimState:
    """One planner step of one episode (pure). Finished episodes stay put."""
    return _unone(step_batch(world, _one(state), _one(action)))


# ---------------------------------------------------------------------------
# observe
# ---------------------------------------------------------------------------


def observe(world: World, state: T.SimState) -> T.Observation:
    """What the policy sees (no target identity, pose or distance inside)."""
    with jax.named_scope("observe"):
        cfg = world.config
        bank = world.bank
        ep = state.episode
        s = ep.scene
        pose = state.pose
        res = bank.grid.resolution
        R = cfg.obs_rays_per_view
        half_fov = math.radians(cfg.hfov) / 2
        within = (jnp.arange(R, dtype=jnp.float32) + 0.5) / R * (2 * half_fov) - half_fov  # Shape: (R,)
        rel = (jnp.arange(8, dtype=jnp.float32) * (math.pi / 4))[:, None] + within[None]  # Shape: (8, R)
        heads = pose[2] + rel

        def free(h):  # eye height and LOW_OBS_HEIGHT
            return _march(lambda p: packed_at(world, world.packed_obs, 2, s, p) != 0, pose[:2], h, cfg.obs_range, 2 * res)

        free_space = jax.vmap(jax.vmap(free))(heads)
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
        handle = jnp.where(seen, idx, -1).astype(jnp.int32)
        attrs = jnp.stack([inst.color[s, idx], inst.material[s, idx], inst.size[s, idx], inst.state[s, idx]], -1)
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
            visible_view=padk(jnp.where(seen, _sector(bearing), -1), -1),
            room_label=label.astype(jnp.int32), **_state_fields(world, state),
        )


def _state_fields(world: World, state: T.SimState) -> dict:
    """The observation's fields read from the state alone (heading, odometry, budgets, last MOVE)."""
    cfg = world.config
    pose, start = state.pose, state.episode.start
    return dict(
        heading=pose[2], odometry=jnp.stack([pose[0] - start[0], pose[1] - start[1], G.wrap_angle(pose[2] - start[2])]),
        goal_category=state.episode.category, steps_left=jnp.int32(cfg.max_steps) - state.step,
        questions_left=jnp.int32(cfg.max_questions) - jnp.sum(state.n_questions),
        n_questions=state.n_questions, blocked=state.blocked, last_move=state.last_move,
    )


def observe_batch(world: World, states: T.SimState, previous: T.Observation, moved, chunk: int | None = None) -> T.Observation:
    """:func:`observe` of a batch (leading axis B) after a step: the
    perception (rays, visible instances, room) is recomputed for the rows in
    ``moved`` only; every other row's pose is unchanged, so it keeps
    ``previous``'s perception with its state fields refreshed. Row for row
    the same as ``vmap(observe)``."""
    obs = masked_map(lambda st: observe(world, st), moved, states, previous, chunk)
    return dataclasses.replace(obs, **jax.vmap(lambda st: _state_fields(world, st))(states))


# ---------------------------------------------------------------------------
# outcomes
# ---------------------------------------------------------------------------


@partial(jax.tree_util.register_dataclass,
         data_fields=["final_distance", "final_euclidean", "min_distance", "path_length", "steps", "stopped",
                      "stop_reason", "n_questions", "n_refused", "n_invalid", "trace_type", "trace_step",
                      "trace_charged", "difficulty", "valid"], meta_fields=[])
@dataclass(frozen=True)
class OutcomeRow:
    """One episode's outcome (arrays; a leading batch axis under vmap).

    Attributes:
        final_distance: () float32 geodesic distance to the target at the end.
        final_euclidean: () float32 2-D distance to the target footprint.
        min_distance: () float32 smallest geodesic distance along the path.
        path_length: () float32 metres travelled.
        steps: () int32 planner steps used.
        stopped: () bool, ended by STOP.
        stop_reason: () int32 (see :mod:`ignjax.sim.types`).
        n_questions: (4,) int32 charged questions per type.
        n_refused: () int32 refused questions.
        n_invalid: () int32 clamped out-of-range actions.
        trace_type, trace_step, trace_charged: (T,) the question trace.
        difficulty: () int32 bin.
        valid: () bool.
    """

    final_distance: jax.Array
    final_euclidean: jax.Array
    min_distance: jax.Array
    path_length: jax.Array
    steps: jax.Array
    stopped: jax.Array
    stop_reason: jax.Array
    n_questions: jax.Array
    n_refused: jax.Array
    n_invalid: jax.Array
    trace_type: jax.Array
    trace_step: jax.Array
    trace_charged: jax.Array
    difficulty: jax.Array
    valid: jax.Array


def outcome(world: World, state: T.SimState) -> OutcomeRow:
    """The outcome row of a (finished) episode."""
    ep = state.episode
    xy = state.pose[:2]
    return OutcomeRow(
        final_distance=geodesic_to_target(world, ep, xy), final_euclidean=euclidean_to_target(world, ep, xy),
        min_distance=state.min_distance, path_length=state.path_length, steps=state.step,
        stopped=state.stop_reason == T.STOPPED, stop_reason=state.stop_reason, n_questions=state.n_questions,
        n_refused=state.n_refused, n_invalid=state.n_invalid, trace_type=state.trace_type, trace_step=state.trace_step,
        trace_charged=state.trace_charged, difficulty=ep.difficulty, valid=ep.valid,
    )


# ---------------------------------------------------------------------------
# API-boundary checks (host)
# ---------------------------------------------------------------------------


def check_action(action: T.Action) -> None:
    """Reject out-of-range actions at the API boundary (host side).

    Raises:
        ConfigError: naming the field and the allowed range.
    """
    a = jax.tree.map(np.asarray, action)
    for name, lo, hi in (("kind", 0, 2), ("direction", 0, 7), ("col", 1, 8), ("row", 1, 8), ("question", 1, 4)):
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
    n_fields = int(world.fields.shape[0])
    for k in range(scene.shape[0]):
        if not 0 <= scene[k] < n_scenes:
            raise ConfigError(None, f"episodes[{k}].scene", f"scene index {int(scene[k])} is not in the bank ({n_scenes} scenes)")
        if not (0 <= target[k] < n_inst.shape[1] and n_inst[scene[k], target[k]]):
            raise ConfigError(None, f"episodes[{k}].target", f"instance index {int(target[k])} is not in scene {world.bank.scene_ids[scene[k]]!r}")
        if not 0 <= fld[k] < n_fields:
            raise ConfigError(None, f"episodes[{k}].field", f"field index {int(fld[k])} does not exist ({n_fields} fields)")
