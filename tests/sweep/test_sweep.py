"""The main job, ``python -m ignjax.sweep``: studies on the shared small
benchmark, outputs recomputable from the outcome tables, resume after
SIGKILL with identical bytes, and bad input rejected before any work."""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import chex
import numpy as np
import pytest

from ignjax.agents import registry
from ignjax.agents.params import param_values
from ignjax.config import (CostsConfig, DifficultyConfig, EvalConfig, SweepConfig, default_toml, fingerprint,
                           parse_set, resolve)
from ignjax.errors import ConfigError, InputError
from ignjax.protocol import LOCKED_COSTS
from ignjax.sim.types import SimConfig
from ignjax.sweep.checkpoints import Checkpoints, prepare_folder
from ignjax.sweep.cli import main
from ignjax.sweep.stages import run_sweep

REPO = Path(__file__).resolve().parents[2]


def _sets(path, out_root) -> list[str]:
    return [f"benchmark.episodes='{path}'", f"run.out='{out_root}'", "eval.agents=['random', 'eig']",
            "eval.batch=8", "costs.samples=500", "costs.scales=[0.25, 1.0, 4.0]", "costs.per_type_factor=4.0",
            "analysis.trajectories=1"]


@pytest.fixture(scope="module")
def sweep_run(small_benchmark, tmp_path_factory):
    root = tmp_path_factory.mktemp("sweep")
    cfg = resolve(None, _sets(small_benchmark["path"], root), quick=True)
    out = root / "full"
    res = run_sweep(cfg, ["eval", "costs", "difficulty", "derive-costs", "analysis"], out, quiet=True)
    return {"cfg": cfg, "out": out, "res": res, "root": root}


def test_report_and_tables_are_written(sweep_run):
    out = sweep_run["out"]
    report = (out / "report.md").read_text()
    for section in ("## Evaluation", "## Cost-weight sensitivity", "## Difficulty-coefficient ablation",
                    "## Cost derivation", "## Interaction analyses"):
        assert section in report
    for name in ("outcomes.parquet", "outcomes.csv", "metrics.csv", "costs_offline.csv", "costs_in_loop.csv",
                 "difficulty_default_bins.csv", "difficulty_calibration.csv", "derive_costs.csv",
                 "analysis_per_difficulty.csv", "analysis_type3_locations.csv"):
        assert (out / name).is_file(), name
    figs = sorted(p.name for p in (out / "figures").glob("*.png"))
    assert "costs_in_loop.png" in figs and "trajectory_0.png" in figs and len(figs) >= 10
    for f in figs:  # every figure the report embeds exists
        assert (out / "figures" / f).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for ref in [line.split("(")[1].rstrip(")") for line in report.splitlines() if line.startswith("![")]:
        assert (out / ref).is_file(), ref


def test_wsr_columns_recompute_from_outcomes_alone(sweep_run):
    """metrics.csv's WSR@t equals a plain loop over outcomes.csv rows."""
    out = sweep_run["out"]
    costs = sweep_run["cfg"].eval.costs
    with open(out / "outcomes.csv") as fh:
        rows = list(csv.DictReader(fh))
    with open(out / "metrics.csv") as fh:
        metrics = {r["agent"]: r for r in csv.DictReader(fh)}
    assert set(metrics) == {"random", "eig"}
    for agent, m in metrics.items():
        mine = [r for r in rows if r["agent"] == agent]
        assert len(mine) == 40
        assert sweep_run["cfg"].eval.require_stop is False  # the paper's rule by default
        for thr in (1.5, 3.0):
            total = 0.0
            for r in mine:
                ok = float(r["final_distance"]) <= thr
                n = [int(r[f"q{t}"]) for t in range(1, 5)]
                total += ok * math.exp(-sum(c * k for c, k in zip(costs, n)))
            assert float(m[f"WSR@{thr:g}"]) == pytest.approx(100 * total / len(mine), abs=1e-3)


