"""``python -m ignjax.bench``: speed figures, measured in one process.

Every figure is a ratio against (or next to) a reference run in the same
process, on the same inputs:

* **rays** - random rays in a 10-room procedural house: the exact fast path
  (:func:`ignjax.sim.rays.fast.fast_rays`), the rollouts' depth ray
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
  batch is sharded over every device (``rollout_parts``: the device count,
  :func:`ignjax.sim.rollout.batch_parts`; on CPU one device per core,
  ``IGNJAX_CPU_DEVICES`` to change it).
* **scaling** - decision steps/s of the EIG agent at B = 4096 sharded over
  1, 2 and all devices (``scaling.devices``), measured after compile in
  turns (best of three each), so a machine shared with other work slows
  them alike; on a CPU also the one-device program with the process pinned
  to one core (``scaling.one_device_one_core``: a lone XLA:CPU device runs
  its larger operations on every core's threads).
* **limit** - what this machine allows the same rollouts at B = 4096
  (:mod:`ignjax.bench.limit`): its gather rates, read bandwidth and
  elementwise rate, each agent's look-ups and operations per decision step
  counted in its own program, the steps/s they allow, what bounds them
  (``"gather"``, ``"bandwidth"`` or ``"compute"``) and the fraction of it
  the decision-steps figure reaches; the top-level ``steps_per_s``,
  ``bound`` and ``fraction`` are the EIG agent's.
* **pieces** - where a decision step's time goes (:mod:`ignjax.bench.pieces`):
  microseconds per decision step of the agent, the waypoints, the
  controller's probes, the oracle, the rest of the step and the
  observation, each run as a program of its own on one device's share of
  the B = 4096 rollouts, beside that share's fused rollout (``whole``).
* **rl** - the RL environment (:mod:`ignjax.rl`, :mod:`ignjax.bench.rl`):
  environment steps/s at B = 4096 with random valid actions and auto-reset
  (``env_steps_per_s``; one jitted scan of 20 steps sharded over the devices),
  next to the ``random`` agent's rollout decision steps/s on the same
  episodes, timed in turns in the same run (``random_rollout_steps_per_s``),
  and their ``ratio``.
* **compile_s** - first call of the EIG agent's rollout at B = 256.
* **time_to_result** - what a researcher waits for a result
  (:mod:`ignjax.bench.time_to_result`): ``evaluate --agent eig`` on the
  500 episodes, ``sweep --study eval --quick`` and the in-the-loop sweep of
  16 cost vectors x 500 episodes, each in a fresh process on an empty cache
  folder (cold) and again on that folder (warm), split into load, compile
  and run, with the number of programs compiled or loaded from the cache.
* **studies** - offline WSR of 10^6 cost vectors x 500 episodes, and the
  in-the-loop sweep (the EIG agent under K cost vectors x 500 episodes in
  one vmapped call; ``--quick`` uses K = 16): ``in_loop_s`` is the first
  call, compile included, ``in_loop_run_s`` a second, compiled call.

``--json``: the last line of stdout is one JSON object with every figure.
``--llm``: only the MLLM host loop's figures (:mod:`ignjax.bench.llm`).
``--pieces``: only the ``pieces`` block.
``--rl``: only the ``rl`` block.
``--time-to-result``: only the ``time_to_result`` block.
``--scaling``: only how cost grows (:mod:`ignjax.bench.scaling`): steps/s and
memory against batch size, scenes in the bank, devices and cost vectors, as
``scaling.png`` and ``scaling.json`` in ``--out``.

The ray figures are :mod:`ignjax.bench.rays`, the rollout and study figures
:mod:`ignjax.bench.rollouts`; this module is the command line.
"""

from __future__ import annotations

import argparse
import json
import sys

from ignjax.bench.scaling import SCALING_BATCH, bench_devices
from ignjax.bench.timing import log
from ignjax.cache import add_cache_arguments, apply_cache_arguments


