"""The page: a run (:class:`~ignjax.view.runfolder.Run`) -> one HTML file.

The data goes into the page as one JSON document (``<script
type="application/json">``) that the inline script (:mod:`ignjax.view.script`)
turns into the index and the episode pages; nothing is fetched. The JSON is
columnar per (agent, episode): one array per per-step field rather than one
object per step, coordinates rounded to 1 cm, yaws to 0.01 rad, discounts
to 0.001, which keeps a page of 500 episodes x 5 agents near 4 MB. Numbers
a reader compares with the outcome tables (final distance, path length)
are rounded to 1 cm too.

Words come from their one home: the oracle's answers from
:mod:`ignjax.sim.oracle_text` (wording keys ``"<episode id>:<step>"``),
labels from :mod:`ignjax.protocol` and :mod:`ignjax.scenes.vocab`, the
success rule and discount from :mod:`ignjax.evaluate.metrics`. Only the
questions of agents that ask by type alone (the JAX agents) are worded
here (:data:`QUESTION_TEXT`).
"""

from __future__ import annotations

import base64
import html
import json
import os
from pathlib import Path

import numpy as np

from ignjax import protocol
from ignjax.evaluate import metrics as M
from ignjax.fileio import atomic_write
from ignjax.scenes import vocab
from ignjax.sim import oracle_text as OT
from ignjax.sim import types as T
from ignjax.view.mapdata import attribute_codes, r2, scene_data
from ignjax.view.runfolder import Run
from ignjax.view.script import SCRIPT
from ignjax.view.style import STYLE, page_html

QUESTION_TEXT = ("What does the target look like?", "Which room is it in, and near what?",
                 "Which way should I go?", "Is this the target?")
"""The question an agent that asks by type alone puts, by type (1..4); a
Type-4 question about a listed instance is worded by the page with its name."""