def test_in_loop_asking_falls_as_costs_rise(sweep_run):
    """Every setting plans with the cost vector it is charged: asking falls as
    all costs rise, and raising one type's cost lowers that type's asking."""
    table = sweep_run["res"]["costs"]["in_loop_table"]
    header, rows = table
    q = {r[0]: r[header.index("|Q|")] for r in rows}
    assert q["all x0.25"] > q["all x4"], q
    per = {r[0]: [r[header.index(f"Q{t}")] for t in range(1, 5)] for r in rows}
    assert [f"Type {t} x4" for t in range(1, 5)] == [r[0] for r in rows[-4:]]
    for t in range(4):  # the per-type vectors: w_t x 4, the others locked
        w = rows[3 + t][1:5]
        assert w[t] == pytest.approx(4 * LOCKED_COSTS[t]) and all(w[s] == pytest.approx(LOCKED_COSTS[s]) for s in range(4) if s != t)
        assert per[f"Type {t + 1} x4"][t] <= per["all x1"][t], (t, per)
    assert sum(per[f"Type {t + 1} x4"][t] for t in range(4)) < sum(per["all x1"]), per


def test_run_json_and_report_header_record_every_setting(sweep_run):
    """run.json holds every key of the configuration (every [sim] field and
    every agent's parameters); the report header states the success rule,
    the simulator settings and the evaluated agents' parameters."""
    out, cfg = sweep_run["out"], sweep_run["cfg"]
    config = json.loads((out / "run.json").read_text())["config"]
    assert config == json.loads(json.dumps(cfg.to_dict()))
    assert set(config["sim"]) == {f.name for f in dataclasses.fields(SimConfig)}
    assert set(config["agents"]) == set(registry())
    assert set(config["agents"]["eig"]) == set(param_values(registry()["eig"]))
    head = (out / "report.md").read_text().split("## ", 1)[0]
    assert "success = final geodesic distance <= tau (the paper's rule" in head
    assert "- Simulator: max_steps=20, max_questions=10," in head and "question_budget=True" in head
    assert "- Agent `eig`: cost-aware: " in head and "Parameters: threshold=2.5, " in head
    assert "- Agent `random`: random moves" in head and "Parameters: stop_prob=0.05." in head


def test_every_sim_field_and_agent_parameter_is_a_config_key():
    """Each [sim] field and each [agents.<name>] parameter can be set with
    --set, reaches the typed configuration and run.json's dict, and is a key
    of sweeps/default.toml."""
    changed = {"max_steps": 24, "max_questions": 7, "horizon": 2.5, "collision_distance": 0.5,
               "collision_heights": [0.2, 0.9], "micro_step": 0.4, "max_micro_steps": 6, "eye_height": 1.1,
               "image_size": [320, 240], "hfov": 90.0, "n_views": 12, "depth_range": 8.0, "pullback": 0.25, "waypoint_tolerance": 0.2,
               "hint_lookahead": 3.0, "confirm_range": 2.5, "stop_radius": 0.8, "hint_reached": 0.7,
               "obs_rays_per_view": 4, "obs_range": 5.0, "max_visible": 12, "trace_len": 30, "question_budget": False,
               "upfront_description": True, "miss_rate": 0.2, "confusion_rate": 0.1}
    assert set(changed) == {f.name for f in dataclasses.fields(SimConfig)}, "add the new SimConfig field here"
    cfg = resolve(None, [f"sim.{k}={json.dumps(v)}" for k, v in changed.items()])
    assert cfg.sim.to_dict() == changed and cfg.to_dict()["sim"] == changed
    # hfov sets the width of the 8 views (12 views tile the circle, so it keeps its default above)
    assert resolve(None, ["sim.hfov=80.0"]).to_dict()["sim"]["hfov"] == 80.0
    for name, agent in registry().items():
        if agent.source is not None:
            continue  # its settings name files, not the parameters' fields (tests/agents/test_learned.py)
        for key, value in param_values(agent).items():
            new = (not value) if isinstance(value, bool) else (value + 1 if not isinstance(value, tuple) else value)
            got = resolve(None, [f"agents.{name}.{key}={json.dumps(new)}"])
            assert got.to_dict()["agents"][name][key] == new
            leaf = np.asarray(getattr(got.agents.make(name), key))
            np.testing.assert_allclose(leaf, np.asarray(new, leaf.dtype))
    toml = tomllib.loads(default_toml())
    assert set(toml["sim"]) == set(changed)
    assert {n: set(v) for n, v in toml["agents"].items()} == {n: set(param_values(a)) for n, a in registry().items()}
    text = default_toml()
    for section, obj in SweepConfig().sections().items():
        if section != "agents":
            # a setting unset by default (TOML has no null) is listed commented out
            unset = {f.name for f in dataclasses.fields(obj) if getattr(obj, f.name) is None}
            assert set(toml[section]) == {f.name for f in dataclasses.fields(obj)} - unset, section
            assert all(f"# {k} = (unset)" in text for k in unset), section


