"""The object catalogue: coverage, geometry contracts, attributes, supports.

Every category is built for every allowed size and state (and every allowed
colour and material at least once). Part bounds are computed here
independently of :func:`catalogue.geom_aabb`, from points sampled on each
primitive's surface, so the containment checks do not trust the code they
check.
"""

from __future__ import annotations

import functools
import itertools
import math
import os

import numpy as np
import pytest

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes, Geom
from ignjax.scenes.procgen import catalogue as cat

TOL = 1e-6
MAX_GEOMS = 48


# ---------------------------------------------------------------------------
# Independent geometry helpers
# ---------------------------------------------------------------------------


def _unit_sphere(n_lat: int = 25, n_lon: int = 64) -> np.ndarray:
    lat = np.linspace(-math.pi / 2, math.pi / 2, n_lat)
    lon = np.linspace(0, 2 * math.pi, n_lon, endpoint=False)
    la, lo = np.meshgrid(lat, lon, indexing="ij")
    return np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], -1).reshape(-1, 3)


_SPHERE = _unit_sphere()
_CIRCLE = np.stack([np.cos(np.linspace(0, 2 * math.pi, 128, endpoint=False)), np.sin(np.linspace(0, 2 * math.pi, 128, endpoint=False))], -1)


def _quat_to_matrix(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def surface_points(g: Geom) -> np.ndarray:
    """Points on the surface of a part (exact corners for boxes, dense samples
    for round primitives) in the instance frame, (N, 3)."""
    a, b, c = g.size
    if g.kind == "box":
        local = np.array(list(itertools.product((-a, a), (-b, b), (-c, c))))
    elif g.kind == "cylinder":
        rim = np.concatenate([_CIRCLE * a, np.zeros((len(_CIRCLE), 1))], 1)
        local = np.concatenate([rim + [0, 0, b], rim - [0, 0, b]])
    elif g.kind == "capsule":
        local = np.concatenate([_SPHERE * a + [0, 0, b], _SPHERE * a - [0, 0, b]])
    elif g.kind == "sphere":
        local = _SPHERE * a
    elif g.kind == "ellipsoid":
        local = _SPHERE * np.array([a, b, c])
    else:
        raise AssertionError(f"unexpected geom kind {g.kind}")
    return local @ _quat_to_matrix(g.quat).T + np.asarray(g.pos)


def sampled_bounds(g: Geom) -> tuple[np.ndarray, np.ndarray]:
    pts = surface_points(g)
    return pts.min(0), pts.max(0)


# ---------------------------------------------------------------------------
# Variants
# ---------------------------------------------------------------------------


def _attribute_sets(spec: cat.CategorySpec) -> list[Attributes]:
    """Every size x state combination, cycling colours and materials so each is used."""
    combos = list(itertools.product(spec.sizes, spec.states or (None,)))
    n = max(len(combos), len(spec.colors), len(spec.materials))
    return [Attributes(spec.colors[i % len(spec.colors)], spec.materials[i % len(spec.materials)], *combos[i % len(combos)])
            for i in range(n)]


@functools.lru_cache(maxsize=None)
def variants(name: str) -> tuple[tuple[Attributes, cat.Built], ...]:
    spec = cat.CATALOGUE[name]
    return tuple((a, spec.build(a, np.random.default_rng(i))) for i, a in enumerate(_attribute_sets(spec)))


def _build(name: str, seed: int = 0, **kw) -> cat.Built:
    spec = cat.CATALOGUE[name]
    fields = dict(color=spec.colors[0], material=spec.materials[0], size="medium" if "medium" in spec.sizes else spec.sizes[0],
                  state=spec.states[0] if spec.states else None)
    fields.update(kw)
    return spec.build(Attributes(**fields), np.random.default_rng(seed))


ALL = sorted(cat.CATALOGUE)


def _with_surfaces(name: str) -> bool:
    return all(b.surfaces for _, b in variants(name))


# ---------------------------------------------------------------------------
# Registry
# ---------------------------------------------------------------------------


def test_catalogue_is_large_and_whitelisted():
    assert len(cat.CATALOGUE) >= 75
    assert set(cat.CATALOGUE) <= vocab.TARGET_WHITELIST_SET
    for name, spec in cat.CATALOGUE.items():
        assert spec.name == name
        assert spec.placement in cat.PLACEMENTS
        assert spec.colors and set(spec.colors) <= set(vocab.COLORS), name
        assert spec.materials and set(spec.materials) <= set(vocab.MATERIALS), name
        assert set(spec.states) <= set(vocab.STATES), name
        assert len(spec.states) != 1, f"{name}: a single state carries no information"
        assert spec.sizes and set(spec.sizes) <= set(vocab.SIZES), name
        assert spec.rooms and set(spec.rooms) <= set(vocab.ROOM_LABELS), name
        assert all(w > 0 for w in spec.rooms.values()), name
        assert (spec.placement == "wall") == (spec.mount_height > 0), name
        assert (spec.placement == "on_support") == bool(spec.supports), name


def test_every_room_label_has_plausible_contents():
    per_room = {label: {n for n, s in cat.CATALOGUE.items() if label in s.rooms} for label in vocab.ROOM_LABELS}
    for label, names in per_room.items():
        assert len(names) >= 4, (label, names)
    expected = {
        "laundry_room": {"washing_machine", "dryer", "laundry_basket", "shelf", "spray_bottle"},
        "entryway": {"coat_rack", "shoe_rack", "bench", "mirror"},
        "closet": {"wardrobe", "shoe_rack", "storage_box", "laundry_basket"},
        "garage": {"bicycle", "toolbox", "workbench", "ladder", "storage_box", "trash_can"},
        "bathroom": {"toilet", "sink", "bathtub", "towel_rack"},
        "kitchen": {"refrigerator", "stove", "cabinet", "microwave"},
        "bedroom": {"bed", "nightstand", "wardrobe", "pillow"},
        "living_room": {"sofa", "coffee_table", "television", "tv_stand"},
        "dining_room": {"dining_table", "chair", "plate"},
        "office": {"desk", "office_chair", "monitor", "keyboard"},
        "hallway": {"painting", "rug", "radiator"},
    }
    for label, names in expected.items():
        assert names <= per_room[label], (label, names - per_room[label])


def test_supports_resolve_to_categories_with_surfaces():
    for name, spec in cat.CATALOGUE.items():
        for sup in spec.supports:
            assert sup in cat.CATALOGUE, (name, sup)
            assert _with_surfaces(sup), f"{name} lists {sup}, which has no support surface"
            assert set(spec.rooms) & set(cat.CATALOGUE[sup].rooms), f"{name} and its support {sup} share no room"


def test_small_objects_fit_on_their_supports():
    """Each on-support object (medium) fits, footprint and height, on some
    surface of every support it lists, in every state of the support."""
    for name, spec in cat.CATALOGUE.items():
        if spec.placement != "on_support":
            continue
        for st in spec.states or (None,):
            hx, hy, hz = _build(name, state=st).half_extents
            for sup in spec.supports:
                sspec = cat.CATALOGUE[sup]
                for sst in sspec.states or (None,):
                    surfs = _build(sup, state=sst).surfaces
                    fits = [s for s in surfs
                            if 2 * hz <= s.clearance and (
                                (hx <= s.half_extents[0] + 0.02 and hy <= s.half_extents[1] + 0.02)
                                or (hy <= s.half_extents[0] + 0.02 and hx <= s.half_extents[1] + 0.02))]
                    assert fits, f"{name} ({st}) does not fit on {sup} ({sst})"


# ---------------------------------------------------------------------------
# Geometry contracts
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", ALL)
def test_builds_are_valid_and_contained(name):
    for attrs, built in variants(name):
        assert built.geoms, (name, attrs)
        assert len(built.geoms) <= MAX_GEOMS, (name, attrs, len(built.geoms))
        hx, hy, hz = built.half_extents
        assert min(hx, hy, hz) > 0 and all(math.isfinite(v) for v in (hx, hy, hz)), (name, attrs)
        los, his = [], []
        for g in built.geoms:
            assert g.kind in ("box", "cylinder", "sphere", "capsule", "ellipsoid"), (name, g.part)
            vals = np.array(g.size + g.pos + g.quat + g.rgba)
            assert np.all(np.isfinite(vals)), (name, g.part)
            assert abs(np.linalg.norm(g.quat) - 1) < 1e-9, (name, g.part)
            assert all(0 <= c <= 1 for c in g.rgba), (name, g.part)
            used = {"box": 3, "ellipsoid": 3, "cylinder": 2, "capsule": 2, "sphere": 1}[g.kind]
            assert all(v > 0 for v in g.size[:used]), (name, g.part, g.size)
            assert g.material is None or g.material in vocab.MATERIALS, (name, g.part)
            lo, hi = sampled_bounds(g)
            los.append(lo)
            his.append(hi)
            # inside the object's box, centred at (0, 0, hz)
            assert np.all(lo >= np.array([-hx, -hy, 0.0]) - TOL), (name, attrs, g.part, lo)
            assert np.all(hi <= np.array([hx, hy, 2 * hz]) + TOL), (name, attrs, g.part, hi)
        lo, hi = np.min(los, 0), np.max(his, 0)
        # the box is tight: parts reach each face (up to sampling of round parts)
        slack = 0.003 * max(hx, hy, hz) + 1e-4
        assert np.allclose(lo, [-hx, -hy, 0.0], atol=slack), (name, attrs, lo)
        assert np.allclose(hi, [hx, hy, 2 * hz], atol=slack), (name, attrs, hi)


def test_geom_aabb_matches_sampled_bounds():
    checked = 0
    for name in ALL:
        for _, built in variants(name)[:2]:
            for g in built.geoms:
                lo, hi = cat.geom_aabb(g)
                slo, shi = sampled_bounds(g)
                tol = 0.003 * max(g.size) + 1e-9
                assert np.all(lo <= slo + 1e-9) and np.all(hi >= shi - 1e-9), (name, g.part)
                assert np.allclose(lo, slo, atol=tol) and np.allclose(hi, shi, atol=tol), (name, g.part, lo, slo)
                checked += 1
    assert checked > 500


@pytest.mark.parametrize("name", [n for n in ALL if any(b.surfaces for _, b in variants(n))])
def test_surfaces_are_real_free_and_inside(name):
    for attrs, built in variants(name):
        hx, hy, hz = built.half_extents
        bounds = [cat.geom_aabb(g) for g in built.geoms]
        for surf in built.surfaces:
            (cx, cy), (sx, sy), h = surf.center, surf.half_extents, surf.height
            assert sx > 0.02 and sy > 0.02 and surf.clearance > 0.05, (name, attrs, surf)
            assert abs(cx) + sx <= hx + TOL and abs(cy) + sy <= hy + TOL, (name, attrs, surf)
            assert 0 < h <= 2 * hz + TOL, (name, attrs, surf)

            def overlaps(lo, hi, shrink=0.002):
                return lo[0] < cx + sx - shrink and hi[0] > cx - sx + shrink and lo[1] < cy + sy - shrink and hi[1] > cy - sy + shrink

            tops = [g.part for g, (lo, hi) in zip(built.geoms, bounds) if overlaps(lo, hi) and abs(hi[2] - h) < 1e-3]
            assert tops, f"{name} {attrs}: no part has its top at the surface height {h:.3f}"
            ceiling = h + (surf.clearance if math.isfinite(surf.clearance) else 10.0)
            for g, (lo, hi) in zip(built.geoms, bounds):
                if overlaps(lo, hi):
                    assert hi[2] <= h + 1e-3 or lo[2] >= ceiling - 1e-3, f"{name} {attrs}: {g.part} intrudes above surface at {h:.3f}"


def test_placement_heights_are_realistic():
    def top(name, **kw):
        return 2 * _build(name, **kw).half_extents[2]

    def surface(name, **kw):
        return max(s.height for s in _build(name, **kw).surfaces)

    assert 0.7 <= surface("dining_table") <= 0.8
    assert 0.7 <= surface("desk") <= 0.8
    assert 0.85 <= min(s.height for s in _build("cabinet").surfaces) <= 0.95
    assert 0.85 <= surface("kitchen_island") <= 0.95
    assert 0.4 <= min(s.height for s in _build("bed").surfaces) <= 0.65
    assert 0.38 <= surface("sofa") <= 0.5
    assert 0.45 <= surface("nightstand") <= 0.7
    assert 1.7 <= top("wardrobe") <= 2.3
    assert 1.6 <= top("refrigerator") <= 2.0
    for name, spec in cat.CATALOGUE.items():
        for attrs, built in variants(name):
            assert spec.mount_height + 2 * built.half_extents[2] <= 2.45, f"{name} {attrs} does not fit under a 2.5 m ceiling"


def test_small_objects_are_small():
    def vol(b):
        return 8 * math.prod(b.half_extents)

    cup, table = _build("cup"), _build("dining_table")
    assert vol(cup) < 1e-3 * vol(table)
    assert 0.06 <= 2 * max(cup.half_extents[:2]) <= 0.1  # "a cup is about 8 cm"
    for name in ("cup", "mug", "remote_control", "alarm_clock", "candle", "soap_dispenser", "bottle", "tissue_box", "book"):
        assert max(2 * v for v in _build(name).half_extents) < 0.35, name
    for name in ("bed", "sofa", "wardrobe", "dining_table", "refrigerator", "bookshelf"):
        assert max(2 * v for v in _build(name).half_extents) > 0.9, name


# ---------------------------------------------------------------------------
# Attributes in the geometry
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", ALL)
def test_colour_and_material_are_expressed(name):
    spec = cat.CATALOGUE[name]
    for attrs, built in variants(name):
        want = np.array(cat.rgba(attrs.color)[:3])
        targets = [want, np.array(cat.glow(cat.rgba(attrs.color))[:3])]
        dist = min(np.linalg.norm(np.array(g.rgba[:3]) - t) for g in built.geoms for t in targets)
        assert dist < 0.2, f"{name} {attrs}: no part shows the colour {attrs.color}"
        assert any(g.material == attrs.material for g in built.geoms), f"{name} {attrs}: no part of material {attrs.material}"
    if len(spec.colors) > 1:
        a, b = (_build(name, color=c) for c in spec.colors[:2])
        assert [g.rgba for g in a.geoms] != [g.rgba for g in b.geoms], name


@pytest.mark.parametrize("name", [n for n in ALL if cat.CATALOGUE[n].states])
def test_states_change_the_geometry(name):
    spec = cat.CATALOGUE[name]
    looks = {}
    for st in spec.states:
        built = _build(name, state=st)
        looks[st] = tuple((g.kind, g.size, g.pos, g.quat, g.rgba) for g in built.geoms)
    for s1, s2 in itertools.combinations(spec.states, 2):
        assert looks[s1] != looks[s2], f"{name}: states {s1} and {s2} look the same"


def test_state_semantics():
    def parts(name, **kw):
        return {g.part: g for g in _build(name, **kw).geoms}

    # lights: a coloured shade is much brighter when on, a white one turns warm
    for name, part in (("floor_lamp", "shade"), ("table_lamp", "lamp_shade")):
        on, off = parts(name, state="on", color="blue")[part], parts(name, state="off", color="blue")[part]
        assert sum(on.rgba[:3]) > sum(off.rgba[:3]) + 0.5, name
        on, off = parts(name, state="on", color="white")[part], parts(name, state="off", color="white")[part]
        assert on.rgba[0] - on.rgba[2] > off.rgba[0] - off.rgba[2] + 0.1, name
    for name in ("television", "monitor"):
        on, off = parts(name, state="on")["screen"], parts(name, state="off")["screen"]
        assert sum(on.rgba[:3]) > 1.0 > 0.3 > sum(off.rgba[:3]), name
    # an open laptop is taller than a closed one; open doors make a wardrobe deeper
    assert _build("laptop", state="open").half_extents[2] > 2 * _build("laptop", state="closed").half_extents[2]
    assert _build("wardrobe", state="open").half_extents[0] > _build("wardrobe", state="closed").half_extents[0] + 0.1
    assert _build("dresser", state="open").half_extents[0] > _build("dresser", state="closed").half_extents[0] + 0.1
    # full containers hold more parts
    for name in ("bookshelf", "vase", "bowl", "fruit_bowl", "laundry_basket"):
        assert len(_build(name, state="full").geoms) > len(_build(name, state="empty").geoms), name
    # an open curtain leaves the middle of the rod bare
    for st, bare in (("open", True), ("closed", False)):
        pleats = [g for g in _build("curtain", state=st).geoms if g.part.startswith("pleat")]
        assert all(abs(g.pos[1]) > 0.3 for g in pleats) == bare


@pytest.mark.parametrize("name", [n for n in ALL if len(cat.CATALOGUE[n].sizes) > 1])
def test_size_classes_scale_the_box(name):
    spec = cat.CATALOGUE[name]
    st = spec.states[0] if spec.states else None
    vols = []
    for size in vocab.SIZES:
        if size in spec.sizes:
            vols.append(math.prod(_build(name, size=size, state=st).half_extents))
    assert all(b > a * 1.1 for a, b in zip(vols, vols[1:])), (name, vols)


@pytest.mark.parametrize("name", ALL)
def test_builders_are_deterministic(name):
    spec = cat.CATALOGUE[name]
    for attrs in _attribute_sets(spec)[:4]:
        a = spec.build(attrs, np.random.default_rng(7))
        b = spec.build(attrs, np.random.default_rng(7))
        assert a == b, name


def test_rng_only_varies_details():
    """Different seeds change details (books, leaves, clock hands) but not the object's size."""
    for name in ALL:
        a, b = _build(name, seed=1), _build(name, seed=2)
        assert np.allclose(a.half_extents, b.half_extents, rtol=0.35, atol=0.05), name


def test_instantiate_places_box_and_surfaces():
    built = _build("dining_table")
    attrs = Attributes("brown", "wood", "medium")
    inst = cat.instantiate("t0", "dining_table", attrs, built, (2.0, 1.0, 0.0), math.pi / 2, room="r0")
    assert inst.bbox.zmin == pytest.approx(0.0) and inst.bbox.zmax == pytest.approx(2 * built.half_extents[2])
    (h, corners), = cat.surfaces_world(inst, built)
    assert h == pytest.approx(built.surfaces[0].height)
    assert np.all(inst.bbox.distance_xy(corners) < 1e-9)
    # yaw pi/2: the table's long side (x) now runs along world y
    assert np.ptp(corners[:, 1]) > np.ptp(corners[:, 0])


# ---------------------------------------------------------------------------
# Gallery smoke test
# ---------------------------------------------------------------------------


def _egl_available() -> str | None:
    try:
        import mujoco

        m = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='1 1 .1' type='plane'/></worldbody></mujoco>")
        r = mujoco.Renderer(m, 16, 16)
        r.close()
    except Exception as e:  # noqa: BLE001 - any failure means no headless GL here
        return f"headless OpenGL rendering unavailable ({os.environ.get('MUJOCO_GL')}): {e!r}"
    return None


@pytest.mark.render
def test_gallery_writes_png(tmp_path):
    reason = _egl_available()
    if reason:
        pytest.skip(reason)
    from ignjax.scenes.viz import gallery

    out = tmp_path / "gallery.png"
    tiles = gallery.render_gallery(out, size=96, names=("chair", "laptop", "curtain"))
    assert out.is_file() and out.stat().st_size > 1000
    # chair, laptop open/closed, curtain open/closed
    assert len(tiles) == 5
    import matplotlib.image as mpimg

    img = mpimg.imread(out)
    assert img.ndim == 3 and img.shape[0] >= 96 and img.shape[1] >= 96 * 3
    assert float(np.std(img[..., :3])) > 0.02  # not a blank image
