"""Rendered observations end to end: the ``render`` block of the bench record.

A *panel* is everything one image-based decision needs: all N views of one
episode (RGB, depth, segmentation), the Planner panel composed, the
Grounder image of the front view with its grid, and both encoded (JPEG).
Both backends render the same B random navigable poses of the first scene
of the benchmark's bank in the same run, after one untimed warm-up call
(contexts and compilation), with one render process per CPU core
(``ViewConfig.workers``, recorded as ``workers``; ``one_process`` gives the
smallest size rendered in this process, for the scaling); ``panels_per_s`` = B / seconds of one timed
call, ``ms_per_decision`` its inverse in milliseconds. A backend that
cannot run here is reported as ``null`` with the reason under ``skipped``.
``depth_agreement``: share of pixels where both backends see a surface
whose z-depths differ by < 2 cm; ``segmentation_agreement``: share of
pixels with the same instance (both at the largest size measured).
"""

from __future__ import annotations

import time

import numpy as np

from ignjax.bench.timing import log
from ignjax.sim.types import SimConfig
from ignjax.sim.views import ViewConfig, ViewRenderer
from ignjax.sim.views.config import egl_available, warp_available
from ignjax.sim.views.encode import encode_images


def _decision(r: ViewRenderer, poses: np.ndarray):
    views = r.render(np.zeros(len(poses), int), poses)
    panels = r.panels(views)
    grounder = r.grounder_images(views, np.zeros(len(poses), int))
    encode_images(panels, "jpeg")
    encode_images(grounder, "jpeg")
    return views


def _timed(bank, sim, cfg, poses):
    """One untimed warm-up decision, then one timed: (views, seconds)."""
    with ViewRenderer(bank, sim, cfg) as r:
        _decision(r, poses)
        t0 = time.perf_counter()
        views = _decision(r, poses)
        return views, time.perf_counter() - t0


def bench_render(bank, quick: bool) -> dict:
    """The ``render`` block (module docstring)."""
    B = 16 if quick else 32
    workers = ViewConfig(workers=0).worker_count()
    sizes = (224, 128) if quick else (448, 224, 128)
    rng = np.random.default_rng(0)
    free = bank.navgrids[0].navigable_points()
    xy = free[rng.choice(len(free), B, replace=len(free) < B)]
    poses = np.concatenate([xy, rng.uniform(-np.pi, np.pi, (B, 1))], 1).astype(np.float32)
    sim = SimConfig()
    out = {"views": sim.n_views, "batch": B, "workers": workers, "scene": bank.scene_ids[0], "panels_per_s": {},
           "ms_per_decision": {}, "skipped": {}, "one_process": {}}
    kept = {}
    for backend, why in (("warp", warp_available()), ("egl", egl_available())):
        for size in sizes:
            key = f"{backend}@{size}"
            if why:
                out["panels_per_s"][key] = out["ms_per_decision"][key] = None
                out["skipped"][backend] = why
                continue
            cfg = ViewConfig(size=size, backend=backend, fallback=False, worlds=B, workers=workers)
            views, dt = _timed(bank, sim, cfg, poses)
            out["panels_per_s"][key] = B / dt
            out["ms_per_decision"][key] = 1000.0 * dt / B
            log(f"  {key}: {B / dt:.2f} panels/s ({1000.0 * dt / B:.0f} ms a decision, {workers} workers)")
            if workers > 1 and size == sizes[-1]:
                _, dt1 = _timed(bank, sim, cfg.replace(workers=1), poses)
                out["one_process"][key] = B / dt1
                log(f"  {key} in one process: {B / dt1:.2f} panels/s")
            if size == sizes[0]:
                kept[backend] = views
    if len(kept) == 2:
        a, b = kept["warp"], kept["egl"]
        both = np.isfinite(a.depth) & np.isfinite(b.depth)
        out["depth_agreement"] = float(np.mean(np.abs(a.depth[both] - b.depth[both]) < 0.02))
        out["segmentation_agreement"] = float(np.mean(a.instance == b.instance))
        w, e = out["panels_per_s"], sizes[0]
        out["warp_over_egl"] = {str(s): w[f"warp@{s}"] / w[f"egl@{s}"] for s in sizes}
        log(f"  agreement: depth {out['depth_agreement']:.4f}, segmentation {out['segmentation_agreement']:.4f}; "
            f"warp/EGL at {e} px {out['warp_over_egl'][str(e)]:.1f}x")
    else:
        out["depth_agreement"] = out["segmentation_agreement"] = None
    return out


__all__ = ["bench_render"]
