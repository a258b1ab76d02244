"""Interaction analyses (paper §4.3): when questions are asked, where Type-3
questions arise, how questioning grows with difficulty, and how much a
Type-3 answer shrinks the explored area.

Inputs
    *Question events* (:func:`events_from_rows` from an outcome table's
    ``trace`` column, or :func:`events_from_trajectory` from a rollout's
    :class:`~ignjax.sim.types.Trajectory`): a dict of flat arrays ``episode``,
    ``type`` (1..4), ``step`` (0-based planner step of the ASK), ``charged``,
    plus per-episode ``steps_used`` and ``difficulty`` (0 easy, 1 medium,
    2 hard; -1 unknown). *Poses*: ``Trajectory.pose`` (E, S + 1, 3), the pose
    before step 0 and after every step, so the question asked at step ``s``
    is asked at ``pose[s]``. Episode ``e`` of the events is row ``e`` of the
    poses.

Question timing (:func:`question_timing`)
    Normalised progress of a question = ``step / steps_used`` in [0, 1)
    (0 = asked at the first step); histogram per type.

Type-3 location
    Where each Type-3 question was asked (corridor, junction, dead end,
    room): :mod:`ignjax.studies.locations`.

Type-3 content (:func:`classify_question`, :func:`type3_content`)
    What a Type-3 question asked, from its text (the paper's split: explicit
    route requests, the spatial position of the goal room, relations
    between rooms). Only agents that write their questions have texts
    (TANDEM and the baselines built on it: the transcript's ``question``,
    :func:`ignjax.evaluate.accounting.question_texts`); for the others (the
    JAX-native agents, ``vlm``) the split is not applicable and no count is
    made. The classifier is a fixed list of patterns, tried on the
    lower-cased text with runs of spaces made one, in this order; the first
    class with a match wins:

    1. ``route`` (how to travel): "which way", "what way", "how do/can/
       should I get/go/reach/head", "how to get/go/reach", "path", "route",
       "next turn", "which turn", "should I turn/go/head/take", "where
       should/do/can I go/head/walk/turn", "direction(s) to", "way to",
       "get to";
    2. ``room_relations`` (rooms among themselves): "next to", "adjacent",
       "connect..." (connects, connected, connection), "between", "beyond",
       "neighbo(u)r...", "lead(s) to/into", "open(s) to/into/onto",
       "relative to", "other side of", "across from", "from the <room>",
       "behind/past/after the <room>" (<room>: a room label of
       :data:`~ignjax.scenes.vocab.ROOM_LABELS`, or room, hall, corridor);
    3. ``goal_room_position`` (where the goal room or target lies): "where
       is/are/'s", "which/what room/part/side/area/wing/floor", "in which
       room/part/area", "located", "location", "which direction is", "how
       far", "is the/this/that/it <room>", "am I/are we in/near/close to/
       far from", "goal room", "target room";
    4. otherwise ``unclassified``.

    So "Which way is the kitchen?" is a route request and "Where is the
    kitchen relative to the hallway?" a relation. A question asked without
    text (TANDEM's controller asks for a route hint on its own after
    several moves without one) is counted apart (``n_without_text``), in
    no class. Shares are over the three content classes (as the paper's
    10/65/25 %).

Questions per difficulty (:func:`questions_per_difficulty`)
    Mean |Q| and mean Q_t per difficulty bin over valid episodes.

Delta-U (:func:`delta_u`, paper §4.3)
    The paper: A_noQA is the area explored before a Type-3 question, A_QA
    the area explored over a matched horizon after incorporating the
    answer, ``Delta-U = (A_noQA - A_QA) / A_noQA``. Here, for a Type-3
    question at step ``s`` of an episode that used ``n`` steps, the
    horizon is ``m = min(h, s)`` planner steps (default h = 5; m = 0 when
    the question is asked at the episode's last step, ``s = n - 1``, whose
    answer is never used): the
    *before* path is ``pose[s - m .. s]`` (the m steps before the question),
    the *after* path the same m steps after the ASK, ``pose[s + 1 ..
    s + 1 + m]``, cut at the episode's end (``pose[n]``): an episode that
    ends within the horizon explores nothing more, so an answer that leads
    the agent to stop soon shrinks A_QA (the horizon is matched to the
    before window, not shortened to the steps left, which would hide that).
    The explored area of a path is the area of the coverage cells (``cell``
    = 0.25 m squares on a world-aligned lattice) whose centre lies within
    ``r`` (default 1 m, a short sensing radius) of the path polyline (the
    segments between consecutive poses, so long MOVEs sweep their whole
    segment): ``A = cell^2 * #cells``, at least the area of one disc of
    radius r, so Delta-U <= 1 - (that disc) / A_noQA and A_noQA > 0.
    Means per difficulty pool the questions of the bin. Questions with
    ``m < min_horizon`` (default 1) are left out (``delta_u`` NaN, never
    counted as zero): one asked before any horizon exists (at step 0; with
    ``min_horizon=3`` also steps 1-2) and one whose answer is never used
    (asked at the last step). ASK steps inside either window
    count as steps that explore nothing, as they do in the episode.
"""

