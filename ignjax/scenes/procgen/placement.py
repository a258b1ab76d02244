"""The furnisher's placement rules, for :mod:`ignjax.scenes.procgen.furnish`
(whose docstring gives them): where a ``floor``, ``floor_wall``, ``wall`` or
``on_support`` object may stand in a room, the gaps kept between objects,
and committing a placement with its instance id.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Mapping, Sequence

import numpy as np

from ignjax.scenes.model import Attributes, Instance
from ignjax.scenes.procgen import catalogue as cat
from ignjax.scenes.procgen.catalogue import Built, CategorySpec
from ignjax.scenes.procgen.params import HouseParams
from ignjax.scenes.procgen.roomspace import FLAT, LOW_WALL_OBJECT, SIDES, Item, RoomCtx, aabb, aabb_dist, overlap

__all__ = ["Furnisher", "weighted_pick"]


def weighted_pick(rng: np.random.Generator, items: Sequence, weights: Sequence[float]):
    """One of ``items`` drawn with probability proportional to ``weights``; None when there is nothing to draw."""
    w = np.asarray(weights, dtype=np.float64)
    total = w.sum()
    if len(items) == 0 or total <= 0:
        return None
    return items[int(rng.choice(len(items), p=w / total))]


class Furnisher:
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

    def commit(self, ctx: RoomCtx, item: Item, blocked: np.ndarray | None) -> Item:
        """Add ``item`` to the room and the house under its instance id (``blocked``: the room's new raster)."""
        iid = self._new_id(item.inst.category)
        item.inst = dataclasses.replace(item.inst, id=iid, name=iid)
        if blocked is not None:
            ctx.blocked = blocked
        ctx.items.append(item)
        self.instances.append(item.inst)
        return item

    def make(self, spec: CategorySpec, attrs: Attributes, built: Built, ctx: RoomCtx, x: float, y: float, z: float,
             yaw: float, level: str, side=None, group=None, support: str | None = None) -> Item:
        """A candidate item (its instance still unnamed) at (x, y, z) turned by ``yaw``."""
        inst = cat.instantiate("pending", spec.name, attrs, built, (x, y, z), yaw, ctx.id, support)
        hx, hy, hz = built.half_extents
        return Item(inst, built, spec, aabb(x, y, yaw, hx, hy), z, z + 2 * hz, level, side, group)

    def _gap(self, a: Item, b: Item) -> float:
        if a.group is not None and a.group == b.group:
            return 0.03
        if a.z1 - a.z0 < FLAT or b.z1 - b.z0 < FLAT:  # one can walk over a rug
            return 0.05
        if a.side is not None and a.side == b.side and a.spec.placement == b.spec.placement == "floor_wall":
            return 0.03
        return self.params.passage_width

    def floor_fits(self, ctx: RoomCtx, cand: Item) -> bool:
        """Whether a floor candidate keeps clear of the walls, the door keep-outs and the placed items."""
        if not ctx.inside(cand.aabb):
            return False
        if cand.z1 > self.params.wall_height - 0.02:
            return False
        if any(overlap(cand.aabb, k) for k in ctx.keepouts):
            return False
        for it in ctx.items:
            if it.level == "floor":
                if aabb_dist(cand.aabb, it.aabb) < self._gap(cand, it) - 1e-9:
                    return False
            elif it.level == "wall":
                if aabb_dist(cand.aabb, it.aabb) < 0.02 and cand.z0 < it.z1 and it.z0 < cand.z1:
                    return False
        return True

    def _wall_fits(self, ctx: RoomCtx, cand: Item) -> bool:
        if not ctx.inside(cand.aabb) or cand.z1 > self.params.wall_height - 0.02:
            return False
        for it in ctx.items:
            if it.level == "wall" and aabb_dist(cand.aabb, it.aabb) < 0.1:
                return False
            if it.level == "floor" and aabb_dist(cand.aabb, it.aabb) < 0.02 and cand.z0 < it.z1 and it.z0 < cand.z1:
                return False
        if cand.z0 < LOW_WALL_OBJECT and any(overlap(cand.aabb, k) for k in ctx.keepouts):
            return False
        return True

    def _pick_side(self, ctx: RoomCtx) -> str:
        sides = list(SIDES)
        lengths = [ctx.side_range(s)[1] - ctx.side_range(s)[0] for s in sides]
        return weighted_pick(self.rng, sides, lengths)

    # -- placements -----------------------------------------------------------
    def place_floor_level(self, ctx: RoomCtx, spec: CategorySpec, attrs: Attributes, built: Built,
                          tries: int = 25, group: int | None = None) -> Item | None:
        """Place a ``floor``, ``floor_wall`` or ``wall`` object somewhere in the room."""
        for _ in range(tries):
            if spec.placement in ("floor_wall", "wall"):
                cand = self._against_wall(ctx, spec, attrs, built, group)
            else:
                cand = self._free_standing(ctx, spec, attrs, built, group)
            if cand is None:
                continue
            blocked = ctx.nav_ok(cand)
            if blocked is None:
                continue
            return self.commit(ctx, cand, blocked)
        return None

    def _against_wall(self, ctx: RoomCtx, spec: CategorySpec, attrs: Attributes, built: Built,
                      group: int | None) -> Item | None:
        """A ``floor_wall`` or ``wall`` candidate with its back on a random wall, or None when it does not fit."""
        hx, hy, hz = built.half_extents
        side = self._pick_side(ctx)
        lo, hi = ctx.side_range(side)
        if hi - lo < 2 * hy:
            return None
        s = float(self.rng.uniform(lo + hy, hi - hy))
        (nx, ny), yaw = SIDES[side]
        ix0, iy0, ix1, iy1 = ctx.inner
        face = {"S": (s, iy0), "N": (s, iy1), "W": (ix0, s), "E": (ix1, s)}[side]
        x, y = face[0] + nx * hx, face[1] + ny * hx
        if spec.placement == "wall":
            if any(s + hy > dr.a0 - 0.1 and s - hy < dr.a1 + 0.1 for dr in ctx.doors if dr.side == side):
                return None
            cand = self.make(spec, attrs, built, ctx, x, y, float(spec.mount_height), yaw, "wall", side)
            return cand if self._wall_fits(ctx, cand) else None
        cand = self.make(spec, attrs, built, ctx, x, y, 0.0, yaw, "floor", side, group)
        return cand if self.floor_fits(ctx, cand) else None

    def _free_standing(self, ctx: RoomCtx, spec: CategorySpec, attrs: Attributes, built: Built,
                       group: int | None) -> Item | None:
        """A ``floor`` candidate at a random spot and quarter turn, or None when it does not fit."""
        hx, hy, hz = built.half_extents
        rng = self.rng
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
            return None
        cand = self.make(spec, attrs, built, ctx, x, y, 0.0, yaw, "floor", None, group)
        return cand if self.floor_fits(ctx, cand) else None

    def place_on_support(self, ctx: RoomCtx, spec: CategorySpec, attrs: Attributes, built: Built,
                         supports: list[Item], tries: int = 12) -> Item | None:
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
            cand = self.make(spec, attrs, built, ctx, x, y, float(h), yaw, "support", support=sup.inst.id)
            if not ctx.inside(cand.aabb) or cand.z1 > self.params.wall_height - 0.02:
                continue
            if self._spot_free(ctx, cand, sup, h):
                return self.commit(ctx, cand, None)
        return None

    @staticmethod
    def _spot_free(ctx: RoomCtx, cand: Item, sup: Item, h: float) -> bool:
        """Whether ``cand`` on the surface of ``sup`` at height ``h`` keeps clear of the objects
        already on that surface and stays below any higher surface of the same support."""
        for it in ctx.items:
            if it.level == "support" and it.inst.support == sup.inst.id and abs(it.z0 - h) < 1e-6:
                if aabb_dist(cand.aabb, it.aabb) < 0.02:
                    return False
        # room above: other surfaces of the same support over this spot
        for h2, c2 in cat.surfaces_world(sup.inst, sup.built):
            if h2 > h + 1e-6 and overlap(cand.aabb, (*c2.min(0), *c2.max(0))) and cand.z1 > h2 - 0.01:
                return False
        return True
