"""Floor plans of procedural houses: the room program, the rectangle layout,
room adjacency, doors and walls.

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
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ignjax.scenes.model import Door, Wall
from ignjax.scenes.procgen.params import HouseParams

__all__ = ["ROOM_AREAS", "room_program", "layout_rooms", "make_doors", "make_walls"]

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
_OPEN_PLAN = ("living_room", "dining_room", "kitchen", "hallway", "entryway")
_PRIVATE = ("bathroom", "closet")
_STACKABLE = ("closet", "bathroom", "laundry_room", "office")  # may share a column with another small room
_MIN_SIDE_BY_LABEL = {"hallway": _HALL_WIDTH[0], "bedroom": 2.4, "kitchen": 2.2, "dining_room": 2.6,
                      "living_room": 3.0, "garage": 3.0}
_HALL_PRIORITY = {"bathroom": 3, "laundry_room": 2, "closet": 0}  # others 1


# ---------------------------------------------------------------------------
# Floor plan
# ---------------------------------------------------------------------------


def _snap(v: float) -> float:
    return round(round(v / _GRID) * _GRID, 6)


def room_program(n: int, rng: np.random.Generator) -> list[str]:
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


def layout_rooms(labels: list[str], rng: np.random.Generator) -> list[tuple[float, float, float, float]]:
    """Lay out rooms of the given labels as rectangles tiling a footprint.

    Args:
        labels: room labels, from :func:`room_program`.
        rng: the plan's generator.

    Returns:
        One (x0, y0, x1, y1) rectangle per label, in order; the rooms form
        a connected adjacency graph.
    """
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


def make_doors(rects, labels, ids, params: HouseParams, rng: np.random.Generator) -> list[Door]:
    """Doors of a floor plan: a spanning tree of the adjacency graph, extra doors, one exterior door.

    Args:
        rects: room rectangles (x0, y0, x1, y1), from :func:`layout_rooms`.
        labels: room labels, in the order of ``rects``.
        ids: room ids, in the order of ``rects``.
        params: house parameters (door widths, extra doors, exterior door).
        rng: the plan's generator.

    Returns:
        Doors ``door_0..``.
    """
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


def make_walls(rects, ids, doors: list[Door], params: HouseParams) -> list[Wall]:
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
