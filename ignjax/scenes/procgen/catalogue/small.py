"""Small objects placed on support surfaces: laptops, books, tableware, lamps, clocks,
kitchenware, decorations, toys and sports gear.

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
    FLAME,
    LIGHT_ON,
    Built,
    box,
    capsule,
    disk,
    ellipsoid,
    finish,
    glow,
    mix,
    pick,
    quat_axis_angle,
    quat_from_z,
    quat_mul,
    rgba,
    ring,
    scale_of,
    segment,
    shade,
    span,
    sphere,
    tint,
)


def build_laptop(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A base with a keyboard deck and a screen: raised (open) or folded flat (closed).

    The screen hinges at the back edge (-x); open, it leans back 20 degrees
    from vertical so the display faces +x.
    """
    s = scale_of(attrs)
    hx, hy, t = 0.12 * s, 0.17 * s, 0.01 * s
    shell = rgba(attrs.color, default="gray")
    geoms = [box("base", (hx, hy, t), (0, 0, t), shell, attrs.material),
             box("keyboard", (hx * 0.45, hy * 0.85, 0.002), (-0.025 * s, 0, 2 * t + 0.002), rgba("black"), "plastic"),
             box("touchpad", (hx * 0.2, hy * 0.25, 0.001), (hx * 0.68, 0, 2 * t + 0.001), shade(shell, 0.85), attrs.material)]
    if attrs.state == "closed":
        geoms.append(box("lid", (hx, hy, t * 0.6), (0, 0, 2 * t + 0.008), shell, attrs.material))
        return finish(geoms)
    tilt = math.radians(20.0)
    sh = 0.11 * s  # screen half height
    cx = -hx - math.sin(tilt) * sh + 0.005
    cz = 2 * t + math.cos(tilt) * sh
    q = quat_axis_angle((0, 1, 0), -tilt)
    geoms.append(box("screen", (0.006, hy, sh), (cx, 0, cz), shell, attrs.material, quat=q))
    geoms.append(box("display", (0.001, hy * 0.9, sh * 0.88), (cx + 0.007 * math.cos(tilt), 0, cz + 0.007 * math.sin(tilt)),
                     (0.15, 0.25, 0.45, 1.0), "glass", quat=q))
    return finish(geoms)


