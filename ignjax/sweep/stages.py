"""The sweep's work: the benchmark it runs on, the rollout stages
(evaluation per agent, the cost-aware agent in the loop), each checkpointed
as it finishes, and :func:`run_sweep`, which runs them and then writes the
report (:mod:`ignjax.sweep.report`).

An MLLM agent in ``eval.agents`` (``vlm``, ...) runs through the host loop
(:func:`ignjax.evaluate.hostloop.run_llm_agent`) against the ``[llm]``
server, with the ``[views]`` observations, ``eval.batch`` episodes in
flight, the charged ``eval.costs`` shown to it and ``run.seed``. Its
checkpoint is the host loop's own (``<run>/llm/<agent>.progress.jsonl``,
one line per finished episode), so ``--resume`` after a kill continues
episode by episode; replies are cached in ``llm.cache_dir`` (default
``<run>/llm_cache``), and transcripts go to ``<run>/transcripts/<agent>.jsonl``;
the question texts the agent wrote (:func:`ignjax.evaluate.hostloop.question_texts`)
stay with its rollout for the analysis study."""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
from tqdm.auto import tqdm

from ignjax.agents import get_agent
from ignjax.agents.llm.catalog import LLM_AGENTS, get_llm_agent
from ignjax.agents.params import plans_with_costs
from ignjax.config import SweepConfig, digest
from ignjax.episodes.construct import BuildConfig, build_benchmark
from ignjax.episodes.dataset import load_benchmark
from ignjax.episodes.schema import construction_path, read_episodes, write_records
from ignjax.errors import ConfigError, InputError
from ignjax.evaluate.runner import episode_batches, make_world, run_agent
from ignjax.scenes.io.sources import scene_sources
from ignjax.sim.rollout import rollout_sweep
from ignjax.sweep.checkpoints import Checkpoints, prepare_folder
from ignjax.sweep.report import in_loop_costs, write_outputs

REPO_SCENES = Path(__file__).resolve().parents[2] / "scenes"
SHIPPED_BENCHMARK = REPO_SCENES / "benchmark.jsonl.gz"


def _to_tree(obj) -> dict:
    return {f.name: np.asarray(getattr(obj, f.name)) for f in dataclasses.fields(obj)}


# ---------------------------------------------------------------------------
# benchmark
# ---------------------------------------------------------------------------


def benchmark_path(cfg: SweepConfig, out_root: Path, progress=None) -> Path:
    """The episode file of ``cfg.benchmark``: the given file, the shipped
    benchmark, or one built from ``benchmark.scenes`` into
    ``<out_root>/_benchmarks/<key>/`` (reused when already there)."""
    b = cfg.benchmark
    if b.episodes:
        p = Path(b.episodes)
        if not p.is_file():
            raise InputError(str(p), "benchmark.episodes", "episode file not found")
        return p
    default = not b.scenes and b.subset == 500 and b.seed == 0
    if default and SHIPPED_BENCHMARK.is_file():
        return SHIPPED_BENCHMARK
    scenes = [Path(b.scenes)] if b.scenes else [REPO_SCENES]
    for s in scenes:
        if not s.exists():
            raise InputError(str(s), "benchmark.scenes", "scene path not found")
    key = digest({"scenes": [str(s.resolve()) for s in scenes], "subset": b.subset, "seed": b.seed})
    path = out_root / "_benchmarks" / key / "episodes.jsonl.gz"
    if path.is_file():
        return path
    built = build_benchmark(scene_sources(scenes), BuildConfig(subset=b.subset, seed=b.seed), progress=progress)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_records(construction_path(path), built["subset_construction"])
    write_records(path, built["subset"])
    return path


def load_episodes(cfg: SweepConfig, path: Path):
    """The episode set at ``path``, cut to ``benchmark.limit`` episodes spread evenly over the file."""
    n = len(read_episodes(path))
    if n == 0:
        raise InputError(str(path), "episodes", "the episode file holds no episodes")
    limit = cfg.benchmark.limit
    if 0 < limit < n:
        # only the scenes the chosen episodes use are loaded
        return load_benchmark(path, indices=np.unique(np.linspace(0, n - 1, limit).round().astype(np.int64)))
    return load_benchmark(path)


# ---------------------------------------------------------------------------
# stages
# ---------------------------------------------------------------------------


def run_eval_stage(es, world, agent_name: str, cfg: SweepConfig, ckpt: Checkpoints, bar=None) -> dict:
    """Outcomes and trajectories of one agent (from the checkpoint when there)."""
    name = f"eval/{agent_name}"
    if ckpt.has(name):
        if bar is not None:
            bar.update(len(es))
        return ckpt.load(name)

    def prog(chunks):
        for c in chunks:
            yield c
            if bar is not None:
                bar.update(min(cfg.eval.batch, len(es) - c))

    # a cost-aware agent plans with the costs it is charged (eval.costs)
    params = cfg.agents.make(agent_name, costs=cfg.eval.costs)
    out, traj = run_agent(es, agent_name, params=params, batch=cfg.eval.batch, seed=cfg.run.seed, world=world,
                          progress=prog, parts=cfg.eval.parts or None)
    tree = {"out": _to_tree(out), "traj": _to_tree(traj)}
    ckpt.save(name, tree)
    return tree


