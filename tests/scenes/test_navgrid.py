"""Navigation grids: voxels and bands against mj_ray, navigability, rooms,
components, reachability, and geodesic fields against scipy's Dijkstra."""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, dijkstra
from scipy.spatial import cKDTree

from ignjax.errors import ConfigError, SceneError
from ignjax.scenes.compile import compile_scene
from ignjax.scenes.geodesic import _sweep, geodesic_field, target_seeds
from ignjax.scenes.model import Attributes, Geom, Instance, OrientedBox
from ignjax.scenes.navgrid import GridConfig, build_navgrid, check_reachable, unreachable_rooms
from ignjax.scenes.procgen.generate import HouseParams, generate_house

RAY_GROUPS = np.array([0, 1, 1, 1, 0, 0], np.uint8)  # what the grid voxelizes: walls, objects, structural


@pytest.fixture(scope="module")
def two_room(two_room_scene):
    compiled = compile_scene(two_room_scene)
    return compiled, build_navgrid(compiled)


@pytest.fixture(scope="module")
def house():
    scene = generate_house(7, HouseParams(n_rooms=6))
    compiled = compile_scene(scene)
    return compiled, build_navgrid(compiled)


@pytest.fixture(scope="module")
def blocked_door_scene(two_room_scene):
    """The two-room scene with a crate filling the door between the rooms."""
    box = OrientedBox((5.0, 2.0, 0.5), (0.15, 0.6, 0.5), 0.0)
    crate = Instance("crate_0", "box", (5.0, 2.0, 0.0), 0.0, box, room="room_0", attributes=Attributes(),
                     geoms=(Geom("box", (0.15, 0.6, 0.5), (0.0, 0.0, 0.5)),))
    return two_room_scene.replace(id="two_rooms_blocked", instances=two_room_scene.instances + (crate,))


@pytest.fixture(scope="module")
def geodesic_jit():
    """Vmapped over a batch of seeds; compiled once per grid shape and batch size."""
    return jax.jit(jax.vmap(geodesic_field, in_axes=(None, 0, None)), static_argnums=2)


def _batch3(seeds: np.ndarray) -> jnp.ndarray:
    """One seed map as a batch of 3 (the batch size every test compiles for)."""
    return jnp.asarray(np.broadcast_to(seeds, (3,) + seeds.shape))


# ---------------------------------------------------------------------------
# Config and cells
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs", [
    dict(resolution=0.0), dict(resolution=float("nan")), dict(agent_radius=-0.1), dict(bands=()),
    dict(bands=((0.5, 0.4),)), dict(bands=((0.0, 1.0), (0.5, 1.5))), dict(slice_height=0.04),
    dict(max_list=0), dict(ray_groups=(9,)), dict(band_names=("a",)),
])
def test_config_rejects_bad_values(kwargs):
    with pytest.raises(ConfigError):
        GridConfig(**kwargs)


def test_cell_convention(two_room):
    compiled, grid = two_room
    res = grid.resolution
    assert grid.shape == grid.occupancy.shape[1:] == grid.navigable.shape
    assert np.allclose(np.round(grid.origin / res) * res, grid.origin)
    # the scene (walls included, 9.1 x 4.1 m) plus the 0.5 m margin
    assert grid.origin[0] <= -0.05 - 0.5 + 1e-9 and grid.origin[1] <= -0.05 - 0.5 + 1e-9
    assert grid.origin[0] + grid.shape[1] * res >= 9.05 + 0.5 - 1e-9
    rc = np.array([[0, 0], [3, 7], [grid.shape[0] - 1, grid.shape[1] - 1]])
    xy = grid.cell_to_world(rc)
    assert np.array_equal(grid.world_to_cell(xy), rc)
    assert np.allclose(xy[0], grid.origin + res / 2)
    # rows run along y, columns along x
    assert np.array_equal(grid.world_to_cell(grid.origin + [3.5 * res, 1.5 * res]), [1, 3])
    assert grid.height >= 2.5 and grid.n_slices * grid.slice_height == pytest.approx(grid.height)


