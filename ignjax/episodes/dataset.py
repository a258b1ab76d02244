"""Episode files -> the array batch the simulator consumes.

:func:`load_benchmark` reads a released episode file, finds and loads the
scenes its records name (``scene_file`` is resolved against the episode
file's folder, then against ``scenes_root`` when given), builds a
:class:`~ignjax.scenes.bank.SceneBank` of exactly those scenes, validates
every record against the scenes, computes one geodesic field per distinct
target and returns an :class:`EpisodeSet`: the records, the bank, the
fields and the batched :class:`~ignjax.sim.types.EpisodeSpec`.

Validation (each error names the file, the line/episode and the field):
unknown scene id or unreadable scene file; a target id not in the scene;
a target category that differs from the scene's; a start pose outside the
scene's navigable area or in a different navigable component than the
target (unreachable); plus every schema check of
:func:`ignjax.episodes.schema.read_episodes`.
"""

from __future__ import annotations

import dataclasses
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.arrays import on_device, take_rows
from ignjax.cache.clock import in_phase
from ignjax.cache.programs import settle_prefetch
from ignjax.devices import available_cores
from ignjax.episodes.difficulty import BIN_INDEX
from ignjax.episodes.schema import read_episodes
from ignjax.errors import ConfigError, EpisodeError, IgnjaxError
from ignjax.scenes import vocab
from ignjax.scenes.bank import SceneBank
from ignjax.scenes.buckets import plan_buckets
from ignjax.scenes.compile import compile_scene
from ignjax.scenes.derived import cached_goal_fields, cached_navgrid
from ignjax.scenes.fieldtable import FieldTable
from ignjax.scenes.io.sources import load_scenes
from ignjax.scenes.navgrid import GridConfig
from ignjax.sim.types import EpisodeSpec


@dataclass(eq=False)
class EpisodeSet:
    """A benchmark ready to run.

    Attributes:
        path: the episode file.
        records: the released records, in file order.
        bank: scene bank of the scenes the records use.
        fields: the geodesic fields of the distinct targets, a
            :class:`~ignjax.scenes.fieldtable.FieldTable` on the device.
        specs: :class:`EpisodeSpec` with a leading axis of len(records).
        field_index: (E,) int32 field of each episode.
        key_index: (E,) int64 the position of each episode in the run's
            episode list (the file, cut by ``limit`` / ``indices``), from
            which its PRNG key comes (:func:`ignjax.sim.rollout.episode_keys`);
            default ``0 .. E - 1``. A bucket of a streamed run
            (:class:`BenchmarkScenes`) or a :meth:`subset` keeps each
            episode's own, so an episode's randomness does not depend on
            which episodes run beside it.
    """

    path: Path
    records: list[dict]
    bank: SceneBank
    fields: jax.Array
    specs: EpisodeSpec
    field_index: np.ndarray
    key_index: np.ndarray | None = None

    def __post_init__(self):
        if self.key_index is None:
            self.key_index = np.arange(len(self.records), dtype=np.int64)

    def __len__(self) -> int:
        return len(self.records)

    @property
    def episode_ids(self) -> list[str]:
        return [r["episode_id"] for r in self.records]

    def subset(self, indices) -> "EpisodeSet":
        """The same benchmark restricted to some episodes (shares bank and fields)."""
        idx = np.asarray(indices, np.int64)
        specs = take_rows(self.specs, idx)
        return dataclasses.replace(self, records=[self.records[i] for i in idx], specs=specs,
                                   field_index=self.field_index[idx], key_index=self.key_index[idx])


def _resolve_scene_file(name: str, episode_file: Path, scenes_root: Path | None) -> Path:
    p = Path(name)
    candidates = [p] if p.is_absolute() else [episode_file.parent / p] + ([scenes_root / p, scenes_root / p.name] if scenes_root else [])
    for c in candidates:
        if c.exists():
            return c
    return candidates[0]


def _cat(bank: SceneBank, name) -> int:
    return bank.category_index(name) if name else -1