def test_offline_study_reference_rows(sweep_run):
    res = sweep_run["res"]["costs"]["offline"]
    assert np.allclose(res["costs"][0], SweepConfig().eval.costs)
    assert res["tau"][0] == pytest.approx(1.0)
    metrics = sweep_run["res"]["eval"]["metrics"]
    for a, name in enumerate(res["agent_names"]):  # row 0 (locked costs) reproduces the evaluation's WSR@1.5
        assert 100 * res["wsr_ranked"][0, a] == pytest.approx(metrics[name]["WSR@1.5"], abs=1e-3)


def test_resume_after_sigkill_gives_identical_outputs(sweep_run, small_benchmark, tmp_path):
    """Kill a run with SIGKILL after its first checkpoint, resume it: same bytes as the uninterrupted run."""
    out = tmp_path / "killed"
    args = [sys.executable, "-m", "ignjax.sweep", "--quick", "--quiet", "--out", str(out)]
    for s in _sets(small_benchmark["path"], sweep_run["root"]):
        args += ["--set", s]
    env = dict(os.environ, PYTHONHASHSEED="0")
    proc = subprocess.Popen(args, cwd=REPO, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    ck = out / "checkpoints"
    deadline = time.time() + 300
    while time.time() < deadline and proc.poll() is None:
        if ck.is_dir() and any(p.is_dir() and ".orbax-checkpoint-tmp" not in p.name for p in ck.iterdir()):
            break
        time.sleep(0.2)
    assert proc.poll() is None, "the run ended before it could be interrupted: " + proc.stderr.read().decode()[-2000:]
    checkpoints = [p for p in ck.iterdir() if p.is_dir() and ".orbax-checkpoint-tmp" not in p.name] if ck.is_dir() else []
    if not checkpoints:
        proc.kill()
        pytest.fail("no checkpoint appeared within 300 s: the kill would not test a resume from one")
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert not (out / "report.md").exists()
    # without --resume the folder is refused
    refused = subprocess.run(args, cwd=REPO, env=env, capture_output=True, text=True)
    assert refused.returncode == 2 and "--resume" in refused.stderr
    done = subprocess.run(args + ["--resume"], cwd=REPO, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-3000:]
    full = sweep_run["out"]
    files = sorted(p.relative_to(full) for p in full.rglob("*") if p.is_file() and "checkpoints" not in p.parts)
    assert files == sorted(p.relative_to(out) for p in out.rglob("*") if p.is_file() and "checkpoints" not in p.parts)
    for f in files:
        assert (full / f).read_bytes() == (out / f).read_bytes(), f


# ---------------------------------------------------------------------------
# bad input: clear errors before any work
# ---------------------------------------------------------------------------


def _err(capsys, argv) -> str:
    assert main(argv) == 2
    return capsys.readouterr().err


def test_unknown_study_and_agent(capsys, tmp_path):
    assert "unknown study 'speed'" in _err(capsys, ["--study", "speed", "--out", str(tmp_path / "a")])
    assert "unknown agent 'oracle'" in _err(capsys, ["--set", "eval.agents=['oracle']", "--out", str(tmp_path / "b")])
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_malformed_toml_names_file_and_line(tmp_path, capsys):
    p = tmp_path / "bad.toml"
    p.write_text("[costs]\nsamples = 10\nscales = [1.0, \n")
    err = _err(capsys, ["--config", str(p)])
    assert "bad.toml:" in err and "malformed TOML" in err
    p.write_text("[costs]\nsamples = 10\nsample_count = 3\n")
    err = _err(capsys, ["--config", str(p)])
    assert "bad.toml:3" in err and "costs.sample_count" in err
    p.write_text("[costz]\nsamples = 10\n")
    assert "unknown section" in _err(capsys, ["--config", str(p)])


def test_set_items_are_checked():
    with pytest.raises(ConfigError, match="unknown key costs.nope"):
        parse_set("costs.nope=3")
    with pytest.raises(ConfigError, match="section.key=value"):
        parse_set("samples")
    with pytest.raises(ConfigError, match="expected an integer"):
        resolve(None, ["costs.samples='many'"])
    assert resolve(None, ["costs.samples=7"]).costs.samples == 7


@pytest.mark.parametrize("costs, reason", [("[-0.1, 0.1, 0.1, 0.1]", "negative"), ("[nan, 0.1, 0.1, 0.1]", "finite"),
                                           ("[0.0, 0.0, 0.0, 0.0]", "zero")])
def test_bad_costs(costs, reason):
    with pytest.raises((ConfigError, InputError), match=reason):
        resolve(None, [f"eval.costs={costs}"])


def test_alpha_must_be_on_the_simplex_unless_normalised():
    with pytest.raises(ConfigError, match="negative"):
        resolve(None, ["difficulty.alpha=[-0.1, 0.5, 0.3, 0.3]"])
    with pytest.raises(ConfigError, match="sum to 1"):
        resolve(None, ["difficulty.alpha=[1.0, 1.0, 1.0, 1.0]"])
    cfg = resolve(None, ["difficulty.alpha=[1.0, 1.0, 1.0, 1.0]", "difficulty.normalize=true"])
    assert cfg.difficulty.alpha == (0.25, 0.25, 0.25, 0.25)
    with pytest.raises(ConfigError, match="thresholds"):
        resolve(None, ["difficulty.thresholds=[0.6, 0.3]"])


def test_empty_episode_file_is_rejected(tmp_path, capsys):
    import gzip

    p = tmp_path / "empty.jsonl.gz"
    with gzip.open(p, "wt") as fh:
        fh.write("")
    err = _err(capsys, ["--study", "eval", "--set", f"benchmark.episodes='{p}'", "--out", str(tmp_path / "r")])
    assert "empty.jsonl.gz" in err and ("no episodes" in err or "empty" in err)


def test_folder_with_another_run_is_refused(sweep_run, tmp_path):
    cfg = resolve(None, _sets("x.jsonl.gz", sweep_run["root"]) + ["costs.samples=999"], quick=True)
    with pytest.raises(InputError, match="different run"):
        run_sweep(cfg, ["derive-costs"], sweep_run["out"], resume=True)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="holds no ignjax run"):
        run_sweep(cfg, ["derive-costs"], foreign)
    assert (foreign / "notes.txt").read_text() == "mine"
    run_sweep(cfg, ["derive-costs"], foreign, force=True)  # --force replaces it
    assert (foreign / "derive_costs.csv").is_file() and not (foreign / "notes.txt").exists()


