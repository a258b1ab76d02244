"""The trainer's checkpoints: ``<run>/checkpoints/<update>/`` (orbax) and their record.

A checkpoint holds the whole training state between two calls of the
compiled program (:class:`ignjax.rl.ppo.Shared`: the weights, Adam's state,
the update counter and the key; :class:`ignjax.rl.ppo.Rows`: every
environment's episode, observation, mask, memory and key), as numpy arrays
flattened in pytree order, so ``--resume`` continues with the same bytes as
a run that never stopped. Beside it, ``<update>/policy.msgpack`` holds the
weights alone (flax's serialisation: the same seed gives the same bytes) and
``<update>.json`` the record a reader checks before any episode: the
package version, the observation layout (slice names and sizes), the action
names, the network's settings and the run's fingerprint. A checkpoint
counts once its record exists (it is written after orbax has committed the
folder), so a run killed mid-save resumes from the one before.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import jax
import numpy as np
import orbax.checkpoint as ocp

from ignjax import __version__
from ignjax.errors import InputError
from ignjax.errors.extras import optional_module
from ignjax.fileio import atomic_write
from ignjax.rl.actions import action_names
from ignjax.rl.obs import obs_layout
from ignjax.sim import types as T

serialization = optional_module("flax.serialization", "rl")

FORMAT = 1
"""Version of the checkpoint record's layout."""
CHECKED = ("format", "ignjax_version", "obs_layout", "actions", "policy")
"""The record's entries that must equal the reader's, each named in the error when it differs."""


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


_WHAT = {"format": "checkpoint format", "ignjax_version": "ignjax version", "obs_layout": "observation layout",
         "actions": "action set", "policy": "network"}


def _diff(key: str, found, expected) -> str:
    if key in ("obs_layout", "actions") and isinstance(found, list):
        for i, (x, y) in enumerate(zip(found, expected)):
            if x != y:
                return f"entry {i} is {x!r} there, {y!r} here"
        return f"{len(found)} entries there, {len(expected)} here"
    return f"{found!r} there, {expected!r} here"


def folder(run: Path) -> Path:
    return Path(run) / "checkpoints"


def latest(run: Path) -> Path | None:
    """The newest complete checkpoint of a run folder (one with its record), or None."""
    done = sorted(p.with_suffix("") for p in folder(run).glob("*.json") if p.with_suffix("").is_dir())
    return done[-1] if done else None


def read_record(path: Path) -> dict:
    """The record of the checkpoint folder ``path``."""
    meta = Path(path).with_suffix(".json")
    if not meta.is_file():
        raise InputError(str(path), "checkpoint", "not a trainer checkpoint (no record beside it)")
    return json.loads(meta.read_text())


def save(run: Path, state, meta: dict) -> Path:
    """Write ``state`` (any pytree) and its record; returns the checkpoint's folder."""
    path = folder(run) / f"{meta['update']:08d}"
    if path.exists():
        shutil.rmtree(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    leaves = [np.asarray(x) for x in jax.device_get(jax.tree.leaves(state))]
    with ocp.PyTreeCheckpointer() as ck:
        ck.save(path.resolve(), {f"{i:05d}": x for i, x in enumerate(leaves)})
    params = state[0].params
    atomic_write(path / "policy.msgpack", serialization.to_bytes(jax.device_get(params)))
    atomic_write(path.with_suffix(".json"), json.dumps(meta, indent=2, sort_keys=True) + "\n")
    return path


def load(path: Path, like):
    """The state saved in ``path``, laid out as the pytree ``like`` (its leaves' shapes are checked)."""
    with ocp.PyTreeCheckpointer() as ck:
        tree = ck.restore(Path(path).resolve())
    leaves, treedef = jax.tree.flatten(like)
    got = [np.asarray(tree[f"{i:05d}"]) for i in range(len(tree))]
    if len(got) != len(leaves) or any(g.shape != tuple(x.shape) for g, x in zip(got, leaves)):
        raise InputError(str(path), "checkpoint", "its arrays do not match this configuration's training state")
    return jax.tree.unflatten(treedef, [g.astype(x.dtype) for g, x in zip(got, leaves)])


def load_policy(path: Path, like):
    """The weights alone (``policy.msgpack``), laid out as ``like``."""
    return serialization.from_bytes(like, (Path(path) / "policy.msgpack").read_bytes())


__all__ = ["CHECKED", "FORMAT", "check_record", "latest", "load", "load_policy", "read_record", "record", "save"]
