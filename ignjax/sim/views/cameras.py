"""The cameras of the egocentric views, shared by both backends.

View k of N looks along ``yaw + k * 2 pi / N`` (counter-clockwise) from the
eye ``(x, y, eye_height)`` with pitch 0, a pinhole of horizontal field of
view ``hfov`` on a square image: exactly the camera
:func:`ignjax.sim.executor.pixel_waypoint` back-projects a grid cell through
(:func:`ignjax.sim.executor.view_camera`). ``hfov`` is the simulator's
``view_hfov`` (:func:`ignjax.protocol.view_hfov`): 90 degrees for 8 views
(neighbours overlap by half, the paper's main setting) and ``360 / N`` for
4 and 12, whose views tile the circle. A 12-view image is as large as an
8-view one and covers 30 x 30 degrees: the same pixels over a narrower
field, so at eye height 1.25 m its bottom edge meets the floor about 4.7 m
ahead (the grid's floor rows lie beyond the executor's 3 m horizon). MuJoCo's camera frame looks
along its -z axis with +y up, so its rotation's columns are (right, -down,
-forward) of the executor's camera frame.

:func:`render_model` compiles a scene once more with N fixed cameras in the
world body (the geoms, and so geom ids, are those of the scene's compiled
model); the warp backend moves them per world through ``cam_xpos`` /
``cam_xmat``, the OpenGL backend renders through a free camera placed the
same way.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ignjax.arrays import xp
from ignjax.errors import ConfigError
from ignjax.scenes.compile import CompiledScene, build_spec


def view_yaws(yaw, n_views: int):
    """(..., N) heading of each view for headings ``yaw`` (...,)."""
    x = xp(yaw)
    return x.asarray(yaw)[..., None] + x.arange(n_views) * (2 * math.pi / n_views)


def mujoco_camera_xmat(yaw):
    """(..., 3, 3) MuJoCo camera-to-world rotation for views along ``yaw``
    (pitch 0): columns right, up, backward."""
    x = xp(yaw)
    yaw = x.asarray(yaw)
    c, s = x.cos(yaw), x.sin(yaw)
    z = x.zeros_like(yaw)
    one = x.ones_like(yaw)
    right = x.stack([s, -c, z], -1)
    up = x.stack([z, z, one], -1)
    back = x.stack([-c, -s, z], -1)
    return x.stack([right, up, back], -1)


def vertical_fov_deg(hfov_deg: float) -> float:
    """Vertical field of view of a square image with horizontal ``hfov_deg``."""
    return math.degrees(2.0 * math.atan(math.tan(math.radians(hfov_deg) / 2.0)))


def render_model(compiled: CompiledScene, n_views: int, hfov_deg: float, size: int):
    """The scene's MuJoCo model with ``n_views`` fixed cameras (``view0`` ..),
    an offscreen buffer of at least ``size`` pixels, and its forward data.

    Returns:
        (model, data); ``model.ngeom`` and geom order equal ``compiled.model``'s.
    """
    spec, _ = build_spec(compiled.scene, compiled.options)
    spec.visual.global_.offwidth = max(int(spec.visual.global_.offwidth), size)
    spec.visual.global_.offheight = max(int(spec.visual.global_.offheight), size)
    spec.visual.global_.fovy = vertical_fov_deg(hfov_deg)
    for k in range(n_views):
        cam = spec.worldbody.add_camera(name=f"view{k}", pos=[0.0, 0.0, 1.0])
        cam.fovy = vertical_fov_deg(hfov_deg)
    model = spec.compile()
    if model.ngeom != compiled.model.ngeom:
        raise RuntimeError(f"scene {compiled.scene.id!r}: the render model has {model.ngeom} geoms, "
                           f"its compiled model {compiled.model.ngeom}")
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def geom_instance_table(compiled: CompiledScene) -> np.ndarray:
    """(ngeom + 1,) int32 instance index of each geom id, shifted by one so
    that index 0 (geom id -1: background) maps to -1 too."""
    return np.concatenate([[-1], compiled.geom_instance]).astype(np.int32)


def check_poses(compiled: CompiledScene, poses: np.ndarray, where: str = "poses") -> None:
    """Refuse poses that are not finite or whose eye lies outside the scene's
    footprint (its bounds), before anything is rendered."""
    poses = np.asarray(poses)
    if poses.ndim != 2 or poses.shape[1] != 3:
        raise ConfigError(None, where, f"must be (rows, 3) poses x, y, yaw; got shape {poses.shape}")
    bad = ~np.all(np.isfinite(poses), axis=1)
    lo, hi = compiled.scene.bounds()
    outside = (poses[:, 0] < lo[0]) | (poses[:, 0] > hi[0]) | (poses[:, 1] < lo[1]) | (poses[:, 1] > hi[1])
    rows = np.nonzero(bad | outside)[0]
    if rows.size:
        r = int(rows[0])
        raise ConfigError(None, f"{where}[{r}]", f"pose {poses[r].tolist()} lies outside scene {compiled.scene.id!r} "
                          f"(x in [{lo[0]:.2f}, {hi[0]:.2f}], y in [{lo[1]:.2f}, {hi[1]:.2f}]); {rows.size} such row(s)")


__all__ = ["check_poses", "geom_instance_table", "mujoco_camera_xmat", "render_model", "vertical_fov_deg", "view_yaws"]
