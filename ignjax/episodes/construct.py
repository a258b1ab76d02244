"""Benchmark construction: scenes -> candidate episodes -> balanced subset.

Per scene (:func:`scene_episodes`):

1. compile to MuJoCo, build the navigation grid (rooms that cannot be
   reached are reported and their targets skipped);
2. inventory and candidate targets (:mod:`ignjax.episodes.inventory`);
3. one geodesic distance field per candidate (all candidates of a scene in
   one vmapped call, :func:`ignjax.scenes.geodesic.goal_fields`);
4. a description that separates the target from its distractors
   (:mod:`ignjax.episodes.describe`), else the candidate is dropped;
5. a **reference view**: an eye pose 1-3 m from the target, in its room,
   facing it, from which the target is visible - the first surface that
   ``mujoco.mj_ray`` hits from the eye towards the target's box centre (or
   its top centre) belongs to the target;
6. **start poses**: navigable cells in the target's component (finite
   geodesic distance) at least ``min_start_distance`` (3 m) away. Per
   target we draw up to ``starts_per_target`` starts: one in the target's
   room when there is one (only ever kept as an *easy* episode), the rest
   in other rooms spread over distance terciles. Medium and hard episodes
   therefore start in another room whenever the house has one reachable;
   easy ones may start in the target's room, never closer than 3 m. Start
   yaw is uniform;
7. difficulty factors, D and the bin (:mod:`ignjax.episodes.difficulty`);
8. the oracle-memory hint (deliberately imperfect): the same-room
   distractor nearest the target when one exists, else the nearest
   distractor, else a point 0.5-1.5 m from the target in a random direction.

Then :func:`select_subset` draws the fixed-size evaluation subset
30:40:30 easy:medium:hard, greedily spreading scenes, goal-room labels,
target categories and targets (each pick minimises how often its scene,
room label, category and target have been picked, ties broken by a seeded
shuffle). Everything random comes from ``seed``: the same scenes and
config give byte-identical files.
"""

from __future__ import annotations

import math
import warnings
import zlib
from dataclasses import dataclass, field

import mujoco
import numpy as np

from ignjax.episodes import describe as D
from ignjax.episodes.difficulty import (
    BIN_NAMES, DEFAULT_ALPHA, DEFAULT_THRESHOLDS, FACTOR_NAMES, FactorNorms, difficulty_factors, validate_alpha,
    validate_thresholds,
)
from ignjax.episodes.inventory import InventoryConfig, build_inventory
from ignjax.episodes.schema import SCHEMA, CONSTRUCTION_SCHEMA, VERSION
from ignjax.errors import ConfigError, SceneError, call_recording_warnings, warn_again
from ignjax.scenes.compile import CompiledScene, compile_scene
from ignjax.scenes.geodesic import goal_fields
from ignjax.scenes.model import Scene
from ignjax.scenes.navgrid import GridConfig, NavGrid, build_navgrid, unreachable_rooms


