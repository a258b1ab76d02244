"""Tolerant parsing of a model's JSON reply, and a small JSON-schema check.

:func:`parse_reply` finds one JSON object in a reply: the whole text, else
the first fenced block (```` ```json ... ``` ````) that holds an object,
else the first balanced top-level ``{...}`` in the prose (braces inside JSON
strings and escapes are respected). It repairs nothing: a trailing comma or
single quotes are reported, not fixed, so that what the agent acts on is
exactly what the model wrote, and the error can go back to the model in a
correction prompt.

:func:`validate` checks a practical subset of JSON schema by hand (no
dependency): ``type`` (object, string, integer, number, boolean, array,
null, or a list of them), ``enum``, ``const``, ``minimum`` / ``maximum`` /
``exclusiveMinimum`` / ``exclusiveMaximum``, ``minLength`` / ``maxLength`` /
``pattern``, ``items`` / ``minItems`` / ``maxItems``, ``properties`` /
``required`` / ``additionalProperties`` (false or a schema), ``anyOf`` /
``oneOf`` / ``allOf``, and local ``$ref`` (``#/$defs/...``,
``#/definitions/...``). Other keywords are ignored. Errors are short and
name the field: ``field 'cell' must be between 1 and 64``.
"""

from __future__ import annotations

import json
import re
from typing import Any

_FENCE = re.compile(r"```[ \t]*([A-Za-z0-9_-]*)[^\n]*\n(.*?)```", re.DOTALL)
_TYPE_WORDS = {"object": "an object", "array": "a list", "string": "a string", "integer": "an integer",
               "number": "a number", "boolean": "true or false", "null": "null"}


def parse_reply(text: str | None, schema: dict | None = None) -> tuple[dict | None, str | None]:
    """The JSON object in ``text``, checked against ``schema`` if given.

    Returns:
        ``(obj, None)`` on success, ``(None, error)`` otherwise; the error
        is one short sentence fit for a correction prompt.
    """
    if text is None or not text.strip():
        return None, "empty reply: expected a JSON object"
    obj, err = _find_object(text)
    if obj is None:
        return None, err
    if schema is not None:
        err = validate(obj, schema)
        if err is not None:
            return None, err
    return obj, None


def _loads(s: str) -> tuple[Any, str | None]:
    try:
        return json.loads(s), None
    except json.JSONDecodeError as e:
        return None, f"invalid JSON: {e.msg} at line {e.lineno} column {e.colno}"
    except RecursionError:
        return None, "invalid JSON: nested too deeply"


def _find_object(text: str) -> tuple[dict | None, str | None]:
    stripped = text.strip()
    first_err = None
    value, err = _loads(stripped)
    if err is None:
        if isinstance(value, dict):
            return value, None
        return None, f"expected a JSON object, got {_kind(value)}"
    spans = list(_balanced_objects(text))
    if stripped.startswith("{") and spans:  # complete but invalid; without a closing brace: cut off (below)
        first_err = err
    for m in _FENCE.finditer(text):
        body = m.group(2).strip()
        if not body.startswith("{"):
            continue
        value, err = _loads(body)
        if isinstance(value, dict):
            return value, None
        first_err = first_err or err
    for start, end in spans:
        value, err = _loads(text[start:end])
        if isinstance(value, dict):
            return value, None
        first_err = first_err or err
    if first_err:
        return None, first_err
    if "{" in text:
        return None, "no complete JSON object in the reply (is it cut off?)"
    return None, "no JSON object in the reply"


def _balanced_objects(text: str):
    """(start, end) of each balanced top-level ``{...}``, in order; braces in
    JSON strings (with escapes) do not count. An unclosed object ends the
    scan."""
    i, n = 0, len(text)
    while i < n:
        start = text.find("{", i)
        if start < 0:
            return
        depth, in_str, esc, j = 0, False, False, start
        while j < n:
            c = text[j]
            if in_str:
                if esc:
                    esc = False
                elif c == "\\":
                    esc = True
                elif c == '"':
                    in_str = False
            elif c == '"':
                in_str = True
            elif c == "{":
                depth += 1
            elif c == "}":
                depth -= 1
                if depth == 0:
                    break
            j += 1
        if j >= n:
            return
        yield start, j + 1
        i = j + 1


