"""Geodesic distance fields on a navigation grid (JAX array programs).

:func:`geodesic_field` is the distance from seed cells over the navigable
mask (8-connected, no corner cutting; the same connectivity as
:attr:`~ignjax.scenes.navgrid.NavGrid.components`); :func:`seeds_from_box`
seeds it at an object's floor footprint, :func:`target_seeds` does that for
one object on a :class:`~ignjax.scenes.navgrid.NavGrid`.
"""

from __future__ import annotations

import functools
import math

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, PartitionSpec as P

from ignjax.scenes.model import OrientedBox
from ignjax.scenes.navgrid import NavGrid


_REL_TOL = 4e-7  # about 3 float32 ulps


def _sweep(d: jax.Array, w: jax.Array, axis: int, reverse: bool, n: jax.Array | None = None) -> jax.Array:
    """One directional relaxation pass along ``axis``.

    ``w[i]`` is the cost of the edge from element ``i - 1`` (``i + 1`` when
    ``reverse``) to element ``i`` along ``axis``, +inf when absent; the pass
    computes ``d'[i] = min(d[i], d'[i -/+ 1] + w[i])``, so it relaxes a whole
    straight run of cells at once.

    ``n`` (a traced int, optional) limits the pass to the first ``n``
    elements along ``axis``: a grid padded to a shared shape
    (:func:`goal_fields`) is relaxed over its own rows or columns only. The
    elements past ``n`` are left as they are, which is what a full pass
    gives them there (padding is +inf with +inf edges), and the first ``n``
    see the same carried value (+inf) as a full pass would bring them, so
    the result is the same bytes; the pass then costs ``n`` steps instead of
    ``d.shape[axis]``. Without ``n``, a ``lax.scan`` over the whole axis.
    """
    dm = jnp.moveaxis(d, axis, 0)
    wm = jnp.moveaxis(w, axis, 0)
    start = jnp.full(dm.shape[1:], jnp.inf, dm.dtype)
    if n is None:
        def step(prev, x):
            di, wi = x
            cur = jnp.minimum(di, prev + wi)
            return cur, cur

        _, out = jax.lax.scan(step, start, (dm, wm), reverse=reverse)
    else:
        def body(i, carry):
            out, prev = carry
            j = n - 1 - i if reverse else i
            cur = jnp.minimum(jax.lax.dynamic_index_in_dim(out, j, keepdims=False),
                              prev + jax.lax.dynamic_index_in_dim(wm, j, keepdims=False))
            return jax.lax.dynamic_update_index_in_dim(out, cur, j, 0), cur

        out, _ = jax.lax.fori_loop(0, n, body, (dm, start))
    return jnp.moveaxis(out, 0, axis)


def _skew_index(H: int, W: int, anti: bool) -> tuple[np.ndarray, np.ndarray]:
    """Gather/scatter indices that put the diagonals of an (H, W) grid into
    the columns of an (H, H + W - 1) array."""
    r = np.arange(H)[:, None]
    s = np.arange(H + W - 1)[None, :]
    c = (s - r) if anti else (s - (H - 1) + r)
    valid = (c >= 0) & (c < W)
    flat = np.where(valid, r * W + np.clip(c, 0, W - 1), H * W)  # H*W: the padding element
    rr, cc = np.mgrid[0:H, 0:W]
    back = rr * (H + W - 1) + ((cc + rr) if anti else (cc - rr + H - 1))
    return flat, back


def _edge_costs(nav: jax.Array, res: float):
    """Costs of the 8 move directions into each cell, +inf where not allowed."""
    inf = jnp.float32(jnp.inf)
    H, W = nav.shape
    n = nav
    pad = jnp.pad(n, 1)  # False outside
    up = pad[:-2, 1:-1]  # neighbour at row - 1
    down = pad[2:, 1:-1]  # row + 1
    left = pad[1:-1, :-2]  # col - 1
    right = pad[1:-1, 2:]  # col + 1
    ul = pad[:-2, :-2]
    ur = pad[:-2, 2:]
    dl = pad[2:, :-2]
    dr = pad[2:, 2:]
    o = jnp.float32(res)
    g = jnp.float32(res * math.sqrt(2.0))
    c = lambda m, cost: jnp.where(n & m, cost, inf)  # noqa: E731
    return {
        "from_left": c(left, o), "from_right": c(right, o), "from_up": c(up, o), "from_down": c(down, o),
        # diagonal from (r-1, c-1): needs (r-1, c) and (r, c-1)
        "from_ul": c(ul & up & left, g), "from_ur": c(ur & up & right, g),
        "from_dl": c(dl & down & left, g), "from_dr": c(dr & down & right, g),
    }


