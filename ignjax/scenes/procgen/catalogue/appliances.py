"""Kitchen and laundry appliances: refrigerators, stoves, ovens, dishwashers, washing
machines, dryers, microwaves, toasters, kettles and coffee machines.

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
    SCREEN_OFF,
    Built,
    Surface,
    box,
    capsule,
    cylinder,
    disk,
    finish,
    hscale,
    quat_from_z,
    rgba,
    ring,
    scale_of,
    segment,
    shade,
    span,
    sphere,
    tint,
)


def build_refrigerator(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tall fridge-freezer: body, freezer drawer below, fridge door above, a
    dark split line, vertical handles and a toe grille."""
    s = scale_of(attrs)
    hy, d, h = 0.38 * s, 0.68, 1.8 * hscale(s, 0.4)
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    split = 0.68 * hscale(s, 0.4)
    metal = tint("metal") if attrs.color not in ("gray",) else shade(main, 0.6)
    g = [span("body", (0, -hy, 0), (d, hy, h), shade(main, 0.9), mat),
         span("grille", (d, -hy + 0.03, 0.02), (d + 0.005, hy - 0.03, 0.08), DARK),
         span("freezer_door", (d, -hy + 0.005, 0.09), (d + 0.04, hy - 0.005, split - 0.008), main, mat),
         span("split", (d, -hy + 0.005, split - 0.008), (d + 0.03, hy - 0.005, split + 0.008), DARK),
         span("fridge_door", (d, -hy + 0.005, split + 0.008), (d + 0.04, hy - 0.005, h - 0.01), main, mat),
         segment("freezer_handle", (d + 0.065, hy - 0.06, split - 0.25), (d + 0.065, hy - 0.06, split - 0.06), 0.012, metal, "metal"),
         segment("fridge_handle", (d + 0.065, hy - 0.06, split + 0.1), (d + 0.065, hy - 0.06, split + 0.6), 0.012, metal, "metal")]
    for k, z in enumerate((split - 0.155, split + 0.35)):
        for j, dz in enumerate((-0.08, 0.08) if k == 0 else (-0.24, 0.24)):
            g.append(segment(f"handle_mount{k}{j}", (d + 0.04, hy - 0.06, z + dz), (d + 0.06, hy - 0.06, z + dz), 0.01, metal, "metal"))
    return finish(g)