def build_book(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A hardback lying flat: two cover boards and a spine in its colour around a block of pages."""
    s = scale_of(attrs)
    hx, hy = 0.075 * s, 0.115 * s
    th = 0.03 * s * float(rng.uniform(0.7, 1.3))
    main = rgba(attrs.color, default="blue")
    c = 0.003
    g = [span("cover_bottom", (-hx, -hy, 0), (hx, hy, c), main, attrs.material),
         span("cover_top", (-hx, -hy, th - c), (hx, hy, th), main, attrs.material),
         span("spine", (-hx, -hy, c), (-hx + c, hy, th - c), shade(main, 0.85), attrs.material),
         span("pages", (-hx + c, -hy + 0.004, c), (hx - 0.004, hy - 0.004, th - c), (0.96, 0.94, 0.86, 1.0), "fabric")]
    return finish(g)


_BLOOMS = ("red", "yellow", "pink", "white", "purple", "orange")


def build_vase(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A vase of stacked forms (foot, bulbous body, neck, lip); full holds a bunch of flowers."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="blue")
    mat = attrs.material
    g = [disk("foot", 0.05 * s, 0.01 * s, (0, 0, 0.01 * s), shade(main, 0.85), mat),
         ellipsoid("body", (0.085 * s, 0.085 * s, 0.11 * s), (0, 0, 0.12 * s), main, mat),
         disk("neck", 0.035 * s, 0.05 * s, (0, 0, 0.25 * s), main, mat),
         disk("lip", 0.047 * s, 0.008 * s, (0, 0, 0.3 * s), shade(main, 0.9), mat)]
    if attrs.state == "full":
        top = np.array([0, 0, 0.3 * s])
        for k in range(5):
            a = 2 * math.pi * k / 5 + float(rng.uniform(-0.3, 0.3))
            lean = float(rng.uniform(0.15, 0.45))
            hgt = float(rng.uniform(0.16, 0.24)) * s
            tip = top + np.array([math.sin(lean) * math.cos(a), math.sin(lean) * math.sin(a), math.cos(lean)]) * hgt
            g.append(segment(f"stem{k}", top, tip, 0.004, (0.25, 0.5, 0.2, 1.0), "wood"))
            g.append(sphere(f"flower{k}", 0.03 * s, tuple(tip), rgba(pick(rng, _BLOOMS)), "fabric"))
        for k in range(2):
            a = k * math.pi + 0.6
            g.append(ellipsoid(f"leaf{k}", (0.07 * s, 0.025 * s, 0.006), (0.05 * s * math.cos(a), 0.05 * s * math.sin(a), 0.34 * s),
                               (0.2, 0.55, 0.22, 1.0), "fabric",
                               quat=quat_mul(quat_axis_angle((0, 0, 1), a), quat_axis_angle((0, 1, 0), -0.5))))
    return finish(g)


def _dish(g: list, main, mat, radii: tuple[float, float, float], heights: tuple[float, float, float], inner) -> float:
    """Append a stepped bowl (foot, lower and upper walls) with a darker inside; returns its rim height."""
    z = 0.0
    for name, r, hz in zip(("foot", "lower", "upper"), radii, heights):
        g.append(disk(name, r, hz / 2, (0, 0, z + hz / 2), main if name != "foot" else shade(main, 0.85), mat))
        z += hz
    g.append(disk("inside", radii[2] * 0.9, 0.0008, (0, 0, z + 0.0008), inner, mat))
    return z


def build_bowl(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A small serving bowl (about 15 cm across); full shows a mound of food."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    g: list = []
    rim = _dish(g, main, attrs.material, (0.035 * s, 0.055 * s, 0.075 * s), (0.01 * s, 0.025 * s, 0.035 * s), shade(main, 0.8))
    if attrs.state == "full":
        food = rgba(pick(rng, ("red", "green", "orange", "purple", "yellow")))
        for k in range(6):
            a = 2 * math.pi * k / 6 + float(rng.uniform(-0.2, 0.2))
            g.append(sphere(f"food{k}", 0.022 * s, (0.04 * s * math.cos(a), 0.04 * s * math.sin(a), rim + 0.008 * s),
                            shade(food, float(rng.uniform(0.85, 1.1))), "fabric"))
        g.append(sphere("food_top", 0.022 * s, (0, 0, rim + 0.03 * s), food, "fabric"))
    return finish(g)


def build_fruit_bowl(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A wide shallow bowl (about 30 cm across); full holds apples, oranges and a bunch of bananas."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    g: list = []
    rim = _dish(g, main, attrs.material, (0.06 * s, 0.11 * s, 0.15 * s), (0.015 * s, 0.025 * s, 0.03 * s), shade(main, 0.8))
    if attrs.state == "full":
        fruit = ((0.8, 0.1, 0.1, 1.0), (0.95, 0.55, 0.1, 1.0), (0.55, 0.8, 0.2, 1.0))
        for k in range(4):
            a = 2 * math.pi * k / 4 + float(rng.uniform(-0.3, 0.3))
            g.append(sphere(f"fruit{k}", 0.038 * s, (0.07 * s * math.cos(a), 0.07 * s * math.sin(a), rim + 0.02 * s),
                            fruit[int(rng.integers(len(fruit)))], "fabric"))
        g.append(sphere("fruit_top", 0.036 * s, (0, 0, rim + 0.06 * s), fruit[int(rng.integers(len(fruit)))], "fabric"))
        for k in range(3):
            q = quat_axis_angle((0, 0, 1), 0.3 * k - 0.3)
            g.append(capsule(f"banana{k}", 0.016 * s, 0.06 * s, (-0.02 * s + 0.02 * s * k, 0.02 * s * (k - 1), rim + 0.065 * s),
                             (0.95, 0.85, 0.25, 1.0), "fabric", quat=quat_mul(q, AXIS_QUAT["x"])))
    return finish(g)


def build_cup(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tumbler cup without a handle, tapering out towards its rim (about 8 cm across, 10 cm tall)."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    g = [disk("lower", 0.03 * s, 0.025 * s, (0, 0, 0.025 * s), main, attrs.material),
         disk("middle", 0.034 * s, 0.025 * s, (0, 0, 0.075 * s - 0.001), main, attrs.material),
         disk("rim", 0.038 * s, 0.006 * s, (0, 0, 0.1 * s - 0.006 * s), shade(main, 0.92), attrs.material),
         disk("inside", 0.033 * s, 0.0008, (0, 0, 0.1 * s + 0.0008), shade(main, 0.6), attrs.material)]
    return finish(g)


def build_mug(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A mug: a straight cylinder with a looped handle and a dark opening."""
    s = scale_of(attrs)
    r, h = 0.042 * s, 0.1 * s
    main = rgba(attrs.color, default="white")
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, attrs.material),
         disk("inside", r * 0.85, 0.0008, (0, 0, h + 0.0008), (0.22, 0.13, 0.07, 1.0), attrs.material)]
    g += ring("handle", (0, r - 0.004, h / 2), (0.032 * s, 0.033 * s), 0.007 * s, 4, main, attrs.material, u=(0, 1, 0), v=(0, 0, 1),
              start=-math.pi / 2, stop=math.pi / 2)
    return finish(g)


