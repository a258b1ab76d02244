"""The Planner panel and the Grounder image (ignjax.sim.views.compose):
layouts, where each view's pixels land, the static overlay, the 8x8 grid's
pixel boxes against ``geometry.grid_to_pixel``, batch == per-row."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ignjax.errors import ConfigError
from ignjax.protocol import VIEW_NAMES
from ignjax.sim.geometry import grid_to_pixel
from ignjax.sim.views.compose import (BLANK, cell_pixel_box, grounder_images, grounder_overlay, panel_layout,
                                      panel_overlay, planner_panels, view_names)

S = 64


def solid_views(n_views: int, rows: int = 2, size: int = S) -> tuple[np.ndarray, np.ndarray]:
    """(rows, n_views, size, size, 3) views, view k of row i one solid colour (all distinct)."""
    colours = np.array([[(37 * k + 11 * i) % 256, (90 + 53 * k) % 256, (200 + 29 * i + 7 * k) % 256]
                        for i in range(rows) for k in range(n_views)], np.uint8).reshape(rows, n_views, 3)
    views = np.broadcast_to(colours[:, :, None, None, :], (rows, n_views, size, size, 3)).copy()
    return views, colours


def cell(panel: np.ndarray, r: int, c: int, size: int = S) -> np.ndarray:
    return panel[..., r * size:(r + 1) * size, c * size:(c + 1) * size, :]


def test_view_names():
    assert view_names(8) == VIEW_NAMES
    assert view_names(4) == ("front", "left", "rear", "right")
    names12 = view_names(12)
    assert len(set(names12)) == 12 and names12[0] == "front" and names12[3] == "left" and names12[6] == "rear"
    assert names12[9] == "right" and names12[1] == "left 30" and names12[11] == "right 30"
    for bad in (0, 6, 16, True):
        with pytest.raises(ConfigError, match="views.n_views"):
            view_names(bad)


@pytest.mark.parametrize("n_views", [4, 8, 12])
def test_layout_is_a_top_down_map(n_views):
    rows, cols, slots = panel_layout(n_views)
    assert (rows, cols) == ((3, 5) if n_views == 12 else (3, 3))
    assert len(slots) == n_views == len(set(slots))
    centre = {(1, c) for c in range(1, cols - 1)}
    assert not centre & set(slots)
    # bearing of each slot from the sheet centre, counter-clockwise from "up" (front), grows with k
    bearings = [math.degrees(math.atan2(-(c - (cols - 1) / 2), (rows - 1) / 2 - r)) % 360 for r, c in slots]
    assert bearings == sorted(bearings) and bearings[0] == 0.0
    for k, b in enumerate(bearings):
        assert abs(b - k * 360 / n_views) < 35, (k, b)


def test_layout_cells():
    assert panel_layout(8)[2] == ((0, 1), (0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2))
    assert panel_layout(4)[2] == ((0, 1), (1, 0), (2, 1), (1, 2))
    slots12 = panel_layout(12)[2]
    assert [slots12[k] for k in (2, 1, 0, 11, 10)] == [(0, 0), (0, 1), (0, 2), (0, 3), (0, 4)]  # top row
    assert [slots12[k] for k in (4, 5, 6, 7, 8)] == [(2, 0), (2, 1), (2, 2), (2, 3), (2, 4)]  # bottom row
    assert slots12[3] == (1, 0) and slots12[9] == (1, 4)


@pytest.mark.parametrize("n_views", [4, 8, 12])
def test_views_land_in_their_slots(n_views):
    views, colours = solid_views(n_views)
    rows, cols, slots = panel_layout(n_views)
    panel = planner_panels(views)
    assert panel.shape == (2, rows * S, cols * S, 3) and panel.dtype == np.uint8
    alpha = panel_overlay(n_views, S).alpha
    for k, (r, c) in enumerate(slots):
        clear = cell(alpha[..., None], r, c)[..., 0] == 0
        assert clear.mean() > 0.5
        for i in range(2):
            got = cell(panel[i], r, c)
            same = np.all(got == colours[i, k], axis=-1)
            assert np.all(same[clear]), (k, i)  # untouched wherever the overlay is transparent
            for gc, gr in ((4, 4), (5, 5), (4, 5), (5, 4)):  # the middle of the slot carries view k
                u0, v0, u1, v1 = cell_pixel_box(gc, gr, S)
                assert same[v0 + 1:v1 - 1, u0 + 1:u1 - 1].all(), (k, i)


@pytest.mark.parametrize("n_views", [4, 8, 12])
def test_overlay_only_on_slots_decorations(n_views):
    """Without grid and labels, a view's only decoration is its separator ring."""
    views, colours = solid_views(n_views, rows=1)
    rows, cols, slots = panel_layout(n_views)
    bare = planner_panels(views, grid=False, labels=False)
    full = planner_panels(views)
    for k, (r, c) in enumerate(slots):
        same = np.all(cell(bare[0], r, c) == colours[0, k], axis=-1)
        assert same[1:-1, 1:-1].all() and not same[0].any() and not same[-1].any()
        assert (cell(full[0], r, c) != cell(bare[0], r, c)).any()  # grid/labels drawn
    a = panel_overlay(n_views, S).alpha
    b = panel_overlay(n_views, S, grid=False, labels=False).alpha
    assert np.all(b[a == 0] == 0)