@dataclass(frozen=True)
class BuildConfig:
    """Everything that decides the benchmark (all random choices from ``seed``).

    Attributes:
        seed: master seed.
        alpha: difficulty coefficients (sum 1).
        thresholds: easy/medium and medium/hard bin thresholds.
        norms: factor normalisations.
        inventory: candidate selection options.
        grid: navigation grid options.
        starts_per_target: start poses drawn per candidate target.
        min_start_distance: smallest geodesic start-to-target distance, m.
        goal_seed_radius: radius around the target's footprint whose
            navigable cells seed its geodesic field, m.
        eye_height: camera height of reference views (and the agent), m.
        view_distance: (min, max) distance of reference views, m.
        subset: size of the evaluation subset (0: the whole corpus).
        proportions: easy:medium:hard shares of the subset.
    """

    seed: int = 0
    alpha: tuple[float, float, float, float] = DEFAULT_ALPHA
    thresholds: tuple[float, float] = DEFAULT_THRESHOLDS
    norms: FactorNorms = field(default_factory=FactorNorms)
    inventory: InventoryConfig = field(default_factory=InventoryConfig)
    grid: GridConfig = field(default_factory=GridConfig)
    starts_per_target: int = 3
    min_start_distance: float = 3.0
    goal_seed_radius: float = 1.0
    eye_height: float = 1.25
    view_distance: tuple[float, float] = (1.0, 3.0)
    subset: int = 500
    proportions: tuple[float, float, float] = (0.3, 0.4, 0.3)

    def __post_init__(self):
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ConfigError(None, "seed", f"must be a non-negative integer, got {self.seed!r}")
        object.__setattr__(self, "alpha", validate_alpha(self.alpha))
        object.__setattr__(self, "thresholds", validate_thresholds(self.thresholds))
        if not (isinstance(self.starts_per_target, int) and self.starts_per_target >= 1):
            raise ConfigError(None, "starts_per_target", f"must be an integer >= 1, got {self.starts_per_target!r}")
        if not (isinstance(self.subset, int) and self.subset >= 0):
            raise ConfigError(None, "subset", f"must be an integer >= 0, got {self.subset!r}")
        p = tuple(float(x) for x in self.proportions)
        if len(p) != 3 or any(x < 0 or not math.isfinite(x) for x in p) or abs(sum(p) - 1) > 1e-6:
            raise ConfigError(None, "proportions", f"must be 3 non-negative shares summing to 1, got {self.proportions!r}")
        if not (0 < self.view_distance[0] < self.view_distance[1]):
            raise ConfigError(None, "view_distance", f"must be (min, max) with 0 < min < max, got {self.view_distance!r}")


@dataclass
class SceneReport:
    """What happened to one scene's candidates (for the summary)."""

    scene_id: str
    candidates: int = 0
    episodes: int = 0
    dropped: dict[str, int] = field(default_factory=dict)
    unreachable_rooms: list[str] = field(default_factory=list)
    skipped: str = ""

    def drop(self, reason: str) -> None:
        self.dropped[reason] = self.dropped.get(reason, 0) + 1


def _rng(seed: int, *keys: str) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed] + [zlib.crc32(k.encode()) for k in keys]))


def _visible(compiled: CompiledScene, eye: np.ndarray, point: np.ndarray, inst_index: int) -> bool:
    vec = point - eye
    dist = float(np.linalg.norm(vec))
    if dist < 1e-6:
        return False
    geomid = np.zeros(1, np.int32)
    d = mujoco.mj_ray(compiled.model, compiled.data, eye, vec / dist, None, 1, -1, geomid)
    if geomid[0] < 0:
        return False
    return int(compiled.geom_instance[geomid[0]]) == inst_index or d >= dist - 1e-3


def reference_view(compiled: CompiledScene, grid: NavGrid, inst_index: int, room_index: int, config: BuildConfig,
                   rng: np.random.Generator, tries: int = 40) -> dict | None:
    """A camera pose facing the target from which it is visible, or None."""
    inst = compiled.scene.instances[inst_index]
    bb = inst.bbox
    pts = grid.navigable_points()
    rc = grid.world_to_cell(pts)
    in_room = grid.room[rc[:, 0], rc[:, 1]] == room_index if room_index >= 0 else np.ones(len(pts), bool)
    d = bb.distance_xy(pts)
    lo, hi = config.view_distance
    cand = np.nonzero(in_room & (d >= lo) & (d <= hi))[0]
    if len(cand) == 0:
        cand = np.nonzero((d >= lo * 0.5) & (d <= hi * 1.5))[0]
    if len(cand) == 0:
        return None
    order = rng.permutation(cand)[:tries]
    targets = [np.array(bb.center), np.array([bb.center[0], bb.center[1], bb.zmax - 0.02])]
    for k in order:
        eye = np.array([pts[k, 0], pts[k, 1], config.eye_height])
        for tgt in targets:
            if _visible(compiled, eye, tgt, inst_index):
                dx, dy, dz = tgt - eye
                return {"x": float(eye[0]), "y": float(eye[1]), "z": float(eye[2]),
                        "yaw": float(math.atan2(dy, dx)), "pitch": float(math.atan2(dz, math.hypot(dx, dy)))}
    return None


