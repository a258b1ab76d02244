"""Furnishing procedural houses: the furnisher that places catalogue objects
in a room, and the per-house distractor plan.

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
    metadata, see :func:`~ignjax.scenes.procgen.generate.house_info`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
from scipy import ndimage

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes, Door, Instance, Room
from ignjax.scenes.procgen import catalogue as cat
from ignjax.scenes.procgen.catalogue import Built, CategorySpec
from ignjax.scenes.procgen.params import HouseParams

__all__ = ["furnish"]

_CELL = 0.1  # raster cell for the navigability check, metres
_AGENT_RADIUS = 0.26  # 0.18 m agent + rounding of objects to 5 cm navigation-grid cells
_REACH = 0.8  # every floor object within this distance of the room's free space
_REACH_WALL = 1.2  # every wall object (a painting may hang above a sofa)
_LOW_WALL_OBJECT = 1.0  # wall objects hung lower than this are obstacles
_FLAT = 0.05  # floor objects lower than this (rugs) can be walked over
_TABLE_HEIGHT = (0.6, 1.1)  # surfaces at this height get companions (seats)
_COMPANION_MAX_HALF = 0.35


def _weighted_pick(rng: np.random.Generator, items: Sequence, weights: Sequence[float]):
    w = np.asarray(weights, dtype=np.float64)
    total = w.sum()
    if len(items) == 0 or total <= 0:
        return None
    return items[int(rng.choice(len(items), p=w / total))]


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


def furnish(rooms: list[Room], rects, doors: list[Door], params: HouseParams,
             catalogue: Mapping[str, CategorySpec], rng: np.random.Generator) -> tuple[list[Instance], list[str]]:
    """Furnish every room of a house and plan its distractors.

    Args:
        rooms: the rooms, in the order of ``rects``.
        rects: room rectangles (x0, y0, x1, y1) on the wall centre lines.
        doors: the house's doors.
        params: house parameters.
        catalogue: categories to place (name -> spec).
        rng: the furnishing generator.

    Returns:
        The placed instances, and the distractor categories that got at
        least one instance.
    """
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
