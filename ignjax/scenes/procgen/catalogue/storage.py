"""Storage furniture and beds: nightstands, dressers, wardrobes, cabinets, bookshelves,
shelves, TV stands, cribs, beds, storage boxes and shoe racks.

Builders ``build_<category>(attrs, rng) -> Built`` in the builder frame of
:mod:`ignjax.scenes.procgen.catalogue`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue.parts import (
    DARK,
    Built,
    Surface,
    box,
    disk,
    doors_front,
    ellipsoid,
    finish,
    hscale,
    legs4,
    pick,
    quat_axis_angle,
    rgba,
    scale_of,
    segment,
    shade,
    span,
    sphere,
    tint,
)


def build_nightstand(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A bedside table: a two-drawer body on short legs; the top is a support."""
    s = scale_of(attrs)
    hx, hy, h = 0.2 * s, 0.23 * s, 0.57 * hscale(s)
    main = rgba(attrs.color, default="brown")
    g = legs4(hx, hy, 0.06, 0.018, tint(attrs.material), attrs.material, inset=0.03)
    g.append(span("body", (-hx, -hy, 0.06), (hx - 0.02, hy, h - 0.02), shade(main, 0.88), attrs.material))
    g.append(span("top", (-hx, -hy - 0.01, h - 0.02), (hx + 0.01, hy + 0.01, h), main, attrs.material))
    dh = (h - 0.1) / 2
    for k in range(2):
        z0 = 0.07 + k * dh
        g.append(span(f"drawer{k}", (hx - 0.02, -hy + 0.02, z0 + 0.005), (hx, hy - 0.02, z0 + dh - 0.005), main, attrs.material))
        g.append(sphere(f"knob{k}", 0.013, (hx + 0.01, 0, z0 + dh / 2), tint("metal"), "metal"))
    return finish(g, (Surface(h, (hx - 0.03, hy - 0.03)),))


