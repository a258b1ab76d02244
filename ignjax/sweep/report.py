"""Studies' tables and figures of a sweep run (:mod:`ignjax.sweep.stages`); the text of ``report.md`` around
them is :mod:`ignjax.sweep.sections`.

Everything here is a deterministic function of the rollouts and the
configuration, so an interrupted-and-resumed run writes the same bytes as
an uninterrupted one. Each ``study_*`` function is also usable on its own
from Python (see the notebooks).
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from ignjax.agents.llm.catalog import LLM_AGENTS, get_llm_agent
from ignjax.config import SweepConfig
from ignjax.evaluate import metrics as M
from ignjax.evaluate.outcomes import (metric_rows, model_totals, outcome_rows, write_metric_table, write_outcomes,
                                      write_trajectories)
from ignjax.fileio import atomic_write
from ignjax.protocol import BIN_INDEX, BIN_NAMES, FACTOR_NAMES
from ignjax.studies import cost_derivation as C
from ignjax.studies import cost_figures as CF
from ignjax.studies import cost_sensitivity as CS
from ignjax.studies import difficulty_ablation as DA
from ignjax.studies import interaction as IA
from ignjax.studies import interaction_plots as IP
from ignjax.studies import locations as LOC
from ignjax.studies._common import save
from ignjax.sweep.in_loop import InLoopRuns, in_loop_figure
from ignjax.sweep.trajectories import plot_trajectories
from ignjax.view.page import write_page
from ignjax.view.runfolder import read_run

VIEWER_FILE = "viewer.html"
"""The episode viewer page the eval study writes next to the outcomes (:mod:`ignjax.view`)."""


def _fmt(v) -> str:
    """A CSV cell: floats to 6 significant digits (``nan`` when not finite)."""
    if isinstance(v, (float, np.floating)):
        return "nan" if not math.isfinite(float(v)) else f"{float(v):.6g}"
    return str(v)


def write_csv(path: Path, header: list[str], rows: list[list]) -> Path:
    """Write a study's table as CSV (atomically); markdown tables are :func:`ignjax.evaluate.metrics.md_table`."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for r in rows:
        w.writerow([_fmt(v) for v in r])
    return atomic_write(path, buf.getvalue())


# ---------------------------------------------------------------------------
# inputs from rollouts
# ---------------------------------------------------------------------------


def agent_arrays(es, rollouts: dict, cfg: SweepConfig) -> dict:
    """Stacked per-agent arrays: success (A, E, T), n_questions (A, E, 4), valid, difficulty."""
    names = list(rollouts)
    outs = [rollouts[a]["out"] for a in names]
    fd = np.stack([np.asarray(o["final_distance"]) for o in outs])
    stopped = np.stack([np.asarray(o["stopped"]) for o in outs])
    reason = np.stack([np.asarray(o["stop_reason"]) for o in outs]) if all("stop_reason" in o for o in outs) else None
    success = np.asarray(M.episode_success(fd, stopped, tuple(cfg.eval.thresholds), cfg.eval.require_stop, reason))
    nq = np.stack([np.asarray(o["n_questions"]) for o in outs]).astype(np.int64)
    difficulty = np.array([BIN_INDEX[r["difficulty"]] for r in es.records], np.int64)
    return {"names": names, "success": success, "n_questions": nq, "valid": np.ones(fd.shape, bool),
            "difficulty": difficulty}


def factors_of(es) -> np.ndarray:
    return np.array([[r["factors"][k] for k in FACTOR_NAMES] for r in es.records], np.float64)


# ---------------------------------------------------------------------------
# studies
# ---------------------------------------------------------------------------


def study_eval(es, rollouts: dict, cfg: SweepConfig, out: Path) -> dict:
    """Outcome tables, metrics, every agent's trajectories and the episode viewer page (:data:`VIEWER_FILE`),
    drawn from the scenes already in memory."""
    rows = []
    trajectories = {}
    for name, tree in rollouts.items():
        if name not in cfg.eval.agents:
            continue
        rows += outcome_rows(name, es.records, SimpleNamespace(**tree["out"]), tree.get("accounting"), cfg.llm.prices)
        trajectories[name] = tree["traj"]
    write_outcomes(rows, out)
    metrics = metric_rows(rows, tuple(cfg.eval.thresholds), tuple(cfg.eval.costs), cfg.eval.require_stop)
    write_metric_table(metrics, out / "metrics.csv")
    write_trajectories(out, trajectories, es.records, episodes=es.path, categories=es.bank.categories,
                       thresholds=cfg.eval.thresholds, costs=cfg.eval.costs, require_stop=cfg.eval.require_stop,
                       sim=cfg.to_dict()["sim"])
    scenes = {sid: es.bank.scene(i) for i, sid in enumerate(es.bank.scene_ids)}
    viewer = write_page(read_run(out, scenes=scenes, title=cfg.run.name), out / VIEWER_FILE)
    return {"rows": rows, "metrics": metrics, "viewer": viewer, "model_totals": model_totals(rows, cfg.llm.prices)}