def test_help_lists_every_option():
    out = subprocess.run([sys.executable, "-m", "ignjax.sweep", "--help"], cwd=REPO, capture_output=True, text=True)
    assert out.returncode == 0
    for opt in ("--study", "--config", "--set", "--out", "--quick", "--resume", "--force"):
        assert opt in out.stdout


# ---------------------------------------------------------------------------
# the configuration: typed, complete in sweeps/default.toml, checked with locations
# ---------------------------------------------------------------------------


def test_default_toml_is_generated_from_the_dataclasses():
    """sweeps/default.toml lists every key with its default and description; regenerate it with
    python -c "from ignjax.config import default_toml; print(default_toml(), end='')" > sweeps/default.toml"""
    assert (REPO / "sweeps" / "default.toml").read_text(encoding="utf-8") == default_toml()
    assert resolve(REPO / "sweeps" / "default.toml") == SweepConfig()
    assert SweepConfig.from_dict(SweepConfig().to_dict()) == SweepConfig()


@pytest.mark.parametrize("name", ["default.toml", "cost_sensitivity_large.toml", "learned_study.toml"])
def test_shipped_configs_resolve(name):
    cfg = resolve(REPO / "sweeps" / name)
    if name == "cost_sensitivity_large.toml":
        assert cfg.costs.samples == 1_000_000 and cfg.run.name == "costs_large"
    if name == "learned_study.toml":
        assert cfg.eval.agents[0] == "learned" and cfg.costs.agent == "learned"


