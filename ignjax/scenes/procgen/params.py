"""Parameters of procedural houses: :class:`HouseParams` (checked on
construction, read from and written to JSON) and the room-count limits
:data:`MIN_ROOMS` / :data:`MAX_ROOMS`.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from ignjax.errors import ConfigError

__all__ = ["HouseParams", "MIN_ROOMS", "MAX_ROOMS"]

MIN_ROOMS = 2
MAX_ROOMS = 12
"""Hard limits on the number of rooms of a procedural house."""


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
