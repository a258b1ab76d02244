"""The OpenGL backend: ``mujoco``'s rasteriser (EGL when headless), one view
at a time; the reference for the warp backend and its fallback.

:class:`EglScene` builds the scene's visual geometry once (``mjv_updateScene``
on the static data; the geoms never move) and, per view, only moves the
camera (``mjv_updateCamera``) and renders twice: a colour pass, and a
segmentation pass whose depth buffer gives depth (MuJoCo renders depth with
the segmentation flags on for precision at range). Segment colours decode
to the scene's visual geoms and through them to geom ids, then to instance
indices, with tables built once.

Depth is OpenGL's z-depth along the optical axis, metres (inf beyond the
far plane, where nothing was drawn).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ignjax.scenes.compile import CompiledScene
from ignjax.sim.views.cameras import geom_instance_table, render_model, view_yaws
from ignjax.sim.views.config import egl_available
from ignjax.sim.views.warp import GEOM_GROUPS
from ignjax.errors import ConfigError


class EglScene:
    """OpenGL renderer of one scene (one GL context; :meth:`close` frees it).

    Args: as :class:`ignjax.sim.views.warp.WarpScene`, without ``nworld``.
    """

    def __init__(self, compiled: CompiledScene, n_views: int, hfov_deg: float, eye_height: float, size: int):
        why = egl_available()
        if why:
            raise ConfigError(None, "views.backend", why)
        self.n_views, self.size, self.eye_height = n_views, size, float(eye_height)
        self.model, self.data = render_model(compiled, n_views, hfov_deg, size)
        self._gl = mujoco.GLContext(size, size)
        self._gl.make_current()
        self._con = mujoco.MjrContext(self.model, mujoco.mjtFontScale.mjFONTSCALE_100.value)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN.value, self._con)
        self._con.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR
        self._rect = mujoco.MjrRect(0, 0, size, size)
        self._scn = mujoco.MjvScene(self.model, maxgeom=self.model.ngeom + 64)
        opt = mujoco.MjvOption()
        opt.geomgroup[:] = 0
        opt.geomgroup[list(GEOM_GROUPS)] = 1
        self._cam = mujoco.MjvCamera()
        self._cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        self._cam.distance = 1.0
        mujoco.mjv_updateScene(self.model, self.data, opt, None, self._cam, mujoco.mjtCatBit.mjCAT_ALL.value, self._scn)
        # segment colour (segid + 1) -> geom id -> instance index (+1 shifts background to row 0)
        geoms = [self._scn.geoms[i] for i in range(self._scn.ngeom)]
        seg_geom = np.full(self._scn.ngeom + 1, -1, np.int32)
        for g in geoms:
            if g.segid >= 0 and g.objtype == int(mujoco.mjtObj.mjOBJ_GEOM):
                seg_geom[g.segid + 1] = g.objid
        self._seg_geom = seg_geom
        self._instance = geom_instance_table(compiled)
        extent = self.model.stat.extent
        self._near = np.float32(self.model.vis.map.znear * extent)
        self._far = np.float32(self.model.vis.map.zfar * extent)
        self._rgb = np.empty((size, size, 3), np.uint8)
        self._seg = np.empty((size, size, 3), np.uint8)
        self._depth = np.empty((size, size), np.float32)

    def _place(self, x: float, y: float, yaw: float) -> None:
        cam = self._cam
        cam.lookat[:] = (x + math.cos(yaw), y + math.sin(yaw), self.eye_height)
        cam.azimuth = math.degrees(yaw)
        cam.elevation = 0.0
        mujoco.mjv_updateCamera(self.model, self.data, cam, self._scn)

    def _metric_depth(self, z: np.ndarray) -> np.ndarray:
        """Reversed-Z buffer values -> z-depth, metres (as ``mujoco.Renderer``)."""
        near, far = self._near, self._far
        c = np.float32(-0.5) * (-(far + near) / (far - near)) - np.float32(0.5)
        d = np.float32(-0.5) * (-(np.float32(2) * far * near) / (far - near))
        out = d / (z.astype(np.float64) + c)
        return np.where(z > 0, out, np.inf).astype(np.float32)

    def render(self, poses: np.ndarray):
        """Views of poses (R, 3); outputs as :meth:`WarpScene.render`."""
        R, N, S = poses.shape[0], self.n_views, self.size
        rgb = np.empty((R, N, S, S, 3), np.uint8)
        depth = np.empty((R, N, S, S), np.float32)
        inst = np.empty((R, N, S, S), np.int32)
        self._gl.make_current()
        flags = self._scn.flags
        yaws = view_yaws(np.asarray(poses[:, 2], np.float64), N)
        for r in range(R):
            for k in range(N):
                self._place(float(poses[r, 0]), float(poses[r, 1]), float(yaws[r, k]))
                flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 0
                flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 0
                mujoco.mjr_render(self._rect, self._scn, self._con)
                mujoco.mjr_readPixels(self._rgb, None, self._rect, self._con)
                flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 1
                flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 1
                mujoco.mjr_render(self._rect, self._scn, self._con)
                mujoco.mjr_readPixels(self._seg, self._depth, self._rect, self._con)
                flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = 0
                flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = 0
                rgb[r, k] = self._rgb[::-1]  # OpenGL rows run bottom-up
                seg = self._seg[::-1].astype(np.int32)
                segid = seg[..., 0] | (seg[..., 1] << 8) | (seg[..., 2] << 16)
                geom = self._seg_geom[np.minimum(segid, self._seg_geom.shape[0] - 1)]
                inst[r, k] = self._instance[geom + 1]
                depth[r, k] = self._metric_depth(self._depth[::-1])
        return rgb, depth, inst

    def close(self) -> None:
        if getattr(self, "_con", None) is not None:
            self._con.free()
            self._con = None
        if getattr(self, "_gl", None) is not None:
            self._gl.free()
            self._gl = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass


__all__ = ["EglScene"]