def _memory_hint(scene: Scene, cand, rng: np.random.Generator) -> dict:
    t = scene.instance(cand.target_id)
    tc = np.array(t.bbox.center[:2])

    def nearest(ids):
        return min(ids, key=lambda i: float(np.linalg.norm(np.array(scene.instance(i).bbox.center[:2]) - tc)))

    if cand.same_room_distractors:
        i = nearest(cand.same_room_distractors)
        return {"kind": "same_room_distractor", "instance_id": i, "position": [float(v) for v in scene.instance(i).position]}
    if cand.distractors:
        i = nearest(cand.distractors)
        return {"kind": "nearest_distractor", "instance_id": i, "position": [float(v) for v in scene.instance(i).position]}
    ang = float(rng.uniform(-math.pi, math.pi))
    r = float(rng.uniform(0.5, 1.5))
    p = t.position
    return {"kind": "offset", "instance_id": None, "position": [p[0] + r * math.cos(ang), p[1] + r * math.sin(ang), p[2]]}


def _pick_starts(field_: np.ndarray, grid: NavGrid, room_index: int, config: BuildConfig,
                 rng: np.random.Generator) -> list[tuple[np.ndarray, bool]]:
    """Start cells [(row, col), same_room] per the rules of the module docstring."""
    ok = np.isfinite(field_) & grid.navigable & (field_ >= config.min_start_distance)
    same = ok & (grid.room == room_index)
    other = ok & (grid.room != room_index) & (grid.room >= 0)
    out: list[tuple[np.ndarray, bool]] = []
    if same.any():
        cells = np.argwhere(same)
        out.append((cells[rng.integers(len(cells))], True))
    n_other = config.starts_per_target - len(out)
    if other.any() and n_other > 0:
        cells = np.argwhere(other)
        dist = field_[cells[:, 0], cells[:, 1]]
        qs = np.quantile(dist, np.linspace(0, 1, n_other + 1))
        for k in range(n_other):
            sel = np.nonzero((dist >= qs[k]) & (dist <= qs[k + 1]))[0]
            if len(sel):
                out.append((cells[sel[rng.integers(len(sel))]], False))
    elif n_other > 0 and same.any():
        cells = np.argwhere(same)
        for _ in range(n_other):
            out.append((cells[rng.integers(len(cells))], True))
    return out


