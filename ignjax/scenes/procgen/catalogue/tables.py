"""Tables and desks: dining, coffee and side tables, desks, kitchen islands and workbenches.

Builders ``build_<category>(attrs, rng) -> Built`` in the builder frame of
:mod:`ignjax.scenes.procgen.catalogue`.
"""

from __future__ import annotations

import numpy as np

from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue.parts import (
    DARK,
    Built,
    Surface,
    box,
    disk,
    finish,
    legs4,
    rgba,
    scale_of,
    segment,
    shade,
    span,
    tint,
)


def build_dining_table(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A top on four legs; the top is a support surface."""
    s = scale_of(attrs)
    hx, hy, h = 0.8 * s, 0.45 * s, 0.75
    top = rgba(attrs.color, default="brown")
    geoms = legs4(hx, hy, h - 0.04, 0.03, tint(attrs.material), attrs.material, inset=0.06)
    geoms.append(box("top", (hx, hy, 0.02), (0, 0, h - 0.02), top, attrs.material))
    geoms.append(span("apron", (-hx + 0.05, -hy + 0.05, h - 0.1), (hx - 0.05, hy - 0.05, h - 0.04), shade(top, 0.8), attrs.material))
    return finish(geoms, (Surface(h, (hx - 0.08, hy - 0.08)),))


def build_coffee_table(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A low table with a lower shelf; the top is a support."""
    s = scale_of(attrs)
    hx, hy, h = 0.3 * s, 0.55 * s, 0.42
    main = rgba(attrs.color, default="brown")
    frame = tint(attrs.material)
    g = [span("top", (-hx, -hy, h - 0.03), (hx, hy, h), main, attrs.material)]
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        x, y = sx * (hx - 0.04), sy * (hy - 0.04)
        g.append(span(f"leg{i}", (x - 0.02, y - 0.02, 0), (x + 0.02, y + 0.02, h - 0.03), frame, attrs.material))
    g.append(span("shelf", (-hx + 0.02, -hy + 0.06, 0.1), (hx - 0.02, hy - 0.06, 0.12), shade(main, 0.85), attrs.material))
    return finish(g, (Surface(h, (hx - 0.04, hy - 0.05)),))


def build_side_table(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A round pedestal table; the top is a support."""
    s = scale_of(attrs)
    r, h = 0.25 * s, 0.56
    main = rgba(attrs.color, default="brown")
    frame = tint(attrs.material)
    g = [disk("foot", 0.17 * s, 0.012, (0, 0, 0.012), frame, attrs.material),
         disk("pedestal", 0.03, (h - 0.044) / 2, (0, 0, 0.024 + (h - 0.044) / 2), frame, attrs.material),
         disk("top", r, 0.01, (0, 0, h - 0.01), main, attrs.material)]
    return finish(g, (Surface(h, (r * 0.68, r * 0.68)),))


def build_desk(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A writing desk: a top, a leg panel, a three-drawer pedestal and a modesty panel."""
    s = scale_of(attrs)
    hx, hy, h = 0.33, 0.65 * s, 0.75
    main = rgba(attrs.color, default="brown")
    side = shade(main, 0.85)
    g = [span("top", (-hx, -hy, h - 0.03), (hx, hy, h), main, attrs.material),
         span("leg_panel", (-hx + 0.02, -hy + 0.02, 0), (hx - 0.02, -hy + 0.05, h - 0.03), side, attrs.material),
         span("modesty", (-hx + 0.02, -hy + 0.05, 0.35), (-hx + 0.04, hy - 0.4, h - 0.03), side, attrs.material),
         span("pedestal", (-hx + 0.02, hy - 0.42, 0), (hx - 0.03, hy - 0.02, h - 0.03), side, attrs.material)]
    for k in range(3):
        z0 = 0.04 + k * (h - 0.1) / 3
        z1 = z0 + (h - 0.1) / 3 - 0.012
        g.append(span(f"drawer{k}", (hx - 0.03, hy - 0.41, z0), (hx - 0.01, hy - 0.03, z1), main, attrs.material))
        g.append(disk(f"knob{k}", 0.012, 0.01, (hx, hy - 0.22, (z0 + z1) / 2), tint("metal"), "metal", axis="x"))
    return finish(g, (Surface(h, (hx - 0.04, hy - 0.04)),))


def build_kitchen_island(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A free-standing counter: cabinet doors on the front, a countertop overhanging at the back for stools."""
    s = scale_of(attrs)
    hy, h = 0.9 * s, 0.92
    main = rgba(attrs.color, default="white")
    top = tint(attrs.material or "stone")
    x0, x1 = -0.2, 0.42
    g = [span("toe_kick", (x0 + 0.05, -hy + 0.05, 0), (x1 - 0.05, hy - 0.05, 0.1), DARK),
         span("body", (x0, -hy + 0.02, 0.1), (x1, hy - 0.02, h - 0.04), shade(main, 0.9), "wood"),
         span("countertop", (-0.5, -hy, h - 0.04), (x1 + 0.03, hy, h), top, attrs.material)]
    n = 3 if hy > 0.8 else 2
    w = (2 * hy - 0.04) / n
    for k in range(n):
        y0 = -hy + 0.02 + k * w
        g.append(span(f"door{k}", (x1, y0 + 0.005, 0.12), (x1 + 0.02, y0 + w - 0.005, h - 0.06), main, "wood"))
        g.append(segment(f"handle{k}", (x1 + 0.035, y0 + w / 2 - 0.08, h - 0.12), (x1 + 0.035, y0 + w / 2 + 0.08, h - 0.12), 0.008,
                         tint("metal"), "metal"))
    return finish(g, (Surface(h, ((x1 + 0.5) / 2 - 0.04, hy - 0.05), ((x1 - 0.5) / 2, 0.0)),))


def build_workbench(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A heavy bench: a thick wooden top on a frame, a lower shelf, a pegboard with tools and a vise."""
    s = scale_of(attrs)
    hx, hy, h = 0.35, 0.8 * s, 0.9
    frame = rgba(attrs.color, default="gray")
    wood = tint("wood")
    g = []
    for i, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        x, y = sx * (hx - 0.05), sy * (hy - 0.05)
        g.append(span(f"leg{i}", (x - 0.03, y - 0.03, 0), (x + 0.03, y + 0.03, h - 0.06), frame, attrs.material))
    g.append(span("top", (-hx, -hy, h - 0.06), (hx, hy, h), wood, "wood"))
    g.append(span("shelf", (-hx + 0.02, -hy + 0.02, 0.14), (hx - 0.02, hy - 0.02, 0.16), shade(wood, 0.85), "wood"))
    g.append(span("pegboard", (-hx, -hy + 0.05, h), (-hx + 0.02, hy - 0.05, h + 0.75), (0.72, 0.6, 0.45, 1.0), "wood"))
    tools = tint("metal")
    g.append(segment("hammer_handle", (-hx + 0.04, -0.4 * s, h + 0.25), (-hx + 0.04, -0.4 * s, h + 0.5), 0.012, wood, "wood"))
    g.append(span("hammer_head", (-hx + 0.025, -0.4 * s - 0.06, h + 0.5), (-hx + 0.055, -0.4 * s + 0.06, h + 0.54), tools, "metal"))
    g.append(span("wrench", (-hx + 0.025, 0.0, h + 0.3), (-hx + 0.035, 0.03, h + 0.55), tools, "metal"))
    g.append(segment("screwdriver", (-hx + 0.04, 0.3 * s, h + 0.3), (-hx + 0.04, 0.3 * s, h + 0.52), 0.012, rgba("red"), "plastic"))
    g.append(span("vise", (hx - 0.1, hy - 0.25, h), (hx + 0.04, hy - 0.07, h + 0.1), rgba("blue"), "metal"))
    return finish(g, (Surface(h, ((2 * hx - 0.14) / 2 - 0.02, hy - 0.3), (-0.02 + 0.05, -0.1)),))
