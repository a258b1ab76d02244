"""Content-addressed cache of chat replies (SQLite, standard library).

**The key.** :func:`request_hash` is the SHA-256 (hex) of the canonical JSON
(``sort_keys=True, separators=(",", ":")``, ``ensure_ascii=False``, UTF-8)
of ::

    {"v": 1, "model": <model name>,
     "params": {temperature, seed, max_tokens, structured, schema_name,
                image_detail, extra_body},
     "schema": <reply JSON schema or null>,
     "messages": [{"role": r, "content": str | [parts]}, ...]}

where a text part is ``{"type": "text", "text": s}`` and an image part is
``{"type": "image", "mime": m, "sha256": <hex digest of its bytes>}``. The
endpoint URL, the API key and the request's ``tag`` (episode id) are not
part of it: the same model served elsewhere, or the same prompt in another
episode, maps to the same entry. ``structured`` is the *configured* mode
(``auto`` stays ``auto`` even after an endpoint fell back to no
``response_format``), so that a replay finds what the recording run stored.

**The store.** :class:`ResponseCache` keeps one table in
``<folder>/llm_cache.sqlite`` in WAL mode with ``synchronous=NORMAL`` and
autocommit: each :meth:`~ResponseCache.put` is committed when it returns,
so a killed process loses at most the requests still in flight. One
connection is shared by the coroutines of one process (and guarded by a
lock for threads); reads and writes are short, so they run inline on the
event loop. Only successful replies are stored (the client never stores
errors), with the reply text, finish reason, token counts and latency — not
the prompt, so the file holds nothing but replies and hashes.
"""

from __future__ import annotations

import hashlib
import json
import os
import sqlite3
import threading
import time
from pathlib import Path
from typing import Any, Iterable

CACHE_FILE = "llm_cache.sqlite"
HASH_VERSION = 1


def canonical_messages(messages: Iterable[dict]) -> list[dict]:
    """Messages as they enter the hash: images replaced by mime + SHA-256.

    Content parts may be plain strings (text), ``{"type": "text", "text":
    ...}`` dicts, or image objects with ``data`` (bytes) and ``mime``
    attributes (:class:`~ignjax.agents.llm.client.ImagePart`)."""
    out = []
    for m in messages:
        content = m.get("content")
        if isinstance(content, (list, tuple)):
            parts = []
            for p in content:
                if isinstance(p, str):
                    parts.append({"type": "text", "text": p})
                elif isinstance(p, dict):
                    parts.append(p)
                else:  # an image part: bytes + mime
                    parts.append({"type": "image", "mime": p.mime, "sha256": hashlib.sha256(p.data).hexdigest()})
            content = parts
        entry = {"role": m.get("role"), "content": content}
        entry.update({k: v for k, v in m.items() if k not in ("role", "content")})
        out.append(entry)
    return out


def request_hash(model: str, params: dict, messages: Iterable[dict], schema: dict | None) -> str:
    """SHA-256 hex of the canonical JSON of a request (see the module doc)."""
    doc = {"v": HASH_VERSION, "model": model, "params": params, "schema": schema,
           "messages": canonical_messages(messages)}
    blob = json.dumps(doc, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()


class ResponseCache:
    """Replies by request hash in ``<folder>/llm_cache.sqlite``.

    Args:
        folder: where the file goes; created with its parents.
    """

    def __init__(self, folder: str | os.PathLike):
        d = Path(folder)
        d.mkdir(parents=True, exist_ok=True)
        self.path = d / CACHE_FILE
        self._lock = threading.Lock()
        self._db = sqlite3.connect(str(self.path), isolation_level=None, check_same_thread=False, timeout=30.0)
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA synchronous=NORMAL")
        self._db.execute("CREATE TABLE IF NOT EXISTS replies (hash TEXT PRIMARY KEY, record TEXT NOT NULL, "
                         "created REAL NOT NULL)")

    def get(self, key: str) -> dict | None:
        """The stored record of ``key``, or ``None``."""
        with self._lock:
            row = self._db.execute("SELECT record FROM replies WHERE hash = ?", (key,)).fetchone()
        return json.loads(row[0]) if row else None

    def put(self, key: str, record: dict[str, Any]) -> None:
        """Store (or replace) the record of ``key``; committed on return."""
        blob = json.dumps(record, sort_keys=True, ensure_ascii=False)
        with self._lock:
            self._db.execute("INSERT OR REPLACE INTO replies (hash, record, created) VALUES (?, ?, ?)",
                             (key, blob, time.time()))

    def __contains__(self, key: str) -> bool:
        with self._lock:
            return self._db.execute("SELECT 1 FROM replies WHERE hash = ?", (key,)).fetchone() is not None

    def __len__(self) -> int:
        with self._lock:
            return self._db.execute("SELECT COUNT(*) FROM replies").fetchone()[0]

    def close(self) -> None:
        with self._lock:
            self._db.close()

    def __enter__(self) -> "ResponseCache":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"ResponseCache({str(self.path)!r})"


__all__ = ["CACHE_FILE", "ResponseCache", "canonical_messages", "request_hash"]
