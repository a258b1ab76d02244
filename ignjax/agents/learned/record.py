"""The record of a trained policy: what a reader checks before any episode.

The trainer (``python -m ignjax.rl.train``) writes ``<run>/checkpoints/<update>/``
and beside it ``<update>.json``, this record: the package version, the
observation layout (slice names and sizes, :func:`ignjax.agents.learned.obs.obs_layout`),
the action names, the network's settings and the run's fingerprint. An
exported policy (``python -m ignjax.rl.export``; the shipped one under
``ignjax/data/policy/``) keeps the same record inside its folder as
``record.json``. :func:`check_record` refuses a record whose layout, action
set, network or version differs from the reader's, naming the file, the
entry and what differs; the trainer's ``--resume`` and the ``learned`` agent
both call it.

The record's own functions live here, with the agents, so that evaluating a
policy needs neither the trainer nor flax; :mod:`ignjax.rl.checkpoint`
(orbax, the training state) re-exports them.
"""

from __future__ import annotations

import json
from pathlib import Path

from ignjax import __version__
from ignjax.agents.learned.actions import action_names
from ignjax.agents.learned.obs import obs_layout
from ignjax.errors import InputError
from ignjax.sim import types as T

FORMAT = 1
"""Version of the checkpoint record's layout."""
CHECKED = ("format", "ignjax_version", "obs_layout", "actions", "policy")
"""The record's entries that must equal the reader's, each named in the error when it differs."""
EXPORTED_RECORD = "record.json"
"""The record's name inside an exported policy folder (a trainer checkpoint keeps it beside its folder)."""

_WHAT = {"format": "checkpoint format", "ignjax_version": "ignjax version", "obs_layout": "observation layout",
         "actions": "action set", "policy": "network"}


def record(config: T.SimConfig, policy: dict, fingerprint: str, update: int) -> dict:
    """The record of a checkpoint taken after ``update`` updates."""
    return {"format": FORMAT, "ignjax_version": __version__,
            "obs_layout": [[s.name, s.size] for s in obs_layout(config)], "actions": list(action_names(config)),
            "policy": dict(policy), "fingerprint": fingerprint, "update": int(update)}


def check_record(found: dict, expected: dict, path) -> None:
    """Refuse a checkpoint whose record differs from ``expected`` in any of :data:`CHECKED`.

    Raises:
        InputError: naming the checkpoint and what differs (first the observation layout, the action set,
            the package version).
    """
    for key in CHECKED:
        a, b = found.get(key), expected[key]
        if a != b:
            raise InputError(str(path), key, f"the checkpoint was written with another {_WHAT[key]}: "
                                             f"{_diff(key, a, b)}")


def _diff(key: str, found, expected) -> str:
    if key in ("obs_layout", "actions") and isinstance(found, list):
        for i, (x, y) in enumerate(zip(found, expected)):
            if x != y:
                return f"entry {i} is {x!r} there, {y!r} here"
        return f"{len(found)} entries there, {len(expected)} here"
    return f"{found!r} there, {expected!r} here"


def folder(run: Path) -> Path:
    """The checkpoints' folder of a run folder."""
    return Path(run) / "checkpoints"


def latest(run: Path) -> Path | None:
    """The newest complete checkpoint of a run folder (one with its record), or None."""
    done = sorted(p.with_suffix("") for p in folder(run).glob("*.json") if p.with_suffix("").is_dir())
    return done[-1] if done else None


def record_path(path: Path) -> Path:
    """Where the record of the checkpoint or exported policy folder ``path`` is (it may not exist)."""
    path = Path(path)
    inside = path / EXPORTED_RECORD
    return inside if inside.is_file() else path.with_suffix(".json")


def read_record(path: Path) -> dict:
    """The record of the checkpoint (or exported policy) folder ``path``.

    Raises:
        InputError: no record, or one that is not a JSON object.
    """
    meta = record_path(path)
    if not meta.is_file():
        raise InputError(str(path), "checkpoint", "not a trainer checkpoint (no record beside it)")
    try:
        data = json.loads(meta.read_text())
    except (ValueError, UnicodeDecodeError) as e:
        raise InputError(str(meta), "record", f"not a JSON record: {e}") from None
    if not isinstance(data, dict):
        raise InputError(str(meta), "record", "not a JSON object")
    return data


__all__ = ["CHECKED", "EXPORTED_RECORD", "FORMAT", "check_record", "folder", "latest", "read_record", "record",
           "record_path"]
