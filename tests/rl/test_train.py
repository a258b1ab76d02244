"""The PPO trainer (``python -m ignjax.rl.train``): its configuration's errors, a short run that writes its
curve and checkpoints and improves its return, the same seed giving the same bytes, ``--resume`` continuing
to the bytes of an uninterrupted run, and refused checkpoints. One tiny configuration, compiled once."""

from __future__ import annotations

import csv
import json
import shutil
import sys

import jax
import numpy as np
import pytest

pytest.importorskip("flax")
pytest.importorskip("optax")

from ignjax.rl import checkpoint as C  # noqa: E402
from ignjax.rl.train import main  # noqa: E402
from ignjax.rl.trainconfig import TrainConfig, resolve  # noqa: E402

UPDATES = 15


def tiny(episodes, out, name="a") -> list[str]:
    """A run where never asking is the best strategy by a wide margin: every end is a success (tau = 100 m) and the
    costs are the locked ones x 8, so a random policy's ~2 questions per episode cost most of its return."""
    sets = {"houses.episodes": f'"{episodes}"', "run.out": f'"{out}"', "run.name": f'"{name}"', "ppo.num_envs": 16,
            "ppo.steps": 20, "ppo.total_steps": 16 * 20 * UPDATES, "ppo.updates_per_call": 5, "ppo.minibatches": 2,
            "ppo.checkpoint_every": 5, "ppo.lr": 0.003, "ppo.epochs": 2, "env.shaping": 0.0, "env.tau": 100.0, "env.sample_costs": "false",
            "env.costs": "[1.5, 1.3, 1.9, 0.8]"}
    return ["--no-progress"] + [a for k, v in sets.items() for a in ("--set", f"{k}={v}")]


def curve(folder):
    with (folder / "curve.csv").open() as fh:
        return list(csv.DictReader(fh))


def state_bytes(ckpt):
    with C.ocp.PyTreeCheckpointer() as ck:
        tree = ck.restore(ckpt.resolve())
    return [np.asarray(tree[k]).tobytes() for k in sorted(tree)]


@pytest.fixture(scope="module")
def runs(small_benchmark, tmp_path_factory):
    """Run ``a``, and ``b`` (the same configuration in another folder)."""
    out = tmp_path_factory.mktemp("train")
    for name in ("a", "b"):
        assert main(tiny(small_benchmark["path"], out, name)) == 0
    return {"out": out, "episodes": small_benchmark["path"]}


def test_config_errors_name_where(tmp_path, capsys):
    bad = tmp_path / "t.toml"
    bad.write_text("[ppo]\nnum_envs = 64\nminibatches = 5\n")
    with pytest.raises(Exception, match=r"t.toml:3: ppo.minibatches"):
        resolve(bad)
    assert main(["--config", str(bad)]) == 2
    assert "t.toml:3" in capsys.readouterr().err
    for item, where in (("ppo.lr=-1", "ppo.lr"), ("ppo.nope=1", "ppo.nope"), ("policy.core=lstm", "policy.core"),
                        ("houses.seed=0", "houses.seed")):
        assert main(["--set", item]) == 2
        err = capsys.readouterr().err
        assert "--set" in err and where in err
    assert TrainConfig().houses.seed != 0  # the training houses are not the shipped benchmark's (seed 0)