from __future__ import annotations

import math
import re

import numpy as np

from ignjax.errors import ConfigError, InputError
from ignjax.evaluate.outcomes import parse_trace
from ignjax.protocol import BIN_NAMES
from ignjax.scenes.vocab import ROOM_DISPLAY, ROOM_LABELS
from ignjax.studies._common import as_array, class_counts
from ignjax.studies.locations import UNKNOWN

CONTENT_CLASSES: tuple[str, ...] = ("route", "goal_room_position", "room_relations", "unclassified")
"""What a Type-3 question asked (module docstring, "Type-3 content")."""
ROUTE_REQUEST, GOAL_ROOM_POSITION, ROOM_RELATIONS, UNCLASSIFIED = range(4)


# ---------------------------------------------------------------------------
# Question events
# ---------------------------------------------------------------------------


def _difficulty_index(value) -> int:
    if isinstance(value, str):
        return BIN_NAMES.index(value) if value in BIN_NAMES else -1
    try:
        v = int(value)
    except (TypeError, ValueError):
        return -1
    return v if 0 <= v < 3 else -1


def events_from_rows(rows: list[dict], *, agent: str | None = None, include_refused: bool = False) -> dict:
    """Question events of one agent from outcome-table rows
    (:func:`ignjax.evaluate.outcomes.read_outcomes`).

    Args:
        rows: table rows (episode ``e`` = the e-th row of the agent).
        agent: the agent to keep; required when the rows hold several.
        include_refused: keep questions refused for budget (not charged).

    Returns:
        dict with ``episode``, ``type``, ``step`` (N,) int64, ``charged`` (N,)
        bool, ``steps_used`` (E,), ``difficulty`` (E,) int64, ``episode_id`` (E,).
    """
    agents = sorted({str(r.get("agent", "")) for r in rows})
    if agent is None and len(agents) > 1:
        raise InputError(None, "agent", f"the rows hold several agents {agents}; name the one to analyse")
    if agent is not None:
        rows = [r for r in rows if str(r.get("agent", "")) == agent]
        if not rows:
            raise InputError(None, "agent", f"no row of agent {agent!r}; agents are {agents}")
    ep, ty, st, ch = [], [], [], []
    for e, r in enumerate(rows):
        try:
            trace = parse_trace(r.get("trace", ""))
        except ValueError as err:
            raise InputError(None, f"rows[{e}].trace", f"cannot parse {r.get('trace')!r}: {err}") from err
        for t, s, c in trace:
            if c or include_refused:
                ep.append(e), ty.append(t), st.append(s), ch.append(c)
    return {
        "episode": np.asarray(ep, np.int64), "type": np.asarray(ty, np.int64), "step": np.asarray(st, np.int64),
        "charged": np.asarray(ch, bool), "steps_used": np.asarray([int(r["steps"]) for r in rows], np.int64),
        "difficulty": np.asarray([_difficulty_index(r.get("difficulty")) for r in rows], np.int64),
        "episode_id": np.asarray([str(r.get("episode_id", "")) for r in rows]),
    }


def events_from_trajectory(trajectory, difficulty=None) -> dict:
    """Question events from a rollout's trajectories.

    Args:
        trajectory: a :class:`~ignjax.sim.types.Trajectory` (or any object with
            ``kind`` (E, S) and ``question`` (E, S)); every ASK step is an
            event (a trajectory does not record whether it was charged, so
            ``charged`` is all True and refused questions are included).
        difficulty: optional (E,) bin per episode.

    Returns:
        the dict of :func:`events_from_rows` (``steps_used`` = steps with
        ``kind >= 0``).
    """
    kind = as_array(trajectory.kind, "trajectory.kind", ndim=2)
    q = as_array(trajectory.question, "trajectory.question", ndim=2)
    if q.shape != kind.shape:
        raise InputError(None, "trajectory.question", f"must match kind's shape {kind.shape}, got {q.shape}")
    E = kind.shape[0]
    e, s = np.nonzero(q > 0)
    if difficulty is None:
        d = np.full(E, -1, np.int64)
    else:
        d = as_array(difficulty, "difficulty", ndim=1).astype(np.int64)
        if d.shape != (E,):
            raise InputError(None, "difficulty", f"must have shape ({E},), got {d.shape}")
    return {"episode": e.astype(np.int64), "type": q[e, s].astype(np.int64), "step": s.astype(np.int64),
            "charged": np.ones(len(e), bool), "steps_used": (kind >= 0).sum(1).astype(np.int64), "difficulty": d,
            "episode_id": np.asarray([str(i) for i in range(E)])}