def episode_specs(records: list[dict], bank: SceneBank, path: str | os.PathLike | None = None) -> tuple[EpisodeSpec, list[tuple[int, int]], np.ndarray]:
    """Validate records against the bank and build their specs.

    Returns:
        (specs with leading axis E, distinct (scene, target) pairs in field
        order, (E,) field index of each episode).

    Raises:
        EpisodeError: naming the file, the episode and the field.
    """
    pairs: dict[tuple[int, int], int] = {}
    rows = []
    for k, rec in enumerate(records):
        where = f"episode {rec['episode_id']}"
        try:
            s = bank.scene_index(rec["scene_id"])
        except KeyError:
            raise EpisodeError(path, f"{where}: scene_id", f"scene {rec['scene_id']!r} is not among the loaded scenes {list(bank.scene_ids)}") from None
        try:
            t = bank.instance_index(s, rec["target_id"])
        except KeyError:
            raise EpisodeError(path, f"{where}: target_id", f"instance {rec['target_id']!r} is not in scene {rec['scene_id']!r}") from None
        scene = bank.scene(s)
        target = scene.instances[t]
        if target.category != rec["target_category"]:
            raise EpisodeError(path, f"{where}: target_category", f"{rec['target_category']!r} but instance {target.id!r} is a {target.category!r}")
        grid = bank.navgrids[s]
        x, y = rec["start"]["x"], rec["start"]["y"]
        r, c = grid.world_to_cell(np.array([x, y]))
        if not (0 <= r < grid.shape[0] and 0 <= c < grid.shape[1]) or not grid.navigable[r, c]:
            raise EpisodeError(path, f"{where}: start", f"start ({x:.3f}, {y:.3f}) is off the navigable area of scene {scene.id!r}")
        goal = rec["goal_room"]["id"]
        gi = grid.room_index(goal) if goal in grid.room_ids else -1
        pairs.setdefault((s, t), len(pairs))
        facts = rec["oracle"]["facts"]
        attrs = [vocab.COLOR_INDEX.get(facts.get("color"), -1), vocab.MATERIAL_INDEX.get(facts.get("material"), -1),
                 vocab.SIZE_INDEX.get(facts.get("size"), -1), vocab.STATE_INDEX.get(facts.get("state"), -1)]
        near = [_cat(bank, c_) for c_ in (facts.get("near") or [])][:3]
        near += [-1] * (3 - len(near))
        rows.append(dict(scene=s, target=t, field=pairs[(s, t)], category=_cat(bank, target.category),
                         start=[x, y, rec["start"]["yaw"]], difficulty=BIN_INDEX[rec["difficulty"]], goal_room=gi,
                         fact_attrs=attrs, fact_on=_cat(bank, facts.get("on")), fact_near=near,
                         region_category=_cat(bank, rec["oracle"].get("region_anchor")), valid=True))
    specs = EpisodeSpec(
        scene=on_device([r["scene"] for r in rows], jnp.int32), target=on_device([r["target"] for r in rows], jnp.int32),
        field=on_device([r["field"] for r in rows], jnp.int32), category=on_device([r["category"] for r in rows], jnp.int32),
        start=on_device([r["start"] for r in rows], jnp.float32), difficulty=on_device([r["difficulty"] for r in rows], jnp.int32),
        goal_room=on_device([r["goal_room"] for r in rows], jnp.int32),
        fact_attrs=on_device([r["fact_attrs"] for r in rows], jnp.int32), fact_on=on_device([r["fact_on"] for r in rows], jnp.int32),
        fact_near=on_device([r["fact_near"] for r in rows], jnp.int32),
        region_category=on_device([r["region_category"] for r in rows], jnp.int32),
        valid=on_device(np.ones(len(rows), bool)),
    )
    return specs, list(pairs), np.asarray([r["field"] for r in rows], np.int32)


FIELD_BATCH = 8
"""Goal fields computed per call when an episode set is built (:func:`field_table`): a scene's last call is padded
to it, so a small batch wastes little (the shipped scenes hold 30-41 targets: 448 fields computed for 408 at 8, 608
at 32); a field is the same bytes whatever the batch."""


