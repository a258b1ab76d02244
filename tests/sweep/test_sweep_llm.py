"""MLLM agents in the main job: ``python -m ignjax.sweep --study eval`` with
``eval.agents`` naming ``vlm`` beside a JAX-native agent, the model server
given in the ``[llm]`` table (the scripted server on 127.0.0.1: a test double
whose replies are computed from the request text) and the observations in
``[views]``. Checks the outcome tables' accounting and cost columns, the
report's model-call tables (totals and per episode), transcripts, the
interaction analyses on an MLLM agent's traces (``tandem-naive``, whose
Planner replies a policy scripts: Type-3 questions with texts of each
content class), a second run answered from the shared cache with zero
requests and identical outcomes, and the configuration errors."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest

from ignjax.agents.llm.scripted import scripted_reply
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.studies.interaction import CONTENT_CLASSES, classify_question
from ignjax.config import fingerprint, resolve
from ignjax.errors import ConfigError
from ignjax.sweep.cli import main
from ignjax.sweep.stages import run_sweep

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
OUTCOME_FIELDS = ("agent", "episode_id", "final_distance", "steps", "stopped", "stop_reason", "q1", "q2", "q3", "q4",
                  "trace")


def _sets(srv, root: Path, cache: Path) -> list[str]:
    return [f"benchmark.episodes='{EPISODES}'", "benchmark.limit=3", f"run.out='{root}'",
            "eval.agents=['random', 'vlm']", "eval.batch=3", "sim.max_steps=6", "views.size=64",
            f"llm.endpoints=['{srv.base_url}']", f"llm.model='{srv.model}'", "llm.api_key_env=''",
            f"llm.cache_dir='{cache}'", "llm.timeout_s=10.0", "llm.prices={prompt = 0.5, completion = 2.0}",
            "analysis.agent='tandem-naive'", "analysis.trajectories=1"]


TYPE3_SCRIPT = {1: "Which way should I go to find the kitchen?", 2: "Where is the bedroom from here?",
                3: "Which room is next to the hallway?", 4: "Can you help me?"}
"""The analysed agent's Type-3 questions by turn (route, goal-room position, room relations, unclassified);
it moves on the later turns."""


def _policy(req: dict) -> str:
    """``tandem-naive``'s Planner follows :data:`TYPE3_SCRIPT`; every other request (the vlm agent, the
    Grounder) gets the server's default reply, a schema-valid instance."""
    if req["response_format"]["json_schema"]["name"] != "planner_decision":
        return scripted_reply(req)
    text = "\n".join(p.get("text", "") for m in req["messages"] for p in
                     ([{"text": m["content"]}] if isinstance(m["content"], str) else m["content"]))
    turn = int(re.search(r"Turn (\d+) of", text).group(1))
    ask = turn in TYPE3_SCRIPT
    return json.dumps({"reasoning": "", "task_phase": "explore", "action": "ask" if ask else "move",
                       "direction": "front", "subgoal": "the open doorway", "purpose": "look", "question_type": 3,
                       "question": TYPE3_SCRIPT.get(turn, ""),
                       "belief_update": {"current_room": "hall", "target_description": "", "visited_areas": [],
                                         "unexplored_areas": [], "key_observations": []}})


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_sweep_eval_runs_an_mllm_agent_and_reruns_from_the_cache(rendering, tmp_path, capsys):
    with ScriptedServer(policy=_policy) as srv:
        sets = _sets(srv, tmp_path, tmp_path / "cache")
        argv = ["--study", "eval,analysis", "--quiet", "--out", str(tmp_path / "a")] + sum((["--set", s] for s in sets), [])
        assert main(argv) == 0, capsys.readouterr().err
        sent = srv.stats()["requests"]
        assert sent > 0
        a = _rows(tmp_path / "a" / "outcomes.csv")
        vlm = [r for r in a if r["agent"] == "vlm"]
        rnd = [r for r in a if r["agent"] == "random"]
        assert len(vlm) == len(rnd) == 3
        tandem = [json.loads(x) for x in (tmp_path / "a" / "transcripts" / "tandem-naive.jsonl").read_text().split("\n")
                  if x]
        # one request per decision (no faults, no bad replies from the scripted policy; tandem-naive's controller
        # takes no decision on its own, so each of its transcript records is one request), none for the JAX agent
        n_vlm = sent - len(tandem)
        assert sum(int(r["requests"]) for r in vlm) == n_vlm == sum(int(r["steps"]) for r in vlm)
        assert all(int(r["prompt_tokens"]) > 0 and r["failure"] == "" for r in vlm)
        assert all(int(r["requests"]) == 0 and int(r["prompt_tokens"]) == 0 for r in rnd)
        # transcripts: one record per decision, naming the request's hash
        lines = (tmp_path / "a" / "transcripts" / "vlm.jsonl").read_text().splitlines()
        assert len(lines) == n_vlm and all(len(json.loads(x)["request_hash"]) == 64 for x in lines)
        # the report has the Table-1 rows for both agents and the model-call totals with the cost estimate
        report = (tmp_path / "a" / "report.md").read_text()
        assert "| vlm |" in report and "| random |" in report
        tokens = [sum(int(r[k]) for r in vlm) for k in ("prompt_tokens", "completion_tokens")]
        cost = (tokens[0] * 0.5 + tokens[1] * 2.0) / 1e6
        assert f"| vlm | {n_vlm} | 0 | {tokens[0]} | {tokens[1]} | 0 | 0 | 0 | 0 | {cost:.4f} |" in report
        # per episode: the outcome rows' cost column and the report's mean / max, both from the rows' tokens
        each = [(int(r["requests"]) + int(r["cache_hits"]), int(r["prompt_tokens"]), int(r["completion_tokens"]))
                for r in vlm]
        costs = [(p * 0.5 + c * 2.0) / 1e6 for _, p, c in each]
        assert [float(r["cost_usd"]) for r in vlm] == pytest.approx(costs)
        assert all(float(r["cost_usd"]) == 0.0 for r in rnd)
        mean = [sum(x[k] for x in each) / 3 for k in range(3)]
        assert (f"| vlm | 3 | {mean[0]:.1f} / {max(x[0] for x in each)} | {mean[1]:.0f} / {max(x[1] for x in each)} | "
                f"{mean[2]:.0f} / {max(x[2] for x in each)} | {sum(costs) / 3:.6f} / {max(costs):.6f} |") in report
        # the agents' options are stated in the report header; the interaction analyses ran on the MLLM agent's traces
        vlm = next(line for line in report.splitlines() if line.startswith("- Agent `vlm`: "))
        assert "Parameters: observation=panel" in vlm and "- Agent `tandem-naive`:" in report
        # what the MLLM agents were sent: the paper's decoding settings and the views' size, in the report and run.json
        assert (f"- MLLM agents: model `{srv.model}`, temperature 0, max_tokens 1024, seed 0; views of 64 x 64 px "
                "(`views.size`), jpeg.") in report
        assert json.loads((tmp_path / "a" / "run.json").read_text())["config"]["views"]["size"] == 64
        section = report.split("## Interaction")[-1]
        assert (tmp_path / "a" / "analysis_per_difficulty.csv").is_file() and "tandem-naive" in section
        # what its Type-3 questions asked, classified from the texts in its transcript: one of each class per episode
        asked = [c["question"] for c in tandem if c["action"] and c["action"][0] == 1 and c["action"][4] == 3]
        expect = [sum(CONTENT_CLASSES[classify_question(q)] == k for q in asked) for k in CONTENT_CLASSES]
        assert expect == [3, 3, 3, 3]
        content = _rows(tmp_path / "a" / "analysis_type3_content.csv")
        assert [(r["content"], int(r["Type-3 questions"])) for r in content] == list(zip(CONTENT_CLASSES, expect)) + [
            ("no text", 0)]
        assert [float(r["share of classified"]) for r in content[:3]] == pytest.approx([1 / 3] * 3)
        assert "| route | 3 | 33.3% | 25.0% |" in section and "| room_relations | 3 | 33.3% | 25.0% |" in section

        # a second run (another folder, same cache) sends nothing and gives the same outcomes
        argv_b = ["--study", "eval", "--quiet", "--out", str(tmp_path / "b")] + sum((["--set", s] for s in sets), [])
        assert main(argv_b) == 0, capsys.readouterr().err
        assert srv.stats()["requests"] == sent
        b = _rows(tmp_path / "b" / "outcomes.csv")
        assert [[r[k] for k in OUTCOME_FIELDS] for r in b] == [[r[k] for k in OUTCOME_FIELDS] for r in a]
        assert sum(int(r["cache_hits"]) for r in b if r["agent"] == "vlm") == n_vlm
        assert sum(int(r["requests"]) for r in b) == 0
        # the cost columns count the cached calls' tokens alike
        assert [r["cost_usd"] for r in b] == [r["cost_usd"] for r in a]
        # an analysis of the vlm agent, whose decisions name the question type only: the split is not applicable
        sets_c = [s for s in sets if not s.startswith("analysis.agent")] + ["analysis.agent='vlm'"]
        argv_c = ["--study", "analysis", "--quiet", "--out", str(tmp_path / "c")]
        argv_c += sum((["--set", s] for s in sets_c), [])
        assert main(argv_c) == 0, capsys.readouterr().err
        assert srv.stats()["requests"] == sent
        report_c = (tmp_path / "c" / "report.md").read_text()
        assert "not applicable, `vlm` names the question type only" in report_c
        assert not (tmp_path / "c" / "analysis_type3_content.csv").exists()


