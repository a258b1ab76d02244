"""How cost grows with the work: ``python -m ignjax.bench --scaling``.

Four curves of the EIG agent's rollout on the benchmark's episodes (the
shipped one unless ``--episodes``), each point one compiled program timed
after its compilation:

* **batch** - decision steps/s and memory against the batch size B
  (:data:`BATCHES`), sharded over every device;
* **scenes** - the same against the number of scenes in the benchmark
  (:data:`SCENE_COUNTS`): its first n scenes, or, where the episode file
  has fewer, renamed copies of them (:meth:`BenchmarkScenes.with_scenes`:
  tables and fields grow as with distinct scenes of the same sizes; the
  record says how many scenes were distinct). The scenes run as an
  evaluation runs them (:func:`ignjax.evaluate.runner.plan_run`): in
  buckets of scenes of similar size of at most ``bank_mb`` MiB each, one
  bucket's world at a time. Each bucket runs a batch of
  B = :data:`SCENES_BATCH` of its episodes, compiled first; steps/s is all
  buckets' steps over their summed time, ``memory_mb`` the largest bucket's
  program, ``world_mb`` the largest bucket's world and ``bank_total_mb`` the
  buckets' worlds together (what one process would hold if it kept them
  all, near the scenes' own sizes: no scene padded to a far larger one);
* **devices** - steps/s at B = :data:`SCALING_BATCH` sharded over 1, 2 and
  every device (on a CPU, the host devices of :mod:`ignjax.devices`);
* **vectors** - the in-the-loop sweep (:func:`ignjax.sim.rollout.rollout_sweep`):
  K cost vectors x :data:`VECTOR_EPISODES` episodes against K
  (:data:`VECTOR_COUNTS`); steps/s counts the decision steps of all K x E
  rows.

Memory is XLA's analysis of each compiled program on one device
(:func:`ignjax.sim.rollout.rollout_memory`: its arguments - the world's
copy, most of it - outputs and temporaries), so it is the same on every
backend and does not depend on what ran before; ``rss_mb`` is the process's
resident high-water mark after the point (points run in increasing size).

The batch, devices and vectors curves run on one bank of the benchmark's
first :data:`BASE_SCENES` scenes (all of the shipped benchmark's).

``--quick`` stops each curve early (B up to 4,096, 12 and 50 scenes,
K up to 256). The figure (``scaling.png``: one panel per curve, steps/s and
peak memory, sizes on a log axis) and the record (``scaling.json``) are written to
the bench's output folder (``--out``, default ``runs/bench``).
"""

from __future__ import annotations

import dataclasses
import json
import os
import resource
import time
from pathlib import Path

import numpy as np

from ignjax.bench.timing import log, time_interleaved

SCALING_BATCH = 4096
"""Episodes of the EIG rollout the device figures (and the scene curve) time."""
SCALING_REPEATS = 3
BATCHES = (256, 1024, 4096, 16384, 65536)
SCENE_COUNTS = (12, 50, 262)
SCENES_BATCH = SCALING_BATCH
VECTOR_COUNTS = (16, 64, 256, 1024, 4096)
VECTOR_EPISODES = 100
"""Episodes of each point of the vectors curve (K x 100 rows: 409,600 at K = 4,096)."""
BASE_SCENES = 12
"""Scenes of the bank the batch, devices and vectors curves run on (the first of the benchmark's)."""
QUICK_LIMITS = {"batch": 4096, "scenes": 50, "vectors": 256}


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _world_bytes(world) -> int:
    import jax

    return int(sum(getattr(a, "nbytes", 0) for a in jax.tree.leaves(world)))


def _point(run, steps_of, memory, repeats: int) -> dict:
    """Compile and run once (steps), time ``repeats`` more calls (best), memory."""
    t0 = time.perf_counter()
    steps = float(steps_of(run()))
    first = time.perf_counter() - t0
    best = min(time_interleaved([run], repeats)[0], first) if repeats else first
    mem = memory()
    return {"steps_per_s": steps / best, "seconds": best, "decision_steps": steps,
            "memory_mb": {k: v / 2**20 for k, v in mem.items()}, "rss_mb": _rss_mb()}


