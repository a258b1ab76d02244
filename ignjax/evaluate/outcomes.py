"""Outcome tables: one row per (agent, episode), written as Parquet and CSV.

Columns (both formats):

==================  ==========================================================
agent               agent name (plus a setting label in sweeps)
episode_id          episode id (from the episode file)
scene_id            scene
difficulty          easy / medium / hard
final_distance      geodesic distance to the target at the end, m
final_euclidean     2-D distance to the target's footprint at the end, m
min_distance        smallest geodesic distance along the path, m (for OSR)
path_length         metres travelled
steps               planner steps used
stopped             ended with a STOP action
stop_reason         running / stop / step_budget
q1, q2, q3, q4      charged questions per type
n_questions         their sum
n_refused           questions refused (budget spent), not charged
n_invalid           out-of-range actions clamped
trace               question attempts as "type@step" (charged) or
                    "type@step!" (refused), separated by spaces
requests ...        MLLM agents' model-call accounting
                    (:data:`ACCOUNTING_COLUMNS`; zero for JAX-native agents)
cost_usd            the episode's tokens at ``llm.prices`` (USD; cache hits
                    included, as their tokens are; NaN for an MLLM agent
                    without prices, 0 for a JAX-native agent)
==================  ==========================================================

Everything the metrics need is in these columns: :func:`metric_rows`
recomputes SR, OSR, NE, TL, Q_t, |Q| and WSR from a table read back from
either file (:func:`read_outcomes`), with any thresholds and costs.

Next to the tables, ``trajectories.npz`` (:func:`write_trajectories`,
:func:`read_trajectories`) keeps every agent's per-step
:class:`~ignjax.sim.types.Trajectory` and what is needed to read it (the
episode file, the category vocabulary its codes index, thresholds, costs,
the success rule and the simulator settings): the episode viewer
(:mod:`ignjax.view`) replays a run folder from these files alone.
"""

from __future__ import annotations

import csv
import io
import json
import os
import zipfile
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ignjax.errors import InputError
from ignjax.evaluate import metrics as M
from ignjax.fileio import atomic_write
from ignjax.protocol import BIN_INDEX, BIN_NAMES, LOCKED_COSTS, SUCCESS_REQUIRES_STOP, SUCCESS_THRESHOLDS
from ignjax.sim.types import STOP_REASONS, OutcomeRow, Trajectory

COLUMNS: tuple[str, ...] = (
    "agent", "episode_id", "scene_id", "difficulty", "final_distance", "final_euclidean", "min_distance",
    "path_length", "steps", "stopped", "stop_reason", "q1", "q2", "q3", "q4", "n_questions", "n_refused", "n_invalid",
    "trace", "requests", "cache_hits", "prompt_tokens", "completion_tokens", "cost_usd", "retries", "invalid_replies",
    "refused_asks", "paraphrase_rejected", "model_latency_s", "failure",
)
ACCOUNTING_COLUMNS: tuple[str, ...] = ("requests", "cache_hits", "prompt_tokens", "completion_tokens", "retries",
                                       "invalid_replies", "refused_asks", "paraphrase_rejected", "model_latency_s",
                                       "failure")
"""Model-call accounting of MLLM agents (:mod:`ignjax.evaluate.accounting`): HTTP attempts sent to a server (every
attempt, answered or not: timeouts and refused connections count; cache hits excluded), cache hits, tokens, HTTP
retries, replies that could not be used, of those the replies that asked a question with none left (answered with
a correction, never passed to the simulator, so not in ``n_refused``), oracle answers whose paraphrase was refused
(``llm.paraphrase``: the template was shown instead), seconds spent waiting on the model in this run, and why an
episode ended by model failure ("" otherwise). Zero (and "") for JAX-native agents; optional when a table is read
(older tables have none)."""
_ACCOUNTING_INTS = ("requests", "cache_hits", "prompt_tokens", "completion_tokens", "retries", "invalid_replies",
                    "refused_asks", "paraphrase_rejected")
PER_EPISODE = ("calls", "prompt_tokens", "completion_tokens", "cost_usd")
"""The per-episode figures of :func:`model_totals` (``calls``: requests sent less their retries, plus cache hits:
the episode's model calls whether or not the cache answered them, as its tokens and cost count them)."""


def _trace(types, steps, charged) -> str:
    parts = [f"{int(t)}@{int(s)}" + ("" if c else "!") for t, s, c in zip(types, steps, charged) if t > 0]
    return " ".join(parts)


