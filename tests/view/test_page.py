"""``python -m ignjax.view``: the page's data agrees with the run folder,
the page is self-contained and the same bytes every time, images and
transcripts in the run folder reach it, one episode exports as GIF/MP4, and
bad input is one error line, exit status 2 and nothing written."""

from __future__ import annotations

import base64
import json
import math
import re

import imageio.v3 as iio
import numpy as np
import pytest

from ignjax.evaluate.outcomes import read_outcomes
from ignjax.sim import oracle_text as OT
from ignjax.view.cli import main

DATA = re.compile(r'<script type="application/json" id="ignjax-data">(.*?)</script>', re.S)


def page_data(path) -> dict:
    return json.loads(DATA.search(path.read_text(encoding="utf-8")).group(1))


def files_in(folder) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_page_is_self_contained_and_deterministic(eval_run, tmp_path, capsys):
    assert main([str(eval_run), "--out", str(tmp_path / "a.html")]) == 0
    assert "40 episodes x 2 agents" in capsys.readouterr().out
    assert main([str(eval_run), "--out", str(tmp_path / "b.html")]) == 0
    a, b = (tmp_path / "a.html").read_bytes(), (tmp_path / "b.html").read_bytes()
    assert a == b
    text = a.decode()
    # nothing loaded from elsewhere: no external script, style, font or image; the one URL is the SVG namespace
    assert re.findall(r"https?://[^\s\"'<>]+", text) == ["http://www.w3.org/2000/svg"]
    assert "<script src" not in text and "<link rel=\"stylesheet\"" not in text and "@import" not in text
    assert files_in(tmp_path) == ["a.html", "b.html"]  # no temporary file left


def test_default_output_is_in_the_run_folder(run_copy):
    assert main([str(run_copy)]) == 0
    assert (run_copy / "viewer.html").is_file() and page_data(run_copy / "viewer.html")["title"] == "run"


def test_page_data_agrees_with_the_run(eval_run, tmp_path, small_benchmark, run_agents):
    assert main([str(eval_run), "--out", str(tmp_path / "v.html")]) == 0
    d = page_data(tmp_path / "v.html")
    rows = {(r["agent"], r["episode_id"]): r for r in read_outcomes(eval_run / "outcomes.csv")}
    records = small_benchmark["set"].records
    assert d["agents"] == list(run_agents) and [e["id"] for e in d["episodes"]] == [r["episode_id"] for r in records]
    assert set(d["scenes"]) == {"small_a", "small_b"}
    answered = set()
    for ep, rec in zip(d["episodes"], records):
        scene = d["scenes"][ep["scene"]]
        assert scene["inst"][ep["target"]][0] == rec["target_id"]
        for a, r in zip(d["agents"], ep["runs"]):
            row = rows[(a, ep["id"])]
            n = row["steps"]
            assert r["n"] == n and len(r["k"]) == n and len(r["pose"]) == 3 * (n + 1) and len(r["wp"]) == 2 * n
            assert r["succ"] == [int(row["final_distance"] <= t) for t in (0.5, 1.5, 3.0)]
            assert r["q"] == [row["q1"], row["q2"], row["q3"], row["q4"]] and r["stop"] == row["stop_reason"]
            disc = math.exp(-sum(w * q for w, q in zip(d["costs"], r["q"])))
            assert r["disc"] == pytest.approx(disc, abs=5e-4)
            assert r["dc"][-1] == pytest.approx(disc, abs=5e-4)
            for t, (k, qt) in enumerate(zip(r["k"], r["qt"])):
                if k != 1:
                    assert r["ans"][t] == ""
                    continue
                answered.add(qt)
                if t in r["rf"]:
                    assert r["ans"][t] == OT.refused_text()
                elif qt == 1:
                    assert r["ans"][t] == rec["oracle"]["appearance"]
                elif qt == 2:
                    assert r["ans"][t] == rec["oracle"]["region"]
                elif qt == 3:
                    assert r["ans"][t] and not OT.route_leaks(r["ans"][t])
                else:
                    assert r["ans"][t].startswith(("Yes", "No"))
            for seen in r["vis"]:
                for v in seen:
                    assert scene["inst"][v if isinstance(v, int) else v[0]] is not None
    assert {1, 4} <= answered


