"""The ray figures of ``python -m ignjax.bench`` and the helpers they share
with the ray tests: random rays from navigable points, per-ray agreement
with a reference, MuJoCo group flags, :func:`benchmark_rays` (the fast path
against ``mjx.ray`` and ``mj_multiRay``), :func:`bench_rays` (that, plus the
rollouts' depth ray) and :func:`bench_probe_rays` (the probe-map rays
against ``mj_ray``)."""

from __future__ import annotations

import math
import time
from typing import Sequence

import jax
import jax.numpy as jnp
import mujoco
import numpy as np

from ignjax.bench.timing import time_interleaved, timed
from ignjax.scenes.bank import SceneBank
from ignjax.scenes.compile import compile_scene
from ignjax.scenes.navgrid import NavGrid, build_navgrid
from ignjax.scenes.procgen.generate import HouseParams, generate_house
from ignjax.scenes.raygrid import ray_grid
from ignjax.sim.rays import queries as SR
from ignjax.sim.rays.exact import exact_rays, mj_multiray, mj_rays
from ignjax.sim.rays.fast import fast_rays
from ignjax.sim.types import SimConfig
from ignjax.sim.world import FINE, LOW_OBS_HEIGHT, World, probe_free


def ray_groups_mask(groups: Sequence[int], include_floor: bool = True) -> tuple[int, ...]:
    """MuJoCo geomgroup flags selecting ``groups`` (and the floor, group 0)."""
    g = [0] * mujoco.mjNGROUP
    for k in groups:
        g[k] = 1
    if include_floor:
        g[0] = 1
    return tuple(g)


# ---------------------------------------------------------------------------
# Random rays, agreement and benchmark
# ---------------------------------------------------------------------------