def _rollout_point(world, specs, agent, params, keys, parts=None, repeats: int = 1) -> dict:
    import jax

    from ignjax.sim.rollout import rollout, rollout_memory

    run = lambda: jax.block_until_ready(rollout(world, specs, agent, params, keys, parts=parts))  # noqa: E731
    return _point(run, lambda out: np.asarray(out[0].steps).sum(),
                  lambda: rollout_memory(world, specs, agent, params, keys, parts=parts), repeats)


def bench_devices(es, world, batch: int = SCALING_BATCH, one_core: bool = True) -> dict:
    """Decision steps/s of the EIG agent's rollout of ``batch`` episodes
    sharded over 1, 2 and all devices (those there are), compiled first and
    then timed in turns (:func:`ignjax.bench.timing.time_interleaved`).

    On a CPU with several devices (and ``one_core``) it also times the
    one-device program in a process pinned to one core
    (``one_device_one_core``, :func:`one_core_steps`; ``es`` must be the
    whole of its episode file).

    Returns:
        {"batch": batch, "devices": {str(count): steps/s}[, "one_device_one_core": steps/s]}.
    """
    import jax

    from ignjax.agents import get_agent
    from ignjax.sim.rollout import episode_keys, rollout

    agent = get_agent("eig")
    params = agent.default_params()
    idx = np.arange(batch) % len(es)
    specs = jax.tree.map(lambda a: a[idx], es.specs)
    keys = episode_keys(0, np.arange(batch))
    counts = sorted({c for c in (1, 2, jax.device_count()) if c <= jax.device_count()})
    runs = [lambda c=c: jax.block_until_ready(rollout(world, specs, agent, params, keys, parts=c)) for c in counts]
    steps = {c: float(np.asarray(run()[0].steps).sum()) for c, run in zip(counts, runs)}  # compile
    best = time_interleaved(runs, SCALING_REPEATS)
    out = {"batch": batch, "devices": {str(c): steps[c] / dt for c, dt in zip(counts, best)}}
    if one_core and jax.default_backend() == "cpu" and len(counts) > 1 and hasattr(os, "sched_setaffinity"):
        out["one_device_one_core"] = one_core_steps(es.path, batch)
    return out


def one_core_steps(episodes, batch: int = SCALING_BATCH) -> float:
    """EIG decision steps/s of :func:`bench_devices`' one-device program in a
    process of one CPU device pinned to one core (Linux): XLA:CPU runs a lone
    device's larger operations on every core's threads, so the one-device
    figure of a process with several devices is not one core's.

    Raises:
        RuntimeError: the process failed (its stderr's end).
    """
    import subprocess
    import sys

    core = min(os.sched_getaffinity(0))
    # the child pins itself before JAX starts, so every thread it makes inherits the one core
    code = ("import json, os, sys; os.sched_setaffinity(0, {int(sys.argv[3])}); "
            "from ignjax.bench.scaling import _one_core_child; "
            "print(json.dumps(_one_core_child(sys.argv[1], int(sys.argv[2]))))")
    r = subprocess.run([sys.executable, "-c", code, str(episodes), str(int(batch)), str(core)], capture_output=True,
                       text=True, env=dict(os.environ, IGNJAX_CPU_DEVICES="1"), timeout=1800)
    if r.returncode != 0:
        raise RuntimeError(f"the one-core process failed: {r.stderr[-2000:]}")
    return float(json.loads(r.stdout.strip().splitlines()[-1]))


def _one_core_child(episodes: str, batch: int) -> float:
    """:func:`one_core_steps`' process: one CPU device, the same episodes and batch."""
    from ignjax.devices import configure_cpu_devices

    configure_cpu_devices()
    from ignjax.episodes.dataset import load_benchmark
    from ignjax.evaluate.runner import make_world

    es = load_benchmark(episodes)
    return bench_devices(es, make_world(es), batch)["devices"]["1"]


