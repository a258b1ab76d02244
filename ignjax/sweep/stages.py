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
from ignjax.config import SweepConfig, digest, fingerprint
from ignjax.devices.parts import PartStore
from ignjax.devices.processes import SINGLE, ProcessGroup
from ignjax.episodes.construct import BuildConfig, build_benchmark
from ignjax.episodes.dataset import load_benchmark
from ignjax.episodes.schema import construction_path, read_episodes, write_records
from ignjax.errors import ConfigError, InputError
from ignjax.evaluate.runner import agent_batches, batch_count, episode_batches, make_world
from ignjax.scenes.io.sources import scene_sources
from ignjax.sim.rollout import batch_parts, rollout_sweep
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


def _batch_sizes(n: int, batch: int, select) -> int:
    """Episodes in the chunks ``select`` of ``n`` episodes cut into ``batch``."""
    batch = max(1, min(int(batch), n))
    return sum(min(batch, n - i * batch) for i in select)


def eval_stage_parts(es, world, agent_name: str, cfg: SweepConfig, store: PartStore, group: ProcessGroup = SINGLE,
                     bar=None) -> int:
    """This process's share of one agent's rollouts, as part files (:mod:`ignjax.devices.parts`).

    Returns:
        Episodes rolled out here (for a progress display).
    """
    name = f"eval/{agent_name}"
    # a cost-aware agent plans with the costs it is charged (eval.costs)
    params = cfg.agents.make(agent_name, costs=cfg.eval.costs)
    n = len(es)

    def compute(select):
        def prog(chunks):
            for c in chunks:
                yield c
                if bar is not None:
                    bar.update(min(cfg.eval.batch, n - c))

        for i, out, traj in agent_batches(es, agent_name, params=params, batch=cfg.eval.batch, seed=cfg.run.seed,
                                          world=world, progress=prog, parts=cfg.eval.parts or None, select=select):
            yield i, {"out": _to_tree(out), "traj": _to_tree(traj)}

    store.run_share(name, batch_count(n, cfg.eval.batch), group, compute)
    return _batch_sizes(n, cfg.eval.batch, group.share(batch_count(n, cfg.eval.batch)))


def merge_stage(name: str, n_batches: int, ckpt: Checkpoints, store: PartStore, axes=None, extra=None) -> dict:
    """A stage's result from its parts (process 0), checkpointed; the parts are then deleted."""
    if ckpt.has(name):
        return ckpt.load(name)
    tree = {**store.gather(name, n_batches, axes), **(extra or {})}
    ckpt.save(name, tree)
    store.remove(name)
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