def test_episodes_and_agent_options(eval_run, tmp_path):
    out = tmp_path / "few.html"
    assert main([str(eval_run), "--out", str(out), "--episodes", "5", "--agent", "random"]) == 0
    d = page_data(out)
    assert len(d["episodes"]) == 5 and d["agents"] == ["random"] and d["n_run_episodes"] == 40
    assert all(len(e["runs"]) == 1 for e in d["episodes"])
    assert main([str(eval_run), "--out", str(out), "--episodes", "1000"]) == 0
    assert len(page_data(out)["episodes"]) == 40


def _png(color) -> bytes:
    img = np.zeros((64, 64, 3), np.uint8)
    img[...] = color
    return iio.imwrite("<bytes>", img, extension=".png")


def _call(agent, episode, step, role, **kw) -> dict:
    rec = {"agent": agent, "episode": episode, "step": step, "role": role, "prompt": f"{role} prompt at {step}",
           "reply": f"{role} reply at {step}", "parsed": {"action": "MOVE"}, "retries": 0, "error": None}
    rec.update(kw)
    return rec


def test_images_and_transcripts_reach_the_page(run_copy, tmp_path, small_benchmark):
    ep = small_benchmark["set"].records[0]["episode_id"]
    images = run_copy / "images" / "eig" / ep
    images.mkdir(parents=True)
    panel, grounder = _png((200, 10, 10)), _png((10, 200, 10))
    (images / "000_panel.png").write_bytes(panel)
    (images / "0_grounder.png").write_bytes(grounder)
    (images / "notes.txt").write_text("not an image")
    hostile = "reply with </script><script>alert(1)</script> in it"
    calls = [_call("eig", ep, 0, "planner", retries=[{"reply": "garbled", "error": "no JSON object"}]),
             _call("eig", ep, 0, "grounder", reply=hostile),
             _call("eig", ep, 1, "planner", parsed=None, error="could not parse the action"),
             _call("eig", "another/episode/0", 0, "planner")]
    (run_copy / "transcripts.jsonl").write_text("\n".join(json.dumps(c) for c in calls) + "\n")
    out = tmp_path / "img.html"
    assert main([str(run_copy), "--out", str(out), "--episodes", "2"]) == 0
    text = out.read_text()
    assert "</script><script>alert" not in text  # a transcript cannot end the data element
    r = page_data(out)["episodes"][0]["runs"][0]
    assert base64.b64decode(r["img"]["0"][0].split(",", 1)[1]) == panel
    assert base64.b64decode(r["img"]["0"][1].split(",", 1)[1]) == grounder
    assert r["img"]["0"][0].startswith("data:image/png;base64,") and list(r["img"]) == ["0"]
    assert [c["role"] for c in r["tx"]["0"]] == ["planner", "grounder"] and r["tx"]["0"][1]["reply"] == hostile
    assert r["tx"]["0"][0]["retries"] == [{"reply": "garbled", "error": "no JSON object"}]
    assert r["tx"]["1"][0]["error"] == "could not parse the action" and r["tx"]["1"][0]["parsed"] is None
    assert "img" not in page_data(out)["episodes"][0]["runs"][1]  # random has none
    # without --episodes: every episode, transcripts kept, images left out (and counted for the notice)
    assert main([str(run_copy), "--out", str(out)]) == 0
    d = page_data(out)
    assert len(d["episodes"]) == 40 and d["images_left_out"] == 1
    assert "img" not in d["episodes"][0]["runs"][0] and "tx" in d["episodes"][0]["runs"][0]