# ---------------------------------------------------------------------------
# Voxels and bands against mj_ray
# ---------------------------------------------------------------------------


def _ray_hits(compiled, pnt, vec, cutoff) -> bool:
    gid = np.zeros(1, np.int32)
    d = mujoco.mj_ray(compiled.model, compiled.data, pnt, vec, RAY_GROUPS, 1, -1, gid)
    return 0 <= d <= cutoff


def _geometry_near(compiled, grid, r, c, zlo, zhi, step=0.01) -> bool:
    """Some geometry lies in the box of cells (r-1..r+1, c-1..c+1) between
    zlo and zhi: rays along x, y and z on a 1 cm lattice across the box."""
    res = grid.resolution
    x0, y0 = grid.origin[0] + (c - 1) * res, grid.origin[1] + (r - 1) * res
    x1, y1 = x0 + 3 * res, y0 + 3 * res
    us = np.arange(x0 + step / 2, x1, step)
    vs = np.arange(y0 + step / 2, y1, step)
    zs = np.arange(zlo + step / 2, zhi, step)
    for x in us:  # vertical rays
        for y in vs:
            if _ray_hits(compiled, np.array([x, y, zhi]), np.array([0.0, 0.0, -1.0]), zhi - zlo):
                return True
    for z in zs:
        for y in vs:
            if _ray_hits(compiled, np.array([x0, y, z]), np.array([1.0, 0.0, 0.0]), x1 - x0):
                return True
        for x in us:
            if _ray_hits(compiled, np.array([x, y0, z]), np.array([0.0, 1.0, 0.0]), y1 - y0):
                return True
    return False


def test_free_band_cells_have_no_geometry(two_room):
    """Exact direction: vertical mj_ray probes inside free cells never hit
    geometry within the band (the voxelization is conservative)."""
    compiled, grid = two_room
    rng = np.random.default_rng(0)
    offs = (np.arange(4) + 0.5) / 4
    for b, (lo, hi) in enumerate(grid.config.bands):
        free = np.argwhere(~grid.bands[b])
        for r, c in free[rng.choice(len(free), 400, replace=False)]:
            for fx in offs:
                for fy in offs:
                    x = grid.origin[0] + (c + fx) * grid.resolution
                    y = grid.origin[1] + (r + fy) * grid.resolution
                    assert not _ray_hits(compiled, np.array([x, y, hi - 1e-3]), np.array([0.0, 0.0, -1.0]),
                                         hi - lo - 2e-3), (b, r, c)


def test_free_cells_near_thin_parts(two_room):
    """Free cells right next to the laptop screen (2 mm) and the painting:
    horizontal probes through a free cell's interior find nothing."""
    compiled, grid = two_room
    occ_any = grid.occupancy.any(0)
    for xy in ((2.35, 2.0), (2.5, 3.9)):  # laptop screen, painting
        r0, c0 = grid.world_to_cell(xy)
        for r in range(r0 - 3, r0 + 4):
            for c in range(c0 - 3, c0 + 4):
                if occ_any[r, c]:
                    continue
                x = grid.origin[0] + (c + 0.5) * grid.resolution
                y = grid.origin[1] + (r + 0.5) * grid.resolution
                for z in np.arange(0.05, 2.4, 0.02):
                    for v in ((1, 0, 0), (0, 1, 0)):
                        v = np.array(v, float)
                        p = np.array([x, y, z]) - v * 0.45 * grid.resolution
                        assert not _ray_hits(compiled, p, v, 0.9 * grid.resolution)


def test_occupied_band_cells_have_geometry(two_room):
    """Every sampled occupied (cell, band) has geometry within one cell (the
    tolerance of conservative voxels of cylinders and other non-boxes)."""
    compiled, grid = two_room
    rng = np.random.default_rng(1)
    for b, (lo, hi) in enumerate(grid.config.bands):
        occ = np.argwhere(grid.bands[b])
        for r, c in occ[rng.choice(len(occ), min(60, len(occ)), replace=False)]:
            assert _geometry_near(compiled, grid, r, c, lo, hi), (b, r, c)


