"""Headless rendering of first-person views with ``mujoco.Renderer``.

Camera conventions (shared with the executor): pinhole, square pixels,
horizontal field of view ``hfov`` (default 90 degrees); camera frame x right,
y down, z forward; the agent's eye looks along heading ``yaw`` (radians,
counter-clockwise from +X) tilted by ``pitch`` (radians, positive up).
View ``k`` of the 8-view panorama looks along ``yaw + k * 45 degrees``.

Rendering uses OpenGL through the backend MuJoCo chose from ``MUJOCO_GL``
when it was imported: EGL (headless Mesa on a CPU machine, the NVIDIA driver
on a GPU machine) after :func:`ignjax.scenes.viz.headless_gl`, which the
command lines call first. Without ``MUJOCO_GL`` and without a display,
:class:`ViewRenderer` says so instead of failing inside OpenGL.
"""

from __future__ import annotations

import math
import os
import sys

import matplotlib.image as mpimg
import mujoco
import numpy as np

from ignjax.errors import IgnjaxError
from ignjax.protocol import VIEW_NAMES  # noqa: F401  (view k's name, for callers labelling views)


def intrinsics(width: int, height: int, hfov_deg: float = 90.0) -> np.ndarray:
    """Pinhole intrinsic matrix K (3, 3) for an image of ``width`` x ``height``
    pixels and a horizontal field of view; square pixels, principal point at
    the image centre."""
    fx = (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
    return np.array([[fx, 0.0, width / 2.0], [0.0, fx, height / 2.0], [0.0, 0.0, 1.0]])


def vertical_fov_deg(width: int, height: int, hfov_deg: float) -> float:
    """Vertical field of view matching ``hfov_deg`` for square pixels."""
    return math.degrees(2.0 * math.atan(math.tan(math.radians(hfov_deg) / 2.0) * height / width))


class ViewRenderer:
    """Renders first-person RGB (and optionally depth) views of one compiled scene.

    Holds one OpenGL context; reuse it for many views and call :meth:`close`
    (or use it as a context manager) when done.

    Args:
        model: the scene's ``mujoco.MjModel``.
        data: its ``mujoco.MjData`` after ``mj_forward``.
        width, height: image size in pixels (at most the model's offscreen size).
        hfov_deg: horizontal field of view, degrees.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, width: int = 320, height: int = 320, hfov_deg: float = 90.0):
        if sys.platform.startswith("linux") and not os.environ.get("MUJOCO_GL") and not os.environ.get("DISPLAY"):
            raise IgnjaxError("no OpenGL backend for rendering: there is no display and MUJOCO_GL is unset; set "
                              "MUJOCO_GL=egl (headless) before mujoco is imported, or call "
                              "ignjax.scenes.viz.headless_gl() first")
        self.model, self.data = model, data
        self.width, self.height, self.hfov_deg = int(width), int(height), float(hfov_deg)
        self._renderer = mujoco.Renderer(model, height=self.height, width=self.width)
        self._camera = mujoco.MjvCamera()
        self._camera.type = mujoco.mjtCamera.mjCAMERA_FREE

    def _place(self, eye, yaw: float, pitch: float) -> None:
        fwd = np.array([math.cos(pitch) * math.cos(yaw), math.cos(pitch) * math.sin(yaw), math.sin(pitch)])
        self._camera.lookat[:] = np.asarray(eye, dtype=np.float64) + fwd
        self._camera.distance = 1.0
        self._camera.azimuth = math.degrees(yaw)
        self._camera.elevation = math.degrees(pitch)
        self.model.vis.global_.fovy = vertical_fov_deg(self.width, self.height, self.hfov_deg)

    def render(self, eye, yaw: float, pitch: float = 0.0) -> np.ndarray:
        """RGB image (H, W, 3) uint8 seen from ``eye`` (3,) along ``yaw``/``pitch``."""
        self._place(eye, yaw, pitch)
        self._renderer.disable_depth_rendering()
        self._renderer.update_scene(self.data, camera=self._camera)
        return self._renderer.render().copy()

    def render_depth(self, eye, yaw: float, pitch: float = 0.0) -> np.ndarray:
        """Depth image (H, W) float32: distance along the optical axis, metres."""
        self._place(eye, yaw, pitch)
        self._renderer.enable_depth_rendering()
        self._renderer.update_scene(self.data, camera=self._camera)
        out = self._renderer.render().astype(np.float32).copy()
        self._renderer.disable_depth_rendering()
        return out

    def panorama(self, eye, yaw: float, pitch: float = 0.0) -> np.ndarray:
        """The 8 views (8, H, W, 3) uint8; view k looks along ``yaw + k*pi/4``."""
        return np.stack([self.render(eye, yaw + k * math.pi / 4, pitch) for k in range(8)])

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __enter__(self) -> "ViewRenderer":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass


def render_rgb(model, data, eye, target, *, fovy: float = 60.0, width: int = 320, height: int = 240) -> np.ndarray:
    """One RGB image (H, W, 3) uint8 from ``eye`` looking at ``target``.

    ``fovy`` is the vertical field of view in degrees. Opens and closes its
    own renderer; use :class:`ViewRenderer` for many images.
    """
    eye = np.asarray(eye, dtype=np.float64)
    d = np.asarray(target, dtype=np.float64) - eye
    yaw = math.atan2(d[1], d[0])
    pitch = math.atan2(d[2], math.hypot(d[0], d[1]))
    hfov = math.degrees(2.0 * math.atan(math.tan(math.radians(fovy) / 2.0) * width / height))
    with ViewRenderer(model, data, width, height, hfov) as r:
        return r.render(eye, yaw, pitch)


def save_png(image: np.ndarray, path) -> None:
    """Write an (H, W, 3) uint8 image as PNG atomically (temp name, then rename)."""
    path = os.fspath(path)
    tmp = f"{path}.tmp-{os.getpid()}.png"
    mpimg.imsave(tmp, np.asarray(image))
    os.replace(tmp, path)