def counts_from_events(events: dict) -> np.ndarray:
    """(E, 4) questions per type per episode."""
    E = len(events["steps_used"])
    out = np.zeros((E, 4), np.int64)
    np.add.at(out, (events["episode"], events["type"] - 1), 1)
    return out


# ---------------------------------------------------------------------------
# Timing
# ---------------------------------------------------------------------------


def question_timing(events: dict, bins: int = 10) -> dict:
    """Histogram per type of the normalised progress ``step / steps_used``.

    Returns:
        dict with ``edges`` (bins + 1,), ``counts`` (4, bins), ``share`` (4, bins)
        fraction of each type's questions per bin (NaN for a type never
        asked), ``n`` (4,) questions per type, ``episodes_with_type`` (4,)
        fraction of episodes asking the type at least once, ``progress`` and
        ``type`` (N,) per question.
    """
    if not isinstance(bins, (int, np.integer)) or bins < 1:
        raise ConfigError(None, "bins", f"must be a positive integer, got {bins!r}")
    ep, ty, st = events["episode"], events["type"], events["step"]
    used = np.asarray(events["steps_used"])[ep]
    if np.any(st >= used) or np.any(st < 0):
        k = int(np.argmax((st >= used) | (st < 0)))
        raise InputError(None, f"events[{k}]", f"question step {int(st[k])} outside the episode's {int(used[k])} steps")
    progress = st / np.maximum(used, 1)
    idx = np.clip(np.floor(progress * bins).astype(np.int64), 0, bins - 1)
    counts = np.zeros((4, bins), np.int64)
    np.add.at(counts, (ty - 1, idx), 1)
    n = counts.sum(1)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(n[:, None] > 0, counts / np.maximum(n, 1)[:, None], np.nan)
    E = len(events["steps_used"])
    asked = counts_from_events(events) > 0
    return {"edges": np.linspace(0, 1, bins + 1), "counts": counts, "share": share, "n": n,
            "episodes_with_type": asked.mean(0) if E else np.full(4, np.nan), "progress": progress, "type": ty}


# ---------------------------------------------------------------------------
# Type-3 content
# ---------------------------------------------------------------------------

_ROOMS = "|".join(sorted({ROOM_DISPLAY[r] for r in ROOM_LABELS} | {"room", "hall", "corridor"}, key=len, reverse=True))
_CONTENT_RULES = (
    (ROUTE_REQUEST, re.compile(
        r"\b(which|what) way\b|\bhow (do|can|should|would|could) (i|we) (get|go|reach|head|find)\b"
        r"|\bhow to (get|go|reach)\b|\b(path|paths|route|routes)\b|\b(next|which) turn\b"
        r"|\bshould (i|we) (turn|go|head|take)\b|\bwhere (should|do|can|must) (i|we) (go|head|walk|turn)\b"
        r"|\bdirections? to\b|\bway to\b|\bget to\b")),
    (ROOM_RELATIONS, re.compile(
        r"\bnext to\b|\badjacent\b|\bconnect(s|ed|ing|ion|ions)?\b|\bbetween\b|\bbeyond\b"
        r"|\bneighbou?r(s|ing|ed)?\b|\bleads? (in)?to\b|\bopens? (in|on)?to\b|\brelative to\b"
        r"|\bother side of\b|\bacross from\b"
        rf"|\bfrom the ({_ROOMS})s?\b|\b(behind|past|after) the ({_ROOMS})s?\b")),
    (GOAL_ROOM_POSITION, re.compile(
        r"\bwhere('s| is| are)\b|\b(which|what) (room|part|side|area|wing|floor)\b|\bin which (room|part|area)\b"
        r"|\blocated\b|\blocation\b|\bwhich direction is\b|\bhow far\b"
        rf"|\bis (the |this |that |it )?({_ROOMS})\b|\b(am i|are we) (in|near|close to|far from)\b"
        r"|\b(goal|target) room\b")),
)