def test_thin_parts_are_voxelized(two_room):
    """The 2 mm laptop screen and the 2 cm painting occupy voxels."""
    compiled, grid = two_room
    scene = compiled.scene
    for iid in ("laptop_0", "painting_0"):
        inst = scene.instance(iid)
        for g in compiled.instance_geoms(scene.instances.index(inst)):
            p = compiled.data.geom_xpos[g]
            r, c = grid.world_to_cell(p[:2])
            k = int(p[2] // grid.slice_height)
            assert grid.occupancy[k, r, c], (iid, g)
    # the painting hangs at 1.2-1.8 m: in the tall band only
    r, c = grid.world_to_cell((2.5, 3.92))
    assert grid.bands[2, r, c] and not grid.bands[0, r, c]


def test_band_heights(two_room):
    compiled, grid = two_room
    scene = compiled.scene
    # the lintel over the door (2.1-2.5 m) is above every band: the doorway is free
    r, c = grid.world_to_cell((5.0, 2.0))
    assert not grid.obstacle[r, c]
    assert grid.occupancy[int(2.3 / grid.slice_height), r, c]
    # the table top (0.71-0.75 m) is in the table band, not in the low band
    r, c = grid.world_to_cell((2.5, 2.0))
    assert grid.bands[1, r, c] and not grid.bands[0, r, c]
    # walls block every band
    r, c = grid.world_to_cell((0.0, 2.0))
    assert grid.bands[:, r, c].all()
    assert scene.room_at((2.5, 2.0)) == "room_0"


# ---------------------------------------------------------------------------
# Rooms, navigability, components
# ---------------------------------------------------------------------------


def test_room_grid_matches_room_contains(two_room, house):
    for compiled, grid in (two_room, house):
        pts = grid.cell_centers()
        expect = np.full(grid.shape, -1)
        for i, room in reversed(list(enumerate(compiled.scene.rooms))):
            expect[room.contains(pts)] = i
        assert np.array_equal(grid.room, expect)


def test_navigable_definition_exact(two_room, house):
    """navigable <=> in a room and no blocked cell (obstacle or outside rooms)
    within agent_radius of the cell centre (disc against squares)."""
    for _, grid in (two_room, house):
        res, rad = grid.resolution, grid.config.agent_radius
        blocked = grid.obstacle | (grid.room < 0)
        bc = grid.cell_to_world(np.argwhere(blocked))
        tree = cKDTree(bc)
        centers = grid.cell_centers().reshape(-1, 2)
        expect = np.zeros(len(centers), bool)
        near = tree.query_ball_point(centers, rad + res, workers=-1)
        for i, (p, idx) in enumerate(zip(centers, near)):
            if not idx:
                expect[i] = True
                continue
            d = np.maximum(np.abs(bc[idx] - p) - res / 2, 0.0)
            expect[i] = bool(np.all(np.hypot(d[:, 0], d[:, 1]) >= rad))
        expect &= (grid.room >= 0).ravel() & ~blocked.ravel()
        assert np.array_equal(grid.navigable.ravel(), expect)


def test_navigable_near_walls_and_furniture(two_room):
    compiled, grid = two_room
    rad = grid.config.agent_radius
    # a row through the living room at y = 1.0: free from x ~ 0.05 + rad to the table legs
    r = grid.world_to_cell((0.0, 1.0))[0]
    xs = grid.cell_to_world(np.stack([np.full(grid.shape[1], r), np.arange(grid.shape[1])], -1))[:, 0]
    nav = grid.navigable[r]
    first = xs[nav].min()
    assert 0.05 + rad <= first <= 0.05 + rad + grid.resolution + 1e-9
    # no navigable cell within the agent radius of the table top's footprint
    table = compiled.scene.instance("table_0").bbox
    d = table.distance_xy(grid.cell_centers())
    assert not grid.navigable[d < rad].any()
    # the door is passable: the doorway centre is navigable
    assert grid.navigable[tuple(grid.world_to_cell((5.0, 2.0)))]


def _grid_graph(nav: np.ndarray, res: float) -> sp.csr_matrix:
    """The 8-connected grid graph without corner cutting, as a sparse matrix."""
    H, W = nav.shape
    idx = np.arange(H * W).reshape(H, W)
    rows, cols, w = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        r0, r1 = max(0, -dr), H - max(0, dr)
        c0, c1 = max(0, -dc), W - max(0, dc)
        ok = nav[r0:r1, c0:c1] & nav[r0 + dr:r1 + dr, c0 + dc:c1 + dc]
        if dr and dc:
            ok &= nav[r0 + dr:r1 + dr, c0:c1] & nav[r0:r1, c0 + dc:c1 + dc]
        rr, cc = np.nonzero(ok)
        rr, cc = rr + r0, cc + c0
        rows.append(idx[rr, cc])
        cols.append(idx[rr + dr, cc + dc])
        w.append(np.full(len(rr), res * (math.sqrt(2) if dr and dc else 1.0)))
    m = sp.coo_matrix((np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))), shape=(H * W, H * W)).tocsr()
    return (m + m.T).tocsr()


