"""Furnishing procedural houses: :func:`furnish` and the order in which a
room is furnished. The room being furnished and its navigability check are
in :mod:`~ignjax.scenes.procgen.roomspace`, the placement rules in
:mod:`~ignjax.scenes.procgen.placement`, tables and their seats in
:mod:`~ignjax.scenes.procgen.companions`, the distractor plan in
:mod:`~ignjax.scenes.procgen.distractors`; the rules they follow are these.

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

from typing import Mapping

import numpy as np

from ignjax.scenes.model import Attributes, Door, Instance, Room
from ignjax.scenes.procgen.catalogue import CategorySpec
from ignjax.scenes.procgen.companions import has_table_surface, is_seat, place_companions
from ignjax.scenes.procgen.distractors import plan_distractors
from ignjax.scenes.procgen.params import HouseParams
from ignjax.scenes.procgen.placement import Furnisher, weighted_pick
from ignjax.scenes.procgen.roomspace import FLAT, Item, RoomCtx

__all__ = ["furnish"]

_Planned = list[tuple[CategorySpec, Attributes]]


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
    f = Furnisher(params, catalogue, rng)
    ctxs = [RoomCtx(r, rect, doors, params) for r, rect in zip(rooms, rects)]
    multi, required = plan_distractors(f, ctxs)
    for k, ctx in enumerate(ctxs):
        _furnish_room(f, ctx, required[k])
    placed = {inst.category for inst in f.instances}
    return f.instances, [m for m in multi if m in placed]  # a planned category that found no room is not reported


def _furnish_room(f: Furnisher, ctx: RoomCtx, req: _Planned) -> None:
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
    anchors, n_fill = _place_anchors(f, ctx, floor_specs, target)
    _place_planned(f, ctx, req, floor_specs)
    _fill_floor(f, ctx, floor_specs, anchors, target, n_fill)
    _place_wall_objects(f, ctx, wall_specs)
    _place_small_objects(f, ctx, req, small_specs)


def _area(f: Furnisher, sp: CategorySpec) -> float:
    b = f.probe(sp)
    return b.half_extents[0] * b.half_extents[1]


def _place(f: Furnisher, ctx: RoomCtx, sp: CategorySpec, attrs: Attributes | None = None,
           tries: int = 25) -> Item | None:
    """Place one object of ``sp`` on the floor or a wall (attributes sampled when not given)."""
    attrs = sp.sample_attributes(f.rng) if attrs is None else attrs
    return f.place_floor_level(ctx, sp, attrs, sp.build(attrs, f.rng), tries=tries)


def _tables(ctx: RoomCtx) -> list[Item]:
    return [it for it in ctx.items if it.level == "floor" and has_table_surface(it.built)]


def _place_anchors(f: Furnisher, ctx: RoomCtx, floor_specs: list[CategorySpec],
                   target: int) -> tuple[list[CategorySpec], int]:
    """Step 1, the room's defining furniture: its highest-weight categories, largest first.
    Returns those categories and how many were placed."""
    label = ctx.label
    anchors: list[CategorySpec] = []
    n_fill = 0
    if floor_specs and target > 0:
        top = max(sp.rooms[label] for sp in floor_specs)
        anchors = sorted((sp for sp in floor_specs if sp.rooms[label] >= top - 1e-9), key=lambda sp: -_area(f, sp))
        for sp in anchors[:target]:
            if _place(f, ctx, sp, tries=40) is not None:
                n_fill += 1
    return anchors, n_fill


def _place_planned(f: Furnisher, ctx: RoomCtx, req: _Planned, floor_specs: list[CategorySpec]) -> None:
    """Step 2, the distractors planned for the room (small ones wait for step 5): seats go
    around a table (one placed for them when the room has none), and a small distractor
    gets a support when the room has none of its supports yet."""
    catalogue, rng, label = f.cat, f.rng, ctx.label
    seats = [(sp, a) for sp, a in req if is_seat(f, sp)]
    for sp, attrs in req:
        if sp.placement != "on_support" and not is_seat(f, sp):
            _place(f, ctx, sp, attrs, tries=40)
    if seats:
        tables = _tables(ctx)
        if not tables:
            opts = [sp for sp in floor_specs if has_table_surface(f.probe(sp))]
            sp = weighted_pick(rng, opts, [o.rooms[label] for o in opts])
            item = _place(f, ctx, sp, tries=40) if sp is not None else None
            tables = [item] if item is not None else []
        for table in tables:
            place_companions(f, ctx, table, 0, seats)
        for sp, attrs in seats:
            _place(f, ctx, sp, attrs, tries=40)
    for sp in [sp for sp, _ in req if sp.placement == "on_support"]:
        if any(it.inst.category in sp.supports and it.built.surfaces for it in ctx.items):
            continue
        sups = [catalogue[n] for n in sp.supports if n in catalogue and catalogue[n].placement != "on_support"]
        for sup in sorted(sups, key=lambda o: -o.rooms.get(label, 0.0)):
            if sup.rooms.get(label, 0.0) > 0 and _place(f, ctx, sup, tries=40) is not None:
                break


def _fill_floor(f: Furnisher, ctx: RoomCtx, floor_specs: list[CategorySpec], anchors: list[CategorySpec],
                target: int, n_fill: int) -> None:
    """Step 3, seats for the tables so far, then a weighted draw of floor categories up to
    ``target``, placed largest first (rugs last), each table with its seats."""
    label = ctx.label
    for table in _tables(ctx):
        n_fill += place_companions(f, ctx, table, max(target - n_fill, 0) + 2)
    if not floor_specs or n_fill >= target:
        return
    used = {sp.name: 1 for sp in anchors}
    drawn = []
    for _ in range(2 * (target - n_fill) + 2):
        w = [sp.rooms[label] * 0.35 ** used.get(sp.name, 0) * 0.8 ** f.counts.get(sp.name, 0) for sp in floor_specs]
        sp = weighted_pick(f.rng, floor_specs, w)
        drawn.append(sp)
        used[sp.name] = used.get(sp.name, 0) + 1
    for sp in sorted(drawn, key=lambda o: (2 * f.probe(o).half_extents[2] < FLAT, -_area(f, o))):
        if n_fill >= target:
            break
        item = _place(f, ctx, sp)
        if item is not None:
            n_fill += 1 + place_companions(f, ctx, item, target - n_fill + 1)


def _place_wall_objects(f: Furnisher, ctx: RoomCtx, wall_specs: list[CategorySpec]) -> None:
    """Step 4, ``wall_objects_per_room`` wall objects (a category's weight halves each time it is drawn)."""
    lo, hi = f.params.wall_objects_per_room
    n_wall = int(f.rng.integers(lo, hi + 1))
    used: dict[str, int] = {}
    placed = 0
    for _ in range(2 * n_wall + 2):
        if placed >= n_wall:
            break
        sp = weighted_pick(f.rng, wall_specs, [o.rooms.get(ctx.label, 0.0) * 0.5 ** used.get(o.name, 0)
                                               for o in wall_specs])
        if sp is None:
            break
        used[sp.name] = used.get(sp.name, 0) + 1
        placed += _place(f, ctx, sp) is not None


def _place_small_objects(f: Furnisher, ctx: RoomCtx, req: _Planned, small_specs: list[CategorySpec]) -> None:
    """Step 5, the small distractors planned for the room, then small objects on every support surface."""
    rng, label = f.rng, ctx.label
    for sp, attrs in req:
        if sp.placement == "on_support":
            sups = [it for it in ctx.items if it.level != "support" and it.built.surfaces and it.inst.category in sp.supports]
            f.place_on_support(ctx, sp, attrs, sp.build(attrs, rng), sups, tries=30)
    lo, hi = f.params.small_objects_per_surface
    for sup in [it for it in ctx.items if it.level != "support" and it.built.surfaces]:
        opts = [o for o in small_specs if sup.inst.category in o.supports and o.rooms.get(label, 0.0) > 0]
        for _surf in sup.built.surfaces:
            for _ in range(int(rng.integers(lo, hi + 1))):
                sp = weighted_pick(rng, opts, [o.rooms[label] for o in opts])
                if sp is None:
                    break
                attrs = sp.sample_attributes(rng)
                f.place_on_support(ctx, sp, attrs, sp.build(attrs, rng), [sup])
