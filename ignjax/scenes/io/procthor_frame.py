"""Unity's frame in ours, for the ProcTHOR importer: points (Y-up,
left-handed -> Z-up, right-handed), headings, and the upright box of a
rotated asset. The conventions and their derivation are in
:mod:`ignjax.scenes.io.procthor`.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ignjax.scenes.model import OrientedBox

__all__ = ["unity_to_world", "unity_yaw", "upright_box"]


def unity_to_world(point) -> np.ndarray:
    """Unity (x, y, z), Y-up left-handed -> ours (x, z, y), Z-up right-handed.

    Works on any array (..., 3).
    """
    p = np.asarray(point, dtype=np.float64)
    return p[..., [0, 2, 1]]


def _wrap(angle: float) -> float:
    a = math.remainder(angle, 2.0 * math.pi)
    return math.pi if a == -math.pi else a


def unity_yaw(rotation_y_degrees: float) -> float:
    """Our heading (radians, CCW from +x) of a ProcTHOR asset turned by
    ``rotation.y`` degrees about Unity's up axis: ``pi/2 - radians(y)``.

    The asset's forward axis (Unity ``+z``) is the direction the result
    points along; see :mod:`ignjax.scenes.io.procthor` for the derivation.
    """
    return _wrap(math.pi / 2.0 - math.radians(rotation_y_degrees))


def _unity_rotation(rx: float, ry: float, rz: float) -> np.ndarray:
    """Unity's Euler rotation (degrees, applied Z then X then Y) as a matrix
    acting on Unity column vectors."""
    x, y, z = (math.radians(v) for v in (rx, ry, rz))
    cx, sx, cy, sy, cz, sz = math.cos(x), math.sin(x), math.cos(y), math.sin(y), math.cos(z), math.sin(z)
    mx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    my = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    mz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return my @ mx @ mz


_CORNER_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)


def upright_box(center_u: np.ndarray, size_u: Sequence[float], rot_u: Sequence[float]) -> tuple[OrientedBox, float]:
    """Upright box (ours) of an asset box centred at ``center_u`` (Unity)."""
    rx, ry, rz = rot_u
    yaw = unity_yaw(ry)
    half = 0.5 * np.asarray(size_u, dtype=np.float64)
    if abs(math.remainder(rx, 360.0)) < 1e-6 and abs(math.remainder(rz, 360.0)) < 1e-6:
        c = unity_to_world(center_u)
        return OrientedBox(tuple(c), (half[2], half[0], half[1]), yaw), yaw
    corners_u = center_u + (_CORNER_SIGNS * half) @ _unity_rotation(rx, ry, rz).T
    corners = unity_to_world(corners_u)
    u = np.array([math.cos(yaw), math.sin(yaw)])
    v = np.array([-math.sin(yaw), math.cos(yaw)])
    c0 = unity_to_world(center_u)
    d = corners[:, :2] - c0[:2]
    pu, pv = d @ u, d @ v
    cu, cv = 0.5 * (pu.max() + pu.min()), 0.5 * (pv.max() + pv.min())
    cxy = c0[:2] + cu * u + cv * v
    zlo, zhi = corners[:, 2].min(), corners[:, 2].max()
    box = OrientedBox((cxy[0], cxy[1], 0.5 * (zlo + zhi)),
                      (0.5 * (pu.max() - pu.min()), 0.5 * (pv.max() - pv.min()), 0.5 * (zhi - zlo)), yaw)
    return box, yaw

