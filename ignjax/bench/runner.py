"""``python -m ignjax.bench``: speed figures, measured in one process.

Every figure is a ratio against (or next to) a reference run in the same
process, on the same inputs:

* **rays** - random rays in a 10-room procedural house: the exact fast path
  (:func:`ignjax.sim.rays.caster.fast_rays`), the rollouts' depth ray
  (:func:`ignjax.sim.rays.queries.march`, voxel traversal with exact primitive
  tests), ``mjx.ray`` (vmapped) and ``mujoco.mj_multiRay``; their
  agreement with ``mj_multiRay`` within one grid cell.
* **probe rays** - agreement with ``mj_ray`` of the probe-map rays the
  rollouts cast: collision rays at the controller's range, the same rays
  over 2 m, and the observation's free-space rays.
* **scene compile** - compiling that house and its navigation grids.
* **decision steps/s** - full rollouts (simulation + agent + oracle +
  accounting, no rendering) on the shipped benchmark for each JAX-native
  agent at B = 256, 1024, 4096 episodes; a decision step is one MOVE, ASK
  or STOP of an unfinished episode (best of three compiled calls). Each
  batch runs as the default concurrent pieces (``rollout_parts``,
  :func:`ignjax.sim.rollout.batch_parts`).
* **compile_s** - first call of the EIG agent's rollout at B = 256.
* **studies** - offline WSR of 10^6 cost vectors x 500 episodes, and the
  in-the-loop sweep (the EIG agent under K cost vectors x 500 episodes in
  one vmapped call; ``--quick`` uses K = 16): ``in_loop_s`` is the first
  call, compile included, ``in_loop_run_s`` a second, compiled call.

``--json``: the last line of stdout is one JSON object with every figure.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

AGENTS = ("random", "explorer", "naive_asker", "eig", "shortest_path")
STEP_REPEATS = 3  # timed calls per decision-steps figure (the best is reported)


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def _bench_house():
    """The 10-room procedural house every ray figure is measured in."""
    from ignjax.scenes.procgen.generate import HouseParams, generate_house

    return generate_house(3, HouseParams(n_rooms=10), "bench_house")


def bench_rays(quick: bool) -> dict:
    import jax
    import jax.numpy as jnp

    from ignjax.scenes.bank import build_navgrid, compile_scene
    from ignjax.sim.rays import queries as SR
    from ignjax.sim.rays.caster import agreement, benchmark_rays, mj_multiray, random_rays, ray_grid, ray_groups_mask

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
    best = min(_timed(lambda: jax.block_until_ready(f(P, V))) for _ in range(3))
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
    import math

    import jax
    import jax.numpy as jnp

    from ignjax.scenes.bank import SceneBank
    from ignjax.sim import env as E
    from ignjax.sim.rays.caster import mj_rays
    from ignjax.sim.types import SimConfig

    bank = SceneBank.build([_bench_house()])
    cfg = SimConfig()
    world = E.World(bank, jnp.zeros((1,) + tuple(bank.grid.navigable.shape[1:]), jnp.float32), cfg)
    res = bank.grid.resolution
    n_col = len(cfg.collision_heights)
    rng = np.random.default_rng(0)
    pts_all = bank.navgrids[0].navigable_points()
    n = 4000 if quick else 20000
    out = {}
    cases = (("collision", cfg.collision_distance + res, res / E.FINE, tuple(cfg.collision_heights), 0),
             ("collision_2m", 2.0, res / E.FINE, tuple(cfg.collision_heights), 0),
             ("observation", cfg.obs_range, 2 * res, (cfg.eye_height, E.LOW_OBS_HEIGHT), n_col))
    for name, rng_m, step, heights, bit0 in cases:
        f = jax.jit(jax.vmap(lambda xy, hd, z: jnp.stack(
            [E.probe_free(world, jnp.int32(0), xy, hd, 1 << (bit0 + j), rng_m, step) for j in range(len(heights))])[z]))
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


def _timed(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def bench_steps(es, world, agents, sizes) -> tuple[dict, float]:
    import jax

    from ignjax.agents.base import get_agent
    from ignjax.sim.rollout import episode_keys, rollout

    out: dict = {}
    compile_s = float("nan")
    for name in agents:
        agent = get_agent(name)
        params = agent.default_params()
        out[name] = {}
        for B in sizes:
            idx = np.arange(B) % len(es)
            specs = jax.tree.map(lambda a: a[idx], es.specs)
            keys = episode_keys(0, np.arange(B))
            t = time.perf_counter()
            res = rollout(world, specs, agent, params, keys)
            jax.block_until_ready(res)
            first = time.perf_counter() - t
            dt = min(_timed(lambda: jax.block_until_ready(rollout(world, specs, agent, params, keys)))
                     for _ in range(STEP_REPEATS))  # best of a few: this figure is a throughput, not a latency
            steps = float(np.asarray(res[0].steps).sum())
            out[name][str(B)] = steps / dt
            if name == "eig" and B == sizes[0]:
                compile_s = first - dt
            _log(f"  {name:14s} B={B:5d}: {steps / dt:10.0f} decision steps/s (first call {first:.1f} s)")
    return out, compile_s


def bench_studies(es, world, quick: bool) -> dict:
    import dataclasses

    import jax
    import jax.numpy as jnp

    from ignjax.evaluate import metrics as M
    from ignjax.agents.base import get_agent
    from ignjax.sim.rollout import episode_keys, rollout_sweep
    from ignjax.studies.cost_sensitivity import cost_samples, offline_wsr

    rng = np.random.default_rng(0)
    A, E = 5, 500
    success = rng.random((A, E, 3)) < 0.4
    nq = rng.integers(0, 4, (A, E, 4))
    valid = np.ones((A, E), bool)
    costs = cost_samples(1_000_000, 0)
    offline_wsr(success, nq, valid, costs[:1000])  # compile
    t = time.perf_counter()
    offline_wsr(success, nq, valid, costs)
    offline_s = time.perf_counter() - t
    K = 16 if quick else 256
    agent = get_agent("eig")
    base = agent.default_params()
    scales = np.geomspace(0.25, 8.0, K)
    params = jax.tree.map(lambda x: jnp.broadcast_to(x, (K,) + jnp.shape(x)), base)
    params = dataclasses.replace(params, costs=jnp.asarray(scales[:, None] * np.asarray(M.LOCKED_COSTS), jnp.float32))
    n = min(len(es), E)
    idx = np.arange(E) % len(es)
    specs = jax.tree.map(lambda a: a[idx], es.specs)
    keys = episode_keys(0, np.arange(E))
    sweep = lambda: jax.block_until_ready(rollout_sweep(world, specs, agent, params, keys))  # noqa: E731
    in_loop_s = _timed(sweep)
    run_s = _timed(sweep)
    _log(f"  offline WSR 1e6 cost vectors x {E} episodes x {A} agents: {offline_s:.2f} s")
    _log(f"  in-the-loop {K} cost vectors x {E} episodes (benchmark of {n}): {in_loop_s:.1f} s incl. compile, "
         f"{run_s:.1f} s compiled")
    return {"offline_wsr_1e6_x_500_s": offline_s, "in_loop_vectors": K, "in_loop_episodes": E,
            "in_loop_s": in_loop_s, "in_loop_run_s": run_s, "in_loop_episodes_per_s": K * E / run_s}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m ignjax.bench", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("--quick", action="store_true", help="fewer rays, the EIG and random agents only, K = 16 in the loop")
    p.add_argument("--json", action="store_true", help="end stdout with one JSON line of every figure")
    p.add_argument("--episodes", help="episode file for the rollouts (default: the shipped benchmark)")
    args = p.parse_args(argv)
    import jax

    from ignjax.episodes.dataset import load_benchmark
    from ignjax.evaluate.runner import make_world
    from ignjax.sweep.runner import SHIPPED_BENCHMARK

    device = f"{jax.default_backend()}: {jax.devices()[0].device_kind} x{jax.device_count()}"
    _log(f"device {device}")
    res: dict = {"device": device, "quick": args.quick}
    _log("rays ...")
    res.update(bench_rays(args.quick))
    r = res["rays_per_s"]
    _log(f"  fast {r['fast']:.3g}/s, rollout depth march {r['rollout_depth_march']:.3g}/s, mjx.ray {r['mjx']:.3g}/s, "
         f"mj_multiRay {r['mj_multiray']:.3g}/s; fast/mjx = {r['fast'] / r['mjx']:.1f}x, "
         f"fast/mj_multiRay = {r['fast'] / r['mj_multiray']:.1f}x; agreement {res['ray_agreement']:.4f} "
         f"(march {res['ray_agreement_depth_march']:.4f}); 10-room house compile + grids {res['scene_compile_s']:.2f} s")
    res["probe_ray_agreement"] = bench_probe_rays(args.quick)
    _log("  probe-map rays within one cell of mj_ray: " + ", ".join(
        f"{k} {v:.4f}" for k, v in res["probe_ray_agreement"].items()))
    es = load_benchmark(args.episodes or SHIPPED_BENCHMARK)
    world = make_world(es)
    _log("decision steps ...")
    agents = ("random", "eig") if args.quick else AGENTS
    from ignjax.sim.rollout import batch_parts

    sizes = (256, 1024, 4096)
    res["rollout_parts"] = {str(B): batch_parts(B) for B in sizes}
    _log("  each batch runs as " + ", ".join(f"{v} pieces at B = {k}" for k, v in res["rollout_parts"].items()))
    res["steps_per_s"], res["compile_s"] = bench_steps(es, world, agents, sizes)
    _log(f"  EIG rollout compile {res['compile_s']:.1f} s")
    _log("studies ...")
    res["studies"] = bench_studies(es, world, args.quick)
    if args.json:
        print(json.dumps(res, sort_keys=True))
    else:
        print(json.dumps(res, indent=2, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
