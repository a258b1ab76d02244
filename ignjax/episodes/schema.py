"""Versioned episode files: records, validation, reading and writing.

An episode file is JSON Lines (optionally gzipped), one episode per line.
Every record carries ``"schema": "ignjax-episode"`` and ``"version": 1``.
Released records hold what an evaluation needs; construction-only fields
(distractor lists, target boxes, structured attributes, anchors) live in a
separate *construction file* (``"schema": "ignjax-episode-construction"``)
so the released subset cannot leak the answer. :func:`strip_record` removes
anything outside :data:`RELEASED_FIELDS`.

Released record (version 1)::

    episode_id        str    unique in the file, "<scene>/<target>/<k>"
    scene_id          str    scene the episode is set in
    scene_file        str    where that scene is read from (relative to the
                             episode file's folder, or absolute)
    difficulty        str    "easy" | "medium" | "hard"
    difficulty_score  float  D = alpha . factors
    factors           {F_distractor, F_room, F_context, F_start: float in [0, 1]}
    alpha             [4 floats]  the coefficients D was computed with
    thresholds        [2 floats]  the bin thresholds
    instruction       str    coarse goal, "Find a laptop."
    start             {x, y, yaw}  metres, radians
    target_category   str
    target_id         str    instance id in the scene
    goal_room         {id, label}
    goal_region       str    Type-2 fact: room and coarse region
    reference_view    {x, y, z, yaw, pitch}  a pose from which the target is visible
    description       str    Type-1 fact: appearance and relations, no room
    oracle            {appearance: str, region: str, facts: {...}}
    memory_hint       {kind: "same_room_distractor"|"nearest_distractor"|"offset",
                       instance_id: str|null, position: [x, y, z]}
"""

from __future__ import annotations

import gzip
import io
import json
import math
import os
from pathlib import Path
from typing import Any, Iterable, Iterator

from ignjax.errors import EpisodeError
from ignjax.protocol import BIN_NAMES, FACTOR_NAMES

SCHEMA = "ignjax-episode"
CONSTRUCTION_SCHEMA = "ignjax-episode-construction"
VERSION = 1

RELEASED_FIELDS: tuple[str, ...] = (
    "schema", "version", "episode_id", "scene_id", "scene_file", "difficulty", "difficulty_score", "factors",
    "alpha", "thresholds", "instruction", "start", "target_category", "target_id", "goal_room", "goal_region",
    "reference_view", "description", "oracle", "memory_hint",
)
CONSTRUCTION_FIELDS: tuple[str, ...] = (
    "schema", "version", "episode_id", "scene_id", "distractors", "same_room_distractors", "anchors",
    "unique_anchors", "rho", "target_bbox", "target_attributes", "start_distance", "start_room",
    "description_facts",
)
LEAK_FIELDS: frozenset[str] = frozenset(CONSTRUCTION_FIELDS) - frozenset(RELEASED_FIELDS)
"""Fields that must never appear in a released record."""


def _num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _need(rec: dict, key: str, kind, where: str, path) -> Any:
    if key not in rec:
        raise EpisodeError(path, f"{where}: {key}", "missing field")
    v = rec[key]
    ok = _num(v) if kind == "number" else isinstance(v, kind) and not (kind is int and isinstance(v, bool))
    if not ok:
        name = kind if isinstance(kind, str) else getattr(kind, "__name__", str(kind))
        raise EpisodeError(path, f"{where}: {key}", f"expected {name}, got {type(v).__name__} {v!r}"[:200])
    return v


