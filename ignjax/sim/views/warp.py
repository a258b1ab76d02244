"""The MuJoCo Warp backend: every view of up to ``nworld`` episodes of one
scene in one ray-traced call.

Per scene and world count, :class:`WarpScene` holds a render context
(``mujoco.mjx.create_render_context``: the scene's BVH, built once from the
static geom poses, and output buffers for ``nworld`` worlds x N cameras)
and one jitted function that writes each world's camera poses into an MJX
``Data`` (``cam_xpos``, ``cam_xmat``; the geoms never move, so the BVH is
never refit) and calls ``mjx.render_with_segmentation`` under ``vmap``.

Outputs are unpacked on the host: RGB from the packed 32-bit words, depth
(z-depth along the optical axis, as the ray tracer writes it and as
OpenGL's depth and the executor's ``z`` are; 0 where no surface -> inf), and
segmentation (geom id -> instance index; -1 for walls, floor, structure
without an instance and background).

Memory: one context holds ``nworld * N * S^2 * 16`` bytes of outputs (4 RGB,
4 depth, 8 segmentation) plus the scene's BVH (a few MB for a house of about
1,000 geoms); JAX holds one more copy of the outputs while they are
unpacked. At 448 px and 8 views that is 25.7 MB per world.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ignjax.scenes.compile import CompiledScene
from ignjax.sim.views.cameras import geom_instance_table, mujoco_camera_xmat, render_model, view_yaws

GEOM_GROUPS = (0, 1, 2, 3)  # floor, walls, objects, structure (ignjax.scenes.compile.GROUP_*)
BACKGROUND = (0.0, 0.0, 0.0, 1.0)


class WarpScene:
    """Batch renderer of one scene for a fixed number of worlds.

    Args:
        compiled: the scene as compiled for the simulator.
        n_views, hfov_deg, eye_height: the views (SimConfig: ``hfov_deg`` is its ``view_hfov``).
        size: pixels per side.
        nworld: episodes per call (rows beyond it are rendered in further calls).
    """

    def __init__(self, compiled: CompiledScene, n_views: int, hfov_deg: float, eye_height: float, size: int, nworld: int):
        import jax
        import jax.numpy as jnp
        import warp
        from mujoco import mjx

        # no start-up banner or per-module load lines on stdout (the bench prints JSON there)
        warp.config.log_level = getattr(warp, "LOG_WARNING", 30)
        self.n_views, self.size, self.nworld, self.eye_height = n_views, size, nworld, float(eye_height)
        model, data = render_model(compiled, n_views, hfov_deg, size)
        self._ctx = mjx.create_render_context(
            model, nworld=nworld, cam_res=(size, size), render_rgb=True, render_depth=True, render_seg=True,
            use_textures=True, use_shadows=False, enabled_geom_groups=list(GEOM_GROUPS), background_color=BACKGROUND)
        npix = size * size
        for name in ("rgb_adr", "depth_adr", "seg_adr"):  # cameras' outputs are laid out one after the other
            adr = np.asarray(getattr(self._ctx, name).numpy())
            if not np.array_equal(adr, np.arange(n_views) * npix):
                raise RuntimeError(f"unexpected render layout {name}={adr.tolist()}")
        self._instance = geom_instance_table(compiled)
        mx = mjx.put_model(model, impl="warp")
        base = mjx.make_data(model, impl="warp")
        base = base.tree_replace({
            "geom_xpos": jnp.asarray(data.geom_xpos, jnp.float32),
            "geom_xmat": jnp.asarray(data.geom_xmat, jnp.float32).reshape(-1, 3, 3),
            "_impl.light_xpos": jnp.asarray(data.light_xpos, jnp.float32),
            "_impl.light_xdir": jnp.asarray(data.light_xdir, jnp.float32),
        })
        rc = self._ctx.pytree()
        eye_h = self.eye_height

        def one(pose):
            yaws = view_yaws(pose[2], n_views)
            eye = jnp.stack([pose[0], pose[1], jnp.float32(eye_h)])
            d = base.replace(cam_xpos=jnp.broadcast_to(eye, (n_views, 3)),
                             cam_xmat=mujoco_camera_xmat(yaws).reshape(base.cam_xmat.shape))
            return d

        def render(poses):
            dx = jax.vmap(one)(poses)
            rgb, depth, seg, _ = jax.vmap(mjx.render_with_segmentation, in_axes=(None, 0, None))(mx, dx, rc)
            return rgb, depth, seg

        self._render = jax.jit(render)

    def render(self, poses: np.ndarray):
        """Views of up to ``nworld`` poses (R, 3).

        Returns:
            rgb (R, N, S, S, 3) uint8, depth (R, N, S, S) float32 z-depth in
            metres (inf where no surface), instance (R, N, S, S) int32.
        """
        R = poses.shape[0]
        if R > self.nworld:
            raise ValueError(f"{R} poses for a context of {self.nworld} worlds")
        padded = np.zeros((self.nworld, 3), np.float32)
        padded[:R] = poses
        padded[R:] = poses[:1]
        rgb, depth, seg = self._render(padded)
        N, S = self.n_views, self.size
        words = np.asarray(rgb)[:R].reshape(R, N, S, S)
        rgb8 = words.view(np.uint8).reshape(R, N, S, S, 4)[..., 2::-1]  # little-endian words: B, G, R, A
        dist = np.asarray(depth)[:R].reshape(R, N, S, S)
        z = np.where(dist > 0, dist, np.inf).astype(np.float32)
        seg = np.asarray(seg)[:R].reshape(R, N, S, S, 2)
        geom = np.where(seg[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM), seg[..., 0], -1)
        inst = self._instance[geom + 1]
        return np.ascontiguousarray(rgb8), z, inst


__all__ = ["GEOM_GROUPS", "WarpScene"]