def run_llm_stage(es, agent_name: str, cfg: SweepConfig, out: Path, bar=None, quiet: bool = False) -> dict:
    """Outcomes, trajectories and model-call accounting of one MLLM agent (module docstring)."""
    from ignjax.evaluate.hostloop import question_texts, run_llm_agent, write_transcripts  # aiohttp, renderers

    llm = cfg.llm
    if llm.cache_dir is None:
        llm = dataclasses.replace(llm, cache_dir=str(out / "llm_cache"))
    res = run_llm_agent(es, get_llm_agent(agent_name), llm, sim=cfg.sim, views=cfg.views, batch=cfg.eval.batch,
                        seed=cfg.run.seed, costs=cfg.eval.costs, out=out, progress=not quiet)
    write_transcripts(out, agent_name, res.transcripts)
    if bar is not None:
        bar.update(len(es))
    acc = {k: np.asarray(v) for k, v in res.accounting.items() if k != "failure"}
    return {"out": _to_tree(res.outcomes), "traj": _to_tree(res.trajectories),
            "accounting": {**acc, "failure": list(res.accounting["failure"])}, "stats": res.stats,
            "questions": question_texts(res.transcripts)}


def run_costs_stage(es, world, cfg: SweepConfig, ckpt: Checkpoints, bar=None) -> dict:
    """The cost-aware agent under K charged cost vectors x all episodes (vmapped over K)."""
    name = "costs/in_loop"
    costs, _ = in_loop_costs(cfg)
    if ckpt.has(name):
        if bar is not None:
            bar.update(len(es) * len(costs))
        return ckpt.load(name)
    agent = get_agent(cfg.costs.agent)
    if not plans_with_costs(agent):
        raise ConfigError(None, "costs.agent", f"{agent.name!r} has no cost parameters to sweep")
    base = cfg.agents.make(agent.name)
    K = len(costs)
    params = jax.tree.map(lambda x: jnp.broadcast_to(x, (K,) + jnp.shape(x)), base)
    # each setting plans with the cost vector it is charged
    params = dataclasses.replace(params, costs=jnp.asarray(costs, jnp.float32))
    batch = max(1, cfg.eval.batch // max(1, K // 4))
    parts = []
    for n_real, specs, keys in episode_batches(es, batch, cfg.run.seed):
        out, _ = rollout_sweep(world, specs, agent, params, keys, parts=cfg.eval.parts or None)
        parts.append({k: v[:, :n_real] for k, v in _to_tree(out).items()})
        if bar is not None:
            bar.update(n_real * K)
    tree = {"out": {k: np.concatenate([p[k] for p in parts], axis=1) for k in parts[0]}, "costs": costs}
    ckpt.save(name, tree)
    return tree


# ---------------------------------------------------------------------------
# the sweep
# ---------------------------------------------------------------------------


def run_sweep(cfg: SweepConfig, studies: list[str], out: Path, *, resume: bool = False, force: bool = False,
              quiet: bool = False) -> dict:
    """Run ``studies`` with configuration ``cfg`` (see :func:`ignjax.config.resolve`) into ``out``.

    Returns a dict of every study's results (also written to ``out``).
    """
    out = Path(out)
    if cfg.derive_costs.annotations and not Path(cfg.derive_costs.annotations).is_file():
        raise InputError(cfg.derive_costs.annotations, "derive-costs.annotations", "file not found")
    if "analysis" in studies and cfg.analysis.agent in LLM_AGENTS:  # (eval.agents is checked with the config)
        try:
            cfg.llm.check_usable()
        except ConfigError as e:
            raise ConfigError(None, e.where, f"{e.reason}: analysis.agent is the MLLM agent {cfg.analysis.agent!r}, "
                                             "which needs a model server (llm.endpoints, llm.model)") from None
    prepare_folder(out, cfg, studies, resume, force)
    needs_rollouts = any(s in studies for s in ("eval", "costs", "difficulty", "analysis"))
    results: dict = {"config": cfg, "studies": studies}
    t0 = time.perf_counter()
    if needs_rollouts:
        path = benchmark_path(cfg, Path(cfg.run.out))
        es = load_episodes(cfg, path)
        print(f"benchmark {path} ({len(es)} episodes) ready in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        world = make_world(es, cfg.sim)
        agents = list(dict.fromkeys(list(cfg.eval.agents) + ([cfg.analysis.agent] if "analysis" in studies else [])))
        k_costs = len(in_loop_costs(cfg)[0]) if "costs" in studies else 0
        total = len(es) * (len(agents) + k_costs)
        ckpt = Checkpoints(out / "checkpoints")
        with tqdm(total=total, desc="rollouts", unit="ep", file=sys.stderr, disable=quiet, dynamic_ncols=True) as bar:
            rollouts = {}
            for a in agents:
                bar.set_postfix_str(a)
                rollouts[a] = (run_llm_stage(es, a, cfg, out, bar, quiet) if a in LLM_AGENTS
                               else run_eval_stage(es, world, a, cfg, ckpt, bar))
            if "costs" in studies:
                bar.set_postfix_str(f"{cfg.costs.agent} x {k_costs} cost vectors")
                results["in_loop"] = run_costs_stage(es, world, cfg, ckpt, bar)
        print(f"rollouts done in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        results["episodes"] = es
        results["rollouts"] = rollouts
    write_outputs(results, out)
    return results


__all__ = ["REPO_SCENES", "SHIPPED_BENCHMARK", "benchmark_path", "load_episodes", "run_costs_stage",
           "run_eval_stage", "run_llm_stage", "run_sweep"]
