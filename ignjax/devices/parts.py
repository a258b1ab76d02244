"""Part files: each process's finished batches, in the run folder.

A multi-process run (:mod:`ignjax.devices.processes`) hands its results to
process 0 through the run folder: for every batch it finishes, a process
writes ``<root>/<stage>/part_<batch>.npz`` (numpy arrays, no pickle),
atomically (a temporary name, then a rename), so a reader sees a whole part
or none. After a barrier, process 0 reads the parts in batch order and
concatenates them; a stage's parts are deleted once its merged result is
written.

Why files rather than collectives (``jax.experimental.multihost_utils``):
the parts are also the run's checkpoint, so a run whose process died
continues with ``--resume`` from every batch any process finished, with any
number of processes; a part needs no equal shapes across processes and no
program spanning them; and the data never passes through a collective that
a dead peer would leave waiting. What it asks: the run folder is on a file
system every process sees (a shared home or scratch on a cluster), which
the outputs need anyway. ``<root>/manifest.json`` holds the fingerprint of
the run the parts belong to; parts of another run are never reused.
"""

from __future__ import annotations

import io
import json
import shutil
import time
from pathlib import Path

import numpy as np

from ignjax.errors import InputError
from ignjax.fileio import atomic_write, remove_leftover_temporaries

MANIFEST = "manifest.json"

VISIBLE_WAIT_S = 30.0
"""How long process 0 waits for a part another process has reported
written to appear (a network file system's caching)."""


def _flatten(tree, prefix: str = "") -> dict[str, np.ndarray]:
    if isinstance(tree, dict):
        out = {}
        for k, v in tree.items():
            if "/" in str(k):
                raise ValueError(f"part keys may not hold '/': {k!r}")
            out.update(_flatten(v, f"{prefix}{k}/"))
        return out
    return {prefix[:-1]: np.asarray(tree)}


def _unflatten(flat: dict[str, np.ndarray]) -> dict:
    out: dict = {}
    for key, v in flat.items():
        *path, leaf = key.split("/")
        d = out
        for p in path:
            d = d.setdefault(p, {})
        d[leaf] = v
    return out


def _stage_dir(stage: str) -> str:
    return stage.replace("/", "__")


class PartStore:
    """The part files of one run under ``root`` (module docstring)."""

    def __init__(self, root: str | Path):
        self.root = Path(root)

    def path(self, stage: str, index: int) -> Path:
        return self.root / _stage_dir(stage) / f"part_{int(index):05d}.npz"

    def prepare(self, fingerprint: str, resume: bool) -> int:
        """Make the folder ready for a run (process 0, before the others start):
        keep the parts of the same run when ``resume``, else delete them.

        Returns:
            How many parts are kept.
        """
        manifest = self.root / MANIFEST
        same = manifest.is_file() and json.loads(manifest.read_text()).get("fingerprint") == fingerprint
        if not (resume and same) and self.root.exists():
            shutil.rmtree(self.root)
        if self.root.exists():
            remove_leftover_temporaries(self.root)  # a part being written when its process died
        atomic_write(manifest, json.dumps({"fingerprint": fingerprint}) + "\n")
        return sum(1 for _ in self.root.glob("*/part_*.npz"))

    def has(self, stage: str, index: int) -> bool:
        return self.path(stage, index).is_file()

    def write(self, stage: str, index: int, tree: dict) -> Path:
        """Write one batch's results (a dict of arrays, nested dicts allowed)."""
        buf = io.BytesIO()
        np.savez(buf, **_flatten(tree))
        return atomic_write(self.path(stage, index), buf.getvalue())

    def read(self, stage: str, index: int, wait_s: float = VISIBLE_WAIT_S) -> dict:
        """One part, waiting up to ``wait_s`` for it to appear.

        Raises:
            InputError: the part is not there (naming it and why that happens).
        """
        p = self.path(stage, index)
        deadline = time.monotonic() + wait_s
        while not p.is_file():
            if time.monotonic() >= deadline:
                raise InputError(str(p), stage, f"part {index} is missing although its process reported it written: "
                                                "the run folder must be on a file system every process sees")
            time.sleep(0.2)
        with np.load(p, allow_pickle=False) as z:
            return _unflatten({k: z[k] for k in z.files})

    def gather(self, stage: str, n: int, axes: dict[str, int] | None = None) -> dict:
        """The ``n`` parts of ``stage`` concatenated in batch order (along axis 0,
        or ``axes[top-level key]``)."""
        parts = [self.read(stage, i) for i in range(n)]

        def cat(key, xs):
            if isinstance(xs[0], dict):
                return {k: cat(key, [x[k] for x in xs]) for k in xs[0]}
            return np.concatenate(xs, axis=(axes or {}).get(key, 0))

        return {k: cat(k, [p[k] for p in parts]) for k in parts[0]}

    def remove(self, stage: str | None = None) -> None:
        """Delete one stage's parts (or, with None, the whole folder)."""
        shutil.rmtree(self.root if stage is None else self.root / _stage_dir(stage), ignore_errors=True)


__all__ = ["MANIFEST", "PartStore", "VISIBLE_WAIT_S"]
