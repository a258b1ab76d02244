"""ChatClient against the real scripted server: wire format, structured
output and its fallback, concurrency and load balancing, retries of every
fault kind, retry caps, key hygiene, config checks, and the reply parser."""

from __future__ import annotations

import asyncio
import logging
import os
import re
import secrets
import socket

import pytest

from ignjax.agents.llm.client import ChatClient
from ignjax.agents.llm.messages import ChatRequest, ImagePart, LLMRequestError, price
from ignjax.agents.llm.config import LLMConfig
from ignjax.agents.llm.parse import parse_reply, validate
from ignjax.errors import ConfigError, InputError

SCHEMA = {
    "type": "object",
    "properties": {
        "action": {"type": "string", "enum": ["move", "ask", "stop"]},
        "cell": {"type": "integer", "minimum": 1, "maximum": 64},
        "why": {"type": "string", "maxLength": 40},
    },
    "required": ["action", "cell"],
    "additionalProperties": False,
}


def req(text="Where is the red chair? Answer in JSON.", schema=None, tag="", images=()):
    content = [text, *images] if images else text
    return ChatRequest([{"role": "system", "content": "You navigate a house."},
                        {"role": "user", "content": content}], schema=schema, tag=tag)


# ---------------------------------------------------------------------------
# wire format and structured output
# ---------------------------------------------------------------------------


def test_images_reach_the_server_as_data_urls(scripted_server, llm_config, run_client):
    srv = scripted_server()
    img_a, img_b = os.urandom(1000), os.urandom(333)
    (res,), _, _ = run_client(llm_config(srv), [req(images=(ImagePart(img_a, "image/jpeg"), ImagePart(img_b, "image/png")))])
    assert res.endpoint == srv.base_url and not res.cache_hit
    parts = srv.last_request["messages"][1]["content"]
    assert parts[0] == {"type": "text", "text": "Where is the red chair? Answer in JSON."}
    assert [p["type"] for p in parts[1:]] == ["image_url", "image_url"]
    assert parts[1]["image_url"]["url"].startswith("data:image/jpeg;base64,")
    assert srv.last_images == [("image/jpeg", img_a), ("image/png", img_b)]
    assert res.prompt_tokens == 4 + 8 + 2 * 256  # the server's approximation: words + 256 per image
    assert "Authorization" not in srv.last_headers  # api_key_env=None: no header
    body = srv.last_request
    assert body["model"] == "ignjax-scripted" and body["temperature"] == 0.0 and body["seed"] == 0
    assert body["max_tokens"] == 256 and "response_format" not in body  # no schema: no response_format


def test_image_detail_and_extra_body_are_sent(scripted_server, llm_config, run_client):
    srv = scripted_server()
    cfg = llm_config(srv, image_detail="low", extra_body={"top_p": 0.5}, seed=None)
    run_client(cfg, [req(images=(ImagePart(b"\xff\xd8jpeg"),))])
    body = srv.last_request
    assert body["messages"][1]["content"][1]["image_url"]["detail"] == "low"
    assert body["top_p"] == 0.5 and "seed" not in body


def test_structured_output_is_sent_and_parsed(scripted_server, llm_config, run_client):
    srv = scripted_server()
    results, stats, _ = run_client(llm_config(srv, structured="json_schema"),
                                   [req(schema=SCHEMA), req(schema=SCHEMA), req("Other question", schema=SCHEMA)])
    rf = srv.last_request["response_format"]
    assert rf == {"type": "json_schema", "json_schema": {"name": "decision", "schema": SCHEMA, "strict": True}}
    for r in results:
        assert r.parse_error is None and validate(r.parsed, SCHEMA) is None
        assert r.finish_reason == "stop" and r.completion_tokens > 0
    assert results[0].text == results[1].text  # same request, same seed: same reply
    assert stats.requests_sent == 3 and stats.prompt_tokens == sum(r.prompt_tokens for r in results)


