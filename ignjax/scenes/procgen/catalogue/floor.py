"""Floor objects: coat racks, plants, floor lamps, rugs, bins and baskets, toolboxes,
bicycles, ladders, dumbbells and basketballs.

Builders ``build_<category>(attrs, rng) -> Built`` in the builder frame of
:mod:`ignjax.scenes.procgen.catalogue`.
"""

from __future__ import annotations

import math

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue.parts import (
    DARK,
    LIGHT_ON,
    Built,
    disk,
    ellipsoid,
    finish,
    glow,
    hscale,
    mix,
    pick,
    quat_axis_angle,
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


def build_coat_rack(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A standing coat rack: splayed feet, a pole, two tiers of hooks, a knob and a coat or two."""
    s = hscale(scale_of(attrs))
    main = rgba(attrs.color, default="brown")
    mat = attrs.material
    h = 1.75 * s
    g = []
    for k in range(4):
        a = math.pi / 4 + k * math.pi / 2
        g.append(segment(f"foot{k}", (0.0, 0.0, 0.2), (0.28 * math.cos(a), 0.28 * math.sin(a), 0.02), 0.02, main, mat))
    g.append(disk("pole", 0.022, h / 2 - 0.01, (0, 0, h / 2), main, mat))
    g.append(sphere("knob", 0.04, (0, 0, h + 0.02), main, mat))
    for tier, (z, a0) in enumerate(((h - 0.1, 0.0), (h - 0.3, math.pi / 4))):
        for k in range(4):
            a = a0 + k * math.pi / 2
            g.append(segment(f"hook{tier}_{k}", (0.0, 0.0, z - 0.04), (0.13 * math.cos(a), 0.13 * math.sin(a), z + 0.05), 0.01, main, mat))
    for k in range(int(rng.integers(0, 3))):
        a = k * math.pi + math.pi / 2 + float(rng.uniform(-0.3, 0.3))
        c = rgba(pick(rng, ("black", "brown", "gray", "blue", "beige", "red", "green")))
        q = quat_axis_angle((0, 0, 1), a)
        px, py = 0.2 * math.cos(a), 0.2 * math.sin(a)
        tx, ty = -math.sin(a), math.cos(a)
        g.append(segment(f"coat{k}_shoulders", (px - 0.16 * tx, py - 0.16 * ty, h - 0.2), (px + 0.16 * tx, py + 0.16 * ty, h - 0.2), 0.06,
                         c, "fabric"))
        g.append(ellipsoid(f"coat{k}", (0.11, 0.24, 0.38), (px, py, h - 0.52), c, "fabric", quat=q))
    return finish(g)


def _leaves(g: list, rng: np.random.Generator, base, n_stems: int, height: tuple[float, float], leaf: tuple[float, float],
            color, spread: float) -> list:
    """Append stems rising from ``base`` with leaves along them; returns the stem tips."""
    bx, by, bz = base
    tips = []
    for k in range(n_stems):
        yaw = 2 * math.pi * k / n_stems + float(rng.uniform(-0.4, 0.4))
        lean = float(rng.uniform(0.1, spread))
        hgt = float(rng.uniform(*height))
        tip = np.array([bx + math.sin(lean) * math.cos(yaw) * hgt, by + math.sin(lean) * math.sin(yaw) * hgt, bz + math.cos(lean) * hgt])
        g.append(segment(f"stem{k}", (bx, by, bz), tip, 0.006, (0.25, 0.4, 0.18, 1.0), "wood"))
        for j, f in enumerate((0.55, 1.0)):
            p = np.array([bx, by, bz]) + f * (tip - np.array([bx, by, bz]))
            a = yaw + (0.0 if j else math.pi / 2)
            q = quat_mul(quat_axis_angle((0, 0, 1), a), quat_axis_angle((0, 1, 0), math.radians(20)))
            c = shade(color, float(rng.uniform(0.8, 1.15)))
            centre = p + np.array([math.cos(a), math.sin(a), 0]) * leaf[0] * 0.8
            g.append(ellipsoid(f"leaf{k}_{j}", (leaf[0], leaf[1], 0.008), tuple(centre), c, "fabric", quat=q))
        tips.append(tip)
    return tips


def build_potted_plant(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A floor plant: a flared pot (showing its material), soil, a trunk with
    branches and clumps of foliage in its colour."""
    s = scale_of(attrs)
    pot = tint(attrs.material or "ceramic")
    foliage = rgba(attrs.color, default="green")
    top = 0.34 * s
    g = [disk("pot_base", 0.11 * s, 0.06 * s, (0, 0, 0.06 * s), shade(pot, 0.9), attrs.material),
         disk("pot_body", 0.145 * s, 0.1 * s, (0, 0, 0.12 * s + 0.1 * s), pot, attrs.material),
         disk("pot_rim", 0.16 * s, 0.01 * s, (0, 0, top - 0.01 * s), shade(pot, 0.95), attrs.material),
         disk("soil", 0.14 * s, 0.003, (0, 0, top + 0.001), (0.25, 0.17, 0.1, 1.0), "stone")]
    bark = (0.4, 0.28, 0.16, 1.0)
    crown = np.array([0.0, 0.0, top + 0.45 * s])
    g.append(segment("trunk", (0, 0, top), crown, 0.018 * s, bark, "wood"))
    n = 7
    for k in range(n):
        a = 2 * math.pi * k / n + float(rng.uniform(-0.3, 0.3))
        up = float(rng.uniform(-0.1, 0.35)) * s
        reach = float(rng.uniform(0.14, 0.22)) * s
        c = crown + np.array([reach * math.cos(a), reach * math.sin(a), up])
        if k % 2 == 0:
            g.append(segment(f"branch{k}", crown - np.array([0, 0, 0.12 * s]), c, 0.01 * s, bark, "wood"))
        semi = np.array([0.15, 0.13, 0.11]) * s * float(rng.uniform(0.85, 1.15))
        g.append(ellipsoid(f"foliage{k}", tuple(semi), tuple(c), shade(foliage, float(rng.uniform(0.75, 1.15))), "fabric",
                           quat=quat_axis_angle((0, 0, 1), a)))
    g.append(ellipsoid("foliage_top", (0.14 * s, 0.14 * s, 0.12 * s), tuple(crown + np.array([0, 0, 0.3 * s])), foliage, "fabric"))
    return finish(g)


def build_houseplant_small(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A small flowering plant in a pot: green leaves and blossoms in its colour."""
    s = scale_of(attrs)
    pot = tint(attrs.material or "ceramic")
    bloom = rgba(attrs.color, default="pink")
    g = [disk("pot", 0.055 * s, 0.045 * s, (0, 0, 0.045 * s), pot, attrs.material),
         disk("pot_rim", 0.062 * s, 0.008 * s, (0, 0, 0.09 * s - 0.008 * s), shade(pot, 0.92), attrs.material),
         disk("soil", 0.05 * s, 0.002, (0, 0, 0.091 * s), (0.25, 0.17, 0.1, 1.0), "stone")]
    tips = _leaves(g, rng, (0.0, 0.0, 0.09 * s), 4, (0.09 * s, 0.15 * s), (0.04 * s, 0.018 * s), rgba("green"), 0.6)
    for k, t in enumerate(tips):
        g.append(sphere(f"bloom{k}", 0.022 * s, tuple(t + np.array([0, 0, 0.012 * s])), bloom, "fabric"))
        eye = rgba("yellow") if attrs.color != "yellow" else rgba("orange")
        g.append(sphere(f"bloom_eye{k}", 0.008 * s, tuple(t + np.array([0, 0, 0.03 * s])), eye, "fabric"))
    return finish(g)


def build_floor_lamp(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A floor lamp: a weighted base, a pole and a drum shade (glowing, with a lit diffuser, when on)."""
    s = scale_of(attrs)
    hs = hscale(s)
    main = rgba(attrs.color, default="beige")
    on = attrs.state == "on"
    metal = tint(attrs.material or "metal")
    h = 1.35 * hs
    r = 0.2 * s
    sh = 0.16 * hs
    g = [disk("base", 0.15 * s, 0.012, (0, 0, 0.012), metal, attrs.material),
         disk("pole", 0.012, h / 2, (0, 0, 0.024 + h / 2), metal, attrs.material),
         disk("shade", r, sh, (0, 0, 0.024 + h + sh * 0.6), glow(main) if on else main, "fabric"),
         disk("diffuser", r * 0.95, 0.002, (0, 0, 0.024 + h - sh * 0.4 - 0.003), LIGHT_ON if on else shade(main, 0.6), "glass")]
    if on:
        g.append(sphere("bulb", 0.035, (0, 0, 0.024 + h - sh * 0.4 - 0.03), LIGHT_ON, "glass"))
    return finish(g)


def build_rug(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A flat area rug: a field in its colour, a contrasting border and a central medallion."""
    s = scale_of(attrs)
    hx, hy = 0.7 * s, 1.0 * s
    main = rgba(attrs.color, default="red")
    trim = shade(main, 0.55) if max(main[:3]) > 0.5 else shade(mix(main, rgba("beige"), 0.6), 1.0)
    b = 0.08 * s
    g = [span("field", (-hx, -hy, 0), (hx, hy, 0.01), main, attrs.material),
         span("border0", (-hx, -hy, 0.0), (-hx + b, hy, 0.013), trim, attrs.material),
         span("border1", (hx - b, -hy, 0.0), (hx, hy, 0.013), trim, attrs.material),
         span("border2", (-hx + b, -hy, 0.0), (hx - b, -hy + b, 0.013), trim, attrs.material),
         span("border3", (-hx + b, hy - b, 0.0), (hx - b, hy, 0.013), trim, attrs.material),
         ellipsoid("medallion", (0.3 * s, 0.42 * s, 0.0025), (0, 0, 0.01), trim, attrs.material)]
    return finish(g)


def build_trash_can(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A pedal bin: a cylindrical body on a base ring, a rim, a domed lid and a foot pedal."""
    s = scale_of(attrs)
    r, h = 0.15 * s, 0.58 * s
    main = rgba(attrs.color, default="gray")
    mat = attrs.material
    g = [disk("base", r * 0.97, 0.015, (0, 0, 0.015), DARK, "plastic"),
         disk("body", r, (h - 0.05) / 2, (0, 0, 0.03 + (h - 0.05) / 2), main, mat),
         disk("rim", r + 0.006, 0.012, (0, 0, h - 0.02), shade(main, 0.8), mat),
         ellipsoid("lid", (r + 0.004, r + 0.004, 0.035 * s), (0, 0, h - 0.008), shade(main, 1.1), mat),
         span("pedal", (r - 0.02, -0.05, 0.02), (r + 0.06, 0.05, 0.04), DARK, "plastic")]
    return finish(g)


def build_laundry_basket(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A hamper: a woven round body with bands, a rim, hand holds and a dark
    opening; full heaps clothes above the rim."""
    s = scale_of(attrs)
    r, h = 0.22 * s, 0.52 * s
    main = rgba(attrs.color, default="beige")
    mat = attrs.material
    g = [disk("body", r, h / 2, (0, 0, h / 2), main, mat),
         disk("rim", r + 0.012, 0.012, (0, 0, h - 0.012), shade(main, 0.8), mat),
         disk("opening", r - 0.01, 0.001, (0, 0, h + 0.001), (0.15, 0.12, 0.1, 1.0))]
    for k in range(3):
        g.append(disk(f"band{k}", r + 0.004, 0.008, (0, 0, 0.08 * s + k * 0.13 * s), shade(main, 0.75), mat))
    for k, sy in enumerate((1, -1)):
        g.append(span(f"handhold{k}", (-0.05, sy * (r + 0.003) - 0.002, h - 0.08), (0.05, sy * (r + 0.003) + 0.002, h - 0.05), DARK))
    if attrs.state == "full":
        for k in range(4):
            a = k * math.pi / 2 + float(rng.uniform(-0.4, 0.4))
            pos = (0.07 * s * math.cos(a), 0.07 * s * math.sin(a), h + 0.02 * s)
            g.append(ellipsoid(f"clothes{k}", (0.12 * s, 0.08 * s, 0.06 * s), pos, rgba(pick(rng, vocab.COLORS)), "fabric",
                               quat=quat_axis_angle((0, 0, 1), a)))
    return finish(g)


def build_toolbox(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A metal tool box: a body, a lid, a carry handle on posts and two latches."""
    s = scale_of(attrs)
    hx, hy, h = 0.11 * s, 0.23 * s, 0.2 * s
    main = rgba(attrs.color, default="red")
    metal = tint("metal")
    g = [span("body", (-hx, -hy, 0), (hx, hy, h - 0.035 * s), main, attrs.material),
         span("lid", (-hx - 0.004, -hy - 0.004, h - 0.035 * s), (hx + 0.004, hy + 0.004, h), shade(main, 0.85), attrs.material),
         segment("handle", (0, -hy * 0.55, h + 0.04 * s), (0, hy * 0.55, h + 0.04 * s), 0.012, DARK, "plastic")]
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"handle_post{k}", (0, sy * hy * 0.55, h), (0, sy * hy * 0.55, h + 0.04 * s), 0.008, metal, "metal"))
        g.append(span(f"latch{k}", (hx, sy * hy * 0.6 - 0.015, h - 0.07 * s), (hx + 0.008, sy * hy * 0.6 + 0.015, h - 0.02 * s), metal,
                      "metal"))
    return finish(g)


def build_bicycle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A bicycle: two spoked wheels with tyres, a diamond frame in its colour,
    a fork, a saddle, handlebars and a chainring."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="red")
    mat = attrs.material or "metal"
    tyre = (0.06, 0.06, 0.06, 1.0)
    metal = tint("metal")
    rw, tube = 0.32 * s, 0.022
    zc = rw + tube
    wx = 0.52 * s
    g = []
    for w, x in enumerate((-wx, wx)):
        g += ring(f"tyre{w}_", (x, 0, zc), rw, tube, 10, tyre, "plastic", u=(1, 0, 0), v=(0, 0, 1))
        g.append(disk(f"hub{w}", 0.03, 0.05, (x, 0, zc), metal, "metal", axis="y"))
        for k in range(3):
            a = k * math.pi / 3 + 0.2
            d = np.array([math.cos(a), 0, math.sin(a)]) * (rw - 0.01)
            g.append(segment(f"spoke{w}_{k}", np.array([x, 0, zc]) - d, np.array([x, 0, zc]) + d, 0.003, metal, "metal", kind="cylinder"))
    rear, front = np.array([-wx, 0, zc]), np.array([wx, 0, zc])
    bb = np.array([-0.04 * s, 0, 0.3 * s])
    seat = np.array([-0.2 * s, 0, 0.82 * s])
    head_top = np.array([0.42 * s, 0, 0.86 * s])
    head_bot = np.array([0.45 * s, 0, 0.72 * s])
    r = 0.018
    for name, a, b in (("chain_stay", rear, bb), ("seat_stay", rear, seat), ("seat_tube", bb, seat), ("top_tube", seat, head_top),
                       ("down_tube", bb, head_bot), ("head_tube", head_bot, head_top), ("fork", head_bot, front)):
        g.append(segment(name, a, b, r, main, mat))
    post = seat + np.array([-0.03 * s, 0, 0.1 * s])
    g.append(segment("seat_post", seat, post, 0.013, metal, "metal"))
    g.append(ellipsoid("saddle", (0.13 * s, 0.06 * s, 0.025), tuple(post + np.array([0.02, 0, 0.02])), DARK, "leather"))
    stem = head_top + np.array([-0.02 * s, 0, 0.12 * s])
    g.append(segment("stem", head_top, stem, 0.014, metal, "metal"))
    g.append(segment("handlebar", stem + np.array([0, -0.26 * s, 0]), stem + np.array([0, 0.26 * s, 0]), 0.012, DARK, "metal"))
    g.append(disk("chainring", 0.1 * s, 0.004, tuple(bb + np.array([0, 0.05, 0])), metal, "metal", axis="y"))
    g.append(segment("crank", bb + np.array([0, 0.06, 0]), bb + np.array([0.06 * s, 0.06, -0.14 * s]), 0.01, metal, "metal"))
    return finish(g)


def build_ladder(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An A-frame stepladder: two front rails with four treads, two rear legs,
    spreader bars and a top cap."""
    s = hscale(scale_of(attrs))
    main = rgba(attrs.color, default="gray")
    mat = attrs.material
    h = 1.5 * s
    g = []
    for k, sy in enumerate((1, -1)):
        g.append(segment(f"rail{k}", (0.32 * s, sy * 0.22, 0.02), (0.06, sy * 0.18, h - 0.03), 0.02, main, mat))
        g.append(segment(f"rear_leg{k}", (-0.32 * s, sy * 0.22, 0.02), (-0.06, sy * 0.18, h - 0.03), 0.018, main, mat))
        g.append(segment(f"spreader{k}", (0.2 * s, sy * 0.2, 0.6 * s), (-0.2 * s, sy * 0.2, 0.6 * s), 0.006, tint("metal"), "metal"))
    for k in range(4):
        f = (k + 1) / 5
        x = 0.32 * s + f * (0.06 - 0.32 * s)
        z = 0.02 + f * (h - 0.05)
        hw = 0.22 + f * (0.18 - 0.22) - 0.02
        g.append(span(f"tread{k}", (x - 0.05, -hw, z - 0.015), (x + 0.05, hw, z + 0.015), shade(main, 0.8), mat))
    g.append(span("top_cap", (-0.1, -0.21, h - 0.03), (0.12, 0.21, h + 0.02), rgba("black") if attrs.color != "black" else rgba("gray"),
                  "plastic"))
    return finish(g)


def build_dumbbell(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A dumbbell lying on the floor: a knurled bar with two weight plates and a collar at each end."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="black")
    r = 0.07 * s
    g = [disk("bar", 0.016, 0.17 * s, (0, 0, r), tint("metal"), "metal", axis="y"),
         disk("grip", 0.019, 0.06 * s, (0, 0, r), shade(tint("metal"), 0.7), "metal", axis="y")]
    for k, sy in enumerate((1, -1)):
        for j, (off, rr) in enumerate(((0.095, r), (0.13, r * 0.85))):
            g.append(disk(f"plate{k}_{j}", rr, 0.017 * s, (0, sy * off * s, r), main, attrs.material, axis="y"))
        g.append(disk(f"collar{k}", 0.028, 0.01, (0, sy * 0.16 * s, r), tint("metal"), "metal", axis="y"))
    return finish(g)


def build_basketball(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A basketball: an orange sphere with black seams (an equator and two meridians)."""
    s = scale_of(attrs)
    r = 0.12 * s
    main = rgba(attrs.color, default="orange")
    seam = (0.08, 0.06, 0.05, 1.0)
    g = [sphere("ball", r, (0, 0, r), main, attrs.material),
         ellipsoid("seam0", (r * 1.004, r * 1.004, 0.003), (0, 0, r), seam, attrs.material),
         ellipsoid("seam1", (0.003, r * 1.004, r * 1.004), (0, 0, r), seam, attrs.material),
         ellipsoid("seam2", (r * 1.004, 0.003, r * 1.004), (0, 0, r), seam, attrs.material)]
    return finish(g)
