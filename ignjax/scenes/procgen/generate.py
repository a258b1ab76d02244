"""Procedural houses: floor plans, doors, walls and furnished rooms.

:func:`generate_house` turns a seed and :class:`HouseParams` into a
:class:`~ignjax.scenes.model.Scene`; :func:`generate_houses` makes a set of
houses of varied sizes. Everything random comes from numpy generators derived
from the seed, so the same seed and parameters give equal scenes (``==``).

Floor plan
    Rooms are axis-aligned rectangles tiling a rectangular footprint. Houses
    of five or more rooms may have (six or more always have) a long, narrow
    hallway across the footprint with a band of rooms on each side (a
    "double-loaded corridor"); smaller houses are one or two bands of rooms.
    A band is a row of columns; a column holds one room, or two small rooms
    stacked (a closet behind a bathroom). Room areas are drawn per label
    (closets 2-4.5 m², bathrooms 3.5-7 m², living rooms 16-30 m², garages
    18-32 m²); the garage is the end column of a band (two exterior walls),
    the entryway a full-depth column (it touches the outside and the
    hallway). Coordinates are snapped to 5 cm, and the whole plan is mirrored
    or transposed at random. A house of four or more rooms always has a
    living room, a kitchen, a bedroom and a bathroom; a house of eleven or
    more has every one of the eleven goal labels.

Doors
    A spanning tree of the room adjacency graph (rooms sharing at least
    1.1 m of wall) chosen with label preferences (hallways connect, closets
    open onto bedrooms, garages onto hallways, entryways or kitchens), plus
    extra doors between non-private rooms with ``extra_door_prob`` (loops),
    plus one exterior door (entryway, else living room). Doors between
    open-plan rooms are sometimes wide openings (``kind="opening"``). Door
    widths are clipped to fit the shared wall.

Walls
    One :class:`~ignjax.scenes.model.Wall` box per stretch of boundary with
    the same rooms on its sides, centred on the boundary line, door gaps cut
    out and a lintel (``bottom=door_height``) above each gap. Room polygons
    are the boundary rectangles (wall centre lines); objects stay inside the
    inner faces.

Furniture (generic over :data:`ignjax.scenes.procgen.catalogue.CATALOGUE`)
    Per room, in this order: the room's defining furniture (its
    highest-weight floor categories in ``spec.rooms``, largest first: the
    bed of a bedroom, the toilet of a bathroom), the distractors planned for
    the room, a weighted draw of further floor categories up to
    ``furniture_density * area`` placed largest first (a category's weight
    decays each time it is drawn; rugs last), wall objects, then small
    objects on every support surface.

    ``floor_wall`` objects stand with their back (-x) against a wall;
    ``floor`` objects stand free (yaw a multiple of 90 degrees). A table (an
    object whose top is a surface at 0.6-1.1 m covering most of its
    footprint, with knee room below) may get a group of seats facing it
    (small ``floor`` categories whose geometry has a part named "seat", such
    as chairs), on all four sides of a free-standing table or in front of a
    desk against a wall. ``wall`` objects hang on a wall's inner face at
    ``spec.mount_height``, never over a door gap; ``on_support`` objects
    stand on a free spot of a surface of a category in ``spec.supports``,
    below any higher surface of the same support.

    Nothing stands within ``door_clearance`` of a door; floor objects keep
    ``passage_width`` between them (except within a group, side by side
    along one wall, or next to a flat object such as a rug, which the agent
    can walk over); and every placement is checked on a 10 cm raster of the
    room inflated by a clearance radius of 0.26 m (a 0.18 m agent plus the
    rounding of objects to the 5 cm cells of the navigation grid, so every
    passage this check accepts is also open on that grid): all door cells of the room
    stay connected, and every floor object stays within 0.8 m (wall objects
    1.2 m) of that connected free space. Objects that break this are
    dropped.

Distractors
    ``multi_categories`` target-eligible categories get a controlled number
    of instances (``instances_per_multi``): each extra instance goes into a
    room that already holds one with ``same_room_prob`` (else another room
    where the category belongs, when there is one) and copies the first
    instance's colour with ``similar_appearance_prob`` (else it gets a
    different colour when the category has one). These categories are left
    out of the random fill, so their counts and rooms are exactly the plan's
    (minus placements that did not fit). They are listed in the scene's
    metadata, see :func:`house_info`.

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
import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np
from scipy import ndimage

from ignjax.errors import ConfigError
from ignjax.scenes.procgen import catalogue as cat
from ignjax.scenes import vocab
from ignjax.scenes.procgen.catalogue import Built, CategorySpec
from ignjax.scenes.model import Attributes, Door, Instance, Room, Scene, SceneMeta, Wall, validate_scene

__all__ = ["HouseParams", "generate_house", "generate_houses", "house_info", "ROOM_AREAS", "MIN_ROOMS", "MAX_ROOMS"]

MIN_ROOMS = 2
MAX_ROOMS = 12
"""Hard limits on the number of rooms of a procedural house."""

ROOM_AREAS: Mapping[str, tuple[float, float]] = {
    "living_room": (16.0, 30.0),
    "kitchen": (8.0, 14.0),
    "dining_room": (10.0, 16.0),
    "bedroom": (9.0, 16.0),
    "bathroom": (3.5, 7.0),
    "office": (7.0, 11.0),
    "laundry_room": (3.5, 6.0),
    "entryway": (3.0, 6.0),
    "closet": (2.0, 4.5),
    "garage": (18.0, 32.0),
}
"""Floor area range (m²) drawn for each room label; hallways are sized by the plan."""

_GRID = 0.05  # plan coordinates are snapped to this, metres
_HALL_WIDTH = (1.2, 1.6)
_MIN_SIDE = 1.5  # smallest room side, metres
_DOOR_MARGIN = 0.2  # door edge to the end of a shared wall, metres
_MIN_DOOR = 0.7  # narrowest door when the shared wall is short, metres
_CELL = 0.1  # raster cell for the navigability check, metres
_AGENT_RADIUS = 0.26  # 0.18 m agent + rounding of objects to 5 cm navigation-grid cells
_REACH = 0.8  # every floor object within this distance of the room's free space
_REACH_WALL = 1.2  # every wall object (a painting may hang above a sofa)
_LOW_WALL_OBJECT = 1.0  # wall objects hung lower than this are obstacles
_FLAT = 0.05  # floor objects lower than this (rugs) can be walked over
_TABLE_HEIGHT = (0.6, 1.1)  # surfaces at this height get companions (seats)
_COMPANION_MAX_HALF = 0.35
_OPEN_PLAN = ("living_room", "dining_room", "kitchen", "hallway", "entryway")
_PRIVATE = ("bathroom", "closet")
_STACKABLE = ("closet", "bathroom", "laundry_room", "office")  # may share a column with another small room
_MIN_SIDE_BY_LABEL = {"hallway": _HALL_WIDTH[0], "bedroom": 2.4, "kitchen": 2.2, "dining_room": 2.6,
                      "living_room": 3.0, "garage": 3.0}
_HALL_PRIORITY = {"bathroom": 3, "laundry_room": 2, "closet": 0}  # others 1


# ---------------------------------------------------------------------------
# Parameters
# ---------------------------------------------------------------------------


def _bad(name: str, reason: str) -> ConfigError:
    return ConfigError(None, f"HouseParams.{name}", reason)


def _check_int(name: str, value: Any, lo: int, hi: int) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise _bad(name, f"must be an integer, got {value!r}")
    if not lo <= value <= hi:
        raise _bad(name, f"must be in [{lo}, {hi}], got {value}")


def _check_float(name: str, value: Any, lo: float, hi: float) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise _bad(name, f"must be a number, got {value!r}")
    if not (math.isfinite(float(value)) and lo <= float(value) <= hi):
        raise _bad(name, f"must be in [{lo}, {hi}], got {value}")


def _check_pair(name: str, value: Any, kind: str, lo: float, hi: float) -> tuple:
    if not isinstance(value, (tuple, list)) or len(value) != 2:
        raise _bad(name, f"must be a (min, max) pair, got {value!r}")
    for v in value:
        (_check_int if kind == "int" else _check_float)(name, v, lo, hi)
    if value[0] > value[1]:
        raise _bad(name, f"min must not exceed max, got {tuple(value)}")
    return tuple(int(v) if kind == "int" else float(v) for v in value)


@dataclass(frozen=True)
class HouseParams:
    """Static parameters of procedural houses (checked on construction).

    Attributes:
        n_rooms: number of rooms, 2..12; None draws it uniformly from
            ``min_rooms..max_rooms``.
        min_rooms: smallest number of rooms drawn when ``n_rooms`` is None (>= 2).
        max_rooms: largest number of rooms drawn when ``n_rooms`` is None (<= 12).
        wall_thickness: wall thickness, metres (0.02..0.4).
        wall_height: wall height, metres (2.0..5.0).
        door_width: clear door width, metres: a number or a (min, max) range
            drawn per door (0.6..2.0); clipped to fit short shared walls.
        door_height: clear door height, metres; the lintel above a door runs
            from here to ``wall_height``.
        extra_door_prob: probability of a door between two adjacent rooms
            that the spanning tree did not connect (loops); bathrooms,
            closets and implausible pairs (garage-bedroom) never get extra
            doors.
        exterior_door: whether the house gets a door to the outside.
        furniture_density: floor-standing objects per m² of free floor (the
            count per room is drawn around ``density * area``).
        max_floor_objects_per_room: cap on floor-standing objects per room
            (companions such as chairs at a table included).
        small_objects_per_surface: (min, max) small objects drawn per support
            surface (a table top, a bed); placed only where they fit.
        wall_objects_per_room: (min, max) wall-mounted objects drawn per room.
        multi_categories: how many target-eligible categories get several
            instances per house (controlled same-category distractors).
        instances_per_multi: (min, max) instances of each such category.
        same_room_prob: probability that each extra instance of such a
            category goes into a room that already holds one (else into
            another room where the category belongs, when there is one).
        similar_appearance_prob: probability that an extra instance copies
            the colour of the category's first instance (else it gets a
            different colour where the category allows one); harder to
            disambiguate by appearance.
        passage_width: minimum free gap between floor objects that are not
            in one group, metres (the agent must pass between them).
        door_clearance: depth in front of each door (on both sides) kept free
            of floor objects, metres.
    """

    n_rooms: int | None = None
    min_rooms: int = 2
    max_rooms: int = 12
    wall_thickness: float = 0.1
    wall_height: float = 2.5
    door_width: float | tuple[float, float] = 0.9
    door_height: float = 2.1
    extra_door_prob: float = 0.3
    exterior_door: bool = True
    furniture_density: float = 0.25
    max_floor_objects_per_room: int = 10
    small_objects_per_surface: tuple[int, int] = (1, 3)
    wall_objects_per_room: tuple[int, int] = (0, 2)
    multi_categories: int = 8
    instances_per_multi: tuple[int, int] = (4, 10)
    same_room_prob: float = 0.5
    similar_appearance_prob: float = 0.3
    passage_width: float = 0.6
    door_clearance: float = 1.0

    def __post_init__(self):
        if self.n_rooms is not None:
            _check_int("n_rooms", self.n_rooms, MIN_ROOMS, MAX_ROOMS)
        _check_int("min_rooms", self.min_rooms, MIN_ROOMS, MAX_ROOMS)
        _check_int("max_rooms", self.max_rooms, MIN_ROOMS, MAX_ROOMS)
        if self.min_rooms > self.max_rooms:
            raise _bad("min_rooms", f"must not exceed max_rooms ({self.max_rooms}), got {self.min_rooms}")
        _check_float("wall_thickness", self.wall_thickness, 0.02, 0.4)
        _check_float("wall_height", self.wall_height, 2.0, 5.0)
        if isinstance(self.door_width, (tuple, list)):
            object.__setattr__(self, "door_width", _check_pair("door_width", self.door_width, "float", 0.6, 2.0))
        else:
            _check_float("door_width", self.door_width, 0.6, 2.0)
        _check_float("door_height", self.door_height, 1.8, 4.9)
        if self.door_height > self.wall_height - 0.1:
            raise _bad("door_height", f"must be at least 0.1 m below wall_height ({self.wall_height}), got {self.door_height}")
        _check_float("extra_door_prob", self.extra_door_prob, 0.0, 1.0)
        if not isinstance(self.exterior_door, (bool, np.bool_)):
            raise _bad("exterior_door", f"must be true or false, got {self.exterior_door!r}")
        _check_float("furniture_density", self.furniture_density, 0.0, 2.0)
        _check_int("max_floor_objects_per_room", self.max_floor_objects_per_room, 0, 100)
        object.__setattr__(self, "small_objects_per_surface",
                           _check_pair("small_objects_per_surface", self.small_objects_per_surface, "int", 0, 20))
        object.__setattr__(self, "wall_objects_per_room",
                           _check_pair("wall_objects_per_room", self.wall_objects_per_room, "int", 0, 20))
        _check_int("multi_categories", self.multi_categories, 0, 50)
        object.__setattr__(self, "instances_per_multi",
                           _check_pair("instances_per_multi", self.instances_per_multi, "int", 2, 20))
        _check_float("same_room_prob", self.same_room_prob, 0.0, 1.0)
        _check_float("similar_appearance_prob", self.similar_appearance_prob, 0.0, 1.0)
        _check_float("passage_width", self.passage_width, 0.3, 2.0)
        _check_float("door_clearance", self.door_clearance, 0.3, 3.0)
        # plain Python numbers, so that the parameters serialise to JSON
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, (bool, np.bool_)):
                object.__setattr__(self, f.name, bool(v))
            elif isinstance(v, (int, np.integer)) and f.type in ("int", "int | None"):
                object.__setattr__(self, f.name, int(v))
            elif isinstance(v, (int, float, np.integer, np.floating)):
                object.__setattr__(self, f.name, float(v))

    @property
    def door_width_range(self) -> tuple[float, float]:
        """``door_width`` as a (min, max) range."""
        if isinstance(self.door_width, tuple):
            return self.door_width
        return (float(self.door_width), float(self.door_width))

    def to_dict(self) -> dict[str, Any]:
        """The fields as a JSON-ready dict (pairs become lists)."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in dataclasses.asdict(self).items()}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "HouseParams":
        """Inverse of :meth:`to_dict`; also accepts the scene metadata
        document (``{"params": {...}, ...}``). Unknown keys raise ConfigError."""
        if "params" in d and isinstance(d["params"], Mapping):
            d = d["params"]
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise ConfigError(None, f"HouseParams.{unknown[0]}", f"unknown parameter; known: {sorted(names)}")
        return cls(**{k: (tuple(v) if isinstance(v, list) else v) for k, v in d.items()})

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> "HouseParams":
        """Read parameters from :meth:`to_json` text or a procedural scene's ``meta.params``."""
        try:
            d = json.loads(text)
        except json.JSONDecodeError as e:
            raise ConfigError(None, "HouseParams", f"not valid JSON: {e}") from e
        if not isinstance(d, dict):
            raise ConfigError(None, "HouseParams", "expected a JSON object")
        return cls.from_dict(d)


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