def _kind(v: Any) -> str:
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "true or false"
    if isinstance(v, int):
        return "an integer"
    if isinstance(v, float):
        return "a number"
    if isinstance(v, str):
        return "a string"
    if isinstance(v, list):
        return "a list"
    if isinstance(v, dict):
        return "an object"
    return type(v).__name__


def _is_type(v: Any, t: str) -> bool:
    if t == "object":
        return isinstance(v, dict)
    if t == "array":
        return isinstance(v, list)
    if t == "string":
        return isinstance(v, str)
    if t == "boolean":
        return isinstance(v, bool)
    if t == "null":
        return v is None
    if t == "integer":
        return (isinstance(v, int) and not isinstance(v, bool)) or (isinstance(v, float) and v.is_integer())
    if t == "number":
        return isinstance(v, (int, float)) and not isinstance(v, bool)
    return True


def resolve_ref(schema: dict, root: dict) -> dict:
    """Follow local ``$ref`` pointers (``#/...``) of ``schema`` within ``root``."""
    seen = 0
    while isinstance(schema, dict) and "$ref" in schema:
        ref = schema["$ref"]
        if not isinstance(ref, str) or not ref.startswith("#"):
            raise ValueError(f"only local $ref is supported, got {ref!r}")
        node: Any = root
        for part in [p for p in ref[1:].split("/") if p]:
            part = part.replace("~1", "/").replace("~0", "~")
            if not isinstance(node, dict) or part not in node:
                raise ValueError(f"$ref {ref!r} does not resolve")
            node = node[part]
        schema = node
        seen += 1
        if seen > 64:
            raise ValueError(f"$ref {ref!r} loops")
    return schema


def _name(path: str) -> str:
    return f"field '{path}'" if path else "the reply"


def _fmt(v: Any) -> str:
    return json.dumps(v) if not isinstance(v, str) else repr(v)


def validate(value: Any, schema: dict, root: dict | None = None, path: str = "") -> str | None:
    """First violation of ``schema`` by ``value`` as a short sentence, or
    ``None`` when it conforms (subset of JSON schema; see the module doc)."""
    root = schema if root is None else root
    if schema is True or schema == {}:
        return None
    if schema is False:
        return f"{_name(path)} is not allowed"
    try:
        schema = resolve_ref(schema, root)
    except ValueError as e:
        return f"schema error at {_name(path)}: {e}"
    if not isinstance(schema, dict):
        return None
    for sub in schema.get("allOf", ()):
        err = validate(value, sub, root, path)
        if err:
            return err
    for key in ("anyOf", "oneOf"):
        if key in schema:
            err = _check_branches(value, schema[key], root, path, exactly_one=key == "oneOf")
            if err:
                return err
    t = schema.get("type")
    if t is not None:
        types = [t] if isinstance(t, str) else list(t)
        if not any(_is_type(value, x) for x in types):
            want = " or ".join(_TYPE_WORDS.get(x, x) for x in types)
            return f"{_name(path)} must be {want}, got {_kind(value)}"
    if "const" in schema and value != schema["const"]:
        return f"{_name(path)} must be {_fmt(schema['const'])}"
    if "enum" in schema and value not in schema["enum"]:
        opts = schema["enum"]
        shown = ", ".join(_fmt(o) for o in opts[:12]) + (", ..." if len(opts) > 12 else "")
        return f"{_name(path)} must be one of {shown}, got {_fmt(value)}"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        err = _check_range(value, schema, path)
        if err:
            return err
    if isinstance(value, str):
        if "minLength" in schema and len(value) < schema["minLength"]:
            return f"{_name(path)} must have at least {schema['minLength']} characters"
        if "maxLength" in schema and len(value) > schema["maxLength"]:
            return f"{_name(path)} must have at most {schema['maxLength']} characters"
        if "pattern" in schema and not re.search(schema["pattern"], value):
            return f"{_name(path)} must match the pattern {schema['pattern']!r}"
    if isinstance(value, list):
        if "minItems" in schema and len(value) < schema["minItems"]:
            return f"{_name(path)} must have at least {schema['minItems']} items"
        if "maxItems" in schema and len(value) > schema["maxItems"]:
            return f"{_name(path)} must have at most {schema['maxItems']} items"
        items = schema.get("items")
        if isinstance(items, (dict, bool)):
            for i, v in enumerate(value):
                err = validate(v, items, root, f"{path}[{i}]")
                if err:
                    return err
    if isinstance(value, dict):
        return _check_object(value, schema, root, path)
    return None


