"""Configuration of rendered observations (:class:`ViewConfig`) and the
choice of backend.

The view geometry is the executor's and lives in :class:`ignjax.sim.types.SimConfig`
(``n_views``, ``eye_height``, ``view_hfov``; pitch 0): a rendered view is exactly
the camera the executor back-projects a grid cell through. What is only
about images lives here: their size, the backend, and how they are encoded.

Backends:

* ``"warp"``: MuJoCo Warp's batch ray tracer through MJX
  (``mujoco.mjx.create_render_context`` / ``mjx.render_with_segmentation``);
  needs the ``warp-lang`` package (MJX ships its MuJoCo Warp copy). All
  views of up to ``worlds`` episodes of one scene in one call, on CPU or GPU.
* ``"egl"``: ``mujoco``'s OpenGL renderer (EGL when headless), one view at a
  time; the reference and the fallback.
* ``"auto"``: warp when installed, EGL otherwise.

With ``fallback`` (default true) a requested backend that cannot run falls
back to the other with a warning naming what is missing; with it false the
error is raised. Either way the check happens before anything is rendered
(:func:`resolve_backend`).
"""

from __future__ import annotations

import dataclasses
import importlib.util
import os
import sys
import warnings
from dataclasses import dataclass

from ignjax.errors import ConfigError

BACKENDS = ("warp", "egl", "auto")
FORMATS = ("jpeg", "png")
MIN_SIZE, MAX_SIZE = 64, 1024
DEFAULT_SIZE = 448
"""Pixels per side of a rendered view unless ``views.size`` says otherwise: the one default of
:class:`ViewConfig`, ``python -m ignjax.evaluate``, ``python -m ignjax.sweep`` (``--quick`` included) and
``python -m ignjax.build render``. The paper states no image size, so this is a choice: a 448 px view
is 56 px per cell of the Grounder's 8x8 grid, 2 x 2 vision tokens of 28 px for Qwen2/2.5-VL-style
models (16 x 16 per view) where 224 px leaves one token per cell, for targets as small as the
benchmark's mugs, remote controls and books; the 8-view Planner panel is then 1344 px square, about
2,300 image tokens, which still fits a 16k context beside the prompt and the 1024-token reply. Lower
it (``--set views.size=224``) for cheap runs."""
WARP_PACKAGE = "warp-lang"