def load_benchmark(path: str | os.PathLike, scenes_root: str | os.PathLike | None = None,
                   grid: GridConfig = GridConfig(), field_batch: int = FIELD_BATCH, progress=None,
                   limit: int | None = None, indices=None) -> EpisodeSet:
    """Read, validate and prepare an episode file for simulation (see module
    doc). ``limit``: only the first N episodes of the file; ``indices``: only
    these episodes (positions in the file, kept in this order); either way
    only the scenes they use are loaded. All in one bank; a benchmark of
    hundreds of scenes is better run a bucket of scenes at a time
    (:func:`open_benchmark`)."""
    bs = open_benchmark(path, scenes_root, grid, limit=limit, indices=indices)
    return bs.episode_set(np.arange(len(bs.records)), field_batch, progress)


@in_phase("load")
def open_benchmark(path: str | os.PathLike, scenes_root: str | os.PathLike | None = None,
                   grid: GridConfig = GridConfig(), limit: int | None = None, indices=None) -> "BenchmarkScenes":
    """Read an episode file, load and compile its scenes on the host and check
    every record against them, building no device table yet (arguments as
    :func:`load_benchmark`). :meth:`BenchmarkScenes.episode_set` then makes
    the :class:`EpisodeSet` of any part of it, and
    :meth:`BenchmarkScenes.buckets` plans a run a bucket of scenes at a time.

    Raises:
        EpisodeError: as :func:`load_benchmark`, for every record; only the
            check that a start reaches its target needs the goal fields and
            is made when a part's :class:`EpisodeSet` is built.
    """
    p = Path(path)
    records = read_episodes(p)
    if indices is not None:
        idx = [int(i) for i in indices]
        bad = [i for i in idx if not 0 <= i < len(records)]
        if bad:
            raise EpisodeError(p, "indices", f"episode index {bad[0]} is outside the file's {len(records)} episodes")
        records = [records[i] for i in idx]
    if limit is not None:
        records = records[:max(0, int(limit))]
    root = Path(scenes_root) if scenes_root else None
    by_file: dict[Path, set[str]] = {}
    first_line: dict[Path, str] = {}
    first_use: dict[tuple[Path, str], str] = {}
    for rec in records:
        f = _resolve_scene_file(rec["scene_file"], p, root)
        by_file.setdefault(f, set()).add(rec["scene_id"])
        first_line.setdefault(f, rec["episode_id"])
        first_use.setdefault((f, rec["scene_id"]), rec["episode_id"])
    files = sorted(by_file.items(), key=lambda kv: str(kv[0]))

    def read(item):  # one scene file: the scenes the records use
        f, ids = item
        try:
            loaded = {s.id: s for s in load_scenes(f)}
        except IgnjaxError as e:
            raise EpisodeError(p, f"episode {first_line[f]}: scene_file", f"cannot load scene file {str(f)!r}: {e}") from e
        for sid in sorted(ids):
            if sid not in loaded:
                raise EpisodeError(p, f"episode {first_use[(f, sid)]}: scene_id",
                                   f"scene {sid!r} not found in {str(f)!r} (it holds {sorted(loaded)})")
        return [loaded[sid] for sid in sorted(ids)]

    def prepare(scene):  # compiled and gridded (the grid through the cache)
        c = compile_scene(scene)
        return c, cached_navgrid(c, grid)

    # each scene compiled and gridded in a worker thread (one per core) while this thread reads the next file:
    # voxelizing and gridding spend most of their time in numpy without Python's lock (the shipped benchmark's
    # 12 houses: 8.3 s -> 7.1 s cold on 2 cores; its USD reads take turns, see ignjax.scenes.io.remembered);
    # each result is the same whichever thread makes it, and errors come in the files' path order
    with ThreadPoolExecutor(max(1, available_cores())) as pool:
        futures = [pool.submit(prepare, scene) for item in files for scene in read(item)]
        done = [f.result() for f in futures]
    if not done:
        raise EpisodeError(p, "episodes", "no episodes to run (the file, cut by limit / indices, is empty)")
    host = SceneBank.from_compiled([c for c, _ in done], [g for _, g in done], arrays=False)
    episode_specs(records, host, p)  # every record checked before any table is built
    return BenchmarkScenes(p, records, host)


