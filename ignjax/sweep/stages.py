"""The sweep's work: the benchmark it runs on, the rollout stages
(evaluation per agent, the cost-aware agent in the loop), each checkpointed
as it finishes, and :func:`run_sweep`, which runs them and then writes the
report (:mod:`ignjax.sweep.report`, :mod:`ignjax.sweep.sections`).

An MLLM agent in ``eval.agents`` (``vlm``, ...) runs through the host loop
(:func:`ignjax.evaluate.hostloop.run_llm_agent`) against the ``[llm]``
server, with the ``[views]`` observations, ``eval.batch`` episodes in
flight, the charged ``eval.costs`` shown to it and ``run.seed``. Its
checkpoint is the host loop's own (``<run>/llm/<agent>.progress.jsonl``,
one line per finished episode), so ``--resume`` after a kill continues
episode by episode, and runs again the episodes that ended by a model
failure (:mod:`ignjax.evaluate.recovery`; the command line then exits with
status 3, :func:`model_failures`). Before any work, every ``llm.endpoints`` URL is asked for
its models (:func:`ignjax.agents.llm.models.check_served`, not under
``llm.replay``): one that does not answer, or an ``llm.model`` it does not
serve, is an error naming it. Replies are cached in ``llm.cache_dir`` (default
``<run>/llm_cache``), and transcripts go to ``<run>/transcripts/<agent>.jsonl``;
the question texts the agent wrote (:func:`ignjax.evaluate.accounting.question_texts`)
stay with its rollout for the analysis study."""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from ignjax.agents import get_agent
from ignjax.agents.llm.catalog import LLM_AGENTS, get_llm_agent
from ignjax.agents.params import plans_with_costs
from ignjax.arrays import on_device, stack_copies
from ignjax.config import SweepConfig, digest, fingerprint
from ignjax.devices.parts import PartStore
from ignjax.devices.processes import SINGLE, ProcessGroup
from ignjax.episodes.construct import BuildConfig, build_benchmark
from ignjax.episodes.dataset import BenchmarkScenes, open_benchmark
from ignjax.episodes.schema import construction_path, read_episodes, write_records
from ignjax.data import shipped
from ignjax.errors import ConfigError, InputError
from ignjax.evaluate.runner import BucketPlan, agent_batches, batch_program, bucket_worlds, episode_batches, plan_run
from ignjax.scenes.io.sources import scene_sources
from ignjax.sim.rollout import batch_parts, rollout_sweep
from ignjax.sweep.checkpoints import Checkpoints, prepare_folder
from ignjax.sweep.report import in_loop_costs
from ignjax.sweep.sections import write_outputs



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
    if not b.scenes:
        episodes = shipped.shipped_episodes()  # checked against the recorded hashes
        if b.subset == shipped.SUBSET and b.seed == shipped.EPISODE_SEED:
            return episodes
    scenes = [Path(b.scenes)] if b.scenes else [shipped.FOLDER]
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


def load_episodes(cfg: SweepConfig, path: Path) -> BenchmarkScenes:
    """The episodes at ``path``, cut to ``benchmark.limit`` episodes spread
    evenly over the file, with their scenes compiled on the host
    (:func:`~ignjax.episodes.dataset.open_benchmark`; the stages build one
    bucket of scenes' tables at a time)."""
    n = len(read_episodes(path))
    if n == 0:
        raise InputError(str(path), "episodes", "the episode file holds no episodes")
    limit = cfg.benchmark.limit
    if 0 < limit < n:
        # only the scenes the chosen episodes use are loaded
        return open_benchmark(path, indices=np.unique(np.linspace(0, n - 1, limit).round().astype(np.int64)))
    return open_benchmark(path)


# ---------------------------------------------------------------------------
# stages
# ---------------------------------------------------------------------------


def merge_stage(name: str, n_batches: int, ckpt: Checkpoints, store: PartStore, axes=None, extra=None,
                order=None) -> dict:
    """A stage's result from its parts (process 0), checkpointed; the parts are then deleted.
    ``order``: optionally a function putting a gathered top-level entry (its key, its tree) into episode order."""
    if ckpt.has(name):
        return ckpt.load(name)
    tree = store.gather(name, n_batches, axes)
    if order is not None:
        tree = {k: order(k, v) for k, v in tree.items()}
    tree = {**tree, **(extra or {})}
    ckpt.save(name, tree)
    store.remove(name)
    return tree