@dataclass(frozen=True)
class ViewConfig:
    """How rendered observations are made.

    Attributes:
        size: pixels per side of a square view, in [64, 1024]; 448 by
            default (``DEFAULT_SIZE``, where the choice is explained: the
            paper states none), 224 for cheap runs.
        backend: ``"warp"``, ``"egl"`` or ``"auto"`` (module docstring).
        fallback: use the other backend when the requested one cannot run.
        worlds: the most episodes one warp call renders (its render context
            is made for this many worlds; fewer pending rows use a smaller
            context: powers of two up to this). 0: chosen from ``memory_mb``.
        memory_mb: output buffers of one warp context stay under this, MB
            (16 bytes per pixel: RGB, depth, segmentation pair).
        max_contexts: render contexts a process keeps at once (the least
            recently used dropped first).
        cache_mb: output buffers of the warp contexts a process keeps stay
            under this, MB (the least recently used dropped first; a
            context larger than this on its own is still made, and kept
            alone). Memory grows with this, not with the number of scenes
            in the bank. A dropped context costs about half a second to
            make again, so the cache should hold every (scene, world
            count) a run keeps using: at 128 px a 16-world context is
            34 MB, at 448 px 411 MB.
        image_format: ``"jpeg"`` or ``"png"``, for encoded images.
        quality: JPEG quality, 1..100.
        panel_grid: draw the 8x8 grid on every view of the Planner panel
            (the paper's panel carries local grids).
        workers: render processes. MuJoCo Warp runs a kernel on one thread
            when it runs on the CPU, and OpenGL renders one view at a time,
            so on a CPU with C cores ``workers = C`` renders C calls at once
            (each worker holds its own contexts; memory grows with it).
            1 (default): render in this process. 0: one per CPU core this
            process may use. Keep 1 on a GPU.
    """

    size: int = DEFAULT_SIZE
    backend: str = "auto"
    fallback: bool = True
    worlds: int = 0
    memory_mb: int = 512
    max_contexts: int = 64
    cache_mb: int = 2048
    image_format: str = "jpeg"
    quality: int = 90
    panel_grid: bool = True
    workers: int = 1

    def __post_init__(self):
        def integer(name, lo, hi, why=""):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
                raise ConfigError(None, f"views.{name}", f"must be an integer in [{lo}, {hi}]{why}, got {v!r}")

        integer("size", MIN_SIZE, MAX_SIZE, " pixels")
        integer("worlds", 0, 1 << 16, " (0: from memory_mb)")
        integer("memory_mb", 1, 1 << 20)
        integer("max_contexts", 1, 1024)
        integer("cache_mb", 1, 1 << 20)
        integer("quality", 1, 100)
        integer("workers", 0, 256, " (0: one per CPU core)")
        if self.backend not in BACKENDS:
            raise ConfigError(None, "views.backend", f"must be one of {', '.join(BACKENDS)}, got {self.backend!r}")
        if self.image_format not in FORMATS:
            raise ConfigError(None, "views.image_format", f"must be one of {', '.join(FORMATS)}, got {self.image_format!r}")
        for name in ("fallback", "panel_grid"):
            if not isinstance(getattr(self, name), bool):
                raise ConfigError(None, f"views.{name}", f"must be true or false, got {getattr(self, name)!r}")

    def world_limit(self, n_views: int) -> int:
        """Most worlds of one warp context: ``worlds``, or what fits ``memory_mb``."""
        if self.worlds:
            return self.worlds
        per_world = n_views * self.size * self.size * 16
        return max(1, min(1024, (self.memory_mb << 20) // per_world))

    def context_bytes(self, n_views: int, worlds: int) -> int:
        """Output buffers of a warp context of ``worlds`` worlds, bytes (16 per pixel)."""
        return worlds * n_views * self.size * self.size * 16

    def worker_count(self) -> int:
        """Render processes to use (``workers``; 0 resolved to the usable cores)."""
        if self.workers:
            return self.workers
        try:
            return max(1, len(os.sched_getaffinity(0)))
        except AttributeError:  # not on Linux
            return max(1, os.cpu_count() or 1)

    def replace(self, **kw) -> "ViewConfig":
        return dataclasses.replace(self, **kw)


def warp_available() -> str | None:
    """None when the warp backend can run here, else the reason."""
    if importlib.util.find_spec("warp") is None:
        return f"the warp backend needs the {WARP_PACKAGE!r} package (pip install \"ignjax[render]\")"
    return None


def egl_available() -> str | None:
    """None when OpenGL rendering can start here, else the reason."""
    if sys.platform.startswith("linux") and not os.environ.get("MUJOCO_GL") and not os.environ.get("DISPLAY"):
        return ("the egl backend needs an OpenGL backend: there is no display and MUJOCO_GL is unset; set MUJOCO_GL=egl "
                "before mujoco is imported, or call ignjax.scenes.viz.headless_gl() first")
    return None


def resolve_backend(config: ViewConfig) -> str:
    """The backend that will render: the requested one, or the fallback.

    Raises:
        ConfigError: naming the missing package or setting, when the
            requested backend cannot run and ``fallback`` is off (or neither
            backend can run).
    """
    checks = {"warp": warp_available, "egl": egl_available}
    wanted = "warp" if config.backend == "auto" else config.backend
    other = "egl" if wanted == "warp" else "warp"
    why = checks[wanted]()
    if why is None:
        return wanted
    if config.backend != "auto" and not config.fallback:
        raise ConfigError(None, "views.backend", why)
    why_other = checks[other]()
    if why_other is not None:
        raise ConfigError(None, "views.backend", f"no rendering backend can run: {why}; {why_other}")
    if config.backend != "auto":
        warnings.warn(f"views.backend={config.backend!r} cannot run ({why}); rendering with {other!r}", stacklevel=2)
    return other


__all__ = ["BACKENDS", "DEFAULT_SIZE", "FORMATS", "MAX_SIZE", "MIN_SIZE", "ViewConfig", "egl_available", "resolve_backend", "warp_available"]