# ---------------------------------------------------------------------------
# Floor plan
# ---------------------------------------------------------------------------


def _snap(v: float) -> float:
    return round(round(v / _GRID) * _GRID, 6)


def _weighted_pick(rng: np.random.Generator, items: Sequence, weights: Sequence[float]):
    w = np.asarray(weights, dtype=np.float64)
    total = w.sum()
    if len(items) == 0 or total <= 0:
        return None
    return items[int(rng.choice(len(items), p=w / total))]


def _room_program(n: int, rng: np.random.Generator) -> list[str]:
    """The room labels of an ``n``-room house, living room first."""
    if n == 2:
        return ["living_room", "bathroom"]
    if n == 3:
        return ["living_room", "bathroom", str(rng.choice(["kitchen", "bedroom"]))]
    labels = ["living_room", "kitchen", "bedroom", "bathroom"]
    extras_all = ["hallway", "entryway", "dining_room", "office", "closet", "laundry_room", "garage"]
    if n >= 4 + len(extras_all):
        labels += extras_all
        fill = ["bedroom", "bathroom", "closet", "bedroom"]
        labels += fill[: n - len(labels)]
        return labels
    if n >= 6 or (n == 5 and rng.random() < 0.5):
        labels.append("hallway")
    pool = ["entryway", "dining_room", "office", "closet", "laundry_room", "garage", "bedroom", "bathroom", "bedroom"]
    weights = [1.0, 1.0, 0.8, 0.8, 0.6, 0.6, 0.9, 0.5, 0.4]
    while len(labels) < n:
        k = int(rng.choice(len(pool), p=np.asarray(weights) / sum(weights)))
        labels.append(pool.pop(k))
        weights.pop(k)
    return labels


