"""Procedural houses: floor plans, doors, walls and furnished rooms.

:func:`generate_house` turns a seed and :class:`HouseParams` into a
:class:`~ignjax.scenes.model.Scene`; :func:`generate_houses` makes a set of
houses of varied sizes (:func:`house_plan` gives each house's seed, parameters
and id without generating it). Everything random comes from numpy generators derived
from the seed, so the same seed and parameters give equal scenes (``==``).

The work is split by idea: :mod:`~ignjax.scenes.procgen.params` (the
parameters and their checks), :mod:`~ignjax.scenes.procgen.layout` (floor
plan, doors, walls) and :mod:`~ignjax.scenes.procgen.furnish` (furniture and
distractors); this module puts them together and records what it did.

Scene metadata
    ``meta.source == "procgen"``, ``meta.seed`` the seed, and ``meta.params``
    a JSON document ``{"params": {...HouseParams fields...}, "n_rooms": n,
    "distractor_categories": [...]}``; :meth:`HouseParams.from_json` reads it
    back, so ``generate_house(meta.seed, HouseParams.from_json(meta.params),
    scene.id)`` rebuilds the scene.
"""

from __future__ import annotations

import dataclasses
import json
from typing import Any, Mapping

import numpy as np

from ignjax.errors import ConfigError
from ignjax.scenes import vocab
from ignjax.scenes.model import Room, Scene, SceneMeta
from ignjax.scenes.model.validation import validate_scene
from ignjax.scenes.procgen import catalogue as cat
from ignjax.scenes.procgen.catalogue import CategorySpec
from ignjax.scenes.procgen.furnish import furnish
from ignjax.scenes.procgen.layout import layout_rooms, make_doors, make_walls, room_program
from ignjax.scenes.procgen.params import HouseParams

__all__ = ["generate_house", "generate_houses", "house_info", "house_plan"]


def house_info(scene: Scene) -> dict[str, Any]:
    """What the generator recorded about a procedural house.

    Returns:
        ``{"params": HouseParams, "n_rooms": int, "distractor_categories":
        list[str]}``: the parameters, the number of rooms drawn and the
        categories that got a controlled number of instances.

    Raises:
        ConfigError: the scene was not made by :func:`generate_house`.
    """
    if scene.meta.source_format != "procgen":
        raise ConfigError(scene.meta.source, "meta.source_format",
                          f"not a procedural house (format {scene.meta.source_format!r})")
    d = json.loads(scene.meta.params)
    return {"params": HouseParams.from_dict(d), "n_rooms": int(d.get("n_rooms", len(scene.rooms))),
            "distractor_categories": list(d.get("distractor_categories", []))}


def _check_seed(seed: Any) -> int:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ConfigError(None, "seed", f"must be a non-negative integer, got {seed!r}")
    return int(seed)


