"""Ray casting: the exact path against mujoco.mj_ray, the fast voxel path
against mj_ray (agreement), line of sight, and the benchmark."""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
import pytest
from mujoco import mjx

from ignjax.bench.rays import agreement, benchmark_rays, random_rays, ray_groups_mask
from ignjax.scenes.compile import compile_scene
from ignjax.scenes.navgrid import build_navgrid
from ignjax.scenes.procgen.generate import HouseParams, generate_house
from ignjax.scenes.raygrid import ray_grid
from ignjax.scenes.voxels import geom_prims
from ignjax.sim.rays.exact import exact_rays, mj_multiray, mj_rays
from ignjax.sim.rays.fast import fast_ray_hit, line_of_sight, prim_hit

GROUPS = ray_groups_mask((1, 2, 3))  # floor, walls, objects, structural


@pytest.fixture(scope="module")
def per_ray_jit():
    """vmap of the per-ray fast_ray_hit (grid unbatched): one compilation per grid."""
    return jax.jit(jax.vmap(lambda g, p, v, m: fast_ray_hit(g, p, v, m), in_axes=(None, 0, 0, None)))


@pytest.fixture(scope="module")
def two_room(two_room_scene):
    compiled = compile_scene(two_room_scene)
    grid = build_navgrid(compiled)
    return compiled, grid, ray_grid(grid, compiled)


@pytest.fixture(scope="module")
def house():
    scene = generate_house(11, HouseParams(n_rooms=6))
    compiled = compile_scene(scene)
    grid = build_navgrid(compiled)
    return compiled, grid, ray_grid(grid, compiled)


def _ids_match(compiled, pnts, vecs, g, ref, ref_id, tol=1e-4) -> np.ndarray:
    """Per ray: same geom as mj_ray, or a geom that mj_ray's own primitive
    test hits at the same distance (touching walls, stacked parts)."""
    ok = g == ref_id
    m, d = compiled.model, compiled.data
    for i in np.nonzero(~ok & (g >= 0) & np.isfinite(ref))[0]:
        t = mujoco.mju_rayGeom(d.geom_xpos[g[i]], d.geom_xmat[g[i]], m.geom_size[g[i]], pnts[i], vecs[i],
                               m.geom_type[g[i]])
        ok[i] = t >= 0 and abs(t - ref[i]) <= tol
    return ok


N_CAST = 10_000  # every fast-path call is padded to this many rays: one compilation per grid


def _cast(fn, rg, pnts, vecs, max_dist):
    """``fn`` (``(per_ray_jit,)``, or a jitted fast_rays) on up to N_CAST
    rays, padded to N_CAST."""
    n = len(pnts)
    assert n <= N_CAST
    p = np.zeros((N_CAST, 3), np.float32)
    v = np.zeros((N_CAST, 3), np.float32)
    v[:, 2] = 1.0
    p[:n], v[:n] = pnts, vecs
    if isinstance(fn, tuple):  # the per-ray path
        d, g = fn[0](rg, jnp.asarray(p), jnp.asarray(v), max_dist)
    else:
        d, g = fn(rg, p, v, max_dist, 0, want_geom=True)
    return np.asarray(d)[:n], np.asarray(g)[:n]


def _rays(grid, n_origins, per_origin, seed, **kw):
    return random_rays(grid, n_origins, per_origin, np.random.default_rng(seed), **kw)


# ---------------------------------------------------------------------------
# Primitive intersection and the exact path
# ---------------------------------------------------------------------------


