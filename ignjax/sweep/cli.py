"""Command line of ``python -m ignjax.sweep``: its options, the study
names ``--study`` accepts, and :func:`main`.

Exit status: 0; 2 on an error (configuration, folder, the model server's
check); 3 (:data:`ignjax.evaluate.recovery.MODEL_FAILURE_EXIT`) when an
MLLM agent's episode ended by a model failure: the report and every output
are written, a line on stderr says how many episodes of which agent ended
so, and the same command with ``--resume`` runs them again (the replies
they got come from the reply cache)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ignjax.cache import add_cache_arguments, apply_cache_arguments, prefetch_command_programs
from ignjax.devices import processes as PR
from ignjax.errors import ConfigError, IgnjaxError

STUDIES: tuple[str, ...] = ("eval", "costs", "difficulty", "derive-costs", "analysis")
"""The studies a sweep can run, in the order it runs them."""


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m ignjax.sweep", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Run ignjax's studies (batched evaluation, cost-weight sensitivity, difficulty-coefficient "
                    "ablation, cost derivation, interaction analyses) and write a report.",
        epilog="Configuration: defaults <- --quick <- --config FILE <- --set items. Sections and keys: see "
               "sweeps/default.toml. Examples:\n"
               "  python -m ignjax.sweep                       # everything, default sizes\n"
               "  python -m ignjax.sweep --study eval --quick --out /tmp/r\n"
               "  python -m ignjax.sweep --set costs.samples=1000000 --set eval.agents='[\"eig\",\"random\"]'\n"
               "Exit status: 0; 2 on an error; 3 when an MLLM agent's episode ended by a model failure (outputs "
               "written; --resume runs those episodes again).")
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
    PR.add_arguments(p)
    add_cache_arguments(p)
    return p


def parse_studies(items: list[str]) -> list[str]:
    """``--study`` items (repeatable, comma-separated, ``all``) -> study names in run order."""
    names = [s.strip() for item in items for s in item.split(",") if s.strip()]
    if not names or "all" in names:
        return list(STUDIES)
    for n in names:
        if n not in STUDIES:
            raise ConfigError(None, "--study", f"unknown study {n!r}; known: {', '.join(STUDIES)}, all")
    return [s for s in STUDIES if s in names]


def check_processes(cfg, studies: list[str]) -> None:
    """A sweep of several processes rolls out JAX-native agents only.

    Raises:
        ConfigError: an MLLM agent is among the agents rolled out (naming ``--processes``).
    """
    from ignjax.agents.llm.catalog import LLM_AGENTS

    agents = list(cfg.eval.agents) + ([cfg.analysis.agent] if "analysis" in studies else [])
    llm = [a for a in dict.fromkeys(agents) if a in LLM_AGENTS]
    if llm and any(s in studies for s in ("eval", "costs", "difficulty", "analysis")):
        raise ConfigError(None, "--processes", f"the MLLM agents ({', '.join(llm)}) run in one process (their model "
                                               "server is what runs in parallel); run this sweep without --processes "
                                               "/ --num-processes / --cluster")


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(argv)
    # Deferred so that `--help` and option errors answer without loading jax, scipy, orbax, the simulator and
    # the studies (measured on the 2-core dev machine: `--help` 0.15 s; 4.6 s with these two at the top).
    from ignjax.config import loaded_agents, resolve

    try:
        apply_cache_arguments(args)  # before anything compiles, the configuration's checks included
        popts = PR.process_options(args)
        studies = parse_studies(args.study)
        # JAX's runtime joins before the configuration is resolved (its checks run JAX code); a launcher checks it
        # once, before it starts any process
        group = PR.start(popts) if not popts.launch else PR.SINGLE
        cfg = resolve(args.config, args.sets, args.quick)
        loaded_agents(cfg, studies)  # a learned agent's checkpoint is read and checked before any work
        out = Path(args.out) if args.out else Path(cfg.run.out) / cfg.run.name
        if popts.launch or popts.distributed:
            check_processes(cfg, studies)
        if popts.launch:
            from ignjax.devices.launch import launch

            return launch("ignjax.sweep", argv, popts.launch)
        from ignjax.evaluate.recovery import report_model_failures
        from ignjax.sweep.stages import model_failures, run_sweep

        prefetch_command_programs("sweep", args)

        t0 = time.perf_counter()
        results = run_sweep(cfg, studies, out, resume=args.resume, force=args.force, quiet=args.quiet, group=group)
        if not group.main:
            return 0
        print(f"wrote {out / 'report.md'} ({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
        return report_model_failures(model_failures(results), "run the same command again with --resume")
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


__all__ = ["STUDIES", "build_parser", "check_processes", "main", "parse_studies"]
