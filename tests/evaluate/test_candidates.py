"""Type-4 questions about the queried candidate (issue: the paper's Type 4
answers yes only when the *queried* candidate is the target, visible in
front and within 3 m).

The vlm agent, started at an episode's reference view (the target in
sight), names a cell of its front view; the scripted server (a test double
on 127.0.0.1 whose replies a policy computes) replies with the cell the test
chose from the same rendered segmentation: the target's cell gets "yes",
the cell of another object beside it "no", a cell with no object a "no"
that says so. Also the cell arithmetic, the projection used for text
observations, and the simulator's answer to each kind of candidate."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.agents.llm.agent import VlmAgent
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate import candidates as C
from ignjax.evaluate.hostloop import run_llm_agent
from ignjax.sim import oracle as O
from ignjax.sim import types as T
from ignjax.sim.views import ViewConfig, ViewRenderer

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
SIM = T.SimConfig(max_steps=2)
SIZE = 64


def test_cell_bounds_follow_the_grid_convention():
    # column 1 is the left edge, row 1 the bottom edge; the cells tile the image
    rows, cols = C.cell_bounds(1, 1, 64, 64)
    assert (rows.start, rows.stop, cols.start, cols.stop) == (56, 64, 0, 8)
    rows, cols = C.cell_bounds(8, 8, 448, 448)
    assert (rows.start, rows.stop, cols.start, cols.stop) == (0, 56, 392, 448)
    cover = np.zeros((64, 64), int)
    for c in range(1, 9):
        for r in range(1, 9):
            cover[C.cell_bounds(c, r, 64, 64)] += 1
    assert (cover == 1).all()
    with pytest.raises(ValueError, match="outside 1..8"):
        C.cell_bounds(0, 3, 64, 64)


def test_segmented_candidate_takes_the_largest_object_and_skips_structure():
    img = np.full((64, 64), -1, np.int32)
    rows, cols = C.cell_bounds(3, 5, 64, 64)
    block = img[rows, cols]
    block[:, :5] = 7  # 40 pixels of object 7
    block[:, 5:] = 2  # 24 pixels of object 2
    structural = np.zeros(10, bool)
    assert C.segmented_candidate(img, structural, 3, 5) == 7
    structural[7] = True  # a wall is no candidate
    assert C.segmented_candidate(img, structural, 3, 5) == 2
    assert C.segmented_candidate(img, structural, 4, 5) == T.NO_CANDIDATE


def test_front_cells_project_like_the_executor_camera():
    cfg = T.SimConfig()
    pose = np.array([1.0, 2.0, np.pi / 2])  # facing +y
    eye = cfg.eye_height
    pts = np.array([[1.0, 5.0, eye],  # straight ahead at eye height: the centre, columns 4|5 and rows 4|5
                    [1.0, 5.0, 0.0],  # ahead on the floor: the centre columns, a lower row
                    [4.0, 2.1, eye],  # far to the right: outside a 90-degree view
                    [1.0, -1.0, eye]])  # behind
    cells = C.front_cells(cfg, pose, pts)
    assert cells[0, 0] in (4, 5) and cells[0, 1] in (4, 5)
    assert cells[1, 0] in (4, 5) and cells[1, 1] < cells[0, 1]
    assert (cells[2:] == 0).all()
    # a point to the left lands in a left column
    assert C.front_cells(cfg, pose, np.array([[0.0, 5.0, eye]]))[0, 0] < 4
    handles, ranges = np.array([3, 9, 5, -1]), np.array([3.0, 2.0, 1.0, 0.5])
    two = np.array([[2, 3], [2, 3], [6, 1], [2, 3]])
    assert C.projected_candidate(two, handles, ranges, 2, 3) == 9  # the nearer of the two in the cell
    assert C.projected_candidate(two, handles, ranges, 7, 7) == T.NO_CANDIDATE


@pytest.fixture(scope="module")
def scene_at_reference(rendering):
    """The shipped benchmark's first episodes started at their reference views, with the front view's
    segmentation there; each usable one has a cell showing the target and a cell showing another object."""
    es = load_benchmark(EPISODES, limit=24)
    starts = np.array([[r["reference_view"][k] for k in ("x", "y", "yaw")] for r in es.records], np.float32)
    es = dataclasses.replace(es, specs=dataclasses.replace(es.specs, start=jnp.asarray(starts)))
    structural = np.asarray(es.bank.instances.structural)
    with ViewRenderer(es.bank, SIM, ViewConfig(size=SIZE)) as r:
        views = r.render(np.asarray(es.specs.scene), starts)
    picks = []
    for k in range(len(es)):
        s, target = int(es.specs.scene[k]), int(es.specs.target[k])
        owner = {(c, w): C.segmented_candidate(views.instance[k, 0], structural[s], c, w)
                 for c in range(1, 9) for w in range(1, 9)}
        on_target = [cw for cw, i in owner.items() if i == target]
        cat = np.asarray(es.bank.instances.category[s])
        others = sorted((cw for cw, i in owner.items() if i not in (target, T.NO_CANDIDATE)),
                        key=lambda cw: cat[owner[cw]] != cat[target])  # a same-category distractor first
        empty = [cw for cw, i in owner.items() if i == T.NO_CANDIDATE]
        if on_target and others and empty:
            picks.append((k, on_target[0], others[0], empty[0]))
    return es, picks


def _policy(cell: tuple[int, int], heard: list):
    """Turn 1: a Type-4 question at ``cell``; turn 2 (its prompt, which carries the answer, kept in
    ``heard``): stop."""
    def reply(req: dict) -> str:
        text = json.dumps(req["messages"])
        if "Turn 1 of" in text:
            return json.dumps({"action": "ask", "direction": 0, "col": cell[0], "row": cell[1], "question": 4,
                               "reason": "check"})
        heard.append(text)
        return json.dumps({"action": "stop", "direction": 0, "col": 4, "row": 1, "question": 1, "reason": "done"})
    return reply


def test_type4_answers_about_the_queried_cell(scene_at_reference):
    es, picks = scene_at_reference
    from ignjax.evaluate.runner import make_world

    world = make_world(es, SIM)
    # the oracle's own check sees the target there (front view, within range, in sight)
    picks = [p for p in picks if bool(O.target_visible_front(world, jax.tree.map(lambda a: a[p[0]], es.specs),
                                                            es.specs.start[p[0]]))][:1]
    assert picks, "no reference views with the target, another object and an empty cell in front"
    for k, *cells in picks:
        target = int(es.specs.target[k])
        for cell, expect in zip(cells, ("yes", "other", "nothing")):  # the target's cell, another object's, empty
            heard: list = []
            with ScriptedServer(policy=_policy(cell, heard)) as srv:
                llm = LLMConfig(endpoints=(srv.base_url,), model=srv.model, api_key_env=None, timeout_s=10.0)
                res = run_llm_agent(es.subset([k]), VlmAgent(), llm, sim=SIM, views=ViewConfig(size=SIZE), batch=1)
            assert int(res.trajectories.kind[0, 0]) == T.ASK and int(res.trajectories.question[0, 0]) == 4
            asked, said = int(res.trajectories.candidate[0, 0]), heard[0]
            if expect == "yes":  # the queried instance is the target: yes
                assert asked == target and "Yes" in said
            elif expect == "other":  # another object in the same view, the target visible beside it: no
                assert asked >= 0 and asked != target
                assert "not the one" in said or "not the target" in said or "not what you are looking at" in said
            else:  # a cell with no object: no, and the reason says so
                assert asked == T.NO_CANDIDATE and ("no object" in said or "Nothing there" in said)
            assert int(np.asarray(res.outcomes.n_questions)[0, 3]) == 1  # charged as every Type-4 question
