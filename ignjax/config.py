"""Configuration of ``python -m ignjax.sweep``: defaults, TOML files, ``--set`` overrides.

A configuration is a two-level mapping ``section -> key -> value``. The
defaults below are the whole schema: a TOML file or a ``--set`` that names
a section or key not in it is an error (with the file and line for TOML).
``--quick`` replaces a few sizes by :data:`QUICK` (CI and smoke runs).
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import os
import tomllib
from pathlib import Path
from typing import Any

from ignjax.errors import ConfigError

STUDIES: tuple[str, ...] = ("eval", "costs", "difficulty", "derive-costs", "analysis")

DEFAULTS: dict[str, dict[str, Any]] = {
    "run": {
        "name": "default",  # folder under run.out
        "out": "runs",
        "seed": 0,  # PRNG seed of every rollout (per-episode keys fold in the episode index)
    },
    "benchmark": {
        "episodes": "",  # an episode file; empty: the shipped benchmark, or one built from `scenes`
        "scenes": "",  # scene folder/files to build from; empty: the shipped scenes/ folder
        "subset": 500,
        "seed": 0,
        "limit": 0,  # > 0: use only the first N episodes (quick runs)
    },
    "eval": {
        "agents": ["random", "explorer", "naive_asker", "eig", "shortest_path"],
        "batch": 256,
        "parts": 0,  # concurrent pieces of each batch (0: ignjax.sim.rollout.batch_parts, 2 on CPU)
        "thresholds": [0.5, 1.5, 3.0],
        "costs": [0.182, 0.162, 0.240, 0.103],
        "require_stop": True,
    },
    "costs": {
        "samples": 100_000,  # offline cost vectors (simplex sample, sum = locked sum; rows 0/1 locked/uniform)
        "seed": 0,
        "agent": "eig",  # the cost-aware agent re-run in the loop
        "scales": [0.25, 0.5, 1.0, 2.0, 4.0, 8.0],  # in-the-loop: locked costs times each scale
        "per_type_factor": 4.0,  # in-the-loop: also each type alone times this factor (0: skip)
        "normalize": False,
    },
    "difficulty": {
        "alpha": [0.35, 0.25, 0.15, 0.25],  # the reference coefficients (distractor, room, context, start)
        "thresholds": [0.30, 0.60],  # the reference bin thresholds
        "normalize": False,  # rescale an alpha that does not sum to 1 instead of rejecting it
        "alpha_step": 0.05,
        "threshold_step": 0.05,
        "split_seed": 0,
        "empty": "unordered",
    },
    "derive-costs": {
        "annotations": "",  # cue-annotation JSONL; empty: the paper's published statistics
        "assumption": "proxy",
        "lambdas": [0.3333333333333333, 0.3333333333333333, 0.3333333333333333],
        "fit": True,
    },
    "analysis": {
        "agent": "eig",
        "horizon": 5,  # matched horizon of Delta-U, planner steps
        "radius": 1.0,  # explored-area radius around the path, m
        "trajectories": 4,  # top-down trajectory plots
    },
}

QUICK: dict[str, dict[str, Any]] = {
    "benchmark": {"limit": 60},
    "eval": {"batch": 64},
    "costs": {"samples": 20_000, "scales": [0.25, 1.0, 4.0]},
    "difficulty": {"alpha_step": 0.1, "threshold_step": 0.1},
    "analysis": {"trajectories": 2},
}


def _line_of(text: str, key: str) -> int | None:
    for i, line in enumerate(text.splitlines(), 1):
        if line.strip().startswith(key):
            return i
    return None


def _check_value(section: str, key: str, value: Any, where: str) -> Any:
    default = DEFAULTS[section][key]
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise ConfigError(where, f"{section}.{key}", f"expected true or false, got {value!r}")
        return value
    if isinstance(default, int):
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(where, f"{section}.{key}", f"expected an integer, got {value!r}")
        return value
    if isinstance(default, float):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ConfigError(where, f"{section}.{key}", f"expected a finite number, got {value!r}")
        return float(value)
    if isinstance(default, str):
        if not isinstance(value, str):
            raise ConfigError(where, f"{section}.{key}", f"expected a string, got {value!r}")
        return value
    if isinstance(default, list):
        if not isinstance(value, list):
            raise ConfigError(where, f"{section}.{key}", f"expected a list, got {value!r}")
        if default and isinstance(default[0], (int, float)) and not isinstance(default[0], bool):
            for v in value:
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise ConfigError(where, f"{section}.{key}", f"expected finite numbers, got {value!r}")
            return [float(v) for v in value]
        if default and isinstance(default[0], str) and not all(isinstance(v, str) for v in value):
            raise ConfigError(where, f"{section}.{key}", f"expected strings, got {value!r}")
        return list(value)
    return value


def merge(config: dict, overrides: dict, where: str, text: str | None = None) -> dict:
    """Apply a ``section -> key -> value`` mapping, checking names and types."""
    out = copy.deepcopy(config)
    for section, items in overrides.items():
        if section not in DEFAULTS:
            line = _line_of(text, f"[{section}]") if text else None
            loc = f"{where}:{line}" if line else where
            raise ConfigError(loc, section, f"unknown section; known: {', '.join(DEFAULTS)}")
        if not isinstance(items, dict):
            raise ConfigError(where, section, "must be a table of settings")
        for key, value in items.items():
            if key not in DEFAULTS[section]:
                line = _line_of(text, key) if text else None
                loc = f"{where}:{line}" if line else where
                raise ConfigError(loc, f"{section}.{key}", f"unknown key; known: {', '.join(DEFAULTS[section])}")
            out[section][key] = _check_value(section, key, value, where)
    return out


def load_toml(path: str | os.PathLike) -> tuple[dict, str]:
    """Read a sweep TOML file. Returns (mapping, text); errors name the file and line."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(str(p), "--config", "file not found")
    text = p.read_text(encoding="utf-8")
    try:
        return tomllib.loads(text), text
    except tomllib.TOMLDecodeError as e:
        line = getattr(e, "lineno", None)
        raise ConfigError(f"{p}:{line}" if line else str(p), "toml", f"malformed TOML: {e}") from None