def geodesic_field(navigable: jax.Array, seeds: jax.Array, resolution: float,
                   max_rounds: int | None = None, extent: tuple | None = None) -> jax.Array:
    """Geodesic distance from seed cells over the navigable grid.

    The graph is the 8-connected grid of navigable cells: orthogonal steps
    cost ``resolution``, diagonal steps ``resolution * sqrt(2)`` and are
    allowed only when both orthogonal neighbours they pass are navigable (no
    corner cutting). The result is ``min over seeds s of seeds[s] +
    path_length(s, cell)``.

    Each ``lax.while_loop`` iteration runs eight directional min-plus sweeps
    (left-right, right-left, down, up and the four diagonals, each a
    ``lax.scan`` of ``d[i] = min(d[i], d[i - 1] + w[i])`` over rows, columns
    or diagonals), so a straight stretch of any length is relaxed in one
    iteration; iteration stops when a round changes nothing (beyond float32
    rounding of equal-length paths, a relative 4e-7), the fixed point of
    Bellman-Ford: the same distances as Dijkstra up to float32 rounding.
    A 10-room house (about 250 x 270 cells) takes about a dozen rounds.

    Args:
        navigable: (H, W) bool.
        seeds: (H, W) float32 initial cost at seed cells, +inf elsewhere;
            seeds on non-navigable cells are ignored.
        resolution: cell size, metres (static).
        max_rounds: optional cap on the rounds (None: H * W, never reached).
        extent: optional ``(rows, cols)`` (ints, may be traced): the grid's
            own size when it is padded (not navigable) to a larger shared
            shape; the sweeps then run over those rows and columns only (the
            same result, in less time; :func:`_sweep`).

    Returns:
        (H, W) float32 distances in metres, +inf where no seed is reachable
        (and on every non-navigable cell).

    Jit-able and vmappable (e.g. over seeds for many targets at once).
    """
    with jax.named_scope("geodesic_field"):
        nav = jnp.asarray(navigable, bool)
        H, W = nav.shape
        inf = jnp.float32(jnp.inf)
        d0 = jnp.where(nav, jnp.asarray(seeds, jnp.float32), inf)
        w = _edge_costs(nav, resolution)
        # diagonals as columns of skewed arrays. Shape: (H, H + W - 1)
        fwd_flat, fwd_back = _skew_index(H, W, anti=False)  # cells with c - r constant
        anti_flat, anti_back = _skew_index(H, W, anti=True)  # cells with c + r constant

        def skew(a, flat):
            return jnp.concatenate([a.reshape(-1), jnp.full((1,), inf, a.dtype)])[flat]

        def unskew(a, back):
            return a.reshape(-1)[back]

        w_ul = skew(w["from_ul"], fwd_flat)
        w_dr = skew(w["from_dr"], fwd_flat)
        w_ur = skew(w["from_ur"], anti_flat)
        w_dl = skew(w["from_dl"], anti_flat)

        rows, cols = (None, None) if extent is None else extent  # the skewed arrays keep the grid's rows

        def one_round(d):
            d = _sweep(d, w["from_left"], 1, False, cols)
            d = _sweep(d, w["from_right"], 1, True, cols)
            d = _sweep(d, w["from_up"], 0, False, rows)
            d = _sweep(d, w["from_down"], 0, True, rows)
            s = skew(d, fwd_flat)
            s = _sweep(s, w_ul, 0, False, rows)
            s = _sweep(s, w_dr, 0, True, rows)
            d = unskew(s, fwd_back)
            s = skew(d, anti_flat)
            s = _sweep(s, w_ur, 0, False, rows)
            s = _sweep(s, w_dl, 0, True, rows)
            return unskew(s, anti_back)

        cap = H * W if max_rounds is None else int(max_rounds)

        def cond(state):
            _, changed, i = state
            return changed & (i < cap)

        def body(state):
            d, _, i = state
            nd = one_round(d)
            # float sums of equal-length paths differ in the last bits; ignore such changes
            return nd, jnp.any(nd < jnp.where(jnp.isinf(d), d, d - _REL_TOL * d)), i + 1

        d, _, _ = jax.lax.while_loop(cond, body, (d0, jnp.array(True), jnp.array(0, jnp.int32)))
        return d


