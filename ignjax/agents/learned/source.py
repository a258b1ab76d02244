"""Where a learned policy comes from: the checkpoint a setting names, loaded and checked before any episode.

``agents.learned.checkpoint`` names one of

* a trainer checkpoint folder, ``<run>/checkpoints/<update>/`` (its record
  ``<update>.json`` beside it, :mod:`ignjax.agents.learned.record`);
* a training run folder: its newest complete checkpoint;
* an exported policy folder (``python -m ignjax.rl.export``): ``policy.npz``
  and ``record.json`` inside;
* nothing (the empty string, the default): the policy shipped as package
  data, :data:`SHIPPED` (``ignjax/data/policy/``).

:func:`load` reads the folder's record and weights (:data:`~ignjax.agents.learned.weights.WEIGHTS_FILE`)
with numpy alone and checks them, in this order: the weights' bytes against
the digest the record holds (``weights_sha256``, where it holds one), the
arrays' names and shapes (:func:`~ignjax.agents.learned.weights.shape_of`),
the network the record describes against the weights, then the record
against this package and simulator configuration
(:func:`~ignjax.agents.learned.record.check_record`: observation layout,
action set, version). Every refusal is one :class:`~ignjax.errors.InputError`
naming the file, the entry and what differs; the command lines print it on
one line and exit with status 2. A loaded checkpoint is cached by its
files' paths, sizes and modification times.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Mapping

import numpy as np

from ignjax.agents.learned.actions import n_actions
from ignjax.agents.learned.obs import obs_size
from ignjax.agents.learned.record import (
    EXPORTED_RECORD, check_record, folder, latest, read_record, record, record_path,
)
from ignjax.agents.learned.weights import WEIGHTS_FILE, NetShape, read_npz, shape_of
from ignjax.errors import InputError
from ignjax.fileio import file_sha256
from ignjax.sim import types as T

SHIPPED = Path(__file__).resolve().parents[2] / "data" / "policy"
"""The policy shipped as package data (an exported policy folder): the default of ``agents.learned.checkpoint``."""
SETTING = "agents.learned.checkpoint"
"""The setting that names the checkpoint (errors name it)."""
KINDS = ("a trainer checkpoint folder (RUN/checkpoints/<update>), a training run folder (its newest checkpoint) or "
         "an exported policy folder (policy.npz and record.json)")


@dataclass(frozen=True, eq=False)
class Loaded:
    """A checked policy.

    Attributes:
        folder: the checkpoint or exported policy folder (absolute).
        weights: ``name -> float32 array`` (read-only numpy).
        record: the checkpoint's record.
        sha256: SHA-256 of the weights file's bytes.
        shape: the network's shape, read from the weights.
    """

    folder: Path
    weights: Mapping[str, np.ndarray]
    record: dict
    sha256: str
    shape: NetShape

    def describe(self) -> dict:
        """What a run records of the policy: where it is and its weights' digest (never the weights)."""
        return {"checkpoint": str(self.folder), "weights_sha256": self.sha256, "network": self.shape.settings(),
                "update": self.record.get("update"), "training_fingerprint": self.record.get("fingerprint")}


def locate(value: str, where: str = SETTING) -> Path:
    """The checkpoint folder a setting names (module docstring); the shipped policy for ``""``.

    Raises:
        InputError: one line naming the path: it does not exist, is a file, is a run folder with no complete
            checkpoint, or is none of the folders above.
    """
    if not value:
        return SHIPPED
    p = Path(value).expanduser().absolute()
    if p.is_file() and p.name == WEIGHTS_FILE:
        p = p.parent
    if not p.exists():
        raise InputError(str(p), where, f"no such folder; give {KINDS}")
    if not p.is_dir():
        raise InputError(str(p), where, f"a file, not a policy; give {KINDS}")
    if (p / EXPORTED_RECORD).is_file() or p.with_suffix(".json").is_file():
        return p
    if folder(p).is_dir():
        last = latest(p)
        if last is None:
            raise InputError(str(p), where, "a training run folder without a complete checkpoint yet (none has its "
                                            "record)")
        return last
    raise InputError(str(p), where, f"not a policy (no checkpoint record in or beside it); give {KINDS}")


def _stamp(path: Path) -> tuple:
    st = path.stat()
    return (str(path), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=8)
def _read(path: str, npz: tuple, meta: tuple) -> tuple[dict, dict, str]:
    """(weights, record, sha256) of the folder ``path`` (keyed by its files' :func:`_stamp`, so a rewritten file
    is read again)."""
    weights = read_npz(Path(npz[0]))
    for a in weights.values():
        a.setflags(write=False)
    return weights, read_record(Path(path)), file_sha256(npz[0])


def _weights_file(path: Path) -> Path:
    npz = path / WEIGHTS_FILE
    if not npz.is_file():
        if (path / "policy.msgpack").is_file():
            raise InputError(str(npz), None, "missing: the checkpoint was written before the trainer exported its "
                                             f"weights; write it with `python -m ignjax.rl.export {path}` (needs "
                                             "the rl extra)")
        raise InputError(str(npz), None, f"missing: {path} holds no policy weights")
    return npz


def load(path: Path, config: T.SimConfig = T.SimConfig()) -> Loaded:
    """The checked policy of the checkpoint or exported policy folder ``path`` (:func:`locate`'s result).

    Raises:
        InputError: the first check that fails (module docstring).
    """
    path = Path(path)
    meta = record_path(path)
    if not meta.is_file():
        raise InputError(str(path), "checkpoint", "not a trainer checkpoint (no record beside it)")
    npz = _weights_file(path)
    weights, found, sha = _read(str(path), _stamp(npz), _stamp(meta))
    if found.get("weights_sha256", sha) != sha:
        raise InputError(str(npz), "weights_sha256", f"its bytes differ from the digest in {meta.name} (truncated, "
                                                     "edited or from another checkpoint)")
    shape = shape_of(weights, npz)
    if found.get("policy") != shape.settings():
        raise InputError(str(meta), "policy", f"the record describes the network {found.get('policy')!r} but "
                                              f"{npz.name} holds {shape.settings()!r}")
    check_record(found, record(config, shape.settings(), "", 0), path)
    for name, got, want, what in (("encoder_0/kernel", shape.obs_dim, obs_size(config), "observation entries"),
                                  ("logits/kernel", shape.n_actions, n_actions(config), "actions")):
        if got != want:
            raise InputError(str(npz), name, f"the network reads {got} {what}, this configuration has {want}")
    return Loaded(path.absolute(), MappingProxyType(weights), found, sha, shape)


__all__ = ["KINDS", "Loaded", "SETTING", "SHIPPED", "load", "locate"]