def parse_set(item: str) -> dict:
    """``section.key=value`` (value in TOML syntax; a bare word is a string)."""
    if "=" not in item or "." not in item.split("=", 1)[0]:
        raise ConfigError(None, "--set", f"expected section.key=value, got {item!r}")
    name, raw = item.split("=", 1)
    section, key = name.strip().rsplit(".", 1)
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    if section not in DEFAULTS:
        raise ConfigError(None, "--set", f"unknown section {section!r}; known: {', '.join(DEFAULTS)}")
    if key not in DEFAULTS[section]:
        raise ConfigError(None, "--set", f"unknown key {section}.{key}; known: {', '.join(DEFAULTS[section])}")
    return {section: {key: value}}


def resolve(config_file: str | None = None, sets: list[str] = (), quick: bool = False) -> dict:
    """Defaults <- quick sizes <- TOML file <- ``--set`` items (later wins)."""
    cfg = copy.deepcopy(DEFAULTS)
    if quick:
        cfg = merge(cfg, QUICK, "quick")
    if config_file:
        data, text = load_toml(config_file)
        cfg = merge(cfg, data, str(config_file), text)
    for item in sets:
        cfg = merge(cfg, parse_set(item), "--set")
    validate(cfg)
    return cfg


def validate(cfg: dict) -> None:
    """Semantic checks that must fail before any work starts."""
    from ignjax.agents.base import registry

    known = registry()
    for name in cfg["eval"]["agents"] + [cfg["costs"]["agent"], cfg["analysis"]["agent"]]:
        if name not in known:
            raise ConfigError(None, "agent", f"unknown agent {name!r}; known: {', '.join(known)}")
    if not cfg["eval"]["agents"]:
        raise ConfigError(None, "eval.agents", "must name at least one agent")
    costs = cfg["eval"]["costs"]
    from ignjax.studies.cost_sensitivity import validate_costs

    if len(costs) != 4:
        raise ConfigError(None, "eval.costs", f"expected 4 costs (one per question type), got {costs}")
    validate_costs(costs, "eval.costs")
    if cfg["costs"]["agent"] not in ("eig",) and not known[cfg["costs"]["agent"]].asks:
        raise ConfigError(None, "costs.agent", f"{cfg['costs']['agent']!r} never asks: nothing to sweep")
    if any(s <= 0 for s in cfg["costs"]["scales"]) or not cfg["costs"]["scales"]:
        raise ConfigError(None, "costs.scales", f"scales must be positive, got {cfg['costs']['scales']}")
    if cfg["costs"]["samples"] < 2:
        raise ConfigError(None, "costs.samples", "must be >= 2")
    for key in ("alpha_step", "threshold_step"):
        v = cfg["difficulty"][key]
        if not 0 < v <= 0.5:
            raise ConfigError(None, f"difficulty.{key}", f"must be in (0, 0.5], got {v}")
    from ignjax.episodes.difficulty import validate_alpha, validate_thresholds

    cfg["difficulty"]["alpha"] = list(validate_alpha(cfg["difficulty"]["alpha"], normalize=cfg["difficulty"]["normalize"],
                                                     where="difficulty.alpha"))
    cfg["difficulty"]["thresholds"] = list(validate_thresholds(cfg["difficulty"]["thresholds"], "difficulty.thresholds"))
    if cfg["difficulty"]["empty"] not in ("unordered", "skip"):
        raise ConfigError(None, "difficulty.empty", "must be 'unordered' or 'skip'")
    if cfg["eval"]["batch"] < 1:
        raise ConfigError(None, "eval.batch", "must be >= 1")
    if cfg["eval"]["parts"] < 0:
        raise ConfigError(None, "eval.parts", f"must be >= 0 (0: the default split), got {cfg['eval']['parts']}")
    if sorted(cfg["eval"]["thresholds"]) != cfg["eval"]["thresholds"] or any(t <= 0 for t in cfg["eval"]["thresholds"]):
        raise ConfigError(None, "eval.thresholds", "must be positive and increasing")
    lam = cfg["derive-costs"]["lambdas"]
    if len(lam) != 3 or any(v < 0 for v in lam):
        raise ConfigError(None, "derive-costs.lambdas", f"expected 3 non-negative weights, got {lam}")


def fingerprint(cfg: dict, studies: list[str]) -> str:
    """Hash of what determines a run's outputs (config + studies)."""
    blob = json.dumps({"config": cfg, "studies": studies}, sort_keys=True).encode()
    return hashlib.sha256(blob).hexdigest()[:16]


__all__ = ["DEFAULTS", "QUICK", "STUDIES", "fingerprint", "load_toml", "merge", "parse_set", "resolve", "validate"]