def _columns(rooms: list[int], labels: list[str], areas: dict[int, float], depth: float,
             rng: np.random.Generator) -> list[list[int]]:
    """Group a band's rooms into columns (one room, or two small rooms stacked)."""
    singles, smalls = [], []
    for i in rooms:
        narrow = areas[i] / depth < 2.0
        (smalls if narrow and labels[i] in _STACKABLE and depth >= 2 * _MIN_SIDE else singles).append(i)
    smalls.sort(key=lambda i: (areas[i], i))
    cols = [[i] for i in singles]
    for k in range(0, len(smalls) - 1, 2):
        a, b = smalls[k], smalls[k + 1]
        # the room that most needs the hallway faces it; closets go to the back
        pa, pb = _HALL_PRIORITY.get(labels[a], 1), _HALL_PRIORITY.get(labels[b], 1)
        if pb > pa or (pa == pb and rng.random() < 0.5):
            a, b = b, a
        cols.append([a, b])
    if len(smalls) % 2:
        cols.append([smalls[-1]])
    order = list(rng.permutation(len(cols)))
    cols = [cols[k] for k in order]
    for lead in ("garage",):
        for k, c in enumerate(cols):
            if labels[c[0]] == lead:
                cols.insert(0, cols.pop(k))
                break
    return cols


def _fit_widths(widths: np.ndarray, total: float, min_w: float) -> np.ndarray | None:
    """Scale column widths to sum to ``total`` keeping each at least ``min_w`` (None if impossible)."""
    if len(widths) * min_w > total:
        return None
    w = np.asarray(widths, dtype=np.float64)
    fixed = np.zeros(len(w), bool)
    for _ in range(len(w) + 1):
        free = ~fixed
        if not free.any():
            return np.full(len(w), total / len(w))
        scale = (total - min_w * fixed.sum()) / w[free].sum()
        out = np.where(fixed, min_w, w * scale)
        low = free & (out < min_w)
        if not low.any():
            return out
        fixed |= low
    return None  # pragma: no cover


def _try_layout(labels: list[str], rng: np.random.Generator) -> list[tuple[float, float, float, float]] | None:
    """One attempt at a plan: room rectangles (x0, y0, x1, y1) in label order, or None."""
    n = len(labels)
    areas = {i: float(rng.uniform(*ROOM_AREAS[lab])) for i, lab in enumerate(labels) if lab != "hallway"}
    hall = [i for i, lab in enumerate(labels) if lab == "hallway"]
    others = [i for i in range(n) if labels[i] != "hallway"]
    n_bands = 1 if (len(others) <= 2 and not hall) else 2
    bands: list[list[int]] = [[] for _ in range(n_bands)]
    band_area = [0.0] * n_bands
    rest = []
    for i in others:
        if labels[i] == "garage" and n_bands == 2:
            bands[1].append(i)
            band_area[1] += areas[i]
        elif labels[i] == "entryway":
            bands[0].append(i)
            band_area[0] += areas[i]
        else:
            rest.append(i)
    rest.sort(key=lambda i: (-areas[i], i))
    for i in rest:
        b = int(np.argmin(band_area)) if n_bands == 2 else 0
        if n_bands == 2 and band_area[0] == band_area[1]:
            b = int(rng.integers(2))
        bands[b].append(i)
        band_area[b] += areas[i]
    if any(not b for b in bands):
        return None
    d_target = float(rng.uniform(3.4, 5.0))
    width = sum(band_area) / (n_bands * d_target)
    hall_w = _snap(float(rng.uniform(*_HALL_WIDTH))) if hall else 0.0
    rects: dict[int, tuple[float, float, float, float]] = {}
    y = 0.0
    band_rows = []
    for b in range(n_bands):
        depth = float(np.clip(band_area[b] / width, 2.6, 6.5))
        cols = _columns(bands[b], labels, areas, depth, rng)
        widths = _fit_widths(np.array([sum(areas[i] for i in c) / depth for c in cols]), width, _MIN_SIDE + 0.1)
        if widths is None:
            return None
        band_rows.append((cols, widths, depth))
    total_w = _snap(width)
    for b, (cols, widths, depth) in enumerate(band_rows):
        depth = _snap(depth)
        y0, y1 = _snap(y), _snap(y + depth)
        xs = [0.0] + [_snap(v) for v in np.cumsum(widths)[:-1]] + [total_w]
        for k, col in enumerate(cols):
            x0, x1 = xs[k], xs[k + 1]
            if x1 - x0 < _MIN_SIDE - 1e-9:
                return None
            if len(col) == 1:
                rects[col[0]] = (x0, y0, x1, y1)
                continue
            a0, a1 = areas[col[0]], areas[col[1]]
            h_front = float(np.clip(depth * a0 / (a0 + a1), _MIN_SIDE, depth - _MIN_SIDE))
            # the first room of a column faces the hallway (or the other band)
            if b == 0:
                ym = _snap(y1 - h_front)
                rects[col[0]], rects[col[1]] = (x0, ym, x1, y1), (x0, y0, x1, ym)
            else:
                ym = _snap(y0 + h_front)
                rects[col[0]], rects[col[1]] = (x0, y0, x1, ym), (x0, ym, x1, y1)
        y = y1
        if b == 0 and hall:
            rects[hall[0]] = (0.0, y1, total_w, _snap(y1 + hall_w))
            y = _snap(y1 + hall_w)
    for i, r in rects.items():
        w, h = r[2] - r[0], r[3] - r[1]
        if min(w, h) < _MIN_SIDE_BY_LABEL.get(labels[i], _MIN_SIDE) - 1e-9:
            return None
        if labels[i] != "hallway" and max(w, h) / min(w, h) > 3.2:
            return None
    # a random symmetry of the rectangle: mirror x, mirror y, transpose
    X, Y = total_w, y
    flip_x, flip_y, swap = (bool(rng.random() < 0.5) for _ in range(3))
    out = []
    for i in range(n):
        x0, y0, x1, y1 = rects[i]
        if flip_x:
            x0, x1 = _snap(X - x1), _snap(X - x0)
        if flip_y:
            y0, y1 = _snap(Y - y1), _snap(Y - y0)
        if swap:
            x0, y0, x1, y1 = y0, x0, y1, x1
        out.append((x0, y0, x1, y1))
    return out


def _layout(labels: list[str], rng: np.random.Generator) -> list[tuple[float, float, float, float]]:
    for _ in range(200):
        rects = _try_layout(labels, rng)
        if rects is not None and _connected(_adjacent_pairs(rects), len(rects)):
            return rects
    raise RuntimeError(f"could not lay out a house with rooms {labels}")  # pragma: no cover


# ---------------------------------------------------------------------------
# Doors and walls
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class _Shared:
    a: int
    b: int
    axis: str  # "v": the line x = c; "h": the line y = c
    c: float
    lo: float
    hi: float


