"""A room being furnished, for the furnisher (:mod:`ignjax.scenes.procgen.furnish`,
whose docstring gives the rules): its inner rectangle and doors, the keep-out
bands in front of the doors, the items placed so far, box geometry, and the
navigability check on a 10 cm raster of the room inflated by the agent's
clearance radius.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ignjax.scenes.model import Door, Instance, Room
from ignjax.scenes.procgen.catalogue import Built, CategorySpec
from ignjax.scenes.procgen.params import HouseParams

__all__ = ["CELL", "AGENT_RADIUS", "REACH", "REACH_WALL", "LOW_WALL_OBJECT", "FLAT", "SIDES", "aabb", "aabb_dist",
           "overlap", "Item", "DoorRef", "RoomCtx"]

CELL = 0.1  # raster cell for the navigability check, metres
AGENT_RADIUS = 0.26  # 0.18 m agent + rounding of objects to 5 cm navigation-grid cells
REACH = 0.8  # every floor object within this distance of the room's free space
REACH_WALL = 1.2  # every wall object (a painting may hang above a sofa)
LOW_WALL_OBJECT = 1.0  # wall objects hung lower than this are obstacles
FLAT = 0.05  # floor objects lower than this (rugs) can be walked over

SIDES = {  # inward normal, yaw of an object whose back is on that wall
    "S": ((0.0, 1.0), math.pi / 2),
    "N": ((0.0, -1.0), -math.pi / 2),
    "W": ((1.0, 0.0), 0.0),
    "E": ((-1.0, 0.0), math.pi),
}


def aabb(cx: float, cy: float, yaw: float, hx: float, hy: float) -> tuple[float, float, float, float]:
    """Axis-aligned box (x0, y0, x1, y1) of a box of half extents hx, hy centred at (cx, cy), turned by ``yaw``."""
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    ex, ey = hx * c + hy * s, hx * s + hy * c
    return (cx - ex, cy - ey, cx + ex, cy + ey)


def aabb_dist(a, b) -> float:
    """Gap between two axis-aligned boxes (0 when they touch or overlap)."""
    dx = max(0.0, a[0] - b[2], b[0] - a[2])
    dy = max(0.0, a[1] - b[3], b[1] - a[3])
    return math.hypot(dx, dy)


def overlap(a, b) -> bool:
    """Whether two axis-aligned boxes overlap (touching is not overlapping)."""
    return a[0] < b[2] - 1e-9 and b[0] < a[2] - 1e-9 and a[1] < b[3] - 1e-9 and b[1] < a[3] - 1e-9


@dataclass
class Item:
    """A placed (or candidate) object: its instance, build, category and extent."""

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
class DoorRef:
    """A door of the room: the wall it is in and its opening along that wall."""

    side: str
    a0: float  # along-wall interval of the opening
    a1: float


class RoomCtx:
    """A room being furnished: its geometry, doors, raster and placed items."""

    def __init__(self, room: Room, rect, doors: list[Door], params: HouseParams):
        self.room = room
        self.id, self.label = room.id, room.label
        t2 = params.wall_thickness / 2
        x0, y0, x1, y1 = rect
        self.inner = (x0 + t2, y0 + t2, x1 - t2, y1 - t2)
        self.area = (self.inner[2] - self.inner[0]) * (self.inner[3] - self.inner[1])
        self.params = params
        self.doors: list[DoorRef] = []
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
            self.doors.append(DoorRef(side, s - d.width / 2, s + d.width / 2))
        self.keepouts = [self._band(dr.side, dr.a0 - 0.15, dr.a1 + 0.15, 0.0, params.door_clearance) for dr in self.doors]
        self.items: list[Item] = []
        self._raster()

    def _raster(self) -> None:
        """Cell centres over the inner rectangle, the cells blocked by the walls, and the cells in front of each door."""
        ix0, iy0, ix1, iy1 = self.inner
        nx = max(1, int(math.floor((ix1 - ix0) / CELL)))
        ny = max(1, int(math.floor((iy1 - iy0) / CELL)))
        xs = ix0 + (np.arange(nx) + 0.5) * (ix1 - ix0) / nx
        ys = iy0 + (np.arange(ny) + 0.5) * (iy1 - iy0) / ny
        self.X, self.Y = np.meshgrid(xs, ys)  # Shape: (ny, nx)
        r = AGENT_RADIUS
        self.blocked = (self.X - ix0 < r) | (ix1 - self.X < r) | (self.Y - iy0 < r) | (iy1 - self.Y < r)
        self.door_cells = []
        for dr in self.doors:
            band = self._band(dr.side, dr.a0 + r, dr.a1 - r, r + 0.01, r + 0.31)
            if band[2] <= band[0] or band[3] <= band[1]:
                mid = 0.5 * (dr.a0 + dr.a1)
                band = self._band(dr.side, mid - CELL, mid + CELL, r + 0.01, r + 0.31)
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
        """The along-wall interval of the inner face of ``side``."""
        ix0, iy0, ix1, iy1 = self.inner
        return (ix0, ix1) if side in ("S", "N") else (iy0, iy1)

    def near(self, aabb, d: float) -> np.ndarray:
        """Cells whose centre is closer than ``d`` to the box."""
        dx = np.maximum(np.maximum(aabb[0] - self.X, self.X - aabb[2]), 0.0)
        dy = np.maximum(np.maximum(aabb[1] - self.Y, self.Y - aabb[3]), 0.0)
        return dx * dx + dy * dy < d * d

    def inside(self, aabb) -> bool:
        """Whether the box lies within the inner rectangle."""
        ix0, iy0, ix1, iy1 = self.inner
        e = 1e-6
        return aabb[0] >= ix0 - e and aabb[1] >= iy0 - e and aabb[2] <= ix1 + e and aabb[3] <= iy1 + e

    @staticmethod
    def obstacle(item: Item) -> bool:
        """Whether the agent cannot walk through the item (flat rugs and high wall objects it can)."""
        if item.level == "floor":
            return item.z1 - item.z0 >= FLAT
        return item.level == "wall" and item.z0 < LOW_WALL_OBJECT

    def nav_ok(self, cand: Item) -> np.ndarray | None:
        """The blocked mask with ``cand`` added when the room stays navigable, else None."""
        blocked = self.blocked
        if self.obstacle(cand):
            blocked = blocked | self.near(cand.aabb, AGENT_RADIUS)
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
                it.reach = self.near(it.aabb, REACH if it.level == "floor" else REACH_WALL)
            if not np.any(main & it.reach):
                return None
        return blocked
