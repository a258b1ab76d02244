"""Rendered observations for a batch of episodes: :class:`ViewRenderer`.

One renderer serves a whole :class:`~ignjax.scenes.bank.SceneBank`. A call
takes the rows awaiting an image-based decision (a mask over the batch, or
explicit scene indices and poses), groups them by scene, and renders each
group with the configured backend:

* warp: one call per scene and chunk of up to ``ViewConfig.world_limit``
  rows. Contexts are made for power-of-two world counts (the smallest that
  holds the group, so a few pending rows do not pay for a full batch),
  kept in a least-recently-used cache whose output buffers (worlds x N x
  S^2 x 16 bytes each) stay under ``cache_mb`` and reused across steps;
  memory therefore grows with ``cache_mb``, not with the scenes in the
  bank (:mod:`ignjax.sim.views.warp`).
* egl: one OpenGL context per scene (a few MB each), one view at a time.
* with ``ViewConfig.workers`` > 1 the calls go to that many worker
  processes (:mod:`ignjax.sim.views.pool`), each with its own contexts.

Poses are checked before anything is rendered (finite, inside the scene's
bounds). The result, :class:`Views`, carries RGB, z-depth and instance
segmentation of every view; :meth:`ViewRenderer.panels` and
:meth:`ViewRenderer.grounder_images` compose the two images the paper's
agents read (:mod:`ignjax.sim.views.compose`) and :func:`ignjax.sim.views.encode.encode_images`
turns them into PNG/JPEG bytes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ignjax.errors import ConfigError
from ignjax.scenes.bank import SceneBank
from ignjax.sim.types import SimConfig, SimState
from ignjax.sim.views.cameras import check_poses
from ignjax.sim.views.config import ViewConfig, resolve_backend
from ignjax.sim.views.contexts import MIN_WORLDS, SceneContexts


@dataclass(frozen=True)
class Views:
    """The rendered views of R rows.

    Attributes:
        rows: (R,) int row of each view set in the batch it came from.
        scene: (R,) int scene index.
        pose: (R, 3) float32 pose (x, y, yaw) the views were taken from.
        rgb: (R, N, S, S, 3) uint8; view k looks along yaw + k * 360 / N.
        depth: (R, N, S, S) float32 z-depth along the optical axis, m (inf: no surface).
        instance: (R, N, S, S) int32 instance index in the scene (-1: none).
    """

    rows: np.ndarray
    scene: np.ndarray
    pose: np.ndarray
    rgb: np.ndarray
    depth: np.ndarray
    instance: np.ndarray

    def __len__(self) -> int:
        return int(self.rows.shape[0])


class ViewRenderer:
    """Batched egocentric views of the scenes of a bank.

    Args:
        bank: the scene bank (its compiled scenes are rendered).
        sim: the simulator configuration (``n_views``, ``view_hfov``, ``eye_height``).
        config: image size, backend, workers and encoding (:class:`ViewConfig`).
    """

    def __init__(self, bank: SceneBank, sim: SimConfig = SimConfig(), config: ViewConfig = ViewConfig()):
        self.bank, self.sim, self.config = bank, sim, config
        self.backend = resolve_backend(config)
        self.n_views = sim.n_views
        self.workers = config.worker_count()
        if self.workers > 1:
            from ignjax.sim.views.pool import RenderPool

            self._contexts = RenderPool(lambda s: bank.compiled[s], self.backend, sim, config, self.workers)
        else:
            self._contexts = SceneContexts(lambda s: bank.compiled[s], self.backend, sim, config)

    # -- rendering ------------------------------------------------------------
    def render(self, scene, poses, rows=None) -> Views:
        """Views of R rows given their scene indices (R,) and poses (R, 3).

        Rows are grouped by scene and cut into calls of at most one
        context's worlds (warp; all rows for OpenGL); with several workers
        each group is cut into at least as many calls as there are workers,
        and the calls run at once, one queue per worker.

        Raises:
            ConfigError: a scene index outside the bank or a pose outside
                its scene (named by row), before anything is rendered.
        """
        scene = np.asarray(scene, np.int64).reshape(-1)
        poses = np.asarray(poses, np.float32).reshape(-1, 3)
        R = scene.shape[0]
        if poses.shape[0] != R:
            raise ConfigError(None, "poses", f"{poses.shape[0]} poses for {R} scene indices")
        rows = np.arange(R) if rows is None else np.asarray(rows, np.int64)
        bad = np.nonzero((scene < 0) | (scene >= self.bank.n_scenes))[0]
        if bad.size:
            raise ConfigError(None, f"scene[{int(bad[0])}]", f"scene index {int(scene[bad[0]])} is not in the bank "
                              f"({self.bank.n_scenes} scenes)")
        groups = [(int(s), np.nonzero(scene == s)[0]) for s in np.unique(scene)]
        for s, idx in groups:
            check_poses(self.bank.compiled[s], poses[idx], where=f"poses (scene {self.bank.scene_ids[s]!r})")
        N, S = self.n_views, self.config.size
        rgb = np.empty((R, N, S, S, 3), np.uint8)
        depth = np.empty((R, N, S, S), np.float32)
        inst = np.empty((R, N, S, S), np.int32)
        calls = []
        for s, idx in groups:
            limit = idx.size if self.backend == "egl" else self.config.world_limit(N)
            limit = max(1, min(limit, -(-idx.size // self.workers)))
            calls += [(s, idx[start:start + limit]) for start in range(0, idx.size, limit)]
        if self.workers > 1:
            outs = self._contexts.render_many([(s, poses[part]) for s, part in calls])
        else:
            outs = (self._contexts.render(s, poses[part]) for s, part in calls)
        for (_, part), out in zip(calls, outs):
            rgb[part], depth[part], inst[part] = out
        return Views(rows=rows, scene=scene, pose=poses, rgb=rgb, depth=depth, instance=inst)

    def render_states(self, states: SimState, mask=None) -> Views:
        """Views of the rows of a (B,) batch of states where ``mask`` (B,) is
        true (default: every row that is not done)."""
        done = np.asarray(states.done)
        mask = ~done if mask is None else np.asarray(mask, bool)
        rows = np.nonzero(mask)[0]
        return self.render(np.asarray(states.episode.scene)[rows], np.asarray(states.pose)[rows], rows)

    # -- the images the agents read ------------------------------------------
    def panels(self, views: Views) -> np.ndarray:
        """(R, H, W, 3) uint8 Planner panels (:func:`ignjax.sim.views.compose.planner_panels`)."""
        from ignjax.sim.views.compose import planner_panels

        return planner_panels(views.rgb, grid=self.config.panel_grid)

    def grounder_images(self, views: Views, direction) -> np.ndarray:
        """(R, S, S, 3) uint8: view ``direction[r]`` of each row with the numbered 8x8 grid."""
        from ignjax.sim.views.compose import grounder_images

        direction = np.asarray(direction, np.int64).reshape(-1)
        if direction.shape[0] != len(views) or np.any((direction < 0) | (direction >= self.n_views)):
            raise ConfigError(None, "direction", f"must be {len(views)} view indices in [0, {self.n_views}), got {direction.tolist()}")
        return grounder_images(views.rgb[np.arange(len(views)), direction])

    def close(self) -> None:
        self._contexts.close()

    def __enter__(self) -> "ViewRenderer":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


__all__ = ["MIN_WORLDS", "SceneContexts", "ViewRenderer", "Views"]
