"""Top-down maps of scenes (matplotlib, Agg; safe in notebooks and headless runs).

:func:`plot_scene_map` draws rooms filled by label, walls, doors and object
footprints coloured by family (:func:`category_family`: seating, tables,
storage and beds, ... -- ten colours a reader can tell apart, where a colour
per category would need a legend of fifty near-identical hues; the HTML
viewer keeps :func:`category_color`). It returns the figure and leaves the axes
usable, so callers can draw targets, distractors or trajectories on top::

    fig = plot_scene_map(scene, highlight={"laptop_0": "red"})
    ax = fig.axes[0]
    ax.plot(xs, ys, "k--")           # a trajectory
    save_figure(fig, "map.png")

Drawing order (z-order): room fills 0, walls 2, doors 3, floor objects 4,
wall-mounted objects 5, supported objects 6 and up (one step per level of
support), highlights 10, labels 11.
"""

from __future__ import annotations

import math
import os
import uuid
import zlib
from pathlib import Path
from typing import Mapping

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Arc, Patch, Polygon

from ignjax.scenes import vocab
from ignjax.scenes.model import Instance, Scene

__all__ = ["FAMILY_COLORS", "FAMILY_NAMES", "ROOM_COLORS", "category_color", "category_family", "plot_scene_map",
           "save_figure"]

ROOM_COLORS: Mapping[str, str] = {
    "bedroom": "#cfe2f3",
    "bathroom": "#d9f2f0",
    "kitchen": "#fff2cc",
    "living_room": "#fce5cd",
    "dining_room": "#f4cccc",
    "office": "#d9d2e9",
    "hallway": "#eeeeee",
    "laundry_room": "#d0e0e3",
    "entryway": "#e6d8c3",
    "closet": "#e2e2d0",
    "garage": "#d5d5d5",
    "other": "#f3f3f3",
}
"""Fill colour of each room label."""

FAMILY_NAMES: Mapping[str, str] = {
    "seating": "seating",
    "tables": "tables and desks",
    "storage": "storage and beds",
    "appliances": "appliances",
    "electronics": "electronics",
    "fixtures": "bath and heating",
    "wall": "wall-hung",
    "floor": "floor items",
    "small": "small objects",
    "other": "other",
}
"""Legend label of each family: the catalogue module a category's builder
lives in (:mod:`ignjax.scenes.procgen.catalogue`), ``other`` for categories
outside the catalogue (imported scenes)."""

FAMILY_COLORS: Mapping[str, str] = {
    "seating": "#4477aa",
    "tables": "#ccbb44",
    "storage": "#996633",
    "appliances": "#66ccee",
    "electronics": "#8866cc",
    "fixtures": "#228833",
    "wall": "#aa3377",
    "floor": "#ee6677",
    "small": "#ee9933",
    "other": "#bbbbbb",
}
"""Fill colour of each family (Paul Tol's bright scheme and neighbours: distinct in print and for common colour
vision deficiencies)."""

_WALL_COLOR = "#2b2b2b"
_PALETTE: tuple[tuple[float, float, float, float], ...] = tuple(
    tuple(float(v) for v in colormaps[name](k / 20 + 0.025)) for name in ("tab20", "tab20b", "tab20c") for k in range(20)
)
_DOOR_COLOR = "#c0392b"
_OPENING_COLOR = "#2e86c1"
_EXTERIOR_DOOR_COLOR = "#27ae60"


def category_color(category: str) -> tuple[float, float, float, float]:
    """A stable colour for a category (the same in every process and run)."""
    h = zlib.crc32(category.encode("utf-8")) % len(_PALETTE)
    return _PALETTE[h]


def category_family(category: str) -> str:
    """The family (a key of :data:`FAMILY_NAMES`) of a category."""
    from ignjax.scenes.procgen.catalogue import CATALOGUE  # on use: plain maps of imported scenes need no catalogue

    spec = CATALOGUE.get(category)
    family = spec.build.__module__.rpartition(".")[2] if spec is not None else "other"
    return family if family in FAMILY_NAMES else "other"


def _support_depth(scene: Scene) -> dict[str, int]:
    by_id = {i.id: i for i in scene.instances}
    depth: dict[str, int] = {}

    def d(inst: Instance, guard: int = 0) -> int:
        if inst.id in depth:
            return depth[inst.id]
        sup = by_id.get(inst.support) if inst.support else None
        v = 0 if sup is None or guard > 32 else d(sup, guard + 1) + 1
        depth[inst.id] = v
        return v

    for inst in scene.instances:
        d(inst)
    return depth


