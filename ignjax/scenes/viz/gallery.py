"""A labelled picture of the whole object catalogue, for checking by eye.

``python -m ignjax.scenes.viz.gallery --out docs/catalogue.png [--size 160]``
renders one instance of every category of :data:`catalogue.CATALOGUE` with
default attributes (medium size, colour and material left unset so that
each builder shows its own default look; ``--sampled`` draws them as
procedural houses do), plus one tile per state for categories that have
states, and writes them as a grid under a title line, with a caption under each
tile (wrapped, never cut).

Each tile is its own minimal scene: one square room with a floor, the
object at the origin facing +x and, for objects that stand against or hang
on a wall, that wall behind it. The camera looks at the object's box from
the front-left, above, at a distance that fits the box in view, so a cup
and a wardrobe fill their tiles alike (compare sizes with the numbers in
the caption, the box's largest dimension in centimetres).

Rendering uses :func:`ignjax.scenes.viz.render.render_rgb` (MuJoCo's offscreen
renderer; headless through EGL, ``MUJOCO_GL=egl`` by default).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from typing import Iterable, Sequence

import numpy as np
from PIL import Image, ImageDraw, ImageFont
from tqdm import tqdm

from ignjax.scenes.viz import headless_gl

if __name__ == "__main__":  # before anything imports mujoco, which reads MUJOCO_GL once
    headless_gl()

from ignjax.scenes.compile import compile_scene  # noqa: E402
from ignjax.scenes.model import Attributes, Room, Scene, SceneMeta, Wall  # noqa: E402
from ignjax.scenes.procgen import catalogue as cat  # noqa: E402
from ignjax.scenes.viz.render import render_rgb  # noqa: E402

FOVY = 40.0
"""Vertical field of view of the gallery camera, degrees."""


def gallery_items(names: Iterable[str] | None = None, sampled: bool = False, seed: int = 0) -> list[tuple[str, str, Attributes]]:
    """(caption, category, attributes) of every tile, in catalogue order.

    Args:
        names: categories to include (default: all of them).
        sampled: draw colour and material as procedural houses do
            (:meth:`CategorySpec.sample_attributes`) instead of leaving them
            unset, which shows each builder's own default look.
        seed: seed of the attribute draws.
    """
    chosen = list(cat.CATALOGUE) if names is None else list(names)
    rng = np.random.default_rng(seed)
    out = []
    for name in chosen:
        spec = cat.CATALOGUE[name]
        size = "medium" if "medium" in spec.sizes else spec.sizes[0]
        drawn = spec.sample_attributes(rng) if sampled else Attributes()
        for state in spec.states or (None,):
            attrs = Attributes(drawn.color, drawn.material, size, state)
            caption = name.replace("_", " ") + (f" ({state})" if state else "")
            out.append((caption, name, attrs))
    return out


def object_scene(category: str, attrs: Attributes, seed: int = 0) -> tuple[Scene, cat.Built, float]:
    """A one-room scene holding one object at the origin (front +x).

    Returns:
        The scene, the built object and the height of its base (the mount
        height for wall objects, else 0).
    """
    spec = cat.CATALOGUE[category]
    built = spec.build(attrs, np.random.default_rng(seed))
    hx, hy, hz = built.half_extents
    z0 = spec.mount_height if spec.placement == "wall" else 0.0
    r = max(4.0, 6.0 * max(hx, hy, hz) + 2.0)
    room = Room("room", "living_room", ((-r, -r), (r, -r), (r, r), (-r, r)), "gallery")
    walls = ()
    if spec.placement in ("wall", "floor_wall"):
        x = -hx - 0.05
        walls = (Wall("back", (x, -r), (x, r), 0.1, max(2.5, z0 + 2 * hz + 0.3), 0.0, ("room",)),)
    inst = cat.instantiate("obj", category, attrs, built, (0.0, 0.0, z0), 0.0, room="room")
    scene = Scene(f"gallery_{category}", (room,), (), walls, (inst,), SceneMeta(source="gallery", source_format="procgen"))
    return scene, built, z0


def camera_for(built: cat.Built, z0: float, fovy: float = FOVY) -> tuple[np.ndarray, np.ndarray]:
    """Eye and target that frame an object's box from the front-left, above.

    Flat objects (rugs, plates, books) are seen from higher up.
    """
    hx, hy, hz = built.half_extents
    target = np.array([0.0, 0.0, z0 + hz])
    radius = math.sqrt(hx * hx + hy * hy + hz * hz)
    dist = radius / math.sin(math.radians(fovy) / 2) * 1.02
    flat = 1.0 - min(1.0, hz / max(hx, hy))
    elev = math.radians(18.0 + 40.0 * flat)
    azim = math.radians(32.0)
    eye = target + dist * np.array([math.cos(elev) * math.cos(azim), math.cos(elev) * math.sin(azim), math.sin(elev)])
    return eye, target


def render_tile(category: str, attrs: Attributes, size: int = 160, seed: int = 0) -> np.ndarray:
    """RGB image (size, size, 3) uint8 of one object."""
    scene, built, z0 = object_scene(category, attrs, seed)
    compiled = compile_scene(scene)
    eye, target = camera_for(built, z0)
    return render_rgb(compiled.model, compiled.data, eye, target, fovy=FOVY, width=size, height=size)


def _caption_font(size: int):
    px = max(9, size // 13)
    try:
        return ImageFont.load_default(size=px)
    except TypeError:  # Pillow < 10.1 has a single bitmap font size
        return ImageFont.load_default()


def wrap_caption(draw, caption: str, font, width: int) -> list[str]:
    """The caption's lines (its own line breaks kept), each broken at spaces
    to fit ``width`` pixels; a single word wider than that is the only thing
    cut (with an ellipsis)."""
    lines: list[str] = []
    for part in caption.split("\n"):
        line = ""
        for word in part.split(" "):
            trial = f"{line} {word}" if line else word
            if line and draw.textlength(trial, font=font) > width:
                lines.append(line)
                line = word
            else:
                line = trial
        lines.append(line)
    out = []
    for line in lines:
        while draw.textlength(line, font=font) > width and len(line) > 2:
            line = line[:-2] + "…"
        out.append(line)
    return out


def compose(tiles: Sequence[tuple[str, np.ndarray]], size: int, cols: int | None = None, title: str | None = None):
    """Arrange captioned tiles in a grid, under an optional title line;
    captions wrap onto as many lines as the longest needs (every row the
    same height); returns a ``PIL.Image``."""
    n = len(tiles)
    cols = cols or max(1, min(n, int(math.ceil(math.sqrt(n * 1.6)))))
    rows = int(math.ceil(n / cols))
    pad = 4
    font = _caption_font(size)
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    wrapped = [wrap_caption(probe, caption, font, size - 4) for caption, _ in tiles]
    line_h = int(math.ceil(font.size * 1.25)) if hasattr(font, "size") else 12
    cap = line_h * max([len(w) for w in wrapped] + [1]) + 2
    width = cols * (size + pad) + pad
    title_font = _caption_font(int(size * 1.8))
    title_h = int(math.ceil(title_font.size * 1.3)) if hasattr(title_font, "size") else 16
    title_lines = wrap_caption(probe, title, title_font, width - 2 * pad) if title else []
    top = title_h * len(title_lines) + (pad if title_lines else 0)
    img = Image.new("RGB", (width, top + rows * (size + cap + pad) + pad), (255, 255, 255))
    draw = ImageDraw.Draw(img)
    for j, line in enumerate(title_lines):
        draw.text((pad + 2, pad + j * title_h), line, fill=(0, 0, 0), font=title_font)
    for k, ((_, tile), lines) in enumerate(zip(tiles, wrapped)):
        r, c = divmod(k, cols)
        x, y = pad + c * (size + pad), top + pad + r * (size + cap + pad)
        img.paste(Image.fromarray(np.asarray(tile, dtype=np.uint8)), (x, y))
        for j, line in enumerate(lines):
            draw.text((x + 2, y + size + 1 + j * line_h), line, fill=(20, 20, 20), font=font)
    return img


def render_gallery(out, size: int = 160, names: Iterable[str] | None = None, cols: int | None = None, seed: int = 0,
                   progress: bool = False, sampled: bool = False) -> list[tuple[str, np.ndarray]]:
    """Render the catalogue (or ``names``) and write the grid PNG to ``out``.

    The PNG is written to a temporary name next to ``out`` and renamed, so a
    reader never sees a half-written file.

    Returns:
        The (caption, image) tiles in grid order.
    """
    items = gallery_items(names, sampled, seed)
    tiles = []
    it = items
    if progress:
        it = tqdm(items, desc="rendering catalogue", unit="tile")
    for caption, name, attrs in it:
        img = render_tile(name, attrs, size, seed)
        built = cat.CATALOGUE[name].build(attrs, np.random.default_rng(seed))
        dim = 200 * max(built.half_extents)
        tiles.append((f"{caption}\n{dim:.0f} cm", img))
    out = os.fspath(out)
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tmp = f"{out}.tmp-{os.getpid()}"
    n_cats = len(dict.fromkeys(name for _, name, _ in items))
    title = (f"Object catalogue: {n_cats} categories, {len(tiles)} tiles (one per state); "
             "under each: category (state) and the largest side of its box")
    compose(tiles, size, cols, title).save(tmp, format="PNG")
    os.replace(tmp, out)
    return tiles


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ignjax.scenes.viz.gallery", description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="docs/catalogue.png", help="PNG file to write (default: %(default)s)")
    parser.add_argument("--size", type=int, default=160, help="tile size in pixels (default: %(default)s)")
    parser.add_argument("--cols", type=int, default=None, help="tiles per row (default: about 1.6 x as wide as tall)")
    parser.add_argument("--only", default=None, help="comma-separated categories to render (default: all)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the builders' small variations (default: %(default)s)")
    parser.add_argument("--sampled", action="store_true", help="draw colours and materials as procedural houses do")
    args = parser.parse_args(argv)
    names = None
    if args.only:
        names = [n.strip() for n in args.only.split(",") if n.strip()]
        unknown = [n for n in names if n not in cat.CATALOGUE]
        if unknown:
            parser.error(f"unknown categories: {', '.join(unknown)}")
    tiles = render_gallery(args.out, args.size, names, args.cols, args.seed, progress=sys.stderr.isatty(), sampled=args.sampled)
    print(f"wrote {args.out}: {len(tiles)} tiles")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