def test_prim_hit_matches_mju_ray_geom():
    """Boxes, spheres, ellipsoids, cylinders and capsules, rays from outside
    and inside, against MuJoCo's own primitive intersection."""
    rng = np.random.default_rng(0)
    xml_kinds = [mujoco.mjtGeom.mjGEOM_BOX, mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_ELLIPSOID,
                 mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_CAPSULE]
    spec = mujoco.MjSpec()
    for k, kind in enumerate(xml_kinds * 4):
        q = rng.normal(size=4)
        spec.worldbody.add_geom(type=kind, size=list(rng.uniform(0.05, 0.5, 3)), pos=list(rng.uniform(-1, 1, 3)),
                                quat=list(q / np.linalg.norm(q)))
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rows, gids = [], []
    for g in range(model.ngeom):
        for row in geom_prims(model, data, g):
            rows.append(row)
            gids.append(g)
    rows = np.asarray(rows, np.float32)
    gids = np.asarray(gids)
    pnts = rng.uniform(-1.5, 1.5, (300, 3))
    pnts[:40] = data.geom_xpos[rng.integers(0, model.ngeom, 40)]  # some from inside
    vecs = rng.normal(size=(300, 3))
    vecs /= np.linalg.norm(vecs, axis=1, keepdims=True)
    hit = jax.jit(jax.vmap(jax.vmap(prim_hit, in_axes=(0, None, None)), in_axes=(None, 0, 0)))
    got = np.asarray(hit(jnp.asarray(rows), jnp.asarray(pnts, jnp.float32), jnp.asarray(vecs, jnp.float32)))
    # a geom's distance is the minimum over its primitives (a capsule has three)
    per_geom = np.full((len(pnts), model.ngeom), np.inf)
    for j, g in enumerate(gids):
        per_geom[:, g] = np.minimum(per_geom[:, g], got[:, j])
    n_hits = 0
    for i in range(len(pnts)):
        for g in range(model.ngeom):
            if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE:
                r, h = model.geom_size[g][:2]
                axis = data.geom_xmat[g].reshape(3, 3)[:, 2]
                u = np.clip((pnts[i] - data.geom_xpos[g]) @ axis, -h, h)
                if np.linalg.norm(pnts[i] - data.geom_xpos[g] - u * axis) <= r:
                    continue  # from inside, a capsule's parts are left one at a time (documented)
            ref = mujoco.mju_rayGeom(data.geom_xpos[g], data.geom_xmat[g], model.geom_size[g], pnts[i], vecs[i],
                                     model.geom_type[g])
            if ref < 0:
                assert np.isinf(per_geom[i, g]), (i, g, per_geom[i, g])
            else:
                n_hits += 1
                assert per_geom[i, g] == pytest.approx(ref, abs=2e-5), (i, g, model.geom_type[g])
    assert n_hits > 150


def test_exact_rays_match_mj_ray(two_room):
    compiled, grid, _ = two_room
    pnts, vecs = _rays(grid, 100, 20, seed=1)
    for groups in (None, GROUPS, ray_groups_mask((1,), include_floor=False)):
        d, g = exact_rays(compiled, pnts, vecs, groups)
        ref, ref_id = mj_rays(compiled, pnts, vecs, groups)
        d, g = np.asarray(d), np.asarray(g)
        assert np.array_equal(np.isinf(d), np.isinf(ref))
        fin = np.isfinite(ref)
        np.testing.assert_allclose(d[fin], ref[fin], atol=2e-4)
        assert _ids_match(compiled, pnts, vecs, g, ref, ref_id)[fin].all()
        assert (g[~fin] == -1).all()


def test_mjx_ray_ignores_cylinders_exact_rays_does_not(two_room):
    """mjx.ray (mujoco-mjx 3.17) has no cylinder test; exact_rays adds it."""
    compiled, grid, _ = two_room
    leg = next(g for g in range(compiled.ngeom) if compiled.model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER)
    c = compiled.data.geom_xpos[leg]
    pnts, vecs = _rays(grid, 100, 20, seed=1)  # the batch shape test_exact_rays_match_mj_ray compiled
    pnts[0] = [c[0] - 0.5, c[1], c[2]]
    vecs[0] = [1.0, 0.0, 0.0]
    ref, ref_id = mj_rays(compiled, pnts[:1], vecs[:1])
    assert ref_id[0] == leg
    raw = jax.jit(jax.vmap(lambda p, v: mjx.ray(compiled.mjx_model, compiled.mjx_data, p, v)))
    _, g_raw = raw(jnp.asarray(pnts[:8], jnp.float32), jnp.asarray(vecs[:8], jnp.float32))
    assert int(g_raw[0]) != leg
    d, g = exact_rays(compiled, pnts, vecs)
    assert int(g[0]) == leg and float(d[0]) == pytest.approx(ref[0], abs=1e-5)