def _adjacent_pairs(rects) -> list[_Shared]:
    out = []
    min_len = _MIN_DOOR + 2 * _DOOR_MARGIN
    for i in range(len(rects)):
        for j in range(i + 1, len(rects)):
            a, b = rects[i], rects[j]
            for axis, (a_lo, a_hi, b_lo, b_hi, a_s0, a_s1, b_s0, b_s1) in (
                ("v", (a[0], a[2], b[0], b[2], a[1], a[3], b[1], b[3])),
                ("h", (a[1], a[3], b[1], b[3], a[0], a[2], b[0], b[2])),
            ):
                for c_a, c_b in ((a_hi, b_lo), (a_lo, b_hi)):
                    if abs(c_a - c_b) < 1e-6:
                        lo, hi = max(a_s0, b_s0), min(a_s1, b_s1)
                        if hi - lo >= min_len - 1e-9:
                            out.append(_Shared(i, j, axis, c_a, lo, hi))
    return out


def _connected(edges: list[_Shared], n: int) -> bool:
    parent = list(range(n))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for e in edges:
        parent[find(e.a)] = find(e.b)
    return len({find(i) for i in range(n)}) == 1


def _edge_cost(la: str, lb: str) -> float:
    pair = {la, lb}
    if "hallway" in pair:
        return 0.0 if not pair & {"garage"} else 0.3
    if "closet" in pair:
        return 0.1 if pair & {"bedroom", "entryway"} else 1.5
    if "bathroom" in pair:
        return 0.3 if pair & {"bedroom", "entryway"} else (2.5 if pair & {"kitchen", "dining_room", "garage"} else 1.8)
    if "garage" in pair:
        return 0.4 if pair & {"entryway", "laundry_room", "kitchen"} else 2.5
    if pair <= set(_OPEN_PLAN):
        return 0.2
    return 1.0


def _door_centre(rng: np.random.Generator, lo: float, hi: float, w: float) -> float:
    """Centre of a door of width ``w`` on the wall stretch lo..hi, clear of its ends."""
    a, b = lo + _DOOR_MARGIN + w / 2, hi - _DOOR_MARGIN - w / 2
    if b <= a:
        return 0.5 * (lo + hi)
    u = float(rng.random())
    if u < 0.75:  # most doors sit near a corner, leaving the walls free for furniture
        jitter = float(rng.uniform(0.0, min(0.3, b - a)))
        s = a + jitter if u < 0.375 else b - jitter
    else:
        s = float(rng.uniform(a, b))
    s = _snap(s)
    return min(max(s, a), b)


def _make_doors(rects, labels, ids, params: HouseParams, rng: np.random.Generator) -> list[Door]:
    edges = _adjacent_pairs(rects)
    cost = [_edge_cost(labels[e.a], labels[e.b]) + float(rng.random()) for e in edges]
    parent = list(range(len(rects)))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    chosen: list[_Shared] = []
    for k in sorted(range(len(edges)), key=lambda k: (cost[k], k)):
        e = edges[k]
        ra, rb = find(e.a), find(e.b)
        if ra != rb:
            parent[ra] = rb
            chosen.append(e)
    tree = set(chosen)
    for e in edges:
        if e in tree:
            continue
        if labels[e.a] in _PRIVATE or labels[e.b] in _PRIVATE or _edge_cost(labels[e.a], labels[e.b]) > 1.0:
            continue
        if rng.random() < params.extra_door_prob:
            chosen.append(e)
    chosen.sort(key=lambda e: (e.a, e.b))
    lo_w, hi_w = params.door_width_range
    doors = []
    for e in chosen:
        avail = e.hi - e.lo - 2 * _DOOR_MARGIN
        open_plan = labels[e.a] in _OPEN_PLAN and labels[e.b] in _OPEN_PLAN and "hallway" not in (labels[e.a], labels[e.b])
        kind = "opening" if open_plan and rng.random() < 0.5 else "door"
        w = float(rng.uniform(max(lo_w, 1.2), max(hi_w, 1.8))) if kind == "opening" else float(rng.uniform(lo_w, hi_w))
        w = math.floor(min(w, avail) * 1000) / 1000
        s = _door_centre(rng, e.lo, e.hi, w)
        pos = (e.c, s) if e.axis == "v" else (s, e.c)
        yaw = math.pi / 2 if e.axis == "v" else 0.0
        doors.append(Door(f"door_{len(doors)}", pos, w, yaw, (ids[e.a], ids[e.b]), params.door_height, kind))
    if params.exterior_door:
        X = max(r[2] for r in rects)
        Y = max(r[3] for r in rects)
        for want in ("entryway", "living_room", None):
            cands = [i for i, lab in enumerate(labels) if want is None or lab == want]
            sides = []
            for i in cands:
                x0, y0, x1, y1 = rects[i]
                for axis, c, lo, hi, on_edge in (("h", y0, x0, x1, y0 == 0.0), ("h", y1, x0, x1, abs(y1 - Y) < 1e-6),
                                                 ("v", x0, y0, y1, x0 == 0.0), ("v", x1, y0, y1, abs(x1 - X) < 1e-6)):
                    if on_edge and hi - lo >= _MIN_DOOR + 2 * _DOOR_MARGIN:
                        sides.append((hi - lo, i, axis, c, lo, hi))
            if sides:
                sides.sort(key=lambda t: (-t[0], t[1]))
                _, i, axis, c, lo, hi = sides[0]
                w = math.floor(min(float(rng.uniform(lo_w, hi_w)), hi - lo - 2 * _DOOR_MARGIN) * 1000) / 1000
                s = _door_centre(rng, lo, hi, w)
                pos = (c, s) if axis == "v" else (s, c)
                doors.append(Door(f"door_{len(doors)}", pos, w, math.pi / 2 if axis == "v" else 0.0,
                                  (ids[i], None), params.door_height, "door"))
                break
    return doors


def _make_walls(rects, ids, doors: list[Door], params: HouseParams) -> list[Wall]:
    """Wall boxes along every room boundary, each stretch once, door gaps cut, lintels above."""
    lines: dict[tuple[str, float], list[tuple[float, float, str]]] = {}
    for i, (x0, y0, x1, y1) in enumerate(rects):
        for key, lo, hi in ((("h", y0), x0, x1), (("h", y1), x0, x1), (("v", x0), y0, y1), (("v", x1), y0, y1)):
            lines.setdefault((key[0], round(key[1], 6)), []).append((lo, hi, ids[i]))
    gaps: dict[tuple[str, float], list[tuple[float, float]]] = {}
    for d in doors:
        vertical = abs(math.sin(d.yaw)) > 0.5
        key = ("v", round(d.position[0], 6)) if vertical else ("h", round(d.position[1], 6))
        s = d.position[1] if vertical else d.position[0]
        gaps.setdefault(key, []).append((s - d.width / 2, s + d.width / 2))
    t, H, hd = params.wall_thickness, params.wall_height, params.door_height
    order = {rid: k for k, rid in enumerate(ids)}
    walls: list[Wall] = []
    for key in sorted(lines):
        axis, c = key
        segs = lines[key]
        gl = gaps.get(key, [])
        pts = sorted({round(v, 6) for lo, hi, _ in segs for v in (lo, hi)} | {round(v, 6) for g in gl for v in g})
        pieces = []  # [lo, hi, rooms, in_gap]
        for p, q in zip(pts[:-1], pts[1:]):
            if q - p < 1e-9:
                continue
            m = 0.5 * (p + q)
            rooms = tuple(sorted({rid for lo, hi, rid in segs if lo < m < hi}, key=order.get))
            if not rooms:
                continue
            in_gap = any(g0 < m < g1 for g0, g1 in gl)
            if pieces and pieces[-1][3] == in_gap and pieces[-1][2] == rooms and abs(pieces[-1][1] - p) < 1e-9:
                pieces[-1][1] = q
            else:
                pieces.append([p, q, rooms, in_gap])
        for k, (lo, hi, rooms, in_gap) in enumerate(pieces):
            if in_gap:
                bottom, height = hd, H - hd
            else:
                bottom, height = 0.0, H
                # close the corners: extend ends that no other piece continues
                if k == 0 or abs(pieces[k - 1][1] - lo) > 1e-9:
                    lo -= t / 2
                if k == len(pieces) - 1 or abs(pieces[k + 1][0] - hi) > 1e-9:
                    hi += t / 2
            start, end = ((c, lo), (c, hi)) if axis == "v" else ((lo, c), (hi, c))
            walls.append(Wall(f"wall_{len(walls)}", start, end, t, height, bottom, rooms))
    return walls


