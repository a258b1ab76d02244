"""The ``learned`` agent with the core install (no flax): the shipped policy and its record, ``python -m
ignjax.evaluate --agent learned`` end to end (the shipped policy and a checkpoint named by ``--set``), what
``run.json`` records (the checkpoint's path and weights' digest, never the weights), checkpoints refused
before any episode with one line naming the file and the entry, the sweep's settings (its fingerprint and
run record name the weights; the in-the-loop study's parameters read each charged cost), and the agent's
compiled program holding the weights as arguments, not constants. The agent against the RL environment and
the flax network: tests/rl/test_learned_agent_env.py."""

from __future__ import annotations

import hashlib
import json
import re
import tomllib
from pathlib import Path

import jax
import numpy as np
import pytest

from ignjax.agents import get_agent
from ignjax.agents.learned.agent import LEARNED, LearnedParams, learned_act, learned_init
from ignjax.agents.learned.record import EXPORTED_RECORD, check_record, record
from ignjax.agents.learned.source import SHIPPED, load, locate
from ignjax.agents.learned.weights import WEIGHTS_FILE, NetShape, npz_bytes
from ignjax.agents.params import make_params, param_record, param_values
from ignjax.config import fingerprint, loaded_agents, resolve
from ignjax.errors import InputError
from ignjax.evaluate.cli import main
from ignjax.fileio import file_sha256
from ignjax.protocol import LOCKED_COSTS
from ignjax.rl.obs import obs_size
from ignjax.rl.actions import n_actions
from ignjax.sim import env as E
from ignjax.sim.types import SimConfig

ROOT = Path(__file__).resolve().parents[2]
DOUBLE = "0.364,0.324,0.48,0.206"
SHAPE = NetShape("gru", 64, 2, obs_size(SimConfig()), n_actions(SimConfig()))
"""The shipped policy's shape: a checkpoint of this shape runs the same compiled program."""