def in_loop_costs(cfg: SweepConfig) -> tuple[np.ndarray, list[str]]:
    """(K, 4) cost vectors of the in-the-loop study and their labels."""
    locked = np.asarray(cfg.eval.costs, np.float64)
    vecs, labels = [], []
    for s in cfg.costs.scales:
        vecs.append(locked * s)
        labels.append(f"all x{s:g}")
    f = cfg.costs.per_type_factor
    if f > 0:
        for t in range(4):
            v = locked.copy()
            v[t] *= f
            vecs.append(v)
            labels.append(f"Type {t + 1} x{f:g}")
    return np.asarray(vecs), labels


def study_costs(es, rollouts: dict, in_loop: dict | None, cfg: SweepConfig, out: Path) -> dict:
    arr = agent_arrays(es, {a: rollouts[a] for a in cfg.eval.agents}, cfg)
    locked = np.asarray(cfg.eval.costs, np.float64)
    total = float(locked.sum())
    include = np.stack([locked, np.full(4, total / 4)])
    costs = CS.cost_samples(int(cfg.costs.samples), int(cfg.costs.seed), total=total, include=include)
    ti = cfg.eval.thresholds.index(1.5) if 1.5 in cfg.eval.thresholds else None
    res = CS.run_study(arr["success"], arr["n_questions"], arr["valid"], costs, agent_names=arr["names"],
                       threshold_index=ti)
    fig = out / "figures"
    CF.plot_marginal_wsr(res, fig / "costs_marginal_wsr.png")
    CF.plot_flip_map(res, fig / "costs_flip_map.png")
    ranked = res["wsr_ranked"]
    rows = []
    for a, name in enumerate(res["agent_names"]):
        rows.append([name, ranked[0, a], ranked[1, a], float(np.mean(ranked[:, a])), float(np.min(ranked[:, a])),
                     float(np.max(ranked[:, a])), int(res["reference_ranks"][a]), float(np.mean(res["ranks"][:, a]))])
    header = ["agent", "WSR charged costs", "WSR equal costs", "WSR mean", "WSR min", "WSR max", "rank (charged costs)",
              "mean rank"]
    write_csv(out / "costs_offline.csv", header, rows)
    summary = {"offline": res, "offline_table": (header, rows)}
    if in_loop is not None:
        vecs, labels = in_loop_costs(cfg)
        o = in_loop["out"]
        fd, stopped = np.asarray(o["final_distance"]), np.asarray(o["stopped"])  # (K, E)
        nq = np.asarray(o["n_questions"]).astype(np.float64)  # (K, E, 4)
        thr = 1.5 if 1.5 in cfg.eval.thresholds else cfg.eval.thresholds[0]
        succ = np.asarray(M.episode_success(fd, stopped, (thr,), cfg.eval.require_stop))[..., 0]
        disc = np.exp(-np.einsum("ket,kt->ke", nq, vecs))
        lrows = []
        for k, lab in enumerate(labels):
            lrows.append([lab] + [float(c) for c in vecs[k]] + [float(nq[k].sum(-1).mean())]
                         + [float(nq[k, :, t].mean()) for t in range(4)]
                         + [100 * float(succ[k].mean()), 100 * float((succ[k] * disc[k]).mean())])
        lheader = ["setting", "w1", "w2", "w3", "w4", "|Q|", "Q1", "Q2", "Q3", "Q4", f"SR@{thr:g}", f"WSR@{thr:g}"]
        write_csv(out / "costs_in_loop.csv", lheader, lrows)
        silent = {a: float(arr["success"][i, :, cfg.eval.thresholds.index(thr)].mean())
                  for i, a in enumerate(arr["names"]) if a == "explorer"}
        runs = InLoopRuns(cfg.costs.agent, tuple(labels), tuple(cfg.costs.scales), float(cfg.costs.per_type_factor),
                          nq, succ, disc, float(thr), silent)
        save(in_loop_figure(runs), fig / "costs_in_loop.png")
        summary["in_loop_table"] = (lheader, lrows)
        summary["in_loop_agent"] = cfg.costs.agent
    return summary