def parse_trace(text: str) -> list[tuple[int, int, bool]]:
    """``"1@0 3@4 4@9!"`` -> [(1, 0, True), (3, 4, True), (4, 9, False)]."""
    out = []
    for part in str(text or "").split():
        charged = not part.endswith("!")
        t, s = part.rstrip("!").split("@")
        out.append((int(t), int(s), charged))
    return out


def outcome_rows(agent: str, records: list[dict], out, accounting: dict | None = None,
                 prices: dict | None = None) -> list[dict]:
    """Rows of an outcome table from a rollout's :class:`~ignjax.sim.types.OutcomeRow`
    (numpy or JAX arrays with leading axis E matching ``records``) and, for
    MLLM agents, the per-episode ``accounting`` (:data:`ACCOUNTING_COLUMNS` -> (E,))
    priced at ``prices`` (``[llm].prices``; None: ``cost_usd`` NaN)."""
    if accounting:
        from ignjax.agents.llm.messages import price# aiohttp only when asked
    o = {k: np.asarray(getattr(out, k)) for k in ("final_distance", "final_euclidean", "min_distance", "path_length",
                                                  "steps", "stopped", "stop_reason", "n_questions", "n_refused",
                                                  "n_invalid", "trace_type", "trace_step", "trace_charged")}
    rows = []
    for k, rec in enumerate(records):
        q = o["n_questions"][k]
        rows.append({
            "agent": agent, "episode_id": rec["episode_id"], "scene_id": rec["scene_id"], "difficulty": rec["difficulty"],
            "final_distance": float(o["final_distance"][k]), "final_euclidean": float(o["final_euclidean"][k]),
            "min_distance": float(o["min_distance"][k]), "path_length": float(o["path_length"][k]),
            "steps": int(o["steps"][k]), "stopped": bool(o["stopped"][k]),
            "stop_reason": STOP_REASONS[int(o["stop_reason"][k])], "q1": int(q[0]), "q2": int(q[1]), "q3": int(q[2]),
            "q4": int(q[3]), "n_questions": int(q.sum()), "n_refused": int(o["n_refused"][k]),
            "n_invalid": int(o["n_invalid"][k]),
            "trace": _trace(o["trace_type"][k], o["trace_step"][k], o["trace_charged"][k]),
            **{c: int(accounting[c][k]) if accounting else 0 for c in _ACCOUNTING_INTS},
            "cost_usd": (_or_nan(price(int(accounting["prompt_tokens"][k]), int(accounting["completion_tokens"][k]),
                                       prices)) if accounting else 0.0),
            "model_latency_s": float(accounting["model_latency_s"][k]) if accounting else 0.0,
            "failure": str(accounting["failure"][k]) if accounting else "",
        })
    return rows


def _or_nan(v) -> float:
    return float("nan") if v is None else float(v)


def model_totals(rows: list[dict], prices: dict | None = None) -> dict[str, dict]:
    """Per MLLM agent (an agent with a model call or a model failure in any
    row): the accounting columns of outcome ``rows`` summed over its
    episodes, the episodes ended by model failure, a cost estimate from
    ``prices`` (``{"prompt": x, "completion": y}`` USD per million tokens,
    as ``[llm].prices``; ``cost_usd`` None without prices), ``episodes``
    and ``per_episode``: for each of :data:`PER_EPISODE`, ``{"mean": ...,
    "max": ...}`` over all the agent's episodes (``cost_usd`` None without
    prices)."""
    from ignjax.agents.llm.messages import price# aiohttp only when asked

    by_agent: dict[str, list[dict]] = {}
    for r in rows:
        by_agent.setdefault(r["agent"], []).append(r)
    out: dict[str, dict] = {}
    for agent, rs in by_agent.items():
        if not any(r["requests"] or r["cache_hits"] or r["failure"] for r in rs):
            continue
        t = {k: sum(int(r.get(k, 0)) for r in rs) for k in _ACCOUNTING_INTS}
        t["failures"] = sum(bool(r["failure"]) for r in rs)
        t["cost_usd"] = price(t["prompt_tokens"], t["completion_tokens"], prices)
        t["episodes"] = len(rs)
        each = {"calls": [int(r["requests"]) - int(r["retries"]) + int(r["cache_hits"]) for r in rs],
                "prompt_tokens": [int(r["prompt_tokens"]) for r in rs],
                "completion_tokens": [int(r["completion_tokens"]) for r in rs],
                "cost_usd": [price(int(r["prompt_tokens"]), int(r["completion_tokens"]), prices) for r in rs]}
        t["per_episode"] = {k: None if v[0] is None else {"mean": float(np.mean(v)), "max": max(v)}
                            for k, v in each.items()}
        out[agent] = t
    return out