def test_four_views_leave_the_corners_blank():
    views, _ = solid_views(4, rows=3)
    panel = planner_panels(views)
    for r, c in ((0, 0), (0, 2), (2, 0), (2, 2)):
        corner = cell(panel, r, c)
        assert np.all(corner[:, 1:-1, 1:-1] == BLANK)
        assert np.all(corner == corner[:1])


@pytest.mark.parametrize("n_views", [4, 8, 12])
def test_centre_cell_is_the_same_for_every_row(n_views):
    rng = np.random.default_rng(n_views)
    views = rng.integers(0, 256, (3, n_views, S, S, 3), dtype=np.uint8)
    rows, cols, _ = panel_layout(n_views)
    panel = planner_panels(views)
    centre = panel[:, S:2 * S, S:(cols - 1) * S]
    assert np.all(centre == centre[:1])
    other = planner_panels(rng.integers(0, 256, (1, n_views, S, S, 3), dtype=np.uint8))
    assert np.array_equal(other[0, S:2 * S, S:(cols - 1) * S], centre[0])
    assert len(np.unique(centre[0].reshape(-1, 3), axis=0)) > 2  # arrows and text on the background


@pytest.mark.parametrize("n_views", [4, 8, 12])
def test_batch_equals_rows_and_is_deterministic(n_views):
    rng = np.random.default_rng(7)
    views = rng.integers(0, 256, (3, n_views, 96, 96, 3), dtype=np.uint8)
    batch = planner_panels(views)
    single = np.concatenate([planner_panels(views[i:i + 1]) for i in range(3)])
    assert np.array_equal(batch, single)
    assert planner_panels(views).tobytes() == batch.tobytes()
    assert np.array_equal(planner_panels(views[::-1])[::-1], batch)


def test_panel_rejects_bad_input():
    views, _ = solid_views(8, rows=1)
    with pytest.raises(ConfigError, match="views.images"):
        planner_panels(views.astype(np.float32))
    with pytest.raises(ConfigError, match="views.images"):
        planner_panels(views[:, :, :, :32])
    with pytest.raises(ConfigError, match="views.n_views"):
        planner_panels(views[:, :5])
    with pytest.raises(ConfigError, match="views.size"):
        planner_panels(views[:, :, :32, :32])


# -- the Grounder's 8x8 grid --------------------------------------------------