def test_components_match_graph(two_room, house, blocked_door_scene):
    blocked = build_navgrid(compile_scene(blocked_door_scene))
    for grid in (two_room[1], house[1], blocked):
        n, labels = connected_components(_grid_graph(grid.navigable, grid.resolution), directed=False)
        lab = labels.reshape(grid.shape)
        nav = grid.navigable
        comp = grid.components
        assert (comp[~nav] == -1).all() and (comp[nav] >= 0).all()
        assert grid.n_components == len(np.unique(lab[nav]))
        # the same partition of the navigable cells
        pairs = np.unique(np.stack([comp[nav], lab[nav]], -1), axis=0)
        assert len(pairs) == grid.n_components
    assert two_room[1].n_components == 1
    assert blocked.n_components == 2


def test_check_reachable(two_room, blocked_door_scene, house):
    compiled, grid = two_room
    check_reachable(compiled.scene, grid)
    check_reachable(house[0].scene, house[1])
    grid_b = build_navgrid(compile_scene(blocked_door_scene))
    assert unreachable_rooms(blocked_door_scene, grid_b) == ["room_1"]
    with pytest.raises(SceneError) as err:
        check_reachable(blocked_door_scene, grid_b, path="house.json")
    msg = str(err.value)
    assert "room_1 (bedroom)" in msg and "house.json" in msg and "room_0" in msg
    assert "room_0 (living_room)" not in msg


def test_room_without_navigable_cells(two_room_scene):
    """A bedroom filled with a crate has no navigable cells; the error says so."""
    box = OrientedBox((7.0, 2.0, 0.5), (1.9, 1.9, 0.5), 0.0)
    crate = Instance("crate_1", "box", (7.0, 2.0, 0.0), 0.0, box, room="room_1",
                     geoms=(Geom("box", (1.9, 1.9, 0.5), (0.0, 0.0, 0.5)),))
    scene = two_room_scene.replace(id="full_bedroom", instances=(crate,))
    grid = build_navgrid(compile_scene(scene))
    with pytest.raises(SceneError, match=r"room_1 \(bedroom\) has no navigable cells"):
        check_reachable(scene, grid)


def test_ten_room_house_builds():
    """A 10-room house compiles, gets a grid and every room is reachable
    (no time limit is asserted: ``python -m ignjax.bench`` times this house's
    compile and grids as ``scene_compile_s``)."""
    scene = generate_house(3, HouseParams(n_rooms=10))
    compiled = compile_scene(scene)
    grid = build_navgrid(compiled)
    check_reachable(scene, grid)


# ---------------------------------------------------------------------------
# Geodesic fields
# ---------------------------------------------------------------------------


def _dijkstra_field(nav, seeds, res):
    """Multi-source Dijkstra with initial costs (a virtual source node)."""
    H, W = nav.shape
    n = H * W
    g = _grid_graph(nav, res)
    s = seeds.ravel().astype(np.float64)
    src = np.nonzero(np.isfinite(s) & nav.ravel())[0]
    offset = 1.0
    extra = sp.csr_matrix((s[src] + offset, (np.zeros(len(src), int), src)), shape=(1, n + 1))
    full = sp.vstack([sp.hstack([g, sp.csr_matrix((n, 1))]), extra]).tocsr()
    d = dijkstra(full, directed=True, indices=n)[:n] - offset
    return d.reshape(H, W)