def test_auto_falls_back_when_the_server_rejects_response_format(scripted_server, llm_config, run_client, caplog):
    srv = scripted_server(reject_response_format=True)
    caplog.set_level(logging.INFO, logger="ignjax.agents.llm")
    (a, b), stats, _ = run_client(llm_config(srv), [req(schema=SCHEMA), req("Second", schema=SCHEMA)])
    sent = srv.requests
    assert ["response_format" in r for r in sent] == [True, False, False]
    assert a.retries == 0 and stats.retries == 0  # the fallback is not a retry
    assert stats.unstructured_endpoints == (srv.base_url,)
    # no response_format: the server answers the prompt's "JSON" with its own object; the schema check reports it
    assert a.parsed is None and "missing required field 'action'" in a.parse_error
    assert "response_format" in caplog.text
    # forced json_schema: the 400 is an error carrying the server's message, not retried
    srv.reset_stats()
    with pytest.raises(LLMRequestError) as e:
        run_client(llm_config(srv, structured="json_schema"), [req(schema=SCHEMA)])
    assert e.value.status == 400 and e.value.attempts == 1 and "guided decoding is not available" in str(e.value)
    assert srv.stats()["requests"] == 1


def test_structured_none_never_sends_response_format(scripted_server, llm_config, run_client):
    srv = scripted_server()
    (r,), _, _ = run_client(llm_config(srv, structured="none"), [req(schema=SCHEMA)])
    assert "response_format" not in srv.last_request
    assert r.parsed is None and r.parse_error.startswith("missing required field")


def test_non_retryable_4xx_carries_the_server_message(scripted_server, llm_config, run_client):
    srv = scripted_server()
    with pytest.raises(LLMRequestError) as e:
        run_client(llm_config(srv, model="no-such-model"), [req()])
    err = e.value
    assert err.status == 404 and err.attempts == 1 and err.endpoint == srv.base_url
    assert "The model `no-such-model` does not exist." in str(err) and srv.base_url in str(err)


# ---------------------------------------------------------------------------
# concurrency and load balancing
# ---------------------------------------------------------------------------


def test_concurrency_bound_is_respected(scripted_server, llm_config, run_client):
    srv = scripted_server(latency=0.02, jitter=0.5, concurrency=64)
    requests = [req(f"question {i}") for i in range(40)]
    results, stats, _ = run_client(llm_config(srv, concurrency=4), requests, many=True)
    assert all(not isinstance(r, Exception) for r in results)
    assert [r.request_hash for r in results] == [ChatClient(llm_config(srv)).request_hash(q) for q in requests]
    s = srv.stats()
    assert s["requests"] == 40 and 2 <= s["max_concurrent"] <= 4 and stats.max_in_flight == 4
    assert stats.in_flight == 0 and stats.capacity == 4


def test_utilisation_of_a_saturated_client(scripted_server, llm_config):
    """24 requests at concurrency 4 fill the client's 4 slots; the in-flight integral between two snapshots
    covers every attempt's time on the wire and never exceeds the capacity, and utilisation is its mean."""
    srv = scripted_server(latency=0.03)

    async def go():
        async with ChatClient(llm_config(srv, concurrency=4)) as client:
            warm = await client.complete(req("warm up"))
            t0 = client.stats()
            results = await client.complete_many([req(f"q {i}") for i in range(24)])
            t1 = client.stats()
            return warm, results, t0, t1, client.utilisation()

    warm, results, t0, t1, overall = asyncio.run(go())
    assert t0.max_in_flight == 1 and t1.max_in_flight == 4 and t0.in_flight == t1.in_flight == 0
    assert t1.requests_sent - t0.requests_sent == 24 and t1.retries == 0 and t1.capacity == 4
    assert srv.stats()["requests"] == 25 and srv.stats()["max_concurrent"] <= 4
    busy, span = t1.in_flight_seconds - t0.in_flight_seconds, t1.t - t0.t
    # a request holds its slot from before it is sent until after its reply is read
    assert busy >= sum(r.latency_s for r in results) > 0
    assert t1.in_flight_seconds >= busy + warm.latency_s
    assert busy <= t1.capacity * span * (1 + 1e-9)  # at most 4 in flight at any time
    window = t1.utilisation_since(t0)
    assert window == pytest.approx(busy / span / 4, rel=1e-12) and 0 < window <= 1 + 1e-9
    assert 0 < overall <= 1 + 1e-9


