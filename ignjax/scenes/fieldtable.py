"""Goal fields held at their own scenes' extents, one after another in one flat array.

A bank pads every scene's grid to the largest rows and the largest columns
over its scenes, and a goal field stored at that padded shape is mostly
padding: the shipped benchmark's scenes fill 37 % of their shared
357 x 342 grid, so its 408 fields took 199 MB as an (F, H, W) stack where
their cells need 74 MB. A :class:`FieldTable` keeps each field at its scene's
own rows and columns, row-major, field after field, and answers a look-up
exactly as the padded stack did: the cell is clipped to the padded grid
(``0 .. H - 1``, ``0 .. W - 1``), and a cell past the field's own extent reads
+inf, the stack's padding. Every value read is the same float as before, so
rollouts are the same bytes.

The flat array is padded with +inf to a whole number of padded fields
(H x W cells): its length then moves in the same steps as the stack's field
count did, so a compiled rollout serves as many field sets as before, and a
table holds at most one padded field more than its cells. Indices are int32:
a table of more than 2^31 - 1 cells (8 GiB of fields) is refused; a run of
that size is cut into buckets of scenes (``--bank-mb``).
"""

from __future__ import annotations

import math
from typing import Sequence

import jax
import numpy as np

from ignjax.arrays import host_empty, pytree_dataclass, xp
from ignjax.errors import ConfigError

MAX_CELLS = 2**31 - 1
"""The most cells a table may hold (its look-ups index it with int32)."""


def padded_cells(extents: Sequence[tuple[int, int]], shape: tuple[int, int]) -> int:
    """Length of the flat array of fields of these own extents on a padded
    grid of ``shape``: their cells, rounded up to a whole number of padded
    fields (at least one, so an empty table still has a cell to gather from)."""
    H, W = (int(n) for n in shape)
    cells = sum(int(h) * int(w) for h, w in extents)
    return max(1, math.ceil(cells / (H * W))) * H * W