# ---------------------------------------------------------------------------
# Furniture
# ---------------------------------------------------------------------------

_SIDES = {  # inward normal, yaw of an object whose back is on that wall
    "S": ((0.0, 1.0), math.pi / 2),
    "N": ((0.0, -1.0), -math.pi / 2),
    "W": ((1.0, 0.0), 0.0),
    "E": ((-1.0, 0.0), math.pi),
}


def _aabb(cx: float, cy: float, yaw: float, hx: float, hy: float) -> tuple[float, float, float, float]:
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    ex, ey = hx * c + hy * s, hx * s + hy * c
    return (cx - ex, cy - ey, cx + ex, cy + ey)


def _aabb_dist(a, b) -> float:
    dx = max(0.0, a[0] - b[2], b[0] - a[2])
    dy = max(0.0, a[1] - b[3], b[1] - a[3])
    return math.hypot(dx, dy)


def _overlap(a, b) -> bool:
    return a[0] < b[2] - 1e-9 and b[0] < a[2] - 1e-9 and a[1] < b[3] - 1e-9 and b[1] < a[3] - 1e-9


@dataclass
class _Item:
    inst: Instance
    built: Built
    spec: CategorySpec
    aabb: tuple[float, float, float, float]
    z0: float
    z1: float
    level: str  # "floor" (stands on the floor), "wall", "support"
    side: str | None = None
    group: int | None = None
    reach: np.ndarray | None = None


@dataclass
class _DoorRef:
    side: str
    a0: float  # along-wall interval of the opening
    a1: float


class _RoomCtx:
    """A room being furnished: its geometry, doors, raster and placed items."""

    def __init__(self, room: Room, rect, doors: list[Door], params: HouseParams):
        self.room = room
        self.id, self.label = room.id, room.label
        t2 = params.wall_thickness / 2
        x0, y0, x1, y1 = rect
        self.inner = (x0 + t2, y0 + t2, x1 - t2, y1 - t2)
        self.area = (self.inner[2] - self.inner[0]) * (self.inner[3] - self.inner[1])
        self.params = params
        self.doors: list[_DoorRef] = []
        for d in doors:
            if room.id not in d.rooms:
                continue
            vertical = abs(math.sin(d.yaw)) > 0.5
            if vertical:
                side = "W" if abs(d.position[0] - x0) < 1e-6 else "E"
                s = d.position[1]
            else:
                side = "S" if abs(d.position[1] - y0) < 1e-6 else "N"
                s = d.position[0]
            self.doors.append(_DoorRef(side, s - d.width / 2, s + d.width / 2))
        self.keepouts = [self._band(dr.side, dr.a0 - 0.15, dr.a1 + 0.15, 0.0, params.door_clearance) for dr in self.doors]
        self.items: list[_Item] = []
        # raster of cell centres over the inner rectangle
        ix0, iy0, ix1, iy1 = self.inner
        nx = max(1, int(math.floor((ix1 - ix0) / _CELL)))
        ny = max(1, int(math.floor((iy1 - iy0) / _CELL)))
        xs = ix0 + (np.arange(nx) + 0.5) * (ix1 - ix0) / nx
        ys = iy0 + (np.arange(ny) + 0.5) * (iy1 - iy0) / ny
        self.X, self.Y = np.meshgrid(xs, ys)  # Shape: (ny, nx)
        r = _AGENT_RADIUS
        self.blocked = (self.X - ix0 < r) | (ix1 - self.X < r) | (self.Y - iy0 < r) | (iy1 - self.Y < r)
        self.door_cells = []
        for dr in self.doors:
            band = self._band(dr.side, dr.a0 + r, dr.a1 - r, r + 0.01, r + 0.31)
            if band[2] <= band[0] or band[3] <= band[1]:
                mid = 0.5 * (dr.a0 + dr.a1)
                band = self._band(dr.side, mid - _CELL, mid + _CELL, r + 0.01, r + 0.31)
            mask = (self.X >= band[0]) & (self.X <= band[2]) & (self.Y >= band[1]) & (self.Y <= band[3])
            self.door_cells.append(mask)

    def _band(self, side: str, a0: float, a1: float, d0: float, d1: float):
        """AABB of the strip along ``side`` from along-coordinate a0..a1, depth d0..d1 from the inner face."""
        ix0, iy0, ix1, iy1 = self.inner
        if side == "S":
            return (a0, iy0 + d0, a1, iy0 + d1)
        if side == "N":
            return (a0, iy1 - d1, a1, iy1 - d0)
        if side == "W":
            return (ix0 + d0, a0, ix0 + d1, a1)
        return (ix1 - d1, a0, ix1 - d0, a1)

    def side_range(self, side: str) -> tuple[float, float]:
        ix0, iy0, ix1, iy1 = self.inner
        return (ix0, ix1) if side in ("S", "N") else (iy0, iy1)

    def near(self, aabb, d: float) -> np.ndarray:
        """Cells whose centre is closer than ``d`` to the box."""
        dx = np.maximum(np.maximum(aabb[0] - self.X, self.X - aabb[2]), 0.0)
        dy = np.maximum(np.maximum(aabb[1] - self.Y, self.Y - aabb[3]), 0.0)
        return dx * dx + dy * dy < d * d

    def inside(self, aabb) -> bool:
        ix0, iy0, ix1, iy1 = self.inner
        e = 1e-6
        return aabb[0] >= ix0 - e and aabb[1] >= iy0 - e and aabb[2] <= ix1 + e and aabb[3] <= iy1 + e

    @staticmethod
    def obstacle(item: "_Item") -> bool:
        """Whether the agent cannot walk through the item (flat rugs and high wall objects it can)."""
        if item.level == "floor":
            return item.z1 - item.z0 >= _FLAT
        return item.level == "wall" and item.z0 < _LOW_WALL_OBJECT

    def nav_ok(self, cand: _Item) -> np.ndarray | None:
        """The blocked mask with ``cand`` added when the room stays navigable, else None."""
        blocked = self.blocked
        if self.obstacle(cand):
            blocked = blocked | self.near(cand.aabb, _AGENT_RADIUS)
        labels, _ = ndimage.label(~blocked)
        common = None
        for mask in self.door_cells:
            ls = set(np.unique(labels[mask]).tolist()) - {0}
            common = ls if common is None else common & ls
            if not common:
                return None
        main = np.isin(labels, sorted(common)) if common else labels > 0
        for it in self.items + [cand]:
            if it.level == "support":
                continue
            if it.reach is None:
                it.reach = self.near(it.aabb, _REACH if it.level == "floor" else _REACH_WALL)
            if not np.any(main & it.reach):
                return None
        return blocked