def test_two_endpoints_share_the_load_least_loaded_first(scripted_server, llm_config, run_client):
    a, b = scripted_server(latency=0.02), scripted_server(latency=0.02)
    cfg = llm_config(a, b, concurrency=3)
    results, stats, _ = run_client(cfg, [req(f"q {i}") for i in range(30)], many=True)
    assert all(not isinstance(r, Exception) for r in results)
    sa, sb = a.stats(), b.stats()
    assert sa["requests"] + sb["requests"] == 30 and sa["requests"] >= 10 and sb["requests"] >= 10
    assert sa["max_concurrent"] <= 3 and sb["max_concurrent"] <= 3 and stats.max_in_flight == 6
    assert {r.endpoint for r in results} == {a.base_url, b.base_url}
    # one at a time: both idle each time, so the tie goes to the lowest index
    a.reset_stats(), b.reset_stats()
    run_client(cfg, [req(f"serial {i}") for i in range(3)])
    assert a.stats()["requests"] == 3 and b.stats()["requests"] == 0


# ---------------------------------------------------------------------------
# faults and retries
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["429", "500", "503", "drop", "malformed"])
def test_each_fault_is_retried_and_then_succeeds(kind, scripted_server, llm_config, run_client):
    srv = scripted_server(faults=f"{kind}@1-2", retry_after=0.01)
    (r,), stats, _ = run_client(llm_config(srv, max_retries=2), [req(schema=SCHEMA)])
    assert r.retries == 2 and stats.retries == 2 and r.parsed is not None
    assert srv.stats()["faults"] == {kind: 2} and srv.stats()["requests"] == 3


def test_probabilistic_faults_are_retried_within_the_cap(scripted_server, llm_config, run_client):
    srv = scripted_server(faults="429:0.1,500:0.1,503:0.05,drop:0.05,malformed:0.1", retry_after=0.01, seed=3)
    results, stats, _ = run_client(llm_config(srv, concurrency=8), [req(f"q {i}", schema=SCHEMA) for i in range(40)],
                                   many=True)
    assert all(not isinstance(r, Exception) and r.parsed is not None for r in results)
    faults = srv.stats()["faults"]
    assert sum(faults.values()) == stats.retries > 0 and len(faults) >= 3
    assert srv.stats()["requests"] == 40 + stats.retries


def test_timeout_is_retried(scripted_server, llm_config, run_client, caplog):
    """The first request sleeps 5 s on the server: the client gives up on it at its 0.3 s timeout (it logs
    so and the server never answers it) and the retry gets the reply."""
    caplog.set_level(logging.INFO, logger="ignjax.agents.llm")
    srv = scripted_server(faults="slow@1", slow_s=5.0)
    (r,), stats, _ = run_client(llm_config(srv, timeout_s=0.3), [req()])
    assert r.retries == 1 and stats.retries == 1 and stats.requests_sent == 2 and r.finish_reason == "stop"
    assert "timed out after 0.3 s; retry 1 in" in caplog.text
    s = srv.stats()
    assert s["faults"] == {"slow": 1} and s["requests"] == 2 and s["statuses"] == {200: 1}


