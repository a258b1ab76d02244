"""Electronics: televisions, monitors, computers, printers, speakers, fans and vacuum cleaners.

Builders ``build_<category>(attrs, rng) -> Built`` in the builder frame of
:mod:`ignjax.scenes.procgen.catalogue`.
"""

from __future__ import annotations

import math

import numpy as np

from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue.parts import (
    AXIS_QUAT,
    DARK,
    SCREEN_OFF,
    Built,
    box,
    capsule,
    disk,
    ellipsoid,
    finish,
    hscale,
    quat_axis_angle,
    rgba,
    ring,
    scale_of,
    segment,
    shade,
    span,
    sphere,
    tint,
)


def _screen_content(g: list, x: float, y0: float, y1: float, z0: float, z1: float, on: bool, desktop: bool) -> None:
    """Append a screen on the plane x: dark when off; when on, a bright picture
    (a landscape for televisions, a desktop with a window for monitors)."""
    if not on:
        g.append(span("screen", (x, y0, z0), (x + 0.003, y1, z1), SCREEN_OFF, "glass"))
        return
    w, hgt = y1 - y0, z1 - z0
    if desktop:
        g.append(span("screen", (x, y0, z0), (x + 0.003, y1, z1), (0.35, 0.6, 0.95, 1.0), "glass"))
        g.append(span("taskbar", (x + 0.003, y0, z0), (x + 0.004, y1, z0 + 0.07 * hgt), (0.12, 0.14, 0.2, 1.0), "glass"))
        g.append(span("window", (x + 0.003, y0 + 0.2 * w, z0 + 0.2 * hgt), (x + 0.004, y0 + 0.75 * w, z0 + 0.85 * hgt),
                      (0.97, 0.97, 0.97, 1.0), "glass"))
    else:
        g.append(span("screen", (x, y0, z0), (x + 0.003, y1, z1), (0.5, 0.78, 1.0, 1.0), "glass"))
        g.append(span("picture_ground", (x + 0.003, y0, z0), (x + 0.004, y1, z0 + 0.4 * hgt), (0.3, 0.7, 0.3, 1.0), "glass"))
        g.append(disk("picture_sun", 0.1 * hgt, 0.0005, (x + 0.0035, y0 + 0.75 * w, z0 + 0.72 * hgt), (1.0, 0.92, 0.4, 1.0), "glass",
                      axis="x"))