IMAGE_MIME = {".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".png": "image/png"}


def _answer_text(rec: dict, t: int, q: int, tr: dict, i: int, categories: tuple[str, ...]) -> str:
    """The oracle's answer to the ASK of step ``t`` (type ``q``) in words."""
    if (q == 3 and "hint_sector" not in tr) or (q == 4 and "confirm" not in tr):
        return ""
    facts = {}
    if q == 3:
        facts = dict(hint_room_label=int(tr["hint_room_label"][i, t]), hint_sector=int(tr["hint_sector"][i, t]),
                     hint_landmark=int(tr["hint_landmark"][i, t]), hint_in_room=bool(tr["hint_in_room"][i, t]))
    elif q == 4:
        facts = dict(confirm=int(tr["confirm"][i, t]), follow_up=int(tr["follow_up"][i, t]))
    return OT.answer_text(q, "refused" in tr and bool(tr["refused"][i, t]), appearance=rec["oracle"]["appearance"],
                          region=rec["oracle"]["region"], categories=categories, key=f"{rec['episode_id']}:{t}", **facts)


def _data_uri(path: Path) -> str:
    mime = IMAGE_MIME[path.suffix.lower()]
    return f"data:{mime};base64," + base64.b64encode(path.read_bytes()).decode("ascii")


def _visible(tr: dict, i: int, t: int, truth: list[list[int]]) -> list:
    """Handles in sight at step ``t``; ``[handle, c, m, s, st]`` where the
    perceived attributes differ from the scene's (perception noise)."""
    out = []
    for k, h in enumerate(tr["visible"][i, t]):
        h = int(h)
        if h < 0:
            continue
        attrs = [int(v) for v in tr["visible_attrs"][i, t, k]] if "visible_attrs" in tr else None
        out.append([h] + attrs if attrs is not None and h < len(truth) and attrs != truth[h] else h)
    return out


def run_entry(run: Run, agent: str, i: int, rec: dict, truth: list[list[int]]) -> dict:
    """The page data of one agent on the i-th shown episode (see the module docstring)."""
    row = run.rows[(agent, rec["episode_id"])]
    tr = run.trajectories[agent]
    meta = run.meta
    n = min(int(row["steps"]), tr["kind"].shape[1])
    q = [int(row[f"q{t}"]) for t in range(1, 5)]
    succ = M.episode_success(np.array([row["final_distance"]]), np.array([row["stopped"]]), tuple(meta["thresholds"]),
                             bool(meta["require_stop"]), np.array([T.STOP_REASONS.index(row["stop_reason"])]))[0]
    pose = tr["pose"][i, : n + 1]
    kind = [int(k) for k in tr["kind"][i, :n]]
    qt = [int(v) for v in tr["question"][i, :n]]
    e = {"succ": [int(s) for s in succ], "disc": round(float(M.question_discount(np.array(q), meta["costs"])), 3),
         "q": q, "ref": int(row["n_refused"]), "stop": row["stop_reason"], "fd": r2(row["final_distance"]),
         "md": r2(row["min_distance"]), "pl": r2(row["path_length"]), "n": n,
         "pose": [v for p in pose for v in (r2(p[0]), r2(p[1]), r2(p[2]))], "k": kind, "qt": qt,
         "ans": [_answer_text(rec, t, qt[t], tr, i, run.categories) if kind[t] == T.ASK else "" for t in range(n)]}
    if "direction" in tr:
        e.update(d=[int(v) for v in tr["direction"][i, :n]], c=[int(v) for v in tr["col"][i, :n]],
                 r=[int(v) for v in tr["row"][i, :n]])
    if "waypoint" in tr:
        e["wp"] = [r2(v) for p in tr["waypoint"][i, :n] for v in p]
    if "blocked" in tr:
        e["bl"] = [int(sum(1 << k for k, b in enumerate(m) if b)) for m in tr["blocked"][i, :n]]
    if "n_questions" in tr:
        nq = np.asarray(tr["n_questions"][i, :n], np.int64).reshape(-1, 4)  # (0, 4) where no episode of a run stepped
        e["nq"] = [int(v) for v in nq.reshape(-1)]
        e["dc"] = [round(float(v), 3) for v in M.question_discount(nq, meta["costs"])]
    if "refused" in tr:
        e["rf"] = [t for t in range(n) if bool(tr["refused"][i, t])]
    if "candidate" in tr:
        e["cand"] = [int(v) for v in tr["candidate"][i, :n]]
    if "hint_progress" in tr:
        e["hp"] = [int(v) if kind[t] == T.MOVE else 0 for t, v in enumerate(tr["hint_progress"][i, :n])]
    if "room_label" in tr:
        e["rl"] = [int(v) for v in tr["room_label"][i, :n]]
    if "visible" in tr:
        e["vis"] = [_visible(tr, i, t, truth) for t in range(n)]
    images = run.images.get((agent, rec["episode_id"]), {})
    if images:
        e["img"] = {str(t): [_data_uri(f[k]) if k in f else "" for k in ("panel", "grounder")]
                    for t, f in sorted(images.items())}
    calls = run.transcripts.get((agent, rec["episode_id"]), [])
    if calls:
        by_step: dict[str, list] = {}
        for c in calls:
            by_step.setdefault(str(c["step"]), []).append(c)
        e["tx"] = by_step
    return e


def episode_entry(run: Run, i: int, rec: dict) -> dict:
    scene = run.scenes[rec["scene_id"]]
    index = {inst.id: k for k, inst in enumerate(scene.instances)}
    target = index.get(rec["target_id"], -1)
    distractors = [k for k, inst in enumerate(scene.instances)
                   if inst.category == rec["target_category"] and inst.id != rec["target_id"]]
    truth = [attribute_codes(inst) for inst in scene.instances]
    start = rec["start"]
    return {"id": rec["episode_id"], "scene": rec["scene_id"], "diff": rec["difficulty"],
            "cat": vocab.category_display(rec["target_category"]), "instr": rec["instruction"],
            "desc": rec["description"], "region": rec["goal_region"],
            "room": vocab.ROOM_DISPLAY.get(rec["goal_room"]["label"], rec["goal_room"]["label"]),
            "target": target, "distr": distractors, "start": [r2(start["x"]), r2(start["y"]), r2(start["yaw"])],
            "runs": [run_entry(run, a, i, rec, truth) for a in run.agents]}


def page_data(run: Run) -> dict:
    """Everything the page shows, as one JSON-able dict."""
    meta = run.meta
    sim = run.sim
    used = sorted({r["scene_id"] for r in run.records})
    return {
        "title": run.title, "agents": run.agents, "thresholds": [float(t) for t in meta["thresholds"]],
        "costs": [float(c) for c in meta["costs"]], "rule": M.success_rule(bool(meta["require_stop"])),
        "upfront": bool(sim.get("upfront_description", False)),
        "noise": bool(sim.get("miss_rate", 0) or sim.get("confusion_rate", 0)),
        "max_steps": int(sim.get("max_steps", protocol.MAX_STEPS)),
        "benchmark": Path(meta["episodes"]).name, "n_run_episodes": run.n_run_episodes,
        "images_left_out": run.images_left_out,
        "views": list(protocol.VIEW_NAMES), "qtypes": list(protocol.QUESTION_TYPES), "qtext": list(QUESTION_TEXT),
        "rooms": [vocab.ROOM_DISPLAY[label] for label in vocab.ALL_ROOM_LABELS],
        "attrs": [list(vocab.COLORS), list(vocab.MATERIALS), list(vocab.SIZES), list(vocab.STATES)],
        "hint": [OT.hint_progress_text(c) for c in range(len(T.HINT_PROGRESS))],
        "scenes": {sid: scene_data(run.scenes[sid]) for sid in used},
        "episodes": [episode_entry(run, i, rec) for i, rec in enumerate(run.records)],
    }


def build_page(run: Run) -> str:
    """The HTML text of the page (deterministic: the same run gives the same text)."""
    data = json.dumps(page_data(run), separators=(",", ":"), sort_keys=True, ensure_ascii=False)
    # "<" only occurs inside JSON strings, where "\u003c" reads the same; escaped, no text (a transcript's
    # "</script>" or "<!--") can end or change the element that holds the data
    data = data.replace("<", "\\u003c")
    return page_html(html.escape(f"{run.title}: ignjax episodes"), STYLE, SCRIPT, data)


def write_page(run: Run, out: str | os.PathLike) -> Path:
    """Write the page atomically (a temporary name, then renamed). Returns the path."""
    return atomic_write(out, build_page(run))


__all__ = ["QUESTION_TEXT", "build_page", "episode_entry", "page_data", "run_entry", "write_page"]
