"""Wall-mounted objects: paintings, mirrors, wall clocks, curtains and towel racks.

Builders ``build_<category>(attrs, rng) -> Built`` in the builder frame of
:mod:`ignjax.scenes.procgen.catalogue`.
"""

from __future__ import annotations

import math

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue.parts import (
    Built,
    box,
    disk,
    ellipsoid,
    finish,
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


def build_painting(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A framed canvas hung on a wall, the picture (a ground colour with two
    shapes) facing +x."""
    s = scale_of(attrs)
    hy, hz, t = 0.4 * s, 0.3 * s, 0.02
    frame = tint(attrs.material)
    ground = rgba(attrs.color)
    x = 2 * t + 0.003
    g = [box("frame", (t, hy, hz), (t, 0, hz), frame, attrs.material),
         box("canvas", (0.003, hy * 0.88, hz * 0.85), (x, 0, hz), ground, "fabric")]
    accents = [c for c in vocab.COLORS if c != attrs.color]
    y = float(rng.uniform(-0.4, 0.1)) * hy
    g.append(span("shape0", (x + 0.003, y - 0.25 * hy, 0.35 * hz), (x + 0.004, y + 0.25 * hy, 1.05 * hz), rgba(pick(rng, accents)),
                  "fabric"))
    g.append(disk("shape1", 0.22 * hz, 0.0006, (x + 0.0045, float(rng.uniform(0.25, 0.55)) * hy, 1.3 * hz), rgba(pick(rng, accents)),
                  "fabric", axis="x"))
    return finish(g)


def build_mirror(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A framed wall mirror; the silvered glass faces +x."""
    s = scale_of(attrs)
    hy, hz = 0.3 * s, 0.45 * s
    frame = rgba(attrs.color, default="brown")
    g = [span("frame", (0, -hy, 0), (0.03, hy, 2 * hz), frame, attrs.material),
         span("glass", (0.03, -hy + 0.04, 0.04), (0.034, hy - 0.04, 2 * hz - 0.04), (0.8, 0.87, 0.92, 1.0), "glass"),
         span("glint", (0.034, -hy + 0.08, 2 * hz - 0.25 * s), (0.035, -hy + 0.1, 2 * hz - 0.08), (0.97, 0.98, 1.0, 1.0), "glass")]
    return finish(g)


def build_wall_clock(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A round wall clock: a rim, a white face with twelve ticks, hour and minute hands and a centre pin."""
    s = scale_of(attrs)
    r = 0.16 * s
    rim = rgba(attrs.color, default="black")
    ink = rgba("black") if attrs.color != "black" else (0.1, 0.1, 0.1, 1.0)
    g = [disk("rim", r, 0.022, (0.022, 0, r), rim, attrs.material, axis="x"),
         disk("face", r * 0.88, 0.003, (0.047, 0, r), rgba("white"), "plastic", axis="x")]
    for k in range(12):
        a = 2 * math.pi * k / 12
        ln = 0.018 * s if k % 3 == 0 else 0.009 * s
        c = r * 0.8 - ln / 2
        g.append(box(f"tick{k}", (0.001, 0.004 if k % 3 == 0 else 0.002, ln / 2), (0.051, -math.sin(a) * c, r + math.cos(a) * c), ink,
                     "plastic", quat=quat_axis_angle((1, 0, 0), a)))
    hour = float(rng.uniform(0, 2 * math.pi))
    minute = float(rng.uniform(0, 2 * math.pi))
    for name, a, ln, w, x in (("hour_hand", hour, 0.45 * r, 0.006, 0.052), ("minute_hand", minute, 0.72 * r, 0.004, 0.054)):
        g.append(box(name, (0.001, w, ln / 2), (x, -math.sin(a) * ln / 2, r + math.cos(a) * ln / 2), ink, "metal",
                     quat=quat_axis_angle((1, 0, 0), a)))
    g.append(disk("pin", 0.008, 0.004, (0.055, 0, r), ink, "metal", axis="x"))
    return finish(g)


def build_curtain(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A curtain on a rod: closed, pleats hang across the whole width; open,
    they are gathered at both sides and tied back. Size scales the width only."""
    s = scale_of(attrs)
    width, h = 1.6 * s, 2.2
    main = rgba(attrs.color, default="beige")
    rod = tint("metal")
    g = [segment("rod", (0.1, -width / 2 - 0.06, h), (0.1, width / 2 + 0.06, h), 0.014, rod, "metal"),
         sphere("finial0", 0.03, (0.1, width / 2 + 0.09, h), rod, "metal"),
         sphere("finial1", 0.03, (0.1, -width / 2 - 0.09, h), rod, "metal")]
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"bracket{k}", (0.0, sy * (width / 2 - 0.02), h), (0.1, sy * (width / 2 - 0.02), h), 0.01, rod, "metal"))

    def pleats(prefix: str, y0: float, y1: float, pitch: float, angle: float) -> None:
        """Accordion folds from y0 to y1: panels alternately turned +-angle about z."""
        n = max(2, int(round(abs(y1 - y0) / pitch)))
        step = (y1 - y0) / n
        half = abs(step) / 2 / math.cos(angle)
        for k in range(n):
            sign = 1 if k % 2 else -1
            q = quat_axis_angle((0, 0, 1), sign * angle)
            g.append(box(f"{prefix}{k}", (0.004, half, (h - 0.05) / 2), (0.1, y0 + (k + 0.5) * step, (h - 0.05) / 2),
                         main if k % 2 else shade(main, 0.85), attrs.material, quat=q))

    if attrs.state == "open":
        bundle = 0.22 * s
        for side, sy in enumerate((1, -1)):
            pleats(f"pleat{side}_", sy * (width / 2 + 0.02), sy * (width / 2 - bundle), 0.035, math.radians(65))
            g.append(ellipsoid(f"tieback{side}", (0.06, bundle / 2 + 0.02, 0.025), (0.1, sy * (width / 2 - bundle / 2 + 0.01), 1.0),
                               shade(main, 0.7), attrs.material))
    else:
        pleats("pleat", -width / 2 - 0.02, width / 2 + 0.02, 0.09, math.radians(35))
    return finish(g)


def build_towel_rack(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A wall towel bar on two brackets with a towel folded over it."""
    s = scale_of(attrs)
    hw = 0.3 * s
    main = rgba(attrs.color, default="gray")
    towel = rgba(pick(rng, ("white", "beige", "blue", "gray", "pink", "green")))
    bar_z, bar_x = 0.5 * s, 0.08
    g = [segment("bar", (bar_x, -hw, bar_z), (bar_x, hw, bar_z), 0.011, main, attrs.material)]
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"bracket{k}", (0.0, sy * hw, bar_z), (bar_x, sy * hw, bar_z), 0.012, main, attrs.material))
        g.append(disk(f"rose{k}", 0.025, 0.006, (0.006, sy * hw, bar_z), main, attrs.material, axis="x"))
    tw = hw - 0.06
    g += [segment("towel_fold", (bar_x, -tw, bar_z + 0.012), (bar_x, tw, bar_z + 0.012), 0.02, towel, "fabric"),
          span("towel_front", (bar_x + 0.013, -tw, 0.0), (bar_x + 0.03, tw, bar_z + 0.012), towel, "fabric"),
          span("towel_back", (bar_x - 0.03, -tw, 0.12 * s), (bar_x - 0.013, tw, bar_z + 0.012), shade(towel, 0.9), "fabric")]
    return finish(g)