def test_mllm_agent_without_a_server_and_other_llm_config_errors(tmp_path):
    with pytest.raises(ConfigError) as e:
        resolve(None, ["eval.agents=['eig', 'vlm']"])
    assert e.value.where == "llm.endpoints" and "'vlm'" in str(e.value)
    with pytest.raises(ConfigError) as e:
        resolve(None, ["eval.agents=['vlm']", "llm.endpoints=['http://127.0.0.1:1/v1']"])
    assert e.value.where == "llm.model"
    with pytest.raises(ConfigError) as e:
        resolve(None, ["llm.timeout_s=-1"])
    assert e.value.where == "llm.timeout_s" and str(e.value).startswith("--set")
    with pytest.raises(ConfigError, match="views.size"):
        resolve(None, ["views.size=20"])
    # an MLLM agent may be the one analysed; it needs the server only when the analysis study runs
    cfg = resolve(None, ["analysis.agent='tandem'"])
    with pytest.raises(ConfigError) as e:
        run_sweep(cfg, ["analysis"], tmp_path / "never")
    assert e.value.where == "llm.endpoints" and "analysis.agent" in str(e.value)
    assert not (tmp_path / "never").exists()
    with pytest.raises(ConfigError, match="unknown key llm.temprature"):
        resolve(None, ["llm.temprature=0.5"])