def _wall_polygon(start, end, thickness: float) -> np.ndarray:
    p0, p1 = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    v = p1 - p0
    n = np.linalg.norm(v)
    if n < 1e-12:
        return np.stack([p0, p0, p0, p0])
    nrm = np.array([-v[1], v[0]]) / n * thickness / 2
    return np.stack([p0 - nrm, p1 - nrm, p1 + nrm, p0 + nrm])


def _draw_door(ax: Axes, door, wall_thickness: float, into: tuple[float, float] | None) -> None:
    c, s = math.cos(door.yaw), math.sin(door.yaw)
    along = np.array([c, s])
    across = np.array([-s, c])
    centre = np.asarray(door.position, dtype=float)
    if into is not None and float(np.dot(np.asarray(into) - centre, across)) < 0:
        along, across = -along, -across  # swing into the door's first room
    yaw = math.atan2(along[1], along[0])
    a, b = centre - along * door.width / 2, centre + along * door.width / 2
    color = _EXTERIOR_DOOR_COLOR if door.rooms[1] is None else (_OPENING_COLOR if door.kind == "opening" else _DOOR_COLOR)
    # the clear opening across the wall
    ax.add_patch(Polygon(_wall_polygon(a, b, wall_thickness * 1.05), closed=True, facecolor="white",
                         edgecolor="none", zorder=2.5))
    if door.kind == "opening":
        ax.plot([a[0], b[0]], [a[1], b[1]], color=color, lw=1.5, ls="--", zorder=3)
        return
    # a leaf hinged at one end, swung open into the first room, and its swing arc
    leaf = a + across * door.width
    ax.plot([a[0], leaf[0]], [a[1], leaf[1]], color=color, lw=1.5, zorder=3)
    ax.plot([a[0], b[0]], [a[1], b[1]], color=color, lw=1.0, zorder=3)
    start = math.degrees(yaw)
    ax.add_patch(Arc(tuple(a), 2 * door.width, 2 * door.width, theta1=start, theta2=start + 90,
                     color=color, lw=0.8, zorder=3))


