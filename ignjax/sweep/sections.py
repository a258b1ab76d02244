"""The text of ``report.md``: setup, definitions and one section per study.

Each section runs its study's tables and figures (:mod:`ignjax.sweep.report`)
and writes its markdown: a first sentence stating the finding, computed
from the study's numbers (the ``*_finding`` functions, pure functions of
the tables, so a test can change the data and see the sentence change),
then what was run, each table with its units and a one-line reading, and a
caption under each figure saying what to look at.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import MappingProxyType

import numpy as np

from ignjax.agents import registry
from ignjax.agents.llm.catalog import LLM_AGENTS, get_llm_agent
from ignjax.agents.policies import DEADLINE_STEPS
from ignjax.config import SweepConfig
from ignjax.evaluate import metrics as M
from ignjax.fileio import atomic_write
from ignjax.protocol import BIN_NAMES, LOCKED_COSTS, QUESTION_TYPES
from ignjax.sim import geometry as G
from ignjax.sweep.report import (VIEWER_FILE, study_analysis, study_costs, study_derive_costs, study_difficulty,
                                 study_eval)

TYPE_WORDS = tuple("route hint" if name == "route" else name for name in QUESTION_TYPES)
"""How the report names question types 1..4 (:data:`ignjax.protocol.QUESTION_TYPES`, the route question's
answer being a hint)."""

FACTOR_WORDS = ("distractors in the scene", "distractors in the target's room", "context",
                "start distance")
"""The difficulty factors (:data:`ignjax.protocol.FACTOR_NAMES`) in words, for table headers."""


def _pct(v: float) -> str:
    return f"{v:.1f}%"


def _best(values: dict[str, float]) -> str:
    return max(values, key=lambda k: (values[k], k))


def figure(path: str, alt: str, caption: str) -> list[str]:
    """An embedded figure: the image with its alt text, then an italic caption line saying what to look at."""
    return [f"![{alt}]({path})", "", f"*{caption}*", ""]


def costs_by_type(costs) -> str:
    """``Type 1 appearance 0.182, Type 2 region 0.162, ...``: a cost vector labelled by question type."""
    return ", ".join(f"Type {t + 1} {TYPE_WORDS[t]} {float(c):.3g}" for t, c in enumerate(costs))


# ---------------------------------------------------------------------------
# setup and definitions
# ---------------------------------------------------------------------------


def _settings(values: dict) -> str:
    return ", ".join(f"{k}={list(v) if isinstance(v, tuple) else v}" for k, v in values.items())


def agent_line(name: str, values: dict) -> str:
    """One agent of the setup: what it is (its registry description) and the parameters that change what it
    does (:attr:`ignjax.agents.Agent.reads`; an MLLM agent's options)."""
    if name in LLM_AGENTS:
        what = get_llm_agent(name).description
    else:
        agent = registry()[name]
        what = agent.description
        if agent.reads is not None:
            values = {k: v for k, v in values.items() if k in agent.reads}
    what = what.rstrip(".") + "."
    return f"- Agent `{name}`: {what} Parameters: {_settings(values) or 'none'}."


def settings_lines(sim: dict, agents: dict[str, dict]) -> list[str]:
    """Markdown lines stating the simulator settings and what each agent is, with the parameters it reads."""
    return [f"- Simulator: {_settings(sim)}."] + [agent_line(name, values) for name, values in agents.items()]


def mllm_settings_line(cfg: SweepConfig) -> str:
    """The report header's line on what the MLLM agents were sent: the model, its decoding settings and the
    image size (``views.size``)."""
    llm, views = cfg.llm, cfg.views
    return (f"- MLLM agents: model `{llm.model}`, temperature {llm.temperature:g}, max_tokens {llm.max_tokens}, "
            f"seed {llm.seed}; views of {views.size} x {views.size} px (`views.size`), {views.image_format}.")


def definitions_lines(cfg: SweepConfig) -> list[str]:
    """The glossary: every metric and symbol the tables use."""
    costs = tuple(cfg.eval.costs)
    locked = "the paper's locked costs" if np.allclose(costs, LOCKED_COSTS) else \
        f"set by `eval.costs`; the paper's locked costs are {costs_by_type(LOCKED_COSTS)}"
    taus = ", ".join(f"{t:g}" for t in cfg.eval.thresholds)
    return ["## Definitions", "",
            f"- **SR@tau** (success rate, %): share of episodes that end with the agent within tau metres of the "
            f"target, tau = {taus}; {M.success_rule(cfg.eval.require_stop)}. Distances are geodesic: along the "
            "free floor, to the nearest free point next to the target.",
            "- **OSR@tau** (oracle success rate, %): share of episodes whose path came within tau of the target at "
            "any step, stopped there or not.",
            "- **NE** (navigation error, m): mean final distance to the target. **TL** (trajectory length, m): mean "
            "length of the path walked.",
            "- **Q1..Q4**: questions of each type per episode; **|Q|**: their sum.",
            "- **WSR@tau** (weighted success rate, %): mean over episodes of success x exp(-(w1 n1 + w2 n2 + w3 n3 "
            "+ w4 n4)), with n_t the episode's questions of type t: a success without questions scores 1, every "
            "question multiplies it by exp(-w_t), a failure scores 0.",
            f"- **Cost vector** w = (w1, w2, w3, w4), the price of one question of each type: {costs_by_type(costs)} "
            f"({locked}). Type 1 asks about the target's appearance, Type 2 the region (room) it is in, Type 3 "
            "for a route hint from where the agent stands, Type 4 whether a given object is the target.",
            "- **Kendall tau**: rank correlation of two orderings of the agents (1: the same order, -1: reversed); "
            "not the success distance tau.",
            "- **Difficulty** (easy / medium / hard): bins of the episode's difficulty score D, a weighted sum of "
            "four factors in [0, 1]: distractors (other objects of the target's category) in the scene and in the "
            "target's room, how little the nearby objects tell the target from its distractors (context), and the "
            "start's distance to the target.", ""]


# ---------------------------------------------------------------------------
# findings: sentences computed from the tables
# ---------------------------------------------------------------------------


def eval_finding(metrics: dict[str, dict], privileged=()) -> str:
    """Which agent leads on SR@1.5 and which on WSR@1.5 (agents with privileged information left out)."""
    fair = {n: r for n, r in metrics.items() if n not in privileged} or metrics
    sr = {n: r["SR@1.5"] for n, r in fair.items()}
    wsr = {n: r["WSR@1.5"] for n, r in fair.items()}
    a, b = _best(sr), _best(wsr)
    if a == b:
        text = f"`{a}` has both the highest SR@1.5 ({_pct(sr[a])}) and the highest WSR@1.5 ({_pct(wsr[a])})"
    else:
        text = (f"`{a}` has the highest SR@1.5 ({_pct(sr[a])}), `{b}` the highest WSR@1.5 ({_pct(wsr[b])}): "
                f"`{a}`'s questions cost it more than its extra successes bring")
    priv = [n for n in metrics if n in privileged]
    if priv and fair is not metrics:
        text += "; " + ", ".join(f"the privileged `{n}` reaches {_pct(metrics[n]['SR@1.5'])}" for n in priv)
    return text + "."


def shortest_move(sim: dict) -> float:
    """Length (m) of the shortest unobstructed MOVE: to the floor point seen at the centre of the grid's bottom
    row in the middle of the view (the executor's waypoint of cell (4-5, 1))."""
    width, height = sim["image_size"]
    ray = G.pixel_ray(G.intrinsics(width, height, math.radians(sim["hfov"])), G.grid_to_pixel(4.5, 1, width, height))
    return sim["eye_height"] / float(ray[1])  # camera frame: y down, z forward (ray's z is 1)


def privileged_note(name: str, row: dict, sim: dict) -> str:
    """Why a privileged agent's SR@0.5 sits far below its SR@1.5 (the executor's step length)."""
    return (f"`{name}` ends within 0.5 m of the target in {_pct(row['SR@0.5'])} of the episodes but within 1.5 m in "
            f"{_pct(row['SR@1.5'])} (NE {row['NE']:.2f} m): it stops as soon as no MOVE brings it closer, and an "
            f"unobstructed MOVE goes at least {shortest_move(sim):.2f} m (the floor point seen at the bottom row of "
            f"the 8 x 8 grid from {sim['eye_height']:g} m eye height), so it cannot make a last short approach; "
            "a target on furniture or against a wall can also have no free floor within 0.5 m. SR@1.5 is its "
            "bound to read.")


def offline_finding(res: dict) -> str:
    """The agents' order under the locked costs and how often sampled cost vectors change it."""
    names = res["agent_names"]
    order = [names[a] for a in np.argsort(np.asarray(res["reference_ranks"]), kind="stable")]
    fl = res["flips"]
    return (f"Under the charged costs the agents rank {' > '.join(f'`{n}`' for n in order)} on WSR@1.5; "
            f"{_pct(100 * fl['fraction_flipped'])} of the {len(res['costs'])} sampled cost vectors change that "
            f"order (mean Kendall tau {fl['tau_mean']:.3f}).")


def in_loop_findings(header: list[str], rows: list[list], agent: str) -> list[str]:
    """The in-the-loop table read: how the total asking moves with the cost scale, and which types' asking rises
    between two scales while the total falls (one type standing in for another)."""
    col = {h: i for i, h in enumerate(header)}
    scaled = [r for r in rows if str(r[0]).startswith("all x")]
    if len(scaled) < 2:
        return []
    sr = next(h for h in header if h.startswith("SR@"))
    q = [r[col["|Q|"]] for r in scaled]
    falls = all(b <= a for a, b in zip(q, q[1:]))
    first, last = scaled[0], scaled[-1]
    out = [f"`{agent}` asks {q[0]:.2f} questions per episode at {first[0][4:]} the charged costs and {q[-1]:.2f} at "
           f"{last[0][4:]}, " + ("falling at every step" if falls else "not falling at every step")
           + f"; its {sr} goes from {_pct(first[col[sr]])} to {_pct(last[col[sr]])}."]
    rises = []
    for a, b in zip(scaled, scaled[1:]):
        for t in range(4):
            qa, qb = a[col[f"Q{t + 1}"]], b[col[f"Q{t + 1}"]]
            if qb > qa + 1e-9:
                rises.append(f"Type {t + 1} ({TYPE_WORDS[t]}) from {qa:.3g} at {a[0][4:]} to {qb:.3g} at {b[0][4:]}")
    if rises:
        out.append("Per type, asking can rise while the total falls: " + "; ".join(rises) + ". Raising every "
                   "cost pushes some questions below the asking threshold first; the information they would have "
                   "given is then missing, so another type's expected gain can grow past it: the agent substitutes "
                   "one question for another.")
    return out


def zero_asking_note(agent: str, label: str, sr: float, stopped_early: float, explorer_sr: float,
                     explorer_early: float, last: int) -> str:
    """Why the cost-aware agent, asking nothing, can succeed less than ``explorer`` (different stopping rules)."""
    return (f"At {label} `{agent}` asks nothing, yet its SR@1.5 ({_pct(sr)}) "
            + ("is below" if sr < explorer_sr else "is not above")
            + f" `explorer`'s ({_pct(explorer_sr)}): the two stop differently. Without answers `{agent}`'s belief "
            "stays split among the instances it has seen and those it has not, so it seldom reaches the posterior "
            f"it needs to stop (`p_stop`) and keeps exploring until the last {DEADLINE_STEPS} steps, when it heads "
            f"for its best candidate: it stopped before step {last} in {_pct(stopped_early)} of the episodes. "
            f"`explorer` stops at the nearest instance of the category it sees ({_pct(explorer_early)} before step "
            f"{last}), right or wrong.")


def difficulty_finding(fraction_ordered: float, n_settings: int, bins: list[list]) -> str:
    """How rarely the per-bin SR keeps easy >= medium >= hard, and how many agents are ordered at the reference."""
    ordered = [r[0] for r in bins if r[1] >= r[2] >= r[3]]
    return (f"{_pct(100 * fraction_ordered)} of the {n_settings} (weights, thresholds) settings keep SR@1.5 "
            f"ordered easy >= medium >= hard for every agent; at the reference setting {len(ordered)} of "
            f"{len(bins)} agents are ordered.")


def calibration_finding(cal: dict) -> str:
    """The fitted difficulty weights and how well they and the reference weights predict failure."""
    a = np.asarray(cal["alpha"], float)
    top = int(np.argmax(a))
    return (f"Fitted to predict failure, the weights put {a[top]:.2f} on {FACTOR_WORDS[top]}; on the held-out "
            f"half their rank correlation with failure is {cal['holdout_corr']:.3f}, against "
            f"{cal['default_holdout_corr']:.3f} for the reference weights.")


def _order_words(ordering) -> str:
    return " > ".join(f"Type {int(t)} {TYPE_WORDS[int(t) - 1]}" for t in ordering)


def derive_finding(rows: list[list]) -> str:
    """Whether the derived costs keep the locked costs' order of the types, and how close they come."""
    locked = rows[0][8]
    derived = rows[1:]
    same = all(r[8] == locked for r in derived)
    best = min(derived, key=lambda r: r[9]) if derived else None
    text = (f"The derived costs {'keep' if same else 'do not all keep'} the locked order of the types (most "
            f"expensive first: {_order_words(str(locked))})")
    if best is not None:
        text += f"; the closest ({best[0]}) lies {best[9]:.3f} (root mean square) from the locked costs"
    return text + "."


def analysis_finding(agent: str, per_difficulty: list[list], du: dict) -> str:
    """How the agent's asking changes with difficulty, and the sign of its Delta-U."""
    q = [r[1] for r in per_difficulty]
    trend = "more" if q[-1] > q[0] else "fewer" if q[-1] < q[0] else "as many"
    mean = [r[6] for r in per_difficulty]
    finite = [m for m in mean if math.isfinite(m)]
    text = f"`{agent}` asks {trend} questions on hard episodes than on easy ones ({q[0]:.2f} -> {q[-1]:.2f} per episode)"
    if finite:
        sign = ("negative in every bin" if all(m < 0 for m in finite) else "positive in every bin"
                if all(m > 0 for m in finite) else "of mixed sign")
        text += (f"; Delta-U of its route questions is {sign} (mean {du['mean_all'] * 100:.1f}% over "
                 f"{du['n_kept']} questions)")
    return text + "."


def delta_u_note(du: dict) -> str:
    """What the sign of Delta-U means here, with the areas behind it."""
    kept = np.isfinite(du["delta_u"])
    if not kept.any():
        return "No route question had a step before and after it, so Delta-U is undefined."
    a0, a1 = float(np.mean(du["area_before"][kept])), float(np.mean(du["area_after"][kept]))
    med = float(np.median(du["delta_u"][kept]))
    text = (f"Delta-U is positive when the agent covers less floor after the answer than before it (the search "
            f"narrows), negative when it covers more. Here the mean area is {a0:.1f} m^2 before and {a1:.1f} m^2 "
            f"after (median Delta-U {100 * med:.1f}%, {100 * float(np.mean(du['delta_u'][kept] < 0)):.0f}% of the "
            "questions negative).")
    if du["mean_all"] < 0:
        text += (" The answers send the agent along a route at least as far as it walked before, so the proxy "
                 "shows no narrowing; the ratio is at most 100% but unbounded below, so a question asked after the "
                 "agent barely moved (small area before) pulls the mean down.")
    return text + " The paper reports +21.9% (easy) to +47.5% (hard) for its agent."


# ---------------------------------------------------------------------------
# sections
# ---------------------------------------------------------------------------


def _section_eval(results: dict, es, rollouts: dict, cfg, out: Path) -> list[str]:
    ev = study_eval(es, rollouts, cfg, out)
    results["eval"] = ev
    privileged = {n for n in ev["metrics"] if n in registry() and registry()[n].privileged}
    parts = ["## Evaluation (Table-1 columns)", "", eval_finding(ev["metrics"], privileged), "",
             "Rates (SR, OSR, WSR) in %, NE and TL in metres, Q1..Q4 and |Q| in questions per episode; "
             "SR/OSR@tau cells give SR and OSR at that distance; the Easy, Medium and Hard columns give SR@1.5 and "
             "|Q| on that difficulty's episodes. Read across a row: SR against WSR shows what the agent's questions "
             "cost it. Privileged agents see the shortest path: an upper bound, not a competitor.", ""]
    if all(t in cfg.eval.thresholds for t in M.DEFAULT_THRESHOLDS):
        parts += [M.table1(ev["metrics"], "markdown"), ""]
        sim = cfg.to_dict()["sim"]
        for n in sorted(privileged):
            parts += [privileged_note(n, ev["metrics"][n], sim), ""]
    parts += ["Per-episode outcomes: `outcomes.parquet`, `outcomes.csv`; metrics: `metrics.csv`; per-step "
              "trajectories: `trajectories.npz`.", "",
              f"Episode viewer: [{VIEWER_FILE}]({VIEWER_FILE}) (one self-contained page: every episode of every "
              "agent, sortable and filterable, replayed step by step on the map with the oracle's answers; "
              "`python -m ignjax.view RUN_DIR` (this folder) rebuilds it, `--gif EPISODE_ID --agent NAME` exports "
              "one episode as an animation).", ""]
    if ev["model_totals"]:
        parts += _model_tables(ev, cfg)
    return parts


def _model_tables(ev: dict, cfg) -> list[str]:
    parts = ["MLLM agents' model calls (requests: every attempt sent to the server, answered or not, cache hits "
             "excluded; tokens as the server counted them; refused asks: questions asked with none left, "
             "corrected; cost from `llm.prices`); per-decision transcripts in `transcripts/<agent>.jsonl`:", ""]
    header = ["agent", "requests", "cache hits", "prompt tokens", "completion tokens", "retries", "invalid replies",
              "refused asks", "ended by model failure", "cost (USD)"]
    rows = [[name, t["requests"], t["cache_hits"], t["prompt_tokens"], t["completion_tokens"], t["retries"],
             t["invalid_replies"], t["refused_asks"], t["failures"],
             "" if t["cost_usd"] is None else f"{t['cost_usd']:.4f}"] for name, t in ev["model_totals"].items()]
    parts += [M.md_table(header, rows), "",
              "Per episode (mean / max over the agent's episodes; model calls sent or answered from the cache, "
              "whose tokens and cost count alike; per-episode figures also in the outcome table's `requests`, "
              "`cache_hits`, `prompt_tokens`, `completion_tokens` and `cost_usd` columns):", ""]
    header = ["agent", "episodes", "model calls", "prompt tokens", "completion tokens", "cost (USD)"]
    rows = []
    for name, t in ev["model_totals"].items():
        pe = t["per_episode"]
        cost = "" if pe["cost_usd"] is None else f"{pe['cost_usd']['mean']:.6f} / {pe['cost_usd']['max']:.6f}"
        rows.append([name, t["episodes"], f"{pe['calls']['mean']:.1f} / {pe['calls']['max']}",
                     f"{pe['prompt_tokens']['mean']:.0f} / {pe['prompt_tokens']['max']}",
                     f"{pe['completion_tokens']['mean']:.0f} / {pe['completion_tokens']['max']}", cost])
    parts += [M.md_table(header, rows), ""]
    if cfg.llm.paraphrase:
        parts += ["Oracle answers were reworded by the model before the agents read them (`llm.paraphrase`; "
                  "transcript role `paraphrase`); rewordings refused by the leak checks, the template shown "
                  "instead: " + ", ".join(f"{name} {t['paraphrase_rejected']}"
                                         for name, t in ev["model_totals"].items()) + ".", ""]
    naive = [n for n in ev["model_totals"] if n.endswith("-naive")]
    if cfg.llm.naive_unbudgeted and naive:
        parts += [f"The naive-QA rows ({', '.join(naive)}) ran with no question budget (`llm.naive_unbudgeted`: "
                  "the reading of the paper's naive rows, docs/protocol.md, \"Reading the paper's tables\"); every other "
                  "agent kept the budget.", ""]
    return parts


def _zero_asking(cs: dict, results: dict, rollouts: dict, cfg) -> list[str]:
    """The note on the cost-aware agent asking nothing against ``explorer``, when both ran."""
    h, rows = cs["in_loop_table"]
    zero = [k for k, r in enumerate(rows) if str(r[0]).startswith("all x") and r[h.index("|Q|")] == 0]
    sr = next((c for c in h if c.startswith("SR@")), None)
    if not zero or "explorer" not in rollouts or "eval" not in results or sr != "SR@1.5":
        return []
    k = zero[-1]
    last = cfg.sim.max_steps - DEADLINE_STEPS
    steps = np.asarray(results["in_loop"]["out"]["steps"])[k]
    ex_steps = np.asarray(rollouts["explorer"]["out"]["steps"])
    ex_sr = results["eval"]["metrics"]["explorer"]["SR@1.5"]
    return [zero_asking_note(cs["in_loop_agent"], rows[k][0], rows[k][h.index(sr)], 100 * float(np.mean(steps < last)),
                             ex_sr, 100 * float(np.mean(ex_steps < last)), last), ""]


def _section_costs(results: dict, es, rollouts: dict, cfg, out: Path) -> list[str]:
    cs = study_costs(es, rollouts, results.get("in_loop"), cfg, out)
    results["costs"] = cs
    res = cs["offline"]
    fl = res["flips"]
    i, j = fl["axes"]
    header, rows = cs["offline_table"]
    parts = ["## Cost-weight sensitivity", "", offline_finding(res), "",
             f"Offline: the stored outcomes re-weighted under {len(res['costs'])} cost vectors: the charged costs, "
             f"equal costs for the four types, and {len(res['costs']) - 2} vectors drawn uniformly among those with "
             "the same total as the charged costs. WSR@1.5 in % (its mean, lowest and highest over the vectors); "
             "rank 1 is the best. Read down a column: an agent that never asks keeps one WSR whatever the costs.", "",
             M.md_table(header, [[r[0]] + [100 * v if i < 5 else v for i, v in enumerate(r[1:])] for r in rows]),
             "", f"Mean cost vector where the ranking changes: {costs_by_type(fl['mean_costs_flipped'])}; where it "
             f"holds: {costs_by_type(fl['mean_costs_kept'])}.", ""]
    parts += figure("figures/costs_marginal_wsr.png", "WSR@1.5 of each agent against each question type's cost",
                    "Each agent's mean WSR@1.5 (%) against one type's sampled cost, one panel per type, the charged "
                    "cost marked; the y-axis is zoomed to the agents' range and shaded bands show the uncertainty "
                    "of each curve. Look at the slopes: the steeper a panel, the more that type's price moves the "
                    "agent's score; flat lines are agents that never ask that type.")
    parts += figure("figures/costs_flip_map.png", f"Share of cost vectors that change the ranking, over the cost "
                    f"shares of Type {i + 1} and Type {j + 1}",
                    f"The share of sampled cost vectors whose agent ranking differs from the charged costs' ranking, "
                    f"over the share of the total cost given to Type {i + 1} ({TYPE_WORDS[i]}, x) and Type {j + 1} "
                    f"({TYPE_WORDS[j]}, y). Look for the regions where the ranking flips.")
    if "in_loop_table" in cs:
        h, lrows = cs["in_loop_table"]
        agent = cs["in_loop_agent"]
        parts += ["### Costs in the loop", "", *in_loop_findings(h, lrows, agent)[:1], "",
                  f"`{agent}` re-run with each cost vector below, which it is both charged and plans with (one "
                  "vmapped call over cost vectors x episodes): \"all xs\" multiplies the four charged costs by s, "
                  f"\"Type t x{cfg.costs.per_type_factor:g}\" one type's cost only. w1..w4: cost of one question of "
                  "Type 1 appearance, 2 region, 3 route hint, 4 confirmation; |Q|, Q1..Q4 per episode; rates in %. "
                  "Read down the |Q| column: asking should fall as costs rise, and a raised type should be asked "
                  "less.", "", M.md_table(h, lrows), ""]
        for line in in_loop_findings(h, lrows, agent)[1:]:
            parts += [line, ""]
        parts += _zero_asking(cs, results, rollouts, cfg)
        parts += figure("figures/costs_in_loop.png", f"{agent}: questions and success against the cost scale",
                        f"Left: `{agent}`'s questions per episode against the cost scale (ticks at the scales run, "
                        f"x{min(cfg.costs.scales):g} to x{max(cfg.costs.scales):g}), per type and in total; right: its "
                        "SR@1.5 and WSR@1.5, with `explorer` (never asks) as a reference line."
                        + (f" Bottom row: the runs that raise one type's cost x{cfg.costs.per_type_factor:g}, that "
                           "type's questions against the locked costs' and the success they leave."
                           if cfg.costs.per_type_factor > 0 else "")
                        + " Bars and bands are 95% intervals over the episodes. Look for asking falling to zero as "
                        "costs rise and success falling toward the reference.")
    return parts


def _section_difficulty(results: dict, es, rollouts: dict, cfg, out: Path) -> list[str]:
    ds = study_difficulty(es, rollouts, cfg, out)
    results["difficulty"] = ds
    abl = ds["ablation"]
    p = ds["default_proportions"]
    cheader, crows = ds["calibration_table"]
    cheader = [cheader[0], *(f"weight: {w}" for w in FACTOR_WORDS), *cheader[5:]]
    parts = ["## Difficulty-coefficient ablation", "",
             difficulty_finding(abl["fraction_ordered"], ds["n_settings"], ds["default_bins"][1]), "",
             "An episode's difficulty score is D = a1 (distractors in the scene) + a2 (distractors in the target's "
             "room) + a3 (context: how little the nearby objects tell the target from its distractors) + a4 (start "
             "distance), each factor in [0, 1]; D below the first threshold is easy, at or above the second hard. "
             f"The study re-bins the episodes for {len(abl['alphas'])} weight vectors (a1..a4) on a grid of the "
             f"simplex x {len(abl['thresholds'])} threshold pairs ({ds['n_settings']} settings), from the factors "
             f"stored with the episodes (a setting that leaves a bin empty counts as {cfg.difficulty.empty}). The "
             f"reference weights {tuple(cfg.difficulty.alpha)} and thresholds {tuple(cfg.difficulty.thresholds)} "
             f"give bins of {100 * p[0]:.0f}/{100 * p[1]:.0f}/{100 * p[2]:.0f}% of the episodes.", "",
             "SR@1.5 (%) per bin at the reference setting; read along a row: a well-ordered agent falls from easy "
             "to hard.", "", M.md_table(*ds["default_bins"]), ""]
    parts += figure("figures/difficulty_ordering.png", "Share of weight settings giving ordered bins",
                    "Left: share of weight vectors whose bins are ordered for every agent, per threshold pair. "
                    "Right: that share against each factor's weight. Look for where ordering holds: the weights "
                    "and thresholds under which harder bins really are harder.")
    parts += [calibration_finding(ds["calibration"]), "",
              "Calibration: the weights whose D best ranks the episodes by failure (Spearman rank correlation "
              "between D and failure, mean over the agents), fitted on one half of the episodes and reported on "
              "the other. Read the last column: higher means D predicts failure better.", "",
              M.md_table(cheader, crows), ""]
    parts += figure("figures/difficulty_calibration.png", "Reference and fitted difficulty weights per factor",
                    "Reference against fitted weight of each factor, with the rank correlations in the legend. "
                    "Look at which factor the fit moves weight to.")
    return parts


def _section_derive_costs(results: dict, es, rollouts: dict, cfg, out: Path) -> list[str]:
    dc = study_derive_costs(cfg, out)
    results["derive-costs"] = dc
    header, rows = dc["table"]
    source = dc["source"]
    if source.startswith("published"):
        source = "the paper's published cue statistics"
        if dc["assumed"]:
            source += (f"; the cues it does not publish ({', '.join(map(str, dc['assumed']))}) share the remaining "
                       "mentions equally and borrow the scores of a similar published cue")
    shown = [[r[0]] + list(r[1:8]) + [" > ".join(str(r[8])), r[9]] for r in rows]
    header = ["setting", "lambda_s (score)", "lambda_h (high gain)", "lambda_r (top 1)", "w1", "w2", "w3", "w4",
              "types by cost, highest first", "RMS distance to locked"]
    parts = ["## Cost derivation", "", derive_finding(rows), "",
             "Each cue c of a target description (colour, shape, room, ...) gets a utility U_c = lambda_s s_c + "
             "lambda_h h_c + lambda_r r_c from its mean importance score s_c, its share of high-gain mentions h_c "
             "and its top-1 rate r_c in human navigation descriptions; a question type's utility is the "
             "mention-weighted mean over its cues, rescaled linearly into the locked costs' range. Input: "
             f"{source}. Read the w columns against the locked row.", "",
             M.md_table(header, shown), ""]
    return parts


def _section_analysis(results: dict, es, rollouts: dict, cfg, out: Path) -> list[str]:
    an = study_analysis(es, rollouts, cfg, out)
    results["analysis"] = an
    agent = an["agent"]
    header, rows = an["per_difficulty"]
    du = an["delta_u"]
    parts = [f"## Interaction analyses (`{agent}`)", "", analysis_finding(agent, rows, du), "",
             f"Questions per episode by difficulty, and Delta-U of the route (Type-3) questions: (A_before - "
             f"A_after) / A_before in %, where A_before is the floor within {du['r']:g} m of the path over the up to "
             f"{du['h']} steps before the question and A_after the same over as many steps after it (the paper's "
             "uncertainty-reduction proxy; areas in m^2, means over the questions counted in the last column).",
             "", M.md_table(header, rows), "", delta_u_note(du), "",
             "Where Type-3 questions were asked, classified from the navigation grid (share of them):", "",
             M.md_table(*an["locations"]), ""]
    if an["content_table"] is not None:
        h, crows = an["content_table"]
        parts += ["What Type-3 questions asked, classified from the question text the agent wrote (rules in "
                  "`ignjax.studies.interaction`; shares of classified in the paper: route 10%, goal-room position "
                  "65%, room relations 25%), in `analysis_type3_content.csv`:", "",
                  M.md_table(h, [[r[0], r[1]] + [f"{100 * v:.1f}%" if math.isfinite(v) else "" for v in r[2:]]
                                 for r in crows]), ""]
    else:
        parts += ["What Type-3 questions asked (route / goal-room position / room relations): not applicable, "
                  f"{an['content']['reason']}.", ""]
    parts += figure("figures/analysis_timing.png", f"When {agent} asks each question type",
                    "Share of each type's questions by how far into the episode they were asked. Look for the "
                    "order: appearance and region early, confirmation late.")
    parts += figure("figures/analysis_type3_locations.png", "Where route questions were asked",
                    "Share of route (Type-3) questions per location class, next to the share of all planner steps "
                    "spent in each class (the base rate), and per content class when the agent writes question "
                    "text. Look for classes where questions are more frequent than steps: junctions and "
                    "corridors, where a route hint helps most.")
    parts += figure("figures/analysis_questions_per_difficulty.png", "Questions per episode by type and difficulty",
                    "Questions per episode of each type on easy, medium and hard episodes. Look for which types "
                    "grow with difficulty.")
    parts += figure("figures/analysis_delta_u.png", "Delta-U of route questions per difficulty",
                    "Mean Delta-U (%) per difficulty; bars below zero mean the agent covered more floor after the "
                    "answer than before it. Compare the sign with the paper's positive values.")
    plots = an["trajectory_plots"]
    for k, (p, rec) in enumerate(plots):
        what = f"the {rec['difficulty']} episode `{rec['episode_id']}` (find a {rec['target_category'].replace('_', ' ')})"
        parts += figure(p.relative_to(out).as_posix(), f"Trajectories of every agent on {rec['episode_id']}",
                        f"Figure {k + 1} of {len(plots)}: every agent on {what}, one panel each, the path coloured "
                        "by planner step with arrows for the direction of travel, the target (gold star) and its "
                        "same-category distractors (grey stars) on top of the furniture, where each question type "
                        "was asked, and each agent's outcome in its panel's title. Look at where the paths part and "
                        "what the questions changed.")
    return parts


SECTIONS = MappingProxyType({
    "eval": _section_eval,
    "costs": _section_costs,
    "difficulty": _section_difficulty,
    "derive-costs": _section_derive_costs,
    "analysis": _section_analysis,
})
"""Study name -> its report section: runs the study's tables and figures on
the sweep's results and returns the section's markdown lines. The order is
the report's (and :data:`ignjax.sweep.cli.STUDIES`', which lists the same
names without importing the studies). A new study is one module in
:mod:`ignjax.studies` plus one entry here and in ``STUDIES``."""


def write_outputs(results: dict, out: Path) -> None:
    """Run the table-and-figure part of each study in ``results["studies"]`` and write ``report.md``."""
    cfg, studies = results["config"], results["studies"]
    es = results.get("episodes")
    rollouts = results.get("rollouts", {})
    parts = [f"# ignjax sweep: {cfg.run.name}", ""]
    if es is not None:
        counts = {b: sum(r["difficulty"] == b for r in es.records) for b in BIN_NAMES}
        parts += [f"Benchmark: {len(es)} episodes in {len(es.bank.scene_ids)} scenes "
                  f"({', '.join(f'{counts[b]} {b}' for b in BIN_NAMES)}); seed {cfg.run.seed}; question costs "
                  f"charged (and planned with by cost-aware agents): {costs_by_type(cfg.eval.costs)}; "
                  f"{M.success_rule(cfg.eval.require_stop)}.", ""]
        agents = list(dict.fromkeys(list(cfg.eval.agents) + ([cfg.analysis.agent] if "analysis" in studies else [])))
        parts += settings_lines(cfg.to_dict()["sim"], cfg.agents.used(agents, cfg.sim))
        parts += [mllm_settings_line(cfg)] if any(a in LLM_AGENTS for a in agents) else []
        parts += [""] + definitions_lines(cfg)
    for name, section in SECTIONS.items():
        if name in studies:
            parts += section(results, es, rollouts, cfg, out)
    atomic_write(out / "report.md", "\n".join(parts))


__all__ = ["FACTOR_WORDS", "SECTIONS", "TYPE_WORDS", "agent_line", "analysis_finding", "calibration_finding",
           "costs_by_type", "definitions_lines", "delta_u_note", "derive_finding", "difficulty_finding",
           "eval_finding", "figure", "in_loop_findings", "mllm_settings_line", "offline_finding", "privileged_note",
           "settings_lines", "shortest_move", "write_outputs", "zero_asking_note"]
