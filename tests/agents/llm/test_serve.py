"""The scripted test-double server on its own: OpenAI request checks,
deterministic replies valid under the request's schema, the policy hook,
queueing, the fault grammar and its determinism, and the command line."""

from __future__ import annotations

import base64
import json
import os
import random
import re
import select
import socket
import subprocess
import sys
import urllib.error
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from ignjax.agents.llm.parse import validate
from ignjax.agents.llm.scripted import schema_instance
from ignjax.agents.llm.serve import DEFAULT_MODEL, FaultSpec
from ignjax.agents.llm.vllm_server import listening_ports
from ignjax.errors import ConfigError

ROOT = Path(__file__).resolve().parents[3]


def post(srv, body, timeout=10):
    """(status, JSON reply or raw text) of one POST /v1/chat/completions."""
    data = body if isinstance(body, bytes) else json.dumps(body).encode()
    rq = urllib.request.Request(f"{srv.base_url}/chat/completions", data=data,
                                headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(rq, timeout=timeout) as r:
            raw = r.read()
            status = r.status
    except urllib.error.HTTPError as e:
        with e:
            raw, status = e.read(), e.code
    try:
        return status, json.loads(raw)
    except ValueError:
        return status, raw.decode()


def chat(text="hello", **extra):
    return {"model": DEFAULT_MODEL, "messages": [{"role": "user", "content": text}], **extra}


def rf(schema):
    return {"type": "json_schema", "json_schema": {"name": "decision", "schema": schema, "strict": True}}


SCHEMA = {
    "$defs": {"cell": {"type": "integer", "minimum": 1, "maximum": 64}},
    "type": "object",
    "properties": {
        "decision": {"oneOf": [
            {"type": "object", "properties": {"action": {"const": "move"}, "cell": {"$ref": "#/$defs/cell"}},
             "required": ["action", "cell"], "additionalProperties": False},
            {"type": "object", "properties": {"action": {"const": "ask"},
                                              "kind": {"enum": ["room", "colour", "near"]}},
             "required": ["action", "kind"], "additionalProperties": False}]},
        "confidence": {"type": "number", "minimum": 0, "maximum": 1},
        "seen": {"type": "array", "items": {"type": "string", "maxLength": 12}, "minItems": 1, "maxItems": 4},
        "done": {"type": "boolean"},
        "note": {"type": ["string", "null"], "minLength": 3},
    },
    "required": ["decision", "confidence", "seen", "done"],
    "additionalProperties": False,
}


def test_models_lists_the_one_model_and_says_test_double(scripted_server):
    srv = scripted_server(model="tiny")
    with urllib.request.urlopen(f"{srv.base_url}/models", timeout=10) as r:
        j = json.loads(r.read())
    assert j["object"] == "list" and [m["id"] for m in j["data"]] == ["tiny"]
    assert "test double" in j["data"][0]["description"]


@pytest.mark.parametrize("body, status, words", [
    (b"not json", 400, "not valid JSON"),
    ({"model": DEFAULT_MODEL}, 400, "'messages' must be a non-empty list"),
    (chat(model="gpt-17"), 404, "`gpt-17` does not exist"),
    ({"model": DEFAULT_MODEL, "messages": [{"role": "wizard", "content": "x"}]}, 400, "role must be one of"),
    ({"model": DEFAULT_MODEL, "messages": [{"role": "user", "content": [{"type": "image_url",
      "image_url": {"url": "data:image/png;base64,!!!notbase64"}}]}]}, 400, "does not decode"),
    ({"model": DEFAULT_MODEL, "messages": [{"role": "user", "content": [{"type": "image_url",
      "image_url": {"url": "https://example.com/a.png"}}]}]}, 400, "data:<mime>;base64"),
    ({"model": DEFAULT_MODEL, "messages": [{"role": "user", "content": [{"type": "audio"}]}]}, 400, "type 'text' or"),
    (chat(response_format={"type": "json_schema"}), 400, "json_schema"),
    (chat(stream=True), 400, "streaming"),
    (chat(max_tokens=0), 400, "max_tokens"),
])
def test_bad_requests_get_openai_style_errors(scripted_server, body, status, words):
    srv = scripted_server()
    got, j = post(srv, body)
    assert got == status and words in j["error"]["message"]
    if status == 400:
        assert j["error"]["type"] == "invalid_request_error"


def test_replies_follow_the_schema_and_are_deterministic(scripted_server):
    srv = scripted_server()
    img = base64.b64encode(os.urandom(64)).decode()
    body = {"model": DEFAULT_MODEL, "seed": 1, "response_format": rf(SCHEMA), "messages": [
        {"role": "user", "content": [{"type": "text", "text": "where now?"},
                                     {"type": "image_url", "image_url": {"url": f"data:image/jpeg;base64,{img}"}}]}]}
    status, j = post(srv, body)
    assert status == 200 and j["object"] == "chat.completion"
    content = j["choices"][0]["message"]["content"]
    assert validate(json.loads(content), SCHEMA) is None and j["choices"][0]["finish_reason"] == "stop"
    assert j["usage"]["prompt_tokens"] == 2 + 256 and j["usage"]["completion_tokens"] == len(content.split())
    assert post(srv, body)[1]["choices"][0]["message"]["content"] == content
    other = {**body, "seed": 2}
    assert post(srv, other)[1]["choices"][0]["message"]["content"] != content


def test_schema_instances_are_valid_for_many_seeds():
    kinds = set()
    for s in range(200):
        v = schema_instance(SCHEMA, random.Random(s))
        assert validate(v, SCHEMA) is None, v
        kinds.add(v["decision"]["action"])
    assert kinds == {"move", "ask"}


def test_plain_replies_and_the_policy_hook(scripted_server):
    srv = scripted_server()
    _, j = post(srv, chat("Reply in JSON please"))
    assert isinstance(json.loads(j["choices"][0]["message"]["content"]), dict)
    _, j = post(srv, chat("Just talk"))
    assert "test double" in j["choices"][0]["message"]["content"]
    seen = []

    def policy(request):
        seen.append(request["messages"][-1]["content"])
        return '{"action": "stop"}' if "stop" in seen[-1] else '{"action": "move"}'

    srv2 = scripted_server(policy=policy)
    assert post(srv2, chat("please stop"))[1]["choices"][0]["message"]["content"] == '{"action": "stop"}'
    assert post(srv2, chat("go on"))[1]["choices"][0]["message"]["content"] == '{"action": "move"}'
    assert seen == ["please stop", "go on"]


def test_requests_beyond_the_concurrency_queue(scripted_server):
    srv = scripted_server(latency=0.05, concurrency=2)
    with ThreadPoolExecutor(8) as pool:
        statuses = list(pool.map(lambda i: post(srv, chat(f"q{i}"))[0], range(8)))
    s = srv.stats()
    assert statuses == [200] * 8 and s["requests"] == 8
    assert s["max_concurrent"] == 2 and s["queue_high_water"] >= 1 and s["statuses"] == {200: 8}


def test_fault_spec_grammar():
    spec = FaultSpec.parse("429:0.1, 500:0.05,slow:0.02,drop:0.02,malformed:0.05,truncated:0.02, 503@3, drop@5-6")
    assert spec.rates[0] == ("429", 0.1) and spec.positions == ((3, 3, "503"), (5, 6, "drop"))
    assert spec.choose(3, 0.99) == "503" and spec.choose(6, 0.99) == "drop"
    assert spec.choose(1, 0.05) == "429" and spec.choose(1, 0.12) == "500" and spec.choose(1, 0.9) is None
    for bad, words in [("teapot:0.1", "unknown fault kind"), ("500:1.5", "in [0, 1]"), ("500:0.6,429:0.6", "sum"),
                       ("500@0", "KIND@N"), ("500@2-1", "KIND@N"), ("500@1-3,drop@2", "overlaps"), ("500", "expected")]:
        with pytest.raises(ConfigError) as e:
            FaultSpec.parse(bad)
        assert e.value.where == "--faults" and words in str(e.value)


def test_random_faults_are_deterministic_and_retries_draw_anew(scripted_server):
    def run(seed):
        srv = scripted_server(faults="500:0.5", seed=seed)
        out = [post(srv, chat(f"q{i % 5}"))[0] for i in range(30)]
        return out, srv.stats()["faults"]

    a, b, c = run(7), run(7), run(8)
    assert a == b and a != c
    assert 0 < a[1]["500"] < 30
    # the same body sent again is not doomed: each retry draws anew
    statuses = a[0]
    assert any(s == 500 for s in statuses[:5]) and any(s == 200 for s in statuses[5:])


def test_fault_responses(scripted_server):
    srv = scripted_server(faults="429@1,malformed@2,truncated@3,503@4,drop@5", retry_after=0.25)
    rq = urllib.request.Request(f"{srv.base_url}/chat/completions", data=json.dumps(chat("JSON")).encode(),
                                headers={"Content-Type": "application/json"})
    with pytest.raises(urllib.error.HTTPError) as e:
        urllib.request.urlopen(rq, timeout=10)
    e.value.close()
    assert e.value.code == 429 and e.value.headers["Retry-After"] == "0.25"
    status, text = post(srv, chat("JSON"))
    assert status == 200 and isinstance(text, str)
    status, j = post(srv, chat("JSON"))
    assert j["choices"][0]["finish_reason"] == "length"
    with pytest.raises(ValueError):
        json.loads(j["choices"][0]["message"]["content"])
    assert post(srv, chat("JSON"))[0] == 503
    with pytest.raises((urllib.error.URLError, ConnectionError, OSError)):
        post(srv, chat("JSON"))
    assert post(srv, chat("JSON"))[0] == 200
    assert srv.stats()["faults"] == {"429": 1, "malformed": 1, "truncated": 1, "503": 1, "drop": 1}


READY = re.compile(r"listening on http://127\.0\.0\.1:(\d+)/v1 ")


def start_cli(*args: str) -> subprocess.Popen:
    """The command-line server started with ``--port 0`` and ``args``."""
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    return subprocess.Popen([sys.executable, "-m", "ignjax.agents.llm.serve", "--port", "0", *args], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def ready_line(proc: subprocess.Popen, wait_s: float = 60) -> tuple[int, str]:
    """The server's ready line (its first line on stdout), read as soon as it is printed, and the port it names."""
    readable, _, _ = select.select([proc.stdout], [], [], wait_s)
    line = proc.stdout.readline() if readable else ""
    m = READY.search(line)
    if m is None:
        proc.kill()
        out, err = proc.communicate(timeout=30)
        pytest.fail(f"no ready line from the server (stdout {line + out!r}); stderr:\n{err[-2000:]}")
    return int(m.group(1)), line


def stop_cli(proc: subprocess.Popen) -> tuple[int, str, str]:
    """Stop the server with SIGTERM (if it still runs): its exit code, stdout and stderr."""
    if proc.poll() is None:
        proc.terminate()
    out, err = proc.communicate(timeout=30)
    return proc.returncode, out, err


def assert_clean_exit(code: int, out: str, err: str) -> None:
    assert code == 0, err
    assert "Traceback" not in err and "RuntimeWarning" not in err and "scripted server stopped" in err


def models(port: int) -> list[str]:
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/v1/models", timeout=10) as r:
        return [m["id"] for m in json.loads(r.read())["data"]]


def test_command_line_server_answers_models():
    """``--port 0``: the server binds a port of its own choosing and its ready line names it; that is the one
    port its process listens on, and it answers there."""
    proc = start_cli("--model", "cli-m", "--faults", "500@1")
    try:
        port, line = ready_line(proc)
        listening, answer = listening_ports(proc.pid), models(port)
    finally:
        code, out, err = stop_cli(proc)
    assert port > 0 and listening == {port} and answer == ["cli-m"]
    assert "not a model" in line and "'cli-m'" in line
    assert_clean_exit(code, out, err)


def test_servers_started_at_once_get_ports_of_their_own(scripted_server):
    """Two in-process servers and two command-line servers, all on port 0 and started together, each bind a
    different port and each answers there with its own model."""
    procs = [start_cli("--model", f"cli-{i}") for i in range(2)]
    try:
        a, b = scripted_server(model="in-0"), scripted_server(model="in-1")
        ports = {"in-0": a.port, "in-1": b.port, "cli-0": ready_line(procs[0])[0],
                 "cli-1": ready_line(procs[1])[0]}
        answers = {model: models(port) for model, port in ports.items()}
    finally:
        exits = [stop_cli(proc) for proc in procs]
    assert len(set(ports.values())) == 4 and min(ports.values()) > 0, ports
    assert a.base_url == f"http://127.0.0.1:{a.port}/v1"
    assert answers == {model: [model] for model in ports}
    for e in exits:
        assert_clean_exit(*e)


def test_listening_ports_are_read_from_proc(scripted_server):
    """:func:`listening_ports` (how the vLLM server's port is found): the listening sockets a process holds,
    IPv4 and IPv6, not one that is only bound or already closed, and nothing for a process that is gone."""
    srv = scripted_server()
    with socket.socket() as listening, socket.socket() as bound:
        listening.bind(("127.0.0.1", 0))
        listening.listen()
        bound.bind(("127.0.0.1", 0))
        lport, bport = listening.getsockname()[1], bound.getsockname()[1]
        ports = listening_ports(os.getpid())
    assert {srv.port, lport} <= ports and bport not in ports
    assert lport not in listening_ports(os.getpid()) and srv.port in listening_ports(os.getpid())
    with socket.socket(socket.AF_INET6) as six:
        try:
            six.bind(("::1", 0))
        except OSError:  # no IPv6 loopback on this machine
            pass
        else:
            six.listen()
            assert six.getsockname()[1] in listening_ports(os.getpid())
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait(timeout=60)
    assert listening_ports(gone.pid) == set()


def test_command_line_rejects_a_bad_fault_spec():
    r = subprocess.run([sys.executable, "-m", "ignjax.agents.llm.serve", "--faults", "teapot:1"], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "--faults" in r.stderr and "unknown fault kind" in r.stderr
