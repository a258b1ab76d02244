"""Small helpers shared by the study modules: input checks and figures."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ignjax.errors import InputError


def as_array(x, name: str, *, ndim: int | tuple[int, ...] | None = None, last: int | None = None,
             dtype=None, finite: bool = False) -> np.ndarray:
    """``np.asarray(x)`` with shape checks that raise :class:`InputError`
    naming ``name``."""
    try:
        a = np.asarray(x) if dtype is None else np.asarray(x, dtype=dtype)
    except (TypeError, ValueError) as e:
        raise InputError(None, name, f"must be a numeric array: {e}") from e
    if ndim is not None:
        allowed = (ndim,) if isinstance(ndim, int) else tuple(ndim)
        if a.ndim not in allowed:
            raise InputError(None, name, f"must have {' or '.join(map(str, allowed))} dimensions, got shape {a.shape}")
    if last is not None and (a.ndim == 0 or a.shape[-1] != last):
        raise InputError(None, name, f"last axis must have size {last}, got shape {a.shape}")
    if finite and a.dtype.kind in "fc" and not np.all(np.isfinite(a)):
        raise InputError(None, name, "contains NaN or infinite values")
    return a


def class_counts(cls: np.ndarray, difficulty: np.ndarray, n_classes: int = 4):
    """``(known, counts, counts_by_difficulty)`` of per-question class codes
    (-1: unknown): which codes are known, each class's count, and the (3,
    n_classes) counts per difficulty bin (questions of an unknown bin, -1,
    left out there)."""
    known = cls >= 0
    counts = np.bincount(cls[known], minlength=n_classes)
    by_d = np.zeros((3, n_classes), np.int64)
    kd = known & (difficulty >= 0)
    np.add.at(by_d, (difficulty[kd], cls[kd]), 1)
    return known, counts, by_d


def new_figure(nrows: int = 1, ncols: int = 1, size=(6.0, 4.0)):
    """A matplotlib figure (Agg canvas, no pyplot state) and its axes array
    (matplotlib is imported here: the studies' arithmetic runs without it)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size)
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False)
    return fig, axes


def save(fig, path: str | os.PathLike, dpi: int = 120) -> Path:
    """Write ``fig`` as PNG atomically (temporary name, then rename)."""
    from ignjax.scenes.viz.mapplot import save_figure

    fig.tight_layout()
    return save_figure(fig, path, dpi=dpi)
