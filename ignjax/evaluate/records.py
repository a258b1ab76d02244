"""An episode's record in the MLLM host loop, and the loop's result.

:func:`episode_entry` is what the host loop keeps of a finished episode (its
outcome, its trajectory padded to the step budget, its model-call accounting
and transcript): one line of the progress file a resumed run reads
(:mod:`ignjax.evaluate.recovery`). :func:`loop_result` stacks the entries
into a :class:`LoopResult`. An episode that never stepped (its first
decision failed) gets the trajectory of an episode that ended before its
first step: every step ``kind == -1`` with the fill values of
:class:`~ignjax.sim.types.Trajectory`, its question counts as at reset.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ignjax.evaluate.accounting import ACCOUNTING
from ignjax.sim import types as T

_ENDED = {"kind": -1, "direction": -1, "col": -1, "row": -1, "candidate": -1, "question": 0, "blocked": False,
          "refused": False}
"""Fill values of the steps after an episode ended (the other fields repeat the final state)."""


@dataclass
class LoopResult:
    """What :func:`~ignjax.evaluate.hostloop.run_llm_agent` returns (episodes in file order).

    Attributes:
        outcomes: :class:`~ignjax.sim.types.OutcomeRow` of numpy arrays (E,).
        trajectories: :class:`~ignjax.sim.types.Trajectory` of numpy arrays (E, ...).
        accounting: column name -> (E,) array (:data:`~ignjax.evaluate.accounting.ACCOUNTING`), plus ``failure``
            (list of str).
        stats: this run's totals: wall time, decisions, utilisation, ``requests`` (HTTP attempts sent in this
            run) and ``retries``, requests in flight, ``resumed`` (episodes kept from an earlier run), ``rerun``
            (episodes that had ended by a model failure, run again), ``failures`` (episodes that ended by one now),
            ``paraphrased`` (paraphrase calls) and ``paraphrase_rejected``.
        transcripts: the transcript records (viewer schema plus request hash,
            image hashes, tokens, latency, cache hit), sorted by episode and step.
    """

    outcomes: T.OutcomeRow
    trajectories: T.Trajectory
    accounting: dict
    stats: dict
    transcripts: list


def never_stepped(sim: T.SimConfig, start, n_questions) -> dict:
    """The step columns of an episode that ended before its first step (lists, ``sim.max_steps`` long)."""
    S, K = sim.max_steps, sim.max_visible
    a = T.Answer.empty()
    fields = {**_ENDED, "waypoint": [float(start[0]), float(start[1])], "blocked": [False] * 8,
              "n_questions": [int(v) for v in n_questions], "room_label": -1, "visible": [-1] * K,
              "visible_attrs": [[-1] * 4] * K,
              **{k: np.asarray(getattr(a, k)).tolist() for k in ("confirm", "follow_up", "hint_room_label",
                                                                   "hint_sector", "hint_landmark", "hint_in_room",
                                                                   "hint_progress")}}
    return {name: [fields[name]] * S for name in T.Trajectory.STEP_FIELDS}


def episode_entry(es, sim: T.SimConfig, ep, outs, r: int, steps: list, final_pose) -> dict:
    """The record of episode ``ep`` (a host-loop slot: ``index``, ``acc``, ``failure``, ``calls``) that ended in
    row ``r`` of the batch outcome ``outs``; ``steps`` its ``(step, pose after, step record)`` tuples."""
    o = {k: np.asarray(getattr(outs, k))[r].tolist() for k in outs.__dataclass_fields__}
    S = sim.max_steps
    start = np.asarray(es.specs.start[ep.index], np.float32)
    pose = np.repeat(np.asarray(final_pose, np.float32)[None], S + 1, 0)
    pose[0] = start
    steps.sort(key=lambda s: s[0])
    last = len(steps)
    if last:
        pose[1:last + 1] = [p for _, p, _ in steps]
        pose[last + 1:] = steps[-1][1]
        cols = {}
        for k, name in enumerate(T.Trajectory.STEP_FIELDS):
            vals = np.stack([rec[k] for _, _, rec in steps])
            fill = np.repeat(vals[-1:], S - last, 0)
            if name in _ENDED:
                fill[:] = _ENDED[name]
            cols[name] = np.concatenate([vals, fill]).tolist()
    else:
        cols = never_stepped(sim, start, o["n_questions"])
    return {"index": ep.index, "episode_id": es.records[ep.index]["episode_id"], "outcome": o,
            "trajectory": {"pose": pose.tolist(), **cols}, "accounting": dict(ep.acc), "failure": ep.failure,
            "calls": ep.calls}


def loop_result(order: list[dict], stats: dict, sim: T.SimConfig) -> LoopResult:
    """The :class:`LoopResult` of the episode records ``order`` (file order)."""
    def column(r: dict, name: str):
        v = r["trajectory"][name]
        if v is None:  # a record from before never-stepped episodes had their columns
            v = never_stepped(sim, r["trajectory"]["pose"][0], r["outcome"]["n_questions"])[name]
        return np.asarray(v)

    outcomes = T.OutcomeRow(**{f.name: np.asarray([r["outcome"][f.name] for r in order])
                               for f in dataclasses.fields(T.OutcomeRow)})
    traj = T.Trajectory(pose=np.stack([np.asarray(r["trajectory"]["pose"], np.float32) for r in order]),
                        **{k: np.stack([column(r, k) for r in order]) for k in T.Trajectory.STEP_FIELDS})
    acc = {k: np.asarray([r["accounting"][k] for r in order]) for k in ACCOUNTING}
    acc["failure"] = [r["failure"] for r in order]
    calls = [c for r in order for c in r["calls"]]
    return LoopResult(outcomes=outcomes, trajectories=traj, accounting=acc, stats=stats, transcripts=calls)


__all__ = ["LoopResult", "episode_entry", "loop_result", "never_stepped"]
