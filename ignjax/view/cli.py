"""``python -m ignjax.view``: a run folder -> one HTML page, or one episode -> GIF/MP4.

::

    python -m ignjax.view RUN_DIR [--out FILE.html] [--episodes N] [--agent NAME ...]
    python -m ignjax.view RUN_DIR --gif EPISODE_ID [--agent NAME] [--out FILE.gif|FILE.mp4]

The page goes to ``RUN_DIR/viewer.html`` unless ``--out`` says otherwise; an
export goes to ``RUN_DIR/<episode id, "/" as "_">_<agent>.gif``. Bad input
(a folder that is not a run folder, an unknown agent or episode,
``--episodes`` below 1, an unknown suffix) is one line on stderr naming the
path or option and the reason, exit status 2, and nothing written.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ignjax.cache import add_cache_arguments, apply_cache_arguments
from ignjax.errors import ConfigError, IgnjaxError


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m ignjax.view", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog="The run folder's layout (images, transcripts) is in the docstring of ignjax.view.")
    p.add_argument("run_dir", metavar="RUN_DIR", help="a run folder of python -m ignjax.evaluate or python -m ignjax.sweep")
    p.add_argument("--out", help="output file (default RUN_DIR/viewer.html; with --gif RUN_DIR/<episode>_<agent>.gif)")
    p.add_argument("--episodes", type=int, metavar="N",
                   help="only the first N episodes of the run, with their images (default: every episode, no images)")
    p.add_argument("--agent", action="append", metavar="NAME",
                   help="an agent to show (repeatable; default every agent of the run); with --gif, the one exported "
                        "(default the run's first)")
    p.add_argument("--benchmark", metavar="EPISODE_FILE", help="the run's episode file, when it is no longer where "
                                                               "the run was made")
    p.add_argument("--scenes-root", help="where to look for scene files the episode file names, if not next to it")
    p.add_argument("--title", help="page title (default: the sweep's run name or the folder's name)")
    p.add_argument("--gif", metavar="EPISODE_ID", help="export this episode as an animation instead of the page")
    p.add_argument("--fps", type=float, default=1.5, help="frames (planner steps) per second of --gif (default 1.5)")
    add_cache_arguments(p)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        apply_cache_arguments(args)
        return run(args)
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


def run(args) -> int:
    # imported on use, so that --help answers at once
    from ignjax.view.export import FORMATS, export_episode
    from ignjax.view.page import write_page
    from ignjax.view.runfolder import check_run_folder, read_run

    if args.episodes is not None and args.episodes <= 0:
        raise ConfigError(None, "--episodes", f"must be a positive number of episodes, got {args.episodes}")
    folder = Path(args.run_dir)
    check_run_folder(folder)
    t0 = time.perf_counter()
    if args.gif is not None:
        if args.agent and len(args.agent) > 1:
            raise ConfigError(None, "--agent", "--gif exports one agent's episode; give --agent once")
        if args.out and Path(args.out).suffix.lower() not in FORMATS:
            raise ConfigError(args.out, "--out", f"the export is a .gif or an .mp4 file, not "
                                                 f"{Path(args.out).suffix or 'no suffix'!r}")
        run_ = read_run(folder, args.agent, args.episodes, benchmark=args.benchmark, scenes_root=args.scenes_root,
                        title=args.title)
        agent = run_.agents[0]
        out = Path(args.out) if args.out else folder / f"{args.gif.replace('/', '_')}_{agent}.gif"
        path = export_episode(run_, args.gif, agent, out, args.fps)
        print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB, {time.perf_counter() - t0:.1f} s)")
        return 0
    out = Path(args.out) if args.out else folder / "viewer.html"
    if out.suffix.lower() not in (".html", ".htm"):
        raise ConfigError(str(out), "--out", "the page is an .html file")
    run_ = read_run(folder, args.agent, args.episodes, benchmark=args.benchmark, scenes_root=args.scenes_root,
                    title=args.title)
    path = write_page(run_, out)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB: {len(run_.records)} episodes x {len(run_.agents)} agents, "
          f"{time.perf_counter() - t0:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