def validate_record(rec: Any, path: str | os.PathLike | None = None, where: str = "record") -> dict:
    """Check one released record's schema, version, fields and types.

    Raises:
        EpisodeError: naming the file, the line/episode and the field.
    """
    if not isinstance(rec, dict):
        raise EpisodeError(path, where, "a record must be a JSON object")
    eid = rec.get("episode_id")
    if isinstance(eid, str):
        where = f"{where} (episode {eid})"
    if rec.get("schema") != SCHEMA:
        raise EpisodeError(path, f"{where}: schema", f"expected {SCHEMA!r}, got {rec.get('schema')!r}")
    if not (type(rec.get("version")) is int and rec["version"] == VERSION):  # true == 1 and 1.0 == 1 in Python
        raise EpisodeError(path, f"{where}: version", f"unknown schema version {rec.get('version')!r}; this ignjax reads version {VERSION}")
    for key in ("episode_id", "scene_id", "scene_file", "instruction", "target_category", "target_id", "goal_region",
                "description"):
        _need(rec, key, str, where, path)
        if not rec[key].strip():
            raise EpisodeError(path, f"{where}: {key}", "must not be empty")
    diff = _need(rec, "difficulty", str, where, path)
    if diff not in BIN_NAMES:
        raise EpisodeError(path, f"{where}: difficulty", f"must be one of {BIN_NAMES}, got {diff!r}")
    _need(rec, "difficulty_score", "number", where, path)
    factors = _need(rec, "factors", dict, where, path)
    for name in FACTOR_NAMES:
        v = _need(factors, name, "number", f"{where}: factors", path)
        if not 0.0 <= v <= 1.0:
            raise EpisodeError(path, f"{where}: factors.{name}", f"must lie in [0, 1], got {v}")
    for key, n in (("alpha", 4), ("thresholds", 2)):
        v = _need(rec, key, list, where, path)
        if len(v) != n or not all(_num(x) for x in v):
            raise EpisodeError(path, f"{where}: {key}", f"must be a list of {n} finite numbers, got {v!r}")
    if any(a < 0 for a in rec["alpha"]):
        raise EpisodeError(path, f"{where}: alpha", f"has a negative entry: {rec['alpha']}")
    t = rec["thresholds"]
    if not t[0] < t[1]:
        raise EpisodeError(path, f"{where}: thresholds", f"must be increasing, got {t}")
    start = _need(rec, "start", dict, where, path)
    for k in ("x", "y", "yaw"):
        _need(start, k, "number", f"{where}: start", path)
    room = _need(rec, "goal_room", dict, where, path)
    _need(room, "id", str, f"{where}: goal_room", path)
    _need(room, "label", str, f"{where}: goal_room", path)
    view = _need(rec, "reference_view", dict, where, path)
    for k in ("x", "y", "z", "yaw", "pitch"):
        _need(view, k, "number", f"{where}: reference_view", path)
    oracle = _need(rec, "oracle", dict, where, path)
    _need(oracle, "appearance", str, f"{where}: oracle", path)
    _need(oracle, "region", str, f"{where}: oracle", path)
    _need(oracle, "facts", dict, f"{where}: oracle", path)
    hint = _need(rec, "memory_hint", dict, where, path)
    kind = _need(hint, "kind", str, f"{where}: memory_hint", path)
    if kind not in ("same_room_distractor", "nearest_distractor", "offset"):
        raise EpisodeError(path, f"{where}: memory_hint.kind", f"unknown kind {kind!r}")
    pos = _need(hint, "position", list, f"{where}: memory_hint", path)
    if len(pos) != 3 or not all(_num(x) for x in pos):
        raise EpisodeError(path, f"{where}: memory_hint.position", f"must be 3 finite numbers, got {pos!r}")
    leaked = sorted(LEAK_FIELDS & set(rec))
    if leaked:
        raise EpisodeError(path, f"{where}: {leaked[0]}", "construction-only field in a released record (it would leak the answer)")
    d = sum(a * f for a, f in zip(rec["alpha"], (factors[n] for n in FACTOR_NAMES)))
    if abs(d - rec["difficulty_score"]) > 1e-9:
        raise EpisodeError(path, f"{where}: difficulty_score", f"{rec['difficulty_score']} differs from alpha . factors = {d}")
    expected = BIN_NAMES[(d >= t[0]) + (d >= t[1])]
    if expected != diff:
        raise EpisodeError(path, f"{where}: difficulty", f"label {diff!r} does not match D = {d:.4f} with thresholds {t} ({expected!r})")
    return rec


def strip_record(rec: dict) -> dict:
    """The released part of a record (construction-only fields dropped)."""
    return {k: rec[k] for k in RELEASED_FIELDS if k in rec}


def _open(path: Path, mode: str, gz: bool | None = None):
    if path.name.endswith(".gz") if gz is None else gz:
        # mtime=0 and no file name in the header: the same records give the same bytes
        raw = open(path, mode.replace("t", "") + "b")
        gz = gzip.GzipFile(filename="", mode=mode.replace("t", "") + "b", fileobj=raw, mtime=0)
        return io.TextIOWrapper(gz, encoding="utf-8", newline="\n") if "t" in mode else gz
    return open(path, mode, encoding="utf-8", newline="\n")


def write_records(path: str | os.PathLike, records: Iterable[dict]) -> Path:
    """Write JSONL (gzipped when the name ends in .gz) atomically and
    deterministically (sorted keys, fixed float repr, no gzip timestamp)."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.with_name(f".{p.name}.tmp-{os.getpid()}")
    try:
        with _open(tmp, "wt", gz=p.name.endswith(".gz")) as f:
            for rec in records:
                f.write(json.dumps(rec, sort_keys=True, separators=(",", ":"), allow_nan=False) + "\n")
        os.replace(tmp, p)
    finally:
        if tmp.exists():
            tmp.unlink()
    return p


def iter_records(path: str | os.PathLike) -> Iterator[tuple[int, Any]]:
    """(line number, parsed JSON) for every non-blank line."""
    p = Path(path)
    if not p.exists():
        raise EpisodeError(p, None, "no such file")
    try:
        with _open(p, "rt") as f:
            for lineno, line in enumerate(f, 1):
                if not line.strip():
                    continue
                try:
                    yield lineno, json.loads(line)
                except json.JSONDecodeError as e:
                    raise EpisodeError(p, f"line {lineno}", f"invalid JSON: {e.msg}") from e
    except (OSError, EOFError, UnicodeDecodeError) as e:
        raise EpisodeError(p, None, f"cannot read as (gzipped) JSON Lines: {e}") from e


def read_episodes(path: str | os.PathLike) -> list[dict]:
    """Read and validate a released episode file (every record, unique ids).

    Raises:
        EpisodeError: naming the file, the line/episode and the field; also
            for an empty file.
    """
    out: list[dict] = []
    seen: dict[str, int] = {}
    for lineno, rec in iter_records(path):
        validate_record(rec, path, f"line {lineno}")
        eid = rec["episode_id"]
        if eid in seen:
            raise EpisodeError(path, f"line {lineno}: episode_id", f"duplicate id {eid!r} (first on line {seen[eid]})")
        seen[eid] = lineno
        out.append(rec)
    if not out:
        raise EpisodeError(path, None, "the episode file holds no episodes")
    return out


def construction_path(path: str | os.PathLike) -> Path:
    """The construction file that goes with an episode file:
    ``name.jsonl.gz`` -> ``name.construction.jsonl.gz``."""
    p = Path(path)
    name = p.name
    for suffix in (".jsonl.gz", ".jsonl", ".json.gz", ".json"):
        if name.endswith(suffix):
            return p.with_name(name[: -len(suffix)] + ".construction" + suffix)
    return p.with_name(name + ".construction")
