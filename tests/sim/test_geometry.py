"""Executor equations on hand-computed cases (paper Appendix C)."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.sim import geometry as G

W, H = 640.0, 480.0


def test_grid_to_pixel_corners_and_centre():
    np.testing.assert_allclose(G.grid_to_pixel(1, 1, W, H), [40.0, 450.0])  # bottom-left cell
    np.testing.assert_allclose(G.grid_to_pixel(8, 8, W, H), [600.0, 30.0])  # top-right cell
    np.testing.assert_allclose(G.grid_to_pixel(4, 2, W, H), [280.0, 390.0])


def test_intrinsics_from_field_of_view():
    K = np.asarray(G.intrinsics(W, H, math.radians(90)))
    assert K[0, 0] == pytest.approx(320.0) and K[1, 1] == pytest.approx(320.0)
    np.testing.assert_allclose(K[:2, 2], [320.0, 240.0])


def test_backproject_and_camera_to_world_hand_case():
    K = G.intrinsics(W, H, math.radians(90))
    # pixel (480, 400) at depth 2: x_c = 2 * ((480-320)/320, (400-240)/320, 1) = (1, 1, 2)
    x_c = np.asarray(G.backproject(K, jnp.array([480.0, 400.0]), 2.0))
    np.testing.assert_allclose(x_c, [1.0, 1.0, 2.0], atol=1e-5)
    # camera at (1, 2, 1.25) looking along +y (yaw = 90 deg): right = +x... R columns = right, down, forward
    R = np.asarray(G.view_rotation(math.pi / 2))
    np.testing.assert_allclose(R[:, 0], [1, 0, 0], atol=1e-6)   # right
    np.testing.assert_allclose(R[:, 1], [0, 0, -1], atol=1e-6)  # down
    np.testing.assert_allclose(R[:, 2], [0, 1, 0], atol=1e-6)   # forward
    x_w = np.asarray(G.camera_to_world(jnp.asarray(R), jnp.array([1.0, 2.0, 1.25]), jnp.asarray(x_c)))
    # 1 m right (+x), 1 m down (-z), 2 m forward (+y)
    np.testing.assert_allclose(x_w, [2.0, 4.0, 0.25], atol=1e-5)


def test_extrinsic_inverse_roundtrip():
    R_wc = G.view_rotation(0.7, -0.2)
    t_wc = jnp.array([3.0, -1.0, 1.25])
    R_cw, t_cw = R_wc.T, -R_wc.T @ t_wc
    R2, t2 = G.invert_extrinsic(R_cw, t_cw)
    np.testing.assert_allclose(R2, R_wc, atol=1e-6)
    np.testing.assert_allclose(t2, t_wc, atol=1e-5)


def test_floor_intersection_hand_case_and_invalid_cases():
    # from (0, 0, 1.25) along (1, 0, -0.5): floor reached after s = 2.5 at x = 2.5
    p, ok = G.floor_intersection(jnp.array([0.0, 0.0, 1.25]), jnp.array([1.0, 0.0, -0.5]))
    assert bool(ok)
    np.testing.assert_allclose(p, [2.5, 0.0, 0.0], atol=1e-6)
    _, ok_up = G.floor_intersection(jnp.array([0.0, 0.0, 1.25]), jnp.array([1.0, 0.0, 0.3]))
    _, ok_flat = G.floor_intersection(jnp.array([0.0, 0.0, 1.25]), jnp.array([1.0, 0.0, 0.0]))
    assert not bool(ok_up) and not bool(ok_flat)


def test_pixel_of_bottom_row_reaches_floor_at_expected_distance():
    # row 1 centre at vfov 90 (W = H): 41.2 degrees below the horizon -> floor at 1.25/tan(41.2) m
    K = G.intrinsics(480.0, 480.0, math.radians(90))
    uv = G.grid_to_pixel(4.5, 1, 480.0, 480.0)
    d_c = G.pixel_ray(K, uv)
    d_w = G.view_rotation(0.0) @ d_c
    p, ok = G.floor_intersection(jnp.array([0.0, 0.0, 1.25]), d_w)
    assert bool(ok)
    assert float(p[0]) == pytest.approx(1.25 / 0.875, rel=1e-5)


def test_relative_target_bearing_sign_and_wrap():
    r, beta = G.relative_target(jnp.array([0.0, 0.0]), 0.0, jnp.array([0.0, 2.0]))
    assert float(r) == pytest.approx(2.0) and float(beta) == pytest.approx(math.pi / 2)  # left is positive
    r, beta = G.relative_target(jnp.array([1.0, 1.0]), math.radians(170), jnp.array([0.0, 0.8]))
    expected = math.atan2(-0.2, -1.0) - math.radians(170)
    expected = (expected + math.pi) % (2 * math.pi) - math.pi
    assert float(beta) == pytest.approx(expected, abs=1e-6)
    assert -math.pi <= float(beta) < math.pi
    # vmappable
    rs, bs = jax.vmap(G.relative_target, in_axes=(0, 0, None))(jnp.zeros((5, 2)), jnp.linspace(0, 3, 5), jnp.array([1.0, 0.0]))
    assert rs.shape == (5,)
