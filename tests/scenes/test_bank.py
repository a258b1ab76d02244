"""The SceneBank: stacking, padding, per-episode scene indexing of the fast
rays and geodesic fields, equal to the per-scene results."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.bench.rays import agreement, random_rays, ray_groups_mask
from ignjax.errors import ConfigError
from ignjax.scenes import vocab
from ignjax.scenes.bank import SceneBank, field_at, target_fields
from ignjax.scenes.geodesic import geodesic_field, goal_fields, target_seeds
from ignjax.scenes.graph import room_adjacency
from ignjax.scenes.procgen.generate import HouseParams, generate_house
from ignjax.scenes.raygrid import ray_grid
from ignjax.sim.rays.exact import mj_rays
from ignjax.sim.rays.fast import fast_ray_hit, fast_rays

GROUPS = ray_groups_mask((1, 2, 3))
N_RAYS = 1536  # rays per scene


@pytest.fixture(scope="module")
def bank(two_room_scene):
    scenes = [two_room_scene, generate_house(5, HouseParams(n_rooms=3)), generate_house(6, HouseParams(n_rooms=5))]
    return SceneBank.build(scenes)


@pytest.fixture(scope="module")
def episode_rays(bank):
    """N_RAYS random depth rays per scene, interleaved across scenes like
    episodes of a batch, with their scene index."""
    rng = np.random.default_rng(0)
    p, v, s = [], [], []
    for i in range(bank.n_scenes):
        pi, vi = random_rays(bank.navgrids[i], N_RAYS // 16, 16, rng)
        p.append(pi)
        v.append(vi)
        s.append(np.full(len(pi), i, np.int32))
    order = rng.permutation(N_RAYS * bank.n_scenes)
    return np.concatenate(p)[order], np.concatenate(v)[order], np.concatenate(s)[order]


@pytest.fixture(scope="module")
def per_ray():
    """vmap of the per-ray fast ray over episodes; the ray grid is unbatched."""
    return jax.jit(jax.vmap(lambda g, p, v, s: fast_ray_hit(g, p, v, 5.0, s), in_axes=(None, 0, 0, 0)))


@pytest.fixture(scope="module")
def batched():
    """The staged batch path with a scene index per ray (compiled once: always N rays)."""
    f = jax.jit(lambda g, p, v, s: fast_rays(g, p, v, 5.0, s, want_geom=True))

    def run(grid, pnts, vecs, scenes):
        n = len(pnts)
        N = N_RAYS * 3
        p = np.zeros((N, 3), np.float32)
        v = np.tile(np.array([0.0, 0.0, 1.0], np.float32), (N, 1))
        sc = np.zeros(N, np.int32)
        p[:n], v[:n], sc[:n] = pnts, vecs, scenes
        d, g = f(grid, p, v, sc)
        return np.asarray(d)[:n], np.asarray(g)[:n]

    return run


def test_bank_is_a_pytree(bank):
    leaves, treedef = jax.tree_util.tree_flatten(bank)
    assert all(isinstance(x, jax.Array) for x in leaves)
    again = jax.tree_util.tree_unflatten(treedef, leaves)
    assert again.scene_ids == bank.scene_ids and again.compiled is bank.compiled
    # static metadata is not traced: a jitted function of the bank sees concrete ids
    n = jax.jit(lambda b: b.instances.valid.sum(axis=1))(bank)
    assert n.tolist() == [len(bank.scene(i).instances) for i in range(bank.n_scenes)]
    assert bank.categories == tuple(sorted(bank.categories))


def test_padded_shapes_and_masks(bank):
    S = bank.n_scenes
    H = max(g.shape[0] for g in bank.navgrids)
    W = max(g.shape[1] for g in bank.navgrids)
    assert bank.grid.navigable.shape == (S, H, W)
    assert bank.rays.voxcode.shape[0] == S and bank.rays.voxcode.shape[2:] == (H, W)
    for i, g in enumerate(bank.navgrids):
        h, w = g.shape
        assert bank.grid.shape[i].tolist() == [h, w]
        nav = np.asarray(bank.grid.navigable[i])
        assert np.array_equal(nav[:h, :w], g.navigable)
        assert not nav[h:].any() and not nav[:, w:].any()  # padding is never navigable
        room = np.asarray(bank.grid.room[i])
        assert (room[h:] == -1).all() and (room[:, w:] == -1).all()
        comp = np.asarray(bank.grid.components[i])
        assert np.array_equal(comp[:h, :w], g.components) and (comp[h:] == -1).all()
        np.testing.assert_allclose(np.asarray(bank.grid.origin[i]), g.origin, atol=1e-6)


def test_instance_table(bank):
    inst = bank.instances
    for s in range(bank.n_scenes):
        scene = bank.scene(s)
        n = len(scene.instances)
        assert np.asarray(inst.valid[s]).sum() == n and not np.asarray(inst.valid[s, n:]).any()
        assert (np.asarray(inst.category[s, n:]) == -1).all()
        rooms = [r.id for r in scene.rooms]
        ids = [i.id for i in scene.instances]
        for k, obj in enumerate(scene.instances):
            assert bank.categories[int(inst.category[s, k])] == obj.category
            assert int(inst.room[s, k]) == (rooms.index(obj.room) if obj.room else -1)
            assert int(inst.support[s, k]) == (ids.index(obj.support) if obj.support else -1)
            assert bool(inst.structural[s, k]) == obj.structural
            np.testing.assert_allclose(np.asarray(inst.center[s, k]), obj.bbox.center, atol=1e-5)
            np.testing.assert_allclose(np.asarray(inst.half_extents[s, k]), obj.bbox.half_extents, atol=1e-5)
            a = obj.attributes
            assert int(inst.color[s, k]) == vocab.COLOR_INDEX.get(a.color, -1)
            assert int(inst.material[s, k]) == vocab.MATERIAL_INDEX.get(a.material, -1)
            assert int(inst.size[s, k]) == vocab.SIZE_INDEX.get(a.size, -1)
            assert int(inst.state[s, k]) == (vocab.STATE_INDEX[a.state] if a.state else -1)
    # a supported object points at its support: the laptop stands on the table
    s = bank.scene_index("two_rooms")
    assert int(inst.support[s, bank.instance_index(s, "laptop_0")]) == bank.instance_index(s, "table_0")


def test_rooms_doors_adjacency(bank):
    for s in range(bank.n_scenes):
        scene = bank.scene(s)
        R = len(scene.rooms)
        assert np.asarray(bank.rooms.valid[s]).sum() == R
        labels = [vocab.ROOM_LABEL_INDEX[r.label] for r in scene.rooms]
        assert np.asarray(bank.rooms.label[s, :R]).tolist() == labels
        adj = np.asarray(bank.rooms.adjacency[s])
        assert np.array_equal(adj, adj.T) and not adj[R:].any()
        ids = [r.id for r in scene.rooms]
        for a, nbrs in room_adjacency(scene).items():
            for b in nbrs:
                assert adj[ids.index(a), ids.index(b)]
        assert adj.sum() == sum(len(v) for v in room_adjacency(scene).values())
        D = len(scene.doors)
        assert np.asarray(bank.doors.valid[s]).sum() == D
        for k, d in enumerate(scene.doors):
            want = [ids.index(r) if r is not None else -1 for r in d.rooms]
            assert np.asarray(bank.doors.rooms[s, k]).tolist() == want
    two = bank.scene_index("two_rooms")
    assert bool(bank.rooms.adjacency[two, 0, 1])


def test_lookups_and_errors(bank, two_room_scene):
    assert bank.scene_index("two_rooms") == 0
    with pytest.raises(KeyError):
        bank.scene_index("nope")
    with pytest.raises(KeyError):
        bank.instance_index(0, "nope")
    assert bank.category_index("chair") >= 0 and bank.category_index("spaceship") == -1
    with pytest.raises(ConfigError):
        SceneBank.build([two_room_scene, two_room_scene])


def test_fast_rays_over_episodes_equal_per_scene(bank, episode_rays, per_ray, batched):
    """Rays of episodes from different scenes, cast against the stacked bank
    with a per-episode scene index, give each scene's own results (and agree
    with mj_ray)."""
    pnts, vecs, scenes = episode_rays
    d_bank, g_bank = batched(bank.rays, pnts, vecs, scenes)
    for s in range(bank.n_scenes):
        m = scenes == s
        ref, _ = mj_rays(bank.compiled[s], pnts[m], vecs[m], GROUPS)
        assert agreement(d_bank[m], ref, 5.0, bank.config.resolution).mean() >= 0.995
    # the smallest scene with its own, unpadded ray grid gives the same numbers
    # (through the vmapped per-ray path: the staged batch path equals it)
    s = int(np.argmin([g.shape[0] * g.shape[1] for g in bank.navgrids]))
    m = scenes == s
    own = ray_grid(bank.navgrids[s], bank.compiled[s])
    d_own, g_own = per_ray(own, jnp.asarray(pnts[m], jnp.float32), jnp.asarray(vecs[m], jnp.float32),
                           jnp.zeros(int(m.sum()), jnp.int32))
    np.testing.assert_allclose(d_bank[m], np.asarray(d_own), atol=1e-5)
    assert np.array_equal(g_bank[m], np.asarray(g_own))


def test_padding_creates_no_hits(bank, batched):
    """Rays from the smallest scene aimed out of it, and rays starting in its
    padded area: the bank answers like the scene alone, i.e. like mj_ray."""
    s = int(np.argmin([g.shape[0] * g.shape[1] for g in bank.navgrids]))
    g = bank.navgrids[s]
    H, W = bank.grid.navigable.shape[1:]
    far = g.origin + np.array([W, H]) * g.resolution * 0.9  # inside the bank's padded extent, outside the scene
    rng = np.random.default_rng(1)
    n = N_RAYS
    pnts = np.concatenate([
        np.column_stack([np.full((n // 2, 2), far), rng.uniform(0.2, 2.0, n // 2)]),
        np.column_stack([g.navigable_points()[rng.integers(0, g.navigable.sum(), n // 2)],
                         rng.uniform(0.2, 2.0, n // 2)]),
    ])
    yaw = rng.uniform(-np.pi, np.pi, n)
    vecs = np.column_stack([np.cos(yaw), np.sin(yaw), np.zeros(n)])
    d, _ = batched(bank.rays, pnts, vecs, np.full(n, s, np.int32))
    ref, _ = mj_rays(bank.compiled[s], pnts, vecs, GROUPS)
    ok = agreement(d, ref, 5.0, g.resolution)
    assert ok[: n // 2].all()  # out in the padding: nothing there but (maybe) the floor's edge
    assert ok.mean() >= 0.995


def test_geodesic_fields_from_bank_equal_per_scene(bank):
    targets = [(s, (7 * s) % len(bank.scene(s).instances)) for s in range(bank.n_scenes)]
    si = jnp.asarray([t[0] for t in targets], jnp.int32)
    ii = jnp.asarray([t[1] for t in targets], jnp.int32)
    fields = np.asarray(jax.jit(lambda b, s, i: target_fields(b, s, i, 1.0))(bank, si, ii))
    H, W = bank.grid.navigable.shape[1:]
    assert fields.shape == (len(targets), H, W)
    solo = jax.jit(lambda nav, seeds: geodesic_field(nav, seeds, bank.config.resolution))
    for k, (s, i) in enumerate(targets):
        g = bank.navgrids[s]
        inst = bank.scene(s).instances[i]
        seeds = target_seeds(g, inst.bbox, g.room_index(inst.room), 1.0)
        own = np.asarray(solo(jnp.asarray(g.navigable), jnp.asarray(seeds)))
        h, w = g.shape
        f = fields[k]
        assert np.array_equal(np.isinf(f[:h, :w]), np.isinf(own))
        fin = np.isfinite(own)
        np.testing.assert_allclose(f[:h, :w][fin], own[fin], rtol=1e-5, atol=1e-5)
        assert np.isinf(f[h:]).all() and np.isinf(f[:, w:]).all()  # no paths through padding
        assert fin.any()
    # reading a field at a world point
    s, i = targets[0]
    g = bank.navgrids[s]
    rc_ = np.argwhere(np.isfinite(fields[0][: g.shape[0], : g.shape[1]]))[0]
    xy = g.cell_to_world(rc_)
    assert float(field_at(bank, jnp.asarray(fields[0]), s, jnp.asarray(xy, jnp.float32))) == \
        pytest.approx(fields[0][rc_[0], rc_[1]])
    assert np.isinf(float(field_at(bank, jnp.asarray(fields[0]), s, jnp.asarray([-100.0, -100.0]))))


def test_goal_fields_equal_bank_fields_bytewise(bank):
    """goal_fields (one scene's grid padded to multiples of 32 cells, what the
    episode loader and construction use) gives the bank's target_fields (the
    bank's padded grid) byte for byte: the padding never changes a field."""
    rooms = np.asarray(bank.instances.room)
    per_bank = jax.jit(lambda b, s, i: target_fields(b, s, i, 1.0))
    H, W = bank.grid.navigable.shape[1:]
    for s in range(bank.n_scenes):
        idx = list(range(min(4, len(bank.scene(s).instances))))
        g = bank.navgrids[s]
        own = goal_fields(g, [bank.scene(s).instances[i].bbox for i in idx], [int(rooms[s, i]) for i in idx], 1.0)
        ref = np.asarray(per_bank(bank, jnp.full(len(idx), s, jnp.int32), jnp.asarray(idx, jnp.int32)))
        padded = np.full((len(idx), H, W), np.inf, np.float32)
        padded[:, :g.shape[0], :g.shape[1]] = own
        assert padded.tobytes() == ref.tobytes()
        assert np.isfinite(own).any()