def scene_episodes(scene: Scene, config: BuildConfig, scene_file: str = "") -> tuple[list[dict], list[dict], SceneReport]:
    """Every eligible episode of one scene.

    Returns:
        (released records, construction records, report), in a
        deterministic order.
    """
    report = SceneReport(scene.id)
    compiled = compile_scene(scene)
    grid = build_navgrid(compiled, config.grid)
    report.unreachable_rooms = unreachable_rooms(scene, grid)
    inv = build_inventory(scene, config.inventory)
    report.candidates = len(inv.candidates)
    if not inv.candidates:
        report.skipped = "no eligible target"
        return [], [], report
    index = {inst.id: k for k, inst in enumerate(scene.instances)}
    cands = [c for c in inv.candidates if c.room is None or c.room not in report.unreachable_rooms]
    for c in inv.candidates:
        if c not in cands:
            report.drop("target room unreachable")
    room_idx = [grid.room_index(c.room) for c in cands]
    fields_ = goal_fields(grid, [scene.instance(c.target_id).bbox for c in cands], room_idx, config.goal_seed_radius)
    released, construction = [], []
    for ci, cand in enumerate(cands):
        target = scene.instance(cand.target_id)
        rng = _rng(config.seed, scene.id, cand.target_id)
        distractors = [scene.instance(i) for i in cand.distractors]
        desc = D.describe_target(scene, inv.anchors, target, distractors, cand.unique_anchors)
        if desc is None:
            report.drop("description cannot separate the target")
            continue
        text, facts = desc
        check = D.check_description(text, scene, inv.anchors, target, distractors)
        if not check.ok:
            report.drop(f"description rejected: {check.reason}")
            continue
        view = reference_view(compiled, grid, index[cand.target_id], room_idx[ci], config, rng)
        if view is None:
            report.drop("target not visible from any reference view")
            continue
        starts = _pick_starts(fields_[ci], grid, room_idx[ci], config, rng)
        if not starts:
            report.drop("no reachable start at least 3 m away")
            continue
        region, region_anchor = D.region_fact(scene, inv.anchors, target)
        room = scene.room(cand.room) if cand.room else None
        hint = _memory_hint(scene, cand, rng)
        has_cross_room = any(not same for _, same in starts)
        for k, (cell, same_room) in enumerate(starts):
            d_start = float(fields_[ci][cell[0], cell[1]])
            f = difficulty_factors(np.float64(len(cand.distractors)), np.float64(len(cand.same_room_distractors)),
                                   np.float64(cand.rho), np.float64(d_start), config.norms)
            factors = {n: float(v) for n, v in zip(FACTOR_NAMES, f)}
            d = sum(a * factors[n] for a, n in zip(config.alpha, FACTOR_NAMES))
            b = BIN_NAMES[(d >= config.thresholds[0]) + (d >= config.thresholds[1])]
            if same_room and b != "easy" and has_cross_room:
                report.drop("same-room start of a medium/hard episode")
                continue
            xy = grid.cell_to_world(cell)
            eid = f"{scene.id}/{cand.target_id}/{k}"
            released.append({
                "schema": SCHEMA, "version": VERSION, "episode_id": eid, "scene_id": scene.id,
                "scene_file": scene_file, "difficulty": b, "difficulty_score": d, "factors": factors,
                "alpha": list(config.alpha), "thresholds": list(config.thresholds),
                "instruction": D.instruction_text(target.category),
                "start": {"x": float(xy[0]), "y": float(xy[1]), "yaw": float(rng.uniform(-math.pi, math.pi))},
                "target_category": target.category, "target_id": target.id,
                "goal_room": {"id": room.id if room else "", "label": room.label if room else "other"},
                "goal_region": region, "reference_view": view, "description": text,
                "oracle": {"appearance": text, "region": region, "region_anchor": region_anchor, "facts": facts.as_dict()},
                "memory_hint": hint,
            })
            construction.append({
                "schema": CONSTRUCTION_SCHEMA, "version": VERSION, "episode_id": eid, "scene_id": scene.id,
                "distractors": list(cand.distractors), "same_room_distractors": list(cand.same_room_distractors),
                "anchors": list(cand.anchors), "unique_anchors": list(cand.unique_anchors), "rho": cand.rho,
                "target_bbox": {"center": list(target.bbox.center), "half_extents": list(target.bbox.half_extents),
                                "yaw": target.bbox.yaw},
                "target_attributes": target.attributes.as_dict(), "start_distance": d_start,
                "start_room": grid.room_ids[int(grid.room[cell[0], cell[1]])] if grid.room[cell[0], cell[1]] >= 0 else None,
                "description_facts": facts.as_dict(),
            })
            report.episodes += 1
    return released, construction, report


def select_subset(records: list[dict], n: int, proportions=(0.3, 0.4, 0.3), seed: int = 0) -> tuple[list[int], dict]:
    """Indices of a balanced, diverse subset of ``records`` (see module doc).

    Returns:
        (indices in corpus order, info) where info has the quotas and any
        shortfall per bin.
    """
    if n <= 0 or n >= len(records) and not any(proportions):
        return list(range(len(records))), {"quota": {}, "short": {}}
    q_easy = int(round(proportions[0] * n))
    q_hard = int(round(proportions[2] * n))
    quota = {"easy": q_easy, "medium": n - q_easy - q_hard, "hard": q_hard}
    rng = np.random.default_rng(np.random.SeedSequence([seed, 0x5EB5E7]))
    keys = {"scene": [r["scene_id"] for r in records], "room": [r["goal_room"]["label"] for r in records],
            "cat": [r["target_category"] for r in records], "target": [f"{r['scene_id']}/{r['target_id']}" for r in records]}
    codes = {k: np.unique(v, return_inverse=True)[1] for k, v in keys.items()}
    counts = {k: np.zeros(c.max() + 1, np.int64) for k, c in codes.items()}
    weight = {"scene": 1.0, "room": 1.0, "cat": 1.0, "target": 4.0}
    chosen: list[int] = []
    short: dict[str, int] = {}
    for b in BIN_NAMES:
        pool = np.array([i for i, r in enumerate(records) if r["difficulty"] == b], np.int64)
        pool = pool[rng.permutation(len(pool))]
        take = min(quota[b], len(pool))
        if take < quota[b]:
            short[b] = quota[b] - take
        alive = np.ones(len(pool), bool)
        for _ in range(take):
            score = sum(weight[k] * counts[k][codes[k][pool]] for k in codes)
            score = np.where(alive, score, np.inf)
            j = int(np.argmin(score))  # first minimum in shuffled order: seeded tie-break
            alive[j] = False
            i = int(pool[j])
            chosen.append(i)
            for k in codes:
                counts[k][codes[k][i]] += 1
    return sorted(chosen), {"quota": quota, "short": short}