def run_llm_stage(es, agent_name: str, cfg: SweepConfig, out: Path, bar=None, quiet: bool = False) -> dict:
    """Outcomes, trajectories and model-call accounting of one MLLM agent (module docstring)."""
    from ignjax.evaluate.accounting import question_texts, write_transcripts
    from ignjax.evaluate.hostloop import run_llm_agent  # aiohttp, renderers

    llm = cfg.llm
    if llm.cache_dir is None:
        llm = dataclasses.replace(llm, cache_dir=str(out / "llm_cache"))
    res = run_llm_agent(es, get_llm_agent(agent_name), llm, sim=cfg.sim, views=cfg.views, batch=cfg.eval.batch,
                        seed=cfg.run.seed, costs=cfg.eval.costs, out=out, progress=not quiet)
    write_transcripts(out, agent_name, res.transcripts)
    if not quiet:
        from ignjax.evaluate.accounting import run_line

        print(run_line(agent_name, len(es), res.stats["wall_s"], res.stats), file=sys.stderr)
    if bar is not None:
        bar.update(len(es))
    acc = {k: np.asarray(v) for k, v in res.accounting.items() if k != "failure"}
    return {"out": _to_tree(res.outcomes), "traj": _to_tree(res.trajectories),
            "accounting": {**acc, "failure": list(res.accounting["failure"])}, "stats": res.stats,
            "questions": question_texts(res.transcripts)}


def model_failures(results: dict) -> dict[str, list[str]]:
    """Each MLLM agent's ``failure`` texts in a :func:`run_sweep` result, one per episode ("" where the episode
    did not end by a model failure); {} when no MLLM agent ran."""
    return {a: [str(f) for f in r["accounting"]["failure"]] for a, r in results.get("rollouts", {}).items()
            if isinstance(r, dict) and "accounting" in r}


