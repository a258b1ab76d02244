"""Reading a run folder for the viewer: outcomes, trajectories, the episode
records and scenes they refer to, and the optional images and transcripts
(the layout is in :mod:`ignjax.view`'s docstring).

Everything is read and checked here, before a page is built, so that a bad
folder fails with one error naming the file, the place and the reason and
nothing is written. The scenes are read with the scene readers alone
(:func:`ignjax.scenes.io.sources.load_scenes`): the viewer needs the scene
model for its map, not the navigation grids and geodesic fields
:func:`ignjax.episodes.dataset.load_benchmark` computes (45 s on the shipped
benchmark), and the category codes are decoded with the vocabulary stored
in ``trajectories.npz``.
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ignjax.episodes.schema import read_episodes
from ignjax.errors import ConfigError, IgnjaxError, InputError
from ignjax.evaluate.outcomes import TRAJECTORY_FILE, read_outcomes, read_trajectories
from ignjax.scenes.io.sources import load_scenes
from ignjax.scenes.model import Scene

IMAGE_DIR = "images"
TRANSCRIPT_FILE = "transcripts.jsonl"
TRANSCRIPT_DIR = "transcripts"
IMAGE_NAME = re.compile(r"^(\d+)_(panel|grounder)(?:_\d+)?\.(jpg|jpeg|png)$", re.IGNORECASE)
"""``<step>_<kind>.<ext>`` of an image file, or ``<step>_grounder_<view>.<ext>`` (the name runs wrote before the
Grounder's image was named like the panel's; see the module docstring of :mod:`ignjax.view`)."""
IMAGE_KINDS = ("panel", "grounder")
TRANSCRIPT_KEYS = ("agent", "episode", "step", "role", "prompt", "reply", "parsed", "retries", "error")
ROLES = ("planner", "grounder", "controller", "paraphrase", "caption")
"""Transcript roles: a Planner or Grounder call, a decision the agent's controller took without a model call, a
rewording of an oracle answer (``llm.paraphrase``), a caption of one view (``navgpt``)."""


@dataclass
class Run:
    """A run folder, read and checked.

    Attributes:
        folder: the run folder.
        title: the page title.
        meta: the trajectory file's metadata (episode file, categories,
            thresholds, costs, success rule, simulator settings).
        agents: the agents shown, in the run's order.
        records: the episode records shown, in the run's row order.
        rows: (agent, episode id) -> outcome row.
        trajectories: agent -> field -> array with one row per shown episode.
        scenes: scene id -> Scene of every shown episode.
        images: (agent, episode id) -> step -> kind -> image file.
        transcripts: (agent, episode id) -> transcript records in file order.
        images_left_out: episodes (over all agents) whose images exist but are
            not embedded (``--episodes`` was not given).
        n_run_episodes: episodes in the run (shown or not).
    """

    folder: Path
    title: str
    meta: dict
    agents: list[str]
    records: list[dict]
    rows: dict
    trajectories: dict
    scenes: dict[str, Scene]
    images: dict = field(default_factory=dict)
    transcripts: dict = field(default_factory=dict)
    images_left_out: int = 0
    n_run_episodes: int = 0

    @property
    def categories(self) -> tuple[str, ...]:
        return tuple(self.meta["categories"])

    @property
    def sim(self) -> dict:
        return self.meta.get("sim") or {}


def check_run_folder(folder: str | os.PathLike) -> Path:
    """The outcome table of a run folder (Parquet first, else CSV).

    Raises:
        InputError: the path is missing, not a folder, or holds no outcome
            table or no trajectory file.
    """
    p = Path(folder)
    if not p.exists():
        raise InputError(p, None, "no such folder")
    if not p.is_dir():
        raise InputError(p, None, "not a folder: give the run folder that python -m ignjax.evaluate or "
                                  "python -m ignjax.sweep wrote")
    table = next((p / n for n in ("outcomes.parquet", "outcomes.csv") if (p / n).is_file()), None)
    if table is None:
        raise InputError(p, None, "not a run folder: it has no outcomes.parquet or outcomes.csv (write one with "
                                  "python -m ignjax.evaluate or python -m ignjax.sweep)")
    if not (p / TRAJECTORY_FILE).is_file():
        raise InputError(p / TRAJECTORY_FILE, None, "missing: the run was written without trajectories (before the "
                                                    "viewer existed); run it again to view it")
    return table


def _title(folder: Path) -> str:
    try:
        run = json.loads((folder / "run.json").read_text())
        name = run.get("config", {}).get("run", {}).get("name")
        if isinstance(name, str) and name:
            return name
    except (OSError, ValueError, AttributeError):
        pass
    return folder.resolve().name


def _scene_file(name: str, episode_file: Path, scenes_root: Path | None) -> Path:
    """Where a record's ``scene_file`` is: absolute, next to the episode file, or under ``scenes_root``
    (the rule of :func:`ignjax.episodes.dataset.load_benchmark`)."""
    p = Path(name)
    candidates = [p] if p.is_absolute() else [episode_file.parent / p] + (
        [scenes_root / p, scenes_root / p.name] if scenes_root else [])
    return next((c for c in candidates if c.exists()), candidates[0])


def _load_scenes(records: list[dict], episode_file: Path, scenes_root: Path | None) -> dict[str, Scene]:
    by_file: dict[Path, set[str]] = {}
    for rec in records:
        by_file.setdefault(_scene_file(rec["scene_file"], episode_file, scenes_root), set()).add(rec["scene_id"])
    scenes: dict[str, Scene] = {}
    for f, ids in sorted(by_file.items(), key=lambda kv: str(kv[0])):
        try:
            loaded = {s.id: s for s in load_scenes(f)}
        except IgnjaxError as e:
            raise InputError(episode_file, "scene_file", f"cannot load scene file {str(f)!r}: {e} "
                                                         "(--scenes-root tells where the scenes are)") from e
        for sid in sorted(ids):
            if sid not in loaded:
                raise InputError(f, None, f"scene {sid!r} not found (the file holds {sorted(loaded)})")
            scenes[sid] = loaded[sid]
    return scenes


def _images(folder: Path, agent: str, episode_id: str) -> dict[int, dict[str, Path]]:
    d = folder / IMAGE_DIR / agent / Path(*episode_id.split("/"))
    out: dict[int, dict[str, Path]] = {}
    if d.is_dir():
        for f in sorted(d.iterdir()):
            m = IMAGE_NAME.match(f.name)
            if m and f.is_file():
                out.setdefault(int(m.group(1)), {})[m.group(2).lower()] = f
    return out


def transcript_files(folder: Path) -> list[Path]:
    files = [folder / TRANSCRIPT_FILE] if (folder / TRANSCRIPT_FILE).is_file() else []
    if (folder / TRANSCRIPT_DIR).is_dir():
        files += sorted(f for f in (folder / TRANSCRIPT_DIR).iterdir() if f.suffix == ".jsonl" and f.is_file())
    return files


def read_transcripts(folder: Path) -> dict[tuple[str, str], list[dict]]:
    """(agent, episode id) -> the transcript records of a run folder, in file order.

    Raises:
        InputError: naming the file and line of a record that is not valid
            JSON or lacks a key of the schema (module docstring of :mod:`ignjax.view`).
    """
    out: dict[tuple[str, str], list[dict]] = {}
    for f in transcript_files(folder):
        with open(f, encoding="utf-8") as fh:
            for n, line in enumerate(fh, 1):
                if not line.strip():
                    continue
                try:
                    rec = json.loads(line)
                except json.JSONDecodeError as e:
                    raise InputError(f, f"line {n}", f"not JSON: {e.msg}") from e
                if not isinstance(rec, dict):
                    raise InputError(f, f"line {n}", "expected a JSON object")
                missing = [k for k in TRANSCRIPT_KEYS if k not in rec]
                if missing:
                    raise InputError(f, f"line {n}", f"missing keys {missing}")
                bad = [k for k in ("agent", "episode", "prompt", "reply") if not isinstance(rec[k], str)]
                if bad or isinstance(rec["step"], bool) or not isinstance(rec["step"], int) or rec["step"] < 0:
                    raise InputError(f, f"line {n}", f"{(bad or ['step'])[0]}: wrong type (agent, episode, prompt "
                                                     "and reply are strings, step a non-negative integer)")
                if rec["role"] not in ROLES:
                    raise InputError(f, f"line {n}: role", f"{rec['role']!r}; expected one of {list(ROLES)}")
                retries = rec["retries"]
                if not (isinstance(retries, int) and not isinstance(retries, bool) and retries >= 0) and not (
                        isinstance(retries, list) and all(isinstance(r, dict) for r in retries)):
                    raise InputError(f, f"line {n}: retries", "expected a count or a list of {reply, error} objects")
                if rec["error"] is not None and not isinstance(rec["error"], str):
                    raise InputError(f, f"line {n}: error", "expected a string or null")
                out.setdefault((rec["agent"], rec["episode"]), []).append(
                    {k: rec[k] for k in TRANSCRIPT_KEYS if k not in ("agent", "episode")})
    return out


def read_run(folder: str | os.PathLike, agents: list[str] | None = None, episodes: int | None = None, *,
             benchmark: str | os.PathLike | None = None, scenes_root: str | os.PathLike | None = None,
             scenes: dict[str, Scene] | None = None, title: str | None = None) -> Run:
    """Read and check a run folder.

    Args:
        agents: agents to show (default: every agent of the run).
        episodes: show the first N episodes of the run, with their images
            (default: every episode, without images).
        benchmark: the episode file, when it is not where the run says.
        scenes_root: where to look for scene files the episode file names.
        scenes: scene id -> Scene already in memory (the sweep's), instead of
            reading the scene files.
        title: the page title (default: see :func:`_title`).

    Raises:
        InputError / ConfigError: naming the path or option and the reason.
    """
    if episodes is not None and (isinstance(episodes, bool) or not isinstance(episodes, int) or episodes <= 0):
        raise ConfigError(None, "--episodes", f"must be a positive number of episodes, got {episodes!r}")
    folder = Path(folder)
    table = check_run_folder(folder)
    meta, trajectories = read_trajectories(folder / TRAJECTORY_FILE)
    run_agents = list(meta["agents"])
    agents = list(dict.fromkeys(agents)) if agents else run_agents
    for a in agents:
        if a not in run_agents:
            raise ConfigError(str(folder), "--agent", f"agent {a!r} is not in this run (it has {', '.join(run_agents)})")
    agents = [a for a in run_agents if a in agents]
    ids = list(meta["episode_ids"])
    n_shown = len(ids) if episodes is None else min(episodes, len(ids))
    shown = ids[:n_shown]
    episode_file = Path(benchmark) if benchmark else Path(meta["episodes"])
    if not episode_file.is_file():
        raise InputError(episode_file, None, "episode file of the run not found (--benchmark gives another path)")
    by_id = {r["episode_id"]: r for r in read_episodes(episode_file)}
    missing = [e for e in shown if e not in by_id]
    if missing:
        raise InputError(episode_file, f"episode {missing[0]}", f"the run has {len(missing)} episode(s) the file lacks")
    records = [by_id[e] for e in shown]
    root = Path(scenes_root) if scenes_root else (Path(meta["scenes_root"]) if meta.get("scenes_root") else None)
    if scenes is None:
        scenes = _load_scenes(records, episode_file, root)
    else:
        lacking = sorted({r["scene_id"] for r in records} - set(scenes))
        if lacking:
            raise InputError(episode_file, "scene_id", f"scenes {lacking} were not given")
    rows = {(r["agent"], r["episode_id"]): r for r in read_outcomes(table) if r["agent"] in agents}
    for a in agents:
        for e in shown:
            if (a, e) not in rows:
                raise InputError(table, f"agent {a!r}, episode {e!r}", "no outcome row for an episode of the trajectories")
    traj = {a: {k: np.asarray(v)[:n_shown] for k, v in trajectories[a].items()} for a in agents}
    images: dict = {}
    left_out = 0
    for a in agents:
        for e in shown:
            found = _images(folder, a, e)
            if found and episodes is not None:
                images[(a, e)] = found
            elif found:
                left_out += 1
    shown_set = set(shown)
    transcripts = {k: v for k, v in read_transcripts(folder).items() if k[0] in agents and k[1] in shown_set}
    return Run(folder=folder, title=title or _title(folder), meta=meta, agents=agents, records=records, rows=rows,
               trajectories=traj, scenes=scenes, images=images, transcripts=transcripts, images_left_out=left_out,
               n_run_episodes=len(ids))


__all__ = ["Run", "check_run_folder", "read_run", "read_transcripts", "transcript_files"]