def build_plate(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A dinner plate (about 26 cm across): a foot ring, a thin disc and a slightly raised well."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    g = [disk("foot", 0.07 * s, 0.003, (0, 0, 0.003), shade(main, 0.9), attrs.material),
         disk("plate", 0.13 * s, 0.005, (0, 0, 0.011), main, attrs.material),
         disk("rim_band", 0.128 * s, 0.0006, (0, 0, 0.0166), shade(main, 0.85), attrs.material),
         disk("well", 0.09 * s, 0.0008, (0, 0, 0.0172), main, attrs.material)]
    return finish(g)


def build_bottle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A water bottle: a body with a label band, a rounded shoulder, a neck and a cap."""
    s = scale_of(attrs)
    r = 0.035 * s
    main = rgba(attrs.color, default="blue", alpha=1.0)
    g = [disk("body", r, 0.085 * s, (0, 0, 0.085 * s), main, attrs.material),
         disk("label", r + 0.001, 0.03 * s, (0, 0, 0.09 * s), rgba("white"), "fabric"),
         ellipsoid("shoulder", (r, r, 0.035 * s), (0, 0, 0.17 * s), main, attrs.material),
         disk("neck", 0.014 * s, 0.02 * s, (0, 0, 0.215 * s), main, attrs.material),
         disk("cap", 0.016 * s, 0.01 * s, (0, 0, 0.24 * s), shade(main, 0.6), "plastic")]
    return finish(g)


def build_wine_bottle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A wine bottle: a dark glass body with a paper label, a sloping shoulder, a long neck and a foil capsule."""
    s = scale_of(attrs)
    r = 0.038 * s
    main = rgba(attrs.color, default="green")
    foil = rgba(pick(rng, ("red", "yellow", "black", "purple")))
    g = [disk("body", r, 0.1 * s, (0, 0, 0.1 * s), main, attrs.material),
         disk("label", r + 0.001, 0.035 * s, (0, 0, 0.09 * s), (0.93, 0.9, 0.8, 1.0), "fabric"),
         ellipsoid("shoulder", (r, r, 0.05 * s), (0, 0, 0.2 * s), main, attrs.material),
         disk("neck", 0.014 * s, 0.045 * s, (0, 0, 0.275 * s), main, attrs.material),
         disk("foil", 0.0155 * s, 0.025 * s, (0, 0, 0.305 * s), foil, "metal")]
    return finish(g)