def seeds_from_box(navigable: jax.Array, room: jax.Array, origin: jax.Array, resolution: float,
                   center: jax.Array, half_extents: jax.Array, yaw: jax.Array, room_index: jax.Array,
                   seed_radius: float) -> jax.Array:
    """Seeds (initial costs) for the geodesic distance to an object (jnp).

    Seed cells are the navigable cells of the object's room whose centres lie
    within ``seed_radius`` of the object's floor footprint; each is seeded
    with its 2-D distance to the footprint. When no cell qualifies, the
    room's navigable cells nearest the footprint (within one cell of the
    minimum distance) are used instead. ``room_index < 0`` allows every room.

    Args:
        navigable: (H, W) bool.
        room: (H, W) int32 room-id grid.
        origin: (2,) grid origin (world x, y of cell (0, 0)'s corner).
        resolution: cell size, metres.
        center: (3,) or (2,) box centre, world.
        half_extents: (3,) or (2,) box half sizes along its own x, y.
        yaw: () box yaw, radians.
        room_index: () int32 index of the object's room, -1 for any.
        seed_radius: metres.

    Returns:
        (H, W) float32 seeds, +inf where not a seed.
    """
    H, W = navigable.shape
    inf = jnp.float32(jnp.inf)
    xs = origin[0] + (jnp.arange(W, dtype=jnp.float32) + 0.5) * resolution  # Shape: (W,)
    ys = origin[1] + (jnp.arange(H, dtype=jnp.float32) + 0.5) * resolution  # Shape: (H,)
    dx = xs[None, :] - center[0]
    dy = ys[:, None] - center[1]
    c, s = jnp.cos(yaw), jnp.sin(yaw)
    lx = dx * c + dy * s
    ly = -dx * s + dy * c
    ex = jnp.maximum(jnp.abs(lx) - half_extents[0], 0.0)
    ey = jnp.maximum(jnp.abs(ly) - half_extents[1], 0.0)
    dist = jnp.sqrt(ex**2 + ey**2).astype(jnp.float32)  # Shape: (H, W)
    allowed = navigable & ((room == room_index) | (room_index < 0))
    near = allowed & (dist <= seed_radius)
    dmin = jnp.min(jnp.where(allowed, dist, inf))
    fallback = allowed & (dist <= dmin + resolution)
    mask = jnp.where(jnp.any(near), near, fallback)
    return jnp.where(mask, dist, inf)


_seeds_jit = jax.jit(seeds_from_box, static_argnums=(3, 8))


def target_seeds(grid: NavGrid, bbox: OrientedBox, room_index: int | None, seed_radius: float = 1.0) -> np.ndarray:
    """Seeds for the geodesic distance to an object on a :class:`NavGrid`.

    See :func:`seeds_from_box`; ``room_index`` indexes ``grid.room_ids``
    (None or -1: any room).

    Returns:
        (H, W) float32 seeds, +inf where not a seed.
    """
    ri = -1 if room_index is None else int(room_index)
    out = _seeds_jit(
        jnp.asarray(grid.navigable), jnp.asarray(grid.room), jnp.asarray(grid.origin, jnp.float32),
        grid.resolution, jnp.asarray(bbox.center, jnp.float32), jnp.asarray(bbox.half_extents, jnp.float32),
        jnp.float32(bbox.yaw), jnp.int32(ri), float(seed_radius),
    )
    return np.asarray(out)


