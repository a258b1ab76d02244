"""Placing built objects in a house: an :class:`~ignjax.scenes.model.Instance`
from a :class:`~ignjax.scenes.procgen.catalogue.parts.Built` and a pose, and
the world footprints of its support surfaces.
"""

from __future__ import annotations

import math

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes, Instance, OrientedBox
from ignjax.scenes.procgen.catalogue.parts import Built


def instantiate(
    instance_id: str,
    category: str,
    attrs: Attributes,
    built: Built,
    position,
    yaw: float,
    room: str | None = None,
    support: str | None = None,
    name: str = "",
) -> Instance:
    """Place a built object in the world as an :class:`Instance`.

    Args:
        position: (3,) world position of the builder origin (footprint
            centre at the object's lowest point).
        yaw: heading of the object's front (+x of the builder frame).
    """
    px, py, pz = (float(v) for v in position)
    hx, hy, hz = built.half_extents
    bbox = OrientedBox((px, py, pz + hz), (hx, hy, hz), yaw)
    return Instance(id=instance_id, category=category, position=(px, py, pz), yaw=yaw, bbox=bbox, room=room,
                    attributes=attrs, support=support, structural=vocab.is_structural(category), geoms=built.geoms,
                    name=name or instance_id)


def surfaces_world(inst: Instance, built: Built) -> list[tuple[float, np.ndarray]]:
    """World footprints of a placed object's support surfaces: list of
    (height, (4, 2) corners counter-clockwise)."""
    c, s = math.cos(inst.yaw), math.sin(inst.yaw)
    rot = np.array([[c, -s], [s, c]])
    out = []
    for surf in built.surfaces:
        hx, hy = surf.half_extents
        local = np.array([[hx, hy], [-hx, hy], [-hx, -hy], [hx, -hy]]) + np.array(surf.center)
        out.append((inst.position[2] + surf.height, local @ rot.T + np.array(inst.position[:2])))
    return out
