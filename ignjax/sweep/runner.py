"""``python -m ignjax.sweep``: the main job.

Runs the studies on a benchmark and writes ``<run.out>/<run.name>/``:

* ``report.md`` - the paper's Table-1 columns for every agent (overall and
  per difficulty) and every study's results with its figures;
* ``outcomes.parquet`` / ``outcomes.csv`` - one row per (agent, episode);
  ``metrics.csv`` - the metric table (both recomputable from the outcomes);
* ``costs_*.csv``, ``difficulty_*.csv``, ``derive_costs.csv``,
  ``analysis_*.csv`` - the studies' tables; ``figures/*.png``;
* ``run.json`` - the resolved configuration and its fingerprint;
  ``checkpoints/`` - the rollouts' partial results (orbax), for ``--resume``.

Studies (``--study``, repeatable or comma-separated; default all):
``eval`` agents x episodes; ``costs`` offline re-weighting of the stored
outcomes over sampled cost vectors plus the cost-aware agent re-run in the
loop under K cost vectors in one vmapped call; ``difficulty`` alpha and
threshold ablation and calibration on the stored factors; ``derive-costs``
the paper's cost construction; ``analysis`` the interaction analyses from
question traces and trajectories. ``costs``, ``difficulty`` and
``analysis`` use the ``eval`` rollouts (run as needed).

Every rollout is checkpointed as it finishes; a run interrupted (even by
SIGKILL) and continued with ``--resume`` writes the same bytes as an
uninterrupted one. Timings go to stderr only, never into the run folder.

Benchmark: ``benchmark.episodes`` when set; else the shipped
``scenes/benchmark.jsonl.gz`` (500 episodes, 150/200/150, seed 0) when the
benchmark settings are the defaults; else one built from
``benchmark.scenes`` into ``<run.out>/_benchmarks/`` and reused.
``benchmark.limit`` keeps N episodes spread evenly over the file (quick runs).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import shutil
import sys
import time
from pathlib import Path

import numpy as np

from ignjax.errors import ConfigError, IgnjaxError, InputError
from ignjax.fileio import atomic_write
from ignjax.config import STUDIES, fingerprint, resolve

REPO_SCENES = Path(__file__).resolve().parents[2] / "scenes"
SHIPPED_BENCHMARK = REPO_SCENES / "benchmark.jsonl.gz"


# ---------------------------------------------------------------------------
# command line
# ---------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m ignjax.sweep", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Run ignjax's studies (batched evaluation, cost-weight sensitivity, difficulty-coefficient "
                    "ablation, cost derivation, interaction analyses) and write a report.",
        epilog="Configuration: defaults <- --quick <- --config FILE <- --set items. Sections and keys: see "
               "sweeps/default.toml. Examples:\n"
               "  python -m ignjax.sweep                       # everything, default sizes\n"
               "  python -m ignjax.sweep --study eval --quick --out /tmp/r\n"
               "  python -m ignjax.sweep --set costs.samples=1000000 --set eval.agents='[\"eig\",\"random\"]'\n")
    p.add_argument("--study", action="append", default=[],
                   help=f"study to run: {', '.join(STUDIES)} or all (repeatable, or comma-separated; default all)")
    p.add_argument("--config", help="TOML file with [section] tables overriding the defaults (see sweeps/)")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one setting; VALUE in TOML syntax (e.g. costs.samples=1000, eval.agents=['eig'])")
    p.add_argument("--out", help="run folder (default <run.out>/<run.name>)")
    p.add_argument("--quick", action="store_true", help="small sizes for CI and smoke runs (60 episodes, fewer samples)")
    p.add_argument("--resume", action="store_true", help="continue an interrupted run in the same folder")
    p.add_argument("--force", action="store_true", help="replace a folder that holds another run")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    return p


def parse_studies(items: list[str]) -> list[str]:
    names = [s.strip() for item in items for s in item.split(",") if s.strip()]
    if not names or "all" in names:
        return list(STUDIES)
    for n in names:
        if n not in STUDIES:
            raise ConfigError(None, "--study", f"unknown study {n!r}; known: {', '.join(STUDIES)}, all")
    return [s for s in STUDIES if s in names]


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        studies = parse_studies(args.study)
        cfg = resolve(args.config, args.sets, args.quick)
        out = Path(args.out) if args.out else Path(cfg["run"]["out"]) / cfg["run"]["name"]
        t0 = time.perf_counter()
        run_sweep(cfg, studies, out, resume=args.resume, force=args.force, quiet=args.quiet)
        print(f"wrote {out / 'report.md'} ({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
        return 0
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


# ---------------------------------------------------------------------------
# run folder, checkpoints
# ---------------------------------------------------------------------------


def prepare_folder(out: Path, cfg: dict, studies: list[str], resume: bool, force: bool) -> None:
    """Create or reuse the run folder; refuse one that holds another run."""
    meta = out / "run.json"
    fp = fingerprint(cfg, studies)
    if out.exists() and any(out.iterdir()):
        if force:
            shutil.rmtree(out)
        elif not meta.is_file():
            raise InputError(str(out), "--out", "folder is not empty and holds no ignjax run; use --force to replace it")
        else:
            old = json.loads(meta.read_text())
            if old.get("fingerprint") != fp:
                raise InputError(str(meta), "fingerprint",
                                 "the folder holds a different run (other configuration or studies); "
                                 "use another --out, or --force to replace it")
            if not resume:
                raise InputError(str(out), "--out", "the folder already holds this run; use --resume to continue "
                                                    "it or --force to start over")
    out.mkdir(parents=True, exist_ok=True)
    if not meta.is_file():
        atomic_write(meta, json.dumps({"fingerprint": fp, "studies": studies, "config": cfg}, indent=2, sort_keys=True)
                    + "\n")


class Checkpoints:
    """Finished rollout stages of a run, saved with orbax (one folder per stage)."""

    def __init__(self, root: Path):
        self.root = root

    def _path(self, name: str) -> Path:
        return self.root / name.replace("/", "__")

    def has(self, name: str) -> bool:
        return self._path(name).is_dir()

    def load(self, name: str) -> dict:
        import orbax.checkpoint as ocp

        with ocp.PyTreeCheckpointer() as ck:
            return ck.restore(self._path(name).resolve())

    def save(self, name: str, tree: dict) -> None:
        import orbax.checkpoint as ocp

        self.root.mkdir(parents=True, exist_ok=True)
        path = self._path(name).resolve()
        tmp = path.with_name(path.name + ".partial")
        if tmp.exists():
            shutil.rmtree(tmp)
        with ocp.PyTreeCheckpointer() as ck:
            ck.save(tmp, tree)
        tmp.rename(path)  # a stage is either absent or complete


def _to_tree(obj) -> dict:
    return {f.name: np.asarray(getattr(obj, f.name)) for f in dataclasses.fields(obj)}


# ---------------------------------------------------------------------------
# benchmark
# ---------------------------------------------------------------------------


def benchmark_path(cfg: dict, out_root: Path, progress=None) -> Path:
    b = cfg["benchmark"]
    if b["episodes"]:
        p = Path(b["episodes"])
        if not p.is_file():
            raise InputError(str(p), "benchmark.episodes", "episode file not found")
        return p
    default = not b["scenes"] and b["subset"] == 500 and b["seed"] == 0
    if default and SHIPPED_BENCHMARK.is_file():
        return SHIPPED_BENCHMARK
    scenes = [Path(b["scenes"])] if b["scenes"] else [REPO_SCENES]
    for s in scenes:
        if not s.exists():
            raise InputError(str(s), "benchmark.scenes", "scene path not found")
    key = fingerprint({"scenes": [str(s.resolve()) for s in scenes], "subset": b["subset"], "seed": b["seed"]}, [])
    path = out_root / "_benchmarks" / key / "episodes.jsonl.gz"
    if path.is_file():
        return path
    from ignjax.scenes.io.sources import scene_sources
    from ignjax.episodes.construct import BuildConfig, build_benchmark
    from ignjax.episodes.schema import construction_path, write_records

    built = build_benchmark(scene_sources(scenes), BuildConfig(subset=b["subset"], seed=b["seed"]), progress=progress)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_records(construction_path(path), built["subset_construction"])
    write_records(path, built["subset"])
    return path


def load_episodes(cfg: dict, path: Path):
    from ignjax.episodes.dataset import load_benchmark

    es = load_benchmark(path)
    if len(es) == 0:
        raise InputError(str(path), "episodes", "the episode file holds no episodes")
    limit = cfg["benchmark"]["limit"]
    if 0 < limit < len(es):
        es = es.subset(np.unique(np.linspace(0, len(es) - 1, limit).round().astype(np.int64)))
    return es


# ---------------------------------------------------------------------------
# stages
# ---------------------------------------------------------------------------


def run_eval_stage(es, world, agent_name: str, cfg: dict, ckpt: Checkpoints, bar=None) -> dict:
    """Outcomes and trajectories of one agent (from the checkpoint when there)."""
    name = f"eval/{agent_name}"
    if ckpt.has(name):
        if bar is not None:
            bar.update(len(es))
        return ckpt.load(name)
    from ignjax.evaluate.runner import run_agent

    def prog(chunks):
        for c in chunks:
            yield c
            if bar is not None:
                bar.update(min(cfg["eval"]["batch"], len(es) - c))

    out, traj = run_agent(es, agent_name, batch=cfg["eval"]["batch"], seed=cfg["run"]["seed"], world=world,
                          progress=prog, parts=cfg["eval"]["parts"] or None)
    tree = {"out": _to_tree(out), "traj": _to_tree(traj)}
    ckpt.save(name, tree)
    return tree


def in_loop_costs(cfg: dict) -> tuple[np.ndarray, list[str]]:
    """(K, 4) cost vectors of the in-the-loop study and their labels."""
    locked = np.asarray(cfg["eval"]["costs"], np.float64)
    vecs, labels = [], []
    for s in cfg["costs"]["scales"]:
        vecs.append(locked * s)
        labels.append(f"all x{s:g}")
    f = cfg["costs"]["per_type_factor"]
    if f > 0:
        for t in range(4):
            v = locked.copy()
            v[t] *= f
            vecs.append(v)
            labels.append(f"Type {t + 1} x{f:g}")
    return np.asarray(vecs), labels


def run_costs_stage(es, world, cfg: dict, ckpt: Checkpoints, bar=None) -> dict:
    """The cost-aware agent under K charged cost vectors x all episodes (vmapped over K)."""
    name = "costs/in_loop"
    costs, _ = in_loop_costs(cfg)
    if ckpt.has(name):
        if bar is not None:
            bar.update(len(es) * len(costs))
        return ckpt.load(name)
    import jax
    import jax.numpy as jnp

    from ignjax.agents.base import get_agent
    from ignjax.evaluate.runner import episode_batches
    from ignjax.sim.rollout import rollout_sweep

    agent = get_agent(cfg["costs"]["agent"])
    base = agent.default_params()
    if not hasattr(base, "costs"):
        raise ConfigError(None, "costs.agent", f"{agent.name!r} has no cost parameters to sweep")
    K = len(costs)
    params = jax.tree.map(lambda x: jnp.broadcast_to(x, (K,) + jnp.shape(x)), base)
    params = dataclasses.replace(params, costs=jnp.asarray(costs, jnp.float32))
    batch = max(1, cfg["eval"]["batch"] // max(1, K // 4))
    parts = []
    for n_real, specs, keys in episode_batches(es, batch, cfg["run"]["seed"]):
        out, _ = rollout_sweep(world, specs, agent, params, keys, parts=cfg["eval"]["parts"] or None)
        parts.append({k: v[:, :n_real] for k, v in _to_tree(out).items()})
        if bar is not None:
            bar.update(n_real * K)
    tree = {"out": {k: np.concatenate([p[k] for p in parts], axis=1) for k in parts[0]}, "costs": costs}
    ckpt.save(name, tree)
    return tree


# ---------------------------------------------------------------------------
# the sweep
# ---------------------------------------------------------------------------


def run_sweep(cfg: dict, studies: list[str], out: Path, *, resume: bool = False, force: bool = False,
              quiet: bool = False) -> dict:
    """Run ``studies`` with configuration ``cfg`` (see :func:`ignjax.config.resolve`) into ``out``.

    Returns a dict of every study's results (also written to ``out``).
    """
    from tqdm.auto import tqdm

    from ignjax.evaluate.runner import make_world
    from ignjax.sweep.report import write_outputs

    out = Path(out)
    if cfg["derive-costs"]["annotations"] and not Path(cfg["derive-costs"]["annotations"]).is_file():
        raise InputError(cfg["derive-costs"]["annotations"], "derive-costs.annotations", "file not found")
    prepare_folder(out, cfg, studies, resume, force)
    needs_rollouts = any(s in studies for s in ("eval", "costs", "difficulty", "analysis"))
    results: dict = {"config": cfg, "studies": studies}
    t0 = time.perf_counter()
    if needs_rollouts:
        path = benchmark_path(cfg, Path(cfg["run"]["out"]))
        es = load_episodes(cfg, path)
        print(f"benchmark {path} ({len(es)} episodes) ready in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        world = make_world(es)
        agents = list(dict.fromkeys(cfg["eval"]["agents"] + ([cfg["analysis"]["agent"]] if "analysis" in studies else [])))
        k_costs = len(in_loop_costs(cfg)[0]) if "costs" in studies else 0
        total = len(es) * (len(agents) + k_costs)
        ckpt = Checkpoints(out / "checkpoints")
        with tqdm(total=total, desc="rollouts", unit="ep", file=sys.stderr, disable=quiet, dynamic_ncols=True) as bar:
            rollouts = {}
            for a in agents:
                bar.set_postfix_str(a)
                rollouts[a] = run_eval_stage(es, world, a, cfg, ckpt, bar)
            if "costs" in studies:
                bar.set_postfix_str(f"{cfg['costs']['agent']} x {k_costs} cost vectors")
                results["in_loop"] = run_costs_stage(es, world, cfg, ckpt, bar)
        print(f"rollouts done in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        results["episodes"] = es
        results["rollouts"] = rollouts
    write_outputs(results, out)
    return results


if __name__ == "__main__":
    sys.exit(main())
