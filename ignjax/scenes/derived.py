"""A scene's derived arrays, kept in the on-disk cache between runs.

Building a navigation grid (voxelization, clearance, ray segments) and the
geodesic field to a target takes seconds per scene; both are pure functions
of the scene, the settings and the code. :func:`cached_navgrid` and
:func:`cached_goal_fields` return what :func:`~ignjax.scenes.navgrid.build_navgrid`
and :func:`~ignjax.scenes.geodesic.goal_fields` return, read from
:func:`ignjax.cache.derived_store` when an entry for the same inputs is
there and computed (then stored) when not, so the arrays are the same bytes
whether the cache was cold, warm or off.

Keys: the scene's lossless JSON (:func:`~ignjax.scenes.model.scenejson.scene_to_json`)
without its id and metadata,
the compile options, the grid configuration (the field adds the instance,
its room and the seed radius) and :func:`ignjax.cache.code_digest` of the
modules that compute them.
"""

from __future__ import annotations

import dataclasses
import weakref

import numpy as np

from ignjax.cache import code_digest, derived_store, digest
from ignjax.scenes.geodesic import goal_fields
from ignjax.scenes.model import SceneMeta
from ignjax.scenes.model.scenejson import scene_to_json
from ignjax.scenes.navgrid import GridConfig, NavGrid, build_navgrid

# ignjax.scenes.model is a package: its digest covers every module in it (elements, polygons, ...)
_GRID_CODE = ("ignjax.scenes.model", "ignjax.scenes.vocab", "ignjax.scenes.compile", "ignjax.scenes.voxels",
              "ignjax.scenes.navgrid")
_FIELD_CODE = _GRID_CODE + ("ignjax.scenes.geodesic",)
_SCALARS = ("n_slices", "n_components", "n_approx")
_ARRAYS = tuple(f.name for f in dataclasses.fields(NavGrid)
                if f.name not in _SCALARS + ("scene_id", "config", "shape", "room_ids"))


_SCENE_KEYS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def scene_key(compiled) -> str:
    """Digest of a compiled scene's source: its lossless JSON without its id
    and metadata (where it was read from; a copy under another name or path
    has the same arrays) and the compile options. Kept per compiled scene
    (its grid and its fields both ask; a scene's JSON takes milliseconds)."""
    key = _SCENE_KEYS.get(compiled)
    if key is None:
        key = _SCENE_KEYS[compiled] = digest(
            scene_to_json(dataclasses.replace(compiled.scene, id="", meta=SceneMeta())), compiled.options)
    return key


def cached_navgrid(compiled, config: GridConfig = GridConfig()) -> NavGrid:
    """:func:`~ignjax.scenes.navgrid.build_navgrid`, through the cache."""
    store = derived_store()
    if store is None:
        return build_navgrid(compiled, config)
    key = digest(code_digest(*_GRID_CODE), scene_key(compiled), config)
    got = store.get("navgrid", key)
    if got is not None:
        return NavGrid(scene_id=compiled.scene.id, config=config, shape=tuple(int(n) for n in got["shape"]),
                       room_ids=tuple(r.id for r in compiled.scene.rooms),
                       **{n: int(got[n]) for n in _SCALARS}, **{n: got[n] for n in _ARRAYS})
    grid = build_navgrid(compiled, config)
    store.put("navgrid", key, {"shape": np.asarray(grid.shape, np.int64),
                               **{n: np.int64(getattr(grid, n)) for n in _SCALARS},
                               **{n: getattr(grid, n) for n in _ARRAYS}})
    return grid


def cached_goal_fields(compiled, grid: NavGrid, instances: list[int], room_indices: list[int],
                       seed_radius: float, batch: int, shape: tuple[int, int] | None = None) -> list[np.ndarray]:
    """The (H, W) float32 geodesic field to each of ``instances`` (indices
    into the scene's instances; ``room_indices`` their rooms in
    ``grid.room_ids``) on ``grid``, through the cache. Missing fields are
    computed :func:`~ignjax.scenes.geodesic.goal_fields` ``batch`` at a time
    (a short batch padded by repeating its last target, so one program
    serves every batch of a grid shape; ``shape``: the padded grid it runs
    on, see :func:`~ignjax.scenes.geodesic.goal_fields`)."""
    store = derived_store()
    keys = [None] * len(instances)
    out: list[np.ndarray | None] = [None] * len(instances)
    if store is not None:
        base = digest(code_digest(*_FIELD_CODE), scene_key(compiled), grid.config, float(seed_radius))
        for k, (i, r) in enumerate(zip(instances, room_indices)):
            keys[k] = digest(base, int(i), int(r))
            got = store.get("goal_field", keys[k])
            out[k] = None if got is None else got["field"]
    todo = [k for k, f in enumerate(out) if f is None]
    boxes = compiled.scene.instances
    for c in range(0, len(todo), batch):
        chunk = todo[c:c + batch]
        padded = chunk + [chunk[-1]] * (batch - len(chunk))
        fields = goal_fields(grid, [boxes[instances[k]].bbox for k in padded], [int(room_indices[k]) for k in padded],
                             seed_radius, shape)
        for j, k in enumerate(chunk):
            out[k] = fields[j]
            if store is not None:
                store.put("goal_field", keys[k], {"field": fields[j]})
    return out


__all__ = ["cached_goal_fields", "cached_navgrid", "scene_key"]