def per_episode_text(t: dict) -> str:
    """One agent's :func:`model_totals` per-episode figures in words (``mean / max``)."""
    pe = t["per_episode"]
    cost = "" if pe["cost_usd"] is None else f", cost {pe['cost_usd']['mean']:.6f} / {pe['cost_usd']['max']:.6f} USD"
    return (f"per episode (mean / max over {t['episodes']}): {pe['calls']['mean']:.1f} / {pe['calls']['max']} model "
            f"calls, {pe['prompt_tokens']['mean']:.0f} / {pe['prompt_tokens']['max']} prompt tokens, "
            f"{pe['completion_tokens']['mean']:.0f} / {pe['completion_tokens']['max']} completion tokens{cost}")


def _arrow_table(rows: list[dict]):
    schema = pa.schema([("agent", pa.string()), ("episode_id", pa.string()), ("scene_id", pa.string()),
                        ("difficulty", pa.string()), ("final_distance", pa.float64()), ("final_euclidean", pa.float64()),
                        ("min_distance", pa.float64()), ("path_length", pa.float64()), ("steps", pa.int32()),
                        ("stopped", pa.bool_()), ("stop_reason", pa.string()), ("q1", pa.int32()), ("q2", pa.int32()),
                        ("q3", pa.int32()), ("q4", pa.int32()), ("n_questions", pa.int32()), ("n_refused", pa.int32()),
                        ("n_invalid", pa.int32()), ("trace", pa.string()),
                        *[(c, pa.int64()) for c in _ACCOUNTING_INTS], ("cost_usd", pa.float64()),
                        ("model_latency_s", pa.float64()), ("failure", pa.string())])
    return pa.Table.from_pylist(rows, schema=schema)


def write_outcomes(rows: list[dict], folder: str | os.PathLike, name: str = "outcomes") -> tuple[Path, Path]:
    """Write ``name.parquet`` and ``name.csv`` atomically. Returns both paths."""
    folder = Path(folder)
    table = _arrow_table(rows)
    buf = io.BytesIO()
    pq.write_table(table, buf)
    p_parquet = folder / f"{name}.parquet"
    atomic_write(p_parquet, buf.getvalue())
    text = io.StringIO()
    w = csv.DictWriter(text, fieldnames=list(COLUMNS), lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})
    p_csv = folder / f"{name}.csv"
    atomic_write(p_csv, text.getvalue().encode())
    return p_parquet, p_csv


def read_outcomes(path: str | os.PathLike) -> list[dict]:
    """Rows of an outcome table from Parquet or CSV (types restored).

    Raises:
        InputError: missing file, unknown format, or missing columns.
    """
    p = Path(path)
    if not p.exists():
        raise InputError(p, None, "no such file")
    if p.suffix == ".parquet":
        rows = pq.read_table(p).to_pylist()
    elif p.suffix == ".csv":
        with open(p, newline="") as f:
            rows = list(csv.DictReader(f))
        floats = ("final_distance", "final_euclidean", "min_distance", "path_length")
        ints = ("steps", "q1", "q2", "q3", "q4", "n_questions", "n_refused", "n_invalid")
        for i, r in enumerate(rows):
            try:
                for k in floats:
                    r[k] = float(r[k])
                for k in ints:
                    r[k] = int(r[k])
                for k in _ACCOUNTING_INTS:
                    if k in r:
                        r[k] = int(r[k])
                for k in ("model_latency_s", "cost_usd"):
                    if k in r:
                        r[k] = float(r[k])
                r["stopped"] = r["stopped"] in ("True", "true", "1")
            except (KeyError, ValueError) as e:
                raise InputError(p, f"line {i + 2}", f"bad or missing value: {e}") from e
    else:
        raise InputError(p, None, "expected a .parquet or .csv outcome table")
    if rows:
        missing = [c for c in COLUMNS if c not in rows[0] and c not in ACCOUNTING_COLUMNS + ("cost_usd",)]
        if missing:
            raise InputError(p, "columns", f"missing {missing}")
        for r in rows:
            for c in ACCOUNTING_COLUMNS:
                if c not in r or r[c] is None:
                    r[c] = "" if c == "failure" else 0.0 if c == "model_latency_s" else 0
            if r.get("cost_usd") is None:  # older tables: no model calls cost nothing, others are unknown
                r["cost_usd"] = 0.0 if not (r["prompt_tokens"] or r["completion_tokens"]) else float("nan")
    return rows


