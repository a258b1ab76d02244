"""The two images the paper's agents read: the Planner's panel and the
Grounder's numbered view.

Conventions (``ignjax.protocol``, ``ignjax.sim.geometry``): view ``k`` of
``N`` looks along ``heading + k * 360/N`` degrees, counter-clockwise, so view
1 of 8 is front-left. Images are ``uint8`` arrays ``(..., H, W, 3)``; views
are square, ``S x S`` with ``64 <= S <= 1024``. The Grounder's grid is 8 x 8:
columns 1..8 left to right, rows 1..8 bottom to top; cell ``(c, r)`` covers
the half-open pixel box :func:`cell_pixel_box`, which holds its centre pixel
``grid_to_pixel(c, r)``. A grid line is ``w = max(1, S // 224)`` px wide
and covers pixels ``b - w//2 .. b - w//2 + w - 1`` of each inner boundary
``b = floor(i * S / 8)``, so a 1 px line is the first pixel row/column of
the cell after it.

Planner panel (:func:`planner_panels`), read as a top-down map, front up and
left left. Each cell is ``S x S`` (the panel is ``rows*S x cols*S``); ``.``
is a blank cell, ``[centre]`` the agent's orientation::

    8 views, 3 x 3:   front-left  front     front-right
                      left        [centre]  right
                      rear-left   rear      rear-right

    4 views, 3 x 3:   .     front     .
                      left  [centre]  right
                      .     rear      .

    12 views, 3 x 5:  left 60   left 30   front     right 30   right 60
                      left      [centre spans 3 cells]         right
                      left 120  left 150  rear      right 150  right 120

Labels (:func:`view_names`): 8 views use ``protocol.VIEW_NAMES``; 4 views
"front", "left", "rear", "right"; 12 views "front", "left 30", "left 60",
"left", "left 120", "left 150", "rear", "right 150", ..., "right 30" (the
number is the angle from the front in degrees). Each view carries its name in
a dark box at its top-left and, optionally, its 8 x 8 grid as faint lines; a
thin light separator rings every cell. The centre cell(s) show the agent's
orientation on a plain dark background: a yellow arrow up labelled "front"
and white arrows labelled "left", "right" and "rear". The corners of the
4-view sheet are plain black.

Grounder image (:func:`grounder_images`): the view with its 8 x 8 grid in
yellow lines, column numbers 1..8 along the bottom edge (left to right) and
row numbers 1..8 along the left edge (bottom to top), each in a dark box.
Text uses Pillow's built-in font (``ImageFont.load_default(size=...)``).

Everything drawn is the same for every image of a given ``(N, S)`` and
options, so it is rendered once with Pillow as an overlay (colour ``(H, W,
3)`` and alpha ``(H, W)``, plus the flat indices of its covered pixels in
the view cells) and blended into the whole batch with numpy broadcasting and
integer arithmetic (bit-for-bit deterministic). Overlays are cached per
``(N, S, options)`` (at most 16 entries, :func:`overlay_cache_info`): each
costs ``4 * H * W`` bytes for colour and alpha plus 12 bytes per covered
view pixel, e.g. 2.3 MB for an 8-view panel of 224 px views and 9.2 MB at
448 px (3.7 / 14.9 MB for 12 views); a cache full of 1024 px 12-view
panels would hold about 16 x 77 MB.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from ignjax.errors import ConfigError
from ignjax.protocol import GRID_CELLS, VIEW_NAMES
from ignjax.sim.views.config import MAX_SIZE, MIN_SIZE

CENTRE_BACKGROUND = (40, 40, 40)
BLANK = (0, 0, 0)
SEPARATOR = (200, 200, 200)
FRONT_ARROW = (255, 200, 0)

_NAMES = {
    4: ("front", "left", "rear", "right"),
    8: VIEW_NAMES,
    12: ("front", "left 30", "left 60", "left", "left 120", "left 150",
         "rear", "right 150", "right 120", "right", "right 60", "right 30"),
}
_SLOTS = {
    4: ((0, 1), (1, 0), (2, 1), (1, 2)),
    8: ((0, 1), (0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2)),
    12: ((0, 2), (0, 1), (0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (2, 3), (2, 4), (1, 4), (0, 4), (0, 3)),
}


class Overlay(NamedTuple):
    """A pre-rendered overlay: ``colour`` (H, W, 3) uint8 and ``alpha`` (H, W)
    uint8 (0 transparent, 255 opaque); ``idx`` the flat indices of the
    covered pixels inside view cells, ``inv_alpha`` (n, 1) and ``colour_alpha``
    (n, 3) their blend terms (uint16). All arrays are read-only."""
    colour: np.ndarray
    alpha: np.ndarray
    idx: np.ndarray
    inv_alpha: np.ndarray
    colour_alpha: np.ndarray

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in self)


def view_names(n_views: int) -> tuple[str, ...]:
    """Direction names of the ``n_views`` views (4, 8 or 12), view k first.

    Raises:
        ConfigError: ``views.n_views`` is not 4, 8 or 12.
    """
    if n_views not in _NAMES or isinstance(n_views, bool):
        raise ConfigError(None, "views.n_views", f"{n_views!r} views: must be 4, 8 or 12")
    return _NAMES[n_views]


def panel_layout(n_views: int) -> tuple[int, int, tuple[tuple[int, int], ...]]:
    """The Planner panel's sheet for ``n_views`` views.

    Returns:
        (rows, cols, slots): ``slots[k] = (row, col)`` of view k (row 0 at
        the top). The orientation cells are row 1, columns 1..cols-2; the
        remaining cells (the corners of the 4-view sheet) are blank.
    """
    view_names(n_views)
    slots = _SLOTS[n_views]
    return 3, 1 + max(c for _, c in slots), slots


def cell_pixel_box(col: int, row: int, size: int) -> tuple[int, int, int, int]:
    """Half-open pixel box ``(u0, v0, u1, v1)`` of grid cell (col, row), both
    1..8, on a ``size x size`` image (u right, v down): the cell is pixels
    ``u0 <= u < u1``, ``v0 <= v < v1``; boundaries are ``floor(i * size / 8)``.

    Raises:
        ConfigError: col or row is outside 1..8.
    """
    for name, x in (("col", col), ("row", row)):
        if isinstance(x, bool) or int(x) != x or not 1 <= x <= GRID_CELLS:
            raise ConfigError(None, f"views.grid.{name}", f"{x!r}: must be an integer in 1..{GRID_CELLS}")
    col, row, size = int(col), int(row), int(size)
    top = GRID_CELLS - row
    return ((col - 1) * size // GRID_CELLS, top * size // GRID_CELLS,
            col * size // GRID_CELLS, (top + 1) * size // GRID_CELLS)


def _font(px: int):
    return ImageFont.load_default(size=px)


def _grid_lines(draw, ox: int, oy: int, size: int, fill) -> None:
    w = max(1, size // 224)
    for i in range(1, GRID_CELLS):
        b = i * size // GRID_CELLS - w // 2
        draw.rectangle([ox + b, oy, ox + b + w - 1, oy + size - 1], fill=fill)
        draw.rectangle([ox, oy + b, ox + size - 1, oy + b + w - 1], fill=fill)


def _text_box(draw, xy, text: str, font, anchor: str, pad: int, box=(0, 0, 0, 170), fill=(255, 255, 255, 255)):
    x0, y0, x1, y1 = draw.textbbox(xy, text, font=font, anchor=anchor)
    draw.rectangle([x0 - pad, y0 - pad, x1 + pad - 1, y1 + pad - 1], fill=box)
    draw.text(xy, text, font=font, anchor=anchor, fill=fill)


def _arrow(draw, x0, y0, x1, y1, width: int, head: int, fill) -> None:
    draw.line([x0, y0, x1, y1], fill=fill, width=width)
    dx, dy = np.sign(x1 - x0), np.sign(y1 - y0)
    px, py = -dy, dx  # perpendicular
    draw.polygon([(x1 + dx * head, y1 + dy * head), (x1 + px * head, y1 + py * head),
                  (x1 - px * head, y1 - py * head)], fill=fill)


def _orientation(width: int, height: int, size: int) -> Image.Image:
    """The centre cell(s): the agent's heading as arrows, on its own image so nothing spills over."""
    im = Image.new("RGBA", (width, height), CENTRE_BACKGROUND + (255,))
    draw = ImageDraw.Draw(im)
    cx, cy = width // 2, height // 2
    font = _font(max(8, size // 14))
    r, width_px, head, gap = size // 20, max(2, size // 56), max(4, size // 28), max(2, size // 64)
    text_w = max(draw.textlength(t, font=font) for t in ("left", "right"))
    text_h = draw.textbbox((0, 0), "front", font=font)[3]
    reach = int(min(size * 0.22, cx - text_w - head - gap - 2, cy - text_h - head - gap - 2))
    reach = max(reach, r + head)
    white = (255, 255, 255, 255)
    draw.ellipse([cx - r, cy - r, cx + r, cy + r], fill=white)
    for (dx, dy), text, anchor, colour in (((0, -1), "front", "mb", FRONT_ARROW + (255,)), ((0, 1), "rear", "mt", white),
                                           ((-1, 0), "left", "rm", white), ((1, 0), "right", "lm", white)):
        _arrow(draw, cx + dx * r, cy + dy * r, cx + dx * reach, cy + dy * reach, width_px, head, colour)
        draw.text((cx + dx * (reach + head + gap), cy + dy * (reach + head + gap)), text, font=font, anchor=anchor,
                  fill=colour)
    return im


def _separator(draw, x0: int, y0: int, size_x: int, size_y: int, size: int) -> None:
    draw.rectangle([x0, y0, x0 + size_x - 1, y0 + size_y - 1], outline=SEPARATOR + (255,), width=max(1, size // 224))


def _finish(sheet: Image.Image, view_mask: np.ndarray) -> Overlay:
    rgba = np.asarray(sheet)
    colour, alpha = np.ascontiguousarray(rgba[..., :3]), np.ascontiguousarray(rgba[..., 3])
    idx = np.flatnonzero((alpha > 0) & view_mask).astype(np.int32 if alpha.size < 2**31 else np.int64)
    a = alpha.reshape(-1)[idx].astype(np.uint16)[:, None]
    ca = colour.reshape(-1, 3)[idx].astype(np.uint16) * a
    out = Overlay(colour, alpha, idx, (255 - a).astype(np.uint16), ca)
    for arr in out:
        arr.setflags(write=False)
    return out


def panel_overlay(n_views: int, size: int, *, grid: bool = True, labels: bool = True) -> Overlay:
    """The Planner panel's overlay for ``n_views`` views of ``size`` px (cached)."""
    view_names(n_views)
    return _panel_overlay(int(n_views), _check_size(size), bool(grid), bool(labels))


@functools.lru_cache(maxsize=16)
def _panel_overlay(n_views: int, size: int, grid: bool, labels: bool) -> Overlay:
    rows, cols, slots = panel_layout(n_views)
    names = view_names(n_views)
    W, H = cols * size, rows * size
    sheet = Image.new("RGBA", (W, H), (0, 0, 0, 0))
    view_mask = np.zeros((H, W), bool)
    layers = {name: Image.new("RGBA", (W, H), (0, 0, 0, 0)) for name in ("grid", "labels", "sep")}
    draws = {name: ImageDraw.Draw(im) for name, im in layers.items()}
    base = ImageDraw.Draw(sheet)
    font, pad = _font(max(10, size // 14)), max(2, size // 64)
    for k, (r, c) in enumerate(slots):
        ox, oy = c * size, r * size
        view_mask[oy:oy + size, ox:ox + size] = True
        if grid:
            _grid_lines(draws["grid"], ox, oy, size, (255, 255, 255, 90))
        if labels:
            off = max(1, size // 224) + pad
            _text_box(draws["labels"], (ox + off, oy + off), names[k], font, "lt", pad)
        _separator(draws["sep"], ox, oy, size, size, size)
    for r in range(rows):
        for c in range(cols):
            if (r, c) not in slots and not (r == 1 and 1 <= c <= cols - 2):
                base.rectangle([c * size, r * size, (c + 1) * size - 1, (r + 1) * size - 1], fill=BLANK + (255,))
                _separator(draws["sep"], c * size, r * size, size, size, size)
    sheet.paste(_orientation((cols - 2) * size, size, size), (size, size))
    _separator(draws["sep"], size, size, (cols - 2) * size, size, size)
    for name in ("grid", "labels", "sep"):
        sheet = Image.alpha_composite(sheet, layers[name])
    return _finish(sheet, view_mask)


def grounder_overlay(size: int, *, numbers: bool = True) -> Overlay:
    """The Grounder image's overlay for a ``size`` px view (cached)."""
    return _grounder_overlay(_check_size(size), bool(numbers))


@functools.lru_cache(maxsize=16)
def _grounder_overlay(size: int, numbers: bool) -> Overlay:
    sheet = Image.new("RGBA", (size, size), (0, 0, 0, 0))
    _grid_lines(ImageDraw.Draw(sheet), 0, 0, size, (255, 230, 0, 200))
    if numbers:
        layer = Image.new("RGBA", (size, size), (0, 0, 0, 0))
        draw = ImageDraw.Draw(layer)
        font, pad = _font(max(9, round(size / 18))), max(1, size // 112)
        edge = max(1, size // 224) + pad
        for i in range(1, GRID_CELLS + 1):
            u0, v0, u1, v1 = cell_pixel_box(1, i, size)  # row i, left column
            row_xy = (edge, (v0 + v1) // 2)
            _text_box(draw, row_xy, str(i), font, "lm", pad)
            u0, v0, u1, v1 = cell_pixel_box(i, 1, size)  # column i, bottom row
            col_xy = ((u0 + u1) // 2, size - edge)
            if i == 1:  # keep column 1's number clear of row 1's, right of it
                right = draw.textbbox(row_xy, "1", font=font, anchor="lm")[2] + 2 * pad
                col_xy = (col_xy[0] + max(0, right - draw.textbbox(col_xy, "1", font=font, anchor="ms")[0]), col_xy[1])
            _text_box(draw, col_xy, str(i), font, "ms", pad)
        sheet = Image.alpha_composite(sheet, layer)
    return _finish(sheet, np.ones((size, size), bool))


def overlay_cache_info() -> dict:
    """Entries, hits and misses of the two overlay caches (panel, grounder)."""
    out = {}
    for name, fn in (("panel", _panel_overlay), ("grounder", _grounder_overlay)):
        info = fn.cache_info()
        out[name] = {"entries": info.currsize, "hits": info.hits, "misses": info.misses, "max_entries": info.maxsize}
    return out


def _check_size(size) -> int:
    if isinstance(size, bool) or int(size) != size or not MIN_SIZE <= size <= MAX_SIZE:
        raise ConfigError(None, "views.size", f"{size!r} px: views must be square, {MIN_SIZE}..{MAX_SIZE} px")
    return int(size)


def _check_views(views, ndim: int, what: str) -> np.ndarray:
    views = np.asarray(views)
    if views.dtype != np.uint8:
        raise ConfigError(None, "views.images", f"{what} must be uint8, got {views.dtype}")
    if views.ndim != ndim or views.shape[-1] != 3 or views.shape[-2] != views.shape[-3]:
        raise ConfigError(None, "views.images", f"{what} must be {'(R, N, S, S, 3)' if ndim == 5 else '(R, S, S, 3)'}"
                          f" square RGB views, got shape {views.shape}")
    _check_size(views.shape[-2])
    return views


def _blend(canvas: np.ndarray, ov: Overlay) -> None:
    """Blend ``ov`` over its covered view pixels of ``canvas`` (R, H, W, 3), C-contiguous, in place."""
    flat = canvas.reshape(canvas.shape[0], -1, 3)
    v = np.take(flat, ov.idx, axis=1).astype(np.uint16)  # (R, n, 3); at most 255 * 255 + 127 below
    v *= ov.inv_alpha
    v += ov.colour_alpha
    v += 127
    v //= 255
    flat[:, ov.idx] = v


def planner_panels(views, *, grid: bool = True, labels: bool = True) -> np.ndarray:
    """The Planner's panel of every row of a batch.

    Args:
        views: (R, N, S, S, 3) uint8, view k of row i at ``views[i, k]``.
        grid: draw each view's 8 x 8 grid lines.
        labels: draw each view's direction name.

    Returns:
        (R, rows*S, cols*S, 3) uint8 panels laid out by :func:`panel_layout`.

    Raises:
        ConfigError: bad dtype/shape (``views.images``), N not 4/8/12
            (``views.n_views``) or S outside 64..1024 (``views.size``).
    """
    views = _check_views(views, 5, "panel views")
    R, N, S = views.shape[:3]
    rows, cols, slots = panel_layout(N)
    ov = panel_overlay(N, S, grid=grid, labels=labels)
    out = np.empty((R, rows * S, cols * S, 3), np.uint8)
    for k, (r, c) in enumerate(slots):
        out[:, r * S:(r + 1) * S, c * S:(c + 1) * S] = views[:, k]
    for r in range(rows):
        for c in range(cols):
            if (r, c) not in slots:
                out[:, r * S:(r + 1) * S, c * S:(c + 1) * S] = ov.colour[r * S:(r + 1) * S, c * S:(c + 1) * S]
    _blend(out, ov)
    return out


def grounder_images(views, *, numbers: bool = True) -> np.ndarray:
    """The Grounder's image of every row of a batch: the selected view with
    its 8 x 8 grid drawn and, optionally, numbered.

    Args:
        views: (R, S, S, 3) uint8.
        numbers: column numbers 1..8 along the bottom, row numbers 1..8 along
            the left edge (bottom to top).

    Returns:
        (R, S, S, 3) uint8, a new array.
    """
    views = _check_views(views, 4, "grounder views")
    out = np.array(views, np.uint8, copy=True, order="C")
    _blend(out, grounder_overlay(views.shape[1], numbers=numbers))
    return out


__all__ = ["view_names", "panel_layout", "cell_pixel_box", "planner_panels", "grounder_images", "panel_overlay",
           "grounder_overlay", "overlay_cache_info", "Overlay", "MIN_SIZE", "MAX_SIZE", "CENTRE_BACKGROUND", "BLANK",
           "SEPARATOR"]
