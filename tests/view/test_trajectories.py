"""``trajectories.npz``: what ``python -m ignjax.evaluate`` saves for the
viewer agrees step by step with the outcome table, is written with the same
bytes every time, and is refused when it is not such a file."""

from __future__ import annotations

import io
import json
import zipfile

import numpy as np
import pytest

from ignjax.errors import InputError
from ignjax.evaluate.outcomes import parse_trace, read_outcomes, read_trajectories, write_trajectories
from ignjax.scenes.io.sources import load_scenes
from ignjax.sim.types import ASK, MOVE, Trajectory


@pytest.fixture(scope="module")
def saved(eval_run):
    meta, traj = read_trajectories(eval_run / "trajectories.npz")
    rows = {(r["agent"], r["episode_id"]): r for r in read_outcomes(eval_run / "outcomes.parquet")}
    return meta, traj, rows


def test_meta_names_the_run(saved, small_benchmark, run_agents):
    meta, traj, _ = saved
    es = small_benchmark["set"]
    assert meta["agents"] == list(run_agents) and list(traj) == list(run_agents)
    assert meta["episode_ids"] == es.episode_ids
    assert meta["episodes"] == str(small_benchmark["path"].resolve())
    assert meta["categories"] == list(es.bank.categories)
    assert meta["thresholds"] == [0.5, 1.5, 3.0] and meta["require_stop"] is False
    assert meta["sim"]["max_steps"] == 20
    for a in run_agents:
        assert set(traj[a]) == {"pose", *Trajectory.STEP_FIELDS}
        assert traj[a]["pose"].shape == (len(es), 21, 3) and traj[a]["visible_attrs"].shape[:2] == (len(es), 20)


def test_every_step_agrees_with_the_outcome_table(saved, small_benchmark, run_agents):
    meta, traj, rows = saved
    es = small_benchmark["set"]
    scenes = {s.id: s for f in sorted(small_benchmark["root"].glob("*.usda")) for s in load_scenes(f)}
    asked_types = set()
    for a in run_agents:
        t = traj[a]
        for i, rec in enumerate(es.records):
            row = rows[(a, rec["episode_id"])]
            kind = t["kind"][i]
            n = int(row["steps"])
            assert (kind[:n] >= 0).all() and (kind[n:] == -1).all()
            assert np.allclose(t["pose"][i, 0], [rec["start"]["x"], rec["start"]["y"], rec["start"]["yaw"]], atol=1e-5)
            # the question trace of the table is the trajectory's ASK steps, refused ones included
            events = parse_trace(row["trace"])
            asks = np.nonzero(kind == ASK)[0]
            assert [s for _, s, _ in events] == list(asks)
            for qt, s, charged in events:
                assert t["question"][i, s] == qt and bool(t["refused"][i, s]) == (not charged)
                asked_types.add(qt)
            assert (t["question"][i][kind != ASK] == 0).all()
            assert list(t["n_questions"][i, n - 1]) == [row["q1"], row["q2"], row["q3"], row["q4"]]
            # MOVE cells where the agent moved, -1 elsewhere; waypoints within the horizon of the pose before
            move = kind == MOVE
            for f, lo, hi in (("direction", 0, 7), ("col", 1, 8), ("row", 1, 8)):
                v = t[f][i]
                assert ((v[move] >= lo) & (v[move] <= hi)).all() and (v[~move] == -1).all()
            reach = np.linalg.norm(t["waypoint"][i] - t["pose"][i, :-1, :2], axis=-1)
            assert (reach[move] <= 3.0 + 1e-3).all() and (reach[~move] < 1e-6).all()
            assert not t["blocked"][i][~move].any()
            for s in np.nonzero((t["question"][i] == 3) & ~t["refused"][i])[0]:
                assert 0 <= t["hint_sector"][i, s] <= 7
            for s in np.nonzero((t["question"][i] == 4) & ~t["refused"][i])[0]:
                assert t["confirm"][i, s] in (0, 1)
            # what was in sight: non-structural instances of the episode's scene, nearest first
            scene = scenes[rec["scene_id"]]
            for s in range(n):
                seen = [int(h) for h in t["visible"][i, s] if h >= 0]
                assert all(not scene.instances[h].structural for h in seen)
                if seen:
                    d = [np.linalg.norm(np.array(scene.instances[h].bbox.center[:2]) - t["pose"][i, s, :2]) for h in seen]
                    assert all(x <= y + 1e-4 for x, y in zip(d, d[1:]))
    assert asked_types >= {1, 4}  # the eig agent asks: the ASK records are exercised


def test_writer_is_deterministic_and_round_trips(saved, tmp_path, small_benchmark):
    meta, traj, _ = saved
    recs = small_benchmark["set"].records
    kw = dict(episodes=meta["episodes"], categories=meta["categories"], thresholds=meta["thresholds"],
              costs=meta["costs"], require_stop=meta["require_stop"], sim=meta["sim"])
    a = write_trajectories(tmp_path / "a", traj, recs, **kw).read_bytes()
    b = write_trajectories(tmp_path / "b", traj, recs, **kw).read_bytes()
    assert a == b
    meta2, traj2 = read_trajectories(tmp_path / "a" / "trajectories.npz")
    assert meta2 == meta
    for name in traj:
        for f, v in traj[name].items():
            assert traj2[name][f].dtype == v.dtype and np.array_equal(traj2[name][f], v), (name, f)
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["trajectories.npz"]  # no temporary left
    with pytest.raises(ValueError, match="rows"):
        write_trajectories(tmp_path / "c", traj, recs[:3], **kw)


def test_reader_refuses_other_files(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_trajectories(tmp_path / "none.npz")
    (tmp_path / "junk.npz").write_text("not a zip")
    with pytest.raises(InputError, match="not a trajectory file"):
        read_trajectories(tmp_path / "junk.npz")
    np.savez(tmp_path / "plain.npz", x=np.zeros(3))
    with pytest.raises(InputError, match="meta"):
        read_trajectories(tmp_path / "plain.npz")
    with zipfile.ZipFile(tmp_path / "other.npz", "w") as zf:
        buf = io.BytesIO()
        np.lib.format.write_array(buf, np.array(json.dumps({"schema": "other", "version": 1, "agents": []})))
        zf.writestr("meta.npy", buf.getvalue())
    with pytest.raises(InputError, match="schema 'other'"):
        read_trajectories(tmp_path / "other.npz")