def build_television(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A flat-panel TV on a pedestal stand: bezel, screen (a bright picture when on, black when off)."""
    s = scale_of(attrs)
    hw, hh = 0.49 * s, 0.28 * s
    bezel = rgba(attrs.color, default="black")
    z0 = 0.1
    g = [span("foot", (-0.12, -0.3 * s, 0), (0.12, 0.3 * s, 0.015), bezel, attrs.material),
         span("neck", (-0.05, -0.05, 0.015), (-0.02, 0.05, z0 + 0.15), bezel, attrs.material),
         span("panel", (-0.02, -hw, z0), (0.01, hw, z0 + 2 * hh), bezel, attrs.material)]
    _screen_content(g, 0.01, -hw + 0.015, hw - 0.015, z0 + 0.015, z0 + 2 * hh - 0.015, attrs.state == "on", desktop=False)
    return finish(g)


def build_monitor(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A computer monitor: a thin panel on an arm and a flat base; the screen shows a desktop when on."""
    s = scale_of(attrs)
    hw, hh = 0.28 * s, 0.17 * s
    bezel = rgba(attrs.color, default="black")
    z0 = 0.1
    g = [span("base", (-0.11, -0.12, 0), (0.06, 0.12, 0.012), bezel, attrs.material),
         span("arm", (-0.08, -0.025, 0.012), (-0.06, 0.025, z0 + hh), bezel, attrs.material),
         span("panel", (-0.06, -hw, z0), (-0.04, hw, z0 + 2 * hh), bezel, attrs.material)]
    _screen_content(g, -0.04, -hw + 0.01, hw - 0.01, z0 + 0.015, z0 + 2 * hh - 0.01, attrs.state == "on", desktop=True)
    return finish(g)


def build_computer(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A desktop tower: a box with a front panel, a power button, a drive slot and vents."""
    s = scale_of(attrs)
    hx, hy, h = 0.2 * s, 0.09 * s, 0.42 * s
    main = rgba(attrs.color, default="black")
    front = shade(main, 1.4) if max(main[:3]) < 0.3 else shade(main, 0.85)
    g = [span("case", (-hx, -hy, 0.015), (hx, hy, h), main, attrs.material),
         span("feet", (-hx + 0.02, -hy + 0.01, 0), (hx - 0.02, hy - 0.01, 0.015), DARK),
         span("front", (hx, -hy + 0.008, 0.02), (hx + 0.008, hy - 0.008, h - 0.005), front, "plastic"),
         span("drive", (hx + 0.008, -hy + 0.02, h - 0.07), (hx + 0.01, hy - 0.02, h - 0.05), DARK),
         disk("power", 0.012, 0.003, (hx + 0.011, 0, h - 0.025), (0.3, 0.6, 1.0, 1.0), "plastic", axis="x")]
    for k in range(4):
        z = 0.06 + k * 0.035
        g.append(span(f"vent{k}", (hx + 0.008, -hy + 0.02, z), (hx + 0.01, hy - 0.02, z + 0.012), DARK))
    return finish(g)


def build_printer(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An inkjet/laser printer: a body with a scanner lid, a paper feed at the back, an output tray and a control panel."""
    s = scale_of(attrs)
    hx, hy, h = 0.18 * s, 0.22 * s, 0.2 * s
    main = rgba(attrs.color, default="white")
    lid = shade(main, 0.85) if max(main[:3]) > 0.3 else shade(main, 2.0)
    g = [span("body", (-hx, -hy, 0), (hx, hy, h - 0.02), main, attrs.material),
         span("lid", (-hx, -hy, h - 0.02), (hx - 0.02, hy, h), lid, attrs.material),
         span("slot", (hx, -hy + 0.05, 0.06 * s), (hx + 0.002, hy - 0.05, 0.09 * s), DARK),
         span("tray", (hx, -hy + 0.07, 0.045 * s), (hx + 0.12 * s, hy - 0.07, 0.055 * s), shade(main, 0.75), attrs.material),
         span("panel", (hx - 0.06, hy - 0.12, h - 0.02), (hx - 0.02, hy - 0.02, h + 0.005), (0.15, 0.15, 0.17, 1.0), "plastic"),
         box("paper", (0.004, hy - 0.08, 0.08 * s), (-hx + 0.01, 0, h + 0.06 * s), rgba("white"), "fabric",
             quat=quat_axis_angle((0, 1, 0), -math.radians(20)))]
    return finish(g)


def build_speaker(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A floor-standing tower speaker: a tall cabinet on a plinth with a tweeter and two woofer cones."""
    s = scale_of(attrs)
    hx, hy, h = 0.15 * s, 0.12 * s, 0.95 * hscale(s)
    main = rgba(attrs.color, default="black")
    cone = (0.1, 0.1, 0.11, 1.0)
    g = [span("plinth", (-hx - 0.02, -hy - 0.02, 0), (hx + 0.02, hy + 0.02, 0.03), DARK),
         span("cabinet", (-hx, -hy, 0.03), (hx, hy, h), main, attrs.material),
         disk("tweeter", 0.025 * s, 0.008, (hx + 0.008, 0, h - 0.09 * s), cone, "metal", axis="x"),
         sphere("tweeter_dome", 0.012 * s, (hx + 0.014, 0, h - 0.09 * s), tint("metal"), "metal")]
    for k, z in enumerate((h - 0.27 * s, h - 0.5 * s)):
        g.append(disk(f"woofer{k}", 0.08 * s, 0.008, (hx + 0.008, 0, z), cone, "plastic", axis="x"))
        g.append(disk(f"woofer_rim{k}", 0.088 * s, 0.004, (hx + 0.004, 0, z), (0.55, 0.55, 0.58, 1.0), "metal", axis="x"))
        g.append(sphere(f"dust_cap{k}", 0.025 * s, (hx + 0.012, 0, z), (0.2, 0.2, 0.22, 1.0), "plastic"))
    return finish(g)


def build_fan(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A pedestal fan: a round base, a pole, a motor housing, three blades and a guard ring."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    h = 1.15 * hscale(s)
    r = 0.22 * s
    g = [disk("base", 0.17 * s, 0.015, (0, 0, 0.015), main, attrs.material),
         disk("pole", 0.014, (h - 0.08) / 2, (0, 0, 0.03 + (h - 0.08) / 2), tint("metal"), "metal"),
         capsule("motor", 0.06 * s, 0.05 * s, (-0.02, 0, h), main, attrs.material, quat=AXIS_QUAT["x"]),
         disk("hub", 0.04 * s, 0.015, (0.07 * s, 0, h), shade(main, 0.85), attrs.material, axis="x")]
    for k in range(3):
        a = 2 * math.pi * k / 3 + 0.3
        q = quat_axis_angle((1, 0, 0), a)
        g.append(ellipsoid(f"blade{k}", (0.006, 0.055 * s, 0.1 * s), (0.07 * s, -math.sin(a) * 0.1 * s, h + math.cos(a) * 0.1 * s),
                           (0.7, 0.85, 0.95, 1.0), "plastic", quat=q))
    g += ring("guard", (0.08 * s, 0, h), r, 0.006, 12, main, attrs.material, u=(0, 1, 0), v=(0, 0, 1))
    return finish(g)


def build_vacuum_cleaner(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An upright vacuum cleaner: a floor head with wheels, a tilted body with a clear bin, a handle pole and a grip."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="red")
    mat = attrs.material
    g = [span("head", (-0.05, -0.15 * s, 0.01), (0.22 * s, 0.15 * s, 0.07), main, mat),
         span("brush", (0.16 * s, -0.14 * s, 0.0), (0.22 * s, 0.14 * s, 0.012), DARK)]
    for k, sy in enumerate((1, -1)):
        g.append(disk(f"wheel{k}", 0.045, 0.015, (-0.04, sy * 0.12 * s, 0.045), DARK, "plastic", axis="y"))
    tilt = math.radians(12)
    base = np.array([-0.02, 0.0, 0.09])
    up = np.array([-math.sin(tilt), 0.0, math.cos(tilt)])
    g.append(segment("body", base, base + up * 0.45 * s, 0.075 * s, main, mat))
    g.append(segment("bin", base + up * 0.12 * s + np.array([0.05 * s, 0, 0]), base + up * 0.35 * s + np.array([0.05 * s, 0, 0]),
                     0.05 * s, (0.7, 0.8, 0.85, 1.0), "glass", kind="cylinder"))
    top = base + up * 1.0 * hscale(s)
    g.append(segment("pole", base + up * 0.5 * s, top, 0.014, tint("metal"), "metal", kind="cylinder"))
    g.append(segment("grip", top, top + np.array([0.07, 0, 0.05]), 0.02, DARK, "plastic"))
    return finish(g)