def plot_scene_map(
    scene: Scene,
    path: str | os.PathLike | None = None,
    *,
    ax: Axes | None = None,
    title: str | None = None,
    highlight: Mapping[str, object] | None = None,
    show_labels: bool = True,
    legend: bool | None = None,
    dpi: int = 120,
) -> Figure:
    """Draw a top-down map of a scene.

    Args:
        scene: the scene.
        path: when given, the PNG is written there (atomically: a temporary
            file in the same folder, then renamed).
        ax: draw into these axes instead of a new figure.
        title: axes title; defaults to the scene id.
        highlight: instance id -> matplotlib colour; those instances are
            drawn with a thick outline and a marker on top of everything.
            Unknown ids raise KeyError.
        show_labels: write room labels (and, unless ``legend`` says
            otherwise, the legend).
        legend: draw the legend of families and doors right of the map
            (default: ``show_labels``).
        dpi: resolution of the written PNG.

    Returns:
        The figure (``fig.axes[0]`` or the ``ax`` given holds the map).
    """
    legend = show_labels if legend is None else legend
    own = ax is None
    if own:
        lo, hi = scene.bounds()
        w, h = max(float(hi[0] - lo[0]), 1.0), max(float(hi[1] - lo[1]), 1.0)
        scale = 9.0 / max(w, h)
        extra = 2.8 if legend else 0.6
        fig = Figure(figsize=(max(4.0, w * scale) + extra, max(3.5, h * scale) + 0.8))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 1, 1)
    else:
        fig = ax.figure
        if fig.canvas is None or not hasattr(fig.canvas, "print_png"):
            FigureCanvasAgg(fig)

    for r in scene.rooms:
        fill = ROOM_COLORS.get(r.label, ROOM_COLORS["other"])
        ax.add_patch(Polygon(np.asarray(r.polygon), closed=True, facecolor=fill, edgecolor="none", zorder=0))
    t_default = 0.1
    for wall in scene.walls:
        if wall.bottom > 1e-6:  # lintels above doors: leave the opening visible
            continue
        ax.add_patch(Polygon(_wall_polygon(wall.start, wall.end, wall.thickness), closed=True,
                             facecolor=_WALL_COLOR, edgecolor=_WALL_COLOR, lw=0.3, zorder=2))
        t_default = wall.thickness
    centroids = {r.id: r.centroid for r in scene.rooms}
    for door in scene.doors:
        _draw_door(ax, door, t_default, centroids.get(door.rooms[0]))

    depth = _support_depth(scene)
    families: dict[str, int] = {}  # family -> instances drawn
    hatched = False
    for inst in sorted(scene.instances, key=lambda i: (i.structural is False, depth.get(i.id, 0), i.bbox.zmax, i.id)):
        if inst.structural and inst.category in ("floor", "ceiling", "room"):
            continue
        if inst.structural and inst.category == "wall":  # imported stages keep mesh walls as instances
            ax.add_patch(Polygon(inst.bbox.footprint(), closed=True, facecolor=_WALL_COLOR, edgecolor=_WALL_COLOR,
                                 lw=0.3, zorder=2))
            continue
        family = category_family(inst.category)
        col = FAMILY_COLORS[family]
        wall_mounted = inst.support is None and inst.position[2] > 0.3
        z = 4 + (1 if wall_mounted else 0) + 2 * depth.get(inst.id, 0)
        ax.add_patch(Polygon(inst.bbox.footprint(), closed=True, facecolor=col, edgecolor="black",
                             lw=0.4, alpha=0.9, zorder=z, hatch="///" if wall_mounted else None))
        if not inst.structural:
            families[family] = families.get(family, 0) + 1
            hatched |= wall_mounted

    if highlight:
        by_id = {i.id: i for i in scene.instances}
        for iid, color in highlight.items():
            inst = by_id[iid]
            ax.add_patch(Polygon(inst.bbox.footprint(), closed=True, facecolor="none", edgecolor=color, lw=2.5,
                                 zorder=10))
            ax.plot([inst.bbox.center[0]], [inst.bbox.center[1]], marker="o", ms=6, color=color, mec="black",
                    mew=0.6, zorder=10)

    if show_labels:
        for r in scene.rooms:
            cx, cy = r.centroid
            ax.text(cx, cy, vocab.ROOM_DISPLAY.get(r.label, r.label), ha="center", va="center", fontsize=8,
                    color="#333333", zorder=11,
                    bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "alpha": 0.6, "edgecolor": "none"})
    if legend:
        handles = [Patch(facecolor=FAMILY_COLORS[f], edgecolor="black", lw=0.4, label=f"{FAMILY_NAMES[f]} ({families[f]})")
                   for f in FAMILY_NAMES if f in families]
        if hatched:
            handles.append(Patch(facecolor="white", edgecolor="black", lw=0.4, hatch="///",
                                 label="hatched: wall-mounted"))
        handles += [Line2D([], [], color=_DOOR_COLOR, lw=1.5, label="door"),
                    Line2D([], [], color=_OPENING_COLOR, lw=1.5, ls="--", label="opening"),
                    Line2D([], [], color=_EXTERIOR_DOOR_COLOR, lw=1.5, label="exterior door")]
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False,
                  borderaxespad=0.0, title="objects (instances)", title_fontsize=8, alignment="left")

    ax.set_aspect("equal")
    ax.autoscale_view()
    lo, hi = scene.bounds()
    pad = 0.3
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(scene.id if title is None else title, fontsize=10)
    if own:
        fig.tight_layout()
    if path is not None:
        save_figure(fig, path, dpi=dpi)
    return fig


def save_figure(fig: Figure, path: str | os.PathLike, dpi: int = 120) -> Path:
    """Write a figure as PNG atomically: to a temporary file in the same
    folder, then renamed over ``path``; a reader never sees a partial file.

    Returns:
        The path written.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    if fig.canvas is None or not hasattr(fig.canvas, "print_png"):
        FigureCanvasAgg(fig)
    tmp = out.parent / f".{out.name}.{os.getpid()}.{uuid.uuid4().hex[:12]}.tmp"
    try:
        with open(tmp, "xb") as fh:  # honours the umask, unlike mkstemp's 0600
            fig.savefig(fh, format="png", dpi=dpi)
        os.replace(tmp, out)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return out