def random_rays(grid: NavGrid, n_origins: int, per_origin: int, rng: np.random.Generator,
                heights=(0.1, 2.0), pitch_deg: float = 45.0, horizontal: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Random rays from random navigable points.

    Origins are uniform over navigable cells (jittered within the cell) at
    heights uniform in ``heights``; each origin gets ``per_origin`` rays with
    uniform yaw and pitch uniform in ``[-pitch_deg, pitch_deg]`` (0 when
    ``horizontal``). Rays are grouped by origin (ray ``i`` starts at origin
    ``i // per_origin``), so :func:`mj_multiray` can cast them too.

    Returns:
        pnts: (n_origins * per_origin, 3); vecs: (n_origins * per_origin, 3) unit.
    """
    cells = np.argwhere(grid.navigable)
    if len(cells) == 0:
        raise ValueError(f"scene {grid.scene_id!r} has no navigable cells")
    pick = cells[rng.integers(0, len(cells), n_origins)]
    xy = grid.cell_to_world(pick) + rng.uniform(-0.5, 0.5, (n_origins, 2)) * grid.resolution
    z = rng.uniform(heights[0], heights[1], n_origins)
    o = np.concatenate([xy, z[:, None]], 1)
    n = n_origins * per_origin
    yaw = rng.uniform(-math.pi, math.pi, n)
    pitch = np.zeros(n) if horizontal else np.radians(rng.uniform(-pitch_deg, pitch_deg, n))
    vecs = np.stack([np.cos(yaw) * np.cos(pitch), np.sin(yaw) * np.cos(pitch), np.sin(pitch)], 1)
    return np.repeat(o, per_origin, axis=0), vecs


def agreement(d_fast, d_exact, max_dist: float, tol: float) -> np.ndarray:
    """Per-ray agreement of two distance arrays (see the module docstring).

    Args:
        d_fast, d_exact: (N,) distances, +inf (or anything > max_dist) on a miss.
        max_dist: the rays' range.
        tol: allowed distance difference for hits (one cell).

    Returns:
        (N,) bool.
    """
    f = np.asarray(d_fast, np.float64)
    e = np.asarray(d_exact, np.float64)
    hf, he = f <= max_dist, e <= max_dist
    both = hf & he & (np.abs(np.where(hf, f, 0) - np.where(he, e, 0)) <= tol)
    neither = ~hf & ~he
    edge = (np.abs(np.minimum(f, 1e9) - max_dist) <= 1e-3) | (np.abs(np.minimum(e, 1e9) - max_dist) <= 1e-3)
    return both | neither | (edge & (hf != he))


def benchmark_rays(compiled, grid: NavGrid, n_rays: int = 100_000, max_dist: float = 5.0, seed: int = 0,
                   horizontal: bool = False, heights=(0.1, 2.0), per_origin: int = 32,
                   include_floor: bool = True, repeat: int = 3) -> dict:
    """Throughput and agreement of the fast path against ``mjx.ray`` and
    ``mj_multiRay`` on the same random rays, in one process.

    Rays: :func:`random_rays` (``horizontal=True`` for collision rays), in
    groups of ``per_origin`` rays sharing an origin so that ``mj_multiRay``
    casts exactly the same rays (one call per origin, ``cutoff=max_dist``).
    Timed: the batched fast path (:func:`fast_rays`, jitted), raw
    ``mjx.ray`` (vmapped, jitted; it ignores cylinders), the exact path
    (:func:`exact_rays`: ``mjx.ray`` plus cylinders) and ``mj_multiRay``.
    Times are the best of ``repeat`` runs after a warm-up (compilation
    excluded), the four paths taking turns in every round. Agreement is measured against ``mj_multiRay`` with
    :func:`agreement` at a tolerance of one grid cell.

    Returns:
        dict: ``n_rays``, ``max_dist``, ``horizontal``, ``ngeom``,
        ``fast_rays_per_s``, ``mjx_rays_per_s``, ``exact_rays_per_s``,
        ``multiray_rays_per_s``, ``speedup_vs_mjx``, ``speedup_vs_multiray``,
        ``agreement`` (fast vs mj_multiRay), ``agreement_exact`` (exact path
        vs mj_multiRay, 1 mm) and ``hit_fraction``.
    """
    from mujoco import mjx  # imported here: mujoco.mjx adds about 3 s to importing this module

    rng = np.random.default_rng(seed)
    n_orig = max(n_rays // per_origin, 1)
    pnts, vecs = random_rays(grid, n_orig, per_origin, rng, heights=heights, horizontal=horizontal)
    n = len(pnts)
    rg = ray_grid(grid, compiled)
    groups = ray_groups_mask(grid.config.ray_groups, include_floor)
    P = jnp.asarray(pnts, jnp.float32)
    V = jnp.asarray(vecs, jnp.float32)
    fast = jax.jit(lambda p, v: fast_rays(rg, p, v, max_dist, 0, include_floor)[0])
    mx, dx = compiled.mjx_model, compiled.mjx_data
    raw = jax.jit(jax.vmap(lambda p, v: mjx.ray(mx, dx, p, v, geomgroup=groups)[0]))
    out = {}

    def run_fast():
        out["fast"] = jax.block_until_ready(fast(P, V))

    def run_raw():
        out["raw"] = jax.block_until_ready(raw(P, V))

    def run_exact():
        out["exact"] = jax.block_until_ready(exact_rays(compiled, P, V, groups)[0])

    def run_multi():
        res = []
        for i in range(n_orig):
            sl = slice(i * per_origin, (i + 1) * per_origin)
            res.append(mj_multiray(compiled, pnts[i * per_origin], vecs[sl], groups, cutoff=max_dist)[0])
        out["multi"] = np.concatenate(res)

    t_fast, t_raw, t_exact, t_multi = time_interleaved((run_fast, run_raw, run_exact, run_multi), repeat)
    ref = out["multi"]
    agree = agreement(np.asarray(out["fast"]), ref, max_dist, grid.resolution)
    agree_exact = agreement(np.asarray(out["exact"]), ref, max_dist, 1e-3)
    return {
        "n_rays": int(n), "max_dist": float(max_dist), "horizontal": bool(horizontal), "ngeom": int(compiled.ngeom),
        "fast_rays_per_s": n / t_fast, "mjx_rays_per_s": n / t_raw, "exact_rays_per_s": n / t_exact,
        "multiray_rays_per_s": n / t_multi, "speedup_vs_mjx": t_raw / t_fast, "speedup_vs_multiray": t_multi / t_fast,
        "agreement": float(agree.mean()), "agreement_exact": float(agree_exact.mean()),
        "hit_fraction": float((ref <= max_dist).mean()),
    }


def _bench_house():
    """The 10-room procedural house every ray figure is measured in."""
    return generate_house(3, HouseParams(n_rooms=10), "bench_house")


def bench_rays(quick: bool) -> dict:
    """The ``rays`` figures: :func:`benchmark_rays` in the 10-room house, the
    rollouts' depth ray (:func:`ignjax.sim.rays.queries.march`) on the same
    kind of rays with its agreement, and the time to compile the house and
    build its grids."""
    house = _bench_house()
    t0 = time.perf_counter()
    compiled = compile_scene(house)
    grid = build_navgrid(compiled)
    compile_s = time.perf_counter() - t0
    n = 16_384 if quick else 65_536
    r = benchmark_rays(compiled, grid, n_rays=n, max_dist=5.0, repeat=4 if quick else 5)
    # the rollouts' depth ray on the same kind of rays
    rng = np.random.default_rng(0)
    pnts, vecs = random_rays(grid, n // 32, 32, rng, heights=(0.1, 2.0))
    rg = ray_grid(grid, compiled)
    f = jax.jit(jax.vmap(lambda p, v: SR.march(rg, jnp.int32(0), p, v, jnp.float32(5.0), static_range=5.0,
                                               outside_hits=False, exact=8, iterations=96)))
    P, V = jnp.asarray(pnts, jnp.float32), jnp.asarray(vecs, jnp.float32)
    jax.block_until_ready(f(P, V))
    best = min(timed(lambda: jax.block_until_ready(f(P, V))) for _ in range(3))
    got = np.asarray(f(P, V))
    groups = ray_groups_mask(grid.config.ray_groups, True)
    ref = np.concatenate([mj_multiray(compiled, pnts[i], vecs[i:i + 32], groups, cutoff=5.0)[0]
                          for i in range(0, len(pnts), 32)])
    march_agree = float(np.mean(agreement(got, ref, 5.0, grid.config.resolution)))
    return {"n_rays": r["n_rays"], "ngeom": r["ngeom"], "rays_per_s": {
        "fast": r["fast_rays_per_s"], "mjx": r["mjx_rays_per_s"], "mj_multiray": r["multiray_rays_per_s"],
        "rollout_depth_march": len(pnts) / best},
        "ray_agreement": r["agreement"], "ray_agreement_depth_march": march_agree,
        "scene_compile_s": compile_s, "speedup_vs_mjx": r["speedup_vs_mjx"],
        "speedup_vs_multiray": r["speedup_vs_multiray"]}


def bench_probe_rays(quick: bool) -> dict:
    """Agreement with ``mj_ray`` (within one navigation cell plus one sample
    step) of the probe-map rays the rollouts cast: the controller's collision
    rays (collision heights, its range ``collision_distance`` + one cell), the
    same rays over 2 m, and the observation's free-space rays (eye and low
    height, ``obs_range``, steps of two cells)."""
    bank = SceneBank.build([_bench_house()])
    cfg = SimConfig()
    world = World(bank, jnp.zeros((1,) + tuple(bank.grid.navigable.shape[1:]), jnp.float32), cfg)
    res = bank.grid.resolution
    n_col = len(cfg.collision_heights)
    rng = np.random.default_rng(0)
    pts_all = bank.navgrids[0].navigable_points()
    n = 4000 if quick else 20000
    out = {}
    cases = (("collision", cfg.collision_distance + res, res / FINE, tuple(cfg.collision_heights), 0),
             ("collision_2m", 2.0, res / FINE, tuple(cfg.collision_heights), 0),
             ("observation", cfg.obs_range, 2 * res, (cfg.eye_height, LOW_OBS_HEIGHT), n_col))
    for name, rng_m, step, heights, bit0 in cases:
        f = jax.jit(jax.vmap(lambda xy, hd, z: jnp.stack(
            [probe_free(world, jnp.int32(0), xy, hd, 1 << (bit0 + j), rng_m, step) for j in range(len(heights))])[z]))
        pts = pts_all[rng.integers(len(pts_all), size=n)]
        hd = rng.uniform(-math.pi, math.pi, n)
        zi = rng.integers(0, len(heights), n)
        got = np.asarray(f(jnp.asarray(pts, jnp.float32), jnp.asarray(hd, jnp.float32), jnp.asarray(zi)))
        P = np.c_[pts, np.asarray(heights)[zi]]
        V = np.c_[np.cos(hd), np.sin(hd), np.zeros(n)]
        ref, _ = mj_rays(bank.compiled[0], P, V, geomgroup=(0, 1, 1, 1, 0, 0))
        ref = np.where(np.isfinite(ref) & (ref <= rng_m), ref, rng_m)
        out[name] = float(np.mean(np.abs(got - ref) <= res + step + 1e-4))
    return out
