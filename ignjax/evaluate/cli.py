"""``python -m ignjax.evaluate``: run agents on an episode file, write outcomes and metrics.

::

    python -m ignjax.evaluate --agent eig [--agent naive_asker ...] [--episodes bench/e.jsonl.gz]
                              [--out runs/eval] [--batch 256] [--seed 0]

Without ``--episodes`` it runs on the shipped benchmark (package data,
:mod:`ignjax.data.shipped`).

Writes ``OUT/outcomes.parquet`` and ``OUT/outcomes.csv`` (one row per agent
and episode; see :mod:`ignjax.evaluate.outcomes`), ``OUT/metrics.csv`` (every metric per
agent, overall and per difficulty), ``OUT/trajectories.npz`` (every agent's
per-step trajectories, which ``python -m ignjax.view OUT`` replays; a few kB
per episode and agent, so always written), ``OUT/run.json`` (every setting
used: the simulator's, each agent's parameters, costs, thresholds, success
rule, seed; ``image_size``: pixels per side of the views the MLLM agents were
shown, ``views.size``, by default :data:`ignjax.sim.views.config.DEFAULT_SIZE`,
null when no agent rendered) and prints the paper's Table-1 columns.

With an MLLM agent, every ``--llm-endpoint`` is asked for its models
(:func:`ignjax.agents.llm.models.check_served`) before any scene is loaded:
an endpoint that does not answer within ``llm.timeout_s``, or a
``--llm-model`` it does not serve, is an error (exit status 2) naming the
endpoint, or the model and the ones served. ``--llm-replay`` and
``--dry-run`` ask nothing.

Exit status: 0; 2 on an error (settings, input files, the model server's
check), with nothing written; 3
(:data:`ignjax.evaluate.recovery.MODEL_FAILURE_EXIT`) when an MLLM agent's
episode ended by a model failure (its requests kept failing): every output
is written, and a line on stderr says how many episodes of which agent
ended so. Running the same command again runs those episodes again, the
replies they got coming from the reply cache; the episodes that ended
normally are kept (``OUT/llm/<agent>.progress.jsonl``,
:mod:`ignjax.evaluate.recovery`).

``--set sim.<key>=<value>`` sets any :class:`~ignjax.sim.types.SimConfig`
field and ``--set agents.<name>.<key>=<value>`` any agent parameter (the keys
of the sweep's ``[sim]`` and ``[agents.<name>]`` tables). A cost-aware agent
plans with the costs it is charged (``--costs``). ``--agent learned`` plays a
policy trained by ``python -m ignjax.rl.train``: ``--set
agents.learned.checkpoint=PATH`` (a checkpoint folder, a run folder or an
exported policy; default the shipped one), read and checked with the other
settings, before any episode; ``run.json`` records its path and the SHA-256
of its weights.
The metrics can be recomputed from either outcome file alone
(``ignjax.evaluate.outcomes.metric_rows(read_outcomes(path))``).

Several processes (``--processes N`` on this machine; ``--coordinator``,
``--num-processes``, ``--process-id`` or ``--cluster`` for one process per
host, :mod:`ignjax.devices.processes`) split the JAX-native agents'
batches: process i runs the i-th contiguous block of each agent's batches
of ``--batch`` episodes and writes each finished batch to ``OUT/parts/``;
process 0 merges them in episode order and writes the outputs once, the
same bytes as one process.

A benchmark of many scenes (the paper's 262 houses) runs a bucket of scenes
at a time: the scenes are grouped by size into banks of at most
``--bank-mb`` MiB each (:func:`ignjax.evaluate.runner.plan_run`), and each
bucket's bank, goal fields and world are built, run and dropped before the
next, so memory stays at one bucket's whatever the benchmark's size. Each
bucket is cut into its own batches; an episode's key is its position in the
file as in a one-bank run, and the outputs are written in episode order.
The MLLM agents run on one bank (an error names the bucket count otherwise). ``--resume`` reuses the parts an interrupted run
with the same settings wrote (with any number of processes); ``OUT/parts/``
is deleted when the outputs are written.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

from ignjax.arrays import parse_assignment, parse_floats
from ignjax.cache import add_cache_arguments, apply_cache_arguments, prefetch_command_programs
from ignjax.devices import processes as PR
from ignjax import __version__
from ignjax.data.shipped import shipped_episodes
from ignjax.errors import ConfigError, IgnjaxError
from ignjax.fileio import atomic_write
from ignjax.protocol import LOCKED_COSTS, SUCCESS_THRESHOLDS


def build_parser() -> argparse.ArgumentParser:
    # imported on use, so that --help and the other commands answer at once
    from ignjax.agents import registry
    from ignjax.agents.llm.catalog import LLM_AGENTS

    agents = registry()
    p = argparse.ArgumentParser(prog="python -m ignjax.evaluate", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog="agents:\n" + "\n".join(f"  {a.name:14s} {a.description}" for a in agents.values())
                                + "".join(f"\n  {n:14s} {c.description}" for n, c in LLM_AGENTS.items()))
    p.add_argument("--episodes", help="episode file (.jsonl or .jsonl.gz) from `python -m ignjax.build episodes` "
                                      "(default: the shipped benchmark, 500 episodes in 12 houses)")
    p.add_argument("--agent", action="append", required=True, help="agent name; repeat for several agents")
    p.add_argument("--out", default="runs/eval", help="output folder (default runs/eval)")
    p.add_argument("--batch", type=int, default=256, help="episodes per compiled batch (default 256)")
    p.add_argument("--parts", type=int, default=0,
                   help="devices each batch is sharded over (default 0: all; on a CPU one device per core, "
                        "IGNJAX_CPU_DEVICES=N to change)")
    p.add_argument("--seed", type=int, default=0, help="seed of the agents' randomness (default 0)")
    p.add_argument("--scenes-root", help="where to look for scene files the episode file names, if not next to it")
    p.add_argument("--thresholds", default=",".join(f"{t:g}" for t in SUCCESS_THRESHOLDS),
                   help="success thresholds in metres (default %(default)s)")
    p.add_argument("--costs", default=",".join(f"{c:.3f}" for c in LOCKED_COSTS),
                   help="per-type question costs for WSR (default: the locked costs %(default)s)")
    p.add_argument("--require-stop", action=argparse.BooleanOptionalAction, default=False,
                   help="success also requires an explicit STOP (Habitat's convention); default: the paper's rule, "
                        "final distance <= tau however the episode ended")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="sim.<key>=<value> (a simulator setting) or agents.<name>.<key>=<value> (an agent parameter); "
                        "values in TOML syntax; repeatable")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.add_argument("--limit", type=int, default=0, help="only the first N episodes of the file, for every agent")
    p.add_argument("--bank-mb", type=float, default=1024,
                   help="the most one bank of scenes (its tables, probe maps and goal fields; one copy per device) "
                        "may take, in MiB (default 1024). A benchmark whose scenes do not fit runs in buckets of "
                        "scenes of similar size, one at a time; the outputs are the same bytes in episode order")
    p.add_argument("--resume", action="store_true",
                   help="reuse the batches an interrupted run with the same settings left in OUT/parts")
    PR.add_arguments(p)
    add_cache_arguments(p)
    g = p.add_argument_group("MLLM agents (" + ", ".join(sorted(LLM_AGENTS)) + "); settings also as --set llm.<key>=<value>"
                             " and --set views.<key>=<value>")
    g.add_argument("--llm-endpoint", action="append", default=[], metavar="URL",
                   help="OpenAI-compatible base URL, e.g. http://127.0.0.1:8000/v1; repeat for several servers")
    g.add_argument("--llm-model", help="the served model's name (checked against each endpoint's GET /models before "
                                       "any scene is loaded)")
    g.add_argument("--llm-key-env", default=None,
                   help="environment variable holding the API key (default OPENAI_API_KEY; unset: no key sent)")
    g.add_argument("--llm-cache", default=None, help="response cache folder (default OUT/llm_cache)")
    g.add_argument("--llm-replay", action="store_true", help="answer from the cache only; a miss is an error naming "
                                                             "the request's hash")
    g.add_argument("--llm-paraphrase", action="store_true",
                   help="have the model reword each oracle answer before the agent reads it (a rewording that breaks "
                        "the answer's rules is dropped for the template); same as --set llm.paraphrase=true")
    g.add_argument("--llm-naive-unbudgeted", action="store_true",
                   help="the -naive agents run with no question budget (the reading of the paper's naive rows, "
                        "docs/protocol.md, 'Reading the paper's tables'); same as --set llm.naive_unbudgeted=true")
    g.add_argument("--llm-concurrency", type=int, default=None, help="requests in flight per endpoint (default 16)")
    g.add_argument("--llm-batch", type=int, default=64, help="episodes in flight at once (default 64; keep it at least twice "
                   "llm.concurrency x endpoints so every server slot has a request queued)")
    g.add_argument("--dry-run", action="store_true",
                   help="print what the MLLM agents would send (requests, images, estimated tokens and cost) and exit "
                        "without sending anything or loading scenes")
    g.add_argument("--save-images", type=int, default=0, metavar="N",
                   help="write the images of the first N episodes (Planner panels, Grounder views) to OUT/images "
                        "(for python -m ignjax.view)")
    return p


def parse_settings(items: list[str], agent_names: list[str], extra: tuple[str, ...] = ()):
    """``--set`` items -> (SimConfig, agent name -> parameter values[, section -> values
    for each section named in ``extra``, e.g. ``("llm", "views")``]).

    Raises:
        ConfigError: a section other than ``sim`` / ``agents.<name>`` / ``extra``, an
            unknown key, or a bad value (naming ``--set`` and the key).
    """
    from ignjax.agents import get_agent
    from ignjax.agents.params import check_param_value
    from ignjax.sim.types import SimConfig

    sim: dict = {}
    agents: dict[str, dict] = {}
    sections: dict[str, dict] = {k: {} for k in extra}
    for item in items:
        name, value = parse_assignment(item, "--set")
        section, key = name.rsplit(".", 1)
        if section == "sim":
            sim[key] = value
        elif section in sections:
            sections[section][key] = value
        elif section.startswith("agents."):
            agent = get_agent(section.split(".", 1)[1])
            if agent.name not in agent_names:
                raise ConfigError(None, "--set", f"{name}: agent {agent.name!r} is not evaluated (--agent)")
            agents.setdefault(agent.name, {})[key] = check_param_value(agent, key, value, "--set")
        else:
            allowed = ", ".join(["sim.<key>", "agents.<name>.<key>"] + [f"{k}.<key>" for k in extra])
            raise ConfigError(None, "--set", f"{name}: python -m ignjax.evaluate takes {allowed} "
                                             f"(the other sections are the sweep's)")
    try:
        cfg = SimConfig.from_values(sim)
    except ConfigError as e:
        raise ConfigError("--set", e.where, e.reason) from None
    return (cfg, agents, sections) if extra else (cfg, agents)


def llm_settings(args, sections: dict, out_dir: Path):
    """The :class:`~ignjax.agents.llm.config.LLMConfig` and
    :class:`~ignjax.sim.views.ViewConfig` of the MLLM agents from the
    ``--llm-*`` flags and the ``--set llm.*`` / ``views.*`` items."""
    from ignjax.agents.llm.config import LLMConfig
    from ignjax.sim.views import ViewConfig

    d = dict(sections.get("llm", {}))
    if args.llm_endpoint:
        d["endpoints"] = list(args.llm_endpoint)
    if args.llm_model:
        d["model"] = args.llm_model
    if args.llm_key_env is not None:
        d["api_key_env"] = args.llm_key_env
    if args.llm_concurrency is not None:
        d["concurrency"] = args.llm_concurrency
    if args.llm_paraphrase:
        d["paraphrase"] = True
    if args.llm_naive_unbudgeted:
        d["naive_unbudgeted"] = True
    if args.llm_replay:
        d["replay"] = True
    d.setdefault("cache_dir", str(args.llm_cache or out_dir / "llm_cache"))
    for need, flag in (("endpoints", "--llm-endpoint"), ("model", "--llm-model")):
        if need not in d:
            raise ConfigError(None, flag, "an MLLM agent needs the model server's base URL (--llm-endpoint) and the "
                                          "served model's name (--llm-model)")
    llm = LLMConfig.from_dict(d, where="--llm-*/--set llm")
    v = dict(sections.get("views", {}))  # the size: ViewConfig's default, DEFAULT_SIZE, unless views.size
    try:
        views = ViewConfig(**v)
    except TypeError as e:
        raise ConfigError("--set", "views", str(e)) from None
    return llm, views


def _dry_run(args, agents, llm_agents, sim, llm, views, costs) -> int:
    """``--dry-run``: the upper bounds of :func:`ignjax.evaluate.dryrun.dry_run` per MLLM agent, as JSON lines."""
    from ignjax.agents.llm.messages import price
    from ignjax.episodes.schema import read_episodes
    from ignjax.evaluate.dryrun import dry_run

    n = len(read_episodes(args.episodes))
    n = min(n, args.limit) if args.limit else n
    for agent in agents:
        if agent not in llm_agents:
            print(json.dumps({"agent": agent.name, "requests": 0, "note": "JAX-native: no model calls"}))
            continue
        est = dry_run(agent, n, sim=sim, views=views, llm=llm, costs=costs)
        est["cost_usd_at_most"] = price(est["prompt_tokens"], est["completion_tokens_at_most"], llm.prices)
        print(json.dumps(est))
    return 0


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(argv)
    try:
        apply_cache_arguments(args)
        popts = PR.process_options(args)
        if popts.launch:  # every setting checked once, here, before any process starts
            from ignjax.devices.launch import launch

            check_settings(args, popts)
            return launch("ignjax.evaluate", argv, popts.launch)
        # JAX's runtime joins before the settings are read (reading them may run JAX code)
        group = PR.start(popts)
        prefetch_command_programs("evaluate", args)
        return run(args, check_settings(args, popts), popts, group)
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


def check_settings(args, popts: PR.ProcessOptions = PR.ProcessOptions()) -> dict:
    """Every setting of ``args``, checked before any work (and before JAX starts).

    Raises:
        ConfigError: naming the flag and the reason.
    """
    from ignjax.agents import get_agent
    from ignjax.agents.llm.catalog import LLM_AGENTS, get_llm_agent
    from ignjax.agents.params import param_record

    agents = [get_llm_agent(a) if a in LLM_AGENTS else get_agent(a) for a in args.agent]
    sim, agent_values, sections = parse_settings(args.set, [a.name for a in agents], ("llm", "views"))
    out_dir = Path(args.out)
    llm_agents = [a for a in agents if a.name in LLM_AGENTS]
    llm, views = llm_settings(args, sections, out_dir) if llm_agents else (None, None)
    if llm_agents and (popts.launch or popts.distributed):
        raise ConfigError(None, "--processes", f"the MLLM agents ({', '.join(a.name for a in llm_agents)}) run in "
                                               "one process (their model server is what runs in parallel); "
                                               "evaluate them without --processes / --num-processes / --cluster")
    if args.limit < 0:
        raise ConfigError(None, "--limit", f"must be >= 0, got {args.limit}")
    thresholds = parse_floats(args.thresholds, 0, "--thresholds")
    costs = parse_floats(args.costs, 4, "--costs")
    if any(c < 0 for c in costs) or any(c != c for c in costs):
        raise ConfigError(None, "--costs", f"costs must be non-negative numbers, got {costs}")
    if args.batch < 1:
        raise ConfigError(None, "--batch", f"must be >= 1, got {args.batch}")
    if not args.bank_mb > 0:
        raise ConfigError(None, "--bank-mb", f"must be > 0, got {args.bank_mb}")
    if args.parts < 0:
        raise ConfigError(None, "--parts", f"must be >= 0, got {args.parts}")
    if args.episodes is None:
        args.episodes = str(shipped_episodes())
    elif not Path(args.episodes).is_file():
        raise ConfigError(None, "--episodes", f"{args.episodes}: file not found")
    for a in agents:  # an agent whose parameters are files (the learned agent's checkpoint): checked before any episode
        if getattr(a, "source", None) is not None:
            param_record(a, agent_values.get(a.name), sim)
    return {"agents": agents, "sim": sim, "agent_values": agent_values, "out_dir": out_dir, "llm_agents": llm_agents,
            "llm": llm, "views": views, "thresholds": thresholds, "costs": costs}


def _check_model_server(llm) -> None:
    """With MLLM agents (``llm`` set): every endpoint answers and serves ``--llm-model``, checked before any scene
    is loaded (:func:`ignjax.agents.llm.models.check_served`; nothing is asked under ``--llm-replay``).

    Raises:
        ConfigError: naming ``--llm-endpoint`` and the endpoint, or ``--llm-model``, the model and the ones served.
    """
    if llm is not None:
        from ignjax.agents.llm.models import check_served  # aiohttp

        check_served(llm, "--llm-model", "--llm-endpoint")


def _fingerprint(args, sim, used: dict) -> str:
    """What a JAX-native agent's outcomes depend on: a part of ``OUT/parts`` is reused only under the same."""
    import hashlib

    h = hashlib.sha256(Path(args.episodes).read_bytes())
    h.update(json.dumps({"scenes_root": args.scenes_root, "limit": args.limit, "batch": args.batch, "seed": args.seed,
                         "bank_mb": args.bank_mb,
                         "sim": sim.to_dict(), "agents": used}, sort_keys=True, default=str).encode())
    return h.hexdigest()


