"""Where Type-3 questions were asked (paper §4.3): each question pose (or
each planner step, for the base rate) classified as corridor, junction,
dead end or room from the navigation grid around it.

Geometry, on a free-space mask of the grid (cells outside the grid
count as blocked): ``mask="navigable"`` (the grid's navigable mask) or
``mask="layout"`` (:func:`layout_mask`: inside a room and free of
anything in the tallest height band -- walls, wardrobes -- eroded by the
agent radius, so beds, tables and chairs do not turn a room into a maze
of passages); the default ``"auto"`` is ``"layout"`` for a grid with
``room``, ``bands`` and ``config`` (a NavGrid) and ``"navigable"``
otherwise. From the question pose (snapped to the nearest free
cell centre within ``snap_radius`` if it lies on a blocked cell; class
-1 unknown otherwise), cast ``n_rays`` (16) rays at angles
``2 pi k / n``, sampled every half cell up to ``reach`` (2 m); ``L_k`` =
distance of the last free sample before the first blocked one
(``reach`` if none). Then

* ``width`` = twice the largest *clearance* (distance from a free cell
  centre to the nearest blocked cell centre) among the pose's cell and
  the free ray samples within ``width_radius`` (1.25 m) of the pose: the
  diameter of the widest free disc the agent sees close by. Measured on
  the (eroded) mask, it is the wall-to-wall width minus twice the agent
  radius; room corners and points next to a wall still see the room's
  wide interior;
* ray k is *open* when ``L_k >= open_length`` (1 m); ``sectors`` = number
  of maximal circular runs of open rays.

Geometric rule, in order: all rays open or ``width > max_width`` (1.6 m)
-> ``room``; else ``sectors >= 3`` -> ``junction``; ``sectors == 2`` ->
``corridor`` (bends included: a narrow passage with two ways out);
``sectors == 1`` -> ``dead_end`` (the passage ends within
``open_length``); ``sectors == 0`` -> ``room`` (an enclosed pocket).
With the defaults, procedural hallways (1.2-1.6 m wall to wall, 0.84-1.24
m on the mask of a 0.18 m agent) and their junctions are narrow.

Room labels (optional, ``[r.label for r in scene.rooms]`` with the grid's
``room`` index array) then decide room versus passage: a pose in a room
whose label is not a passage label (``passage_labels``, default
``hallway``) is ``room`` whatever the local geometry (it is inside a
closed room, as the paper counts it); a pose in a passage room keeps its
geometric class, a wide spot (``room``) becoming ``corridor``; a pose
outside every room keeps its geometric class.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ignjax.errors import ConfigError, InputError
from ignjax.studies._common import as_array, class_counts

LOCATION_CLASSES: tuple[str, ...] = ("corridor", "junction", "dead_end", "room")
CORRIDOR, JUNCTION, DEAD_END, ROOM = range(4)
UNKNOWN = -1
"""A pose (or question) no class could be given."""

# ---------------------------------------------------------------------------
# Type-3 location classes
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class LocationParams:
    """Parameters of the location rule (module docstring).

    Attributes:
        n_rays: rays cast (>= 4).
        reach: ray length, metres.
        open_length: free length making a ray open, metres (<= reach).
        max_width: largest local free width (on the free-space mask) of a
            corridor, junction or dead end, metres.
        width_radius: how far from the pose the local free width looks,
            metres (<= reach).
        snap_radius: how far a pose on a blocked cell may be moved to the
            nearest free cell centre, metres.
        passage_labels: room labels of passages (see the module docstring).
    """

    n_rays: int = 16
    reach: float = 2.0
    open_length: float = 1.0
    max_width: float = 1.6
    width_radius: float = 1.25
    snap_radius: float = 0.25
    passage_labels: tuple[str, ...] = ("hallway",)

    def __post_init__(self):
        if not isinstance(self.n_rays, int) or self.n_rays < 4:
            raise ConfigError(None, "LocationParams.n_rays", f"must be an integer >= 4, got {self.n_rays!r}")
        for name in ("reach", "open_length", "max_width", "width_radius"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise ConfigError(None, f"LocationParams.{name}", f"must be a positive number, got {v!r}")
        if not (isinstance(self.snap_radius, (int, float)) and math.isfinite(self.snap_radius) and self.snap_radius >= 0):
            raise ConfigError(None, "LocationParams.snap_radius", f"must be a non-negative number, got {self.snap_radius!r}")
        for name in ("open_length", "width_radius"):
            if getattr(self, name) > self.reach:
                raise ConfigError(None, f"LocationParams.{name}",
                                  f"must not exceed reach ({self.reach}), got {getattr(self, name)}")


def _grid_parts(grid, mask="auto"):
    if isinstance(mask, str):
        if mask == "auto":
            mask = "layout" if all(hasattr(grid, k) for k in ("room", "bands", "config")) else "navigable"
        if mask not in ("navigable", "layout"):
            raise ConfigError(None, "mask", f"must be 'auto', 'navigable', 'layout' or an (H, W) array, got {mask!r}")
    layout = layout_mask(grid) if isinstance(mask, str) and mask == "layout" else None
    try:
        origin = np.asarray(grid.origin, np.float64).reshape(2)
        res = float(grid.resolution)
        if layout is not None:
            free = layout
        else:
            free = np.asarray(grid.navigable if isinstance(mask, str) else mask, bool)
    except (AttributeError, TypeError, ValueError) as e:
        raise InputError(None, "grid", f"needs navigable (H, W), origin (2,) and resolution: {e}") from e
    if free.ndim != 2 or not (res > 0):
        raise InputError(None, "grid", f"the mask must be (H, W) and the resolution positive, got {free.shape}, {res}")
    return free, origin, res


def layout_mask(grid, band: int = -1, agent_radius: float | None = None) -> np.ndarray:
    """(H, W) bool free space of the room layout: cells inside a room whose
    disc of ``agent_radius`` (default the grid's) meets no cell that is
    outside all rooms or occupied in height band ``band`` (default the
    tallest: walls and tall furniture, not beds, tables or chairs). Uses a
    :class:`~ignjax.scenes.navgrid.NavGrid`'s ``room``, ``bands``,
    ``resolution`` and ``config.agent_radius``; contains the navigable mask."""
    try:
        room = np.asarray(grid.room)
        occ = np.asarray(grid.bands)[band]
        res = float(grid.resolution)
        radius = float(grid.config.agent_radius if agent_radius is None else agent_radius)
    except (AttributeError, IndexError, TypeError, ValueError) as e:
        raise InputError(None, "grid", f"a layout mask needs room, bands, resolution and config.agent_radius: {e}") from e
    blocked = (room < 0) | occ
    n = int(math.ceil(radius / res + 0.5))
    o = np.arange(-n, n + 1)
    dx = np.maximum(np.abs(o)[None, :] - 0.5, 0.0) * res
    dy = np.maximum(np.abs(o)[:, None] - 0.5, 0.0) * res
    disc = dx ** 2 + dy ** 2 < radius ** 2  # cells whose square comes within the radius of the centre
    return ~ndimage.binary_dilation(blocked, structure=disc, border_value=1) & (room >= 0)


def classify_locations(grid, xy, params: LocationParams = LocationParams(), room_labels=None,
                       mask="auto") -> dict:
    """Location class of world points on a navigation grid.

    Args:
        grid: a :class:`~ignjax.scenes.navgrid.NavGrid` or any object with
            ``navigable`` (H, W), ``origin`` (2,), ``resolution`` (and
            ``room`` (H, W) room indices for ``room_labels``).
        xy: (P, 2) world points, metres.
        params: the rule's parameters.
        room_labels: optional label per room index (``[r.label for r in
            scene.rooms]``).
        mask: ``"auto"`` (default), ``"navigable"``, ``"layout"``
            (:func:`layout_mask`) or an (H, W) bool free-space array.

    Returns:
        dict with ``cls`` (P,) int (index into :data:`LOCATION_CLASSES`, -1
        unknown), ``lengths`` (P, n_rays) free ray lengths (m), ``width`` (P,)
        local free width (m), ``sectors`` (P,) open sectors, ``snapped`` (P,)
        bool (the pose was moved to a navigable cell).
    """
    nav, origin, res = _grid_parts(grid, mask)
    H, W = nav.shape
    p = as_array(xy, "xy", ndim=2, last=2, dtype=np.float64, finite=True)
    P = p.shape[0]
    rc = np.floor((p[:, ::-1] - origin[::-1]) / res).astype(np.int64)  # (row, col)
    inb = (rc[:, 0] >= 0) & (rc[:, 0] < H) & (rc[:, 1] >= 0) & (rc[:, 1] < W)
    ok = inb.copy()
    ok[inb] = nav[rc[inb, 0], rc[inb, 1]]
    start = p.copy()
    snapped = np.zeros(P, bool)
    known = ok.copy()
    if (~ok).any() and nav.any():
        cand = ~ok
        _, ind = ndimage.distance_transform_edt(~nav, return_indices=True)
        rcc = np.clip(rc[cand], 0, [H - 1, W - 1])
        # nearest navigable cell of the (clipped) cell; its centre must be within snap_radius of the point
        near = np.stack([ind[0][rcc[:, 0], rcc[:, 1]], ind[1][rcc[:, 0], rcc[:, 1]]], -1)
        centre = origin + (near[:, ::-1] + 0.5) * res
        close = np.linalg.norm(centre - p[cand], axis=1) <= params.snap_radius + 1e-9
        idx = np.nonzero(cand)[0][close]
        start[idx] = centre[close]
        snapped[idx] = True
        known[idx] = True
        rc[idx] = near[close]

    # clearance (m) of every navigable cell: distance to the nearest non-navigable cell centre (outside = blocked)
    clear = ndimage.distance_transform_edt(np.pad(nav, 1))[1:-1, 1:-1] * res
    K = params.n_rays
    ang = 2 * np.pi * np.arange(K) / K
    dirs = np.stack([np.cos(ang), np.sin(ang)], -1)  # (K, 2)
    ds = res / 2
    n_s = int(math.ceil(params.reach / ds))
    dist = np.minimum(ds * np.arange(1, n_s + 1), params.reach)  # (S,)
    lengths = np.zeros((P, K))
    width = np.zeros(P)
    c0 = np.zeros(P)
    c0[known] = clear[rc[known, 0], rc[known, 1]]
    chunk = max(1, (1 << 22) // (K * n_s))
    for i in range(0, P, chunk):
        pts = start[i:i + chunk, None, None, :] + dirs[None, :, None, :] * dist[None, None, :, None]  # (p, K, S, 2)
        cr = np.floor((pts[..., ::-1] - origin[::-1]) / res).astype(np.int64)
        inside = (cr[..., 0] >= 0) & (cr[..., 0] < H) & (cr[..., 1] >= 0) & (cr[..., 1] < W)
        free = np.zeros(inside.shape, bool)
        free[inside] = nav[cr[..., 0][inside], cr[..., 1][inside]]
        cl = np.zeros(inside.shape)
        cl[inside] = clear[cr[..., 0][inside], cr[..., 1][inside]]
        blocked = ~free
        first = np.where(blocked.any(-1), blocked.argmax(-1), n_s)  # (p, K) index of the first blocked sample
        lengths[i:i + chunk] = np.where(first == n_s, params.reach, np.where(first > 0, dist[np.maximum(first - 1, 0)], 0.0))
        seen = (np.arange(n_s) < first[..., None]) & (dist <= params.width_radius + 1e-9)  # visible, close samples
        width[i:i + chunk] = 2 * np.maximum(c0[i:i + chunk], np.where(seen, cl, 0.0).max((-1, -2)))
    open_ = lengths >= params.open_length - 1e-9
    sectors = (open_ & ~np.roll(open_, 1, axis=1)).sum(1)
    all_open = open_.all(1)
    cls = np.select([all_open | (width > params.max_width), sectors >= 3, sectors == 2, sectors == 1],
                    [ROOM, JUNCTION, CORRIDOR, DEAD_END], ROOM)
    if room_labels is not None:
        room = getattr(grid, "room", None)
        if room is None:
            raise InputError(None, "grid.room", "room_labels need the grid's room-index array")
        room = np.asarray(room)
        labels = np.asarray([str(x) for x in room_labels] + [""])  # index -1 -> ""
        ridx = np.full(P, -1, np.int64)
        ridx[known] = room[rc[known, 0], rc[known, 1]]
        if ridx.max(initial=-1) >= len(labels) - 1:
            raise InputError(None, "room_labels", f"has {len(labels) - 1} labels but the grid uses room {ridx.max()}")
        passage = np.isin(labels[ridx], list(params.passage_labels))
        in_room = (ridx >= 0) & ~passage
        cls = np.where(in_room, ROOM, np.where(passage & (cls == ROOM), CORRIDOR, cls))
    cls = np.where(known, cls, UNKNOWN)
    return {"cls": cls.astype(np.int64), "lengths": lengths, "width": width, "sectors": sectors, "snapped": snapped}


def _grid_lists(grids, n_episodes: int, scene_index, room_labels):
    """(grids, room labels per grid, (E,) grid index per episode) of :func:`type3_locations`' arguments."""
    if not isinstance(grids, (list, tuple)):
        return [grids], [room_labels], np.zeros(n_episodes, np.int64)
    glist = list(grids)
    if scene_index is None:
        raise InputError(None, "scene_index", "is required with several grids")
    sidx = as_array(scene_index, "scene_index", ndim=1).astype(np.int64)
    if sidx.shape[0] != n_episodes or sidx.min(initial=0) < 0 or sidx.max(initial=0) >= len(glist):
        raise InputError(None, "scene_index", f"must give one grid index in 0..{len(glist) - 1} per episode")
    labels = [None] * len(glist) if room_labels is None else list(room_labels)
    if len(labels) != len(glist):
        raise InputError(None, "room_labels", f"must hold one label sequence per grid ({len(glist)})")
    return glist, labels, sidx


def _classify_at(glist, labels, sidx, pz, ep, st, params, mask):
    """(cls, width, sectors) of the poses ``pz[ep, st]``, each on its episode's grid; a position repeated
    (turning or asking in place) is classified once."""
    n = len(ep)
    cls = np.full(n, UNKNOWN, np.int64)
    width = np.full(n, np.nan)
    sectors = np.zeros(n, np.int64)
    xy = pz[ep, st, :2]
    for g in np.unique(sidx[ep]) if n else []:
        m = np.nonzero(sidx[ep] == g)[0]
        points, back = np.unique(xy[m], axis=0, return_inverse=True)
        r = classify_locations(glist[g], points, params, labels[g], mask)
        back = back.reshape(-1)
        cls[m], width[m], sectors[m] = r["cls"][back], r["width"][back], r["sectors"][back]
    return cls, width, sectors


def type3_locations(grids, poses, events: dict, *, scene_index=None, room_labels=None,
                    params: LocationParams = LocationParams(), mask="auto") -> dict:
    """Location class of every Type-3 question.

    Args:
        grids: one grid, or a sequence of grids indexed by ``scene_index``.
        poses: (E, S + 1, 3) (or (E, S + 1, 2)) trajectory poses.
        events: question events (:func:`~ignjax.studies.interaction.events_from_rows` / :func:`~ignjax.studies.interaction.events_from_trajectory`).
        scene_index: (E,) grid index per episode (required with several grids).
        room_labels: one label sequence per grid (or one, for a single grid).
        mask: ``"auto"``, ``"navigable"`` or ``"layout"`` (see :func:`classify_locations`).

    Returns:
        dict with per-question ``episode``, ``step``, ``cls``, ``width``,
        ``sectors``; ``classes`` (names), ``counts`` (4,), ``n_unknown``,
        ``fractions`` (4,) over classified questions, ``counts_by_difficulty`` (3, 4).
    """
    pz = as_array(poses, "poses", ndim=3, dtype=np.float64)
    if pz.shape[-1] not in (2, 3):
        raise InputError(None, "poses", f"last axis must be (x, y[, yaw]), got shape {pz.shape}")
    sel = events["type"] == 3
    ep, st = events["episode"][sel], events["step"][sel]
    if ep.size and (ep.max() >= pz.shape[0] or st.max() >= pz.shape[1]):
        raise InputError(None, "poses", f"shape {pz.shape} does not cover the events (episode {ep.max()}, step {st.max()})")
    glist, labels, sidx = _grid_lists(grids, pz.shape[0], scene_index, room_labels)
    cls, width, sectors = _classify_at(glist, labels, sidx, pz, ep, st, params, mask)
    known, counts, by_d = class_counts(cls, np.asarray(events["difficulty"])[ep])
    return {"episode": ep, "step": st, "cls": cls, "width": width, "sectors": sectors, "classes": LOCATION_CLASSES,
            "counts": counts, "n_unknown": int((~known).sum()),
            "fractions": counts / counts.sum() if counts.sum() else np.full(4, np.nan), "counts_by_difficulty": by_d}


def step_locations(grids, poses, steps_used, *, scene_index=None, room_labels=None,
                   params: LocationParams = LocationParams(), mask="auto") -> dict:
    """Location class of the pose before every planner step an episode used
    (``poses[e, s]`` for ``s < steps_used[e]``): the base rate of where the
    steps are spent, against which :func:`type3_locations` reads. Arguments
    as :func:`type3_locations` (``steps_used``: (E,), e.g. ``events["steps_used"]``).

    Returns:
        dict with ``classes`` (names), ``counts`` (4,) steps per class,
        ``n_unknown``, ``n`` (steps), ``fractions`` (4,) over classified steps.
    """
    pz = as_array(poses, "poses", ndim=3, dtype=np.float64)
    used = as_array(steps_used, "steps_used", ndim=1).astype(np.int64)
    if used.shape[0] != pz.shape[0] or (used.size and (used.min() < 0 or used.max() >= pz.shape[1])):
        raise InputError(None, "steps_used", f"must give 0..{pz.shape[1] - 1} steps for each of {pz.shape[0]} episodes")
    glist, labels, sidx = _grid_lists(grids, pz.shape[0], scene_index, room_labels)
    ep = np.repeat(np.arange(pz.shape[0]), used)
    st = np.concatenate([np.arange(u) for u in used]) if used.size else np.zeros(0, np.int64)
    cls = _classify_at(glist, labels, sidx, pz, ep, st.astype(np.int64), params, mask)[0]
    known = cls >= 0
    counts = np.bincount(cls[known], minlength=4)
    return {"classes": LOCATION_CLASSES, "counts": counts, "n_unknown": int((~known).sum()), "n": int(len(cls)),
            "fractions": counts / counts.sum() if counts.sum() else np.full(4, np.nan)}


__all__ = ["LOCATION_CLASSES", "UNKNOWN", "LocationParams", "classify_locations", "layout_mask", "step_locations",
           "type3_locations"]