def build_dresser(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A chest of drawers (three rows of two); open pulls out the top row with clothes inside."""
    s = scale_of(attrs)
    hx, hy, h = 0.24, 0.6 * s, 0.85
    main = rgba(attrs.color, default="brown")
    g = [span("plinth", (-hx + 0.02, -hy + 0.02, 0), (hx - 0.03, hy - 0.02, 0.07), shade(main, 0.7), attrs.material),
         span("body", (-hx, -hy, 0.07), (hx - 0.02, hy, h - 0.03), shade(main, 0.85), attrs.material),
         span("top", (-hx, -hy - 0.01, h - 0.03), (hx + 0.01, hy + 0.01, h), main, attrs.material)]
    dh = (h - 0.12) / 3
    opened = attrs.state == "open"
    for row in range(3):
        z0 = 0.08 + row * dh
        for col in range(2):
            y0, y1 = (-hy + 0.015, -0.005) if col == 0 else (0.005, hy - 0.015)
            out = 0.3 if opened and row == 2 else 0.0
            g.append(span(f"drawer{row}{col}", (hx - 0.02 + out, y0, z0 + 0.006), (hx + out, y1, z0 + dh - 0.006), main, attrs.material))
            g.append(segment(f"pull{row}{col}", (hx + out + 0.015, (y0 + y1) / 2 - 0.05, z0 + dh / 2),
                             (hx + out + 0.015, (y0 + y1) / 2 + 0.05, z0 + dh / 2), 0.007, tint("metal"), "metal"))
            if out:
                g.append(span(f"tray{col}", (hx - 0.02, y0 + 0.01, z0 + 0.01), (hx - 0.02 + out, y1 - 0.01, z0 + dh - 0.02),
                              shade(main, 0.75), attrs.material))
                g.append(ellipsoid(f"clothes{col}", (0.1, (y1 - y0) * 0.35, 0.03), (hx + out * 0.5, (y0 + y1) / 2, z0 + dh - 0.02),
                                   rgba(pick(rng, ("blue", "white", "red", "gray", "pink"))), "fabric"))
    return finish(g, (Surface(h, (hx - 0.04, hy - 0.04), (-0.005, 0.0)),))


def build_wardrobe(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tall two-door wardrobe; open swings the doors out and shows a rail of clothes and a hat shelf."""
    s = scale_of(attrs)
    hy, d, h = 0.5 * s, 0.6, 2.0 * hscale(s, 0.4)
    main = rgba(attrs.color, default="brown")
    inner = shade(main, 0.6)
    mat = attrs.material
    g = [span("plinth", (0.02, -hy + 0.02, 0), (d - 0.02, hy - 0.02, 0.08), shade(main, 0.7), mat),
         span("cornice", (0, -hy - 0.015, h - 0.04), (d + 0.025, hy + 0.015, h), main, mat)]
    wdoor = hy
    if attrs.state != "open":
        g.append(span("body", (0, -hy, 0.08), (d, hy, h - 0.04), shade(main, 0.9), mat))
        for k, sy in enumerate((1, -1)):
            y0, y1 = (0.003, hy) if sy > 0 else (-hy, -0.003)
            g.append(span(f"door{k}", (d, y0, 0.09), (d + 0.02, y1, h - 0.05), main, mat))
            g.append(segment(f"handle{k}", (d + 0.035, sy * 0.05, h / 2 - 0.15), (d + 0.035, sy * 0.05, h / 2 + 0.15), 0.01,
                             tint("metal"), "metal"))
        return finish(g)
    g += [span("back", (0, -hy, 0.08), (0.02, hy, h - 0.04), inner, mat),
          span("side0", (0, hy - 0.02, 0.08), (d, hy, h - 0.04), shade(main, 0.9), mat),
          span("side1", (0, -hy, 0.08), (d, -hy + 0.02, h - 0.04), shade(main, 0.9), mat),
          span("bottom", (0.02, -hy + 0.02, 0.08), (d, hy - 0.02, 0.1), inner, mat),
          span("hat_shelf", (0.02, -hy + 0.02, h - 0.38), (d, hy - 0.02, h - 0.36), shade(main, 0.8), mat),
          segment("rail", (d / 2, -hy + 0.02, h - 0.45), (d / 2, hy - 0.02, h - 0.45), 0.012, tint("metal"), "metal")]
    n = max(3, int(round(2 * hy / 0.16)))
    for k in range(n):
        y = -hy + 0.1 + k * (2 * hy - 0.2) / (n - 1)
        length = float(rng.uniform(0.5, 0.95))
        g.append(ellipsoid(f"garment{k}", (0.22, 0.035, length / 2), (d / 2, y, h - 0.47 - length / 2),
                           rgba(pick(rng, vocab.COLORS)), "fabric"))
    for k, sy in enumerate((1, -1)):
        alpha = math.radians(-90 + 105) * sy  # door direction from its hinge
        dirx, diry = math.cos(alpha), math.sin(alpha)
        hinge = (d + 0.01, sy * hy)
        cx, cy = hinge[0] + dirx * wdoor / 2, hinge[1] + diry * wdoor / 2
        q = quat_axis_angle((0, 0, 1), alpha - math.pi / 2)
        g.append(box(f"door{k}", (0.01, wdoor / 2, (h - 0.14) / 2), (cx, cy, 0.09 + (h - 0.14) / 2), main, mat, quat=q))
    return finish(g)


def build_cabinet(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A base cabinet with a countertop (the support) and two doors; open shows the shelf and contents."""
    s = scale_of(attrs)
    hy, d, h = 0.42 * s, 0.58, 0.9
    main = rgba(attrs.color, default="white")
    top = tint(attrs.material if attrs.material in ("stone", "wood", "metal") else "stone")
    opened = attrs.state == "open"
    g = [span("toe_kick", (0.0, -hy + 0.02, 0), (d - 0.06, hy - 0.02, 0.1), DARK),
         span("countertop", (0, -hy - 0.01, h - 0.04), (d + 0.03, hy + 0.01, h), top, attrs.material)]
    if opened:
        g += [span("back", (0, -hy, 0.1), (0.02, hy, h - 0.04), shade(main, 0.55), "wood"),
              span("side0", (0, hy - 0.02, 0.1), (d, hy, h - 0.04), shade(main, 0.9), "wood"),
              span("side1", (0, -hy, 0.1), (d, -hy + 0.02, h - 0.04), shade(main, 0.9), "wood"),
              span("bottom", (0.02, -hy + 0.02, 0.1), (d, hy - 0.02, 0.12), shade(main, 0.7), "wood"),
              span("shelf", (0.02, -hy + 0.02, 0.47), (d - 0.02, hy - 0.02, 0.49), shade(main, 0.8), "wood")]
        for k in range(3):
            y = -hy + 0.12 + k * (2 * hy - 0.24) / 2
            g.append(disk(f"jar{k}", 0.05, 0.07, (0.3, y, 0.56), rgba(pick(rng, ("red", "yellow", "white", "green"))), "glass"))
    else:
        g.append(span("body", (0, -hy, 0.1), (d, hy, h - 0.04), shade(main, 0.9), "wood"))
    doors_front(g, d, -hy, hy, 0.12, h - 0.06, 2, main, "wood", opened)
    return finish(g, (Surface(h, ((d + 0.03) / 2 - 0.04, hy - 0.04), ((d + 0.03) / 2, 0.0)),))


def build_bookshelf(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tall bookcase: sides, back, plinth, top and four shelves; full puts rows
    of books on each level. Every free shelf length (and the top) is a support."""
    s = scale_of(attrs)
    hy, d, h = 0.45 * s, 0.32, 1.8 * hscale(s, 0.4)
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    t = 0.02
    g = [span("back", (0, -hy, 0), (0.01, hy, h), shade(main, 0.8), mat),
         span("side0", (0, hy - t, 0), (d, hy, h), main, mat),
         span("side1", (0, -hy, 0), (d, -hy + t, h), main, mat),
         span("plinth", (0.01, -hy + t, 0), (d, hy - t, 0.07), main, mat),
         span("top", (0, -hy, h - t), (d + 0.01, hy, h), main, mat)]
    n_levels = 5
    pitch = (h - t - 0.07) / n_levels
    surfaces = []
    full = attrs.state == "full"
    inner = hy - t
    for k in range(n_levels):
        z = 0.07 + k * pitch  # top of this level's floor board
        if k > 0:
            g.append(span(f"shelf{k}", (0.01, -inner, z - t), (d, inner, z), main, mat))
        clear = pitch - t if k < n_levels - 1 else pitch
        free0, free1 = -inner, inner
        if full:
            frac = float(rng.uniform(0.5, 0.7))
            left = k % 2 == 0
            y = -inner + 0.005 if left else inner - 0.005
            end = -inner + 2 * inner * frac if left else inner - 2 * inner * frac
            j = 0
            while j < 7 and ((y < end) if left else (y > end)):
                w = float(rng.uniform(0.04, 0.085))
                bh = min(clear - 0.03, float(rng.uniform(0.2, 0.28)) * min(1.0, clear / 0.33))
                bd = float(rng.uniform(0.18, 0.24))
                y0, y1 = (y, y + w) if left else (y - w, y)
                g.append(span(f"book{k}_{j}", (0.02, y0, z), (0.02 + bd, y1, z + bh), rgba(pick(rng, vocab.COLORS)), "fabric"))
                y = y1 + 0.002 if left else y0 - 0.002
                j += 1
            free0, free1 = (y + 0.01, inner) if left else (-inner, y - 0.01)
        if free1 - free0 > 0.12:
            surfaces.append(Surface(z, (d / 2 - 0.03, (free1 - free0) / 2 - 0.01), (d / 2 + 0.005, (free0 + free1) / 2), clear))
    surfaces.append(Surface(h, (d / 2 - 0.03, hy - 0.03), (d / 2, 0.0)))
    return finish(g, surfaces)


def build_shelf(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An open shelving unit: four corner posts and four boards, each board a support."""
    s = scale_of(attrs)
    hy, d, h = 0.45 * s, 0.4, 1.5 * hscale(s)
    main = rgba(attrs.color, default="gray")
    mat = attrs.material
    g = []
    for i, (x, y) in enumerate(((0.02, hy - 0.02), (d - 0.02, hy - 0.02), (d - 0.02, -hy + 0.02), (0.02, -hy + 0.02))):
        g.append(span(f"post{i}", (x - 0.02, y - 0.02, 0), (x + 0.02, y + 0.02, h), shade(main, 0.8), mat))
    levels = [0.12, 0.12 + (h - 0.14) / 3, 0.12 + 2 * (h - 0.14) / 3, h - 0.02]
    surfaces = []
    for k, z in enumerate(levels):
        g.append(span(f"board{k}", (0.0, -hy, z - 0.02), (d, hy, z), main, mat))
        clear = levels[k + 1] - 0.02 - z if k + 1 < len(levels) else math.inf
        surfaces.append(Surface(z, (d / 2 - 0.05, hy - 0.06), (d / 2, 0.0), clear))
    return finish(g, surfaces)


def build_tv_stand(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A low media console: closed cabinets at the ends, an open dark middle bay; the top is a support."""
    s = scale_of(attrs)
    hy, d, h = 0.75 * s, 0.42, 0.5
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    g = legs4(d / 2, hy, 0.06, 0.02, tint("metal"), "metal", inset=0.05)
    g = [dataclasses.replace(x, pos=(x.pos[0] + d / 2, x.pos[1], x.pos[2])) for x in g]
    g += [span("body", (0, -hy, 0.06), (d, hy, h - 0.02), shade(main, 0.85), mat),
          span("top", (0, -hy - 0.01, h - 0.02), (d + 0.01, hy + 0.01, h), main, mat),
          span("bay", (d, -hy / 3 + 0.01, 0.09), (d + 0.002, hy / 3 - 0.01, h - 0.05), DARK)]
    for k, sy in enumerate((-1, 1)):
        y0, y1 = (-hy + 0.01, -hy / 3 - 0.01) if sy < 0 else (hy / 3 + 0.01, hy - 0.01)
        g.append(span(f"door{k}", (d, y0, 0.08), (d + 0.02, y1, h - 0.04), main, mat))
        g.append(segment(f"handle{k}", (d + 0.03, (y0 + y1) / 2 - 0.06, h - 0.1), (d + 0.03, (y0 + y1) / 2 + 0.06, h - 0.1), 0.007,
                         tint("metal"), "metal"))
    return finish(g, (Surface(h, (d / 2 - 0.03, hy - 0.03), (d / 2, 0.0)),))


def build_crib(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A baby cot: corner posts, top rails, slatted long sides, solid ends and a mattress (the support)."""
    s = scale_of(attrs)
    hy, hx, h = 0.65 * s, 0.36 * s, 1.0
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    mz = 0.36
    g = [span("base", (-hx + 0.03, -hy + 0.03, mz - 0.14), (hx - 0.03, hy - 0.03, mz - 0.1), shade(main, 0.85), mat),
         span("mattress", (-hx + 0.035, -hy + 0.035, mz - 0.1), (hx - 0.035, hy - 0.035, mz), rgba("white"), "fabric")]
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        x, y = sx * (hx - 0.025), sy * (hy - 0.025)
        g.append(span(f"post{i}", (x - 0.025, y - 0.025, 0), (x + 0.025, y + 0.025, h), main, mat))
    for k, sy in enumerate((1, -1)):
        y = sy * (hy - 0.025)
        g.append(span(f"end{k}", (-hx + 0.05, y - 0.012, mz - 0.14), (hx - 0.05, y + 0.012, h - 0.1), main, mat))
    n = max(5, int(round((2 * hy - 0.1) / 0.13)))
    for k, sx in enumerate((1, -1)):
        x = sx * (hx - 0.025)
        g.append(segment(f"rail{k}", (x, -hy + 0.05, h - 0.04), (x, hy - 0.05, h - 0.04), 0.02, main, mat))
        g.append(segment(f"low_rail{k}", (x, -hy + 0.05, mz - 0.12), (x, hy - 0.05, mz - 0.12), 0.02, main, mat))
        for j in range(n):
            y = -hy + 0.05 + (j + 0.5) * (2 * hy - 0.1) / n
            g.append(disk(f"slat{k}_{j}", 0.011, (h - 0.06 - mz + 0.1) / 2, (x, y, (h - 0.06 + mz - 0.1) / 2 - 0.01), main, mat))
    return finish(g, (Surface(mz, (hx - 0.08, hy - 0.08)),))


def build_bed(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A frame on short legs with a headboard at -x and a footboard, a mattress,
    pillows and a blanket. Made: the blanket lies flat over the lower part of
    the bed (its top is the support). Unmade: the covers are bunched at the
    foot, a pillow is askew, and the bare mattress between is the support."""
    s = scale_of(attrs)
    hx, hy = 1.0, 0.8 * s
    frame_h, mat_h = 0.3, 0.22
    wood = tint(attrs.material)
    cover = rgba(attrs.color, default="blue")
    top = frame_h + mat_h
    g = legs4(hx, hy, 0.1, 0.035, wood, attrs.material, inset=0.06)
    g += [span("frame", (-hx, -hy, 0.1), (hx, hy, frame_h), wood, attrs.material),
          span("headboard", (-hx, -hy, 0.1), (-hx + 0.08, hy, 1.05), wood, attrs.material),
          span("footboard", (hx - 0.05, -hy, 0.1), (hx, hy, 0.42), wood, attrs.material),
          span("mattress", (-hx + 0.08, -hy + 0.03, frame_h), (hx - 0.05, hy - 0.03, top), rgba("white"), "fabric")]
    n_pillows = 2 if hy > 0.6 else 1
    unmade = attrs.state == "unmade"
    for k in range(n_pillows):
        y = 0.0 if n_pillows == 1 else (k - 0.5) * hy
        q = quat_axis_angle((0, 0, 1), float(rng.uniform(0.2, 0.5))) if unmade and k == n_pillows - 1 else (1.0, 0.0, 0.0, 0.0)
        g.append(ellipsoid(f"pillow{k}", (0.14, min(0.3, hy / n_pillows - 0.04), 0.07), (-hx + 0.25, y, top + 0.06), rgba("white"),
                           "fabric", quat=q))
    if unmade:
        for k in range(3):
            q = quat_axis_angle((0, 0, 1), float(rng.uniform(-0.25, 0.25)))
            g.append(ellipsoid(f"blanket{k}", (0.2, hy * 0.75, 0.08), (hx - 0.33 + 0.1 * (k - 1), (k - 1) * 0.1 * s, top + 0.05), cover,
                               "fabric", quat=q))
        surf = Surface(top, (0.33, hy - 0.12), (-0.2, 0.0))
    else:
        x0 = -hx + 0.48
        g.append(span("blanket", (x0, -hy + 0.01, top), (hx - 0.05, hy - 0.01, top + 0.04), cover, "fabric"))
        for k, sy in enumerate((1, -1)):
            y = sy * (hy - 0.02)
            g.append(span(f"drape{k}", (x0, y - 0.01, top - 0.2), (hx - 0.05, y + 0.01, top + 0.04), cover, "fabric"))
        surf = Surface(top + 0.04, ((hx - 0.05 - x0) / 2 - 0.05, hy - 0.12), ((hx - 0.05 + x0) / 2, 0.0))
    return finish(g, (surf,))


def build_storage_box(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A lidded storage tote with hand holds; the lid is a support."""
    s = scale_of(attrs)
    hx, hy, h = 0.2 * s, 0.3 * s, 0.3 * s
    main = rgba(attrs.color, default="blue")
    g = [span("body", (-hx + 0.015, -hy + 0.015, 0), (hx - 0.015, hy - 0.015, h - 0.03), main, attrs.material),
         span("lid", (-hx, -hy, h - 0.03), (hx, hy, h), shade(main, 0.8), attrs.material)]
    for k, sy in enumerate((1, -1)):
        g.append(span(f"grip{k}", (-0.05, sy * (hy - 0.015) - 0.003, h - 0.09), (0.05, sy * (hy - 0.015) + 0.003, h - 0.06), DARK))
    return finish(g, (Surface(h, (hx - 0.02, hy - 0.02)),))


def build_shoe_rack(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A low rack: end panels, two slanted slatted levels with pairs of shoes, and a top board (a support)."""
    s = scale_of(attrs)
    hy, d, h = 0.4 * s, 0.3, 0.5
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    g = [span("top", (0, -hy, h - 0.02), (d, hy, h), main, mat)]
    for k, sy in enumerate((1, -1)):
        y = sy * (hy - 0.015)
        g.append(span(f"end{k}", (0, y - 0.015, 0), (d, y + 0.015, h - 0.02), main, mat))
    slant = quat_axis_angle((0, 1, 0), math.radians(12))
    shoe_colors = ("black", "brown", "white", "blue", "red", "gray", "beige")
    for lvl, z in enumerate((0.07, 0.26)):
        g.append(box(f"level{lvl}", (d / 2 - 0.01, hy - 0.03, 0.008), (d / 2, 0, z), shade(main, 0.85), mat, quat=slant))
        n_pairs = int(rng.integers(1, 4))
        for p in range(n_pairs):
            y = -hy + 0.12 + p * (2 * hy - 0.24) / 2
            c = rgba(pick(rng, shoe_colors))
            for q, dy in enumerate((-0.05, 0.05)):
                g.append(ellipsoid(f"shoe{lvl}_{p}_{q}", (0.13, 0.04, 0.045), (d / 2, y + dy, z + 0.05), c, "leather", quat=slant))
    return finish(g, (Surface(h, (d / 2 - 0.02, hy - 0.02), (d / 2, 0.0)),))
