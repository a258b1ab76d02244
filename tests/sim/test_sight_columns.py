"""The ray grid's occupancy packed per column (``ignjax.scenes.raygrid.occupied_columns``,
``World.columns``): the sight lines read it and must give the answers ``voxcode`` gives."""

from __future__ import annotations

import jax
import numpy as np

from ignjax.scenes.raygrid import COLUMN_WORD_BITS, occupied_columns
from ignjax.sim.rays import queries as SR


def test_columns_hold_the_occupied_voxels_below_each_scene_height(small_world):
    rays = small_world.bank.rays
    vox = np.asarray(rays.voxcode)
    cols = occupied_columns(rays)
    S, Z, H, W = vox.shape
    assert cols.shape == (S, H, W, -(-Z // COLUMN_WORD_BITS)) and cols.dtype == np.uint32
    k = np.arange(Z)
    bits = (cols[..., k // COLUMN_WORD_BITS] >> (k % COLUMN_WORD_BITS).astype(np.uint32)) & 1  # (S, H, W, Z)
    want = (vox <= 1) & (k[None, :, None, None] < np.asarray(rays.dims)[:, 2, None, None, None])
    np.testing.assert_array_equal(bits.transpose(0, 3, 1, 2).astype(bool), want)
    assert want.any() and not want.all()  # the scenes have both
    np.testing.assert_array_equal(np.asarray(small_world.columns), cols)


def test_segments_read_from_columns_as_from_voxcode(small_world):
    """Random segments, some starting outside the grid, below the floor or above the top slice."""
    rays = small_world.bank.rays
    rng = np.random.default_rng(0)
    n = 20000
    s = rng.integers(0, rays.voxcode.shape[0], n)
    org, dims = np.asarray(rays.origin)[s], np.asarray(rays.dims)[s]
    top = rays.voxcode.shape[1] * rays.slice_height
    a = np.stack([org[:, 0] + rng.uniform(-1.0, 1.0 + dims[:, 0] * rays.resolution),
                  org[:, 1] + rng.uniform(-1.0, 1.0 + dims[:, 1] * rays.resolution),
                  rng.uniform(-0.5, top + 0.5, n)], 1).astype(np.float32)
    u = rng.normal(size=(n, 3)).astype(np.float32)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    limit = rng.uniform(0.0, 8.0, n).astype(np.float32)

    def blocked(columns):
        return np.asarray(jax.jit(jax.vmap(lambda *x: SR.segment_blocked(rays, *x, 0.1, 0, 70, columns)))(s, a, u, limit))

    packed, direct = blocked(small_world.columns), blocked(None)
    np.testing.assert_array_equal(packed, direct)
    assert 0.05 < direct.mean() < 0.95  # both answers occur