@pytest.mark.parametrize("size", [64, 224, 448])
def test_cell_boxes_tile_the_image_and_hold_grid_to_pixel(size):
    assert cell_pixel_box(1, 1, size)[0] == 0 and cell_pixel_box(1, 1, size)[3] == size  # bottom-left
    assert cell_pixel_box(8, 8, size)[2] == size and cell_pixel_box(8, 8, size)[1] == 0  # top-right
    cover = np.zeros((size, size), int)
    cols, rows = np.meshgrid(np.arange(1, 9), np.arange(1, 9), indexing="ij")
    uv = np.asarray(grid_to_pixel(cols.ravel(), rows.ravel(), size, size))
    for (c, r), u, v in zip(zip(cols.ravel(), rows.ravel()), uv[0], uv[1]):
        u0, v0, u1, v1 = cell_pixel_box(c, r, size)
        cover[v0:v1, u0:u1] += 1
        assert u0 <= u < u1 and v0 <= v < v1, (c, r, size)
    assert np.all(cover == 1)


def test_cell_box_rejects_bad_cells():
    for col, row, where in ((0, 1, "views.grid.col"), (9, 1, "views.grid.col"), (1, 0, "views.grid.row"),
                            (1, 9, "views.grid.row"), (1.5, 1, "views.grid.col")):
        with pytest.raises(ConfigError, match=where):
            cell_pixel_box(col, row, 224)


@pytest.mark.parametrize("size", [64, 224, 448])
def test_grid_lines_fall_on_cell_boundaries(size):
    img = grounder_images(np.zeros((1, size, size, 3), np.uint8), numbers=False)[0]
    lit = img.any(axis=-1)
    w = max(1, size // 224)
    for c in range(1, 9):
        for r in range(1, 9):
            u0, v0, u1, v1 = cell_pixel_box(c, r, size)
            if u0 > 0:
                assert lit[:, u0].all()  # the box's left edge is a grid line
            if v1 < size:
                assert lit[v1].all()  # and the line below it is the top edge of the cell below
            assert not lit[v0 + w:v1 - w, u0 + w:u1 - w].any()  # the inside is untouched
    u0, v0, u1, v1 = cell_pixel_box(1, 1, size)
    assert (u0, v1) == (0, size) and lit[v0, :u1].all() and lit[v0:, u1].all()


@pytest.mark.parametrize("size", [224, 448])
def test_grounder_numbers_sit_on_the_bottom_row_and_left_column(size):
    rng = np.random.default_rng(size)
    views = rng.integers(0, 256, (2, size, size, 3), dtype=np.uint8)
    plain = grounder_images(views, numbers=False)
    numbered = grounder_images(views)
    diff = (numbered != plain).any(axis=-1)
    _, bottom, left, _ = cell_pixel_box(1, 1, size)
    rr, cc = np.nonzero(diff.any(axis=0))
    assert np.all((rr >= bottom) | (cc < left))
    for i in range(1, 9):
        u0, v0, u1, v1 = cell_pixel_box(i, 1, size)
        assert diff[:, v0:v1, u0:u1].any(axis=(1, 2)).all()  # column number i
        u0, v0, u1, v1 = cell_pixel_box(1, i, size)
        assert diff[:, v0:v1, u0:u1].any(axis=(1, 2)).all()  # row number i
    # numbers differ from one another
    boxes = [cell_pixel_box(i, 1, size) for i in range(2, 9)]
    glyphs = {grounder_overlay(size).alpha[v0:v1, u0:u1].tobytes() for u0, v0, u1, v1 in boxes}
    assert len(glyphs) == 7


def test_grounder_batch_equals_rows_and_leaves_input():
    rng = np.random.default_rng(3)
    views = rng.integers(0, 256, (3, 224, 224, 3), dtype=np.uint8)
    before = views.copy()
    out = grounder_images(views)
    assert out.shape == views.shape and out.dtype == np.uint8
    assert np.array_equal(views, before)
    assert np.array_equal(out, np.concatenate([grounder_images(views[i:i + 1]) for i in range(3)]))
    with pytest.raises(ConfigError, match="views.images"):
        grounder_images(views[0])