def test_truncated_reply_is_returned_with_a_parse_error(scripted_server, llm_config, run_client):
    srv = scripted_server(faults="truncated@1")
    (r, again), _, _ = run_client(llm_config(srv), [req(schema=SCHEMA), req(schema=SCHEMA)])
    assert r.finish_reason == "length" and r.parsed is None and r.retries == 0
    assert "cut off at max_tokens" in r.parse_error
    assert again.finish_reason == "stop" and again.text.startswith(r.text)


def test_max_tokens_cuts_the_reply(scripted_server, llm_config, run_client):
    srv = scripted_server()
    (r,), _, _ = run_client(llm_config(srv, max_tokens=2), [req(schema=SCHEMA)])
    assert r.finish_reason == "length" and r.completion_tokens == 2 and "cut off" in r.parse_error


def test_faults_that_never_stop_give_an_error_naming_endpoint_status_attempts(scripted_server, llm_config, run_client):
    srv = scripted_server(faults="503:1.0")
    with pytest.raises(LLMRequestError) as e:
        run_client(llm_config(srv, max_retries=3), [req(tag="ep-7")])
    err, msg = e.value, str(e.value)
    assert err.endpoint == srv.base_url and err.status == 503 and err.attempts == 4
    assert srv.base_url in msg and "HTTP 503" in msg and "after 4 attempts" in msg and "max_retries=3" in msg
    assert "'ep-7'" in msg and srv.stats()["requests"] == 4


def test_connection_refused_is_retried_then_reported(llm_config, run_client):
    with socket.socket() as s:  # bound, never listening, held for the whole test: connections are refused
        s.bind(("127.0.0.1", 0))
        url = f"http://127.0.0.1:{s.getsockname()[1]}/v1"
        with pytest.raises(LLMRequestError) as e:
            run_client(llm_config(url, max_retries=1), [req()])
    assert e.value.status is None and e.value.attempts == 2 and "connection error" in str(e.value)
    assert e.value.endpoint == url


def test_retry_after_is_honoured(scripted_server, llm_config, run_client, caplog):
    """After a 429 the client waits the server's Retry-After (capped at backoff_max_s) instead of its own
    backoff: it says so, and the server sees at least that long between the 429 and the retry."""
    caplog.set_level(logging.INFO, logger="ignjax.agents.llm")
    srv = scripted_server(faults="429@1", retry_after=0.3)
    (r,), _, _ = run_client(llm_config(srv, backoff_base_s=0.001, backoff_max_s=5.0), [req()])
    assert r.retries == 1 and srv.stats()["statuses"] == {429: 1, 200: 1}
    assert re.findall(r"HTTP 429: rate limited \(scripted fault\); retry 1 in ([0-9.]+) s", caplog.text) == ["0.300"]
    first, retry = srv.arrivals
    assert retry - first >= 0.3
    # a Retry-After of 30 s is capped at backoff_max_s
    caplog.clear()
    srv2 = scripted_server(faults="429@1", retry_after=30)
    (r2,), _, _ = run_client(llm_config(srv2, backoff_base_s=0.001, backoff_max_s=0.1), [req()])
    assert r2.retries == 1 and srv2.stats()["statuses"] == {429: 1, 200: 1}
    assert re.findall(r"retry 1 in ([0-9.]+) s", caplog.text) == ["0.100"]
    first, retry = srv2.arrivals
    assert retry - first >= 0.1


def test_per_episode_retry_cap(scripted_server, llm_config):
    srv = scripted_server(faults="500@1-3,500@5-100")

    async def go():
        async with ChatClient(llm_config(srv, max_retries=10, max_retries_per_episode=2)) as client:
            with pytest.raises(LLMRequestError) as first:
                await client.complete(req("a", tag="ep-1"))  # requests 1-3 fail: 2 retries, then the cap
            ok = await client.complete(req("b", tag="ep-2"))  # request 4 succeeds
            with pytest.raises(LLMRequestError) as second:
                await client.complete(req("c", tag="ep-1"))  # cap already spent: one attempt
            return first.value, ok, second.value, client.episode_retries("ep-1")

    first, ok, second, spent = asyncio.run(go())
    assert first.attempts == 3 and "max_retries_per_episode=2" in str(first) and "'ep-1'" in str(first)
    assert ok.retries == 0 and spent == 2
    assert second.attempts == 1 and "max_retries_per_episode=2" in str(second)


