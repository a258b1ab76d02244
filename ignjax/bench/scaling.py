"""How cost grows with the work: ``python -m ignjax.bench --scaling``.

Four curves of the EIG agent's rollout on the benchmark's episodes (the
shipped one unless ``--episodes``), each point one compiled program timed
after its compilation:

* **batch** - decision steps/s and memory against the batch size B
  (:data:`BATCHES`), sharded over every device;
* **scenes** - the same at B = :data:`SCENES_BATCH` against the number of
  scenes in the bank (:data:`SCENE_COUNTS`). Where the episode file has
  fewer scenes than a point asks for, the bank is filled with renamed
  copies of its scenes (each copy a separate slice of every table, so
  memory and table sizes grow as with distinct scenes of the same sizes)
  and the episodes are spread over the copies; the record says how many
  distinct scenes there were. A point whose world would not fit in
  :data:`MEMORY_SHARE` of the machine's available memory is skipped with
  the estimate (the bank pads every scene to the largest one: its memory
  is the scene count times the largest scene);
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
MEMORY_SHARE = 0.5
"""A scenes point runs only if its world's estimate stays under this share of the available memory."""
QUICK_LIMITS = {"batch": 4096, "scenes": 50, "vectors": 256}


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _available_bytes() -> int:
    try:
        with open("/proc/meminfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_AVPHYS_PAGES"))


def _tile(es, world, n: int, batch: int):
    """(world, specs) of a bank of ``n`` scenes made from ``es``'s (renamed
    copies where it has fewer) and ``batch`` episodes spread over them."""
    import jax
    import jax.numpy as jnp

    from ignjax.sim.env import World

    bank, S = world.bank, world.bank.n_scenes
    idx = np.arange(batch) % len(es)
    specs = jax.tree.map(lambda a: a[idx], es.specs)
    if n == S:
        return world, specs
    src = np.arange(n) % S
    take = lambda tree: jax.tree.map(lambda a: a[src], tree)  # noqa: E731
    ids = tuple(bank.scene_ids[s] if k < S else f"{bank.scene_ids[s]}~{k // S}" for k, s in enumerate(src))
    bank_n = dataclasses.replace(bank, rays=take(bank.rays), grid=take(bank.grid), instances=take(bank.instances),
                                 rooms=take(bank.rooms), doors=take(bank.doors), scene_ids=ids,
                                 compiled=tuple(bank.compiled[s] for s in src),
                                 navgrids=tuple(bank.navgrids[s] for s in src))
    world_n = World(bank_n, world.fields, world.config, fine=world.fine[src], packed_obs=world.packed_obs[src])
    reps = -(-n // S)
    scene = np.asarray(specs.scene)
    moved = scene + S * (np.arange(batch) % reps)
    scene = np.where(moved < n, moved, scene)
    return world_n, dataclasses.replace(specs, scene=jnp.asarray(scene, specs.scene.dtype))


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


def bench_devices(es, world, batch: int = SCALING_BATCH) -> dict:
    """Decision steps/s of the EIG agent's rollout of ``batch`` episodes
    sharded over 1, 2 and all devices (those there are), compiled first and
    then timed in turns (:func:`ignjax.bench.timing.time_interleaved`).

    Returns:
        {"batch": batch, "devices": {str(count): steps/s}}.
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
    return {"batch": batch, "devices": {str(c): steps[c] / dt for c, dt in zip(counts, best)}}


def growth_curves(es, world, quick: bool, batches=BATCHES, scene_counts=SCENE_COUNTS, vector_counts=VECTOR_COUNTS,
                  scenes_batch: int = SCENES_BATCH, vector_episodes: int = VECTOR_EPISODES,
                  devices_batch: int = SCALING_BATCH) -> dict:
    """The four curves (module docstring) as one record (``devices_batch``
    0: no devices curve)."""
    import jax
    import jax.numpy as jnp

    from ignjax.agents import get_agent
    from ignjax.protocol import LOCKED_COSTS
    from ignjax.sim.rollout import episode_keys, rollout_memory, rollout_sweep

    if quick:
        batches = tuple(b for b in batches if b <= QUICK_LIMITS["batch"])
        scene_counts = tuple(n for n in scene_counts if n <= QUICK_LIMITS["scenes"])
        vector_counts = tuple(k for k in vector_counts if k <= QUICK_LIMITS["vectors"])
    agent = get_agent("eig")
    params = agent.default_params()
    out: dict = {"agent": "eig", "distinct_scenes": world.bank.n_scenes, "episodes": len(es),
                 "batch": {}, "scenes": {}, "vectors": {}, "skipped": {}}
    for B in batches:
        idx = np.arange(B) % len(es)
        specs = jax.tree.map(lambda a: a[idx], es.specs)
        out["batch"][str(B)] = p = _rollout_point(world, specs, agent, params, episode_keys(0, np.arange(B)),
                                                  repeats=1 if B >= 16384 else 2)
        log(f"  B = {B}: {p['steps_per_s']:.3g} steps/s, program {p['memory_mb']['peak']:.0f} MB")
    per_scene = _world_bytes(world) - int(world.fields.nbytes)
    per_scene /= world.bank.n_scenes
    budget = MEMORY_SHARE * _available_bytes()
    for n in scene_counts:
        need = per_scene * n + world.fields.nbytes
        if need * max(1, jax.local_device_count()) > budget:
            out["skipped"][f"scenes={n}"] = (f"the padded bank of {n} scenes needs about {need / 2**30:.1f} GiB per "
                                             f"device copy, over {MEMORY_SHARE:g} of the {budget / MEMORY_SHARE / 2**30:.1f} "
                                             "GiB available")
            log(f"  {n} scenes: skipped ({out['skipped'][f'scenes={n}']})")
            continue
        w, specs = _tile(es, world, n, scenes_batch)
        p = _rollout_point(w, specs, agent, params, episode_keys(0, np.arange(scenes_batch)), repeats=1)
        p["world_mb"] = _world_bytes(w) / 2**20
        out["scenes"][str(n)] = p
        log(f"  {n} scenes: {p['steps_per_s']:.3g} steps/s, world {p['world_mb']:.0f} MB")
        del w
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
        out["devices"] = bench_devices(es, world, devices_batch)["devices"]
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

    panels = (("batch", "batch size B (episodes)"), ("scenes", "scenes in the bank"),
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
    skipped = "; ".join(f"{k}: {v}" for k, v in rec.get("skipped", {}).items())
    fig.suptitle(f"EIG rollout, {rec.get('device', '')}" + (f"\nskipped {skipped}" if skipped else ""), fontsize=9)
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


__all__ = ["BATCHES", "SCENE_COUNTS", "VECTOR_COUNTS", "SCALING_BATCH", "bench_devices", "growth_curves",
           "plot_growth", "write_growth"]