def generate_house(seed: int, params: HouseParams = HouseParams(), scene_id: str | None = None, *,
                   catalogue: Mapping[str, CategorySpec] | None = None) -> Scene:
    """Generate one furnished house.

    Args:
        seed: non-negative integer; the same seed and parameters give an
            equal scene.
        params: generator parameters.
        scene_id: the scene's id; defaults to ``f"house_{seed}"``.
        catalogue: categories to place (name -> spec); defaults to
            :data:`ignjax.scenes.procgen.catalogue.CATALOGUE`. Pass your own mapping
            to furnish houses with custom categories.

    Returns:
        A validated :class:`~ignjax.scenes.model.Scene` (rooms ``room_0..``
        with the living room first, doors ``door_0..``, walls ``wall_0..``,
        instances ``{category}_{k}``).

    Raises:
        ConfigError: ``seed`` is not a non-negative integer or ``params`` is
            not a :class:`HouseParams`.
    """
    seed = _check_seed(seed)
    if not isinstance(params, HouseParams):
        raise ConfigError(None, "params", f"expected HouseParams, got {type(params).__name__}")
    catalogue = cat.CATALOGUE if catalogue is None else catalogue
    plan_ss, furnish_ss = np.random.SeedSequence(seed).spawn(2)
    rng = np.random.default_rng(plan_ss)
    n = params.n_rooms if params.n_rooms is not None else int(rng.integers(params.min_rooms, params.max_rooms + 1))
    labels = room_program(n, rng)
    rects = layout_rooms(labels, rng)
    ids = [f"room_{i}" for i in range(n)]
    seen: dict[str, int] = {}
    rooms = []
    for i, (lab, (x0, y0, x1, y1)) in enumerate(zip(labels, rects)):
        seen[lab] = seen.get(lab, 0) + 1
        name = vocab.ROOM_DISPLAY[lab].capitalize() + (f" {seen[lab]}" if seen[lab] > 1 else "")
        rooms.append(Room(ids[i], lab, ((x0, y0), (x1, y0), (x1, y1), (x0, y1)), name))
    doors = make_doors(rects, labels, ids, params, rng)
    walls = make_walls(rects, ids, doors, params)
    instances, multi = furnish(rooms, rects, doors, params, catalogue, np.random.default_rng(furnish_ss))
    meta = SceneMeta(source="procgen", source_format="procgen", up_axis="Z", meters_per_unit=1.0, seed=seed,
                     params=json.dumps({"params": params.to_dict(), "n_rooms": n, "distractor_categories": multi},
                                       sort_keys=True))
    scene = Scene(scene_id or f"house_{seed}", tuple(rooms), tuple(doors), tuple(walls), tuple(instances), meta,
                  wall_height=params.wall_height)
    return validate_scene(scene)


def generate_houses(count: int, seed: int, params: HouseParams = HouseParams(), *,
                    catalogue: Mapping[str, CategorySpec] | None = None) -> list[Scene]:
    """Generate ``count`` houses of varied sizes.

    When ``params.n_rooms`` is None the room counts are spread evenly over
    ``min_rooms..max_rooms`` (12 houses with the default 2..12 cover every
    size) in an order shuffled from ``seed``. House ``i`` is
    ``generate_house(s_i, params_i, f"house_{seed}_{i:03d}")`` where ``s_i``
    derives from ``(seed, i)`` and ``params_i`` fixes its ``n_rooms``.

    Args:
        count: number of houses (>= 0).
        seed: non-negative integer.
        params: generator parameters shared by all houses.
        catalogue: see :func:`generate_house`.

    Returns:
        The houses, in order.
    """
    return [generate_house(s_i, p_i, scene_id, catalogue=catalogue)
            for s_i, p_i, scene_id in house_plan(count, seed, params)]


def house_plan(count: int, seed: int, params: HouseParams = HouseParams()) -> list[tuple[int, HouseParams, str]]:
    """The ``(seed, params, scene_id)`` of each house :func:`generate_houses`
    makes, in order, without generating any: house ``i`` is
    ``generate_house(*plan[i])``, independent of the other houses, so the
    houses can be generated in any order or in separate processes.

    Raises:
        ConfigError: ``count`` or ``seed`` is not a non-negative integer.
    """
    seed = _check_seed(seed)
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 0:
        raise ConfigError(None, "count", f"must be a non-negative integer, got {count!r}")
    count = int(count)
    if params.n_rooms is not None:
        sizes = [params.n_rooms] * count
    else:
        sizes = [int(v) for v in np.round(np.linspace(params.min_rooms, params.max_rooms, count))] if count > 1 \
            else [int(np.random.default_rng([seed, 1]).integers(params.min_rooms, params.max_rooms + 1))] * count
        order = np.random.default_rng([seed, 0]).permutation(count)
        sizes = [sizes[k] for k in order]
    out = []
    for i in range(count):
        s_i = int(np.random.SeedSequence([seed, i]).generate_state(1, np.uint32)[0])
        out.append((s_i, dataclasses.replace(params, n_rooms=sizes[i]), f"house_{seed}_{i:03d}"))
    return out
