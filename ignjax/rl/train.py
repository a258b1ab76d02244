"""``python -m ignjax.rl.train``: PPO on the RL environment.

::

    python -m ignjax.rl.train [--config FILE] [--set table.key=value ...] [--resume | --force] [--no-progress]
    python -m ignjax.rl.train --print-config        # every setting with its default, as TOML

Settings: :mod:`ignjax.rl.trainconfig` (errors name ``file:line`` or the
``--set`` item). The run folder ``<run.out>/<run.name>/`` receives
``run.json`` (the configuration and its fingerprint), ``houses/`` (the
training benchmark built from procedural houses of ``houses.seed``, unless
``houses.episodes`` names a file), ``curve.csv`` and ``curve.png`` (one row
per update: steps, wall seconds, the ended episodes' mean return (their
WSR), success, questions and length, the losses) and
``checkpoints/<update>/`` (:mod:`ignjax.rl.checkpoint`). ``--resume``
continues from the newest checkpoint with the same bytes as a run that
never stopped; a checkpoint of another observation layout, action set,
network or package version is refused before any episode. The same
configuration gives the same checkpoint bytes on one machine.

Needs the ``rl`` extra (flax, optax): without it the command prints the
``pip install "ignjax[rl]"`` line and exits with status 2.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

from ignjax.cache import add_cache_arguments, apply_cache_arguments
from ignjax.errors import ConfigError, IgnjaxError, InputError
from ignjax.errors.extras import require_extra
from ignjax.fileio import atomic_write
from ignjax.rl import trainconfig as TC

def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m ignjax.rl.train", description=__doc__.split("\n\n")[0])
    p.add_argument("--config", help="TOML file of settings (python -m ignjax.rl.train --print-config shows them all)")
    p.add_argument("--set", action="append", default=[], metavar="TABLE.KEY=VALUE", help="override one setting")
    p.add_argument("--resume", action="store_true", help="continue the run folder's newest checkpoint")
    p.add_argument("--force", action="store_true", help="replace a run folder that holds another run")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--print-config", action="store_true", help="print the settings as TOML and exit")
    add_cache_arguments(p)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(sys.argv[1:] if argv is None else list(argv))
    try:
        require_extra("flax", "rl")
        require_extra("optax", "rl")
        cfg = TC.resolve(args.config, args.set)
        if args.print_config:
            print(TC.to_toml(cfg), end="")
            return 0
        if args.resume and args.force:
            raise ConfigError(None, "--resume", "cannot be combined with --force")
        apply_cache_arguments(args)
        run(cfg, resume=args.resume, force=args.force, progress=not args.no_progress)
        return 0
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


def prepare_folder(out: Path, cfg: TC.TrainConfig, resume: bool, force: bool) -> None:
    """Create or reuse the run folder; refuse one that holds another run or, without --resume, this one."""
    meta = out / "run.json"
    if out.exists() and any(out.iterdir()):
        if force:
            shutil.rmtree(out)
        elif not meta.is_file():
            raise InputError(str(out), "--out", "folder is not empty and holds no training run; use --force")
        elif json.loads(meta.read_text()).get("fingerprint") != cfg.fingerprint():
            raise InputError(str(meta), "fingerprint", "the folder holds a run of another configuration; "
                                                       "set run.name, or use --force to replace it")
        elif not resume:
            raise InputError(str(out), "run.name", "the folder already holds this run; use --resume or --force")
    out.mkdir(parents=True, exist_ok=True)
    if not meta.is_file():
        from ignjax import __version__

        atomic_write(meta, json.dumps({"fingerprint": cfg.fingerprint(), "ignjax_version": __version__,
                                       "config": cfg.to_dict()}, indent=2, sort_keys=True) + "\n")


def training_episodes(cfg: TC.TrainConfig, out: Path) -> Path:
    """The episode file to train on: ``houses.episodes``, or the benchmark built into ``<run>/houses/``."""
    if cfg.houses.episodes:
        path = Path(cfg.houses.episodes)
        if not path.is_file():
            raise ConfigError(None, "houses.episodes", f"no such file: {path}")
        return path
    folder = out / "houses"
    path = folder / "episodes.jsonl.gz"
    if path.is_file():
        return path
    from ignjax.episodes.construct import BuildConfig, build_benchmark
    from ignjax.episodes.schema import construction_path, write_records
    from ignjax.scenes.io.usd import save_usd
    from ignjax.scenes.procgen.generate import generate_houses

    staging = folder.with_name("houses.partial")
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir(parents=True)
    houses = generate_houses(cfg.houses.count, cfg.houses.seed)
    for h in houses:
        save_usd(h, staging / f"{h.id}.usda")
    built = build_benchmark([(h, f"{h.id}.usda") for h in houses],
                            BuildConfig(seed=cfg.houses.seed, subset=cfg.houses.subset))
    write_records(staging / path.name, built["subset"])
    write_records(construction_path(staging / path.name), built["subset_construction"])
    shutil.rmtree(folder, ignore_errors=True)
    staging.rename(folder)
    return path


def run(cfg: TC.TrainConfig, resume: bool = False, force: bool = False, progress: bool = True) -> Path:
    """Train; returns the run folder (see the module docstring)."""
    from ignjax.rl import loop

    out = Path(cfg.run.out) / cfg.run.name
    prepare_folder(out, cfg, resume, force)
    return loop.train(cfg, out, training_episodes(cfg, out), resume, progress)


__all__ = ["main", "prepare_folder", "run", "training_episodes"]

if __name__ == "__main__":
    from ignjax.devices import configure_cpu_devices

    configure_cpu_devices()
    sys.exit(main())
