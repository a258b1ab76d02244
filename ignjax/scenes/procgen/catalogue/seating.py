"""Seating: chairs, sofas, armchairs, office chairs, stools, benches, ottomans and dog beds.

Builders ``build_<category>(attrs, rng) -> Built`` in the builder frame of
:mod:`ignjax.scenes.procgen.catalogue`.
"""

from __future__ import annotations

import math

import numpy as np

from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue.parts import (
    Built,
    Surface,
    box,
    disk,
    ellipsoid,
    finish,
    hscale,
    legs4,
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


def build_chair(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A seat, a back and four legs; the back is at -x (the chair faces +x)."""
    s = scale_of(attrs)
    hx = hy = 0.22 * s
    seat_h = 0.45 * s
    main = rgba(attrs.color)
    frame = tint(attrs.material)
    geoms = legs4(hx, hy, seat_h - 0.03 * s, 0.018 * s, frame, attrs.material)
    geoms.append(box("seat", (hx, hy, 0.03 * s), (0, 0, seat_h - 0.015 * s), main, attrs.material))
    back_h = 0.45 * s
    geoms.append(box("back", (0.02 * s, hy, back_h / 2), (-hx + 0.02 * s, 0, seat_h + back_h / 2), main, attrs.material))
    geoms.append(box("back_rail", (0.025 * s, hy * 0.9, 0.03 * s), (-hx + 0.05 * s, 0, seat_h + back_h - 0.05 * s), shade(main, 0.85),
                     attrs.material))
    return finish(geoms)


def _upholstered(attrs: Attributes, width: float, n_cushions: int, *, depth: float, seat_h: float, back_h: float,
                 arm_h: float, arm_w: float, leg_h: float, default: str = "gray") -> Built:
    """Sofa-like seating: legs, a base, rolled armrests, a back, seat and back
    cushions; the seat cushions are the support surface."""
    main = rgba(attrs.color, default=default)
    dark = shade(main, 0.82)
    mat = attrs.material
    hx, hy = depth / 2, width / 2
    g = legs4(hx, hy, leg_h, 0.025, tint("wood"), "wood", inset=0.07)
    base_top = seat_h - 0.14
    g.append(span("base", (-hx, -hy + arm_w, leg_h), (hx - 0.02, hy - arm_w, base_top), dark, mat))
    arm_top = arm_h - arm_w / 2
    for k, sy in enumerate((1, -1)):
        y = sy * (hy - arm_w / 2)
        g.append(span(f"arm{k}", (-hx, y - arm_w / 2, leg_h), (hx, y + arm_w / 2, arm_top), main, mat))
        g.append(disk(f"arm_roll{k}", arm_w / 2, hx, (0, y, arm_top), main, mat, axis="x"))
    back_d = 0.2
    inner = hy - arm_w
    g.append(span("back", (-hx, -inner, base_top), (-hx + back_d, inner, back_h), main, mat))
    seat_x0 = -hx + back_d + 0.14
    cw = 2 * inner / n_cushions
    for k in range(n_cushions):
        y0 = -inner + k * cw
        g.append(span(f"seat_cushion{k}", (-hx + back_d, y0 + 0.003, base_top), (hx - 0.01, y0 + cw - 0.003, seat_h),
                      main if k % 2 == 0 else shade(main, 0.95), mat))
        g.append(span(f"back_cushion{k}", (-hx + back_d, y0 + 0.006, seat_h), (seat_x0, y0 + cw - 0.006, back_h - 0.03),
                      shade(main, 1.06), mat))
    surf = Surface(seat_h, ((hx - 0.02 - seat_x0) / 2 - 0.01, inner - 0.04), ((hx - 0.02 + seat_x0) / 2, 0.0))
    return finish(g, (surf,))


def build_sofa(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A three-seat (two when small) sofa against a wall; the seat is a support."""
    s = scale_of(attrs)
    width = 2.0 * s
    return _upholstered(attrs, width, 3 if width >= 1.8 else 2, depth=0.9, seat_h=0.45, back_h=0.85, arm_h=0.64,
                        arm_w=0.17, leg_h=0.08)


def build_armchair(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A one-seat upholstered chair with rolled arms and a tall back."""
    s = scale_of(attrs)
    return _upholstered(attrs, 0.88 * s, 1, depth=0.85 * s, seat_h=0.44, back_h=0.92 * hscale(s), arm_h=0.64,
                        arm_w=0.15, leg_h=0.12, default="green")


def build_office_chair(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A five-star base on casters, a gas column, a seat, a tilted back and armrests."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="black")
    metal = tint("metal")
    black = rgba("black")
    g = []
    reach = 0.31 * s
    for k in range(5):
        a = 2 * math.pi * k / 5
        end = (reach * math.cos(a), reach * math.sin(a), 0.075)
        g.append(segment(f"star{k}", (0, 0, 0.1), end, 0.02, metal, "metal"))
        g.append(sphere(f"caster{k}", 0.03, (end[0], end[1], 0.03), black, "plastic"))
    seat_h = 0.48 * s
    g.append(disk("sleeve", 0.035, (0.26 - 0.1) / 2, (0, 0, 0.18), black, "plastic"))
    g.append(disk("column", 0.022, (seat_h - 0.08 - 0.1) / 2, (0, 0, (seat_h - 0.08 + 0.1) / 2), metal, "metal"))
    g.append(span("mechanism", (-0.1, -0.1, seat_h - 0.09), (0.1, 0.1, seat_h - 0.05), black, "metal"))
    hs = 0.25 * s
    g.append(box("seat", (hs, hs, 0.04), (0.02, 0, seat_h - 0.01), main, attrs.material))
    tilt = math.radians(12)
    bh = 0.3 * s
    q = quat_axis_angle((0, 1, 0), -tilt)
    bx, bz = -hs - 0.02 + math.sin(tilt) * bh * 0.2, seat_h + 0.1 + bh
    g.append(box("back", (0.035, hs * 0.92, bh), (bx - math.sin(tilt) * bh * 0.5, 0, bz), main, attrs.material, quat=q))
    g.append(segment("back_spine", (-0.15 * s, 0, seat_h - 0.06), (bx - 0.03, 0, seat_h + 0.2), 0.02, black, "metal"))
    for k, sy in enumerate((1, -1)):
        y = sy * (hs + 0.015)
        g.append(span(f"arm_post{k}", (-0.06, y - 0.015, seat_h), (-0.02, y + 0.015, seat_h + 0.2), black, "plastic"))
        g.append(span(f"arm_pad{k}", (-0.14, y - 0.035, seat_h + 0.2), (0.12, y + 0.035, seat_h + 0.23), black, "plastic"))
    return finish(g)


def build_stool(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A bar stool: a round seat on four splayed legs with a foot ring."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    frame = tint(attrs.material)
    h = 0.66 * s
    r_top, r_bot, lr = 0.12 * s, 0.2 * s, 0.016
    g = []
    for k in range(4):
        a = math.pi / 4 + k * math.pi / 2
        c, sn = math.cos(a), math.sin(a)
        g.append(segment(f"leg{k}", (r_bot * c, r_bot * sn, lr), (r_top * c, r_top * sn, h - 0.03), lr, frame, attrs.material))
    zr = 0.25 * s
    rr = r_bot + (r_top - r_bot) * (zr - lr) / (h - 0.03 - lr)
    g += ring("foot_ring", (0, 0, zr), rr, 0.01, 8, frame, attrs.material, start=math.pi / 4, stop=math.pi / 4 + 2 * math.pi)
    g.append(disk("seat", 0.18 * s, 0.025, (0, 0, h - 0.025), main, attrs.material))
    g.append(disk("cushion", 0.165 * s, 0.01, (0, 0, h + 0.008), shade(main, 1.1), attrs.material))
    return finish(g)


def build_bench(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An entryway bench: a long seat on two end panels with a slatted shoe shelf; the seat is a support."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    frame = tint(attrs.material)
    hy, hx, h = 0.6 * s, 0.19, 0.46
    g = [span("seat", (-hx, -hy, h - 0.05), (hx, hy, h), main, attrs.material)]
    for k, sy in enumerate((1, -1)):
        y = sy * (hy - 0.06)
        g.append(span(f"end{k}", (-hx + 0.02, y - 0.025, 0), (hx - 0.02, y + 0.025, h - 0.05), frame, attrs.material))
    for k in range(3):
        x = -hx + 0.06 + k * (2 * hx - 0.12) / 2
        g.append(span(f"slat{k}", (x - 0.04, -hy + 0.085, 0.1), (x + 0.04, hy - 0.085, 0.12), frame, attrs.material))
    return finish(g, (Surface(h, (hx - 0.02, hy - 0.04)),))


def build_ottoman(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An upholstered footstool: a padded body with a cushion top on short legs."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="beige")
    h = 0.3 * s
    g = legs4(h, h, 0.06, 0.02, tint("wood"), "wood", inset=0.04)
    g.append(span("body", (-h, -h, 0.06), (h, h, 0.36), main, attrs.material))
    g.append(span("cushion", (-h + 0.01, -h + 0.01, 0.36), (h - 0.01, h - 0.01, 0.42), shade(main, 1.08), attrs.material))
    g.append(span("piping", (-h - 0.005, -h - 0.005, 0.355), (h + 0.005, h + 0.005, 0.365), shade(main, 0.7), attrs.material))
    return finish(g, (Surface(0.42, (h - 0.05, h - 0.05)),))


def build_dog_bed(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An oval pet bed: a flat cushion inside a rolled rim."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    ax, ay = 0.42 * s, 0.32 * s
    g = [ellipsoid("cushion", (ax - 0.05, ay - 0.05, 0.05), (0, 0, 0.05), shade(main, 1.15), attrs.material)]
    g += ring("rim", (0, 0, 0.08), (ax - 0.07, ay - 0.07), 0.07, 10, main, attrs.material)
    return finish(g)