def to_metric_outcomes(rows: list[dict], distance: str = "geodesic") -> OutcomeRow:
    """The rollout's outcome type (:class:`~ignjax.sim.types.OutcomeRow`, numpy
    arrays with a leading episode axis) from table rows, for
    :func:`ignjax.evaluate.metrics.summarize`.

    Args:
        distance: ``"geodesic"`` (default) or ``"euclidean"`` final distance
            for success; OSR always uses the geodesic minimum along the path.
    """
    key = {"geodesic": "final_distance", "euclidean": "final_euclidean"}[distance]
    traces = [parse_trace(r["trace"]) for r in rows]
    T = max((len(t) for t in traces), default=0)
    trace = np.zeros((len(rows), T, 3), np.int64)
    for i, t in enumerate(traces):
        if t:
            trace[i, : len(t)] = t
    return OutcomeRow.from_numpy(
        final_distance=np.array([r[key] for r in rows], float),
        final_euclidean=np.array([r["final_euclidean"] for r in rows], float),
        min_distance=np.array([r["min_distance"] for r in rows], float),
        path_length=np.array([r["path_length"] for r in rows], float),
        steps=np.array([r["steps"] for r in rows], np.int64),
        stopped=np.array([r["stopped"] for r in rows], bool),
        stop_reason=np.array([STOP_REASONS.index(r["stop_reason"]) for r in rows], np.int64),
        n_questions=np.array([[r["q1"], r["q2"], r["q3"], r["q4"]] for r in rows], np.int64),
        n_refused=np.array([r["n_refused"] for r in rows], np.int64),
        n_invalid=np.array([r["n_invalid"] for r in rows], np.int64),
        trace_type=trace[..., 0], trace_step=trace[..., 1], trace_charged=trace[..., 2].astype(bool),
        difficulty=np.array([BIN_INDEX[r["difficulty"]] for r in rows], np.int64),
    )


def metric_rows(rows: list[dict], thresholds=SUCCESS_THRESHOLDS, costs=LOCKED_COSTS, require_stop: bool = SUCCESS_REQUIRES_STOP,
                distance: str = "geodesic") -> dict[str, dict]:
    """Agent -> :func:`ignjax.evaluate.metrics.metric_row`, recomputed from table rows."""
    agents: dict[str, list[dict]] = {}
    for r in rows:
        agents.setdefault(r["agent"], []).append(r)
    return {a: M.metric_row(to_metric_outcomes(rs, distance), thresholds, costs, require_stop) for a, rs in agents.items()}


def write_metric_table(metrics: dict[str, dict], path: str | os.PathLike) -> Path:
    """One CSV row per agent with every metric (overall and per difficulty)."""
    p = Path(path)
    keys: list[str] = []
    for m in metrics.values():
        keys += [k for k in m if k not in keys]
    text = io.StringIO()
    w = csv.DictWriter(text, fieldnames=["agent"] + keys, lineterminator="\n")
    w.writeheader()
    for agent, m in metrics.items():
        w.writerow({"agent": agent, **{k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in m.items()}})
    atomic_write(p, text.getvalue().encode())
    return p


# ---------------------------------------------------------------------------
# trajectories
# ---------------------------------------------------------------------------

TRAJECTORY_FILE = "trajectories.npz"
"""Name of the trajectory file in a run folder."""
TRAJECTORY_SCHEMA, TRAJECTORY_VERSION = "ignjax-trajectories", 1
REQUIRED_TRAJECTORY_FIELDS = ("pose", "kind", "question")
"""Fields every trajectory file has (the others may be missing from runs
saved before they were recorded; readers treat them as absent)."""

# storage dtypes: the smallest that holds every value (counts and codes are
# small; instance handles fit in int16); float fields stay float32
_STORE = {"pose": np.float32, "waypoint": np.float32, "blocked": np.bool_, "refused": np.bool_,
          "hint_in_room": np.bool_, "visible_attrs": np.int8}