def classify_question(text: str) -> int:
    """Content class of one Type-3 question's text: an index into
    :data:`CONTENT_CLASSES` (the rules of the module docstring, "Type-3
    content"; ``unclassified`` for text that no rule matches, empty text
    included)."""
    t = " ".join(str(text or "").lower().replace("\u2019", "'").split())
    for cls, pattern in _CONTENT_RULES:
        if pattern.search(t):
            return cls
    return UNCLASSIFIED


def type3_content(events: dict, texts: dict | None, *, reason: str = "") -> dict:
    """What every Type-3 question asked (module docstring, "Type-3 content").

    Args:
        events: question events (:func:`events_from_rows` / :func:`events_from_trajectory`).
        texts: ``(episode index, step) -> question text`` of the agent's ASK
            decisions (a question missing from it, or with "", was asked
            without text); None: the agent writes no question texts, and the
            split is not applicable.
        reason: why it is not applicable (with ``texts`` None), for reports.

    Returns:
        dict with ``applicable``; if False only ``reason``, ``classes`` and
        ``n`` (Type-3 questions); otherwise per-question ``episode``,
        ``step``, ``text`` and ``cls`` (-1 without text), ``classes``
        (:data:`CONTENT_CLASSES`), ``counts`` (4,) over the questions with
        text, ``n_without_text``, ``n``, ``fractions`` (3,) of the three
        content classes over the questions they hold (NaN if none) and
        ``counts_by_difficulty`` (3, 4).
    """
    sel = events["type"] == 3
    ep, st = events["episode"][sel], events["step"][sel]
    if texts is None:
        return {"applicable": False, "reason": reason or "the agent's questions carry no text",
                "classes": CONTENT_CLASSES, "n": int(sel.sum())}
    txt = [str(texts.get((int(e), int(s)), "") or "") for e, s in zip(ep, st)]
    cls = np.asarray([classify_question(t) if t.strip() else UNKNOWN for t in txt], np.int64)
    known, counts, by_d = class_counts(cls, np.asarray(events["difficulty"])[ep])
    n3 = counts[:3].sum()
    return {"applicable": True, "episode": ep, "step": st, "text": txt, "cls": cls, "classes": CONTENT_CLASSES,
            "counts": counts, "n_without_text": int((~known).sum()), "n": int(len(ep)),
            "fractions": counts[:3] / n3 if n3 else np.full(3, np.nan), "counts_by_difficulty": by_d}


# ---------------------------------------------------------------------------
# Questions per difficulty
# ---------------------------------------------------------------------------


def questions_per_difficulty(n_questions, difficulty, valid=None) -> dict:
    """Mean questions per episode by difficulty bin.

    Args:
        n_questions: (..., E, 4) counts (leading axes: agents...).
        difficulty: (..., E) or (E,) bin indices (0..2; others ignored).
        valid: optional mask like ``difficulty``.

    Returns:
        dict with ``mean_total`` (..., 3), ``mean_per_type`` (..., 3, 4) (NaN
        for an empty bin) and ``count`` (..., 3).
    """
    n = as_array(n_questions, "n_questions", last=4, dtype=np.float64, finite=True)
    if n.ndim < 2:
        raise InputError(None, "n_questions", f"must be (..., E, 4), got shape {n.shape}")
    d = as_array(difficulty, "difficulty")
    try:
        d = np.broadcast_to(d, n.shape[:-1])
        v = np.ones(n.shape[:-1], bool) if valid is None else np.broadcast_to(np.asarray(valid, bool), n.shape[:-1])
    except ValueError as e:
        raise InputError(None, "difficulty", f"shape {np.shape(difficulty)} does not match n_questions {n.shape}") from e
    oh = ((d[..., None] == np.arange(3)) & v[..., None]).astype(np.float64)  # (..., E, 3)
    count = oh.sum(-2)
    per = np.einsum("...et,...eg->...gt", n, oh)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count[..., None] > 0, per / np.maximum(count, 1)[..., None], np.nan)
    return {"mean_total": mean.sum(-1), "mean_per_type": mean, "count": count.astype(np.int64)}


# ---------------------------------------------------------------------------
# Delta-U
# ---------------------------------------------------------------------------