def _jax_agent_params(agents, llm_names, agent_values: dict, costs, sim) -> tuple[dict, dict]:
    """Each JAX agent's parameters (a cost-aware agent plans with the costs it is charged) and what ``run.json``
    records of them: every parameter's value, and of weights loaded from a checkpoint its path and digest."""
    from ignjax.agents.params import make_params, param_record

    params = {a.name: make_params(a, agent_values.get(a.name), costs=costs, config=sim) for a in agents
              if a.name not in llm_names}
    used = {a.name: param_record(a, agent_values.get(a.name), sim, params[a.name]) for a in agents if a.name in params}
    return params, used


def run(args, settings: dict | None = None, popts: PR.ProcessOptions = PR.ProcessOptions(),
        group: PR.ProcessGroup | None = None) -> int:
    # imported on use, so that --help and the other commands answer at once
    from tqdm.auto import tqdm

    from ignjax.devices.parts import PartStore
    from ignjax.episodes.dataset import open_benchmark
    from ignjax.evaluate.runner import bucket_batches, plan_run

    st = settings or check_settings(args, popts)
    agents, sim, out_dir, llm, views = st["agents"], st["sim"], st["out_dir"], st["llm"], st["views"]
    costs = st["costs"]
    llm_names = {a.name for a in st["llm_agents"]}
    if args.dry_run:
        return _dry_run(args, agents, st["llm_agents"], sim, llm, views, costs)
    _check_model_server(llm)
    group = PR.start(popts) if group is None else group
    from ignjax.sim.rollout import batch_parts

    try:  # this process's devices, known once JAX has started
        batch_parts(None, args.parts or None)
    except ConfigError as e:
        raise ConfigError(None, "--parts", e.reason) from None
    quiet = args.quiet or not group.main
    params, used = _jax_agent_params(agents, llm_names, st["agent_values"], costs, sim)
    store = PartStore(out_dir / "parts")
    if group.main:
        kept = store.prepare(_fingerprint(args, sim, used), args.resume)
        if args.resume:
            print(f"resuming: {kept} finished batches in {store.root}", file=sys.stderr)
    group.agree(_fingerprint(args, sim, used), "arguments")
    t0 = time.perf_counter()
    bs = open_benchmark(args.episodes, args.scenes_root, limit=args.limit or None)
    plan = plan_run(bs, args.batch, args.bank_mb)
    if len(plan.buckets) > 1 and llm_names:
        raise ConfigError(None, "--bank-mb", f"the {len(bs.host.scene_ids)} scenes need {len(plan.buckets)} buckets "
                                             f"at --bank-mb {args.bank_mb:g}; the MLLM agents run on one bank: raise "
                                             "--bank-mb, or evaluate fewer episodes (--limit)")
    if group.main:
        print(f"loaded {len(bs)} episodes in {len(bs.host.scene_ids)} scenes ({time.perf_counter() - t0:.1f} s)"
              + (f"; {len(plan.buckets)} buckets of scenes of at most {args.bank_mb:g} MiB, run one at a time"
                 if len(plan.buckets) > 1 else ""), file=sys.stderr)
    n_batches = len(plan.chunks)
    mine = list(group.share(n_batches))
    jobs, reused, bars = {}, {}, {}
    for agent in agents:
        if agent.name in llm_names:
            continue
        todo = [i for i in mine if not store.has(f"eval/{agent.name}", i)]
        jobs[agent.name] = (agent, params[agent.name], todo)
        reused[agent.name] = len(mine) - len(todo)
        bars[agent.name] = tqdm(total=len(todo), desc=agent.name, unit="batch", file=sys.stderr, disable=quiet,
                                dynamic_ncols=True)

    seconds = dict.fromkeys(jobs, 0.0)
    t1 = time.perf_counter()
    for name, i, out, traj in bucket_batches(bs, plan, jobs, seed=args.seed, config=sim, parts=args.parts or None):
        store.write(f"eval/{name}", i, {"out": _fields(out), "traj": _fields(traj)})
        bars[name].update(1)
        seconds[name] += time.perf_counter() - t1
        t1 = time.perf_counter()
    for name, (_, _, todo) in jobs.items():
        bars[name].close()
        if not quiet:
            print(f"{name}: {len(todo)} batches of {args.batch} episodes in {seconds[name]:.1f} s"
                  + (f" ({reused[name]} from an earlier run)" if reused[name] else "")
                  + (f" (process 0 of {group.count})" if group.count > 1 else ""), file=sys.stderr)
    group.barrier("parts")
    status = 0
    if group.main:
        from ignjax.evaluate.recovery import report_model_failures

        failures = _write_outputs(args, st, bs, plan, store, used, llm_names)
        store.remove()
        status = report_model_failures(failures, "run the same command again")
    group.barrier("written")
    return status