def test_missing_extra_is_one_line(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "flax", None)
    assert main(["--print-config"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and 'pip install "ignjax[rl]"' in err


def test_run_writes_curve_and_checkpoints_and_improves(runs):
    a = runs["out"] / "a"
    rows = curve(a)
    assert [int(r["update"]) for r in rows] == list(range(1, UPDATES + 1))
    assert (a / "curve.png").is_file() and (a / "run.json").is_file()
    assert [p.name for p in sorted((a / "checkpoints").glob("*.json"))] == ["00000005.json", "00000010.json",
                                                                            "00000015.json"]
    ret = np.array([float(r["return"]) for r in rows])
    assert ret[-3:].mean() > ret[:3].mean() + 0.25, ret  # random asks ~2 questions; the learned policy stops asking


def test_same_seed_same_bytes(runs):
    a, b = (runs["out"] / n / "checkpoints" / f"{UPDATES:08d}" for n in ("a", "b"))
    assert (a / "policy.msgpack").read_bytes() == (b / "policy.msgpack").read_bytes()
    assert state_bytes(a) == state_bytes(b)
    drop = lambda rows: [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]  # noqa: E731
    assert drop(curve(a.parents[1])) == drop(curve(b.parents[1]))


def test_resume_continues_to_the_same_bytes(runs):
    src, dst = runs["out"] / "a", runs["out"] / "c"
    shutil.copytree(src, dst)
    for u in (10, 15):
        shutil.rmtree(dst / "checkpoints" / f"{u:08d}")
        (dst / "checkpoints" / f"{u:08d}.json").unlink()
    assert main(tiny(runs["episodes"], runs["out"], "c")) == 2  # the folder holds this run: --resume or --force
    assert main(tiny(runs["episodes"], runs["out"], "c") + ["--resume"]) == 0
    last = f"checkpoints/{UPDATES:08d}"
    assert (dst / last / "policy.msgpack").read_bytes() == (src / last / "policy.msgpack").read_bytes()
    assert state_bytes(dst / last) == state_bytes(src / last)
    assert len(curve(dst)) == UPDATES


@pytest.mark.parametrize("key, value, says", [("obs_layout", [["free_space", 23]], "observation layout"),
                                              ("actions", ["stop"], "action set"),
                                              ("ignjax_version", "0.0.0", "ignjax version")])
def test_checkpoint_of_another_layout_is_refused(runs, capsys, key, value, says):
    dst = runs["out"] / f"bad_{key}"
    shutil.copytree(runs["out"] / "a", dst)
    meta = dst / "checkpoints" / f"{UPDATES:08d}.json"
    record = json.loads(meta.read_text())
    record[key] = value
    meta.write_text(json.dumps(record))
    capsys.readouterr()
    assert main(tiny(runs["episodes"], runs["out"], dst.name) + ["--resume"]) == 2
    err = capsys.readouterr().err
    assert says in err and str(meta.with_suffix("")) in err
    with pytest.raises(Exception, match=says):
        C.check_record(record, C.record(TrainConfig().sim, {"core": "gru", "hidden": 64, "layers": 2}, "", 0), meta)
    assert jax.device_count() >= 1


def test_checkpoints_hold_the_weights_as_plain_arrays(runs, tmp_path, capsys):
    """Every checkpoint's ``policy.npz`` is its ``policy.msgpack`` as named arrays, with its digest in the record;
    a checkpoint written without one (an older run) gets the same bytes from ``python -m ignjax.rl.export``,
    and ``--out`` makes an exported policy folder the learned agent loads."""
    from ignjax.agents.learned.source import load
    from ignjax.agents.learned.weights import from_flax, npz_bytes, read_npz
    from ignjax.fileio import file_sha256
    from ignjax.rl.export import main as export

    last = runs["out"] / "a" / "checkpoints" / f"{UPDATES:08d}"
    npz = last / "policy.npz"
    tree = C.serialization.msgpack_restore((last / "policy.msgpack").read_bytes())
    assert npz.read_bytes() == npz_bytes(from_flax(tree))
    assert C.read_record(last)["weights_sha256"] == file_sha256(npz)
    old = tmp_path / "run"
    shutil.copytree(runs["out"] / "a", old)
    (old / "checkpoints" / f"{UPDATES:08d}" / "policy.npz").unlink()
    assert export([str(old), "--out", str(tmp_path / "exported")]) == 0  # the run folder: its newest checkpoint
    assert (old / "checkpoints" / f"{UPDATES:08d}" / "policy.npz").read_bytes() == npz.read_bytes()
    loaded = load(tmp_path / "exported")
    assert loaded.sha256 == file_sha256(npz) and loaded.record["update"] == UPDATES
    assert loaded.record["training"]["fingerprint"] == json.loads((old / "run.json").read_text())["fingerprint"]
    assert set(read_npz(npz)) == set(loaded.weights)
    capsys.readouterr()
    assert export([str(tmp_path)]) == 2 and "not a policy" in capsys.readouterr().err
