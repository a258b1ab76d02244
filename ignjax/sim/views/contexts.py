"""The backend's per-scene renderers of one process: :class:`SceneContexts`
(used by :class:`~ignjax.sim.views.renderer.ViewRenderer` in its own
process and by each render worker of :mod:`ignjax.sim.views.pool`)."""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

from ignjax.sim.types import SimConfig
from ignjax.sim.views.config import ViewConfig

MIN_WORLDS = 2
"""Smallest warp context. MuJoCo Warp's one-world contexts trace a few
pixels differently (one colour level, depth by ~1e-4 m) from contexts of
two or more worlds, which all agree; with at least two worlds a view's
pixels never depend on how many rows were pending when it was rendered."""


class SceneContexts:
    """The backend's per-scene renderers, made on first use and kept in a
    least-recently-used cache of at most ``config.max_contexts`` renderers
    whose warp output buffers stay under ``config.cache_mb`` (closed when
    dropped). Used in this process and, one each, in the render workers.

    Args:
        compiled: ``compiled(s)`` gives scene ``s``'s :class:`~ignjax.scenes.compile.CompiledScene`.
        backend: ``"warp"`` or ``"egl"`` (resolved).
    """

    def __init__(self, compiled, backend: str, sim: SimConfig, config: ViewConfig):
        self.compiled, self.backend, self.sim, self.config = compiled, backend, sim, config
        self._scenes: OrderedDict = OrderedDict()
        self.made = 0  # renderers made so far (a cache too small for a run's groups shows here)

    def _scene(self, s: int, rows: int):
        cfg, sim = self.config, self.sim
        if self.backend == "egl":
            key = (s, 0)
        else:
            limit = max(MIN_WORLDS, cfg.world_limit(sim.n_views))
            key = (s, min(limit, max(MIN_WORLDS, 1 << max(0, int(rows - 1).bit_length()))))
        if key in self._scenes:
            self._scenes.move_to_end(key)
            return self._scenes[key]
        budget = cfg.cache_mb << 20
        size = cfg.context_bytes(sim.n_views, key[1])
        while self._scenes and (len(self._scenes) >= cfg.max_contexts
                                or self._bytes() + size > budget):
            _, old = self._scenes.popitem(last=False)
            close = getattr(old, "close", None)
            if close:
                close()
        compiled = self.compiled(s)
        if self.backend == "egl":
            from ignjax.sim.views.egl import EglScene

            r = EglScene(compiled, sim.n_views, sim.view_hfov, sim.eye_height, cfg.size)
        else:
            from ignjax.sim.views.warp import WarpScene

            r = WarpScene(compiled, sim.n_views, sim.view_hfov, sim.eye_height, cfg.size, key[1])
        self._scenes[key] = r
        self.made += 1
        return r

    def _bytes(self) -> int:
        return sum(self.config.context_bytes(self.sim.n_views, k[1]) for k in self._scenes)

    def render(self, s: int, poses: np.ndarray):
        """(rgb, depth, instance) of the views of ``poses`` (R, 3) in scene
        ``s``, R at most one call's rows (:meth:`ViewRenderer.render`)."""
        return self._scene(s, poses.shape[0]).render(poses)

    def close(self) -> None:
        for r in self._scenes.values():
            close = getattr(r, "close", None)
            if close:
                close()
        self._scenes.clear()


__all__ = ["MIN_WORLDS", "SceneContexts"]