def _costs_setup(cfg: SweepConfig):
    costs, _ = in_loop_costs(cfg)
    agent = get_agent(cfg.costs.agent)
    if not plans_with_costs(agent):
        raise ConfigError(None, "costs.agent", f"{agent.name!r} has no cost parameters to sweep")
    K = len(costs)
    batch = max(1, cfg.eval.batch // max(1, K // 4))
    return costs, agent, batch


def _costs_params(cfg: SweepConfig, agent, costs):
    """The cost-aware agent's parameters, one row per charged cost vector (each setting plans with the vector it
    is charged)."""
    base = cfg.agents.make(agent.name, sim=cfg.sim)
    return dataclasses.replace(stack_copies(base, len(costs)), costs=on_device(costs, np.float32))


def _stage_programs(es, world, work: dict, plans: dict, cfg: SweepConfig, c_agent, c_params) -> list:
    """The rollout program of each stage with work in this bucket (for its first batch: every batch of a stage is
    the same program), so they compile side by side (:func:`ignjax.sim.rollout.compile_ahead`)."""
    calls, parts, seed = [], cfg.eval.parts or None, cfg.run.seed
    for stage, batches in work.items():
        if not batches:
            continue
        chunk, batch = batches[0][1], plans[stage].batch
        if stage == "costs/in_loop":
            calls.append(batch_program(es, world, c_agent, c_params, batch, seed, chunk, parts, sweep=True))
        else:
            agent = stage.split("/", 1)[1]
            calls.append(batch_program(es, world, agent, cfg.agents.make(agent, cfg.eval.costs, cfg.sim), batch, seed,
                                       chunk, parts))
    return calls


def rollout_stage_parts(bs: BenchmarkScenes, plans: dict, todo: dict, cfg: SweepConfig, store: PartStore):
    """This process's batches of the rollout stages, a bucket of scenes at a time
    (:func:`ignjax.evaluate.runner.bucket_worlds`), each written as a part file.

    Args:
        plans: stage -> :class:`~ignjax.evaluate.runner.BucketPlan`: ``eval/<agent>`` (``eval.batch``
            episodes a batch) and ``costs/in_loop`` (the cost-aware agent under all K cost vectors, vmapped,
            on smaller batches so each batch is the same program as in one process).
        todo: stage -> the batch indices to run.

    Yields:
        rows rolled out per finished batch (episodes x settings), for a progress display.
    """
    parts = cfg.eval.parts or None
    seed = cfg.run.seed
    c_agent = c_params = None
    if "costs/in_loop" in plans:
        costs, c_agent, _ = _costs_setup(cfg)
        c_params = _costs_params(cfg, c_agent, costs)
    for es, world, work in bucket_worlds(bs, plans, todo, cfg.sim,
                                         lambda es, world, work: _stage_programs(es, world, work, plans, cfg, c_agent,
                                                                                 c_params)):
        for stage, batches in work.items():
            if not batches:
                continue
            index = {c: i for i, c in batches}
            select = [c for _, c in batches]
            if stage == "costs/in_loop":
                for (n_real, specs, keys), c in zip(episode_batches(es, plans[stage].batch, seed, select=select),
                                                    select):
                    out, _ = rollout_sweep(world, specs, c_agent, c_params, keys, parts=parts)
                    store.write(stage, index[c], {"out": {k: v[:, :n_real] for k, v in _to_tree(out).items()}})
                    yield n_real * len(costs)
                continue
            agent = stage.split("/", 1)[1]
            # a cost-aware agent plans with the costs it is charged (eval.costs)
            params = cfg.agents.make(agent, cfg.eval.costs, cfg.sim)
            for c, out, traj in agent_batches(es, agent, params=params, batch=plans[stage].batch, seed=seed,
                                              world=world, parts=parts, select=select):
                store.write(stage, index[c], {"out": _to_tree(out), "traj": _to_tree(traj)})
                yield len(out.steps)


# ---------------------------------------------------------------------------
# the sweep
# ---------------------------------------------------------------------------


def check_model_server(cfg: SweepConfig, studies: list[str]) -> None:
    """Before any work: when ``studies`` roll out an MLLM agent (in ``eval.agents``, or ``analysis.agent``
    under the analysis study), the ``[llm]`` table names a server, and every endpoint answers and serves
    ``llm.model`` (:func:`ignjax.agents.llm.models.check_served`; nothing is asked under ``llm.replay``).

    Raises:
        ConfigError: naming the missing setting, the endpoint that did not answer, or the model and the ones served.
    """
    if "analysis" in studies and cfg.analysis.agent in LLM_AGENTS:  # (eval.agents is checked with the config)
        try:
            cfg.llm.check_usable()
        except ConfigError as e:
            raise ConfigError(None, e.where, f"{e.reason}: analysis.agent is the MLLM agent {cfg.analysis.agent!r}, "
                                             "which needs a model server (llm.endpoints, llm.model)") from None
    if not any(s in studies for s in ("eval", "costs", "difficulty", "analysis")):
        return  # nothing is rolled out
    agents = list(cfg.eval.agents) + ([cfg.analysis.agent] if "analysis" in studies else [])
    if any(a in LLM_AGENTS for a in agents):
        from ignjax.agents.llm.models import check_served  # aiohttp

        check_served(cfg.llm)


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
    check_model_server(cfg, studies)
    needs_rollouts = any(s in studies for s in ("eval", "costs", "difficulty", "analysis"))
    if needs_rollouts and not cfg.benchmark.episodes and not cfg.benchmark.scenes:
        shipped.shipped_episodes()  # a damaged default is one error before the run folder is touched
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
        bs = load_episodes(cfg, path)
        plan = plan_run(bs, cfg.eval.batch, cfg.eval.bank_mb)
        llm_agents = [a for a in agents if a in LLM_AGENTS]
        if llm_agents and len(plan.buckets) > 1:
            raise ConfigError(None, "eval.bank_mb",
                              f"the {bs.host.n_scenes} scenes need {len(plan.buckets)} buckets at eval.bank_mb = "
                              f"{cfg.eval.bank_mb:g}; the MLLM agents ({', '.join(llm_agents)}) run on one bank: "
                              "raise eval.bank_mb, or run fewer episodes (benchmark.limit)")
        if group.main:
            print(f"benchmark {shipped.describe(path)} ({len(bs)} episodes in {bs.host.n_scenes} scenes"
                  + (f", {len(plan.buckets)} buckets run one at a time" if len(plan.buckets) > 1 else "")
                  + f") ready in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        ckpt = Checkpoints(out / "checkpoints")
        plans = {f"eval/{a}": plan for a in agents if a not in LLM_AGENTS}
        k_costs = len(in_loop_costs(cfg)[0]) if "costs" in studies else 0
        if k_costs:
            plans["costs/in_loop"] = BucketPlan(plan.buckets, _costs_setup(cfg)[2])
        todo = {}
        rows = 0
        for stage, p in plans.items():
            if ckpt.has(stage):
                continue
            todo[stage] = [i for i in group.share(len(p.chunks)) if not store.has(stage, i)]
            chunks = p.chunks
            rows += sum(min(p.batch, len(p.buckets[chunks[i][0]]) - chunks[i][1] * p.batch) for i in todo[stage]) * (
                k_costs if stage == "costs/in_loop" else 1)
        with tqdm(total=rows, desc="rollouts", unit="ep", file=sys.stderr, disable=quiet or not group.main,
                  dynamic_ncols=True) as bar:
            for n_rows in rollout_stage_parts(bs, {k: plans[k] for k in todo}, todo, cfg, store):
                bar.update(n_rows)
        group.barrier("parts")
        if group.main:
            rollouts = {}
            for a in agents:
                rollouts[a] = (run_llm_stage(bs.episode_set(plan.buckets[0]), a, cfg, out, None, quiet)
                               if a in LLM_AGENTS else
                               merge_stage(f"eval/{a}", len(plan.chunks), ckpt, store,
                                           order=lambda _, tree: plan.to_run_order(tree)))
            if k_costs:
                costs = in_loop_costs(cfg)[0]
                results["in_loop"] = merge_stage("costs/in_loop", len(plans["costs/in_loop"].chunks), ckpt, store,
                                                 {"out": 1}, {"costs": costs},
                                                 order=lambda _, tree: plan.to_run_order(tree, axis=1))
            print(f"rollouts done in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
            results["episodes"] = bs.host_set()
            results["rollouts"] = rollouts
    if group.main:
        write_outputs(results, out)
        store.remove()
    group.barrier("written")
    return results if group.main else {}


__all__ = ["benchmark_path", "check_model_server", "load_episodes", "merge_stage",
           "model_failures", "rollout_stage_parts", "run_llm_stage", "run_sweep"]