def study_difficulty(es, rollouts: dict, cfg: SweepConfig, out: Path) -> dict:
    arr = agent_arrays(es, {a: rollouts[a] for a in cfg.eval.agents}, cfg)
    ti = cfg.eval.thresholds.index(1.5) if 1.5 in cfg.eval.thresholds else 0
    success = arr["success"][..., ti]
    factors = factors_of(es)
    alphas = DA.alpha_grid(cfg.difficulty.alpha_step)
    thresholds = DA.threshold_grid(cfg.difficulty.threshold_step)
    # the reference setting (difficulty.alpha / thresholds) is added to the grids so it is always evaluated
    d_alpha = np.asarray(cfg.difficulty.alpha, np.float64)
    d_thr = np.asarray(cfg.difficulty.thresholds, np.float64)
    alphas = np.concatenate([d_alpha[None], alphas])
    thresholds = np.concatenate([d_thr[None], thresholds])
    abl = DA.ablate(factors, success, None, alphas, thresholds, empty=cfg.difficulty.empty)
    gi, hi = 0, 0
    cal = DA.calibrate(factors, 1.0 - success, None, alphas[1:], cfg.difficulty.split_seed)
    fig = out / "figures"
    DA.plot_ordering(abl, fig / "difficulty_ordering.png")
    DA.plot_calibration(cal, fig / "difficulty_calibration.png")
    rows = [[name] + [100 * float(abl["sr"][gi, hi, a, b]) for b in range(3)] for a, name in enumerate(arr["names"])]
    header = ["agent", "SR@1.5 easy", "SR@1.5 medium", "SR@1.5 hard"]
    write_csv(out / "difficulty_default_bins.csv", header, rows)
    crow = [["fitted"] + [float(x) for x in cal["alpha"]] + [cal["fit_corr"], cal["holdout_corr"]],
            ["default (0.35, 0.25, 0.15, 0.25)"] + [float(x) for x in cal["default_alpha"]] + [cal["default_fit_corr"], cal["default_holdout_corr"]]]
    cheader = ["alpha", *FACTOR_NAMES, "spearman fit half", "spearman holdout half"]
    write_csv(out / "difficulty_calibration.csv", cheader, crow)
    return {"ablation": abl, "calibration": cal, "default_bins": (header, rows), "calibration_table": (cheader, crow),
            "default_proportions": abl["proportions"][gi, hi], "n_settings": int(abl["ordered"].size)}


def study_derive_costs(cfg: SweepConfig, out: Path) -> dict:
    dc = cfg.derive_costs
    if dc.annotations:
        stats = C.statistics_from_annotations(dc.annotations)
        source = f"annotations {dc.annotations}"
    else:
        stats = C.published_statistics(dc.assumption)
        source = f"published statistics (assumption: {dc.assumption})"
    locked = tuple(cfg.eval.costs)
    derived = C.derive_costs(stats, tuple(dc.lambdas), locked=locked)
    fitted = C.fit_lambdas(stats, locked=locked) if dc.fit else None
    header = ["setting", "lambda_s", "lambda_h", "lambda_r", "w1", "w2", "w3", "w4", "ordering", "rmse to locked"]
    rows = [["locked", "", "", ""] + list(locked) + ["".join(str(t) for t in C._ordering(locked)), 0.0]]
    for name, d in (("given lambdas", derived), ("fitted lambdas", fitted)):
        if d is not None:
            rows.append([name, *d.lambdas, *map(float, d.costs), "".join(str(t) for t in d.ordering), d.rmse])
    write_csv(out / "derive_costs.csv", header, rows)
    return {"source": source, "table": (header, rows), "assumed": list(getattr(stats, "assumed", []) or [])}


def question_content(es, agent: str, tree: dict, events: dict) -> dict:
    """:func:`ignjax.studies.interaction.type3_content` of the analysed agent:
    from the question texts its MLLM rollout keeps (``tree["questions"]``),
    or not applicable, with the reason, for an agent that writes none."""
    if agent not in LLM_AGENTS:
        return IA.type3_content(events, None, reason=f"`{agent}` is a JAX-native agent: it asks by type code, "
                                                     "without question text")
    if not get_llm_agent(agent).writes_questions:
        return IA.type3_content(events, None, reason=f"`{agent}` names the question type only; its decisions "
                                                     "carry no question text")
    index = {eid: i for i, eid in enumerate(es.episode_ids)}
    texts = {(index[q["episode"]], q["step"]): q["text"] for q in tree.get("questions", ())}
    return IA.type3_content(events, texts)


def _threshold(cfg: SweepConfig) -> float:
    """The success threshold the figures use: 1.5 m when evaluated, else the first."""
    return 1.5 if 1.5 in cfg.eval.thresholds else float(cfg.eval.thresholds[0])