@pytree_dataclass(static=("shape",))
class FieldTable:
    """Geodesic fields of F targets, each at its own extent (module docstring).

    Attributes:
        values: (N,) float32 the fields' cells, field after field, row-major,
            then +inf to a whole number of padded fields (:func:`padded_cells`).
        start: (F,) int32 where each field's first cell is in ``values``.
        rows: (F,) int32 each field's own rows.
        cols: (F,) int32 each field's own columns.
        shape: (H, W) the padded grid the fields are read on (static).
    """

    values: jax.Array
    start: jax.Array
    rows: jax.Array
    cols: jax.Array
    shape: tuple[int, int]

    def __len__(self) -> int:
        return int(self.start.shape[0])

    @property
    def nbytes(self) -> int:
        return sum(int(np.dtype(a.dtype).itemsize) * math.prod(a.shape)
                   for a in (self.values, self.start, self.rows, self.cols))

    def at(self, field, row, col):
        """The value of field ``field`` at cell (``row``, ``col``), as the padded
        (F, H, W) stack reads it: the cell clipped to the padded grid, +inf
        past the field's own extent. ``row`` and ``col`` may be arrays of one
        shape; numpy in, numpy out (host checks), else jax.numpy (traced)."""
        np_ = xp(self.values, field, row, col)
        H, W = self.shape
        r = np_.clip(row, 0, H - 1)
        c = np_.clip(col, 0, W - 1)
        h, w = self.rows[field], self.cols[field]
        inside = (r < h) & (c < w)
        i = self.start[field] + np_.where(inside, r * w + c, 0)
        return np_.where(inside, self.values[i], np_.float32(np.inf))

    def field(self, f: int) -> np.ndarray:
        """Field ``f`` as an (H, W) numpy array on the padded grid (+inf padding)."""
        H, W = self.shape
        h, w, s = int(self.rows[f]), int(self.cols[f]), int(self.start[f])
        out = np.full((H, W), np.inf, np.float32)
        out[:h, :w] = np.asarray(self.values[s:s + h * w]).reshape(h, w)
        return out

    def dense(self) -> np.ndarray:
        """Every field as an (F, H, W) numpy stack on the padded grid (+inf padding)."""
        return np.stack([self.field(f) for f in range(len(self))]) if len(self) else \
            np.zeros((0,) + tuple(self.shape), np.float32)

    @staticmethod
    def layout(extents: Sequence[tuple[int, int]], shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray, int]:
        """(start (F,) int32, extents (F, 2) int32, length of ``values``) of fields of these own extents.

        Raises:
            ConfigError: an extent larger than ``shape``, or more cells than :data:`MAX_CELLS`.
        """
        ext = np.asarray(extents, np.int64).reshape(-1, 2)
        H, W = (int(n) for n in shape)
        if len(ext) and (ext.min() < 0 or ext[:, 0].max() > H or ext[:, 1].max() > W):
            raise ConfigError(None, "fields", f"a field's own extent must lie within the padded grid {H} x {W}, got "
                              f"{ext[:, 0].max()} x {ext[:, 1].max()}")
        n = padded_cells(ext, (H, W))
        if n > MAX_CELLS:
            raise ConfigError(None, "bank_mb", f"the goal fields of one bank would hold {n} cells, more than the "
                              f"{MAX_CELLS} int32 look-ups reach: cut the run into smaller buckets of scenes "
                              "(a lower --bank-mb / eval.bank_mb)")
        sizes = ext[:, 0] * ext[:, 1]
        start = (np.cumsum(sizes) - sizes).astype(np.int32)
        return start, ext.astype(np.int32), n

    @classmethod
    def of(cls, fields: Sequence[np.ndarray], shape: tuple[int, int]) -> "FieldTable":
        """A host table (numpy leaves) of fields given at their own extents."""
        start, ext, n = cls.layout([np.shape(f) for f in fields], shape)
        values = host_empty(n, np.float32)  # shared with CPU devices, not copied (ignjax.arrays.host_empty)
        end = int(start[-1]) + int(ext[-1, 0] * ext[-1, 1]) if len(fields) else 0
        values[end:] = np.inf
        for s, f in zip(start, fields):
            a = np.asarray(f, np.float32).reshape(-1)
            values[int(s):int(s) + a.size] = a
        return cls(values, start, ext[:, 0].copy(), ext[:, 1].copy(), (int(shape[0]), int(shape[1])))

    @classmethod
    def from_dense(cls, stack) -> "FieldTable":
        """A table of an (F, H, W) stack on the padded grid, each field at the
        whole padded extent (numpy or jax.numpy, as given): the same look-ups."""
        np_ = xp(stack)
        F, H, W = stack.shape
        if F * H * W > MAX_CELLS:
            raise ConfigError(None, "fields", f"{F} fields of {H} x {W} cells are more than the {MAX_CELLS} cells "
                              "int32 look-ups reach")
        start = np_.arange(F, dtype=np_.int32) * np_.int32(H * W)
        full = lambda n: np_.full((F,), n, np_.int32)  # noqa: E731
        values = stack.reshape(-1) if F else np_.full((H * W,), np.inf, np_.float32)
        return cls(values.astype(np_.float32), start, full(H), full(W), (int(H), int(W)))

    @classmethod
    def shapes(cls, extents: Sequence[tuple[int, int]], shape: tuple[int, int], sharding=None) -> "FieldTable":
        """The table of fields of these own extents as shapes only
        (:class:`jax.ShapeDtypeStruct` leaves with ``sharding``): what a program
        is compiled for before the fields are computed."""
        _, ext, n = cls.layout(extents, shape)
        sds = lambda m, dt: jax.ShapeDtypeStruct((m,), dt, sharding=sharding)  # noqa: E731
        F = len(ext)
        return cls(sds(n, np.float32), sds(F, np.int32), sds(F, np.int32), sds(F, np.int32),
                   (int(shape[0]), int(shape[1])))


__all__ = ["FieldTable", "MAX_CELLS", "padded_cells"]
