"""docs/mllm.md ("The key"): the API key named by ``--llm-key-env`` "is only ever put in the
``Authorization`` header: never in logs, outcomes, ``run.json``,
checkpoints, transcripts or error messages". One ``python -m
ignjax.evaluate`` (in process) of the ``navgpt`` agent (a caption call per view, a Planner call) against the
scripted server (a real HTTP server on 127.0.0.1), with a server error on one
request so a retry is logged: the server received the key as a bearer token,
and no file of the run folder (response cache included) and no line the run
printed holds it, as text, base64 or hex."""

from __future__ import annotations

import base64
import json
import logging
import secrets
from pathlib import Path

from ignjax.agents.llm.serve import ScriptedServer
from ignjax.evaluate.cli import main as evaluate

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"
KEY_ENV = "IGNJAX_TEST_SECRET_KEY"


def _forms(key: str) -> list[bytes]:
    raw = key.encode()
    return [raw, base64.b64encode(raw), base64.urlsafe_b64encode(raw), raw.hex().encode()]


def test_api_key_reaches_the_server_and_no_file_of_the_run(rendering, tmp_path, monkeypatch, capfd, caplog):
    key = "sk-ignjax-" + secrets.token_hex(16)
    monkeypatch.setenv(KEY_ENV, key)
    caplog.set_level(logging.DEBUG)
    out = tmp_path / "run"
    with ScriptedServer(faults="500@2") as srv:
        argv = ["--episodes", str(EPISODES), "--agent", "navgpt", "--limit", "1", "--set", "sim.max_steps=3", "--set", "views.size=64",
                "--llm-endpoint", srv.base_url, "--llm-model", srv.model, "--llm-key-env", KEY_ENV,
                "--out", str(out), "--quiet"]
        assert evaluate(argv) == 0
        assert srv.last_headers["Authorization"] == f"Bearer {key}"
        assert srv.stats()["faults"] == {"500": 1}
    files = [p for p in out.rglob("*") if p.is_file()]
    names = {p.relative_to(out).as_posix() for p in files}
    assert {"run.json", "outcomes.csv", "transcripts/navgpt.jsonl", "llm/navgpt.progress.jsonl",
            "llm_cache/llm_cache.sqlite"} <= names, sorted(names)
    assert json.loads((out / "run.json").read_text())["image_size"] == 64  # the views navgpt's captioner saw
    printed = capfd.readouterr()
    assert "retry 1" in caplog.text
    texts = {p.relative_to(out).as_posix(): p.read_bytes() for p in files}
    texts.update({"stdout": printed.out.encode(), "stderr": printed.err.encode(), "log": caplog.text.encode()})
    for form in _forms(key):
        assert not [name for name, data in texts.items() if form in data], form