class _Furnisher:
    """Places catalogue objects in the rooms of one house."""

    def __init__(self, params: HouseParams, catalogue: Mapping[str, CategorySpec], rng: np.random.Generator):
        self.params = params
        self.cat = catalogue
        self.rng = rng
        self.counts: dict[str, int] = {}
        self.instances: list[Instance] = []
        self.exclude: set[str] = set()
        self.next_group = 0
        self._probes: dict[str, Built] = {}

    # -- helpers ------------------------------------------------------------
    def probe(self, spec: CategorySpec) -> Built:
        """A medium-sized build of ``spec`` (cached; does not touch the house's generator)."""
        if spec.name not in self._probes:
            self._probes[spec.name] = spec.build(Attributes(size="medium"), np.random.default_rng(0))
        return self._probes[spec.name]

    def _new_id(self, category: str) -> str:
        k = self.counts.get(category, 0)
        self.counts[category] = k + 1
        return f"{category}_{k}"

    def _commit(self, ctx: _RoomCtx, item: _Item, blocked: np.ndarray | None) -> _Item:
        iid = self._new_id(item.inst.category)
        item.inst = dataclasses.replace(item.inst, id=iid, name=iid)
        if blocked is not None:
            ctx.blocked = blocked
        ctx.items.append(item)
        self.instances.append(item.inst)
        return item

    def _make(self, spec: CategorySpec, attrs: Attributes, built: Built, ctx: _RoomCtx, x: float, y: float, z: float,
              yaw: float, level: str, side=None, group=None, support: str | None = None) -> _Item:
        inst = cat.instantiate("pending", spec.name, attrs, built, (x, y, z), yaw, ctx.id, support)
        hx, hy, hz = built.half_extents
        return _Item(inst, built, spec, _aabb(x, y, yaw, hx, hy), z, z + 2 * hz, level, side, group)

    def _gap(self, a: _Item, b: _Item) -> float:
        if a.group is not None and a.group == b.group:
            return 0.03
        if a.z1 - a.z0 < _FLAT or b.z1 - b.z0 < _FLAT:  # one can walk over a rug
            return 0.05
        if a.side is not None and a.side == b.side and a.spec.placement == b.spec.placement == "floor_wall":
            return 0.03
        return self.params.passage_width

    def _floor_fits(self, ctx: _RoomCtx, cand: _Item) -> bool:
        if not ctx.inside(cand.aabb):
            return False
        if cand.z1 > self.params.wall_height - 0.02:
            return False
        if any(_overlap(cand.aabb, k) for k in ctx.keepouts):
            return False
        for it in ctx.items:
            if it.level == "floor":
                if _aabb_dist(cand.aabb, it.aabb) < self._gap(cand, it) - 1e-9:
                    return False
            elif it.level == "wall":
                if _aabb_dist(cand.aabb, it.aabb) < 0.02 and cand.z0 < it.z1 and it.z0 < cand.z1:
                    return False
        return True

    def _wall_fits(self, ctx: _RoomCtx, cand: _Item) -> bool:
        if not ctx.inside(cand.aabb) or cand.z1 > self.params.wall_height - 0.02:
            return False
        for it in ctx.items:
            if it.level == "wall" and _aabb_dist(cand.aabb, it.aabb) < 0.1:
                return False
            if it.level == "floor" and _aabb_dist(cand.aabb, it.aabb) < 0.02 and cand.z0 < it.z1 and it.z0 < cand.z1:
                return False
        if cand.z0 < _LOW_WALL_OBJECT and any(_overlap(cand.aabb, k) for k in ctx.keepouts):
            return False
        return True

    def _pick_side(self, ctx: _RoomCtx) -> str:
        sides = list(_SIDES)
        lengths = [ctx.side_range(s)[1] - ctx.side_range(s)[0] for s in sides]
        return _weighted_pick(self.rng, sides, lengths)

    # -- placements -----------------------------------------------------------
    def place_floor_level(self, ctx: _RoomCtx, spec: CategorySpec, attrs: Attributes, built: Built,
                          tries: int = 25, group: int | None = None) -> _Item | None:
        """Place a ``floor``, ``floor_wall`` or ``wall`` object somewhere in the room."""
        hx, hy, hz = built.half_extents
        rng = self.rng
        for _ in range(tries):
            if spec.placement in ("floor_wall", "wall"):
                side = self._pick_side(ctx)
                lo, hi = ctx.side_range(side)
                if hi - lo < 2 * hy:
                    continue
                s = float(rng.uniform(lo + hy, hi - hy))
                (nx, ny), yaw = _SIDES[side]
                ix0, iy0, ix1, iy1 = ctx.inner
                face = {"S": (s, iy0), "N": (s, iy1), "W": (ix0, s), "E": (ix1, s)}[side]
                x, y = face[0] + nx * hx, face[1] + ny * hx
                if spec.placement == "wall":
                    if any(s + hy > dr.a0 - 0.1 and s - hy < dr.a1 + 0.1 for dr in ctx.doors if dr.side == side):
                        continue
                    cand = self._make(spec, attrs, built, ctx, x, y, float(spec.mount_height), yaw, "wall", side)
                    if not self._wall_fits(ctx, cand):
                        continue
                else:
                    cand = self._make(spec, attrs, built, ctx, x, y, 0.0, yaw, "floor", side, group)
                    if not self._floor_fits(ctx, cand):
                        continue
            else:
                yaw = (float(rng.integers(4)) - 1.0) * math.pi / 2
                ex, ey = (hx, hy) if abs(math.cos(yaw)) > 0.5 else (hy, hx)
                ix0, iy0, ix1, iy1 = ctx.inner
                x = y = None
                for margin in (self.params.passage_width, 0.1):
                    xl, xh = ix0 + ex + margin, ix1 - ex - margin
                    yl, yh = iy0 + ey + margin, iy1 - ey - margin
                    if xh >= xl and yh >= yl:
                        x, y = float(rng.uniform(xl, xh)), float(rng.uniform(yl, yh))
                        break
                if x is None:
                    continue
                cand = self._make(spec, attrs, built, ctx, x, y, 0.0, yaw, "floor", None, group)
                if not self._floor_fits(ctx, cand):
                    continue
            blocked = ctx.nav_ok(cand)
            if blocked is None:
                continue
            return self._commit(ctx, cand, blocked)
        return None

    def place_on_support(self, ctx: _RoomCtx, spec: CategorySpec, attrs: Attributes, built: Built,
                         supports: list[_Item], tries: int = 12) -> _Item | None:
        """Place a small object on a free spot of one of ``supports``' surfaces."""
        hx, hy, hz = built.half_extents
        rng = self.rng
        options = []
        for sup in supports:
            for k, (h, corners) in enumerate(cat.surfaces_world(sup.inst, sup.built)):
                options.append((sup, k, h, corners))
        if not options:
            return None
        for _ in range(tries):
            sup, k, h, corners = options[int(rng.integers(len(options)))]
            if 2 * hz > sup.built.surfaces[k].clearance - 0.01:  # no room under the next shelf board
                continue
            q = int(rng.integers(4)) if sup.spec.placement == "floor" else (0 if rng.random() < 0.6 else int(rng.integers(4)))
            yaw = math.atan2(math.sin(sup.inst.yaw + q * math.pi / 2), math.cos(sup.inst.yaw + q * math.pi / 2))
            ex, ey = (hx, hy) if abs(math.cos(yaw)) > 0.5 else (hy, hx)
            sx0, sy0 = corners.min(0)
            sx1, sy1 = corners.max(0)
            if sx1 - sx0 < 2 * ex or sy1 - sy0 < 2 * ey:
                continue
            x = float(rng.uniform(sx0 + ex, sx1 - ex))
            y = float(rng.uniform(sy0 + ey, sy1 - ey))
            cand = self._make(spec, attrs, built, ctx, x, y, float(h), yaw, "support", support=sup.inst.id)
            if not ctx.inside(cand.aabb) or cand.z1 > self.params.wall_height - 0.02:
                continue
            ok = True
            for it in ctx.items:
                if it.level == "support" and it.inst.support == sup.inst.id and abs(it.z0 - h) < 1e-6:
                    if _aabb_dist(cand.aabb, it.aabb) < 0.02:
                        ok = False
                        break
            if not ok:
                continue
            # room above: other surfaces of the same support over this spot
            for h2, c2 in cat.surfaces_world(sup.inst, sup.built):
                if h2 > h + 1e-6 and _overlap(cand.aabb, (*c2.min(0), *c2.max(0))) and cand.z1 > h2 - 0.01:
                    ok = False
                    break
            if not ok:
                continue
            return self._commit(ctx, cand, None)
        return None

    def is_seat(self, spec: CategorySpec) -> bool:
        """A small free-standing category whose geometry has a part named "seat"."""
        if spec.placement != "floor":
            return False
        b = self.probe(spec)
        return (max(b.half_extents[:2]) <= _COMPANION_MAX_HALF and 2 * b.half_extents[2] <= 1.3
                and any("seat" in g.part for g in b.geoms))

    @staticmethod
    def has_table_surface(built: Built) -> bool:
        """A table or desk: its top is a surface at table height covering most of
        the footprint, with knee room below (parts fill little of the volume
        under the top, unlike a cabinet or a washing machine)."""
        hx, hy, hz = built.half_extents
        for surf in built.surfaces:
            h = surf.height
            if not (_TABLE_HEIGHT[0] <= h <= _TABLE_HEIGHT[1]) or 2 * hz > h + 0.05:
                continue
            if surf.half_extents[0] * surf.half_extents[1] < 0.5 * hx * hy:
                continue
            if _fill_below(built, h - 0.05) <= 0.4:
                return True
        return False

    def place_companions(self, ctx: _RoomCtx, table: _Item, budget: int,
                         pending: list[tuple[CategorySpec, Attributes]] | None = None) -> int:
        """Seats facing a table-height support; returns how many were placed.

        With ``pending`` (required seats of this room: (spec, attributes)),
        those are placed first and removed from the list as they are placed;
        otherwise up to ``budget`` seats of one category allowed in the room
        (one sampled set of attributes: a matching set).
        """
        if table.level != "floor" or not self.has_table_surface(table.built):
            return 0
        queue: list[tuple[CategorySpec, Attributes]] = []
        if pending:
            queue = list(pending)
        else:
            if budget <= 0:
                return 0
            cands, weights = [], []
            for name, spec in self.cat.items():
                w = float(spec.rooms.get(ctx.label, 0.0))
                if w > 0 and name not in self.exclude and self.is_seat(spec):
                    cands.append(spec)
                    weights.append(w * w)
            spec = _weighted_pick(self.rng, cands, weights)
            if spec is None or self.rng.random() < 0.15:
                return 0
            attrs = spec.sample_attributes(self.rng)
            queue = [(spec, attrs)] * budget
        if table.group is None:
            table.group = self.next_group
            self.next_group += 1
        tx, ty = table.inst.position[:2]
        thx, thy, _ = table.built.half_extents
        c, s = math.cos(table.inst.yaw), math.sin(table.inst.yaw)
        # sides in the table frame: (outward normal, half length of side, half depth to side)
        sides = [((1.0, 0.0), thy, thx)]
        if table.spec.placement == "floor":
            sides += [((-1.0, 0.0), thy, thx), ((0.0, 1.0), thx, thy), ((0.0, -1.0), thx, thy)]
        placed = 0
        built_cache: dict[int, Built] = {}
        for (nx, ny), half_len, half_depth in sides:
            for k in range(2):
                if not queue:
                    return placed
                spec, attrs = queue[0]
                key = id(attrs)
                if key not in built_cache:
                    built_cache[key] = spec.build(attrs, self.rng)
                built = built_cache[key]
                hx, hy, _ = built.half_extents
                n_slots = int(min(2, (2 * half_len + 0.1) // (2 * hy + 0.15)))
                if k >= n_slots:
                    break
                off = 0.0 if n_slots == 1 else (k - 0.5) * half_len
                lx = nx * (half_depth + 0.05 + hx) - ny * off
                ly = ny * (half_depth + 0.05 + hx) + nx * off
                wx, wy = tx + c * lx - s * ly, ty + s * lx + c * ly
                # facing the table: the seat's +x points against the side's outward normal
                onx, ony = c * nx - s * ny, s * nx + c * ny
                yaw = round(math.atan2(-ony, -onx) / (math.pi / 2)) * (math.pi / 2)
                yaw = math.atan2(math.sin(yaw), math.cos(yaw))
                cand = self._make(spec, attrs, built, ctx, wx, wy, 0.0, yaw, "floor", None, table.group)
                if not self._floor_fits(ctx, cand):
                    continue
                blocked = ctx.nav_ok(cand)
                if blocked is None:
                    continue
                self._commit(ctx, cand, blocked)
                placed += 1
                done = queue.pop(0)
                if pending is not None and done in pending:
                    pending.remove(done)
        return placed

    def attributes_like(self, spec: CategorySpec, first: Attributes | None) -> Attributes:
        """Attributes of an extra instance of a distractor category."""
        attrs = spec.sample_attributes(self.rng)
        if first is None or first.color is None:
            return attrs
        if self.rng.random() < self.params.similar_appearance_prob:
            return dataclasses.replace(attrs, color=first.color)
        others = [c for c in spec.colors if c != first.color]
        if others:
            return dataclasses.replace(attrs, color=str(self.rng.choice(others)))
        return attrs


def _fill_below(built: Built, height: float) -> float:
    """Fraction of the box footprint x ``height`` that the parts fill below ``height``
    (parts approximated by their axis-aligned extents in the builder frame)."""
    hx, hy, _ = built.half_extents
    vol = 0.0
    for g in built.geoms:
        if g.kind == "box":
            ex, area = g.size, 4 * g.size[0] * g.size[1]
        elif g.kind in ("cylinder", "capsule"):
            r = g.size[0]
            ex, area = (r, r, g.size[1] + (r if g.kind == "capsule" else 0.0)), math.pi * r * r
        elif g.kind == "sphere":
            ex, area = (g.size[0],) * 3, math.pi * g.size[0] ** 2
        elif g.kind == "ellipsoid":
            ex, area = g.size, math.pi * g.size[0] * g.size[1]
        else:
            continue
        z0, z1 = g.pos[2] - ex[2], g.pos[2] + ex[2]
        vol += area * max(0.0, min(z1, height) - max(z0, 0.0))
    return vol / max(4 * hx * hy * height, 1e-9)


def _eligible(spec: CategorySpec, label: str, catalogue: Mapping[str, CategorySpec]) -> bool:
    if spec.rooms.get(label, 0.0) <= 0:
        return False
    if spec.placement != "on_support":
        return True
    return any(s in catalogue and catalogue[s].placement != "on_support" and catalogue[s].rooms.get(label, 0.0) > 0
               for s in spec.supports)


def _furnish(rooms: list[Room], rects, doors: list[Door], params: HouseParams,
             catalogue: Mapping[str, CategorySpec], rng: np.random.Generator) -> tuple[list[Instance], list[str]]:
    f = _Furnisher(params, catalogue, rng)
    ctxs = [_RoomCtx(r, rect, doors, params) for r, rect in zip(rooms, rects)]

    # -- distractor plan --------------------------------------------------------
    cands, weights = [], []
    for name, spec in catalogue.items():
        if not vocab.is_target_eligible(name):
            continue
        n_el = sum(_eligible(spec, c.label, catalogue) for c in ctxs)
        if n_el == 0:
            continue
        b = f.probe(spec)
        foot = 4 * b.half_extents[0] * b.half_extents[1]
        cands.append(name)
        weights.append(min(n_el, params.instances_per_multi[1]) / (0.3 + foot))
    multi: list[str] = []
    while len(multi) < params.multi_categories and cands:
        name = _weighted_pick(rng, cands, weights)
        k = cands.index(name)
        cands.pop(k)
        weights.pop(k)
        multi.append(name)
    f.exclude = set(multi)
    required: dict[int, list[tuple[CategorySpec, Attributes]]] = {k: [] for k in range(len(ctxs))}
    first_attrs: dict[str, Attributes] = {}
    for name in multi:
        spec = catalogue[name]
        el = [k for k, c in enumerate(ctxs) if _eligible(spec, c.label, catalogue)]
        w = [spec.rooms.get(ctxs[k].label, 0.0) for k in el]
        m = int(rng.integers(params.instances_per_multi[0], params.instances_per_multi[1] + 1))
        used = [_weighted_pick(rng, el, w)]
        for _ in range(m - 1):
            others = [k for k in el if k not in used]
            if rng.random() < params.same_room_prob or not others:
                used.append(used[int(rng.integers(len(used)))])
            else:
                used.append(_weighted_pick(rng, others, [spec.rooms.get(ctxs[k].label, 0.0) for k in others]))
        for j, k in enumerate(used):
            attrs = spec.sample_attributes(rng) if j == 0 else f.attributes_like(spec, first_attrs[name])
            if j == 0:
                first_attrs[name] = attrs
            required[k].append((spec, attrs))

    for k, ctx in enumerate(ctxs):
        _furnish_room(f, ctx, required[k])
    placed = {inst.category for inst in f.instances}
    return f.instances, [m for m in multi if m in placed]  # a planned category that found no room is not reported


def _furnish_room(f: _Furnisher, ctx: _RoomCtx, req: list[tuple[CategorySpec, Attributes]]) -> None:
    """Furnish one room: its defining furniture, the distractors planned for it,
    a weighted random fill, wall objects, then small objects on surfaces.

    ``target`` (from ``furniture_density``) counts the room's own furniture;
    the distractors planned for the room come on top of it.
    """
    params, catalogue, rng, label = f.params, f.cat, f.rng, ctx.label
    floor_specs = [sp for sp in catalogue.values()
                   if sp.placement in ("floor", "floor_wall") and sp.name not in f.exclude and sp.rooms.get(label, 0.0) > 0]
    wall_specs = [sp for sp in catalogue.values() if sp.placement == "wall" and sp.name not in f.exclude]
    small_specs = [sp for sp in catalogue.values() if sp.placement == "on_support" and sp.name not in f.exclude]
    target = int(round(params.furniture_density * ctx.area * float(rng.uniform(0.8, 1.2))))
    target = min(target, params.max_floor_objects_per_room)
    n_fill = 0

    def area(sp: CategorySpec) -> float:
        b = f.probe(sp)
        return b.half_extents[0] * b.half_extents[1]

    def place(sp: CategorySpec, attrs: Attributes | None = None, tries: int = 25) -> _Item | None:
        attrs = sp.sample_attributes(rng) if attrs is None else attrs
        return f.place_floor_level(ctx, sp, attrs, sp.build(attrs, rng), tries=tries)

    # 1. the room's defining furniture: its highest-weight categories, largest first
    anchors: list[CategorySpec] = []
    if floor_specs and target > 0:
        top = max(sp.rooms[label] for sp in floor_specs)
        anchors = sorted((sp for sp in floor_specs if sp.rooms[label] >= top - 1e-9), key=lambda sp: -area(sp))
        for sp in anchors[:target]:
            if place(sp, tries=40) is not None:
                n_fill += 1

    # 2. distractors planned for this room; seats go around a table when the room can have one
    seats = [(sp, a) for sp, a in req if f.is_seat(sp)]
    for sp, attrs in req:
        if sp.placement != "on_support" and not f.is_seat(sp):
            place(sp, attrs, tries=40)
    if seats:
        tables = [it for it in ctx.items if it.level == "floor" and f.has_table_surface(it.built)]
        if not tables:
            opts = [sp for sp in floor_specs if f.has_table_surface(f.probe(sp))]
            sp = _weighted_pick(rng, opts, [o.rooms[label] for o in opts])
            item = place(sp, tries=40) if sp is not None else None
            tables = [item] if item is not None else []
        for table in tables:
            f.place_companions(ctx, table, 0, seats)
        for sp, attrs in seats:
            place(sp, attrs, tries=40)
    for sp in [sp for sp, _ in req if sp.placement == "on_support"]:
        if any(it.inst.category in sp.supports and it.built.surfaces for it in ctx.items):
            continue
        sups = [catalogue[n] for n in sp.supports if n in catalogue and catalogue[n].placement != "on_support"]
        for sup in sorted(sups, key=lambda o: -o.rooms.get(label, 0.0)):
            if sup.rooms.get(label, 0.0) > 0 and place(sup, tries=40) is not None:
                break

    # 3. seats for the tables so far, then a weighted draw placed largest first (rugs last)
    for table in [it for it in ctx.items if it.level == "floor" and f.has_table_surface(it.built)]:
        n_fill += f.place_companions(ctx, table, max(target - n_fill, 0) + 2)
    if floor_specs and n_fill < target:
        used = {sp.name: 1 for sp in anchors}
        drawn = []
        for _ in range(2 * (target - n_fill) + 2):
            w = [sp.rooms[label] * 0.35 ** used.get(sp.name, 0) * 0.8 ** f.counts.get(sp.name, 0) for sp in floor_specs]
            sp = _weighted_pick(rng, floor_specs, w)
            drawn.append(sp)
            used[sp.name] = used.get(sp.name, 0) + 1
        for sp in sorted(drawn, key=lambda o: (2 * f.probe(o).half_extents[2] < _FLAT, -area(o))):
            if n_fill >= target:
                break
            item = place(sp)
            if item is not None:
                n_fill += 1 + f.place_companions(ctx, item, target - n_fill + 1)

    # 4. wall objects
    n_wall = int(rng.integers(params.wall_objects_per_room[0], params.wall_objects_per_room[1] + 1))
    used = {}
    placed = 0
    for _ in range(2 * n_wall + 2):
        if placed >= n_wall:
            break
        sp = _weighted_pick(rng, wall_specs, [o.rooms.get(label, 0.0) * 0.5 ** used.get(o.name, 0) for o in wall_specs])
        if sp is None:
            break
        used[sp.name] = used.get(sp.name, 0) + 1
        placed += place(sp) is not None

    # 5. small distractors, then small objects on every support surface
    for sp, attrs in req:
        if sp.placement == "on_support":
            sups = [it for it in ctx.items if it.level != "support" and it.built.surfaces and it.inst.category in sp.supports]
            f.place_on_support(ctx, sp, attrs, sp.build(attrs, rng), sups, tries=30)
    lo, hi = params.small_objects_per_surface
    for sup in [it for it in ctx.items if it.level != "support" and it.built.surfaces]:
        opts = [o for o in small_specs if sup.inst.category in o.supports and o.rooms.get(label, 0.0) > 0]
        for _surf in sup.built.surfaces:
            for _ in range(int(rng.integers(lo, hi + 1))):
                sp = _weighted_pick(rng, opts, [o.rooms[label] for o in opts])
                if sp is None:
                    break
                attrs = sp.sample_attributes(rng)
                f.place_on_support(ctx, sp, attrs, sp.build(attrs, rng), [sup])


# ---------------------------------------------------------------------------
# Entry points
# ---------------------------------------------------------------------------


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
    labels = _room_program(n, rng)
    rects = _layout(labels, rng)
    ids = [f"room_{i}" for i in range(n)]
    seen: dict[str, int] = {}
    rooms = []
    for i, (lab, (x0, y0, x1, y1)) in enumerate(zip(labels, rects)):
        seen[lab] = seen.get(lab, 0) + 1
        name = vocab.ROOM_DISPLAY[lab].capitalize() + (f" {seen[lab]}" if seen[lab] > 1 else "")
        rooms.append(Room(ids[i], lab, ((x0, y0), (x1, y0), (x1, y1), (x0, y1)), name))
    doors = _make_doors(rects, labels, ids, params, rng)
    walls = _make_walls(rects, ids, doors, params)
    instances, multi = _furnish(rooms, rects, doors, params, catalogue, np.random.default_rng(furnish_ss))
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
        p_i = dataclasses.replace(params, n_rooms=sizes[i])
        out.append(generate_house(s_i, p_i, f"house_{seed}_{i:03d}", catalogue=catalogue))
    return out