def scene_task(task: tuple[Scene, BuildConfig, str]) -> tuple[list[dict], list[dict], SceneReport, list]:
    """:func:`scene_episodes` of one ``(scene, config, scene_file)`` plus the
    warnings it raised as ``(category, message)`` pairs: the unit of work of
    :func:`build_benchmark` when it runs in another process."""
    (r, c, rep), caught = call_recording_warnings(scene_episodes, *task)
    return r, c, rep, caught


def _mapped_episodes(scenes, config: BuildConfig, map_, progress):
    """(scene, released, construction, report) per scene, in scene order, computed by
    ``map_`` (a process pool's map); the scenes' warnings are raised here
    again in scene order."""
    it = progress(scenes) if progress else scenes
    results = map_(scene_task, [(scene, config, scene_file) for scene, scene_file in scenes])
    for (scene, _), (r, c, rep, caught) in zip(it, results):
        warn_again(caught, stacklevel=4)
        yield scene, r, c, rep


def build_benchmark(scenes: list[tuple[Scene, str]], config: BuildConfig = BuildConfig(), progress=None, map_=None):
    """Build the whole corpus and the evaluation subset.

    Args:
        scenes: (scene, scene_file) pairs; ``scene_file`` is stored in the
            records so evaluations can find the scene again.
        config: construction options.
        progress: optional callable wrapping an iterable (a progress bar).
        map_: optional ``map_(fn, items)`` returning results in item order,
            such as a process pool's (:func:`ignjax.build.pool.ordered_map`):
            the scenes' episodes are then built by it. Each scene's episodes
            depend on (seed, scene) alone, so the result is the same.

    Returns:
        dict with ``corpus`` / ``corpus_construction`` (all episodes),
        ``subset`` / ``subset_construction`` (the evaluation subset),
        ``reports`` (one :class:`SceneReport` per scene) and ``subset_info``.
    """
    ids = [s.id for s, _ in scenes]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise SceneError(None, "scenes", f"scene ids must be unique across the sources; repeated: {dup}")
    corpus, corpus_c, reports = [], [], []
    if map_ is None:
        it = progress(scenes) if progress else scenes
        per_scene = ((scene, *scene_episodes(scene, config, scene_file)) for scene, scene_file in it)
    else:
        per_scene = _mapped_episodes(scenes, config, map_, progress)
    for scene, r, c, rep in per_scene:
        if rep.skipped:
            warnings.warn(f"scene {scene.id}: skipped ({rep.skipped})", stacklevel=2)
        if rep.unreachable_rooms:
            warnings.warn(f"scene {scene.id}: rooms {rep.unreachable_rooms} are unreachable; their targets are skipped", stacklevel=2)
        corpus += r
        corpus_c += c
        reports.append(rep)
    idx, info = select_subset(corpus, config.subset, config.proportions, config.seed) if config.subset else (list(range(len(corpus))), {"quota": {}, "short": {}})
    return {"corpus": corpus, "corpus_construction": corpus_c, "subset": [corpus[i] for i in idx],
            "subset_construction": [corpus_c[i] for i in idx], "reports": reports, "subset_info": info}