@dataclass(eq=False)
class BenchmarkScenes:
    """An episode file's records and their scenes, compiled and gridded on the
    host, with no device table yet (:func:`open_benchmark`).

    Attributes:
        path: the episode file.
        records: the run's records (the file, cut by ``limit`` / ``indices``).
        host: a :class:`~ignjax.scenes.bank.SceneBank` of every scene the
            records use, host-side lookups only (``arrays=False``).
    """

    path: Path
    records: list[dict]
    host: SceneBank

    def __len__(self) -> int:
        return len(self.records)

    def scene_of(self) -> np.ndarray:
        """(E,) int the host bank's index of each record's scene."""
        return np.array([self.host.scene_index(r["scene_id"]) for r in self.records], np.int64)

    def buckets(self, budget_bytes: float, per_cell: int = 0) -> list[np.ndarray]:
        """The run's episodes cut into buckets of scenes of similar size whose
        tables and goal fields fit ``budget_bytes``
        (:func:`ignjax.scenes.buckets.plan_buckets`; ``per_cell``: the
        bytes a caller adds per navigation cell, e.g. the simulator's probe
        maps).

        Returns:
            Per bucket, the positions of its episodes in :attr:`records`
            (increasing); one bucket of every episode when all fit.
        """
        scene = self.scene_of()
        targets = {(int(s), r["target_id"]) for s, r in zip(scene, self.records)}
        fields = np.bincount([s for s, _ in targets], minlength=self.host.n_scenes)
        plan = plan_buckets(self.host.navgrids, budget_bytes, fields, per_cell)
        return [np.flatnonzero(np.isin(scene, b)) for b in plan]

    def host_set(self) -> EpisodeSet:
        """The whole run as an :class:`EpisodeSet` without device tables: the
        host-side bank (:attr:`host`), the records and their specs, no goal
        fields (``fields`` is None). For what reads episodes and scenes but
        simulates nothing (reports, studies of finished rollouts)."""
        specs, _, field_index = episode_specs(self.records, self.host, self.path)
        return EpisodeSet(self.path, self.records, self.host, None, specs, field_index)

    def with_scenes(self, n: int) -> "BenchmarkScenes":
        """The same benchmark over exactly ``n`` scenes, for measuring how cost
        grows with the scene count: the first ``n`` scenes (host order) and
        their records; with fewer scenes than ``n``, renamed copies
        (``<id>~<k>``) fill the rest, each with a copy of its scene's records
        (episode ids ``<id>~<k>``), so tables and fields grow as with
        distinct scenes of the same sizes."""
        h = self.host
        if n < 1:
            raise ConfigError(None, "scenes", f"must be >= 1, got {n}")
        src = [k % h.n_scenes for k in range(n)]
        names = [h.scene_ids[s] if k < h.n_scenes else f"{h.scene_ids[s]}~{k // h.n_scenes}" for k, s in enumerate(src)]
        compiled, grids, records = [], [], []
        by_scene: dict[str, list[dict]] = {}
        for r in self.records:
            by_scene.setdefault(r["scene_id"], []).append(r)
        for name, s in zip(names, src):
            c, g = h.compiled[s], h.navgrids[s]
            if name != h.scene_ids[s]:
                c = dataclasses.replace(c, scene=dataclasses.replace(c.scene, id=name))
                g = dataclasses.replace(g, scene_id=name)
                records += [{**r, "scene_id": name, "episode_id": f"{r['episode_id']}~{name.rsplit('~', 1)[1]}"}
                            for r in by_scene.get(h.scene_ids[s], [])]
            else:
                records += by_scene.get(name, [])
            compiled.append(c)
            grids.append(g)
        return BenchmarkScenes(self.path, records,
                               SceneBank.from_compiled(compiled, grids, categories=h.categories, arrays=False))

    @in_phase("load")
    def episode_set(self, positions, field_batch: int = FIELD_BATCH, progress=None) -> EpisodeSet:
        """The :class:`EpisodeSet` of the records at ``positions`` (in that
        order): a bank of only the scenes they use (in the host bank's order,
        with the whole run's category vocabulary), their goal fields, and each
        episode's :attr:`EpisodeSet.key_index` its position in the run
        (:meth:`prepare`, then :meth:`with_fields`).

        Raises:
            EpisodeError: a start that cannot reach its target.
        """
        return self.with_fields(*self.prepare(positions), field_batch, progress)

    @in_phase("load")
    def prepare(self, positions) -> tuple[EpisodeSet, list[tuple[int, int]]]:
        """:meth:`episode_set` without its goal fields: the set (``fields`` None;
        the bank's tables on the device, the specs) and its (scene, instance)
        target pairs, the rows of the fields :meth:`with_fields` computes. Every
        shape of the simulator's world is known from it
        (:func:`ignjax.sim.world.world_shapes`), so programs can compile while
        the fields are computed."""
        idx = np.asarray(positions, np.int64)
        records = [self.records[i] for i in idx]
        h = self.host
        used = sorted({h.scene_index(r["scene_id"]) for r in records})
        bank = SceneBank.from_compiled([h.compiled[s] for s in used], [h.navgrids[s] for s in used],
                                       categories=h.categories)
        specs, pairs, field_index = episode_specs(records, bank, self.path)
        return EpisodeSet(self.path, records, bank, None, specs, field_index, key_index=idx), pairs

    @in_phase("load")
    def with_fields(self, es: EpisodeSet, pairs: list[tuple[int, int]], field_batch: int = FIELD_BATCH,
                    progress=None) -> EpisodeSet:
        """A :meth:`prepare`-d set with its goal fields, each start checked to reach its target.

        Raises:
            EpisodeError: a start that cannot reach its target.
        """
        bank, records, specs, field_index = es.bank, es.records, es.specs, es.field_index
        fields = field_table(bank, pairs, field_batch, progress)
        # reachability: the start must see a finite geodesic distance to its target (on the host, before upload)
        starts, scene = np.asarray(specs.start), np.asarray(specs.scene)
        cells = np.array([bank.navgrids[s].world_to_cell(xy) for s, xy in zip(scene, starts[:, :2])],
                         np.int64).reshape(-1, 2)
        at_start = fields.at(np.asarray(field_index), cells[:, 0], cells[:, 1])
        for k in np.flatnonzero(~np.isfinite(at_start))[:1]:
            raise EpisodeError(es.path, f"episode {records[k]['episode_id']}: start",
                               "the target cannot be reached from the start pose")
        settle_prefetch()  # no program loaded ahead runs past the loading (ignjax.cache.programs.start_prefetch)
        return dataclasses.replace(es, fields=jax.device_put(fields))