def build_stove(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A freestanding range: body, black glass cooktop with four burners
    (glowing when on; their tops are the support), a control backsplash with
    knobs, and an oven door with a window and a bar handle."""
    s = scale_of(attrs)
    hy, d, h = 0.38 * s, 0.62, 0.9
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    on = attrs.state == "on"
    g = [span("body", (0, -hy, 0), (d, hy, h), main, mat),
         span("cooktop", (0, -hy, h), (d, hy, h + 0.015), (0.05, 0.05, 0.06, 1.0), "glass"),
         span("backsplash", (0, -hy, h + 0.015), (0.07, hy, h + 0.17), shade(main, 0.9), mat),
         span("door", (d, -hy + 0.02, 0.14), (d + 0.03, hy - 0.02, h - 0.14), shade(main, 0.95), mat),
         span("window", (d + 0.03, -hy + 0.1, 0.28), (d + 0.033, hy - 0.1, h - 0.3),
              (0.95, 0.45, 0.1, 1.0) if on else SCREEN_OFF, "glass"),
         segment("handle", (d + 0.06, -hy + 0.06, h - 0.18), (d + 0.06, hy - 0.06, h - 0.18), 0.012, tint("metal"), "metal"),
         span("drawer", (d, -hy + 0.02, 0.02), (d + 0.02, hy - 0.02, 0.12), shade(main, 0.9), mat)]
    for k in range(4):
        x = 0.07 + (d - 0.07) * (0.3 if k % 2 == 0 else 0.72)
        y = (-1 if k < 2 else 1) * hy * 0.48
        r = 0.09 if k in (0, 3) else 0.07
        g.append(disk(f"burner{k}", r, 0.0015, (x, y, h + 0.0165), FLAME if on else (0.22, 0.22, 0.24, 1.0), "glass"))
    for k in range(4):
        y = -hy + (k + 0.5) * 2 * hy / 4
        g.append(disk(f"knob{k}", 0.022, 0.012, (0.082, y, h + 0.1), tint("metal"), "metal", axis="x"))
    return finish(g, (Surface(h + 0.018, ((d - 0.1) / 2 - 0.02, hy - 0.03), ((d + 0.1) / 2, 0.0)),))


def build_oven(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tall oven housing with two built-in ovens: fronts with control strips,
    windows (lit orange when on) and bar handles."""
    s = scale_of(attrs)
    hy, d, h = 0.32 * s, 0.6, 2.0 * hscale(s, 0.4)
    front = rgba(attrs.color, default="black")
    housing = (0.88, 0.86, 0.82, 1.0)
    on = attrs.state == "on"
    g = [span("housing", (0, -hy, 0), (d, hy, h), housing, "wood"),
         span("drawer", (d, -hy + 0.01, 0.1), (d + 0.02, hy - 0.01, 0.5), housing, "wood"),
         segment("drawer_handle", (d + 0.035, -0.1, 0.45), (d + 0.035, 0.1, 0.45), 0.008, tint("metal"), "metal")]
    for k, z0 in enumerate((0.55, 1.15)):
        z1 = z0 + 0.58
        g += [span(f"oven{k}", (d, -hy + 0.02, z0), (d + 0.025, hy - 0.02, z1), front, attrs.material),
              span(f"controls{k}", (d + 0.025, -hy + 0.03, z1 - 0.08), (d + 0.03, hy - 0.03, z1 - 0.02), shade(front, 0.6), "glass"),
              span(f"window{k}", (d + 0.025, -hy + 0.08, z0 + 0.08), (d + 0.028, hy - 0.08, z1 - 0.2),
                   (1.0, 0.55, 0.15, 1.0) if on else SCREEN_OFF, "glass"),
              segment(f"handle{k}", (d + 0.055, -hy + 0.05, z1 - 0.13), (d + 0.055, hy - 0.05, z1 - 0.13), 0.011, tint("metal"), "metal")]
    return finish(g)


def build_dishwasher(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A dishwasher: body under a worktop (the support), a full-height door with a control strip and a bar handle."""
    s = scale_of(attrs)
    hy, d, h = 0.3 * s, 0.58, 0.85
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    g = [span("toe_kick", (0, -hy + 0.01, 0), (d - 0.05, hy - 0.01, 0.09), DARK),
         span("body", (0, -hy, 0.09), (d, hy, h - 0.03), shade(main, 0.9), mat),
         span("worktop", (0, -hy, h - 0.03), (d + 0.02, hy, h), tint("stone"), "stone"),
         span("door", (d, -hy + 0.005, 0.1), (d + 0.03, hy - 0.005, h - 0.1), main, mat),
         span("control_strip", (d, -hy + 0.005, h - 0.1), (d + 0.02, hy - 0.005, h - 0.035), (0.2, 0.2, 0.22, 1.0), "plastic"),
         segment("handle", (d + 0.055, -hy + 0.08, h - 0.14), (d + 0.055, hy - 0.08, h - 0.14), 0.01, tint("metal"), "metal")]
    return finish(g, (Surface(h, ((d + 0.02) / 2 - 0.03, hy - 0.03), ((d + 0.02) / 2, 0.0)),))


def _front_loader(attrs: Attributes, rng: np.random.Generator, *, dryer: bool) -> Built:
    """A front-loading washer or dryer: body, control panel, a round door (swung open on its hinge when open)."""
    s = scale_of(attrs)
    hy, d, h = 0.3 * s, 0.6 * s, 0.85 * s
    main = rgba(attrs.color, default="white")
    mat = attrs.material
    chrome = tint("metal")
    r = (0.21 if dryer else 0.19) * s
    zc = h * (0.48 if dryer else 0.45)
    g = [span("body", (0, -hy, 0), (d, hy, h), main, mat),
         span("panel", (d, -hy, h - 0.12 * s), (d + 0.015, hy, h), shade(main, 0.92), mat),
         disk("dial", 0.03 * s, 0.015, (d + 0.03, hy * (0.45 if dryer else 0.55), h - 0.06 * s), chrome, "metal", axis="x")]
    if dryer:
        g.append(span("display", (d + 0.015, -hy * 0.3, h - 0.09 * s), (d + 0.018, hy * 0.2, h - 0.03 * s), SCREEN_OFF, "glass"))
        g.append(span("vent", (d, -hy + 0.05, 0.02), (d + 0.006, hy - 0.05, 0.07), DARK))
        glass = (0.25, 0.25, 0.27, 1.0)
    else:
        g.append(span("drawer", (d + 0.015, -hy + 0.02, h - 0.1 * s), (d + 0.02, -hy + 0.2 * s, h - 0.03 * s), shade(main, 0.8), mat))
        glass = (0.3, 0.45, 0.6, 1.0)
    if attrs.state == "open":
        g.append(disk("opening", r * 0.82, 0.002, (d + 0.002, 0, zc), DARK, axis="x"))
        g.append(disk("drum", r * 0.7, 0.002, (d + 0.0045, 0, zc), (0.55, 0.57, 0.6, 1.0), "metal", axis="x"))
        hinge = np.array([d + 0.03, r, zc])
        ang = math.radians(100)
        direc = np.array([math.sin(ang), -math.cos(ang), 0.0])
        c = hinge + direc * r
        q = quat_from_z((math.cos(ang), math.sin(ang), 0.0))
        g.append(cylinder("door_ring", r, 0.025, tuple(c), chrome, "metal", quat=q))
        g.append(cylinder("door_glass", r * 0.78, 0.03, tuple(c), glass, "glass", quat=q))
    else:
        g.append(disk("door_ring", r, 0.025, (d + 0.025, 0, zc), chrome, "metal", axis="x"))
        g.append(disk("door_glass", r * 0.78, 0.03, (d + 0.03, 0, zc), glass, "glass", axis="x"))
    return finish(g, (Surface(h, (d / 2 - 0.03, hy - 0.03), (d / 2, 0.0)),))


def build_washing_machine(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A front-loading washing machine: a round glass door (open or closed), a dial and a detergent drawer; the top is a support."""
    return _front_loader(attrs, rng, dryer=False)


def build_dryer(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A tumble dryer: a larger smoky round door, a dial, a display and a vent; the top is a support."""
    return _front_loader(attrs, rng, dryer=True)


def build_microwave(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A countertop microwave: body, a door with a window (lit yellow with a
    turntable plate when on), a side control panel with buttons."""
    s = scale_of(attrs)
    hy, d, h = 0.25 * s, 0.36 * s, 0.29 * s
    main = rgba(attrs.color, default="black")
    on = attrs.state == "on"
    g = [span("body", (0, -hy, 0.01), (d, hy, h), main, attrs.material),
         span("feet", (0.03, -hy + 0.03, 0), (d - 0.03, hy - 0.03, 0.01), DARK),
         span("door", (d, -hy + 0.01, 0.02), (d + 0.015, hy * 0.4, h - 0.01), shade(main, 0.85), attrs.material),
         span("window", (d + 0.015, -hy + 0.04, 0.05 * s), (d + 0.018, hy * 0.4 - 0.04, h - 0.05 * s),
              (1.0, 0.85, 0.45, 1.0) if on else SCREEN_OFF, "glass"),
         span("panel", (d, hy * 0.4 + 0.005, 0.02), (d + 0.01, hy - 0.01, h - 0.01), (0.15, 0.15, 0.17, 1.0), "plastic")]
    for k in range(3):
        z = h - 0.06 * s - k * 0.05 * s
        g.append(span(f"button{k}", (d + 0.01, hy * 0.55, z - 0.012), (d + 0.016, hy * 0.85, z + 0.012), (0.7, 0.7, 0.72, 1.0), "plastic"))
    if on:
        g.append(span("plate", (d + 0.018, -hy + 0.09, 0.06 * s), (d + 0.02, hy * 0.4 - 0.09, 0.08 * s), (0.95, 0.95, 0.9, 1.0), "glass"))
    return finish(g)


def build_toaster(attrs: Attributes, rng: np.random.Generator) -> Built:
    """A two-slot toaster: a rounded body, two dark slots on top, a lever and feet."""
    s = scale_of(attrs)
    hx, hy, hz = 0.085 * s, 0.1 * s, 0.085 * s
    main = rgba(attrs.color, default="gray")
    z = 0.008 + hz
    g = [span("base", (-hx, -hy - 0.02 * s, 0), (hx, hy + 0.02 * s, 0.008), DARK, "plastic"),
         box("body", (hx, hy, hz), (0, 0, z), main, attrs.material),
         capsule("ends", hx, hy, (0, 0, z), main, attrs.material, quat=AXIS_QUAT["y"])]
    for k, dx in enumerate((-0.035 * s, 0.035 * s)):
        g.append(span(f"slot{k}", (dx - 0.012 * s, -hy * 0.9, z + hz - 0.001), (dx + 0.012 * s, hy * 0.9, z + hz + 0.002), DARK))
    g.append(span("lever", (0.0, hy + hx - 0.01, z + 0.02), (0.03 * s, hy + hx + 0.02, z + 0.04), DARK, "plastic"))
    return finish(g)


def build_kettle(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An electric kettle: a power base, a tapered body, a lid with a knob, a spout and a looped handle."""
    s = scale_of(attrs)
    main = rgba(attrs.color, default="white")
    r = 0.08 * s
    g = [disk("base", r * 1.05, 0.008, (0, 0, 0.008), DARK, "plastic"),
         disk("body", r, 0.07 * s, (0, 0, 0.016 + 0.07 * s), main, attrs.material),
         disk("shoulder", r * 0.85, 0.025 * s, (0, 0, 0.016 + 0.14 * s + 0.025 * s), main, attrs.material),
         disk("lid", r * 0.7, 0.006, (0, 0, 0.016 + 0.19 * s + 0.006), shade(main, 0.85), attrs.material),
         sphere("knob", 0.014 * s, (0, 0, 0.016 + 0.19 * s + 0.016), DARK, "plastic"),
         segment("spout", (r * 0.8, 0, 0.08 * s), (r + 0.05 * s, 0, 0.18 * s), 0.013 * s, main, attrs.material)]
    g += ring("handle", (-r, 0, 0.115 * s), (0.05 * s, 0.075 * s), 0.012 * s, 5, DARK, "plastic", u=(-1, 0, 0), v=(0, 0, 1),
              start=-math.pi / 2, stop=math.pi / 2)
    return finish(g)


def build_coffee_machine(attrs: Attributes, rng: np.random.Generator) -> Built:
    """An espresso machine: a rear tower with a water tank, an overhanging head
    with a spout and buttons, a drip tray holding a small cup."""
    s = scale_of(attrs)
    hy = 0.12 * s
    main = rgba(attrs.color, default="black")
    mat = attrs.material
    h = 0.36 * s
    g = [span("tray", (-0.16 * s, -hy, 0), (0.17 * s, hy, 0.025 * s), (0.2, 0.2, 0.22, 1.0), "metal"),
         span("tower", (-0.17 * s, -hy, 0), (-0.02 * s, hy, h), main, mat),
         span("tank", (-0.2 * s, -hy * 0.8, 0.05 * s), (-0.17 * s, hy * 0.8, h - 0.04 * s), (0.6, 0.75, 0.85, 1.0), "glass"),
         span("head", (-0.17 * s, -hy, h - 0.07 * s), (0.15 * s, hy, h), main, mat),
         disk("spout", 0.018 * s, 0.015 * s, (0.08 * s, 0, h - 0.085 * s), tint("metal"), "metal"),
         disk("cup", 0.03 * s, 0.03 * s, (0.08 * s, 0, 0.025 * s + 0.03 * s), rgba("white"), "ceramic")]
    for k in range(3):
        g.append(disk(f"button{k}", 0.012 * s, 0.003, (0.1 * s, (k - 1) * 0.05 * s, h + 0.003), tint("metal"), "metal"))
    return finish(g)