def scenes_point(bs, n: int, batch: int = SCENES_BATCH, bank_mb: float | None = None) -> dict:
    """One point of the scenes curve (module docstring): the EIG rollout over
    ``n`` scenes of ``bs`` (a :class:`~ignjax.episodes.dataset.BenchmarkScenes`),
    a bucket at a time."""
    import jax

    from ignjax.agents import get_agent
    from ignjax.evaluate.runner import BANK_MB, make_world, plan_run
    from ignjax.sim.rollout import episode_keys

    agent = get_agent("eig")
    params = agent.default_params()
    sub = bs.with_scenes(n)
    plan = plan_run(sub, batch, BANK_MB if bank_mb is None else bank_mb)
    steps = seconds = 0.0
    memory: dict = {}
    worlds = []
    for pos in plan.buckets:
        es = sub.episode_set(pos)
        world = make_world(es)
        idx = np.arange(batch) % len(es)
        specs = jax.tree.map(lambda a: a[idx], es.specs)
        p = _rollout_point(world, specs, agent, params, episode_keys(0, es.key_index[idx]), repeats=1)
        steps += p["decision_steps"]
        seconds += p["seconds"]
        memory = {k: max(v, memory.get(k, 0.0)) for k, v in p["memory_mb"].items()}
        worlds.append(_world_bytes(world))
        del es, world
    return {"steps_per_s": steps / seconds, "seconds": seconds, "decision_steps": steps, "memory_mb": memory,
            "buckets": len(plan.buckets), "world_mb": max(worlds) / 2**20, "bank_total_mb": sum(worlds) / 2**20,
            "rss_mb": _rss_mb()}


def growth_curves(bs, quick: bool, batches=BATCHES, scene_counts=SCENE_COUNTS, vector_counts=VECTOR_COUNTS,
                  scenes_batch: int = SCENES_BATCH, vector_episodes: int = VECTOR_EPISODES,
                  devices_batch: int = SCALING_BATCH, bank_mb: float | None = None) -> dict:
    """The four curves (module docstring) of the benchmark ``bs`` (a
    :class:`~ignjax.episodes.dataset.BenchmarkScenes`) as one record
    (``devices_batch`` 0: no devices curve; ``bank_mb``: the buckets' budget,
    default :data:`ignjax.evaluate.runner.BANK_MB`)."""
    import jax
    import jax.numpy as jnp

    from ignjax.agents import get_agent
    from ignjax.evaluate.runner import make_world
    from ignjax.protocol import LOCKED_COSTS
    from ignjax.sim.rollout import episode_keys, rollout_memory, rollout_sweep

    base = bs.with_scenes(min(BASE_SCENES, bs.host.n_scenes))
    es = base.episode_set(np.arange(len(base)))
    world = make_world(es)

    if quick:
        batches = tuple(b for b in batches if b <= QUICK_LIMITS["batch"])
        scene_counts = tuple(n for n in scene_counts if n <= QUICK_LIMITS["scenes"])
        vector_counts = tuple(k for k in vector_counts if k <= QUICK_LIMITS["vectors"])
    agent = get_agent("eig")
    params = agent.default_params()
    out: dict = {"agent": "eig", "distinct_scenes": bs.host.n_scenes, "base_scenes": world.bank.n_scenes,
                 "episodes": len(es), "batch": {}, "scenes": {}, "vectors": {}}
    for B in batches:
        idx = np.arange(B) % len(es)
        specs = jax.tree.map(lambda a: a[idx], es.specs)
        out["batch"][str(B)] = p = _rollout_point(world, specs, agent, params, episode_keys(0, np.arange(B)),
                                                  repeats=1 if B >= 16384 else 2)
        log(f"  B = {B}: {p['steps_per_s']:.3g} steps/s, program {p['memory_mb']['peak']:.0f} MB")
    for n in scene_counts:
        out["scenes"][str(n)] = p = scenes_point(bs, n, scenes_batch, bank_mb)
        log(f"  {n} scenes: {p['steps_per_s']:.3g} steps/s in {p['buckets']} bucket(s); largest world "
            f"{p['world_mb']:.0f} MB, all buckets {p['bank_total_mb']:.0f} MB")
    E = vector_episodes
    idx = np.arange(E) % len(es)
    specs = jax.tree.map(lambda a: a[idx], es.specs)
    keys = episode_keys(0, np.arange(E))
    for K in vector_counts:
        scales = np.geomspace(0.25, 8.0, K)
        pb = jax.tree.map(lambda x: jnp.broadcast_to(x, (K,) + jnp.shape(x)), params)
        pb = dataclasses.replace(pb, costs=jnp.asarray(scales[:, None] * np.asarray(LOCKED_COSTS), jnp.float32))
        run = lambda pb=pb: jax.block_until_ready(rollout_sweep(world, specs, agent, pb, keys))  # noqa: E731
        p = _point(run, lambda o: np.asarray(o[0].steps).sum(),
                   lambda pb=pb: rollout_memory(world, specs, agent, pb, keys, sweep=True), repeats=1)
        p["episodes"] = E
        out["vectors"][str(K)] = p
        log(f"  {K} cost vectors x {E} episodes: {p['steps_per_s']:.3g} steps/s, {p['seconds']:.1f} s")
    if devices_batch:
        dev = bench_devices(es, world, devices_batch, one_core=base.host.n_scenes == bs.host.n_scenes
                            and len(base) == len(bs))
        out["devices"] = dev["devices"]
        if "one_device_one_core" in dev:
            out["one_device_one_core"] = dev["one_device_one_core"]
        out["devices_batch"] = devices_batch
    return out