def _costs_setup(es, cfg: SweepConfig):
    costs, _ = in_loop_costs(cfg)
    agent = get_agent(cfg.costs.agent)
    if not plans_with_costs(agent):
        raise ConfigError(None, "costs.agent", f"{agent.name!r} has no cost parameters to sweep")
    K = len(costs)
    batch = max(1, cfg.eval.batch // max(1, K // 4))
    return costs, agent, batch


def costs_stage_parts(es, world, cfg: SweepConfig, store: PartStore, group: ProcessGroup = SINGLE, bar=None) -> int:
    """This process's share of the cost-aware agent under K charged cost vectors x all episodes (vmapped over K):
    every cost vector of its chunks of episodes, so that each chunk is the same program as in one process."""
    costs, agent, batch = _costs_setup(es, cfg)
    base = cfg.agents.make(agent.name)
    K = len(costs)
    params = jax.tree.map(lambda x: jnp.broadcast_to(x, (K,) + jnp.shape(x)), base)
    # each setting plans with the cost vector it is charged
    params = dataclasses.replace(params, costs=jnp.asarray(costs, jnp.float32))

    def compute(select):
        for i, (n_real, specs, keys) in zip(select, episode_batches(es, batch, cfg.run.seed, select=select)):
            out, _ = rollout_sweep(world, specs, agent, params, keys, parts=cfg.eval.parts or None)
            yield i, {"out": {k: v[:, :n_real] for k, v in _to_tree(out).items()}}
            if bar is not None:
                bar.update(n_real * K)

    n = batch_count(len(es), batch)
    store.run_share("costs/in_loop", n, group, compute)
    return _batch_sizes(len(es), batch, group.share(n)) * K


# ---------------------------------------------------------------------------
# the sweep
# ---------------------------------------------------------------------------


def run_sweep(cfg: SweepConfig, studies: list[str], out: Path, *, resume: bool = False, force: bool = False,
              quiet: bool = False, group: ProcessGroup = SINGLE) -> dict:
    """Run ``studies`` with configuration ``cfg`` (see :func:`ignjax.config.resolve`) into ``out``.

    With several processes (``group``, :mod:`ignjax.devices.processes`),
    every process calls this with the same arguments: process 0 prepares
    the run folder, each process rolls out its share of every stage's
    batches (the ``i``-th contiguous block; a sweep's K cost vectors stay
    together, so every batch is the same program as in one process) into
    ``out/parts/``, and process 0 merges them, checkpoints each stage and
    writes the report; the MLLM agents' stages run in process 0 (the
    command line refuses them with several processes).

    Returns a dict of every study's results (also written to ``out``; on
    processes other than 0, an empty dict).
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
    needs_rollouts = any(s in studies for s in ("eval", "costs", "difficulty", "analysis"))
    agents = list(dict.fromkeys(list(cfg.eval.agents) + ([cfg.analysis.agent] if "analysis" in studies else [])))
    if needs_rollouts:
        try:  # this process's devices (before any work)
            batch_parts(None, cfg.eval.parts or None)
        except ConfigError as e:
            raise ConfigError(None, "eval.parts", e.reason) from None
    store = PartStore(out / "parts")
    fp = fingerprint(cfg, studies)
    t0 = time.perf_counter()
    if group.main:
        prepare_folder(out, cfg, studies, resume, force)
        if needs_rollouts:
            benchmark_path(cfg, Path(cfg.run.out))  # built once, by process 0
            kept = store.prepare(fp, resume=True)  # prepare_folder has checked that the folder holds this run
            if kept and resume:
                print(f"resuming: {kept} finished batches in {store.root}", file=sys.stderr)
    group.agree(fp, "--config/--set/--study")
    results: dict = {"config": cfg, "studies": studies}
    if needs_rollouts:
        path = benchmark_path(cfg, Path(cfg.run.out))
        es = load_episodes(cfg, path)
        if group.main:
            print(f"benchmark {path} ({len(es)} episodes) ready in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        world = make_world(es, cfg.sim)
        ckpt = Checkpoints(out / "checkpoints")
        jax_agents = [a for a in agents if a not in LLM_AGENTS]
        share = group.share
        k_costs = len(in_loop_costs(cfg)[0]) if "costs" in studies else 0
        costs_batch = max(1, cfg.eval.batch // max(1, k_costs // 4))
        total = (sum(0 if ckpt.has(f"eval/{a}") else _batch_sizes(len(es), cfg.eval.batch,
                                                                  share(batch_count(len(es), cfg.eval.batch)))
                     for a in jax_agents)
                 + (_batch_sizes(len(es), costs_batch, share(batch_count(len(es), costs_batch))) * k_costs
                    if k_costs and not ckpt.has("costs/in_loop") else 0))
        with tqdm(total=total, desc="rollouts", unit="ep", file=sys.stderr, disable=quiet or not group.main,
                  dynamic_ncols=True) as bar:
            for a in jax_agents:
                if not ckpt.has(f"eval/{a}"):
                    bar.set_postfix_str(a)
                    eval_stage_parts(es, world, a, cfg, store, group, bar)
            if k_costs and not ckpt.has("costs/in_loop"):
                bar.set_postfix_str(f"{cfg.costs.agent} x {k_costs} cost vectors")
                costs_stage_parts(es, world, cfg, store, group, bar)
        group.barrier("parts")
        if group.main:
            rollouts = {}
            for a in agents:
                rollouts[a] = (run_llm_stage(es, a, cfg, out, None, quiet) if a in LLM_AGENTS
                               else merge_stage(f"eval/{a}", batch_count(len(es), cfg.eval.batch), ckpt, store))
            if k_costs:
                costs = in_loop_costs(cfg)[0]
                results["in_loop"] = merge_stage("costs/in_loop", batch_count(len(es), costs_batch), ckpt, store,
                                                 {"out": 1}, {"costs": costs})
            print(f"rollouts done in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
            results["episodes"] = es
            results["rollouts"] = rollouts
    if group.main:
        write_outputs(results, out)
        store.remove()
    group.barrier("written")
    return results if group.main else {}


__all__ = ["REPO_SCENES", "SHIPPED_BENCHMARK", "benchmark_path", "costs_stage_parts", "eval_stage_parts",
           "load_episodes", "merge_stage", "run_llm_stage", "run_sweep"]