# ---------------------------------------------------------------------------
# Fields to many objects on one grid
# ---------------------------------------------------------------------------


GRID_PAD = 32
""":func:`goal_fields` pads a grid's rows and columns to multiples of this."""


def _object_field(navigable, room, origin, resolution, center, half_extents, yaw, room_index, seed_radius,
                  extent=None):
    """Geodesic field to one object: :func:`seeds_from_box`, then :func:`geodesic_field`
    (``extent``: the grid's own rows and columns, see there)."""
    seeds = seeds_from_box(navigable, room, origin, resolution, center, half_extents, yaw, room_index, seed_radius)
    return geodesic_field(navigable, seeds, resolution, extent=extent)


FIELD_AXIS = "fields"


@functools.lru_cache(maxsize=None)
def _fields_program(parts: int, resolution: float, seed_radius: float):
    """One jitted program for every caller: :func:`_object_field` vmapped
    over targets, the targets split over this process's first ``parts``
    devices (on CPU one device per core; a field's lanes never mix, so the
    bytes are the same on any number of devices). Compiled once per padded
    grid shape, K, device count, resolution and seed radius; the grid's own
    size (``extent``, (2,) int32: its rows and columns inside the padded
    shape) is an argument, so scenes of any size share the program and each
    pays for its own rows and columns."""
    mesh = Mesh(np.array(jax.local_devices()[:parts]), (FIELD_AXIS,))
    fields = jax.vmap(lambda nav, room, origin, extent, c, h, yaw, r: _object_field(
        nav, room, origin, resolution, c, h, yaw, r, seed_radius, (extent[0], extent[1])),
        in_axes=(None, None, None, None, 0, 0, 0, 0))
    lanes = P(FIELD_AXIS)
    return jax.jit(jax.shard_map(fields, mesh=mesh, in_specs=(P(), P(), P(), P(), lanes, lanes, lanes, lanes),
                                 out_specs=lanes, check_vma=False))


def goal_fields(grid: NavGrid, boxes: list, room_indices: list[int], seed_radius: float,
                shape: tuple[int, int] | None = None) -> np.ndarray:
    """Geodesic fields (K, H, W) float32 to K objects on one grid (vmapped).

    The grid is padded (not navigable) to ``shape`` when given (a bank's
    padded grid: one compiled program for all its scenes), else to multiples
    of :data:`GRID_PAD` cells, so scenes of similar size share one; the
    padding does not change a field (it is never navigable). Benchmark
    construction calls it with a scene's candidates, the episode loader
    (:func:`ignjax.episodes.dataset.field_table`) with its targets.

    Args:
        grid: the navigation grid.
        boxes: K :class:`~ignjax.scenes.model.OrientedBox` footprints.
        room_indices: K indices into ``grid.room_ids`` (-1: any room).
        seed_radius: metres (see :func:`seeds_from_box`).

    Returns:
        (K, H, W) float32 metres, +inf where the object cannot be reached.
    """
    if not boxes:
        return np.zeros((0,) + tuple(grid.shape), np.float32)
    H, W = grid.shape
    Hp, Wp = shape if shape is not None else (-(-H // GRID_PAD) * GRID_PAD, -(-W // GRID_PAD) * GRID_PAD)
    nav = np.zeros((Hp, Wp), bool)
    nav[:H, :W] = grid.navigable
    room = np.full((Hp, Wp), -1, np.int32)
    room[:H, :W] = grid.room
    K = len(boxes)
    parts = min(len(jax.local_devices()), K)
    extra = -K % parts  # K padded to whole shares with copies of the last target
    boxes, rooms = list(boxes) + [boxes[-1]] * extra, list(room_indices) + [room_indices[-1]] * extra
    out = _fields_program(parts, float(grid.resolution), float(seed_radius))(
        nav, room, np.asarray(grid.origin, np.float32), np.array([H, W], np.int32),
        np.array([b.center for b in boxes], np.float32),
        np.array([b.half_extents for b in boxes], np.float32), np.array([b.yaw for b in boxes], np.float32),
        np.array(rooms, np.int32))
    return np.asarray(out)[:K, :H, :W]