def test_geodesic_small_exact(geodesic_jit):
    """A 4 x 5 grid with a wall in column 2 (open in the last row): distances by hand."""
    nav = np.ones((4, 5), bool)
    nav[0:3, 2] = False
    seeds = np.full((4, 5), np.inf, np.float32)
    seeds[0, 0] = 0.0
    d = np.asarray(geodesic_jit(jnp.asarray(nav), _batch3(seeds), 1.0))[0]
    s2 = math.sqrt(2)
    assert d[0, 1] == pytest.approx(1.0)
    assert d[1, 1] == pytest.approx(s2)
    assert d[3, 1] == pytest.approx(2 + s2)
    # (2, 1) -> (3, 2) would cut the wall's corner at (2, 2): the path goes round it
    assert d[3, 2] == pytest.approx(3 + s2)
    assert d[3, 3] == pytest.approx(4 + s2)
    # (3, 2) -> (2, 3) would cut the same corner
    assert d[2, 3] == pytest.approx(5 + s2)
    assert d[0, 4] == pytest.approx(6 + 2 * s2)  # (3,3) -> (2,4) diagonal -> (1,4) -> (0,4)
    assert np.isinf(d[0, 2])
    seeds[0, 0] = 0.5  # initial costs add
    d2 = np.asarray(geodesic_jit(jnp.asarray(nav), _batch3(seeds), 1.0))[0]
    np.testing.assert_allclose(d2[nav], d[nav] + 0.5, rtol=1e-6)


def test_geodesic_matches_dijkstra(two_room, house, blocked_door_scene, geodesic_jit):
    rng = np.random.default_rng(3)
    blocked = build_navgrid(compile_scene(blocked_door_scene))
    for grid in (two_room[1], house[1], blocked):
        nav = grid.navigable
        cells = np.argwhere(nav)
        seeds = np.full((3,) + nav.shape, np.inf, np.float32)
        for b in range(3):
            pick = cells[rng.choice(len(cells), b + 1, replace=False)]
            seeds[b, pick[:, 0], pick[:, 1]] = rng.uniform(0, 2, b + 1)
        seeds[0, 0, 0] = 0.0  # a seed on a non-navigable cell is ignored
        out = np.asarray(geodesic_jit(jnp.asarray(nav), jnp.asarray(seeds), grid.resolution))
        for b in range(3):
            ref = _dijkstra_field(nav, seeds[b], grid.resolution)
            assert np.array_equal(np.isinf(out[b]), np.isinf(ref))
            fin = np.isfinite(ref)
            # float32 sums of a few hundred steps of 0.05 / 0.0707 m against float64
            np.testing.assert_allclose(out[b][fin], ref[fin], rtol=1e-5, atol=1e-5)
        assert np.isinf(out[:, ~nav]).all()
    # with the door blocked, a seed in the living room never reaches the bedroom
    living = np.argwhere(blocked.navigable & (blocked.room == 0))[0]
    seeds = np.full(blocked.shape, np.inf, np.float32)
    seeds[tuple(living)] = 0.0
    d = np.asarray(geodesic_jit(jnp.asarray(blocked.navigable), _batch3(seeds), blocked.resolution))[0]
    assert np.isinf(d[blocked.room == 1]).all()
    assert np.isfinite(d[blocked.navigable & (blocked.room == 0)]).all()