def _member(zf: zipfile.ZipFile, name: str, array: np.ndarray) -> None:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, np.asarray(array), allow_pickle=False)
    # a fixed timestamp and mode: the same trajectories give the same bytes
    info = zipfile.ZipInfo(name + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = 0o644 << 16
    zf.writestr(info, buf.getvalue(), compresslevel=6)


def write_trajectories(folder: str | os.PathLike, trajectories: dict, records: list[dict], *,
                       episodes: str | os.PathLike, categories, thresholds, costs, require_stop: bool,
                       sim: dict | None = None, scenes_root: str | os.PathLike | None = None) -> Path:
    """Write ``folder/trajectories.npz`` atomically (deterministic bytes).

    A zip of ``.npy`` members that :func:`numpy.load` reads without pickle:
    ``meta`` (a JSON string: ``schema``, ``version``, ``agents``,
    ``episode_ids`` in row order, ``episodes`` (the episode file, absolute),
    ``scenes_root``, ``categories`` (the scene bank's vocabulary, which the
    category codes index), ``thresholds``, ``costs``, ``require_stop``,
    ``sim``) and, for the i-th agent, ``a<i>.<field>`` for each field of
    :class:`~ignjax.sim.types.Trajectory` with a leading episode axis.

    Args:
        trajectories: agent name -> Trajectory (or a dict of its fields),
            rows in the order of ``records``.
        records: the episode records the rows belong to.
    """
    names = list(trajectories)
    meta = {"schema": TRAJECTORY_SCHEMA, "version": TRAJECTORY_VERSION, "agents": names,
            "episode_ids": [r["episode_id"] for r in records], "episodes": str(Path(episodes).resolve()),
            "scenes_root": str(Path(scenes_root).resolve()) if scenes_root else None,
            "categories": list(categories), "thresholds": [float(t) for t in thresholds],
            "costs": [float(c) for c in costs], "require_stop": bool(require_stop), "sim": sim or {}}
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        _member(zf, "meta", np.array(json.dumps(meta, sort_keys=True)))
        for i, name in enumerate(names):
            tr = trajectories[name]
            fields = tr if isinstance(tr, dict) else {f: getattr(tr, f) for f in ("pose",) + Trajectory.STEP_FIELDS}
            for field in ("pose",) + Trajectory.STEP_FIELDS:
                if field not in fields:
                    continue
                a = np.asarray(fields[field])
                if len(a) != len(records):
                    raise ValueError(f"trajectories[{name!r}].{field}: {len(a)} rows for {len(records)} episodes")
                _member(zf, f"a{i}.{field}", a.astype(_STORE.get(field, np.int16)))
    return atomic_write(Path(folder) / TRAJECTORY_FILE, buf.getvalue())


def read_trajectories(path: str | os.PathLike) -> tuple[dict, dict[str, dict[str, np.ndarray]]]:
    """(meta, agent name -> field -> array) from a file of :func:`write_trajectories`.

    Raises:
        InputError: missing or unreadable file, another schema or version,
            or a required field missing.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(p, None, "no such file")
    try:
        with np.load(p, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError, zipfile.BadZipFile) as e:
        raise InputError(p, None, f"not a trajectory file: {e}") from e
    if "meta" not in arrays:
        raise InputError(p, "meta", "missing: not a trajectory file of ignjax")
    try:
        meta = json.loads(str(arrays.pop("meta").reshape(-1)[0]))
    except json.JSONDecodeError as e:
        raise InputError(p, "meta", f"not JSON: {e}") from e
    if meta.get("schema") != TRAJECTORY_SCHEMA or meta.get("version") != TRAJECTORY_VERSION:
        raise InputError(p, "meta", f"schema {meta.get('schema')!r} version {meta.get('version')!r}; "
                                    f"expected {TRAJECTORY_SCHEMA!r} version {TRAJECTORY_VERSION}")
    out: dict[str, dict[str, np.ndarray]] = {}
    for i, name in enumerate(meta["agents"]):
        fields = {k.split(".", 1)[1]: v for k, v in arrays.items() if k.split(".", 1)[0] == f"a{i}"}
        missing = [f for f in REQUIRED_TRAJECTORY_FIELDS if f not in fields]
        if missing:
            raise InputError(p, f"agent {name!r}", f"missing fields {missing}")
        out[name] = fields
    return meta, out


__all__ = ["COLUMNS", "ACCOUNTING_COLUMNS", "PER_EPISODE", "BIN_NAMES", "outcome_rows", "model_totals",
           "per_episode_text", "write_outcomes", "read_outcomes", "to_metric_outcomes", "metric_rows",
           "write_metric_table", "parse_trace", "TRAJECTORY_FILE", "write_trajectories", "read_trajectories"]