def test_config_is_frozen_typed_and_checked_from_python():
    cfg = resolve(None, ["eval.thresholds=[1, 2]", "sim.max_steps=12", "sim.collision_heights=[0.2, 1]"])
    assert cfg.eval.thresholds == (1.0, 2.0) and isinstance(cfg.eval.thresholds[0], float)
    assert cfg.sim == SimConfig(max_steps=12, collision_heights=(0.2, 1.0))
    with pytest.raises(dataclasses.FrozenInstanceError):
        cfg.eval.batch = 3
    with pytest.raises(ConfigError, match="eval.batch: must be >= 1"):
        EvalConfig(batch=0)
    with pytest.raises(ConfigError, match="expected an integer"):
        CostsConfig(samples=1.5)
    assert DifficultyConfig(alpha=[2, 2, 2, 2], normalize=True).alpha == (0.25, 0.25, 0.25, 0.25)
    with pytest.raises(ConfigError, match="sim.max_steps"):
        resolve(None, ["sim.max_steps=0"])
    with pytest.raises(ConfigError, match="expected integers"):
        resolve(None, ["sim.image_size=[1.5, 2]"])


def test_errors_name_where_the_key_was_set(tmp_path):
    p = tmp_path / "c.toml"
    p.write_text("[run]\nname = 'x'\n\n[costs]\nseed = 1\nscales = [1.0, -2.0]\n")
    with pytest.raises(ConfigError, match=r"c.toml:6: costs.scales: scales must be positive"):
        resolve(p)
    p.write_text("[eval]\nbatch = 'many'\n")
    with pytest.raises(ConfigError, match=r"c.toml:2: eval.batch: expected an integer"):
        resolve(p)
    p.write_text("[eval]\nbatch = 0\n")
    assert resolve(p, ["eval.batch=8"]).eval.batch == 8  # a later layer may repair an earlier one's value
    with pytest.raises(ConfigError, match=r"c.toml:2: eval.batch: must be >= 1"):
        resolve(p)
    with pytest.raises(ConfigError, match=r"--set: eval.agents: unknown agent 'oracle'"):
        resolve(p, ["eval.batch=8", "eval.agents=['oracle']"])
    with pytest.raises(ConfigError, match=r"--set: difficulty.alpha: .*sum to 1"):
        resolve(None, ["difficulty.alpha=[1.0, 1.0, 1.0, 1.0]"])


def test_fingerprint_is_a_function_of_the_configuration():
    a, b = resolve(None, ["costs.samples=7"]), resolve(None, ["costs.samples=7"])
    assert fingerprint(a, ["eval"]) == fingerprint(b, ["eval"])
    assert fingerprint(a, ["eval"]) != fingerprint(a, ["eval", "costs"])
    assert fingerprint(a, ["eval"]) != fingerprint(resolve(None, ["costs.samples=8"]), ["eval"])
    assert fingerprint(a, ["eval"]) != fingerprint(resolve(None, ["costs.samples=7", "sim.max_steps=21",
                                                                  "sim.trace_len=21"]), ["eval"])


