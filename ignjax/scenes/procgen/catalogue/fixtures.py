"""Bathroom fixtures (toilets, sinks, bathtubs, showers) and other fixed pieces
(radiators, fireplaces, pianos, safes).

Builders ``build_<category>(attrs, rng) -> Built`` in the builder frame of
:mod:`ignjax.scenes.procgen.catalogue`.
"""

from __future__ import annotations

import math

import numpy as np

from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue.parts import (
    DARK,
    FLAME,
    LIGHT_ON,
    Built,
    Surface,
    box,
    cylinder,
    disk,
    doors_front,
    ellipsoid,
    finish,
    mix,
    quat_axis_angle,
    rgba,
    scale_of,
    segment,
    shade,
    span,
    tint,
)


def build_toilet(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A close-coupled toilet: pedestal, bowl, seat ring, a lid (down when
    closed, raised against the tank when open), a cistern with a flush button."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    mat = attrs.material or "ceramic"
    seat_z = 0.4 * s
    g = [ellipsoid("pedestal", (0.14 * s, 0.12 * s, 0.2 * s), (0.02, 0, 0.2 * s), main, mat),
         ellipsoid("bowl", (0.24 * s, 0.19 * s, 0.11 * s), (0.06 * s, 0, seat_z - 0.11 * s), main, mat),
         ellipsoid("seat", (0.24 * s, 0.19 * s, 0.015), (0.06 * s, 0, seat_z), shade(main, 0.96), mat),
         span("tank", (-0.33 * s, -0.2 * s, seat_z - 0.05), (-0.14 * s, 0.2 * s, seat_z + 0.36 * s), main, mat),
         span("tank_lid", (-0.34 * s, -0.21 * s, seat_z + 0.36 * s), (-0.13 * s, 0.21 * s, seat_z + 0.38 * s), shade(main, 0.95), mat),
         disk("flush", 0.02, 0.004, (-0.235 * s, 0, seat_z + 0.38 * s + 0.004), tint("metal"), "metal")]
    if attrs.state == "open":
        g.append(ellipsoid("opening", (0.16 * s, 0.12 * s, 0.004), (0.08 * s, 0, seat_z + 0.012), (0.72, 0.82, 0.88, 1.0), "ceramic"))
        g.append(ellipsoid("lid", (0.012, 0.18 * s, 0.22 * s), (-0.115 * s, 0, seat_z + 0.23 * s), main, mat,
                           quat=quat_axis_angle((0, 1, 0), -math.radians(8))))
    else:
        g.append(ellipsoid("lid", (0.23 * s, 0.18 * s, 0.012), (0.06 * s, 0, seat_z + 0.02), main, mat))
    return finish(g)


def build_sink(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A vanity: a two-door cabinet, a countertop with a round vessel basin
    (with a drain inside) and a mixer tap; the counter beside the basin is a support."""
    s = scale_of(attrs)
    hy, d, h = 0.42 * s, 0.48, 0.86
    main = rgba(attrs.color, default="white")
    basin = tint(attrs.material if attrs.material in ("ceramic", "metal", "stone") else "ceramic")
    bx, by, br = d / 2 + 0.04, -0.06 * s, 0.17
    g = [span("toe_kick", (0, -hy + 0.02, 0), (d - 0.05, hy - 0.02, 0.08), DARK),
         span("cabinet", (0, -hy, 0.08), (d, hy, h - 0.04), shade(main, 0.9), "wood"),
         span("counter", (0, -hy - 0.01, h - 0.04), (d + 0.02, hy + 0.01, h), main, attrs.material),
         disk("basin_foot", 0.11, 0.02, (bx, by, h + 0.02), basin, attrs.material),
         disk("basin", br, 0.035, (bx, by, h + 0.075), basin, attrs.material),
         disk("basin_inside", br - 0.015, 0.001, (bx, by, h + 0.111), mix(basin, (0.45, 0.55, 0.65), 0.45), attrs.material),
         disk("drain", 0.018, 0.0005, (bx, by, h + 0.1125), DARK, "metal"),
         disk("tap_base", 0.025, 0.02, (0.07, -0.06 * s, h + 0.02), tint("metal"), "metal"),
         segment("tap_neck", (0.07, -0.06 * s, h + 0.02), (0.07, -0.06 * s, h + 0.2), 0.012, tint("metal"), "metal"),
         segment("tap_spout", (0.07, -0.06 * s, h + 0.2), (0.2, -0.06 * s, h + 0.16), 0.011, tint("metal"), "metal")]
    doors_front(g, d, -hy, hy, 0.1, h - 0.06, 2, main, "wood", False)
    y0 = by + br + 0.02
    return finish(g, (Surface(h, (0.13, (hy - 0.02 - y0) / 2), (d / 2 + 0.02, (hy - 0.02 + y0) / 2)),))


def build_bathtub(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A built-in bath: an apron front, thick rims, a white interior with water-blue floor, a tap at one end."""
    s = scale_of(attrs)
    hy, d, h = 0.85 * s, 0.76, 0.56
    main = rgba(attrs.color, default="white")
    mat = attrs.material or "ceramic"
    inner = rgba("white")
    t = 0.09
    g = [span("apron", (d - 0.04, -hy, 0), (d, hy, h - 0.02), main, mat),
         span("base", (0, -hy, 0), (d - 0.04, hy, 0.1), shade(main, 0.9), mat),
         span("floor", (t, -hy + t, 0.1), (d - t, hy - t, 0.12), (0.78, 0.88, 0.95, 1.0), mat),
         span("rim_back", (0, -hy, 0.1), (t, hy, h), main, mat),
         span("rim_front", (d - t, -hy, h - 0.03), (d, hy, h), main, mat),
         span("rim_end0", (0, hy - t, 0.1), (d, hy, h), main, mat),
         span("rim_end1", (0, -hy, 0.1), (d, -hy + t, h), main, mat),
         span("wall_front", (d - t, -hy + t, 0.1), (d - t + 0.02, hy - t, h - 0.03), inner, mat)]
    tap = tint("metal")
    g.append(segment("tap_riser", (t / 2, -hy + t / 2 + 0.05, h), (t / 2, -hy + t / 2 + 0.05, h + 0.12), 0.015, tap, "metal"))
    g.append(segment("tap_spout", (t / 2, -hy + t / 2 + 0.05, h + 0.12), (t / 2 + 0.03, -hy + t + 0.1, h + 0.1), 0.013, tap, "metal"))
    return finish(g)


def build_shower(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A shower enclosure: a tray, a tiled back panel, glass side and front panels
    in a metal frame, a riser with a round head and a mixer."""
    s = scale_of(attrs)
    hy, d, h = 0.45 * s, 0.9 * s, 2.0
    tile = rgba(attrs.color, default="white")
    glass = (0.75, 0.88, 0.95, 0.35)
    metal = tint("metal")
    g = [span("tray", (0, -hy, 0), (d, hy, 0.06), rgba("white"), "ceramic"),
         span("back", (0, -hy, 0.06), (0.03, hy, h), tile, attrs.material),
         span("side_glass", (0.03, hy - 0.008, 0.06), (d, hy, h - 0.02), glass, "glass"),
         span("front_glass", (d - 0.008, -hy, 0.06), (d, hy - 0.01, h - 0.02), glass, "glass"),
         span("frame_top_side", (0.03, hy - 0.015, h - 0.02), (d, hy, h), metal, "metal"),
         span("frame_top_front", (d - 0.015, -hy, h - 0.02), (d, hy, h), metal, "metal"),
         segment("door_handle", (d + 0.025, -hy * 0.2, 0.9), (d + 0.025, -hy * 0.2, 1.2), 0.012, metal, "metal"),
         disk("drain", 0.04, 0.001, (d / 2, 0, 0.061), metal, "metal"),
         segment("riser", (0.05, 0.0, 1.0), (0.05, 0.0, 1.9), 0.012, metal, "metal"),
         segment("arm", (0.05, 0.0, 1.9), (0.18, 0.0, 1.9), 0.01, metal, "metal"),
         cylinder("head", 0.08, 0.012, (0.2, 0.0, 1.88), metal, "metal", quat=quat_axis_angle((0, 1, 0), math.radians(25))),
         disk("mixer", 0.035, 0.02, (0.05, 0.0, 1.05), metal, "metal", axis="x")]
    return finish(g)


def build_radiator(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A column radiator: vertical sections between top and bottom headers, on two feet, with a valve."""
    s = scale_of(attrs)
    n = max(6, int(round(12 * s)))
    main = rgba(attrs.color, default="white")
    pitch = 0.065
    w = (n - 1) * pitch
    z0, z1 = 0.12, 0.7
    g = []
    for k in range(n):
        y = -w / 2 + k * pitch
        g.append(segment(f"column{k}", (0.06, y, z0 + 0.03), (0.06, y, z1 - 0.03), 0.025, main, attrs.material))
    g.append(segment("header_top", (0.06, -w / 2, z1 - 0.04), (0.06, w / 2, z1 - 0.04), 0.02, main, attrs.material))
    g.append(segment("header_bottom", (0.06, -w / 2, z0 + 0.04), (0.06, w / 2, z0 + 0.04), 0.02, main, attrs.material))
    for k, sy in enumerate((1, -1)):
        g.append(span(f"foot{k}", (0.03, sy * (w / 2 - 0.06) - 0.015, 0), (0.09, sy * (w / 2 - 0.06) + 0.015, z0), main, attrs.material))
    g.append(disk("valve", 0.02, 0.03, (0.06, w / 2 + 0.06, z0 + 0.04), tint("metal"), "metal", axis="y"))
    g.append(span("wall_bracket", (0.0, -0.02, z1 - 0.06), (0.04, 0.02, z1 - 0.02), main, attrs.material))
    return finish(g)


def build_fireplace(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A chimney breast fireplace: a surround with a dark firebox, a mantel shelf
    (the support), a hearth slab and logs; on adds flames."""
    s = scale_of(attrs)
    hy, d, h = 0.7 * s, 0.32, 1.1
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    ow, oh = 0.42 * s, 0.62
    g = [span("breast", (0, -hy, 0), (0.06, hy, h), main, mat),
         span("jamb0", (0, ow, 0), (d, hy, h - 0.05), main, mat),
         span("jamb1", (0, -hy, 0), (d, -ow, h - 0.05), main, mat),
         span("lintel", (0, -ow, oh), (d, ow, h - 0.05), main, mat),
         span("firebox", (0.06, -ow, 0.04), (0.1, ow, oh), DARK),
         span("mantel", (0, -hy - 0.06, h - 0.05), (d + 0.06, hy + 0.06, h), shade(main, 0.85), mat),
         span("hearth", (0, -hy - 0.05, 0), (d + 0.35, hy + 0.05, 0.04), tint("stone"), "stone")]
    for k in range(2):
        g.append(disk(f"log{k}", 0.045, ow * 0.65, (0.16 + 0.07 * k, 0, 0.085 + 0.06 * k), (0.4, 0.24, 0.12, 1.0), "wood", axis="y"))
    if attrs.state == "on":
        for k, (y, hz) in enumerate(((-0.12, 0.13), (0.0, 0.18), (0.13, 0.12))):
            g.append(ellipsoid(f"flame{k}", (0.04, 0.07, hz), (0.18, y * s, 0.15 + hz * 0.8), FLAME, "glass"))
        g.append(ellipsoid("flame_core", (0.03, 0.05, 0.09), (0.2, 0, 0.2), LIGHT_ON, "glass"))
    return finish(g, (Surface(h, ((d + 0.06) / 2 - 0.02, hy - 0.02), ((d + 0.06) / 2, 0.0)),))


def build_piano(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An upright piano: a tall case, a keybed with white and black keys, a
    music desk, front legs and pedals; the lid is a support."""
    s = scale_of(attrs)
    hy, h = 0.75 * s, 1.22
    main = rgba(attrs.color, default="black")
    mat = attrs.material
    white = rgba("white")
    g = [span("case", (0, -hy, 0), (0.32, hy, h), main, mat),
         span("lid", (0, -hy - 0.01, h - 0.02), (0.34, hy + 0.01, h), shade(main, 1.3) if max(main[:3]) < 0.2 else shade(main, 0.9), mat),
         span("keybed", (0.32, -hy, 0.64), (0.6, hy, 0.72), main, mat),
         span("white_keys", (0.34, -hy + 0.06, 0.72), (0.58, hy - 0.06, 0.745), white, "plastic"),
         span("key_slip", (0.58, -hy + 0.06, 0.72), (0.6, hy - 0.06, 0.755), main, mat),
         span("fallboard", (0.32, -hy + 0.04, 0.72), (0.34, hy - 0.04, 0.82), main, mat),
         box("music_desk", (0.01, hy * 0.4, 0.1), (0.35, 0, 0.95), main, mat, quat=quat_axis_angle((0, 1, 0), -math.radians(12)))]
    span_keys = 2 * hy - 0.12
    octaves = 4  # drawn wider than real octaves: the pattern of twos and threes is what reads as a keyboard
    ow = span_keys / octaves
    k = 0
    for o in range(octaves):
        for off in (1, 2, 4, 5, 6):  # black keys sit between white keys C-D, D-E, F-G, G-A, A-B
            y = -hy + 0.06 + o * ow + off / 7 * ow
            g.append(span(f"black_key{k}", (0.42, y - 0.006, 0.745), (0.58, y + 0.006, 0.765), rgba("black"), "plastic"))
            k += 1
    for j, sy in enumerate((1, -1)):
        g.append(segment(f"leg{j}", (0.55, sy * (hy - 0.05), 0.0), (0.55, sy * (hy - 0.05), 0.64), 0.03, main, mat, kind="cylinder"))
    for j in range(2):
        g.append(span(f"pedal{j}", (0.32, -0.06 + j * 0.08, 0.06), (0.4, -0.04 + j * 0.08, 0.075), (0.85, 0.7, 0.3, 1.0), "metal"))
    return finish(g, (Surface(h, (0.15, hy - 0.04), (0.17, 0.0)),))


def build_safe(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A steel safe: a heavy cube with an inset door, hinges, a combination dial and a spoked handle."""
    s = scale_of(attrs)
    c = 0.22 * s
    main = rgba(attrs.color, default="gray")
    metal = tint("metal")
    g = [span("body", (-c, -c, 0.02), (c, c, 2 * c + 0.02), main, attrs.material),
         span("feet", (-c + 0.02, -c + 0.02, 0), (c - 0.02, c - 0.02, 0.02), DARK),
         span("door", (c, -c + 0.03, 0.05), (c + 0.02, c - 0.03, 2 * c - 0.01), shade(main, 0.85), attrs.material),
         disk("dial", 0.045 * s, 0.01, (c + 0.03, -0.03, c + 0.1 * s), metal, "metal", axis="x"),
         disk("hub", 0.015, 0.015, (c + 0.035, 0.08 * s, c - 0.06 * s), metal, "metal", axis="x")]
    for k in range(3):
        a = 2 * math.pi * k / 3
        end = (c + 0.045, 0.08 * s + 0.06 * s * math.cos(a), c - 0.06 * s + 0.06 * s * math.sin(a))
        g.append(segment(f"spoke{k}", (c + 0.045, 0.08 * s, c - 0.06 * s), end, 0.007, metal, "metal"))
    for k, z in enumerate((0.12, 2 * c - 0.08)):
        g.append(disk(f"hinge{k}", 0.012, 0.035, (c + 0.01, c - 0.03, z), metal, "metal"))
    return finish(g)