def field_table(bank: SceneBank, pairs: list[tuple[int, int]], batch: int = FIELD_BATCH, progress=None) -> FieldTable:
    """Geodesic fields of (scene, instance) pairs as a host :class:`~ignjax.scenes.fieldtable.FieldTable`
    (numpy leaves; each field at its scene's own extent, read on the bank's padded grid).

    Each scene's targets go through
    :func:`~ignjax.scenes.derived.cached_goal_fields` (the on-disk cache in
    front of :func:`~ignjax.scenes.geodesic.goal_fields`, the batcher
    benchmark construction uses), ``batch`` at a time, seed radius 1 m, on
    the bank's padded grid (one compiled program for every scene);
    ``progress`` wraps the iteration over scenes. Each call's targets are
    split over the local devices (on CPU one per core). Read through
    :meth:`~ignjax.scenes.fieldtable.FieldTable.at`, the fields equal
    :func:`~ignjax.scenes.bank.target_fields` on the bank's grid, byte for
    byte (checked on the shipped benchmark).
    """
    H, W = bank.grid.navigable.shape[1:]
    out: list[np.ndarray | None] = [None] * len(pairs)
    rooms = np.asarray(bank.instances.room)
    by_scene: dict[int, list[tuple[int, int]]] = {}
    for f, (s, i) in enumerate(pairs):
        by_scene.setdefault(s, []).append((f, i))
    scenes = list(by_scene)
    for s in (progress(scenes) if progress else scenes):
        items, grid = by_scene[s], bank.navgrids[s]
        fields = cached_goal_fields(bank.compiled[s], grid, [i for _, i in items], [int(rooms[s, i]) for _, i in items],
                                    1.0, batch, (H, W))
        for (f, _), field in zip(items, fields):
            out[f] = field
    return FieldTable.of(out, (H, W))