def test_checkpoint_stage_is_absent_until_complete(tmp_path):
    ck = Checkpoints(tmp_path / "checkpoints")
    stale = tmp_path / "checkpoints" / "eval__x.orbax-checkpoint-tmp"  # what a save killed midway leaves
    stale.mkdir(parents=True)
    (stale / "junk").write_text("partial")
    assert not ck.has("eval/x")
    tree = {"out": {"a": np.arange(5, dtype=np.float32)}, "costs": np.eye(2)}
    ck.save("eval/x", tree)
    assert ck.has("eval/x") and not stale.exists()
    got = ck.load("eval/x")
    assert np.array_equal(got["out"]["a"], tree["out"]["a"]) and np.array_equal(got["costs"], tree["costs"])


def test_resume_deletes_what_a_killed_write_left_and_nothing_else(tmp_path):
    """A run killed inside atomic_write leaves ``.<name>.tmp-<pid>``; --resume deletes it, keeps the rest."""
    cfg, out = resolve(None, ["costs.samples=7"]), tmp_path / "run"
    prepare_folder(out, cfg, ["eval"], resume=False, force=False)
    (out / "figures").mkdir()
    left = [out / ".outcomes.csv.tmp-4242", out / "figures" / ".costs_in_loop.png.tmp-4243"]
    kept = [out / "outcomes.csv", out / "figures" / "costs_in_loop.png", out / "notes.tmp-1"]
    for p in left + kept:
        p.write_text("x")
    with pytest.raises(InputError, match="--resume"):
        prepare_folder(out, cfg, ["eval"], resume=False, force=False)
    assert all(p.exists() for p in left)  # a refused call changes nothing
    prepare_folder(out, cfg, ["eval"], resume=True, force=False)
    assert not any(p.exists() for p in left) and all(p.exists() for p in kept)


def test_every_study_has_one_report_section_in_the_same_order():
    from ignjax.sweep.cli import STUDIES
    from ignjax.sweep.sections import SECTIONS

    assert tuple(SECTIONS) == STUDIES


def test_sweep_in_buckets_gives_the_same_results(sweep_run, small_benchmark, tmp_path):
    """The sweep's rollout stages (``eig``'s evaluation and the in-the-loop costs) with a bank budget that
    splits the two scenes into two buckets, run one at a time: the results every study is computed from equal
    the one-bank run's exactly, and so does the in-the-loop table, byte for byte. (The evaluation's files in
    buckets are checked byte for byte in tests/evaluate/test_buckets.py, ``random``'s rollouts there too.)"""
    from ignjax.episodes.dataset import open_benchmark
    from ignjax.evaluate.runner import plan_run
    from ignjax.scenes.buckets import padded_bytes

    bs = open_benchmark(small_benchmark["path"])
    tight = (padded_bytes(bs.host.navgrids) - 1) / 2**20
    assert len(plan_run(bs, 256, tight).buckets) == 2
    sets = _sets(small_benchmark["path"], sweep_run["root"]) + [f"eval.bank_mb={tight!r}", "eval.agents=['eig']"]
    out = tmp_path / "buckets"
    res = run_sweep(resolve(None, sets, quick=True), ["eval", "costs"], out, quiet=True)
    one = sweep_run["res"]
    chex.assert_trees_all_equal(res["rollouts"]["eig"], one["rollouts"]["eig"])
    chex.assert_trees_all_equal(res["in_loop"], one["in_loop"])
    assert (out / "costs_in_loop.csv").read_bytes() == (sweep_run["out"] / "costs_in_loop.csv").read_bytes()
    assert json.loads((out / "run.json").read_text())["config"]["eval"]["bank_mb"] == pytest.approx(tight)


