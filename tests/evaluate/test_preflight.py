"""The generation and image defaults (the paper's temperature 0 and 1024-token
cap; one view size for ``ViewConfig``, ``python -m ignjax.evaluate`` and the
sweep), and ``python -m ignjax.evaluate`` stopping before any episode on a
model the server does not serve or an endpoint where nothing answers (the
scripted server on 127.0.0.1, a closed port)."""

from __future__ import annotations

import socket
import subprocess
import sys
from pathlib import Path

from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.serve import ScriptedServer
from ignjax.config import resolve
from ignjax.evaluate.cli import build_parser, llm_settings, main
from ignjax.sim.views.config import DEFAULT_SIZE, ViewConfig

ROOT = Path(__file__).resolve().parents[2]
EPISODES = ROOT / "scenes" / "benchmark.jsonl.gz"


def test_generation_settings_and_one_view_size():
    assert (LLMConfig().temperature, LLMConfig().max_tokens) == (0.0, 1024)
    assert ViewConfig().size == DEFAULT_SIZE == 448
    for cfg in (resolve(None, []), resolve(None, [], quick=True)):
        assert cfg.views.size == DEFAULT_SIZE and (cfg.llm.temperature, cfg.llm.max_tokens) == (0.0, 1024)
    args = build_parser().parse_args(["--episodes", str(EPISODES), "--agent", "vlm",
                                      "--llm-endpoint", "http://127.0.0.1:8000/v1", "--llm-model", "m"])
    llm, views = llm_settings(args, {}, Path("out"))
    assert views.size == DEFAULT_SIZE and (llm.temperature, llm.max_tokens) == (0.0, 1024)
    assert llm_settings(args, {"views": {"size": 64}}, Path("out"))[1].size == 64


def test_a_wrong_model_stops_the_command_before_any_episode(tmp_path):
    out = tmp_path / "run"
    with ScriptedServer() as srv:
        proc = subprocess.run([sys.executable, "-m", "ignjax.evaluate", "--episodes", str(EPISODES), "--agent", "vlm",
                               "--llm-endpoint", srv.base_url, "--llm-model", "ignjax-scriptd", "--limit", "2",
                               "--out", str(out), "--quiet"], cwd=ROOT, capture_output=True, text=True, timeout=300)
        sent = srv.stats()["requests"]
    assert proc.returncode == 2, proc.stderr[-3000:]
    assert f"error: --llm-model: model 'ignjax-scriptd' is not served: {srv.base_url} serves 'ignjax-scripted'" \
        in proc.stderr
    assert "Traceback" not in proc.stderr and "loaded" not in proc.stderr  # no scene was loaded
    assert sent == 0 and not list(out.rglob("outcomes.*"))


def test_an_endpoint_where_nothing_listens_is_named(tmp_path, capsys):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        url = f"http://127.0.0.1:{s.getsockname()[1]}/v1"  # released below: nothing listens there
    out = tmp_path / "run"
    argv = ["--episodes", str(EPISODES), "--agent", "tandem", "--llm-endpoint", url, "--llm-model", "m",
            "--limit", "2", "--out", str(out), "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"error: --llm-endpoint: {url} did not list its models (GET {url}/models): connection error" in err
    assert not list(out.rglob("outcomes.*"))
    # a dry run only counts: no server needed, none asked
    assert main(argv + ["--dry-run"]) == 0