def build_parser() -> argparse.ArgumentParser:
    """The command line's options (also read by the documentation's tests, which parse its commands)."""
    p = argparse.ArgumentParser(prog="python -m ignjax.bench", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("--quick", action="store_true", help="fewer rays, the EIG and random agents only, K = 16 in the loop")
    p.add_argument("--json", action="store_true", help="end stdout with one JSON line of every figure")
    p.add_argument("--episodes", help="episode file for the rollouts (default: the shipped benchmark)")
    p.add_argument("--scaling", action="store_true",
                   help="only how cost grows: EIG decision steps/s and memory against batch size, scenes in the bank, "
                        "devices and cost vectors; writes OUT/scaling.png and OUT/scaling.json (ignjax.bench.scaling)")
    p.add_argument("--out", default="runs/bench", help="output folder of --scaling's figure (default runs/bench)")
    p.add_argument("--llm", action="store_true",
                   help="only the MLLM loop's figures (the llm block: batched vs sequential episodes per hour against "
                        "the local scripted server, utilisation, host ms per decision; ignjax.bench.llm)")
    p.add_argument("--pieces", action="store_true",
                   help="only where a decision step's time goes: microseconds per decision of each piece of the step "
                        "(ignjax.bench.pieces); with --quick the EIG and random agents")
    p.add_argument("--rl", action="store_true",
                   help="only the rl block: the RL environment's steps/s at B = 4096 with random valid actions and "
                        "auto-reset, next to the random agent's rollout (ignjax.bench.rl)")
    p.add_argument("--time-to-result", action="store_true",
                   help="only the time_to_result block: evaluate, a quick sweep and the in-the-loop sweep, each cold "
                        "and warm in fresh processes (ignjax.bench.time_to_result)")
    add_cache_arguments(p)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    apply_cache_arguments(args)
    # imported here, not at the top: the figures pull in jax, MuJoCo and the
    # simulator (about 5 s), which ``--help`` should not wait for
    import jax

    from ignjax.bench.limit import LIMIT_BATCH, bench_limit
    from ignjax.bench.rays import bench_probe_rays, bench_rays
    from ignjax.bench.render import bench_render
    from ignjax.bench.rollouts import AGENTS, bench_steps, bench_studies
    from ignjax.episodes.dataset import load_benchmark
    from ignjax.evaluate.runner import make_world
    from ignjax.sim.rollout import batch_parts
    from ignjax.data.shipped import shipped_episodes
    from ignjax.errors import IgnjaxError

    try:
        episodes = args.episodes or shipped_episodes()
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    device = f"{jax.default_backend()}: {jax.devices()[0].device_kind} x{jax.device_count()}"
    log(f"device {device}")
    res: dict = {"device": device, "quick": args.quick}
    if args.llm:
        from ignjax.bench.llm import bench_llm

        log("MLLM host loop against the scripted server ...")
        res["llm"] = bench_llm(load_benchmark(episodes), args.quick)
        print(json.dumps(res, sort_keys=True) if args.json else json.dumps(res, indent=2, sort_keys=True))
        return 0
    if args.scaling:
        from ignjax.bench.scaling import growth_curves, write_growth

        from ignjax.episodes.dataset import open_benchmark

        log("how cost grows (EIG rollout) ...")
        res["scaling"] = growth_curves(open_benchmark(episodes), args.quick)
        res["scaling"]["device"] = device
        res["scaling"]["files"] = write_growth(res["scaling"], args.out)
        log(f"  wrote {res['scaling']['files']['png']}")
        print(json.dumps(res, sort_keys=True) if args.json else json.dumps(res, indent=2, sort_keys=True))
        return 0
    if args.time_to_result:
        res["time_to_result"] = _time_to_result(episodes)
        print(json.dumps(res, sort_keys=True) if args.json else json.dumps(res, indent=2, sort_keys=True))
        return 0
    if args.rl:
        es = load_benchmark(episodes)
        res["rl"] = _rl(es, make_world(es))
        print(json.dumps(res, sort_keys=True) if args.json else json.dumps(res, indent=2, sort_keys=True))
        return 0
    if args.pieces:
        es = load_benchmark(episodes)
        res["pieces"] = _pieces(es, make_world(es), ("random", "eig") if args.quick else AGENTS)
        print(json.dumps(res, sort_keys=True) if args.json else json.dumps(res, indent=2, sort_keys=True))
        return 0
    res["time_to_result"] = _time_to_result(episodes)  # first: fresh processes, this one still small
    log("rays ...")
    res.update(bench_rays(args.quick))
    r = res["rays_per_s"]
    log(f"  fast {r['fast']:.3g}/s, rollout depth march {r['rollout_depth_march']:.3g}/s, mjx.ray {r['mjx']:.3g}/s, "
         f"mj_multiRay {r['mj_multiray']:.3g}/s; fast/mjx = {r['fast'] / r['mjx']:.1f}x, "
         f"fast/mj_multiRay = {r['fast'] / r['mj_multiray']:.1f}x; agreement {res['ray_agreement']:.4f} "
         f"(march {res['ray_agreement_depth_march']:.4f}); 10-room house compile + grids {res['scene_compile_s']:.2f} s")
    res["probe_ray_agreement"] = bench_probe_rays(args.quick)
    log("  probe-map rays within one cell of mj_ray: " + ", ".join(
        f"{k} {v:.4f}" for k, v in res["probe_ray_agreement"].items()))
    es = load_benchmark(episodes)
    world = make_world(es)
    log("rendered observations ...")
    res["render"] = bench_render(es.bank, args.quick)
    log("decision steps ...")
    agents = ("random", "eig") if args.quick else AGENTS
    sizes = (256, 1024, 4096)
    res["rollout_parts"] = {str(B): batch_parts(B) for B in sizes}
    log(f"  each batch sharded over {batch_parts()} {jax.default_backend()} devices")
    res["steps_per_s"], res["compile_s"] = bench_steps(es, world, agents, sizes)
    log(f"  EIG rollout compile {res['compile_s']:.1f} s")
    res["rl"] = _rl(es, world)
    log(f"what the machine allows a decision step (B = {LIMIT_BATCH}) ...")
    res["limit"] = bench_limit(es, world, agents, LIMIT_BATCH, res["steps_per_s"], args.quick)
    res["pieces"] = _pieces(es, world, agents)
    res["scaling"] = _scaling(es, world)
    log("studies ...")
    res["studies"] = bench_studies(es, world, args.quick)
    if args.json:
        print(json.dumps(res, sort_keys=True))
    else:
        print(json.dumps(res, indent=2, sort_keys=True))
    return 0


def _time_to_result(episodes) -> dict:
    """:func:`ignjax.bench.time_to_result.bench_time_to_result`, with its progress lines."""
    from ignjax.bench.time_to_result import bench_time_to_result

    log("time to result (fresh processes; cold = empty cache folder, then warm) ...")
    return bench_time_to_result(str(episodes), log=log)


def _rl(es, world) -> dict:
    """:func:`ignjax.bench.rl.bench_rl` at B = 4096, with its progress lines."""
    from ignjax.bench.rl import RL_BATCH, bench_rl

    log(f"RL environment (B = {RL_BATCH}, random valid actions, auto-reset) ...")
    return bench_rl(es, world)


def _pieces(es, world, agents) -> dict:
    """:func:`ignjax.bench.pieces.bench_pieces` at the limit's batch, with its progress lines."""
    from ignjax.bench.limit import LIMIT_BATCH
    from ignjax.bench.pieces import bench_pieces

    log(f"where a decision step's time goes (one device's share of B = {LIMIT_BATCH}) ...")
    return bench_pieces(es, world, agents, LIMIT_BATCH)


def _scaling(es, world=None) -> dict:
    """:func:`ignjax.bench.scaling.bench_devices`, with its progress lines."""
    from ignjax.evaluate.runner import make_world

    log(f"scaling: EIG rollout at B = {SCALING_BATCH} over 1, 2 and all devices ...")
    out = bench_devices(es, world or make_world(es))
    log("  " + ", ".join(f"{c} devices {v:.0f} decision steps/s" for c, v in out["devices"].items())
        + (f"; 1 device with the process pinned to one core {out['one_device_one_core']:.0f}"
           if "one_device_one_core" in out else ""))
    return out


if __name__ == "__main__":
    sys.exit(main())