def build_table_lamp(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A bedside lamp: a base, a bulbous body, a neck and a drum shade (glowing, with a lit bulb below, when on)."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    on = attrs.state == "on"
    shade_c = glow(main) if on else mix(main, rgba("beige"), 0.25)
    g = [disk("base", 0.07 * s, 0.012 * s, (0, 0, 0.012 * s), shade(main, 0.8), attrs.material),
         ellipsoid("body", (0.065 * s, 0.065 * s, 0.09 * s), (0, 0, 0.1 * s), main, attrs.material),
         disk("neck", 0.01, 0.06 * s, (0, 0, 0.24 * s), tint("metal"), "metal"),
         disk("lamp_shade", 0.14 * s, 0.09 * s, (0, 0, 0.33 * s), shade_c, "fabric"),
         disk("diffuser", 0.13 * s, 0.002, (0, 0, 0.24 * s - 0.003), LIGHT_ON if on else shade(shade_c, 0.7), "glass")]
    if on:
        g.append(sphere("bulb", 0.022 * s, (0, 0, 0.24 * s - 0.02 * s), LIGHT_ON, "glass"))
    return finish(g)


def build_candle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A pillar candle on a holder dish with a wick; on (lit) adds a flame."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    holder = tint(attrs.material or "metal")
    h = 0.12 * s
    g = [disk("holder", 0.045 * s, 0.005, (0, 0, 0.005), holder, attrs.material),
         disk("candle", 0.025 * s, h / 2, (0, 0, 0.01 + h / 2), main, "plastic"),
         segment("wick", (0, 0, 0.01 + h), (0, 0, 0.01 + h + 0.01), 0.0015, DARK)]
    if attrs.state == "on":
        g.append(ellipsoid("flame", (0.007, 0.007, 0.018), (0, 0, 0.01 + h + 0.025), FLAME, "glass"))
        g.append(ellipsoid("flame_core", (0.004, 0.004, 0.009), (0, 0, 0.01 + h + 0.02), LIGHT_ON, "glass"))
    return finish(g)


def build_alarm_clock(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A twin-bell alarm clock: a round body facing +x, a white dial with hands, two bells, a hammer and feet."""
    s = scale_of(attrs)
    r = 0.055 * s
    main = rgba(attrs.color, default="red")
    metal = tint("metal")
    zc = 0.012 + r
    g = [disk("body", r, 0.025 * s, (0, 0, zc), main, attrs.material, axis="x"),
         disk("dial", r * 0.85, 0.002, (0.025 * s + 0.002, 0, zc), rgba("white"), "plastic", axis="x")]
    hour, minute = float(rng.uniform(0, 2 * math.pi)), float(rng.uniform(0, 2 * math.pi))
    for name, a, ln in (("hour_hand", hour, 0.025 * s), ("minute_hand", minute, 0.038 * s)):
        g.append(box(name, (0.001, 0.0025, ln / 2), (0.025 * s + 0.005, -math.sin(a) * ln / 2, zc + math.cos(a) * ln / 2), DARK, "metal",
                     quat=quat_axis_angle((1, 0, 0), a)))
    for k, sy in enumerate((1, -1)):
        g.append(sphere(f"bell{k}", 0.024 * s, (0, sy * 0.035 * s, zc + r + 0.005 * s), main, attrs.material))
        g.append(segment(f"foot{k}", (0.0, sy * 0.03 * s, zc - r * 0.8), (0.0, sy * 0.045 * s, 0.006), 0.006, metal, "metal"))
    g.append(segment("hammer", (0, 0, zc + r), (0, 0, zc + r + 0.03 * s), 0.004, metal, "metal"))
    return finish(g)


def build_keyboard(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A computer keyboard: a slim tray with five rows of keys and a space bar."""
    s = scale_of(attrs)
    hx, hy = 0.07 * s, 0.22 * s
    main = rgba(attrs.color, default="black")
    keys = shade(main, 1.6) if max(main[:3]) < 0.3 else shade(main, 0.75)
    g = [span("tray", (-hx, -hy, 0), (hx, hy, 0.012), main, attrs.material)]
    pitch = (2 * hx - 0.02) / 6
    for k in range(5):
        x = hx - 0.01 - (k + 0.5) * pitch
        g.append(span(f"key_row{k}", (x - pitch * 0.4, -hy + 0.012, 0.012), (x + pitch * 0.4, hy - 0.012, 0.02), keys, "plastic"))
    x = hx - 0.01 - 5.5 * pitch
    g.append(span("space_bar", (x - pitch * 0.4, -hy * 0.35, 0.012), (x + pitch * 0.4, hy * 0.35, 0.02), keys, "plastic"))
    return finish(g)


def build_pot(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A cooking pot: a cylindrical body with a rolled rim, a lid with a knob and two side handles."""
    s = scale_of(attrs)
    r, h = 0.11 * s, 0.13 * s
    main = rgba(attrs.color, default="gray")
    metal = tint("metal")
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, attrs.material),
         disk("rim", r + 0.004, 0.005, (0, 0, h - 0.005), shade(main, 0.9), attrs.material),
         disk("lid", r - 0.002, 0.005, (0, 0, h + 0.005), shade(main, 1.1), attrs.material),
         sphere("knob", 0.016, (0, 0, h + 0.022), DARK, "plastic")]
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"handle{k}", (0, sy * (r - 0.005), h - 0.025), (0, sy * (r + 0.035), h - 0.02), 0.01, metal, "metal"))
    return finish(g)


def build_pan(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A frying pan: a shallow body with a dark non-stick inside and a long handle."""
    s = scale_of(attrs)
    r = 0.13 * s
    main = rgba(attrs.color, default="black")
    g = [disk("body", r, 0.02 * s, (0, 0, 0.02 * s), main, attrs.material),
         disk("inside", r * 0.9, 0.0008, (0, 0, 0.04 * s + 0.0008), (0.12, 0.12, 0.13, 1.0), attrs.material),
         segment("handle", (0, r - 0.01, 0.03 * s), (0, r + 0.2 * s, 0.05 * s), 0.012, DARK, "plastic")]
    return finish(g)


def build_cutting_board(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A chopping board with a handle tab and a hanging hole."""
    s = scale_of(attrs)
    hx, hy = 0.15 * s, 0.2 * s
    main = rgba(attrs.color, default="brown")
    g = [span("board", (-hx, -hy, 0), (hx, hy, 0.018), main, attrs.material),
         span("tab", (-hx * 0.4, hy, 0), (hx * 0.4, hy + 0.06 * s, 0.018), main, attrs.material),
         disk("hole", 0.012, 0.0006, (0, hy + 0.03 * s, 0.0186), DARK),
         span("groove", (-hx + 0.015, -hy + 0.015, 0.018), (hx - 0.015, -hy + 0.02, 0.0186), shade(main, 0.75), attrs.material)]
    return finish(g)


def build_pillow(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A square scatter cushion: a plump ellipsoid over a rounded-square core, with piping."""
    s = scale_of(attrs)
    a = 0.22 * s
    main = rgba(attrs.color, default="white")
    g = [box("core", (a * 0.9, a * 0.9, 0.045 * s), (0, 0, 0.06 * s), main, attrs.material),
         ellipsoid("puff", (a, a, 0.075 * s), (0, 0, 0.075 * s), main, attrs.material),
         box("piping", (a * 0.93, a * 0.93, 0.006), (0, 0, 0.075 * s), shade(main, 0.8), attrs.material)]
    return finish(g)


def build_teddy_bear(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A sitting teddy bear facing +x: body, head with ears and snout, arms, legs and eyes."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    light = mix(main, rgba("beige"), 0.5)
    k = s
    g = [ellipsoid("body", (0.065 * k, 0.075 * k, 0.085 * k), (0, 0, 0.09 * k), main, "fabric"),
         ellipsoid("belly", (0.02 * k, 0.05 * k, 0.06 * k), (0.052 * k, 0, 0.085 * k), light, "fabric"),
         sphere("head", 0.058 * k, (0.01 * k, 0, 0.215 * k), main, "fabric"),
         ellipsoid("snout", (0.025 * k, 0.028 * k, 0.02 * k), (0.06 * k, 0, 0.205 * k), light, "fabric"),
         sphere("nose", 0.008 * k, (0.085 * k, 0, 0.212 * k), DARK, "plastic")]
    for j, sy in enumerate((1, -1)):
        g.append(sphere(f"ear{j}", 0.022 * k, (0.0, sy * 0.045 * k, 0.265 * k), main, "fabric"))
        g.append(sphere(f"eye{j}", 0.007 * k, (0.058 * k, sy * 0.02 * k, 0.232 * k), DARK, "plastic"))
        g.append(ellipsoid(f"arm{j}", (0.022 * k, 0.022 * k, 0.055 * k), (0.025 * k, sy * 0.075 * k, 0.11 * k), main, "fabric",
                           quat=quat_axis_angle((1, 0, 0), sy * 0.35)))
        g.append(ellipsoid(f"leg{j}", (0.06 * k, 0.03 * k, 0.028 * k), (0.06 * k, sy * 0.045 * k, 0.028 * k), main, "fabric"))
        g.append(ellipsoid(f"paw{j}", (0.004 * k, 0.022 * k, 0.02 * k), (0.118 * k, sy * 0.045 * k, 0.03 * k), light, "fabric"))
    return finish(g)


def build_basket(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A woven carry basket: a tapered body with bands, a rim, a dark inside and an arched handle."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="beige")
    mat = attrs.material
    r0, r1, h = 0.12 * s, 0.15 * s, 0.14 * s
    g = [disk("lower", r0, h * 0.25, (0, 0, h * 0.25), shade(main, 0.9), mat),
         disk("upper", r1, h * 0.25, (0, 0, h * 0.75), main, mat),
         disk("rim", r1 + 0.006, 0.007, (0, 0, h - 0.007), shade(main, 0.75), mat),
         disk("inside", r1 - 0.01, 0.0008, (0, 0, h + 0.0008), (0.2, 0.15, 0.1, 1.0), mat),
         disk("band", r0 + 0.003, 0.005, (0, 0, h * 0.25), shade(main, 0.7), mat)]
    g += ring("handle", (0, 0, h), (r1, 0.14 * s), 0.009, 6, shade(main, 0.8), mat, u=(0, 1, 0), v=(0, 0, 1), start=0.0, stop=math.pi)
    return finish(g)


def build_picture_frame(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A standing photo frame leaning back on a kickstand; the photo (sky over ground) faces +x."""
    s = scale_of(attrs)
    hy, hz = 0.09 * s, 0.12 * s
    main = rgba(attrs.color, default="black")
    tilt = math.radians(12)
    q = quat_axis_angle((0, 1, 0), -tilt)
    up = np.array([-math.sin(tilt), 0, math.cos(tilt)])
    fwd = np.array([math.cos(tilt), 0, math.sin(tilt)])
    c = np.array([0.0, 0.0, 0.0]) + up * hz + fwd * 0.0
    sky = rgba(pick(rng, ("blue", "white", "orange")))
    ground = rgba(pick(rng, ("green", "beige", "gray", "brown")))
    g = [box("frame", (0.008, hy, hz), tuple(c), main, attrs.material, quat=q),
         box("photo_sky", (0.001, hy * 0.78, hz * 0.4), tuple(c + fwd * 0.009 + up * hz * 0.4), sky, "glass", quat=q),
         box("photo_ground", (0.001, hy * 0.78, hz * 0.4), tuple(c + fwd * 0.009 - up * hz * 0.4), ground, "glass", quat=q),
         segment("kickstand", c - fwd * 0.008, np.array([-0.09 * s, 0, 0.004]), 0.004, main, attrs.material)]
    return finish(g)


def build_soap_dispenser(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A pump soap bottle: a round body, a collar, a pump head with a spout pointing +x."""
    s = scale_of(attrs)
    r = 0.035 * s
    main = rgba(attrs.color, default="white")
    metal = tint("metal")
    g = [disk("body", r, 0.06 * s, (0, 0, 0.06 * s), main, attrs.material),
         disk("collar", 0.016 * s, 0.008, (0, 0, 0.12 * s + 0.008), metal, "metal"),
         disk("stem", 0.007, 0.012, (0, 0, 0.12 * s + 0.028), metal, "metal"),
         disk("pump_head", 0.014 * s, 0.008, (0, 0, 0.12 * s + 0.046), metal, "metal"),
         segment("spout", (0, 0, 0.12 * s + 0.046), (0.045 * s, 0, 0.12 * s + 0.04), 0.005, metal, "metal")]
    return finish(g)


def build_towel(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A stack of two folded bath towels with rounded folded edges."""
    s = scale_of(attrs)
    hx, hy, t = 0.14 * s, 0.2 * s, 0.025 * s
    main = rgba(attrs.color, default="white")
    g = []
    for k in range(2):
        dx = float(rng.uniform(-0.01, 0.01))
        z = k * 2 * t
        c = main if k == 0 else shade(main, 0.95)
        g.append(span(f"towel{k}", (-hx + dx, -hy, z), (hx - t + dx, hy, z + 2 * t), c, "fabric"))
        g.append(disk(f"fold{k}", t, hy, (hx - t + dx, 0, z + t), c, "fabric", axis="y"))
    return finish(g)


def build_tissue_box(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tissue box: a printed box with a dark slot and a tissue poking out of the top."""
    s = scale_of(attrs)
    hx, hy, h = 0.06 * s, 0.12 * s, 0.09 * s
    main = rgba(attrs.color, default="blue")
    g = [span("box", (-hx, -hy, 0), (hx, hy, h), main, attrs.material),
         ellipsoid("slot", (0.02 * s, 0.07 * s, 0.001), (0, 0, h + 0.0005), DARK),
         ellipsoid("tissue", (0.012 * s, 0.045 * s, 0.035 * s), (0, 0, h + 0.02 * s), rgba("white"), "fabric",
                   quat=quat_axis_angle((0, 0, 1), 0.2))]
    return finish(g)


def build_globe(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A desk globe: a base, a stem, a tilted half meridian and a sphere with continents."""
    s = scale_of(attrs)
    R = 0.15 * s
    ocean = rgba(attrs.color, default="blue")
    stand = tint(attrs.material or "wood")
    zc = 0.05 + R + 0.03
    tilt = math.radians(23.4)
    axis = np.array([math.sin(tilt), 0.0, math.cos(tilt)])
    side = np.array([math.cos(tilt), 0.0, -math.sin(tilt)])
    g = [disk("base", 0.085 * s, 0.012, (0, 0, 0.012), stand, attrs.material),
         disk("stem", 0.012, (zc - R - 0.024) / 2 + 0.01, (0, 0, 0.024 + (zc - R - 0.024) / 2), stand, attrs.material),
         sphere("globe", R, (0, 0, zc), ocean, "plastic")]
    g += ring("meridian", (0, 0, zc), R + 0.012, 0.005, 7, tint("metal"), "metal", u=axis, v=-side, start=0.0, stop=math.pi)
    land = ((0.35, 0.6, 0.25, 1.0), (0.7, 0.6, 0.35, 1.0))
    for k, (lat, lon) in enumerate(((0.6, 0.3), (0.0, 0.9), (-0.4, 0.4), (0.5, 2.4), (-0.3, 3.6), (0.9, 4.6))):
        lat += float(rng.uniform(-0.1, 0.1))
        n = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
        g.append(ellipsoid(f"land{k}", (0.5 * R, 0.35 * R, 0.06 * R), (0.0, 0.0, zc) + n * (R - 0.04 * R), land[k % 2], "plastic",
                           quat=quat_from_z(n)))
    return finish(g)


def build_sculpture(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An abstract sculpture on a plinth: a leaning column, a twisted block and a sphere."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    lean = float(rng.uniform(-0.25, 0.25))
    twist = float(rng.uniform(0, math.pi / 2))
    top = np.array([0.0, math.sin(lean) * 0.2 * s, 0.05 + math.cos(lean) * 0.2 * s])
    base = tint("stone") if mat != "stone" else shade(main, 0.7)
    g = [span("plinth", (-0.07 * s, -0.07 * s, 0), (0.07 * s, 0.07 * s, 0.04), base, "stone"),
         segment("column", (0, 0, 0.06), top, 0.025 * s, main, mat),
         box("block", (0.04 * s, 0.04 * s, 0.04 * s), tuple(top + np.array([0, 0, 0.04 * s])), main, mat,
             quat=quat_mul(quat_axis_angle((0, 0, 1), twist), quat_axis_angle((1, 0, 0), math.pi / 4))),
         sphere("orb", 0.035 * s, tuple(top + np.array([0, 0, 0.125 * s])), shade(main, 0.9), mat)]
    return finish(g)


def build_remote_control(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A TV remote: a slim rounded body with a red power button, a d-pad and rows of buttons."""
    s = scale_of(attrs)
    hx, hy = 0.09 * s, 0.024 * s
    main = rgba(attrs.color, default="black")
    btn = (0.6, 0.6, 0.62, 1.0) if max(main[:3]) < 0.5 else (0.2, 0.2, 0.22, 1.0)
    g = [box("body", (hx, hy, 0.009), (0, 0, 0.009), main, attrs.material),
         disk("power", 0.006, 0.0015, (hx - 0.015, hy * 0.5, 0.019), rgba("red"), "plastic"),
         disk("dpad", 0.013 * s, 0.0015, (hx * 0.25, 0, 0.019), btn, "plastic")]
    for k in range(3):
        x = -hx * 0.2 - k * 0.022 * s
        g.append(span(f"buttons{k}", (x - 0.005, -hy * 0.7, 0.018), (x + 0.005, hy * 0.7, 0.0205), btn, "plastic"))
    return finish(g)


def build_spray_bottle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A trigger spray bottle: a body with a label, a neck, a trigger head with a nozzle pointing +x and a trigger."""
    s = scale_of(attrs)
    r = 0.04 * s
    main = rgba(attrs.color, default="blue")
    head = rgba("white") if attrs.color != "white" else rgba("gray")
    h = 0.17 * s
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, attrs.material),
         disk("label", r + 0.001, 0.035 * s, (0, 0, h * 0.45), rgba("white") if attrs.color != "white" else rgba("yellow"), "fabric"),
         disk("neck", 0.016 * s, 0.015 * s, (0, 0, h + 0.015 * s), head, "plastic"),
         span("head", (-0.02 * s, -0.017 * s, h + 0.03 * s), (0.06 * s, 0.017 * s, h + 0.065 * s), head, "plastic"),
         disk("nozzle", 0.01 * s, 0.008 * s, (0.068 * s, 0, h + 0.05 * s), DARK, "plastic", axis="x"),
         segment("trigger", (0.035 * s, 0, h + 0.03 * s), (0.045 * s, 0, h - 0.02 * s), 0.007 * s, head, "plastic")]
    return finish(g)


def build_dish_rack(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A draining rack: a drip tray, a wire frame and a few plates standing in it beside a cup."""
    s = scale_of(attrs)
    hx, hy = 0.17 * s, 0.24 * s
    main = rgba(attrs.color, default="gray")
    mat = attrs.material
    g = [span("tray", (-hx, -hy, 0), (hx, hy, 0.012), shade(main, 0.85), mat)]
    for k, sx in enumerate((1, -1)):
        g.append(segment(f"rail{k}", (sx * (hx - 0.01), -hy + 0.01, 0.09 * s), (sx * (hx - 0.01), hy - 0.01, 0.09 * s), 0.004, main, mat))
        for j, sy in enumerate((1, -1)):
            x, y = sx * (hx - 0.01), sy * (hy - 0.01)
            g.append(segment(f"post{k}{j}", (x, y, 0.012), (x, y, 0.09 * s), 0.004, main, mat))
    n = int(rng.integers(2, 5))
    for k in range(n):
        y = -hy + 0.05 + k * 0.045 * s
        c = rgba(pick(rng, ("white", "blue", "beige", "green")))
        g.append(disk(f"plate{k}", 0.1 * s, 0.005, (0.0, y, 0.012 + 0.1 * s), c, "ceramic", axis="y"))
    c = rgba(pick(rng, ("red", "white", "yellow")))
    g.append(disk("cup", 0.035 * s, 0.045 * s, (0.0, hy - 0.06, 0.012 + 0.045 * s), c, "ceramic"))
    return finish(g)


def build_watering_can(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A watering can: a round body, a long spout with a rose pointing +x, and an arched top handle."""
    s = scale_of(attrs)
    r, h = 0.08 * s, 0.18 * s
    main = rgba(attrs.color, default="green")
    mat = attrs.material
    tip = np.array([0.27 * s, 0, 0.25 * s])
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, mat),
         disk("top", r * 0.9, 0.005, (0, 0, h + 0.005), shade(main, 0.85), mat),
         segment("spout", (r * 0.7, 0, 0.05 * s), tip, 0.011 * s, main, mat),
         segment("rose", tip, tip + np.array([0.02, 0, 0.015]) * s, 0.022 * s, shade(main, 0.8), mat, kind="cylinder")]
    g += ring("handle", (-0.02 * s, 0, h), (0.065 * s, 0.09 * s), 0.01 * s, 5, main, mat, u=(1, 0, 0), v=(0, 0, 1), start=0.0, stop=math.pi)
    return finish(g)


def build_tennis_racket(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tennis racket lying flat: an oval head frame with a string bed, a throat and a wrapped handle."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="blue")
    mat = attrs.material
    ax, ay, t = 0.15 * s, 0.12 * s, 0.011
    cx = 0.17 * s
    g = ring("head", (cx, 0, t), (ax, ay), t, 12, main, mat)
    g.append(ellipsoid("strings", (ax - 0.005, ay - 0.005, 0.0015), (cx, 0, t), (0.92, 0.92, 0.85, 1.0), "plastic"))
    throat = np.array([cx - ax, 0, t])
    neck = np.array([cx - ax - 0.08 * s, 0, t])
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"throat{k}", np.array([cx - ax * 0.8, sy * ay * 0.6, t]), neck, t * 0.8, main, mat))
    g.append(segment("shaft", neck, throat, t * 0.8, main, mat))
    g.append(segment("grip", neck, neck - np.array([0.19 * s, 0, 0]), 0.015, DARK, "leather"))
    return finish(g)


def build_baseball_bat(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A baseball bat lying along x: a knob, a thin handle tapering out to a thick barrel."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    L = 0.84 * s
    zc = 0.034 * s
    x0 = -L / 2
    grip = DARK if attrs.color != "black" else rgba("gray")
    g = [disk("knob", 0.022 * s, 0.006, (x0 + 0.006, 0, zc), shade(main, 0.8), mat, axis="x"),
         segment("handle", (x0 + 0.01, 0, zc), (x0 + 0.34 * L, 0, zc), 0.013 * s, grip, "leather"),
         segment("taper", (x0 + 0.3 * L, 0, zc), (x0 + 0.6 * L, 0, zc), 0.022 * s, main, mat),
         segment("barrel", (x0 + 0.6 * L, 0, zc), (L / 2 - 0.034 * s, 0, zc), 0.034 * s, main, mat)]
    return finish(g)


def build_headphones(attrs: Attributes, rng: np.random.Generator) -> Built:
    """Over-ear headphones standing on their ear cups: two cups with cushions joined by an arched headband."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="black")
    r = 0.045 * s
    w = 0.085 * s
    g = []
    for k, sy in enumerate((1, -1)):
        g.append(disk(f"cup{k}", r, 0.017 * s, (0, sy * w, r), main, attrs.material, axis="y"))
        g.append(disk(f"cushion{k}", r * 0.9, 0.008 * s, (0, sy * (w - 0.024 * s), r), DARK, "leather", axis="y"))
        g.append(segment(f"yoke{k}", (0, sy * (w + 0.005 * s), 2 * r - 0.005), (0, sy * w * 0.95, 2 * r + 0.03 * s), 0.005 * s, main,
                         attrs.material))
    g += ring("headband", (0, 0, 2 * r + 0.03 * s), (w * 0.95, 0.08 * s), 0.011 * s, 6, main, attrs.material, u=(0, 1, 0), v=(0, 0, 1),
              start=0.0, stop=math.pi)
    return finish(g)
