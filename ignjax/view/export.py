"""One episode as an animated GIF or MP4, for slides and papers.

Frames are drawn with matplotlib (Agg): the scene's top-down map
(:func:`ignjax.scenes.viz.mapplot.plot_scene_map`, the target outlined in
gold and its distractors in orange), the path up to the frame's pose, the
agent and its heading, the step's waypoint, the places questions were
asked, and the step in words underneath (the same words as the page:
:func:`ignjax.view.page.run_entry`). One frame per pose: the start, then
one per planner step, the last one stating the outcome.

GIF is written with imageio's Pillow plugin (deterministic bytes); MP4
(H.264) needs the ``imageio-ffmpeg`` package, which ships its own ffmpeg
(``pip install imageio-ffmpeg``). Either file is written atomically.
"""

from __future__ import annotations

import math
import os
import textwrap
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ignjax.errors import ConfigError, InputError
from ignjax.fileio import atomic_write
from ignjax.protocol import QUESTION_TYPES, VIEW_NAMES
from ignjax.scenes.viz.mapplot import plot_scene_map
from ignjax.sim.oracle_text import hint_progress_text
from ignjax.sim.types import HINT_PROGRESS
from ignjax.view.mapdata import attribute_codes
from ignjax.view.page import QUESTION_TEXT, run_entry
from ignjax.view.runfolder import Run

FORMATS = (".gif", ".mp4")
QUESTION_COLORS = ("#7d3c98", "#e67e22", "#c0392b", "#27ae60")
FRAME_INCHES, FRAME_DPI = 6.4, 100
"""640 x 640 pixel frames: a multiple of 16 on each side, as H.264 encoders want."""


def step_words(entry: dict, t: int) -> str:
    """Step ``t`` of a :func:`~ignjax.view.page.run_entry` in words (the end when ``t == n``)."""
    n = entry["n"]
    if t >= n:
        ok = ", ".join("yes" if s else "no" for s in entry["succ"])
        how = "STOP" if entry["stop"] == "stop" else "the step budget"
        return (f"ended by {how} after {n} steps: distance {entry['fd']:.2f} m, success {ok}, "
                f"questions {'/'.join(map(str, entry['q']))}, WSR discount {entry['disc']:.3f}")
    k, q = entry["k"][t], entry["qt"][t]
    if k == 0:
        cell = f" {VIEW_NAMES[entry['d'][t]]} (col {entry['c'][t]}, row {entry['r'][t]})" if "d" in entry else ""
        text = f"step {t}: MOVE{cell}"
        progress = entry.get("hp", [0] * n)[t]
        return text + (f". {entry['hint_words'][progress]}" if progress > 0 else "")
    if k == 1:
        refused = " (refused)" if t in entry.get("rf", ()) else ""
        return f"step {t}: ASK Type {q} {QUESTION_TYPES[q - 1]}{refused}: {QUESTION_TEXT[q - 1]} Oracle: {entry['ans'][t]}"
    return f"step {t}: STOP"


def episode_frames(run: Run, episode_id: str, agent: str) -> list[np.ndarray]:
    """(H, W, 3) uint8 frames of one agent's episode (see the module docstring)."""
    ids = [r["episode_id"] for r in run.records]
    if episode_id not in ids:
        raise ConfigError(str(run.folder), "--gif", f"episode {episode_id!r} is not among the run's episodes shown "
                                                    f"({len(ids)}; e.g. {ids[0]!r})")
    if agent not in run.agents:
        raise ConfigError(str(run.folder), "--agent", f"agent {agent!r} is not in this run ({', '.join(run.agents)})")
    i = ids.index(episode_id)
    rec = run.records[i]
    scene = run.scenes[rec["scene_id"]]
    entry = run_entry(run, agent, i, rec, [attribute_codes(x) for x in scene.instances])
    entry["hint_words"] = [hint_progress_text(c) for c in range(len(HINT_PROGRESS))]
    n = entry["n"]
    pose = np.asarray(entry["pose"], float).reshape(n + 1, 3)
    same = [x.id for x in scene.instances if x.category == rec["target_category"] and x.id != rec["target_id"]]
    highlight = {**{iid: "orange" for iid in same}, rec["target_id"]: "gold"}
    fig = Figure(figsize=(FRAME_INCHES, FRAME_INCHES), dpi=FRAME_DPI)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0.06, 0.2, 0.9, 0.74))
    plot_scene_map(scene, ax=ax, show_labels=False, highlight=highlight,
                   title=f"{episode_id} ({rec['difficulty']}), {agent}")
    ax.plot(pose[0, 0], pose[0, 1], "o", ms=8, mfc="white", mec="black", zorder=12)
    for t in range(n):
        if entry["k"][t] == 1:
            ax.plot(pose[t, 0], pose[t, 1], "o", ms=7, color=QUESTION_COLORS[entry["qt"][t] - 1], mec="black", zorder=13)
    (path,) = ax.plot([], [], "-", color="#1f3b73", lw=2.0, zorder=14)
    (way,) = ax.plot([], [], "--", color="#555555", lw=1.0, zorder=14)
    (agent_dot,) = ax.plot([], [], "o", ms=10, color="#1f3b73", mec="white", zorder=15)
    (head,) = ax.plot([], [], "-", color="white", lw=2.0, zorder=16)
    words = fig.text(0.04, 0.16, "", va="top", ha="left", fontsize=9, family="sans-serif")
    frames = []
    for v in range(n + 1):
        x, y, yaw = pose[v]
        path.set_data(pose[: v + 1, 0], pose[: v + 1, 1])
        agent_dot.set_data([x], [y])
        head.set_data([x, x + 0.3 * math.cos(yaw)], [y, y + 0.3 * math.sin(yaw)])
        moving = v < n and entry["k"][v] == 0 and "wp" in entry
        way.set_data(([x, entry["wp"][2 * v]], [y, entry["wp"][2 * v + 1]]) if moving else ([], []))
        words.set_text("\n".join(textwrap.wrap(step_words(entry, v), 100)[:6]))
        canvas.draw()
        frames.append(np.asarray(canvas.buffer_rgba())[..., :3].copy())
    return frames


def export_episode(run: Run, episode_id: str, agent: str, out: str | os.PathLike, fps: float = 1.5) -> Path:
    """Write one agent's episode as ``out`` (``.gif`` or ``.mp4``). Returns the path.

    Raises:
        ConfigError: an unknown episode or agent, another suffix, a frame
            rate that is not positive, or MP4 without ``imageio-ffmpeg``.
    """
    out = Path(out)
    suffix = out.suffix.lower()
    if suffix not in FORMATS:
        raise ConfigError(str(out), "--out", f"the export is a .gif or an .mp4 file, not {out.suffix or 'no suffix'!r}")
    if not (isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0):
        raise ConfigError(None, "--fps", f"must be a positive number, got {fps!r}")
    if suffix == ".mp4":
        try:
            # optional, so imported here: only MP4 needs it
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            raise ConfigError(str(out), "--out", "MP4 needs the imageio-ffmpeg package (pip install imageio-ffmpeg); "
                                                 "a .gif needs nothing more") from None
    frames = np.stack(episode_frames(run, episode_id, agent))
    if suffix == ".gif":
        data = iio.imwrite("<bytes>", frames, extension=".gif", duration=int(round(1000 / fps)), loop=0)
    else:
        data = iio.imwrite("<bytes>", frames, extension=".mp4", fps=fps, codec="libx264", macro_block_size=16)
    if not data:
        raise InputError(out, None, "the encoder wrote nothing")
    return atomic_write(out, data)


__all__ = ["episode_frames", "export_episode", "step_words"]
