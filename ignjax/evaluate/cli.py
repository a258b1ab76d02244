"""``python -m ignjax.evaluate``: run agents on an episode file, write outcomes and metrics.

::

    python -m ignjax.evaluate --episodes bench/e.jsonl.gz --agent eig [--agent naive_asker ...]
                              [--out runs/eval] [--batch 256] [--seed 0]

Writes ``OUT/outcomes.parquet`` and ``OUT/outcomes.csv`` (one row per agent
and episode; see :mod:`ignjax.evaluate.outcomes`), ``OUT/metrics.csv`` (every metric per
agent, overall and per difficulty), ``OUT/trajectories.npz`` (every agent's
per-step trajectories, which ``python -m ignjax.view OUT`` replays; a few kB
per episode and agent, so always written), ``OUT/run.json`` (every setting
used: the simulator's, each agent's parameters, costs, thresholds, success
rule, seed) and prints the paper's Table-1 columns.

``--set sim.<key>=<value>`` sets any :class:`~ignjax.sim.types.SimConfig`
field and ``--set agents.<name>.<key>=<value>`` any agent parameter (the keys
of the sweep's ``[sim]`` and ``[agents.<name>]`` tables). A cost-aware agent
plans with the costs it is charged (``--costs``).
The metrics can be recomputed from either outcome file alone
(``ignjax.evaluate.outcomes.metric_rows(read_outcomes(path))``).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from ignjax.arrays import parse_assignment, parse_floats
from ignjax.errors import ConfigError, IgnjaxError
from ignjax.fileio import atomic_write
from ignjax.protocol import LOCKED_COSTS, SUCCESS_THRESHOLDS


def build_parser() -> argparse.ArgumentParser:
    # imported on use, so that --help and the other commands answer at once
    from ignjax.agents import registry

    agents = registry()
    p = argparse.ArgumentParser(prog="python -m ignjax.evaluate", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog="agents:\n" + "\n".join(f"  {a.name:14s} {a.description}" for a in agents.values()))
    p.add_argument("--episodes", required=True, help="episode file (.jsonl or .jsonl.gz) from `ignjax.build.cli episodes`")
    p.add_argument("--agent", action="append", required=True, help="agent name; repeat for several agents")
    p.add_argument("--out", default="runs/eval", help="output folder (default runs/eval)")
    p.add_argument("--batch", type=int, default=256, help="episodes per compiled batch (default 256)")
    p.add_argument("--parts", type=int, default=0,
                   help="concurrent pieces of each batch, one thread each (default 0: 2 on CPU, 1 on accelerators; "
                        "more on machines with more cores)")
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
    return p


def parse_settings(items: list[str], agent_names: list[str]):
    """``--set`` items -> (SimConfig, agent name -> parameter values).

    Raises:
        ConfigError: a section other than ``sim`` / ``agents.<name>``, an
            unknown key, or a bad value (naming ``--set`` and the key).
    """
    from ignjax.agents import get_agent
    from ignjax.agents.params import check_param_value
    from ignjax.sim.types import SimConfig

    sim: dict = {}
    agents: dict[str, dict] = {}
    for item in items:
        name, value = parse_assignment(item, "--set")
        section, key = name.rsplit(".", 1)
        if section == "sim":
            sim[key] = value
        elif section.startswith("agents."):
            agent = get_agent(section.split(".", 1)[1])
            if agent.name not in agent_names:
                raise ConfigError(None, "--set", f"{name}: agent {agent.name!r} is not evaluated (--agent)")
            agents.setdefault(agent.name, {})[key] = check_param_value(agent, key, value, "--set")
        else:
            raise ConfigError(None, "--set", f"{name}: python -m ignjax.evaluate takes sim.<key> and "
                                             f"agents.<name>.<key> (the other sections are the sweep's)")
    try:
        return SimConfig.from_values(sim), agents
    except ConfigError as e:
        raise ConfigError("--set", e.where, e.reason) from None


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return run(args)
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


def run(args) -> int:
    # imported on use, so that --help and the other commands answer at once
    from tqdm.auto import tqdm

    # imported on use, so that --help and the other commands answer at once
    from ignjax.evaluate import metrics as M
    from ignjax.agents import get_agent
    from ignjax.agents.params import make_params, param_values_of
    from ignjax.episodes.dataset import load_benchmark
    from ignjax.evaluate.runner import make_world, run_agent
    from ignjax.evaluate.outcomes import (TRAJECTORY_FILE, metric_rows, outcome_rows, write_metric_table,
                                          write_outcomes, write_trajectories)

    agents = [get_agent(a) for a in args.agent]
    sim, agent_values = parse_settings(args.set, [a.name for a in agents])
    thresholds = parse_floats(args.thresholds, 0, "--thresholds")
    costs = parse_floats(args.costs, 4, "--costs")
    if any(c < 0 for c in costs) or any(c != c for c in costs):
        raise ConfigError(None, "--costs", f"costs must be non-negative numbers, got {costs}")
    if args.batch < 1:
        raise ConfigError(None, "--batch", f"must be >= 1, got {args.batch}")
    if args.parts < 0:
        raise ConfigError(None, "--parts", f"must be >= 0, got {args.parts}")
    t0 = time.perf_counter()
    es = load_benchmark(args.episodes, args.scenes_root)
    world = make_world(es, sim)
    print(f"loaded {len(es)} episodes in {len(es.bank.scene_ids)} scenes ({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
    rows = []
    trajectories = {}
    used: dict[str, dict] = {}
    for agent in agents:
        t1 = time.perf_counter()
        bar = (lambda it, name=agent.name: tqdm(it, desc=name, unit="batch", file=sys.stderr, disable=args.quiet, dynamic_ncols=True))
        # a cost-aware agent plans with the costs it is charged
        params = make_params(agent, agent_values.get(agent.name), costs=costs)
        used[agent.name] = param_values_of(params)
        out, traj = run_agent(es, agent, params=params, batch=args.batch, seed=args.seed, progress=bar, world=world,
                              parts=args.parts or None)
        rows += outcome_rows(agent.name, es.records, out)
        trajectories[agent.name] = traj
        print(f"{agent.name}: {len(es)} episodes in {time.perf_counter() - t1:.1f} s", file=sys.stderr)
    out_dir = Path(args.out)
    p_parquet, p_csv = write_outcomes(rows, out_dir)
    metrics = metric_rows(rows, thresholds, costs, args.require_stop)
    write_metric_table(metrics, out_dir / "metrics.csv")
    write_trajectories(out_dir, trajectories, es.records, episodes=args.episodes, scenes_root=args.scenes_root,
                       categories=es.bank.categories, thresholds=thresholds, costs=costs,
                       require_stop=args.require_stop, sim=sim.to_dict())
    run_record = {"episodes": str(args.episodes), "seed": args.seed, "batch": args.batch, "thresholds": list(thresholds),
                  "costs": list(costs), "require_stop": args.require_stop,
                  "success_rule": M.success_rule(args.require_stop), "sim": sim.to_dict(), "agents": used}
    atomic_write(out_dir / "run.json", json.dumps(run_record, indent=2) + "\n")
    print(M.success_rule(args.require_stop))
    if all(t in thresholds for t in SUCCESS_THRESHOLDS):
        print(M.table1(metrics, "text"))
    print(f"wrote {p_parquet}, {p_csv}, {out_dir / 'metrics.csv'}, {out_dir / TRAJECTORY_FILE} and "
          f"{out_dir / 'run.json'} (view the episodes: python -m ignjax.view {out_dir})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
