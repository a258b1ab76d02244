"""``python -m ignjax``: the version, and the commands the package provides.

::

    python -m ignjax --version      # prints "ignjax 0.1.0"
"""

from __future__ import annotations

import argparse
import sys

from ignjax import __version__

COMMANDS = {
    "ignjax.sweep": "the main job: every study on a benchmark, one report",
    "ignjax.evaluate": "run agents on an episode file, write outcomes and metrics",
    "ignjax.build": "build scenes and benchmarks, inspect and render scene sources",
    "ignjax.bench": "throughput and time-to-result figures",
    "ignjax.view": "the episode viewer of a run folder",
}


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m ignjax", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog="commands:\n" + "\n".join(f"  python -m {c:16s} {d}" for c, d in COMMANDS.items()))
    p.add_argument("--version", action="version", version=f"ignjax {__version__}")
    return p


def main(argv: list[str] | None = None) -> int:
    p = build_parser()
    p.parse_args(argv)
    p.print_help()
    return 0


if __name__ == "__main__":
    sys.exit(main())
