"""Scenes as compact map data for the page's SVG maps.

The page draws each scene once per episode panel from this data (rooms,
walls, doors, instance footprints), in world coordinates (metres, y up; the
script flips y). Coordinates are rounded to 1 cm, which is finer than any
line the map draws and keeps the data small and the bytes stable. The
colours are those of :mod:`ignjax.scenes.viz.mapplot`, so the page and the
matplotlib maps (the sweep's figures, the GIF export) look alike.
"""

from __future__ import annotations

import math

from matplotlib.colors import to_hex

from ignjax.scenes import vocab
from ignjax.scenes.model import Instance, Scene
from ignjax.scenes.viz.mapplot import ROOM_COLORS, category_color

SKIPPED_STRUCTURAL = ("floor", "ceiling", "room")
"""Structural instances that are not drawn (the rooms' fills stand for them)."""


def r2(v: float) -> float:
    """A coordinate rounded to 1 cm (``-0.0`` made ``0.0``, so equal values print alike)."""
    return round(float(v), 2) + 0.0


def flat(points) -> list[float]:
    return [r2(c) for p in points for c in p[:2]]


def attribute_words(inst: Instance) -> str:
    a = inst.attributes
    return " ".join(w for w in (a.size, a.color, a.material, a.state) if w)


def attribute_codes(inst: Instance) -> list[int]:
    """The instance's colour, material, size and state codes (the observation's order; -1 unknown)."""
    a = inst.attributes
    return [vocab.COLOR_INDEX.get(a.color, -1), vocab.MATERIAL_INDEX.get(a.material, -1),
            vocab.SIZE_INDEX.get(a.size, -1), vocab.STATE_INDEX.get(a.state, -1)]


def instance_entry(inst: Instance) -> list | None:
    """``[id, category words, attribute words, colour, footprint (8 numbers), centre x, y, kind]``
    (kind: 0 object, 1 structural wall) or None for an instance the map does not draw."""
    if inst.structural and inst.category in SKIPPED_STRUCTURAL:
        return None
    wall = inst.structural and inst.category == "wall"
    color = "#2b2b2b" if wall else to_hex(category_color(inst.category))
    c = inst.bbox.center
    return [inst.id, vocab.category_display(inst.category), attribute_words(inst), color,
            flat(inst.bbox.footprint()), r2(c[0]), r2(c[1]), 1 if wall else 0]


def scene_data(scene: Scene) -> dict:
    """The map data of one scene (see the module docstring).

    ``inst`` is aligned with ``scene.instances`` (None where not drawn), so
    an instance handle of the observation indexes it directly.
    """
    lo, hi = scene.bounds()
    rooms = [[vocab.ROOM_DISPLAY.get(r.label, r.label), ROOM_COLORS.get(r.label, ROOM_COLORS["other"]),
              flat(r.polygon), r2(r.centroid[0]), r2(r.centroid[1])] for r in scene.rooms]
    walls = [[r2(w.start[0]), r2(w.start[1]), r2(w.end[0]), r2(w.end[1]), r2(w.thickness)]
             for w in scene.walls if w.bottom <= 1e-6]  # lintels above doors leave the opening visible
    doors = []
    for d in scene.doors:
        ca, sa = math.cos(d.yaw) * d.width / 2, math.sin(d.yaw) * d.width / 2
        kind = 2 if d.rooms[1] is None else (1 if d.kind == "opening" else 0)
        doors.append([r2(d.position[0] - ca), r2(d.position[1] - sa), r2(d.position[0] + ca),
                      r2(d.position[1] + sa), kind])
    return {"bounds": [r2(lo[0]), r2(lo[1]), r2(hi[0]), r2(hi[1])], "rooms": rooms, "walls": walls, "doors": doors,
            "inst": [instance_entry(i) for i in scene.instances]}


__all__ = ["attribute_codes", "attribute_words", "flat", "instance_entry", "r2", "scene_data"]
