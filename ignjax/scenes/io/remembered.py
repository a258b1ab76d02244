"""Scene files read once: a scene imported from a source file is kept in the
on-disk cache (:func:`ignjax.cache.derived_store`) as its lossless JSON, so
the next process reads it back instead of importing the file again (about
0.2 s per shipped USD house, 2.7 s for the shipped benchmark).

An entry is keyed by the file's path and bytes, the reader, and the source
of :mod:`ignjax.scenes` (with the library versions, and USD's), and it lists
the other files the scene was composed from (USD sublayers, references,
payloads) with a digest of each: it is used only while all of them are
unchanged. A read that warned (missing references, skipped prims, ...) is
not kept, so every such warning is given again on every read; the stored
JSON must read back to the same JSON, or it is not kept either.
"""

from __future__ import annotations

import hashlib
import json
import threading
import warnings
from pathlib import Path
from typing import Callable

import numpy as np

from ignjax.cache import code_digest, derived_store, digest
from ignjax.scenes.model import Scene
from ignjax.scenes.model.scenejson import scene_from_dict, scene_to_json


_RECORDING = threading.Lock()
"""Held while a read's warnings are recorded: :func:`warnings.catch_warnings`
swaps the process's warning state, so two threads' reads (scene files loaded
side by side, :func:`ignjax.episodes.dataset.open_benchmark`) take turns; a
warning another thread gives meanwhile is recorded here and given again, so
it is shown all the same (that read is then not kept)."""


def _file_digest(p: Path) -> str | None:
    try:
        return hashlib.blake2b(p.read_bytes(), digest_size=20).hexdigest()
    except OSError:
        return None


def read_remembered(path: Path, kind: str, read: Callable[[], tuple[Scene, tuple[Path, ...]]],
                    versions: str = "") -> Scene:
    """The scene ``read()`` returns (with the files it was composed from),
    read back from the cache when the same file was read before.

    Args:
        path: the source file.
        kind: the reader's name (part of the key).
        read: reads the file: (scene, other files it used).
        versions: versions of the reader's own libraries (part of the key).
    """
    store = derived_store()
    if store is None:
        return read()[0]
    try:
        data = path.read_bytes()
    except OSError:
        return read()[0]  # the reader names the file and the reason
    key = digest(code_digest("ignjax.scenes"), kind, versions, str(path), data)
    got = store.get("scene", key)
    if got is not None:
        deps = json.loads(got["deps"].tobytes().decode())
        if all(_file_digest(Path(f)) == h for f, h in deps.items()):
            return scene_from_dict(json.loads(got["scene"].tobytes().decode()), str(path))
    with _RECORDING, warnings.catch_warnings(record=True) as caught:  # the warnings state is the process's
        warnings.simplefilter("always")
        scene, used = read()
    for w in caught:  # given again where they were raised, as if not caught
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)
    text = scene_to_json(scene)
    if not caught and scene_to_json(scene_from_dict(json.loads(text), str(path))) == text:
        deps = {str(f): _file_digest(f) for f in used}
        if all(deps.values()):
            store.put("scene", key, {"scene": np.frombuffer(text.encode(), np.uint8),
                                     "deps": np.frombuffer(json.dumps(deps, sort_keys=True).encode(), np.uint8)})
    return scene


__all__ = ["read_remembered"]