# ---------------------------------------------------------------------------
# the report's text: tables that render, captions, findings from the data
# ---------------------------------------------------------------------------

CELL_SPLIT = re.compile(r"(?<!\\)\|")


def _cells(line: str) -> list[str]:
    """A GFM table row's cells (an escaped pipe, ``\\|``, stays inside its cell)."""
    return [c.strip() for c in CELL_SPLIT.split(line.strip())[1:-1]]


def _tables(text: str) -> list[tuple[int, list[str]]]:
    """(line index, lines) of every block of consecutive lines starting with ``|``."""
    out, lines = [], text.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("|"):
            j = i
            while j < len(lines) and lines[j].startswith("|"):
                j += 1
            out.append((i, lines[i:j]))
            i = j
        else:
            i += 1
    return out


def test_every_table_renders_with_a_reading(sweep_run):
    """Every table in report.md is a GFM table: a header, a separator row of as many cells, every row with as
    many cells as the header (escaped pipes kept inside cells), and a line of text before it."""
    text = (sweep_run["out"] / "report.md").read_text()
    lines = text.splitlines()
    tables = _tables(text)
    assert len(tables) >= 8
    for start, rows in tables:
        header = _cells(rows[0])
        assert len(rows) >= 3 and all(re.fullmatch(r":?-{3,}:?", c) for c in _cells(rows[1])), rows[:2]
        for row in rows[1:]:
            assert len(_cells(row)) == len(header), (rows[0], row)
        before = [line for line in lines[:start] if line.strip()]
        assert before and not before[-1].startswith(("|", "#", "!")), rows[0]
    assert "| Agent | Easy SR@1.5 | Easy \\|Q\\| |" in text  # the |Q| columns are escaped at the source


def test_every_figure_has_a_caption_and_its_own_alt_text(sweep_run):
    lines = (sweep_run["out"] / "report.md").read_text().splitlines()
    figures = [(i, re.fullmatch(r"!\[(.+)\]\((.+)\)", line)) for i, line in enumerate(lines) if line.startswith("![")]
    assert len(figures) >= 10 and all(m for _, m in figures)
    alts = [m.group(1) for _, m in figures]
    assert len(set(alts)) == len(alts), alts
    for i, m in figures:
        caption = next(line for line in lines[i + 1:] if line.strip())
        assert caption.startswith("*") and caption.endswith("*") and len(caption) > 40, (m.group(2), caption)


def test_sections_open_with_findings_from_the_data(sweep_run):
    """The evaluation's first sentence names the agent metrics.csv shows as best on SR@1.5; the in-the-loop
    finding quotes the table's first and last |Q|; every section's first line is a sentence, not a table."""
    out = sweep_run["out"]
    text = (out / "report.md").read_text()
    with open(out / "metrics.csv") as fh:
        metrics = {r["agent"]: r for r in csv.DictReader(fh)}
    best = max(metrics, key=lambda a: float(metrics[a]["SR@1.5"]))
    body = {s.split("\n", 1)[0]: s.split("\n", 1)[1] for s in text.split("\n## ")[1:]}
    first = {k: next(line for line in v.splitlines() if line.strip()) for k, v in body.items()}
    assert first["Evaluation (Table-1 columns)"].startswith(f"`{best}` has")
    assert f"({float(metrics[best]['SR@1.5']):.1f}%)" in first["Evaluation (Table-1 columns)"]
    for name, line in first.items():
        assert line[0] not in "|!" and line.endswith("."), (name, line)
    h, rows = sweep_run["res"]["costs"]["in_loop_table"]
    assert f"asks {rows[0][h.index('|Q|')]:.2f} questions per episode at x0.25" in text
    head = text.split("## ", 1)[0]
    random_line = [line for line in head.splitlines() if line.startswith("- Agent `random`")]
    assert random_line and "stop_prob" in random_line[0]
    assert "Eq. wsr" not in text and "row 0 locked" not in text and "F_distractor" not in text
