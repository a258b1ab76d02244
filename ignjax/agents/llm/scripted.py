"""What the scripted test double (:mod:`ignjax.agents.llm.serve`) replies:
a reply computed from the request by a script, never by a language model.
With a reply schema, :func:`schema_instance` writes an instance of it from a
generator seeded by the request; without one, a short sentence naming the
request's digest; a caller's ``policy`` may answer instead. Also how tests
and policies read a request (:func:`request_text`, :func:`texts_and_images`)."""

from __future__ import annotations

import base64
import hashlib
import json
import random
import re
from typing import Any, Callable

from ignjax.agents.llm.parse import resolve_ref

DATA_URL = re.compile(r"^data:(?P<mime>[\w.+-]+/[\w.+-]+);base64,(?P<b64>.*)$", re.DOTALL)
"""An image part's ``data:`` URL: its mime type and base64 payload."""
_WORDS = ("kitchen", "chair", "table", "left", "right", "door", "sofa", "lamp", "north", "window", "bed", "red")


def schema_instance(schema: Any, rng: random.Random, root: Any = None, depth: int = 0) -> Any:
    """A value valid under ``schema`` (the subset :mod:`~ignjax.agents.llm.parse`
    checks), chosen by ``rng``."""
    root = schema if root is None else root
    if schema is True or schema is None or schema == {}:
        return rng.choice(_WORDS)
    schema = resolve_ref(schema, root)
    if "const" in schema:
        return schema["const"]
    if schema.get("enum"):
        return rng.choice(schema["enum"])
    for key in ("anyOf", "oneOf"):
        if schema.get(key):
            merged = {k: v for k, v in schema.items() if k != key}
            merged.update(resolve_ref(rng.choice(schema[key]), root))
            return schema_instance(merged, rng, root, depth + 1)
    if schema.get("allOf"):
        merged = {k: v for k, v in schema.items() if k != "allOf"}
        for sub in schema["allOf"]:
            sub = resolve_ref(sub, root)
            for k, v in sub.items():
                if k == "properties":
                    merged["properties"] = {**merged.get("properties", {}), **v}
                elif k == "required":
                    merged["required"] = list(dict.fromkeys(list(merged.get("required", [])) + list(v)))
                else:
                    merged.setdefault(k, v)
        return schema_instance(merged, rng, root, depth + 1)
    t = schema.get("type")
    if isinstance(t, list):
        non_null = [x for x in t if x != "null"]
        t = rng.choice(non_null or t)
    if t is None:
        t = ("object" if "properties" in schema else "array" if "items" in schema
             else "integer" if "minimum" in schema or "maximum" in schema else "string")
    if t == "object":
        props = schema.get("properties") or {}
        required = set(schema.get("required") or ())
        keys = [k for k in props if depth < 8 or k in required]
        return {k: schema_instance(props[k], rng, root, depth + 1) for k in keys}
    if t == "array":
        lo = int(schema.get("minItems", 1))
        hi = int(schema.get("maxItems", lo + 2))
        n = lo if depth >= 8 else rng.randint(lo, max(lo, min(hi, lo + 3)))
        return [schema_instance(schema.get("items", {}), rng, root, depth + 1) for _ in range(n)]
    if t in ("integer", "number"):
        lo, hi = schema.get("minimum"), schema.get("maximum")
        xlo, xhi = schema.get("exclusiveMinimum"), schema.get("exclusiveMaximum")
        if t == "integer":
            lo = int(lo) if lo is not None else (int(xlo) + 1 if xlo is not None else 0)
            hi = int(hi) if hi is not None else (int(xhi) - 1 if xhi is not None else lo + 100)
            return rng.randint(lo, max(lo, hi))
        lo = float(lo) if lo is not None else (float(xlo) + 1e-3 if xlo is not None else 0.0)
        hi = float(hi) if hi is not None else (float(xhi) - 1e-3 if xhi is not None else lo + 100.0)
        return min(max(round(rng.uniform(lo, hi), 3), lo), hi)
    if t == "boolean":
        return rng.random() < 0.5
    if t == "null":
        return None
    s = " ".join(rng.choice(_WORDS) for _ in range(rng.randint(1, 3)))
    lo, hi = int(schema.get("minLength", 0)), schema.get("maxLength")
    s = s.ljust(lo, "x")
    return s[: int(hi)] if hi is not None else s


def request_text(body: dict) -> str:
    """Every text part of a request's messages, one per line (what a reply policy reads)."""
    return "\n".join(texts_and_images(body)[0])


def texts_and_images(body: dict) -> tuple[list[str], list[tuple[str, bytes]]]:
    texts, images = [], []
    for m in body.get("messages", ()):
        c = m.get("content")
        if isinstance(c, str):
            texts.append(c)
        elif isinstance(c, list):
            for p in c:
                if p.get("type") == "text":
                    texts.append(p.get("text", ""))
                elif p.get("type") == "image_url":
                    mm = DATA_URL.match(p["image_url"]["url"])
                    images.append((mm.group("mime"), base64.b64decode(mm.group("b64"))))
    return texts, images


def scripted_reply(body: dict, policy: Callable[[dict], str] | None = None) -> str:
    """The reply text for a (checked) request body; see the module doc."""
    if policy is not None:
        return str(policy(body))
    texts, images = texts_and_images(body)
    digest = hashlib.sha256(json.dumps([texts, [hashlib.sha256(b).hexdigest() for _, b in images],
                                        body.get("seed")]).encode()).hexdigest()
    rng = random.Random(int(digest[:16], 16))
    rf = body.get("response_format") or {}
    if rf.get("type") == "json_schema":
        return json.dumps(schema_instance(rf["json_schema"]["schema"], rng))
    last_user = ""
    for m in body.get("messages", ()):
        if m.get("role") == "user":
            c = m.get("content")
            last_user = c if isinstance(c, str) else " ".join(p.get("text", "") for p in c if p.get("type") == "text")
    if rf.get("type") == "json_object" or re.search(r"\bjson\b", last_user, re.IGNORECASE):
        return json.dumps({"reply": f"scripted {digest[:8]}", "choice": rng.randint(1, 64)})
    return f"Scripted reply {digest[:8]}: {rng.choice(_WORDS)} {rng.choice(_WORDS)} (test double, not a model)."


def cut_words(text: str, max_words: int) -> str:
    m = list(re.finditer(r"\S+", text))
    return text[: m[max_words - 1].end()] if len(m) > max_words else text


__all__ = ["DATA_URL", "cut_words", "request_text", "schema_instance", "scripted_reply", "texts_and_images"]