def test_complete_many_returns_exceptions_in_place(scripted_server, llm_config, run_client):
    srv = scripted_server(faults="500@3")  # request 2 is the bad one; 3 is the third's first attempt
    bad = ChatRequest([{"role": "wizard", "content": "the server rejects this role"}])
    results, stats, _ = run_client(llm_config(srv, concurrency=1), [req("first"), bad, req("third")], many=True)
    assert isinstance(results[1], LLMRequestError) and results[1].status == 400 and results[1].attempts == 1
    assert "role must be one of" in str(results[1])
    assert [r.text[:15] for r in (results[0], results[2])] == ["Scripted reply "] * 2
    assert (results[0].retries, results[2].retries) == (0, 1)
    assert stats.requests_failed == 1 and stats.replies_ok == 2


def test_retry_jitter_is_reproducible(scripted_server, llm_config, run_client, caplog):
    caplog.set_level(logging.INFO, logger="ignjax.agents.llm")

    def waits():
        caplog.clear()
        srv = scripted_server(faults="500@1-3")
        run_client(llm_config(srv, backoff_base_s=0.02, backoff_max_s=0.05, max_retries=3), [req()])
        return re.findall(r"retry \d in ([0-9.]+) s", caplog.text)

    first = waits()
    assert len(first) == 3 and first == waits()


# ---------------------------------------------------------------------------
# the API key
# ---------------------------------------------------------------------------


def test_api_key_is_sent_only_in_the_authorization_header(scripted_server, llm_config, run_client, monkeypatch,
                                                          caplog, tmp_path):
    key = "sk-test-" + secrets.token_hex(16)
    monkeypatch.setenv("IGNJAX_TEST_LLM_KEY", key)
    caplog.set_level(logging.DEBUG)
    srv = scripted_server(faults="500@2")
    cfg = llm_config(srv, api_key_env="IGNJAX_TEST_LLM_KEY", cache_dir=str(tmp_path / "cache"), max_retries=2)
    (r,), _, rep = run_client(cfg, [req(schema=SCHEMA)])
    assert srv.last_headers["Authorization"] == f"Bearer {key}"
    assert key not in rep and "<secret>" in rep
    # a server echoing the request back in its error: the message is scrubbed
    evil = ChatRequest([{"role": f"intruder-{key}", "content": "hi"}])
    with pytest.raises(LLMRequestError) as e:
        run_client(cfg, [evil])
    assert e.value.status == 400 and "***" in str(e.value)
    # retries are logged; never with the key
    srv2 = scripted_server(faults="503:1.0")
    with pytest.raises(LLMRequestError) as e2:
        run_client(llm_config(srv2, api_key_env="IGNJAX_TEST_LLM_KEY", max_retries=1), [req()])
    for text in (str(e.value), repr(e.value), str(e2.value), repr(e2.value), str(cfg.public_dict()), repr(cfg),
                 caplog.text, repr(r)):
        assert key not in text
    assert "retry 1" in caplog.text
    for f in (tmp_path / "cache").iterdir():
        assert key.encode() not in f.read_bytes()


def test_unset_key_variable_sends_no_header(scripted_server, llm_config, run_client, monkeypatch):
    monkeypatch.delenv("IGNJAX_TEST_UNSET_KEY", raising=False)
    srv = scripted_server()
    run_client(llm_config(srv, api_key_env="IGNJAX_TEST_UNSET_KEY"), [req()])
    assert "Authorization" not in srv.last_headers


# ---------------------------------------------------------------------------
# config and request checks, price
# ---------------------------------------------------------------------------


