"""The sweep's run folder carries the viewer: ``trajectories.npz`` next to
the outcomes, ``viewer.html`` written by the eval study and linked from
``report.md``, and ``python -m ignjax.view`` on that folder gives the same
bytes (the same run folder, the same page)."""

from __future__ import annotations

import json
import re

from ignjax.config import resolve
from ignjax.evaluate.outcomes import read_outcomes, read_trajectories
from ignjax.sweep.stages import run_sweep
from ignjax.view.cli import main

DATA = re.compile(r'<script type="application/json" id="ignjax-data">(.*?)</script>', re.S)


def test_sweep_writes_and_links_the_viewer(small_benchmark, tmp_path):
    sets = [f"benchmark.episodes='{small_benchmark['path']}'", f"run.out='{tmp_path}'", "run.name='viewer-check'",
            "eval.agents=['random', 'explorer']", "eval.batch=8", "benchmark.limit=16"]
    out = tmp_path / "sweep"
    run_sweep(resolve(None, sets, quick=True), ["eval"], out, quiet=True)
    report = (out / "report.md").read_text()
    assert "[viewer.html](viewer.html)" in report
    meta, traj = read_trajectories(out / "trajectories.npz")
    rows = read_outcomes(out / "outcomes.parquet")
    assert meta["agents"] == ["random", "explorer"] and len(meta["episode_ids"]) == 16
    assert [r["episode_id"] for r in rows if r["agent"] == "random"] == meta["episode_ids"]
    for a in meta["agents"]:
        steps = [r["steps"] for r in rows if r["agent"] == a]
        assert [int((k >= 0).sum()) for k in traj[a]["kind"]] == steps
    page = (out / "viewer.html").read_text()
    data = json.loads(DATA.search(page).group(1))
    assert data["title"] == "viewer-check" and [e["id"] for e in data["episodes"]] == meta["episode_ids"]
    # the command line, reading the scenes from their files, writes the same page as the sweep did
    assert main([str(out), "--out", str(tmp_path / "again.html")]) == 0
    assert (tmp_path / "again.html").read_bytes() == (out / "viewer.html").read_bytes()
