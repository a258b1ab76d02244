"""The executor's geometry, equation by equation (paper Appendix B/C).

Conventions (DESIGN.md): world Z up, metres; agent yaw counter-clockwise
from +X; view k looks along ``yaw + k * pi/4``; camera frame x right, y
down, z forward; grid cells for grounding are columns 1..8 left to right,
rows 1..8 bottom to top.

* :func:`grid_to_pixel` - Eq. (app:grid-to-pixel): centre pixel of a cell,
  u = (c - 1/2) W / 8, v = H - (r - 1/2) H / 8.
* :func:`backproject` - Eq. (app:camera-backproject): x_c = z K^-1 [u, v, 1].
* :func:`camera_to_world` - Eq. (app:camera-to-world): x_w = R_wc x_c + t_wc.
* :func:`invert_extrinsic` - Eq. (app:extrinsic-inverse).
* :func:`floor_intersection` - Eq. (app:floor-intersection):
  x_w = t_wc - (n.t_wc + b)/(n.d_w) d_w.
* :func:`relative_target` - Eq. (app:relative-target): Delta = g - p,
  r = |Delta|, beta = wrap(atan2(Delta_y, Delta_x) - theta).

All functions are pure ``jax.numpy`` code for one query (vmap for more).
"""

from __future__ import annotations

import math

import jax.numpy as jnp


def wrap_angle(a):
    """Wrap angles to [-pi, pi)."""
    return (a + jnp.pi) % (2 * jnp.pi) - jnp.pi


def intrinsics(width: float, height: float, hfov: float):
    """K (3, 3) for square pixels, horizontal field of view ``hfov`` (radians)."""
    fx = (width / 2.0) / math.tan(hfov / 2.0)
    return jnp.array([[fx, 0.0, width / 2.0], [0.0, fx, height / 2.0], [0.0, 0.0, 1.0]], dtype=jnp.float32)


def grid_to_pixel(col, row, width: float, height: float):
    """Centre pixel (u, v) of grid cell (col, row), both 1..8.

    Returns:
        (2,) float32 pixel coordinates (u right, v down).
    """
    u = (jnp.asarray(col, jnp.float32) - 0.5) * width / 8.0
    v = height - (jnp.asarray(row, jnp.float32) - 0.5) * height / 8.0
    return jnp.stack([u, v])


def pixel_ray(K, uv):
    """Camera-frame direction K^-1 [u, v, 1] (3,) (z component 1), in closed
    form for a pinhole K without skew (the same arithmetic batched or not)."""
    x = (uv[0] - K[0, 2]) / K[0, 0]
    y = (uv[1] - K[1, 2]) / K[1, 1]
    return jnp.stack([x, y, jnp.ones_like(x)])


def matvec3(R, x):
    """R @ x for a 3x3 matrix, as explicit sums in a fixed order."""
    return jnp.stack([R[i, 0] * x[0] + R[i, 1] * x[1] + R[i, 2] * x[2] for i in range(3)])


def backproject(K, uv, depth):
    """Camera-frame point x_c = z K^-1 [u, v, 1] for z-depth ``depth`` (3,)."""
    return depth * pixel_ray(K, uv)


def view_rotation(yaw, pitch=0.0):
    """Camera-to-world rotation R_wc (3, 3) for a camera looking along
    ``yaw`` (about +Z) tilted by ``pitch`` (positive up). Columns are the
    camera's x (right), y (down) and z (forward) axes in world coordinates."""
    cy, sy = jnp.cos(yaw), jnp.sin(yaw)
    cp, sp = jnp.cos(pitch), jnp.sin(pitch)
    forward = jnp.stack([cp * cy, cp * sy, sp])
    right = jnp.stack([sy, -cy, jnp.zeros_like(cy)])
    down = jnp.cross(forward, right)
    return jnp.stack([right, down, forward], axis=1)


def camera_to_world(R_wc, t_wc, x_c):
    """x_w = R_wc x_c + t_wc."""
    return matvec3(R_wc, x_c) + t_wc


def invert_extrinsic(R_cw, t_cw):
    """(R_wc, t_wc) = (R_cw^T, -R_cw^T t_cw): world-to-camera -> camera-to-world."""
    R_wc = R_cw.T
    return R_wc, -R_wc @ t_cw


def floor_intersection(t_wc, d_w, n=(0.0, 0.0, 1.0), b=0.0):
    """Intersection of the ray t_wc + s d_w with the plane n.x + b = 0.

    Returns:
        (point (3,), valid) where valid means the plane lies ahead of the
        camera (s > 0) and the ray is not parallel to it.
    """
    n = jnp.asarray(n, jnp.float32)
    denom = n[0] * d_w[0] + n[1] * d_w[1] + n[2] * d_w[2]
    s = -(n[0] * t_wc[0] + n[1] * t_wc[1] + n[2] * t_wc[2] + b) / jnp.where(jnp.abs(denom) > 1e-9, denom, 1e-9)
    valid = (jnp.abs(denom) > 1e-9) & (s > 0)
    return t_wc + s * d_w, valid


def relative_target(position, theta, goal):
    """Distance r and relative bearing beta of goal g from pose (p, theta).

    Args:
        position: (2,) agent floor position.
        theta: heading, radians.
        goal: (2,) active waypoint.

    Returns:
        (r, beta): metres, radians in [-pi, pi) (positive: to the left).
    """
    delta = jnp.asarray(goal) - jnp.asarray(position)
    r = jnp.linalg.norm(delta)
    beta = wrap_angle(jnp.arctan2(delta[1], delta[0]) - theta)
    return r, beta