def test_mj_multiray_matches_mj_ray(two_room):
    compiled, grid, _ = two_room
    pnts, vecs = _rays(grid, 5, 40, seed=2)
    for i in range(5):
        sl = slice(40 * i, 40 * (i + 1))
        d, g = mj_multiray(compiled, pnts[sl][0], vecs[sl], GROUPS)
        ref, ref_id = mj_rays(compiled, pnts[sl], vecs[sl], GROUPS)
        np.testing.assert_allclose(d, ref)
        assert np.array_equal(g, ref_id)
    # the cutoff only culls geoms (by bounding sphere): hits within it are unchanged
    d, _ = mj_multiray(compiled, pnts[0], vecs[:40], GROUPS, cutoff=0.5)
    ref, _ = mj_rays(compiled, pnts[:40], vecs[:40], GROUPS)
    np.testing.assert_allclose(d[ref <= 0.5], ref[ref <= 0.5])


# ---------------------------------------------------------------------------
# Fast path
# ---------------------------------------------------------------------------


def _agreement(fn, compiled, grid, rg, pnts, vecs, max_dist):
    d, g = _cast(fn, rg, pnts, vecs, max_dist)
    ref, ref_id = mj_rays(compiled, pnts, vecs, GROUPS)
    ok = agreement(d, ref, max_dist, grid.resolution)
    return ok, d, g, ref, ref_id


@pytest.mark.parametrize("which", ["two_room", "house"])
def test_fast_depth_rays_agree_with_mj_ray(which, request, per_ray_jit):
    """Depth rays: origins at navigable points, heights 0.1-2 m, any yaw,
    pitch in [-45, 45] degrees, 5 m. (The batched fast_rays gives the same
    numbers: tests/test_bank.py.)"""
    compiled, grid, rg = request.getfixturevalue(which)
    fn = (per_ray_jit,)
    pnts, vecs = _rays(grid, 500, 20, seed=3)
    ok, d, g, ref, ref_id = _agreement(fn, compiled, grid, rg, pnts, vecs, 5.0)
    print(f"{which}: depth-ray agreement {ok.mean():.5f}")
    assert ok.mean() >= 0.995
    # the geom hit is mj_ray's wherever the distances agree closely
    close = np.isfinite(ref) & (ref <= 5.0) & np.isfinite(d) & (np.abs(np.where(np.isfinite(d), d, 0) - ref) < 1e-3)
    assert _ids_match(compiled, pnts, vecs, g, ref, ref_id)[close].mean() > 0.999


@pytest.mark.parametrize("height", [0.1, 0.3, 0.5, 0.75, 1.0, 1.5])
def test_fast_collision_rays_agree_with_mj_ray(house, per_ray_jit, height):
    """Horizontal collision rays of 0.65 m at several heights (exactly on the
    5 cm slice lattice, where faces of snapped furniture lie)."""
    compiled, grid, rg = house
    pnts, vecs = _rays(grid, 200, 16, seed=int(height * 100), heights=(height, height), horizontal=True)
    ok, *_ = _agreement((per_ray_jit,), compiled, grid, rg, pnts, vecs, 0.65)
    assert ok.mean() >= 0.995


