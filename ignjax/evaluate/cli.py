"""``python -m ignjax.evaluate``: run agents on an episode file, write outcomes and metrics.

::

    python -m ignjax.evaluate --episodes bench/e.jsonl.gz --agent eig [--agent naive_asker ...]
                              [--out runs/eval] [--batch 256] [--seed 0]

Writes ``OUT/outcomes.parquet`` and ``OUT/outcomes.csv`` (one row per agent
and episode; see :mod:`ignjax.evaluate.outcomes`), ``OUT/metrics.csv`` (every metric per
agent, overall and per difficulty) and prints the paper's Table-1 columns.
The metrics can be recomputed from either outcome file alone
(``ignjax.evaluate.outcomes.metric_rows(read_outcomes(path))``).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ignjax.arrays import parse_floats
from ignjax.errors import ConfigError, IgnjaxError
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
    p.add_argument("--no-require-stop", dest="require_stop", action="store_false",
                   help="count an episode as a success when it ends close enough, even without STOP")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    return p


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
    from ignjax.episodes.dataset import load_benchmark
    from ignjax.evaluate.runner import make_world, run_agent
    from ignjax.evaluate.outcomes import metric_rows, outcome_rows, write_metric_table, write_outcomes

    agents = [get_agent(a) for a in args.agent]
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
    world = make_world(es)
    print(f"loaded {len(es)} episodes in {len(es.bank.scene_ids)} scenes ({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
    rows = []
    for agent in agents:
        t1 = time.perf_counter()
        bar = (lambda it, name=agent.name: tqdm(it, desc=name, unit="batch", file=sys.stderr, disable=args.quiet, dynamic_ncols=True))
        out, _ = run_agent(es, agent, batch=args.batch, seed=args.seed, progress=bar, world=world,
                           parts=args.parts or None)
        rows += outcome_rows(agent.name, es.records, out)
        print(f"{agent.name}: {len(es)} episodes in {time.perf_counter() - t1:.1f} s", file=sys.stderr)
    out_dir = Path(args.out)
    p_parquet, p_csv = write_outcomes(rows, out_dir)
    metrics = metric_rows(rows, thresholds, costs, args.require_stop)
    write_metric_table(metrics, out_dir / "metrics.csv")
    if all(t in thresholds for t in SUCCESS_THRESHOLDS):
        print(M.table1(metrics, "text"))
    print(f"wrote {p_parquet}, {p_csv} and {out_dir / 'metrics.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