def test_config_from_dict_and_public_dict_round_trip():
    d = {"endpoints": ["http://127.0.0.1:8000/v1/", "http://10.0.0.2:8000/v1"], "model": "qwen",
         "prices": {"prompt": 1, "completion": 2}, "extra_body": {"guided_decoding_backend": "xgrammar"}}
    cfg = LLMConfig.from_dict(d)
    assert cfg.endpoints == ("http://127.0.0.1:8000/v1", "http://10.0.0.2:8000/v1")
    assert cfg.prices == {"prompt": 1.0, "completion": 2.0}
    pub = cfg.public_dict()
    assert LLMConfig.from_dict(pub) == cfg and pub["api_key_env"] == "OPENAI_API_KEY"


@pytest.mark.parametrize("bad, field, words", [
    ({"temprature": 0.5}, "llm.temprature", "unknown setting"),
    ({"timeout_s": -1}, "llm.timeout_s", "must be > 0"),
    ({"concurrency": 0}, "llm.concurrency", "must be >= 1"),
    ({"concurrency": 2.5}, "llm.concurrency", "expected an integer"),
    ({"max_retries": True}, "llm.max_retries", "expected an integer"),
    ({"temperature": 3}, "llm.temperature", "must be <= 2.0"),
    ({"temperature": "hot"}, "llm.temperature", "expected a finite number"),
    ({"structured": "yes"}, "llm.structured", "must be one of 'auto', 'json_schema', 'none'"),
    ({"endpoints": ["localhost:8000"]}, "llm.endpoints[0]", "http:// or https://"),
    ({"endpoints": []}, "llm.endpoints", "at least one URL"),
    ({"backoff_max_s": 0.1}, "llm.backoff_max_s", "must be >= backoff_base_s"),
    ({"prices": {"prompt": 1}}, "llm.prices.completion", "number >= 0"),
    ({"extra_body": {"model": "x"}}, "llm.extra_body.model", "set by the client"),
    ({"image_detail": "ultra"}, "llm.image_detail", "must be one of"),
    ({"seed": "zero"}, "llm.seed", "expected an integer or none"),
])
def test_bad_config_values_name_the_field(bad, field, words):
    d = {"endpoints": ["http://127.0.0.1:8000/v1"], "model": "m", **bad}
    with pytest.raises(ConfigError) as e:
        LLMConfig.from_dict(d, path="sweep.toml")
    assert e.value.where == field and words in str(e.value) and str(e.value).startswith("sweep.toml: ")


def test_missing_model_and_key_pasted_into_api_key_env():
    with pytest.raises(ConfigError, match=r"llm\.model: required"):
        LLMConfig.from_dict({"endpoints": ["http://h/v1"]})
    # the defaults (the sweep's [llm] table when no MLLM agent runs) build, but no client starts from them
    with pytest.raises(ConfigError, match=r"llm\.endpoints: needs at least one URL"):
        ChatClient(LLMConfig())
    with pytest.raises(ConfigError, match=r"llm\.model: needs the served model's name"):
        ChatClient(LLMConfig(endpoints=("http://h/v1",)))
    assert LLMConfig(endpoints=("http://h/v1",), model="m", api_key_env="").api_key_env is None
    key = "sk-" + secrets.token_hex(12)
    with pytest.raises(ConfigError) as e:
        LLMConfig(endpoints=("http://h/v1",), model="m", api_key_env=key)
    assert "NAME of an environment variable" in str(e.value) and key not in str(e.value)
    with pytest.raises(ConfigError, match="replay needs a response cache"):
        ChatClient(LLMConfig(endpoints=(), model="m", replay=True))


def test_bad_requests_name_the_place():
    with pytest.raises(InputError, match=r"messages\[0\]\.content\[1\]"):
        ChatRequest([{"role": "user", "content": ["text", b"raw bytes"]}])
    with pytest.raises(InputError, match="ImagePart.mime"):
        ImagePart(b"x", "jpeg")
    with pytest.raises(InputError, match="messages"):
        ChatRequest([])
    assert "bytes" in repr(ImagePart(b"\x00" * 5000)) and len(repr(ImagePart(b"\x00" * 5000))) < 80


