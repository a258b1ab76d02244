"""The response cache: hits send nothing, the hash covers image bytes but
not the endpoint, replay answers only from the cache, errors are never
stored, and the SQLite file survives reopening."""

from __future__ import annotations

import sqlite3

import pytest

from ignjax.agents.llm.cache import CACHE_FILE, ResponseCache, request_hash
from ignjax.agents.llm.client import ChatClient
from ignjax.agents.llm.messages import ChatRequest, ImagePart, LLMRequestError, ReplayMissError

SCHEMA = {"type": "object", "properties": {"cell": {"type": "integer", "minimum": 1, "maximum": 64}},
          "required": ["cell"]}


def req(text="Which cell? Answer in JSON.", image=b"\xff\xd8 one image", tag=""):
    return ChatRequest([{"role": "user", "content": [text, ImagePart(image, "image/jpeg")]}], schema=SCHEMA, tag=tag)


def test_second_identical_request_is_a_hit_and_sends_nothing(scripted_server, llm_config, run_client, tmp_path):
    srv = scripted_server()
    cfg = llm_config(srv, cache_dir=str(tmp_path / "deep" / "cache"))
    (first,), s1, _ = run_client(cfg, [req(tag="ep-1")])
    assert srv.stats()["requests"] == 1 and not first.cache_hit and first.endpoint == srv.base_url
    (hit, other), s2, _ = run_client(cfg, [req(tag="ep-2"), req("Another question")])
    assert srv.stats()["requests"] == 2  # only the new question was sent
    assert hit.cache_hit and hit.endpoint is None and hit.retries == 0
    assert (hit.text, hit.parsed, hit.request_hash, hit.prompt_tokens, hit.finish_reason) == (
        first.text, first.parsed, first.request_hash, first.prompt_tokens, first.finish_reason)
    assert hit.latency_s == first.latency_s and not other.cache_hit
    assert s2.cache_hits == 1 and s2.requests_sent == 1
    assert (tmp_path / "deep" / "cache" / CACHE_FILE).is_file()


def test_hash_covers_image_bytes_not_the_endpoint(scripted_server, llm_config, run_client, tmp_path):
    a, b = scripted_server(), scripted_server()
    cfg_a = llm_config(a, cache_dir=str(tmp_path))
    cfg_b = llm_config(b, cache_dir=str(tmp_path))
    ca, cb = ChatClient(cfg_a), ChatClient(cfg_b)
    assert ca.request_hash(req()) == cb.request_hash(req())
    assert ca.request_hash(req()) != ca.request_hash(req(image=b"\xff\xd8 other image"))
    assert ca.request_hash(req()) != ChatClient(llm_config(a, temperature=0.7)).request_hash(req())
    assert ca.request_hash(req()) != ChatClient(llm_config(a, model="other")).request_hash(req())
    assert ca.request_hash(req(tag="x")) == ca.request_hash(req(tag="y"))
    run_client(cfg_a, [req()])
    (r,), _, _ = run_client(cfg_b, [req()])
    assert r.cache_hit and b.stats()["requests"] == 0
    (r2,), _, _ = run_client(cfg_b, [req(image=b"\xff\xd8 other image")])
    assert not r2.cache_hit and b.stats()["requests"] == 1


def test_request_hash_definition():
    msgs = [{"role": "user", "content": ["hi", ImagePart(b"abc", "image/png")]}]
    h = request_hash("m", {"temperature": 0.0}, msgs, None)
    same = [{"role": "user", "content": [{"type": "text", "text": "hi"}, ImagePart(b"abc", "image/png")]}]
    assert h == request_hash("m", {"temperature": 0.0}, same, None)
    assert h != request_hash("m", {"temperature": 0.0}, [{"role": "user", "content": ["hi", ImagePart(b"abc", "image/jpeg")]}], None)
    assert h != request_hash("m", {"temperature": 0.0}, msgs, {"type": "object"})
    assert len(h) == 64 and int(h, 16) >= 0


def test_replay_answers_from_the_cache_and_a_miss_names_hash_and_path(scripted_server, llm_config, run_client,
                                                                      tmp_path):
    srv = scripted_server()
    run_client(llm_config(srv, cache_dir=str(tmp_path)), [req()])
    srv.stop()  # nothing listens any more: replay must not send
    cfg = llm_config(srv.base_url, cache_dir=str(tmp_path), replay=True)
    (r,), stats, _ = run_client(cfg, [req()])
    assert r.cache_hit and stats.requests_sent == 0
    missing = req("never asked")
    with pytest.raises(ReplayMissError) as e:
        run_client(cfg, [missing])
    h = ChatClient(cfg).request_hash(missing)
    assert e.value.request_hash == h and h in str(e.value) and str(tmp_path / CACHE_FILE) in str(e.value)


def test_errors_are_never_cached(scripted_server, llm_config, run_client, tmp_path):
    srv = scripted_server(faults="500:1.0")
    with pytest.raises(LLMRequestError):
        run_client(llm_config(srv, cache_dir=str(tmp_path), max_retries=1), [req()])
    with ResponseCache(tmp_path) as cache:
        assert len(cache) == 0


def test_cache_file_reopens_and_uses_wal(tmp_path):
    with ResponseCache(tmp_path / "a" / "b") as cache:
        cache.put("k1", {"text": "hello", "finish_reason": "stop", "prompt_tokens": 3, "completion_tokens": 1,
                         "latency_s": 0.5})
        assert "k1" in cache and cache.get("nope") is None
    db = sqlite3.connect(tmp_path / "a" / "b" / CACHE_FILE)  # another connection sees the committed row
    assert db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    assert db.execute("SELECT COUNT(*) FROM replies").fetchone()[0] == 1
    db.close()
    with ResponseCache(tmp_path / "a" / "b") as cache:
        assert cache.get("k1")["text"] == "hello" and len(cache) == 1