def explored_area(xy, r: float = 1.0, cell: float = 0.25) -> float:
    """Area (m^2) of the ``cell`` x ``cell`` lattice squares (lattice aligned
    with the world origin) whose centre lies within ``r`` of the polyline
    through the points ``xy`` (M, 2) (a single point: a disc)."""
    p = as_array(xy, "xy", ndim=2, last=2, dtype=np.float64, finite=True)
    if p.shape[0] == 0:
        return 0.0
    lo = np.floor((p.min(0) - r) / cell).astype(np.int64)
    hi = np.floor((p.max(0) + r) / cell).astype(np.int64)
    ix, iy = np.meshgrid(np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1), indexing="ij")
    c = (np.stack([ix.ravel(), iy.ravel()], -1) + 0.5) * cell  # (C, 2) centres
    a = p[:-1] if len(p) > 1 else p
    b = p[1:] if len(p) > 1 else p
    ab = b - a  # (G, 2)
    L2 = (ab * ab).sum(1)
    t = np.clip(((c[:, None, :] - a[None]) * ab[None]).sum(-1) / np.where(L2 > 0, L2, 1.0)[None], 0.0, 1.0)
    q = a[None] + t[..., None] * ab[None]
    d2 = ((c[:, None, :] - q) ** 2).sum(-1).min(1)
    return float((d2 <= r * r + 1e-12).sum() * cell * cell)


def delta_u(poses, events: dict, *, h: int = 5, r: float = 1.0, cell: float = 0.25, min_horizon: int = 1) -> dict:
    """Explored-area uncertainty proxy of every Type-3 question (module doc).

    Args:
        poses: (E, S + 1, 2 or 3) trajectory poses.
        events: question events (only Type 3 are used).
        h: horizon in planner steps; r: coverage radius, m; cell: lattice
            size, m; min_horizon: shortest horizon kept (questions at
            steps below it have no before window worth the name).

    Returns:
        dict with per-question ``episode``, ``step``, ``horizon`` (m),
        ``area_before`` (A_noQA, m^2), ``area_after`` (A_QA, m^2), ``delta_u``
        (NaN where left out: horizon too short, or asked at the last step),
        ``difficulty``; and ``mean``,
        ``median`` (3,) per difficulty over the kept questions (NaN if none),
        ``count`` (3,), ``mean_all``, ``n_kept``, ``h``, ``r``, ``cell``.
    """
    if not isinstance(h, (int, np.integer)) or h < 1:
        raise ConfigError(None, "delta_u.h", f"must be a positive integer, got {h!r}")
    for name, val in (("r", r), ("cell", cell)):
        if not isinstance(val, (int, float)) or not math.isfinite(val) or val <= 0:
            raise ConfigError(None, f"delta_u.{name}", f"must be a positive number, got {val!r}")
    pz = as_array(poses, "poses", ndim=3, dtype=np.float64)
    sel = events["type"] == 3
    ep, st = events["episode"][sel], events["step"][sel]
    used = np.asarray(events["steps_used"])[ep]
    if ep.size and ((used + 1).max() > pz.shape[1] or ep.max() >= pz.shape[0]):
        raise InputError(None, "poses", f"shape {pz.shape} does not cover the episodes' steps")
    n = len(ep)
    horizon = np.where(st < used - 1, np.minimum(h, st), 0)  # no step after the answer: no horizon
    a0 = np.full(n, np.nan)
    a1 = np.full(n, np.nan)
    for i in range(n):
        m, s, e, u = int(horizon[i]), int(st[i]), int(ep[i]), int(used[i])
        if m < min_horizon:
            continue
        a0[i] = explored_area(pz[e, s - m:s + 1, :2], r, cell)
        a1[i] = explored_area(pz[e, s + 1:min(s + 1 + m, u) + 1, :2], r, cell)
    with np.errstate(invalid="ignore", divide="ignore"):
        du = (a0 - a1) / a0
    diff = np.asarray(events["difficulty"])[ep]
    kept = np.isfinite(du)
    mean, med, cnt = np.full(3, np.nan), np.full(3, np.nan), np.zeros(3, np.int64)
    for g in range(3):
        m = kept & (diff == g)
        cnt[g] = m.sum()
        if cnt[g]:
            mean[g], med[g] = du[m].mean(), np.median(du[m])
    return {"episode": ep, "step": st, "horizon": horizon, "area_before": a0, "area_after": a1, "delta_u": du,
            "difficulty": diff, "mean": mean, "median": med, "count": cnt,
            "mean_all": float(du[kept].mean()) if kept.any() else float("nan"), "n_kept": int(kept.sum()),
            "h": int(h), "r": float(r), "cell": float(cell)}


__all__ = ["CONTENT_CLASSES", "UNKNOWN", "events_from_rows",
           "events_from_trajectory", "counts_from_events", "question_timing", "classify_question", "type3_content",
           "questions_per_difficulty", "explored_area", "delta_u"]
