"""Scenes grouped into buckets of similar size, so no scene is padded to a far larger one.

A :class:`~ignjax.scenes.bank.SceneBank` pads every per-scene table to the
maxima over the scenes it holds. For the dozen scenes of a small benchmark
that costs little; for hundreds of procedural or ProcTHOR houses, whose grids
differ several-fold in area, one bank would hold every scene at the size of
the largest (7.5 GB for 262 houses). :func:`plan_buckets` cuts the scenes
into buckets whose padded tables fit a byte budget, each of scenes of
similar size so it pads only to neighbours;
evaluation then builds one bucket's bank at a time
(:mod:`ignjax.episodes.dataset`, :class:`~ignjax.episodes.dataset.BenchmarkScenes`).

:func:`padded_bytes` is the estimate the plan uses: the bytes of the tables
that grow with a scene's grid (the ray caster's voxel and segment tables,
primitives, the navigation grid tables, the simulator's occupancy columns
packed from the voxels), ``per_cell`` more bytes per
navigation cell for what the caller derives from the grid (the simulator's
probe maps), and each scene's goal fields of 4 bytes a cell of the scene's
own grid (:class:`~ignjax.scenes.fieldtable.FieldTable`). The small
per-instance, room and door tables are left out (a few kB a scene).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ignjax.errors import ConfigError
from ignjax.scenes.fieldtable import padded_cells
from ignjax.scenes.navgrid import NavGrid
from ignjax.scenes.raygrid import column_words, ray_grid_arrays

GRID_TABLE_BYTES = 9
"""Bytes a navigation cell takes in the bank's grid table: navigable (1), room (4), component (4)."""


def _table_shapes(grid: NavGrid) -> dict[str, tuple[tuple[int, ...], int]]:
    """name -> (shape, item size) of one scene's arrays that the bank pads and stacks, and of the
    occupancy columns the simulator's world packs from its voxels (:func:`~ignjax.scenes.raygrid.occupied_columns`)."""
    out = {k: (np.shape(v), np.asarray(v).itemsize) for k, v in ray_grid_arrays(grid).items()}
    out["grid"] = (tuple(grid.shape), GRID_TABLE_BYTES)
    Z, H, W = out["voxcode"][0]
    out["columns"] = ((H, W, column_words(Z)), 4)
    return out


def _padded(shapes: Sequence[dict], fields: Sequence[int], per_cell: int) -> int:
    """:func:`padded_bytes` from the scenes' :func:`_table_shapes` and their goal-field counts."""
    if not shapes:
        return 0
    total = 0
    for name, (_, size) in shapes[0].items():
        top = [max(d) for d in zip(*[s[name][0] for s in shapes])]
        total += len(shapes) * int(np.prod(top, dtype=np.int64)) * size
    h, w = (max(d) for d in zip(*[s["grid"][0] for s in shapes]))
    extents = [s["grid"][0] for s, n in zip(shapes, fields) for _ in range(int(n))]
    field_bytes = 4 * padded_cells(extents, (h, w)) + 12 * len(extents) if extents else 0
    return int(total + h * w * len(shapes) * per_cell + field_bytes)


def _per_scene(fields, n: int) -> list[int]:
    return [int(fields)] * n if np.ndim(fields) == 0 else [int(f) for f in fields]


def padded_bytes(grids: Sequence[NavGrid], fields: int | Sequence[int] = 0, per_cell: int = 0) -> int:
    """Estimated bytes of a bank of ``grids`` padded to their maxima (module docstring).

    Args:
        grids: the scenes' navigation grids.
        fields: goal fields (one per distinct target) each scene brings, held
            beside the bank at the scene's own extent
            (:class:`~ignjax.scenes.fieldtable.FieldTable`); one number: that
            many for every scene.
        per_cell: further bytes per navigation cell of each scene (padded).
    """
    return _padded([_table_shapes(g) for g in grids], _per_scene(fields, len(grids)), per_cell)


BUCKET_COST = 0.1
"""What a bucket more costs in :func:`plan_buckets`, as a share of the budget
(each bucket compiles its own programs)."""


def plan_buckets(grids: Sequence[NavGrid], budget_bytes: float, fields: Sequence[int] | None = None,
                 per_cell: int = 0) -> list[list[int]]:
    """Cut scenes into buckets whose :func:`padded_bytes` fit ``budget_bytes``.

    When every scene fits in one bucket the plan is that one bucket, in the
    given order, so a small benchmark runs exactly as one bank. Otherwise
    the scenes are ordered by grid rows, then columns (then the given order),
    and cut into runs of that order that minimise the buckets' padded bytes
    plus :data:`BUCKET_COST` x budget per bucket (dynamic programming over
    the cut points; the order keeps each bucket's rows close, the cost its
    columns). A scene over the budget on its own gets a bucket of its own.
    On 262 procedural houses (grids of 92-421 x 97-418 cells) and a 1 GiB
    budget this gives 7 buckets whose scene tables sum to 1.5x the scenes'
    own, against 3.9x for one bank.

    Args:
        grids: the scenes' navigation grids.
        budget_bytes: the most one bucket's tables (and fields) may take.
        fields: goal fields each scene brings (default none).
        per_cell: as in :func:`padded_bytes`.

    Returns:
        Buckets of scene indices (positions in ``grids``), each in increasing
        order; the buckets from the fewest grid rows up.

    Raises:
        ConfigError: a budget that is not a positive number.
    """
    if not budget_bytes > 0:
        raise ConfigError(None, "budget", f"a bucket's byte budget must be positive, got {budget_bytes}")
    n = len(grids)
    fields = [0] * n if fields is None else _per_scene(fields, n)
    shapes = [_table_shapes(g) for g in grids]
    if _padded(shapes, fields, per_cell) <= budget_bytes:
        return [list(range(n))] if n else []
    order = sorted(range(n), key=lambda i: (grids[i].shape[0], grids[i].shape[1], i))
    # best[j]: the least cost of cutting order[:j]; cut[j]: where its last bucket starts
    best = [0.0] + [float("inf")] * n
    cut = [0] * (n + 1)
    for j in range(1, n + 1):
        for i in range(j - 1, -1, -1):
            run = order[i:j]
            size = _padded([shapes[k] for k in run], [fields[k] for k in run], per_cell)
            if size > budget_bytes and len(run) > 1:
                break  # longer runs only grow
            cost = best[i] + size + BUCKET_COST * budget_bytes
            if cost < best[j]:
                best[j], cut[j] = cost, i
    buckets = []
    j = n
    while j > 0:
        buckets.append(sorted(order[cut[j]:j]))
        j = cut[j]
    return buckets[::-1]


__all__ = ["BUCKET_COST", "GRID_TABLE_BYTES", "padded_bytes", "plan_buckets"]