def plot_growth(rec: dict, path: str | os.PathLike) -> Path:
    """``scaling.png``: one panel per curve (steps/s, and peak program memory on a second axis; x on a log scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import EngFormatter

    import io

    from ignjax.fileio import atomic_write

    panels = (("batch", "batch size B (episodes)"), ("scenes", "scenes (run in buckets, one at a time)"),
              ("devices", "devices"), ("vectors", "cost vectors K (in-the-loop sweep)"))
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    for ax, (key, label) in zip(axes.ravel(), panels):
        pts = rec.get(key) or {}
        xs = sorted(pts, key=float)
        if not xs:
            ax.text(0.5, 0.5, "not measured", ha="center", va="center", transform=ax.transAxes)
            ax.set_xlabel(label)
            continue
        x = [float(v) for v in xs]
        sps = [pts[v] if key == "devices" else pts[v]["steps_per_s"] for v in xs]
        ax.plot(x, sps, "o-", color="tab:blue", label="decision steps/s")
        ax.set_xscale("log", base=2)
        ax.set_ylim(bottom=0)
        ax.set_xlabel(label)
        ax.set_ylabel("decision steps/s", color="tab:blue")
        ax.set_xticks(x, [str(int(v)) for v in x])
        ax.yaxis.set_major_formatter(EngFormatter(sep=""))
        if key != "devices":
            ax2 = ax.twinx()
            ax2.plot(x, [pts[v]["memory_mb"]["peak"] for v in xs], "s--", color="tab:red", label="program memory")
            ax2.set_ylim(bottom=0)
            ax2.yaxis.set_major_formatter(EngFormatter(sep=""))
            ax2.set_ylabel("peak program memory (MB)", color="tab:red")
        ax.grid(alpha=0.3, which="both")
    fig.suptitle(f"EIG rollout, {rec.get('device', '')}", fontsize=9)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, dpi=110, format="png")
    plt.close(fig)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return atomic_write(path, buf.getvalue())


def write_growth(rec: dict, out: str | os.PathLike) -> dict:
    """Write ``scaling.json`` and ``scaling.png`` into ``out``; their paths."""
    from ignjax.fileio import atomic_write

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(out / "scaling.json", json.dumps(rec, indent=2, sort_keys=True, default=float) + "\n")
    return {"json": str(out / "scaling.json"), "png": str(plot_growth(rec, out / "scaling.png"))}


__all__ = ["BASE_SCENES", "BATCHES", "SCENE_COUNTS", "VECTOR_COUNTS", "SCALING_BATCH", "bench_devices",
           "growth_curves", "plot_growth", "scenes_point", "write_growth"]
