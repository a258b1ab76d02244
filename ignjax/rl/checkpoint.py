"""The trainer's checkpoints: ``<run>/checkpoints/<update>/`` (orbax) and their record.

A checkpoint holds the whole training state between two calls of the
compiled program (:class:`ignjax.rl.ppo.Shared`: the weights, Adam's state,
the update counter and the key; :class:`ignjax.rl.ppo.Rows`: every
environment's episode, observation, mask, memory and key), as numpy arrays
flattened in pytree order, so ``--resume`` continues with the same bytes as
a run that never stopped. Beside it, ``<update>/policy.msgpack`` holds the
weights alone (flax's serialisation: the same seed gives the same bytes),
``<update>/policy.npz`` the same weights as plain named arrays
(:mod:`ignjax.agents.learned.weights`: what the ``learned`` agent reads,
without flax) and ``<update>.json`` the record a reader checks before any
episode (:mod:`ignjax.agents.learned.record`, re-exported here): the
package version, the observation layout (slice names and sizes), the action
names, the network's settings, the run's fingerprint and the SHA-256 of
``policy.npz``. A checkpoint counts once its record exists (it is written
after orbax has committed the folder), so a run killed mid-save resumes
from the one before.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import jax
import numpy as np
import orbax.checkpoint as ocp

from ignjax.agents.learned.record import (
    CHECKED, FORMAT, check_record, folder, latest, read_record, record, record_path,
)
from ignjax.agents.learned.weights import WEIGHTS_FILE, from_flax, npz_bytes
from ignjax.errors import InputError
from ignjax.errors.extras import optional_module
from ignjax.fileio import atomic_write

serialization = optional_module("flax.serialization", "rl")


def save(run: Path, state, meta: dict) -> Path:
    """Write ``state`` (any pytree) and its record; returns the checkpoint's folder."""
    path = folder(run) / f"{meta['update']:08d}"
    if path.exists():
        shutil.rmtree(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    leaves = [np.asarray(x) for x in jax.device_get(jax.tree.leaves(state))]
    with ocp.PyTreeCheckpointer() as ck:
        ck.save(path.resolve(), {f"{i:05d}": x for i, x in enumerate(leaves)})
    params = jax.device_get(state[0].params)
    atomic_write(path / "policy.msgpack", serialization.to_bytes(params))
    weights = npz_bytes(from_flax(params))
    atomic_write(path / WEIGHTS_FILE, weights)
    meta = {**meta, "weights_sha256": hashlib.sha256(weights).hexdigest()}
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


__all__ = ["CHECKED", "FORMAT", "check_record", "folder", "latest", "load", "load_policy", "read_record", "record",
           "record_path", "save"]