def random_weights(shape: NetShape = SHAPE, seed: int = 0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    return {n: (0.3 * rng.standard_normal(s)).astype(np.float32) for n, s in shape.shapes().items()}


def export(folder: Path, weights=None, config: SimConfig = SimConfig(), **changes) -> Path:
    """An exported policy folder of ``weights`` and its record (``changes`` replace record entries)."""
    weights = random_weights() if weights is None else weights
    data = npz_bytes(weights)
    rec = {**record(config, {"core": "gru", "hidden": 64, "layers": 2}, "test", 0),
           "weights_sha256": hashlib.sha256(data).hexdigest(), **changes}
    folder.mkdir(parents=True, exist_ok=True)
    (folder / WEIGHTS_FILE).write_bytes(data)
    (folder / EXPORTED_RECORD).write_text(json.dumps(rec))
    return folder


def test_shipped_policy_is_recorded_checked_and_small():
    npz, meta = SHIPPED / WEIGHTS_FILE, SHIPPED / EXPORTED_RECORD
    rec = json.loads(meta.read_text())
    assert rec["weights_sha256"] == file_sha256(npz)
    assert npz.stat().st_size < 1 << 20
    check_record(rec, record(SimConfig(), rec["policy"], "", 0), SHIPPED)
    loaded = load(locate(""), SimConfig())
    assert loaded.folder == SHIPPED and loaded.sha256 == rec["weights_sha256"]
    readme = (SHIPPED / "README.md").read_text()
    assert "python -m ignjax.rl.train" in readme and "python -m ignjax.rl.export" in readme
    assert rec["training"]["config"]["run"]["seed"] is not None  # how it was trained travels with it
    package_data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert "data/policy/*" in package_data["ignjax"]


def test_settings_and_run_record_name_the_checkpoint_not_the_weights(tmp_path):
    assert param_values(LEARNED) == {"checkpoint": "", "greedy": False}
    folder = export(tmp_path / "p")
    params = make_params(LEARNED, {"checkpoint": str(folder), "greedy": True},
                         costs=[float(c) for c in DOUBLE.split(",")])
    assert isinstance(params, LearnedParams) and bool(params.greedy)
    np.testing.assert_allclose(params.costs, [float(c) for c in DOUBLE.split(",")])
    assert any(leaf.size == 64 * 64 for leaf in jax.tree.leaves(params))  # the weights are the pytree's leaves
    rec = param_record(LEARNED, {"checkpoint": str(folder)}, SimConfig(), params)
    assert rec["checkpoint"] == str(folder) and rec["weights_sha256"] == file_sha256(folder / WEIGHTS_FILE)
    assert len(json.dumps(rec)) < 1000  # no numbers of the weights
    with pytest.raises(Exception, match="expected a string"):
        make_params(LEARNED, {"checkpoint": 3})


def test_weights_are_arguments_of_the_compiled_step_not_constants(small_world, small_benchmark):
    """The cache rule: ``init`` / ``act`` are module-level functions of ignjax, and the weights reach the
    program as parameters (nothing the size of a weight matrix is closed over)."""
    for fn in (LEARNED.init, LEARNED.act, LEARNED.default_params):
        assert fn.__module__.startswith("ignjax.") and "<" not in fn.__qualname__
    params = LEARNED.default_params()
    spec = jax.tree.map(lambda a: a[0], small_benchmark["set"].specs)
    state = E.reset(small_world, spec, jax.random.key(0))
    obs = E.observe(small_world, state)
    pstate = learned_init(params, obs, jax.random.key(1))
    jaxpr = jax.make_jaxpr(learned_act)(params, obs, state.answers, pstate, jax.random.key(2))
    assert all(np.size(c) < 1000 for c in jaxpr.consts), [np.shape(c) for c in jaxpr.consts]
    action, after = learned_act(params, obs, state.answers, pstate, jax.random.key(2))
    assert after.carry.shape == (64,) and not bool(after.first) and 0 <= int(action.kind) <= 2


def test_default_parameters_stay_concrete_when_first_built_under_a_trace():
    """They are cached: built first inside a traced function (a rollout asking for them), they must not hold
    that trace's tracers."""
    from ignjax.agents.learned import agent as L

    L._shipped.cache_clear()
    jax.eval_shape(lambda: L.default_params().costs)
    assert not any(isinstance(x, jax.core.Tracer) for x in jax.tree.leaves(L.default_params()))


@pytest.fixture(scope="module")
def evaluated(small_benchmark, tmp_path_factory):
    """``--agent learned`` with the shipped policy, then with a checkpoint named by --set (the same network
    shape, so the same compiled program), greedy on and twice the locked costs."""
    out = tmp_path_factory.mktemp("eval_learned")
    ckpt = export(out / "exported", random_weights(seed=1))
    argv = ["--episodes", str(small_benchmark["path"]), "--agent", "learned", "--limit", "8", "--batch", "8",
            "--quiet"]
    assert main(argv + ["--out", str(out / "shipped")]) == 0
    assert main(argv + ["--out", str(out / "set"), "--costs", DOUBLE, "--set", f"agents.learned.checkpoint={ckpt}",
                        "--set", "agents.learned.greedy=true"]) == 0
    return {"out": out, "checkpoint": ckpt}


def test_evaluate_runs_the_learned_agent(evaluated):
    from ignjax.evaluate.outcomes import read_outcomes

    for name in ("shipped", "set"):
        rows = read_outcomes(evaluated["out"] / name / "outcomes.csv")
        assert len(rows) == 8 and {r["agent"] for r in rows} == {"learned"}
    shipped = json.loads((evaluated["out"] / "shipped" / "run.json").read_text())["agents"]["learned"]
    assert shipped["checkpoint"] == str(SHIPPED) and shipped["greedy"] is False
    assert shipped["weights_sha256"] == file_sha256(SHIPPED / WEIGHTS_FILE)
    assert shipped["costs"] == pytest.approx(LOCKED_COSTS)
    text = (evaluated["out"] / "set" / "run.json").read_text()
    used = json.loads(text)["agents"]["learned"]
    assert used["checkpoint"] == str(evaluated["checkpoint"]) and used["greedy"] is True
    assert used["weights_sha256"] == file_sha256(evaluated["checkpoint"] / WEIGHTS_FILE)
    assert used["costs"] == pytest.approx([float(c) for c in DOUBLE.split(",")])  # planned = charged
    assert set(used) == {"checkpoint", "weights_sha256", "network", "update", "training_fingerprint", "greedy",
                         "costs"}
    assert len(text) < 4000  # the weights are not in it


def test_the_viewer_shows_the_learned_agent(evaluated):
    from ignjax.view.cli import main as view

    out = evaluated["out"] / "shipped"
    assert view([str(out), "--out", str(out / "v.html")]) == 0
    assert '"learned"' in (out / "v.html").read_text()


def _refusal(capsys, small_benchmark, tmp_path, checkpoint) -> str:
    """Evaluate with ``checkpoint``: exit status 2, one line on stderr, no output folder, no episode loaded."""
    out = tmp_path / "out"
    capsys.readouterr()
    rc = main(["--episodes", str(small_benchmark["path"]), "--agent", "learned", "--out", str(out), "--quiet",
               "--set", f"agents.learned.checkpoint={checkpoint}"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and err.startswith("error: "), err
    assert "loaded" not in err and not out.exists()
    return err


@pytest.mark.parametrize("entry, value, says", [
    ("obs_layout", [["free_space", 23]], "observation layout: entry 0 is ['free_space', 23] there"),
    ("actions", ["stop"], "action set"),
    ("ignjax_version", "0.0.0", "ignjax version: '0.0.0' there"),
    ("policy", {"core": "gru", "hidden": 128, "layers": 2}, "policy: the record describes the network"),
    ("weights_sha256", "0" * 64, "weights_sha256: its bytes differ"),
])
def test_a_checkpoint_that_does_not_fit_is_refused_before_any_episode(capsys, small_benchmark, tmp_path, entry,
                                                                      value, says):
    folder = export(tmp_path / "p", **{entry: value})
    err = _refusal(capsys, small_benchmark, tmp_path, folder)
    assert says in err and str(folder) in err, err


def test_a_path_that_is_not_a_checkpoint_is_one_line(capsys, small_benchmark, tmp_path):
    (tmp_path / "empty").mkdir()
    assert "not a policy" in _refusal(capsys, small_benchmark, tmp_path, tmp_path / "empty")
    assert "no such folder" in _refusal(capsys, small_benchmark, tmp_path, tmp_path / "nowhere")
    run = tmp_path / "run"
    (run / "checkpoints").mkdir(parents=True)
    assert "without a complete checkpoint" in _refusal(capsys, small_benchmark, tmp_path, run)
    old = export(tmp_path / "old")
    (old / WEIGHTS_FILE).unlink()
    (old / "policy.msgpack").write_bytes(b"")
    assert "python -m ignjax.rl.export" in _refusal(capsys, small_benchmark, tmp_path, old)
    export(tmp_path / "junk")
    (tmp_path / "junk" / WEIGHTS_FILE).write_bytes(b"not a zip")
    assert "not a weights file" in _refusal(capsys, small_benchmark, tmp_path, tmp_path / "junk")


def test_a_run_folder_means_its_newest_checkpoint(tmp_path):
    run = tmp_path / "run"
    for update, seed in ((5, 1), (10, 2)):
        ckpt = run / "checkpoints" / f"{update:08d}"
        ckpt.mkdir(parents=True)
        data = npz_bytes(random_weights(seed=seed))
        (ckpt / WEIGHTS_FILE).write_bytes(data)
        rec = {**record(SimConfig(), SHAPE.settings(), "fp", update), "weights_sha256": hashlib.sha256(data).hexdigest()}
        ckpt.with_suffix(".json").write_text(json.dumps(rec))
    assert locate(str(run)) == run / "checkpoints" / "00000010"
    assert load(locate(str(run))).record["update"] == 10
    with pytest.raises(InputError, match="observation layout"):
        load(locate(str(run)), SimConfig(max_visible=4))  # another simulator configuration: another vector


def test_sweep_records_and_checks_the_checkpoint(tmp_path, capsys):
    """The sweep's run record and fingerprint name the weights' digest; the in-the-loop cost study's parameters
    read each charged cost; a bad checkpoint stops the sweep before its folder is made."""
    from ignjax.sweep.cli import main as sweep
    from ignjax.sweep.stages import _costs_params

    folder = export(tmp_path / "p")
    sets = ['eval.agents=["learned"]', 'costs.agent="learned"', f"agents.learned.checkpoint={folder}"]
    cfg = resolve(None, sets)
    loaded = loaded_agents(cfg, ["eval", "costs"])
    assert loaded["learned"]["checkpoint"] == str(folder)
    assert loaded["learned"]["weights_sha256"] == file_sha256(folder / WEIGHTS_FILE)
    before = fingerprint(cfg, ["eval"])
    export(folder, random_weights(seed=7))  # retrained into the same folder: another run
    assert fingerprint(cfg, ["eval"]) != before
    assert loaded_agents(cfg, ["derive-costs"]) == {}
    costs = np.asarray(LOCKED_COSTS, np.float32)[None] * np.array([[0.5], [1.0], [4.0]], np.float32)
    params = _costs_params(cfg, get_agent("learned"), costs)
    np.testing.assert_allclose(params.costs, costs)
    assert params.weights["encoder_0/kernel"].shape == (3,) + SHAPE.shapes()["encoder_0/kernel"]
    bad = export(tmp_path / "bad", ignjax_version="0.0.0")
    out = tmp_path / "sweep"
    capsys.readouterr()
    assert sweep(["--out", str(out), "--study", "eval", "--set", 'eval.agents=["learned"]',
                  "--set", f"agents.learned.checkpoint={bad}"]) == 2
    err = capsys.readouterr().err
    assert re.search(r"ignjax_version: .*'0\.0\.0' there", err) and str(bad) in err and not out.exists()