def test_price():
    assert price(1_000_000, 500_000, {"prompt": 0.5, "completion": 2.0}) == pytest.approx(1.5)
    assert price(10, 10, None) is None


# ---------------------------------------------------------------------------
# the tolerant parser
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("text, expected", [
    ('{"cell": 3}', {"cell": 3}),
    ('  \n{"cell": 3}\n', {"cell": 3}),
    ('```json\n{"cell": 3}\n```', {"cell": 3}),
    ('Sure!\n```\n{"cell": 3}\n```\nDone.', {"cell": 3}),
    ('I pick {"cell": 3, "why": "the {red} chair \\"is\\" there }"} because.', {"cell": 3, "why": 'the {red} chair "is" there }'}),
    ('Set {a} is empty; answer: {"cell": 4}', {"cell": 4}),
    ('{"a": {"b": [1, {"c": 2}]}} trailing', {"a": {"b": [1, {"c": 2}]}}),
])
def test_parse_reply_finds_the_object(text, expected):
    assert parse_reply(text) == (expected, None)


@pytest.mark.parametrize("text, words", [
    ('{"cell": 3,}', "invalid JSON"),
    ("Here: {'cell': 3}", "invalid JSON"),
    ('{"cell": 3, "why": "cut', "no complete JSON object"),
    ("I will move left.", "no JSON object"),
    ("", "empty reply"),
    ("[1, 2]", "expected a JSON object"),
])
def test_parse_reply_reports_without_repairing(text, words):
    parsed, err = parse_reply(text)
    assert parsed is None and words in err


@pytest.mark.parametrize("obj, error", [
    ({"action": "move", "cell": 65}, "field 'cell' must be between 1 and 64, got 65"),
    ({"action": "move", "cell": "3"}, "field 'cell' must be an integer, got a string"),
    ({"action": "jump", "cell": 3}, "field 'action' must be one of 'move', 'ask', 'stop', got 'jump'"),
    ({"cell": 3}, "missing required field 'action'"),
    ({"action": "ask", "cell": 3, "x": 1}, "unexpected field 'x'"),
    ({"action": "ask", "cell": 3, "why": "y" * 41}, "field 'why' must have at most 40 characters"),
    ({"action": "ask", "cell": 3.0}, None),
])
def test_schema_subset(obj, error):
    err = validate(obj, SCHEMA)
    assert (err is None) if error is None else error in err


def test_schema_any_of_and_refs():
    schema = {
        "$defs": {"cell": {"type": "integer", "minimum": 1, "maximum": 64}},
        "anyOf": [
            {"type": "object", "properties": {"action": {"const": "move"}, "cell": {"$ref": "#/$defs/cell"}},
             "required": ["action", "cell"], "additionalProperties": False},
            {"type": "object", "properties": {"action": {"const": "ask"}, "question": {"type": "string"}},
             "required": ["action", "question"], "additionalProperties": False},
        ],
    }
    assert validate({"action": "move", "cell": 5}, schema) is None
    assert validate({"action": "ask", "question": "is it red?"}, schema) is None
    assert validate({"action": "move", "cell": 99}, schema) == "field 'cell' must be between 1 and 64, got 99"
    assert "missing required field 'question'" in validate({"action": "ask"}, schema)
    assert "none of the allowed forms" in validate({"action": "fly"}, schema)
    assert parse_reply('ok: {"action": "move", "cell": 0}', schema) == (
        None, "field 'cell' must be between 1 and 64, got 0")
    items = {"type": "array", "items": {"type": "boolean"}, "minItems": 1}
    assert validate({"v": [True, 1]}, {"properties": {"v": items}}) == "field 'v[1]' must be true or false, got an integer"