def test_a_model_the_server_does_not_serve_stops_the_sweep_before_any_work(tmp_path, capsys):
    """Checked before the run folder is made, for an MLLM agent in eval.agents or as analysis.agent."""
    with ScriptedServer() as srv:
        sets = [s for s in _sets(srv, tmp_path, tmp_path / "cache") if not s.startswith("llm.model")]
        for study, wrong in (("eval", "eval.agents=['random', 'vlm']"), ("analysis", "eval.agents=['random']")):
            argv = ["--study", study, "--quiet", "--out", str(tmp_path / study)]
            argv += sum((["--set", s] for s in sets + [wrong, "llm.model='qwen2-vl'"]), [])
            assert main(argv) == 2
            err = capsys.readouterr().err
            assert f"error: llm.model: model 'qwen2-vl' is not served: {srv.base_url} serves '{srv.model}'" in err
            assert not (tmp_path / study).exists()
        assert srv.stats()["requests"] == 0
    # where nothing answers: the endpoint named
    dead = sets + [f"llm.model='{srv.model}'"]  # the server has stopped: nothing listens at its URL
    argv = ["--study", "eval", "--quiet", "--out", str(tmp_path / "dead")] + sum((["--set", s] for s in dead), [])
    assert main(argv) == 2
    assert f"error: llm.endpoints: {srv.base_url} did not list its models" in capsys.readouterr().err
    assert not (tmp_path / "dead").exists()


def test_where_the_model_is_served_does_not_change_the_run():
    base = ["eval.agents=['vlm']", "llm.model='m'"]
    a = resolve(None, base + ["llm.endpoints=['http://10.0.0.1:8000/v1']", "llm.concurrency=4"])
    b = resolve(None, base + ["llm.endpoints=['http://10.0.0.2:8000/v1', 'http://10.0.0.3:8000/v1']",
                              "views.workers=2"])
    c = resolve(None, ["eval.agents=['vlm']", "llm.model='other'", "llm.endpoints=['http://10.0.0.1:8000/v1']"])
    assert fingerprint(a, ["eval"]) == fingerprint(b, ["eval"]) != fingerprint(c, ["eval"])
