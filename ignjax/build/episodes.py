"""``python -m ignjax.build episodes``: build a benchmark from scenes, or check a file.

Build::

    python -m ignjax.build episodes --scenes scenes --out e.jsonl.gz --subset 500 --seed 0

writes ``e.jsonl.gz`` (the released evaluation subset),
``e.construction.jsonl.gz`` (construction-only fields of the same episodes),
``e.corpus.jsonl.gz`` (every eligible episode, released fields) and
``e.stats.png`` (the statistics figure), and prints the summary. Scene
paths may be scene folders (with or without ``manifest.json``), USD files,
ProcTHOR JSON/JSONL(.gz) or glTF/GLB/OBJ files; each record stores its scene
file relative to the output's folder. ``--workers N`` reads the scene files
and builds each scene's episodes in N processes (0: one per CPU core); the
files are the same bytes as with one.

Check::

    python -m ignjax.build episodes --check e.jsonl.gz [--schema-only]

validates every record (schema, version, fields, D = alpha . factors, bins,
no construction fields) and, unless ``--schema-only``, every record against
its scene (scene found, target in the scene, start navigable and reachable),
then prints the counts.
"""

from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path

from ignjax.arrays import parse_floats
from ignjax.errors import ConfigError, SceneError
from ignjax.scenes.io.sources import scene_sources


def _out_paths(out: Path) -> dict[str, Path]:
    # imported on use, so that --help and the other commands answer at once
    from ignjax.episodes.schema import construction_path

    name = out.name
    stem = name
    for suffix in (".jsonl.gz", ".jsonl"):
        if name.endswith(suffix):
            stem = name[: -len(suffix)]
            break
    gz = ".jsonl.gz" if name.endswith(".gz") else ".jsonl"
    return {"subset": out, "construction": construction_path(out), "corpus": out.with_name(stem + ".corpus" + gz),
            "figure": out.with_name(stem + ".stats.png")}


def build_episodes(args) -> int:
    # imported on use, so that --help and the other commands answer at once
    from tqdm.auto import tqdm

    # imported on use, so that --help and the other commands answer at once
    from ignjax.build.pool import ordered_map, resolve_workers
    from ignjax.episodes.construct import BuildConfig, build_benchmark
    from ignjax.episodes.difficulty import validate_alpha, validate_thresholds
    from ignjax.episodes.schema import strip_record, write_records
    from ignjax.episodes.stats import format_summary, statistics_figure, summarize

    if not args.scenes:
        raise ConfigError(None, "--scenes", "give at least one scene source (or use --check FILE)")
    if not args.out:
        raise ConfigError(None, "--out", "give the episode file to write (.jsonl or .jsonl.gz)")
    out = Path(args.out)
    if not (out.name.endswith(".jsonl") or out.name.endswith(".jsonl.gz")):
        raise ConfigError(None, "--out", f"must end in .jsonl or .jsonl.gz, got {out.name!r}")
    if args.subset < 0:
        raise ConfigError(None, "--subset", f"must be >= 0, got {args.subset}")
    alpha = validate_alpha(parse_floats(args.alpha, 4, "--alpha"), normalize=args.normalize_alpha, where="--alpha")
    thresholds = validate_thresholds(parse_floats(args.thresholds, 2, "--thresholds"), where="--thresholds")
    config = BuildConfig(seed=args.seed, alpha=alpha, thresholds=thresholds, subset=args.subset,
                         starts_per_target=args.starts)
    workers = resolve_workers(args.workers)
    progress = (lambda it: tqdm(it, desc="scenes", file=sys.stderr, disable=args.quiet, dynamic_ncols=True))
    with ordered_map(workers) as map_:  # with one worker: the built-in map, here
        sources = scene_sources(args.scenes, map_=map_)
        pairs = [(s, Path(os.path.relpath(f.resolve(), out.parent.resolve())).as_posix()) for s, f in sources]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            built = build_benchmark(pairs, config, progress=progress, map_=map_ if workers > 1 else None)
    for w in caught:
        print(f"warning: {w.message}", file=sys.stderr)
    paths = _out_paths(out)
    write_records(paths["corpus"], [strip_record(r) for r in built["corpus"]])
    write_records(paths["construction"], built["subset_construction"])
    write_records(paths["subset"], [strip_record(r) for r in built["subset"]])
    corpus_s = summarize(built["corpus"], built["corpus_construction"], config.norms)
    subset_s = summarize(built["subset"], built["subset_construction"], config.norms)
    fig_path = Path(args.figure) if args.figure else paths["figure"]
    statistics_figure(corpus_s, subset_s, fig_path, thresholds=thresholds)
    skipped = [r for r in built["reports"] if r.skipped]
    dropped: dict[str, int] = {}
    for r in built["reports"]:
        for k, v in r.dropped.items():
            dropped[k] = dropped.get(k, 0) + v
    print(format_summary("corpus", corpus_s))
    print(format_summary("evaluation subset", subset_s))
    print(f"scenes: {len(built['reports'])} read, {len(skipped)} skipped (no eligible target)"
          + (": " + ", ".join(r.scene_id for r in skipped) if skipped else ""))
    if dropped:
        print("candidates dropped: " + ", ".join(f"{k} {v}" for k, v in sorted(dropped.items(), key=lambda kv: -kv[1])))
    short = built["subset_info"].get("short", {})
    if short:
        print("warning: the corpus lacks episodes for the requested split: "
              + ", ".join(f"{b} short by {n}" for b, n in short.items()), file=sys.stderr)
    print(f"wrote {paths['subset']} ({len(built['subset'])} episodes), {paths['construction']}, {paths['corpus']}, {fig_path}")
    return 0


def check_episodes(args) -> int:
    # imported on use, so that --help and the other commands answer at once
    from ignjax.episodes.schema import read_episodes
    from ignjax.episodes.stats import format_summary, summarize

    path = Path(args.check)
    records = read_episodes(path)
    if not args.schema_only:
        # imported on use, so that --help and the other commands answer at once
        from ignjax.episodes.dataset import load_benchmark

        es = load_benchmark(path)
        print(f"checked {len(es)} episodes against {len(es.bank.scene_ids)} scenes: every scene, target and start is valid")
    print(format_summary(str(path), summarize(records)))
    return 0


def run_episodes_command(args) -> int:
    if args.check:
        return check_episodes(args)
    return build_episodes(args)