def _check_range(v: float, schema: dict, path: str) -> str | None:
    lo, hi = schema.get("minimum"), schema.get("maximum")
    xlo, xhi = schema.get("exclusiveMinimum"), schema.get("exclusiveMaximum")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        if lo is not None and hi is not None:
            return f"{_name(path)} must be between {lo} and {hi}, got {_fmt(v)}"
        return f"{_name(path)} must be {'>= ' + str(lo) if lo is not None else '<= ' + str(hi)}, got {_fmt(v)}"
    if xlo is not None and not isinstance(xlo, bool) and v <= xlo:
        return f"{_name(path)} must be > {xlo}, got {_fmt(v)}"
    if xhi is not None and not isinstance(xhi, bool) and v >= xhi:
        return f"{_name(path)} must be < {xhi}, got {_fmt(v)}"
    return None


def _check_object(value: dict, schema: dict, root: dict, path: str) -> str | None:
    props = schema.get("properties", {}) or {}
    for req in schema.get("required", ()):
        if req not in value:
            return f"missing required field '{_join(path, req)}'"
    for k, v in value.items():
        if k in props:
            err = validate(v, props[k], root, _join(path, k))
            if err:
                return err
        else:
            extra = schema.get("additionalProperties", True)
            if extra is False:
                allowed = ", ".join(props) or "none"
                return f"unexpected field '{_join(path, k)}' (allowed: {allowed})"
            if isinstance(extra, dict):
                err = validate(v, extra, root, _join(path, k))
                if err:
                    return err
    return None


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


def _check_branches(value: Any, branches: list, root: dict, path: str, exactly_one: bool) -> str | None:
    errs = [validate(value, b, root, path) for b in branches]
    ok = sum(e is None for e in errs)
    if ok == 1 or (ok > 1 and not exactly_one):
        return None
    if ok > 1:
        return f"{_name(path)} matches more than one allowed form"
    # report the branch whose discriminating constants (const / one-value enum
    # properties) the value matches, if one does: its error is the useful one
    if isinstance(value, dict):
        for b, e in zip(branches, errs):
            try:
                b = resolve_ref(b, root)
            except ValueError:
                continue
            disc = _discriminators(b, root)
            if disc and all(value.get(k) == v for k, v in disc.items()):
                return e
    shown = "; or ".join(errs[:3])
    return f"{_name(path)} matches none of the allowed forms: {shown}"


def _discriminators(branch: dict, root: dict) -> dict:
    out = {}
    for k, p in (branch.get("properties") or {}).items():
        try:
            p = resolve_ref(p, root)
        except ValueError:
            continue
        if isinstance(p, dict):
            if "const" in p:
                out[k] = p["const"]
            elif isinstance(p.get("enum"), list) and len(p["enum"]) == 1:
                out[k] = p["enum"][0]
    return out


__all__ = ["parse_reply", "resolve_ref", "validate"]