def _image_size(st: dict) -> int | None:
    """Pixels per side of the views the MLLM agents were shown (``views.size``); None when no agent rendered."""
    rendered = [a for a in st["llm_agents"] if a.renders]  # a panel, or views for a Grounder or a captioner
    return st["views"].size if rendered else None


def _fields(obj) -> dict:
    return {f.name: np.asarray(getattr(obj, f.name)) for f in dataclasses.fields(obj)}


def _write_outputs(args, st: dict, bs, plan, store, used: dict, llm_names: set) -> dict[str, list[str]]:
    """Process 0: the JAX-native agents' outcomes from the parts, the MLLM agents' from the host loop, every file.
    Returns each MLLM agent's ``failure`` texts, one per episode ("" where it did not end by a model failure)."""
    from types import SimpleNamespace

    from ignjax.evaluate import metrics as M
    from ignjax.evaluate.accounting import run_line, write_transcripts
    from ignjax.evaluate.hostloop import run_llm_agent
    from ignjax.evaluate.outcomes import (TRAJECTORY_FILE, metric_rows, model_totals, outcome_rows, per_episode_text,
                                          write_metric_table, write_outcomes, write_trajectories)

    agents, sim, out_dir, llm, views = st["agents"], st["sim"], st["out_dir"], st["llm"], st["views"]
    thresholds, costs = st["thresholds"], st["costs"]
    rows = []
    trajectories = {}
    failures: dict[str, list[str]] = {}
    records = bs.records
    es = bs.episode_set(plan.buckets[0]) if llm_names else None  # one bucket: checked before the run
    for agent in agents:
        t1 = time.perf_counter()
        if agent.name in llm_names:
            res = run_llm_agent(es, agent, llm, sim=sim, views=views, batch=args.llm_batch, seed=args.seed, costs=costs,
                                out=out_dir, save_images=args.save_images, progress=not args.quiet)
            rows += outcome_rows(agent.name, records, res.outcomes, res.accounting, llm.prices)
            trajectories[agent.name] = res.trajectories
            write_transcripts(out_dir, agent.name, res.transcripts)
            used[agent.name] = {"options": {k: v for k, v in vars(agent).items()}, "llm": llm.public_dict(),
                                "views": dataclasses.asdict(views)}
            failures[agent.name] = list(res.accounting["failure"])
            print(run_line(agent.name, len(es), time.perf_counter() - t1, res.stats), file=sys.stderr)
            continue
        tree = plan.to_run_order(store.gather(f"eval/{agent.name}", len(plan.chunks)))
        rows += outcome_rows(agent.name, records, SimpleNamespace(**tree["out"]))
        trajectories[agent.name] = tree["traj"]
    used = {a.name: used[a.name] for a in agents}  # in the order of --agent
    p_parquet, p_csv = write_outcomes(rows, out_dir)
    metrics = metric_rows(rows, thresholds, costs, args.require_stop)
    write_metric_table(metrics, out_dir / "metrics.csv")
    write_trajectories(out_dir, trajectories, records, episodes=args.episodes, scenes_root=args.scenes_root,
                       categories=bs.host.categories, thresholds=thresholds, costs=costs,
                       require_stop=args.require_stop, sim=sim.to_dict())
    run_record = {"ignjax_version": __version__, "episodes": str(args.episodes), "seed": args.seed, "batch": args.batch, "thresholds": list(thresholds),
                  "costs": list(costs), "require_stop": args.require_stop,
                  "success_rule": M.success_rule(args.require_stop), "sim": sim.to_dict(), "agents": used,
                  "limit": args.limit, "bank_mb": args.bank_mb, "image_size": _image_size(st),
                  "model_totals": model_totals(rows, llm.prices if llm else None)}
    atomic_write(out_dir / "run.json", json.dumps(run_record, indent=2) + "\n")
    print(M.success_rule(args.require_stop))
    if all(t in thresholds for t in SUCCESS_THRESHOLDS):
        print(M.table1(metrics, "text"))
    for name, totals in run_record["model_totals"].items():
        cost = f", estimated cost {totals['cost_usd']:.4f} USD" if totals["cost_usd"] is not None else ""
        rejected = (f", {totals['paraphrase_rejected']} paraphrases refused (template used)"
                    if llm is not None and llm.paraphrase else "")
        print(f"{name}: in the outcomes (this run and the episodes kept from earlier ones): "
              f"{totals['requests']} requests, {totals['cache_hits']} cache hits, "
              f"{totals['prompt_tokens']} + {totals['completion_tokens']} tokens, {totals['retries']} retries, "
              f"{totals['invalid_replies']} invalid replies ({totals['refused_asks']} asks with no question left), "
              f"{totals['failures']} episodes ended by model failure{rejected}{cost}")
        print(f"{name}: {per_episode_text(totals)}")
    print(f"wrote {p_parquet}, {p_csv}, {out_dir / 'metrics.csv'}, {out_dir / TRAJECTORY_FILE} and "
          f"{out_dir / 'run.json'} (view the episodes: python -m ignjax.view {out_dir})")
    return failures


if __name__ == "__main__":
    sys.exit(main())
