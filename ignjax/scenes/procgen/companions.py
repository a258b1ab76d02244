"""Tables and the seats that face them, for the furnisher
(:mod:`ignjax.scenes.procgen.furnish`, whose docstring gives the rules): what
counts as a table (a surface at table height over most of the footprint,
knee room below) and as a seat (a small free-standing category with a part
named "seat"), and seats placed in slots around a free-standing table or in
front of a desk against a wall.
"""

from __future__ import annotations

import math

from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue import Built, CategorySpec
from ignjax.scenes.procgen.placement import Furnisher, weighted_pick
from ignjax.scenes.procgen.roomspace import Item, RoomCtx

__all__ = ["is_seat", "has_table_surface", "place_companions"]

_TABLE_HEIGHT = (0.6, 1.1)  # surfaces at this height get companions (seats)
_COMPANION_MAX_HALF = 0.35


def is_seat(f: Furnisher, spec: CategorySpec) -> bool:
    """A small free-standing category whose geometry has a part named "seat"."""
    if spec.placement != "floor":
        return False
    b = f.probe(spec)
    return (max(b.half_extents[:2]) <= _COMPANION_MAX_HALF and 2 * b.half_extents[2] <= 1.3
            and any("seat" in g.part for g in b.geoms))


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


def place_companions(f: Furnisher, ctx: RoomCtx, table: Item, budget: int,
                     pending: list[tuple[CategorySpec, Attributes]] | None = None) -> int:
    """Seats facing a table-height support; returns how many were placed.

    With ``pending`` (required seats of this room: (spec, attributes)),
    those are placed first and removed from the list as they are placed;
    otherwise up to ``budget`` seats of one category allowed in the room
    (one sampled set of attributes: a matching set).
    """
    if table.level != "floor" or not has_table_surface(table.built):
        return 0
    queue = list(pending) if pending else _seat_set(f, ctx, budget)
    if not queue:
        return 0
    if table.group is None:
        table.group = f.next_group
        f.next_group += 1
    return _place_around(f, ctx, table, queue, pending)


def _seat_set(f: Furnisher, ctx: RoomCtx, budget: int) -> list[tuple[CategorySpec, Attributes]]:
    """Up to ``budget`` seats of one seat category drawn for the room, all with one set of attributes
    (empty when the budget is spent, the room has no seat category, or the draw gives none)."""
    if budget <= 0:
        return []
    cands, weights = [], []
    for name, spec in f.cat.items():
        w = float(spec.rooms.get(ctx.label, 0.0))
        if w > 0 and name not in f.exclude and is_seat(f, spec):
            cands.append(spec)
            weights.append(w * w)
    spec = weighted_pick(f.rng, cands, weights)
    if spec is None or f.rng.random() < 0.15:
        return []
    attrs = spec.sample_attributes(f.rng)
    return [(spec, attrs)] * budget


def _place_around(f: Furnisher, ctx: RoomCtx, table: Item, queue: list[tuple[CategorySpec, Attributes]],
                  pending: list[tuple[CategorySpec, Attributes]] | None) -> int:
    """Seats of ``queue`` in up to two slots per side of ``table``, facing it; returns how many were placed."""
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
                built_cache[key] = spec.build(attrs, f.rng)
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
            cand = f.make(spec, attrs, built, ctx, wx, wy, 0.0, yaw, "floor", None, table.group)
            if not f.floor_fits(ctx, cand):
                continue
            blocked = ctx.nav_ok(cand)
            if blocked is None:
                continue
            f.commit(ctx, cand, blocked)
            placed += 1
            done = queue.pop(0)
            if pending is not None and done in pending:
                pending.remove(done)
    return placed
