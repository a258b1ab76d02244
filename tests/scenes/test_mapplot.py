"""Top-down scene maps: PNG output, atomic writes, colours, highlights, caller axes."""

from __future__ import annotations

import os
import struct
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.image import imread

from ignjax.scenes.viz.mapplot import (FAMILY_NAMES, ROOM_COLORS, category_color, category_family, plot_scene_map,
                                      save_figure)
from ignjax.scenes.procgen.generate import HouseParams, generate_house

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@pytest.fixture(scope="module")
def house():
    return generate_house(4, HouseParams(n_rooms=7))


def _png_size(path) -> tuple[int, int]:
    with open(path, "rb") as fh:
        head = fh.read(24)
    assert head[:8] == PNG_MAGIC
    return struct.unpack(">II", head[16:24])


def _has_color(img: np.ndarray, rgb, tol: float = 0.02) -> bool:
    return bool(np.any(np.all(np.abs(img[..., :3] - np.asarray(rgb)) < tol, axis=-1)))


def test_map_png_is_written_for_a_generated_house(house, tmp_path):
    out = tmp_path / "maps" / "house.png"
    fig = plot_scene_map(house, out, dpi=80)
    assert isinstance(fig, Figure)
    assert out.stat().st_size > 10_000
    w, h = _png_size(out)
    assert w > 300 and h > 300
    assert sorted(os.listdir(out.parent)) == ["house.png"]  # no temporary file left behind
    img = imread(out)
    # every room label present in the house shows up as its fill colour
    for label in {r.label for r in house.rooms}:
        assert _has_color(img, to_rgb(ROOM_COLORS[label])), label
    # walls are drawn dark
    assert _has_color(img, to_rgb("#2b2b2b"))
    ax = fig.axes[0]
    assert ax.get_xlabel() == "x (m)" and ax.get_ylabel() == "y (m)"
    assert ax.get_aspect() == 1.0
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    for family in {category_family(c) for c in house.categories()}:  # one entry per family, with its count
        assert any(t.startswith(FAMILY_NAMES[family] + " (") for t in legend), family
    fig.canvas.draw()
    box = ax.get_legend().get_window_extent(fig.canvas.get_renderer())
    assert fig.bbox.x0 <= box.x0 and box.x1 <= fig.bbox.x1 + 0.5  # right of the map, not cut by the figure's edge
    assert box.x0 >= ax.get_window_extent().x1


def test_existing_file_is_replaced_atomically(house, tmp_path):
    out = tmp_path / "map.png"
    out.write_bytes(b"old")
    plot_scene_map(house, out, dpi=50, show_labels=False)
    assert out.read_bytes()[:8] == PNG_MAGIC
    assert os.listdir(tmp_path) == ["map.png"]


def test_failed_write_leaves_no_partial_file(house, tmp_path):
    fig = plot_scene_map(house, dpi=50)
    target = tmp_path / "dir_not_file"
    target.mkdir()
    with pytest.raises(OSError):
        save_figure(fig, target)  # a directory cannot be replaced by a file
    assert os.listdir(tmp_path) == ["dir_not_file"]
    assert os.listdir(target) == []


def test_highlight_draws_the_given_colour_on_top(house, tmp_path):
    target = house.objects[0]
    out_plain, out_hl = tmp_path / "plain.png", tmp_path / "hl.png"
    plot_scene_map(house, out_plain, dpi=60, show_labels=False)
    plot_scene_map(house, out_hl, dpi=60, show_labels=False, highlight={target.id: (0.0, 1.0, 0.0)})
    assert not _has_color(imread(out_plain), (0.0, 1.0, 0.0), tol=0.05)
    assert _has_color(imread(out_hl), (0.0, 1.0, 0.0), tol=0.05)
    with pytest.raises(KeyError):
        plot_scene_map(house, highlight={"no_such_instance": "red"})


def test_draws_into_caller_axes_and_leaves_them_usable(two_room_scene, tmp_path):
    fig = Figure(figsize=(8, 4))
    FigureCanvasAgg(fig)
    ax_left, ax_right = fig.subplots(1, 2)
    got = plot_scene_map(two_room_scene, ax=ax_right, title="two rooms")
    assert got is fig and ax_right.get_title() == "two rooms"
    assert not ax_left.patches  # the other axes are untouched
    # rooms + walls (lintels skipped) + door opening + instances
    n_full_walls = sum(1 for w in two_room_scene.walls if w.bottom == 0)
    assert len(ax_right.patches) >= len(two_room_scene.rooms) + n_full_walls + len(two_room_scene.instances)
    ax_right.plot([1.0, 4.0], [1.0, 3.0], "k--")  # callers can keep drawing
    out = save_figure(fig, tmp_path / "two.png", dpi=50)
    assert out.read_bytes()[:8] == PNG_MAGIC


def test_supported_objects_are_drawn_above_their_support(two_room_scene):
    fig = plot_scene_map(two_room_scene)
    ax = fig.axes[0]
    laptop = two_room_scene.instance("laptop_0")
    table = two_room_scene.instance("table_0")

    def zorder_of(inst):
        fp = inst.bbox.footprint()
        for p in ax.patches:
            if not hasattr(p, "get_xy"):
                continue
            xy = np.asarray(p.get_xy())[:4]
            if xy.shape == fp.shape and np.allclose(xy, fp):
                return p.get_zorder()
        raise AssertionError(f"no patch for {inst.id}")

    assert zorder_of(laptop) > zorder_of(table)


def test_category_colours_are_stable_and_spread():
    names = ["chair", "laptop", "bed", "painting", "dining_table", "sofa", "mug", "book", "vase", "toilet",
             "sink", "desk", "lamp", "rug", "cup", "plate", "bowl", "towel", "pillow", "mirror"]
    colours = [category_color(n) for n in names]
    assert colours == [category_color(n) for n in names]
    assert len(set(colours)) >= 12
    # the same in another process with another string-hash seed
    code = "from ignjax.scenes.viz.mapplot import category_color as c; print([c(n) for n in %r])" % (names,)
    env = dict(os.environ, PYTHONHASHSEED="999", PYTHONPATH=ROOT)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True, cwd=ROOT)
    assert out.stdout.strip() == str(colours)