def _drawn_agents(es, rollouts: dict, cfg: SweepConfig) -> tuple[dict, dict]:
    """The rollouts the trajectory figures draw (every evaluated agent, then the analysed one) and each one's
    (E,) success at :func:`_threshold`."""
    names = [a for a in dict.fromkeys([*cfg.eval.agents, cfg.analysis.agent]) if a in rollouts]
    drawn = {a: rollouts[a] for a in names}
    arr = agent_arrays(es, drawn, cfg)
    ti = cfg.eval.thresholds.index(_threshold(cfg))
    return drawn, {a: arr["success"][i, :, ti] for i, a in enumerate(arr["names"])}


def study_analysis(es, rollouts: dict, cfg: SweepConfig, out: Path) -> dict:
    agent = cfg.analysis.agent
    tree = rollouts[agent]
    traj = SimpleNamespace(**tree["traj"])
    diff = np.array([BIN_INDEX[r["difficulty"]] for r in es.records], np.int64)
    events = IA.events_from_trajectory(traj, diff)
    timing = IA.question_timing(events)
    grids = list(es.bank.navgrids)
    labels = [[room.label for room in es.bank.scene(i).rooms] for i in range(len(grids))]
    scene_index = np.asarray(es.specs.scene)
    loc = LOC.type3_locations(grids, np.asarray(traj.pose), events, scene_index=scene_index, room_labels=labels)
    qpd = IA.questions_per_difficulty(np.asarray(tree["out"]["n_questions"]), diff)
    du = IA.delta_u(np.asarray(traj.pose), events, h=int(cfg.analysis.horizon), r=float(cfg.analysis.radius))
    content = question_content(es, agent, tree, events)
    fig = out / "figures"
    steps = LOC.step_locations(grids, np.asarray(traj.pose), events["steps_used"], scene_index=scene_index,
                              room_labels=labels)
    IP.plot_question_timing(timing, fig / "analysis_timing.png")
    IP.plot_location_classes(loc, fig / "analysis_type3_locations.png", content=content, steps=steps)
    IP.plot_questions_per_difficulty(qpd, fig / "analysis_questions_per_difficulty.png")
    IP.plot_delta_u(du, fig / "analysis_delta_u.png")
    kept = np.isfinite(du["delta_u"])

    def bin_mean(values, b):  # mean over the bin's counted questions (nan when none)
        m = kept & (du["difficulty"] == b)
        return float(np.mean(values[m])) if m.any() else float("nan")

    rows = [[BIN_NAMES[b], float(qpd["mean_total"][b])] + [float(qpd["mean_per_type"][b, t]) for t in range(4)]
            + [100 * float(du["mean"][b]), 100 * float(du["median"][b]), bin_mean(du["area_before"], b),
               bin_mean(du["area_after"], b), int(du["count"][b])]
            for b in range(3)]
    header = ["difficulty", "|Q|", "Q1", "Q2", "Q3", "Q4", "Delta-U mean (%)", "Delta-U median (%)", "A_before (m^2)",
              "A_after (m^2)", "Type-3 questions counted"]
    write_csv(out / "analysis_per_difficulty.csv", header, rows)
    lheader = ["class", "Type-3 questions", "share"]
    lrows = [[c, int(n), float(f)] for c, n, f in zip(loc["classes"], loc["counts"], loc["fractions"])]
    write_csv(out / "analysis_type3_locations.csv", lheader, lrows)
    ctable = None
    if content["applicable"]:
        n = content["n"]
        cheader = ["content", "Type-3 questions", "share of classified", "share of all"]
        nan = float("nan")
        crows = [[c, int(k), float(content["fractions"][i]) if i < 3 else nan, k / n if n else nan]
                 for i, (c, k) in enumerate(zip(content["classes"], content["counts"]))]
        crows.append(["no text", content["n_without_text"], nan, content["n_without_text"] / n if n else nan])
        write_csv(out / "analysis_type3_content.csv", cheader, crows)
        ctable = (cheader, crows)
    plots = plot_trajectories(es, *_drawn_agents(es, rollouts, cfg), int(cfg.analysis.trajectories), fig,
                              int(cfg.run.seed), _threshold(cfg))
    return {"agent": agent, "per_difficulty": (header, rows), "locations": (lheader, lrows), "timing": timing,
            "delta_u": du,
            "content": content, "content_table": ctable, "trajectory_plots": plots}


__all__ = ["VIEWER_FILE", "agent_arrays", "factors_of", "in_loop_costs", "plot_trajectories", "question_content",
           "study_analysis", "study_costs", "study_derive_costs", "study_difficulty", "study_eval", "write_csv"]