@pytest.mark.parametrize("axis,reverse", [(0, False), (0, True), (1, False), (1, True)])
def test_sweep_over_extent_is_one_full_pass(axis, reverse):
    """One relaxation pass limited to the first n rows / columns (``_sweep``'s
    ``n``) equals the full pass there and leaves the rest as it was."""
    rng = np.random.default_rng(axis * 2 + reverse)
    d = rng.uniform(0, 5, (9, 7)).astype(np.float32)
    wts = np.where(rng.random((9, 7)) < 0.8, rng.uniform(0.1, 1, (9, 7)), np.inf).astype(np.float32)
    n = 5
    cut = (slice(None, n), slice(None)) if axis == 0 else (slice(None), slice(None, n))
    ref = np.asarray(_sweep(jnp.asarray(d[cut]), jnp.asarray(wts[cut]), axis, reverse))
    got = np.asarray(jax.jit(lambda a, b, k: _sweep(a, b, axis, reverse, k))(jnp.asarray(d), jnp.asarray(wts), n))
    assert got[cut].tobytes() == ref.tobytes()
    rest = (slice(n, None), slice(None)) if axis == 0 else (slice(None), slice(n, None))
    assert got[rest].tobytes() == d[rest].tobytes()
    assert not np.array_equal(ref, d[cut])  # the pass relaxed something


def test_geodesic_extent_same_bytes(house):
    """Sweeping a padded grid over its own rows and columns only (``extent``,
    what goal_fields does on a bank's shared shape) gives the full sweep's
    bytes: in the grid and in the padding."""
    grid = house[1]
    nav = grid.navigable
    h, w = nav.shape
    rng = np.random.default_rng(5)
    cells = np.argwhere(nav)
    seeds = np.full(nav.shape, np.inf, np.float32)
    pick = cells[rng.choice(len(cells), 3, replace=False)]
    seeds[pick[:, 0], pick[:, 1]] = rng.uniform(0, 1, 3)
    H, W = h + 37, w + 11
    pnav = np.zeros((H, W), bool)
    pnav[:h, :w] = nav
    pseeds = np.full((H, W), np.inf, np.float32)
    pseeds[:h, :w] = seeds
    full = jax.jit(lambda n, s: geodesic_field(n, s, grid.resolution))
    part = jax.jit(lambda n, s, e: geodesic_field(n, s, grid.resolution, extent=(e[0], e[1])))
    ref = np.asarray(full(jnp.asarray(pnav), jnp.asarray(pseeds)))
    got = np.asarray(part(jnp.asarray(pnav), jnp.asarray(pseeds), jnp.asarray([h, w], jnp.int32)))
    assert got.tobytes() == ref.tobytes()
    assert np.isfinite(got[:h, :w]).sum() > 100 and np.isinf(got[h:]).all() and np.isinf(got[:, w:]).all()
    own = np.asarray(full(jnp.asarray(nav), jnp.asarray(seeds)))  # the grid without padding: the same bytes
    assert got[:h, :w].tobytes() == own.tobytes()
    whole = np.asarray(part(jnp.asarray(pnav), jnp.asarray(pseeds), jnp.asarray([H, W], jnp.int32)))
    assert whole.tobytes() == ref.tobytes()


def test_target_seeds(two_room, geodesic_jit):
    compiled, grid = two_room
    chair = compiled.scene.instance("chair_2")  # in the bedroom, near the dividing wall
    room = grid.room_index(chair.room)
    seeds = target_seeds(grid, chair.bbox, room, seed_radius=1.0)
    sel = np.isfinite(seeds)
    assert sel.any()
    assert (grid.room[sel] == room).all() and grid.navigable[sel].all()
    d = chair.bbox.distance_xy(grid.cell_centers())
    np.testing.assert_allclose(seeds[sel], d[sel], atol=1e-5)
    assert (d[sel] <= 1.0 + 1e-6).all()
    # every navigable cell of the room within the radius is a seed (none through the wall)
    assert np.array_equal(sel, grid.navigable & (grid.room == room) & (d <= 1.0))
    # the field reads as the geodesic distance to the object: 0 next to it, grows away from it
    f = np.asarray(geodesic_jit(jnp.asarray(grid.navigable), _batch3(seeds), grid.resolution))[0]
    near = grid.world_to_cell((6.0, 1.4))
    far = grid.world_to_cell((1.0, 3.0))  # in the living room: through the door
    assert f[tuple(near)] < 0.5 < f[tuple(far)]
    assert f[tuple(far)] > math.hypot(1.0 - 6.0, 3.0 - 1.4) - 1.0
