"""Typed TOML configuration: frozen dataclass sections checked value by value,
layered from defaults, a TOML file and ``--set section.key=value`` items, with
every error naming ``file:line`` or the ``--set`` item and the key.

The sweep's configuration (:mod:`ignjax.config`) and the trainer's
(:mod:`ignjax.rl.trainconfig`) are built on these functions:

* :func:`check_value` / :func:`check_fields` - a value checked against its field's default type.
* :func:`line_of` / :func:`load_toml` - where a key sits in a file; reading one with its line in errors.
* :func:`resolve_sections` - defaults <- file <- ``--set`` for a mapping of plain sections.
* :func:`toml_value` / :func:`sections_toml` - a configuration written back as commented TOML.
"""

from __future__ import annotations

import dataclasses
import math
import os
import textwrap
import tomllib
from pathlib import Path
from typing import Any, Callable, Mapping

from ignjax.arrays import field_docs, parse_assignment
from ignjax.errors import ConfigError


def check_value(key: str, value: Any, default: Any, where: str | None) -> Any:
    """``value`` checked against the type of ``default`` (the field's default)
    and normalised: ints given for floats become floats, lists become tuples."""
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise ConfigError(where, key, f"expected true or false, got {value!r}")
        return value
    if isinstance(default, int):
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(where, key, f"expected an integer, got {value!r}")
        return value
    if isinstance(default, float):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ConfigError(where, key, f"expected a finite number, got {value!r}")
        return float(value)
    if isinstance(default, str):
        if not isinstance(value, str):
            raise ConfigError(where, key, f"expected a string, got {value!r}")
        return value
    if isinstance(default, tuple):
        return _check_tuple(key, value, default, where)
    return value


def _check_tuple(key: str, value: Any, default: tuple, where: str | None) -> tuple:
    if not isinstance(value, (list, tuple)):
        raise ConfigError(where, key, f"expected a list, got {value!r}")
    if default and all(isinstance(v, int) and not isinstance(v, bool) for v in default):
        if any(isinstance(v, bool) or not isinstance(v, int) for v in value):
            raise ConfigError(where, key, f"expected integers, got {list(value)!r}")
        return tuple(value)
    if default and isinstance(default[0], (int, float)) and not isinstance(default[0], bool):
        for v in value:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ConfigError(where, key, f"expected finite numbers, got {list(value)!r}")
        return tuple(float(v) for v in value)
    if default and isinstance(default[0], str) and not all(isinstance(v, str) for v in value):
        raise ConfigError(where, key, f"expected strings, got {list(value)!r}")
    return tuple(value)


def check_fields(obj, section: str) -> None:
    """Type-check and normalise every field of a (frozen) section in place."""
    for f in dataclasses.fields(obj):
        value = check_value(f"{section}.{f.name}", getattr(obj, f.name), f.default, None)
        object.__setattr__(obj, f.name, value)


def line_of(text: str, section: str, key: str | None = None) -> int | None:
    """Line (1-based) of ``[section]``, or of ``key = ...`` inside it."""
    inside = False
    for i, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if s.startswith("["):
            inside = s.split("#", 1)[0].strip() == f"[{section}]"
            if inside and key is None:
                return i
        elif inside and key is not None and s.split("=", 1)[0].strip().strip('"\'') == key:
            return i
    return None


def load_toml(path: str | os.PathLike) -> tuple[dict, str]:
    """Read a TOML file. Returns (mapping, text); errors name the file and line."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(str(p), "--config", "file not found")
    text = p.read_text(encoding="utf-8")
    try:
        return tomllib.loads(text), text
    except tomllib.TOMLDecodeError as e:
        line = getattr(e, "lineno", None)
        raise ConfigError(f"{p}:{line}" if line else str(p), "toml", f"malformed TOML: {e}") from None


def _defaults(cls: type) -> dict[str, Any]:
    d = cls()
    return {f.name: getattr(d, f.name) for f in dataclasses.fields(d)}


def _check_names(schema: Mapping[str, type], section: str, items: Any, where: str, text: str | None) -> None:
    if section not in schema:
        line = line_of(text, section) if text else None
        raise ConfigError(f"{where}:{line}" if line else where, section, f"unknown section; known: {', '.join(schema)}")
    if not isinstance(items, dict):
        raise ConfigError(where, section, "must be a table of settings")
    known = _defaults(schema[section])
    for key in items:
        if key not in known:
            line = line_of(text, section, key) if text else None
            raise ConfigError(f"{where}:{line}" if line else where, f"{section}.{key}",
                              f"unknown key; known: {', '.join(known)}")


def resolve_sections(schema: Mapping[str, type], build: Callable[[dict[str, dict[str, Any]]], Any],
                     config_file: str | os.PathLike | None = None, sets=()) -> Any:
    """Defaults <- a TOML file <- ``--set section.key=value`` items (later wins), for plain sections.

    Args:
        schema: TOML table name -> frozen dataclass section (every field with a default).
        build: makes the configuration from ``table -> key -> value`` (the sections check their meaning).
        config_file: a TOML file, or None.
        sets: ``--set`` items.

    Raises:
        ConfigError: naming ``file:line`` or ``--set`` and the key, for an unknown name, a value of the wrong
            type or one its section rejects.
    """
    values: dict[str, dict[str, Any]] = {name: {} for name in schema}
    origin: dict[str, str] = {}

    def apply(overrides: dict, where: str, text: str | None = None) -> None:
        for section, items in overrides.items():
            _check_names(schema, section, items, where, text)
            for key, value in items.items():
                line = line_of(text, section, key) if text else None
                loc = f"{where}:{line}" if line else where
                values[section][key] = check_value(f"{section}.{key}", value, _defaults(schema[section])[key], loc)
                origin[f"{section}.{key}"] = loc

    if config_file:
        data, text = load_toml(config_file)
        apply(data, str(config_file), text)
    for item in sets:
        name, value = parse_assignment(item, "--set")
        section, key = name.rsplit(".", 1)
        if section not in schema:
            raise ConfigError(None, "--set", f"unknown section {section!r}; known: {', '.join(schema)}")
        apply({section: {key: value}}, "--set")
    try:
        return build(values)
    except ConfigError as e:
        loc = origin.get((e.where or "").split("[", 1)[0])
        if loc and not e.path:
            raise ConfigError(loc, e.where, e.reason) from None
        raise


def toml_value(v: Any) -> str:
    """``v`` written as a TOML value."""
    import json

    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float) and not math.isfinite(v):
        return ("inf" if v > 0 else "-inf") if v == v else "nan"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    return "[" + ", ".join(toml_value(x) for x in v) + "]"


def sections_toml(sections: Mapping[str, Any], out: list[str]) -> list[str]:
    """``out`` extended by each ``[table]`` of ``sections`` (name -> section object), every key under its description."""
    for name, section in sections.items():
        docs = field_docs(type(section))
        if out:
            out.append("")
        out.append(f"[{name}]")
        for f in dataclasses.fields(section):
            out += textwrap.wrap(docs.get(f.name, "").replace("``", "`"), 110, initial_indent="# ", subsequent_indent="# ")
            value = getattr(section, f.name)
            # TOML has no null: a setting that is unset by default is shown commented out
            out.append(f"# {f.name} = (unset)" if value is None else f"{f.name} = {toml_value(value)}")
    return out


__all__ = ["check_fields", "check_value", "line_of", "load_toml", "resolve_sections", "sections_toml", "toml_value"]
