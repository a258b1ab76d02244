"""Procedural houses: seeded floor plans, doors, walls and furnished rooms.

* :mod:`~ignjax.scenes.procgen.generate`: :func:`generate_house`,
  :func:`generate_houses`, :func:`house_info` (the entry points).
* :mod:`~ignjax.scenes.procgen.params`: :class:`HouseParams` and its checks.
* :mod:`~ignjax.scenes.procgen.layout`: room program, rectangle layout,
  adjacency, doors and walls.
* :mod:`~ignjax.scenes.procgen.furnish`: :func:`furnish`, each room furnished
  in order (its docstring gives the rules).
* :mod:`~ignjax.scenes.procgen.roomspace`: the room being furnished, box
  geometry and the navigability check.
* :mod:`~ignjax.scenes.procgen.placement`: the placement rules (the furnisher).
* :mod:`~ignjax.scenes.procgen.companions`: tables and the seats facing them.
* :mod:`~ignjax.scenes.procgen.distractors`: the per-house distractor plan.
* :mod:`~ignjax.scenes.procgen.catalogue`: the object categories and their
  builders.
"""

from ignjax.scenes.procgen.generate import generate_house, generate_houses, house_info
from ignjax.scenes.procgen.layout import ROOM_AREAS
from ignjax.scenes.procgen.params import MAX_ROOMS, MIN_ROOMS, HouseParams

__all__ = ["HouseParams", "generate_house", "generate_houses", "house_info", "ROOM_AREAS", "MIN_ROOMS", "MAX_ROOMS"]
