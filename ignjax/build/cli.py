"""``python -m ignjax.build``: build scenes and benchmarks, inspect sources.

Sub-commands::

    python -m ignjax.build scenes --out DIR [--count N] [--seed S] [--maps] [--workers N]
    python -m ignjax.build inspect PATH [--json]
    python -m ignjax.build episodes --scenes PATH... --out FILE.jsonl.gz [--subset N] [--seed S] [--alpha a1,a2,a3,a4] [--workers N]
    python -m ignjax.build episodes --check FILE
    python -m ignjax.build default --out DIR [--workers N]

``default`` writes the shipped benchmark (:mod:`ignjax.data.shipped`) again
into ``DIR`` and checks every file against the recorded hashes; where bytes
differ it compares the episodes value by value (floats within a relative
1e-9: another numpy build or CPU rounds some last digits differently) and
exits 1 only when an episode really differs.

Errors on bad input are printed as one line naming the file, the place in it
and the reason, and the command exits with status 2 without writing
half-finished outputs.

``--workers N`` (``scenes`` and ``episodes``) does the per-scene work in N
processes (0: one per CPU core; :mod:`ignjax.build.pool`); the files written
and the errors raised are the same as with the default of one.

``inspect PATH --json`` prints exactly one JSON object on stdout: for one
scene ``{"source", "scene_id", "format", "up_axis", "meters_per_unit",
"rooms": [{"id", "label"}], "instances": [...]}``, for a source holding
several ``{"source", "scenes": [<one object per scene>]}``. ``up_axis`` and
``meters_per_unit`` are the source's own; every coordinate is in metres in
ignjax's Z-up frame (floor at z = 0). Each non-structural instance is
``{"id", "category", "room", "position", "center", "size", "yaw"}``:

* ``position``: the bottom centre of the instance's upright box (the centre
  of its floor footprint at its lowest point: where it stands), ``[x, y, z]``;
* ``center``: the centre of the box, ``[x, y, z]``;
* ``size``: the box's full extents ``[along its x, along its y, height]``;
* ``yaw``: the box's rotation about +Z in radians (counter-clockwise from
  +x), which turns its x and y extents into the world;
* ``room``: the id of the room it is in, or null.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from ignjax.cache import add_cache_arguments, apply_cache_arguments
from ignjax.errors import ConfigError, IgnjaxError, SceneError


def _progress(iterable, total: int, desc: str, quiet: bool):
    # imported on use, so that --help and the other commands answer at once
    from tqdm.auto import tqdm

    return tqdm(iterable, total=total, desc=desc, disable=quiet, file=sys.stderr, dynamic_ncols=True)


def _write_house(scene, folder: Path, check: bool, maps: bool) -> dict:
    """Check a house (unless ``check`` is false), write its USD file (and
    map) into ``folder``; returns its manifest entry."""
    # imported on use, so that --help and the other commands answer at once
    from ignjax.scenes.io.manifest import manifest_entry
    from ignjax.scenes.io.usd import save_usd

    if check:
        # imported on use, so that --help and the other commands answer at once
        from ignjax.scenes.compile import compile_scene
        from ignjax.scenes.navgrid import GridConfig, build_navgrid, check_reachable

        grid = build_navgrid(compile_scene(scene), GridConfig())
        check_reachable(scene, grid, scene.id)
    entry = manifest_entry(scene, save_usd(scene, folder / f"{scene.id}.usda"))
    if maps:
        # imported on use, so that --help and the other commands answer at once
        from ignjax.scenes.viz.mapplot import plot_scene_map

        (folder / "maps").mkdir(exist_ok=True)
        plot_scene_map(scene, folder / "maps" / f"{scene.id}.png")
    return entry


def _house_task(task: tuple) -> dict:
    """One house of ``scenes --workers N`` (in a worker process): generate it
    and :func:`_write_house` it into the staging folder."""
    # imported on use, so that --help and the other commands answer at once
    from ignjax.scenes.procgen import generate as procgen

    seed, params, scene_id, staging, check, maps = task
    return _write_house(procgen.generate_house(seed, params, scene_id), Path(staging), check, maps)


def _move_staged(staging: Path, out: Path, scene_id: str) -> None:
    """Move a house's files from the staging folder to their place in ``out``
    (renames within one file system: each file appears whole)."""
    for rel in (f"{scene_id}.usda", f"maps/{scene_id}.png"):
        src, dst = staging / rel, out / rel
        if not src.exists():
            continue
        try:
            dst.parent.mkdir(exist_ok=True)
            os.replace(src, dst)
        except OSError as e:
            raise SceneError(dst, None, f"cannot write: {e}") from e


def _scenes_parallel(args, params, workers: int, out: Path) -> list[dict]:
    """The houses of ``scenes`` built by ``workers`` processes; same files as
    the serial loop of :func:`cmd_scenes`. Each house is written into a
    staging folder inside ``out`` and moved into place in house order, so a
    house that fails its check, its USD file or its map leaves what the serial
    loop leaves (the houses before it, no manifest) and the error is its own.
    (A house the generator itself fails on, which valid parameters do not
    give, is reported the same way; the serial loop reports it before writing
    anything.)"""
    # imported on use, so that --help and the other commands answer at once
    from ignjax.build.pool import ordered_map
    from ignjax.scenes.procgen import generate as procgen

    plan = procgen.house_plan(args.count, args.seed, params)  # validates count and seed before anything is written
    out.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=out))
    tasks = [(s_i, p_i, scene_id, str(staging), args.check, args.maps) for s_i, p_i, scene_id in plan]
    entries = []
    try:
        with ordered_map(workers, len(tasks)) as map_:
            results = map_(_house_task, tasks)
            for _, _, scene_id in _progress(plan, len(plan), "houses", args.quiet):
                try:
                    entry = next(results)
                except BaseException:
                    _move_staged(staging, out, scene_id)  # what the serial loop had written of this house
                    raise
                _move_staged(staging, out, scene_id)
                entries.append(entry)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return entries


def cmd_scenes(args) -> int:
    """Generate procedural houses, write them as USD plus a manifest."""
    # imported on use, so that --help and the other commands answer at once
    from ignjax.build.pool import resolve_workers
    from ignjax.scenes.procgen import generate as procgen

    workers = resolve_workers(args.workers)
    params = procgen.HouseParams(min_rooms=args.min_rooms, max_rooms=args.max_rooms)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ConfigError(out, "--out", "exists and is not a folder")
    t0 = time.perf_counter()
    if workers > 1:
        entries = _scenes_parallel(args, params, workers, out)
        return _scenes_done(args, params, out, entries, t0)
    scenes = procgen.generate_houses(args.count, args.seed, params)  # validates count and seed before anything is written
    out.mkdir(parents=True, exist_ok=True)
    entries = []
    for scene in _progress(scenes, len(scenes), "houses", args.quiet):
        entries.append(_write_house(scene, out, args.check, args.maps))
    return _scenes_done(args, params, out, entries, t0)


def _scenes_done(args, params, out: Path, entries: list[dict], t0: float) -> int:
    # imported on use, so that --help and the other commands answer at once
    from ignjax.scenes.io.manifest import write_manifest

    write_manifest(out, entries, {"seed": args.seed, "count": args.count, "params": params.to_dict()})
    total = sum(e["instances"] for e in entries)
    print(f"wrote {len(entries)} houses ({sum(e['rooms'] for e in entries)} rooms, {total} instances) "
          f"and {out / 'manifest.json'} in {time.perf_counter() - t0:.1f} s")
    return 0


def _round(values) -> list[float]:
    return [round(float(v), 6) + 0.0 for v in values]


def inspect_summary(scene) -> dict:
    """The ``inspect --json`` object of one scene (the contract is in this
    module's docstring): :func:`~ignjax.scenes.model.scenejson.scene_summary` plus each
    instance's box as ``center``, ``size`` (full extents) and ``yaw``."""
    # imported on use, so that --help and the other commands answer at once
    from ignjax.scenes.model.scenejson import scene_summary

    doc = scene_summary(scene)
    boxes = {i.id: i.bbox for i in scene.objects}
    for item in doc["instances"]:
        box = boxes[item["id"]]
        item["center"] = _round(box.center)
        item["size"] = _round(2.0 * h for h in box.half_extents)
        item["yaw"] = _round([box.yaw])[0]
    return doc


def cmd_inspect(args) -> int:
    """Summarise any supported scene source."""
    # imported on use, so that --help and the other commands answer at once
    from ignjax.scenes.io.sources import load_scenes

    scenes = load_scenes(args.path)
    if args.json:
        if len(scenes) == 1:
            doc = inspect_summary(scenes[0])
        else:
            doc = {"source": str(args.path), "scenes": [inspect_summary(s) for s in scenes]}
        sys.stdout.write(json.dumps(doc) + "\n")
        return 0
    for s in scenes:
        cats = s.categories()
        multi = {c: n for c, n in cats.items() if n > 1}
        print(f"{s.id}  ({s.meta.source_format}: {s.meta.source})")
        print(f"  up axis {s.meta.up_axis}, {s.meta.meters_per_unit:g} m/unit; {len(s.rooms)} rooms, {len(s.doors)} doors, "
              f"{len(s.walls)} walls, {len(s.objects)} objects in {len(cats)} categories")
        print("  rooms: " + ", ".join(f"{r.id}={r.label}" for r in s.rooms))
        if multi:
            print("  several instances: " + ", ".join(f"{c} x{n}" for c, n in sorted(multi.items(), key=lambda kv: -kv[1])))
        print("  categories: " + ", ".join(f"{c}({n})" for c, n in cats.items()))
    return 0


def cmd_render(args) -> int:
    """Top-down map and first-person 8-view panorama of a scene."""
    # imported on use, so that --help and the other commands answer at once
    import math

    # imported on use, so that --help and the other commands answer at once
    import numpy as np

    # imported on use, so that --help and the other commands answer at once
    from ignjax.scenes.compile import compile_scene
    from ignjax.scenes.io.sources import load_scenes
    from ignjax.scenes.viz.mapplot import plot_scene_map
    from ignjax.scenes.navgrid import GridConfig, build_navgrid
    from ignjax.protocol import VIEW_NAMES
    from ignjax.scenes.bank import SceneBank
    from ignjax.scenes.viz.render import save_png
    from ignjax.sim.types import SimConfig
    from ignjax.sim.views import ViewConfig, ViewRenderer

    scenes = load_scenes(args.path)
    if args.scene:
        scenes = [s for s in scenes if s.id == args.scene]
        if not scenes:
            raise SceneError(args.path, "--scene", f"no scene {args.scene!r} in the source")
    scene = scenes[0]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    compiled = compile_scene(scene)
    grid = build_navgrid(compiled, GridConfig())
    if args.pose:
        x, y, yaw = (float(v) for v in args.pose.split(","))
    else:  # the navigable cell farthest from obstacles in the first room, facing its centroid
        room0 = grid.room_index(scene.rooms[0].id)
        clear = np.where(grid.navigable & (grid.room == room0), grid.clearance, -1)
        r, c = np.unravel_index(int(np.argmax(clear)), clear.shape)
        x, y = grid.cell_to_world(np.array([r, c]))
        cx, cy = scene.rooms[0].centroid
        yaw = math.atan2(cy - y, cx - x) if (cx - x) ** 2 + (cy - y) ** 2 > 0.25 else 0.0
    plot_scene_map(scene, out / f"{scene.id}_map.png")
    # the views as the agents see them (ignjax.sim.views): executor cameras, Planner panel, Grounder image
    bank = SceneBank.from_compiled([compiled], [grid])
    size = {} if args.size is None else {"size": args.size}  # None: ViewConfig's default
    with ViewRenderer(bank, SimConfig(), ViewConfig(**size, backend=args.backend)) as r:
        views = r.render([0], [[x, y, yaw]])
        panel = r.panels(views)[0]
        grounder = r.grounder_images(views, [0])[0]
    save_png(views.rgb[0, 0], out / f"{scene.id}_front.png")
    save_png(panel, out / f"{scene.id}_panorama.png")
    save_png(grounder, out / f"{scene.id}_grounder.png")
    print(f"wrote {out / (scene.id + '_map.png')}, {out / (scene.id + '_front.png')}, "
          f"{out / (scene.id + '_panorama.png')} and {out / (scene.id + '_grounder.png')} "
          f"(eye at x={x:.2f}, y={y:.2f}, yaw={yaw:.2f}; {r.backend} backend; views {', '.join(VIEW_NAMES)})")
    return 0


def cmd_default(args) -> int:
    """The shipped benchmark again (:mod:`ignjax.data.shipped`): its houses and
    episode files written into ``--out``, then compared with the recorded hashes."""
    from ignjax.data import shipped

    out = Path(args.out)
    common = ["--workers", str(args.workers)] + (["--quiet"] if args.quiet else [])
    steps = (["scenes", "--out", str(out), "--count", str(shipped.SCENE_COUNT), "--seed", str(shipped.SCENE_SEED)],
             ["episodes", "--scenes", str(out), "--out", str(out / shipped.EPISODES.name),
              "--subset", str(shipped.SUBSET), "--seed", str(shipped.EPISODE_SEED)])
    for step in steps:
        sub_args = build_parser().parse_args(step + common)
        sub_args.func(sub_args)
    bad = shipped.mismatches(out, shipped.recorded_hashes())
    use = (f"use it with --set benchmark.episodes={out / shipped.EPISODES.name} (sweep) or --episodes "
           f"{out / shipped.EPISODES.name} (evaluate)")
    if not bad:
        print(f"{out} holds the shipped benchmark, byte for byte; {use}")
        return 0
    diffs, rounded = shipped.episode_differences(out / shipped.EPISODES.name)
    if diffs:
        print(f"{out} differs from the shipped benchmark: {len(diffs)} episode values, first {diffs[0]}", file=sys.stderr)
        return 1
    print(f"{out} holds the shipped benchmark's episodes; {len(bad)} of its files differ from the shipped bytes only by "
          f"floating-point rounding ({rounded} episode numbers differ in their last digits, as they do between numpy "
          f"builds and CPUs); {use}")
    return 0


def cmd_episodes(args) -> int:
    # imported on use, so that --help and the other commands answer at once
    from ignjax.build.episodes import run_episodes_command

    return run_episodes_command(args)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m ignjax.build", description=__doc__.split("\n\n")[0])
    add_cache_arguments(p)  # before the command: python -m ignjax.build --no-compile-cache episodes ...
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("scenes", help="generate procedural houses as USD plus manifest.json")
    s.add_argument("--out", required=True, help="output folder (created if missing)")
    s.add_argument("--count", type=int, default=12, help="number of houses (default 12)")
    s.add_argument("--seed", type=int, default=0, help="seed; the same seed gives the same files (default 0)")
    s.add_argument("--min-rooms", type=int, default=2, help="fewest rooms per house (default 2)")
    s.add_argument("--max-rooms", type=int, default=12, help="most rooms per house (default 12)")
    s.add_argument("--maps", action="store_true", help="also write a top-down map PNG per house into OUT/maps/")
    s.add_argument("--no-check", dest="check", action="store_false",
                   help="skip compiling each house and checking that every room is reachable")
    s.add_argument("--workers", type=int, default=1,
                   help="processes that build houses in parallel (default 1: this process; 0: one per CPU core); "
                        "the files are the same for any number")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.set_defaults(func=cmd_scenes)

    i = sub.add_parser("inspect", help="summarise a scene source (USD, ProcTHOR JSON/JSONL, glTF/GLB/OBJ, scene folder)")
    i.add_argument("path")
    i.add_argument("--json", action="store_true",
                   help="print exactly one JSON object on stdout; per instance: position (bottom centre of its box), "
                        "center, size (full box extents) and yaw of its box, metres, Z-up")
    i.set_defaults(func=cmd_inspect)

    r = sub.add_parser("render", help="draw a scene's top-down map and render the Planner panel and a Grounder image")
    r.add_argument("path", help="a scene source (USD, ProcTHOR JSON, glTF/GLB/OBJ, scene folder)")
    r.add_argument("--scene", help="scene id, when the source holds several (default: the first)")
    r.add_argument("--out", default=".", help="output folder (default: current folder)")
    r.add_argument("--pose", help="eye pose x,y,yaw (metres, radians); default: an open spot of the first room")
    r.add_argument("--size", type=int, default=None,
                   help="pixels per view, 64..1024 (default: ViewConfig's, ignjax.sim.views.config.DEFAULT_SIZE)")
    r.add_argument("--backend", default="auto", choices=("auto", "warp", "egl"),
                   help="renderer (default auto: MuJoCo Warp when installed, else OpenGL)")
    r.set_defaults(func=cmd_render)

    d = sub.add_parser("default", help="write the shipped benchmark (12 houses, 500 episodes) again, byte for byte, "
                                       "and check it against the recorded hashes")
    d.add_argument("--out", required=True, help="output folder (created if missing)")
    d.add_argument("--workers", type=int, default=1, help="processes, as for scenes and episodes (default 1)")
    d.add_argument("--quiet", action="store_true", help="no progress bars")
    d.set_defaults(func=cmd_default)

    e = sub.add_parser("episodes", help="build a benchmark from scenes, or --check an episode file")
    e.add_argument("--scenes", nargs="+", help="scene sources: the scenes/ folder, USD files, ProcTHOR JSON/JSONL, glTF")
    e.add_argument("--out", help="episode file to write (.jsonl or .jsonl.gz)")
    e.add_argument("--subset", type=int, default=500, help="size of the balanced evaluation subset (default 500; 0 = all)")
    e.add_argument("--seed", type=int, default=0, help="seed of every random choice (default 0)")
    e.add_argument("--alpha", default="0.35,0.25,0.15,0.25", help="difficulty coefficients a1,a2,a3,a4 (sum 1)")
    e.add_argument("--thresholds", default="0.30,0.60", help="easy/medium and medium/hard thresholds")
    e.add_argument("--normalize-alpha", action="store_true", help="rescale --alpha to sum 1 instead of rejecting it")
    e.add_argument("--starts", type=int, default=3, help="start poses sampled per candidate target (default 3)")
    e.add_argument("--check", metavar="FILE", help="validate an episode file (against its scenes too) and print its counts")
    e.add_argument("--schema-only", action="store_true", help="with --check: validate the records only, not against the scenes")
    e.add_argument("--figure", help="where to draw the statistics figure (default: next to --out)")
    e.add_argument("--workers", type=int, default=1,
                   help="processes that load scenes and build their episodes in parallel (default 1: this process; "
                        "0: one per CPU core); the files are the same for any number")
    e.add_argument("--quiet", action="store_true", help="no progress bar")
    e.set_defaults(func=cmd_episodes)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        apply_cache_arguments(args)
        return int(args.func(args) or 0)
    except IgnjaxError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