@pytest.mark.parametrize("line, where", [
    ("not json", "line 2: not JSON"),
    ('{"agent": "eig"}', "line 2: missing keys"),
    ('{"agent": "eig", "episode": "e", "step": -1, "role": "planner", "prompt": "", "reply": "", "parsed": null, '
     '"retries": 0, "error": null}', "line 2: step: wrong type"),
    ('{"agent": "eig", "episode": "e", "step": 0, "role": "critic", "prompt": "", "reply": "", "parsed": null, '
     '"retries": 0, "error": null}', "line 2: role"),
])
def test_bad_transcript_is_refused(run_copy, tmp_path, capsys, line, where):
    good = json.dumps(_call("eig", "e", 0, "planner"))
    (run_copy / "transcripts.jsonl").write_text(good + "\n" + line + "\n")
    assert main([str(run_copy), "--out", str(tmp_path / "x.html")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "transcripts.jsonl" in err and where in err
    assert files_in(tmp_path) == ["run"]


def test_bad_input(eval_run, run_copy, tmp_path, capsys):
    out = tmp_path / "o" / "v.html"
    empty = tmp_path / "empty"
    empty.mkdir()
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    no_traj = tmp_path / "no_traj"
    no_traj.mkdir()
    (no_traj / "outcomes.csv").write_text((eval_run / "outcomes.csv").read_text())
    cases = [
        ([str(tmp_path / "missing")], "missing: no such folder"),
        ([str(a_file)], "file.txt: not a folder"),
        ([str(empty)], "not a run folder: it has no outcomes.parquet or outcomes.csv"),
        ([str(no_traj)], "trajectories.npz: missing"),
        ([str(eval_run), "--agent", "nope"], "--agent: agent 'nope' is not in this run (it has eig, random)"),
        ([str(eval_run), "--episodes", "0"], "--episodes: must be a positive number of episodes, got 0"),
        ([str(eval_run), "--episodes", "-3"], "--episodes: must be a positive number of episodes, got -3"),
        ([str(eval_run), "--benchmark", str(tmp_path / "gone.jsonl")], "gone.jsonl: episode file of the run not found"),
        ([str(eval_run), "--out", str(tmp_path / "o" / "v.txt")], "v.txt: --out: the page is an .html file"),
        ([str(eval_run), "--gif", "no/such/episode"], "--gif: episode 'no/such/episode'"),
        ([str(eval_run), "--gif", "x", "--out", str(tmp_path / "o" / "e.avi")], "e.avi: --out: the export is a .gif"),
        ([str(eval_run), "--gif", "x", "--agent", "eig", "--agent", "random"], "--agent: --gif exports one agent"),
    ]
    for argv, message in cases:
        if "--out" not in argv and "--gif" not in argv:
            argv = argv + ["--out", str(out)]
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("error: ") and err.count("\n") == 1 and message in err, (argv, err)
    assert not (tmp_path / "o").exists()  # nothing half-written
    assert files_in(eval_run) == ["metrics.csv", "outcomes.csv", "outcomes.parquet", "run.json", "trajectories.npz"]


def test_gif_export(eval_run, tmp_path, small_benchmark):
    rows = [r for r in read_outcomes(eval_run / "outcomes.csv") if r["agent"] == "eig"]
    row = max(rows, key=lambda r: (r["n_questions"] > 0, r["steps"]))
    gif = tmp_path / "e.gif"
    assert main([str(eval_run), "--gif", row["episode_id"], "--agent", "eig", "--out", str(gif)]) == 0
    frames = iio.imread(gif, index=None)
    assert frames.shape[0] == row["steps"] + 1 and frames.shape[1:3] == (640, 640)
    assert not np.array_equal(frames[0], frames[-1])  # the agent moved
    first = gif.read_bytes()
    assert main([str(eval_run), "--gif", row["episode_id"], "--agent", "eig", "--out", str(gif)]) == 0
    assert gif.read_bytes() == first
    assert main([str(eval_run), "--gif", row["episode_id"]]) == 0  # default: the run's first agent, in the run folder
    name = row["episode_id"].replace("/", "_") + "_eig.gif"
    assert (eval_run / name).is_file()
    (eval_run / name).unlink()


@pytest.mark.filterwarnings(r"ignore:os.fork\(\) was called:RuntimeWarning")  # ffmpeg runs as a subprocess
def test_mp4_export(eval_run, tmp_path):
    pytest.importorskip("imageio_ffmpeg", reason="MP4 export needs the optional imageio-ffmpeg package")
    row = read_outcomes(eval_run / "outcomes.csv")[0]
    mp4 = tmp_path / "e.mp4"
    assert main([str(eval_run), "--gif", row["episode_id"], "--agent", row["agent"], "--out", str(mp4)]) == 0
    frames = iio.imread(mp4, index=None, plugin="FFMPEG")
    assert frames.shape[0] == row["steps"] + 1 and frames.shape[1:3] == (640, 640)
