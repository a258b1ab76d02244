"""The model check before any episode (:func:`ignjax.agents.llm.models.check_served`)
against real servers on 127.0.0.1: the scripted server's model list, a closed
port, a port that accepts connections but never answers, and a server that
rejects the key and echoes it back (the key must not reach the error)."""

from __future__ import annotations

import asyncio
import secrets
import socket
import threading

import pytest

from ignjax.agents.llm.models import check_served, served_models
from ignjax.agents.llm.serve import DEFAULT_MODEL
from ignjax.errors import ConfigError

KEY_ENV = "IGNJAX_TEST_MODELS_KEY"


def _closed_port() -> int:
    """A port nothing listens on (bound, then released)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_served_model_passes_and_asks_no_completion(scripted_server, llm_config):
    a, b = scripted_server(), scripted_server()
    check_served(llm_config(a, b))
    assert a.stats()["requests"] == b.stats()["requests"] == 0  # the model list is no chat request
    assert asyncio.run(served_models(llm_config(a))) == {a.base_url: [DEFAULT_MODEL]}


def test_a_model_not_served_names_it_and_the_served_ones(scripted_server, llm_config):
    right, other = scripted_server(), scripted_server(model="qwen2-vl")
    with pytest.raises(ConfigError) as e:
        check_served(llm_config(right, other, model="ignjax-scriptd"))
    assert e.value.where == "llm.model"
    msg = str(e.value)
    assert "'ignjax-scriptd' is not served" in msg
    assert f"{right.base_url} serves '{DEFAULT_MODEL}'" in msg and f"{other.base_url} serves 'qwen2-vl'" in msg
    # one endpoint of two lacking the model is named alone; the command line names its own flags
    with pytest.raises(ConfigError) as e:
        check_served(llm_config(right, other), "--llm-model", "--llm-endpoint")
    assert e.value.where == "--llm-model" and other.base_url in str(e.value) and right.base_url not in str(e.value)


def test_an_endpoint_that_does_not_answer_is_named(llm_config):
    closed = f"http://127.0.0.1:{_closed_port()}/v1"
    with pytest.raises(ConfigError) as e:
        check_served(llm_config(closed))
    assert e.value.where == "llm.endpoints" and f"{closed} did not list its models" in str(e.value)
    assert "connection error" in str(e.value)
    # a port that takes the connection but never answers: an error once the client's timeout has passed
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(8)  # connections wait in the backlog; none is accepted
        url = f"http://127.0.0.1:{silent.getsockname()[1]}/v1"
        with pytest.raises(ConfigError) as e:
            check_served(llm_config(url, timeout_s=0.3), "--llm-model", "--llm-endpoint")
    assert e.value.where == "--llm-endpoint" and url in str(e.value) and "no answer within 0.3 s" in str(e.value)


def test_replay_asks_nothing(llm_config, tmp_path):
    check_served(llm_config(f"http://127.0.0.1:{_closed_port()}/v1", replay=True, cache_dir=str(tmp_path)))


def _echo_key_server(sock: socket.socket) -> threading.Thread:
    """Answer one request with 401 and a message quoting its Authorization header (as a careless proxy might)."""
    def serve():
        conn, _ = sock.accept()
        with conn:
            head = b""
            while b"\r\n\r\n" not in head:
                head += conn.recv(4096)
            auth = next(line for line in head.decode().split("\r\n") if line.lower().startswith("authorization:"))
            body = ('{"error": {"message": "invalid key in ' + auth.split(":", 1)[1].strip() + '"}}').encode()
            conn.sendall(b"HTTP/1.1 401 Unauthorized\r\nContent-Type: application/json\r\nConnection: close\r\n"
                         + f"Content-Length: {len(body)}\r\n\r\n".encode() + body)

    t = threading.Thread(target=serve, daemon=True)
    t.start()
    return t


def test_the_key_is_sent_and_never_in_the_error(llm_config, monkeypatch):
    key = "sk-ignjax-" + secrets.token_hex(16)
    monkeypatch.setenv(KEY_ENV, key)
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        sock.listen(1)
        url = f"http://127.0.0.1:{sock.getsockname()[1]}/v1"
        t = _echo_key_server(sock)
        with pytest.raises(ConfigError) as e:
            check_served(llm_config(url, api_key_env=KEY_ENV))
        t.join(5)
    msg = str(e.value)
    # the server got the key (its echo was scrubbed to ***), the error does not hold it
    assert "HTTP 401: invalid key in Bearer ***" in msg and key not in msg and key not in repr(e.value)