def test_fast_ray_hand_built(two_room, per_ray_jit):
    """Exact expectations in the two-room scene (walls 0.1 m thick on the
    room boundaries, floor at z = 0, the door at x = 5, y 1.5-2.5)."""
    compiled, grid, rg = two_room
    cases = [  # origin, direction, expected distance
        ((2.5, 1.0, 1.0), (0, -1, 0), 0.95),  # south wall's inner face at y = 0.05
        ((0.8, 3.0, 1.0), (-1, 0, 0), 0.75),  # west wall at x = 0.05
        ((4.0, 2.0, 2.0), (1, 0, 0), 4.95),  # through the door (below the lintel) to the east wall at 8.95
        ((4.0, 2.0, 2.3), (1, 0, 0), 0.95),  # at lintel height: the lintel's face at x = 4.95
        ((7.0, 3.0, 1.3), (0, 0, -1), 1.3),  # straight down onto the floor
        ((7.0, 3.0, 1.3), (0, 0, 1), math.inf),  # straight up: no ceiling
        ((4.0, 1.0, 1.0), (math.cos(0.3), math.sin(0.3), 0), (4.95 - 4.0) / math.cos(0.3)),  # dividing wall
    ]
    pnts = np.array([c[0] for c in cases], float)
    vecs = np.array([c[1] for c in cases], float)
    vecs /= np.linalg.norm(vecs, axis=1, keepdims=True)
    d, g = _cast((per_ray_jit,), rg, pnts, vecs, 10.0)
    ref, ref_id = mj_rays(compiled, pnts, vecs, GROUPS)
    for i, (_, _, want) in enumerate(cases):
        if math.isinf(want):
            assert np.isinf(d[i]) and np.isinf(ref[i])
        else:
            assert float(d[i]) == pytest.approx(want, abs=1e-4), i
            assert ref[i] == pytest.approx(want, abs=1e-9), i
            assert int(g[i]) == ref_id[i], i
    # beyond max_dist is a miss
    d, _ = _cast((per_ray_jit,), rg, pnts, vecs, 0.9)
    assert np.isinf(d[[0, 4]]).all()
    # without the floor, the downward ray misses
    one = jax.jit(lambda p, v: fast_ray_hit(rg, p, v, 10.0, include_floor=False))
    assert np.isinf(float(one(jnp.asarray(pnts[4], jnp.float32), jnp.asarray(vecs[4], jnp.float32))[0]))


def test_line_of_sight(two_room):
    compiled, grid, rg = two_room
    los = jax.jit(jax.vmap(lambda a, b: line_of_sight(rg, a, b)))
    painting_face = np.array([2.5, 3.897 - 0.003, 1.5])  # the canvas's front face
    a = np.array([
        [1.0, 1.0, 1.2],  # across the living room, nothing in between
        [1.0, 1.0, 1.2],  # to the bedroom through the dividing wall
        [1.0, 1.0, 1.2],  # to a point on the painting's surface
        [4.0, 2.0, 1.5],  # through the door into the bedroom
        [2.5, 1.0, 0.3],  # up under the table top
    ])
    b = np.array([
        [4.0, 3.5, 1.6],
        [7.0, 0.5, 1.2],
        painting_face,
        [7.0, 2.0, 1.5],
        [2.5, 3.0, 0.9],
    ])
    # and 2000 random segments between navigable points (they exercise fast_ray,
    # whose voxels entirely inside a primitive end a ray without an exact test)
    rng = np.random.default_rng(7)
    pts = grid.navigable_points()
    ra = np.c_[pts[rng.integers(0, len(pts), 2000)], rng.uniform(0.2, 1.8, 2000)]
    rb = np.c_[pts[rng.integers(0, len(pts), 2000)], rng.uniform(0.2, 1.8, 2000)]
    a, b = np.concatenate([a, ra]), np.concatenate([b, rb])
    got = np.asarray(los(jnp.asarray(a, jnp.float32), jnp.asarray(b, jnp.float32)))
    assert got[:5].tolist() == [True, False, True, True, False]
    # consistent with mj_ray on the same segments (up to segments ending within 1 mm of a surface)
    d = b - a
    length = np.linalg.norm(d, axis=1)
    ref, _ = mj_rays(compiled, a, d / length[:, None], GROUPS)
    clear = np.abs(ref - (length - 0.05)) > 1e-3
    assert np.array_equal(got[clear], (ref >= length - 0.05)[clear])
    assert 0.2 < got.mean() < 0.9


@pytest.mark.slow
def test_benchmark_rays_smoke(two_room):
    compiled, grid, _ = two_room
    r = benchmark_rays(compiled, grid, n_rays=640, max_dist=5.0, seed=0, repeat=1)
    for key in ("fast_rays_per_s", "mjx_rays_per_s", "exact_rays_per_s", "multiray_rays_per_s"):
        assert r[key] > 0
    assert r["n_rays"] == 640 and r["agreement"] >= 0.99 and r["agreement_exact"] == 1.0
