"""A folder of named array bundles, each one ``.npz`` file that carries a
checksum of its arrays, written atomically and evicted oldest first.

An entry is read back only when it is complete and its checksum matches;
anything else (a truncated file, a file of another format, one removed by
another process while being read) is a miss, with a warning when the file
was there but damaged, and the caller computes the arrays again and writes
them over it. A folder that cannot be written makes one warning; the run
goes on without storing.
"""

from __future__ import annotations

import hashlib
import io
import importlib
import inspect
import os
import threading
import warnings
from pathlib import Path

import numpy as np

from ignjax.cache.folder import cache_root
from ignjax.cache.npz import read_npz
from ignjax.fileio import atomic_write

FORMAT = 3
"""Version of the entry layout (3: checksums by :func:`array_digest` with SHA-256). It is
part of every key made with :func:`code_digest`, so entries of another
version are never looked up; one read anyway is a quiet miss."""

DEFAULT_BOUND_BYTES = 4 << 30
"""Size bound of the derived-array store (oldest entries evicted first)."""

_CHECKSUM, _FORMAT = "__checksum__", "__format__"


class CacheWarning(UserWarning):
    """A cache could not be used; the run goes on without it."""


def digest(*parts) -> str:
    """Hex blake2b digest of ``parts`` (str, bytes, or anything with a
    deterministic ``repr``: numbers, tuples, frozen dataclasses)."""
    h = hashlib.blake2b(digest_size=20)
    for p in parts:
        b = p if isinstance(p, bytes) else (p if isinstance(p, str) else repr(p)).encode()
        h.update(len(b).to_bytes(8, "little"))
        h.update(b)
    return h.hexdigest()


_CODE: dict[tuple[str, ...], str] = {}


def code_digest(*modules: str) -> str:
    """Digest of the named modules' source files (a package: every module
    in it) and of the versions of the libraries that compute with them
    (numpy, scipy, jax, jaxlib, mujoco): an entry computed by other code is
    never read back."""
    if modules not in _CODE:
        import jax
        import jaxlib
        import mujoco
        import scipy

        srcs = [src for m in modules for src in _sources(importlib.import_module(m))]
        _CODE[modules] = digest(FORMAT, np.__version__, scipy.__version__, jax.__version__, jaxlib.__version__,
                                mujoco.__version__, *modules, *srcs)
    return _CODE[modules]


def _sources(module) -> list[bytes]:
    if not hasattr(module, "__path__"):
        return [Path(inspect.getsourcefile(module)).read_bytes()]
    root = Path(module.__path__[0])
    return [str(p.relative_to(root)).encode() + b"\0" + p.read_bytes() for p in sorted(root.rglob("*.py"))]


def array_digest(*parts, size: int = 20) -> bytes:
    """SHA-256 digest (its first ``size`` bytes) of arrays (or anything
    ``np.asarray`` takes), each with its dtype and shape: equal exactly when
    every part has the same dtype, shape and bytes. SHA-256 because
    processors compute it in hardware (about twice blake2b's speed here:
    a warm run checksums every derived array it reads); the arrays are hashed
    in place, not copied."""
    h = hashlib.sha256()
    for part in parts:
        a = np.ascontiguousarray(np.asarray(part))
        h.update(f"{a.dtype.str}|{a.shape}|".encode())
        h.update(a.reshape(-1).view(np.uint8) if a.size else b"")
    return h.digest()[:size]


def _checksum(arrays: dict[str, np.ndarray]) -> np.ndarray:
    names = sorted(arrays)
    return np.frombuffer(array_digest(np.array(names), *(arrays[n] for n in names), size=32), np.uint8)


class ArrayStore:
    """Array bundles under ``root/<kind>/<key>.npz``.

    Args:
        root: the store's folder (created on the first write).
        bound_bytes: after a write, the oldest entries (by last use) are
            deleted until the store holds at most this many bytes.
    """

    def __init__(self, root: str | os.PathLike, bound_bytes: int = DEFAULT_BOUND_BYTES):
        self.root = Path(root)
        self.bound_bytes = int(bound_bytes)
        self._unwritable = False
        self._bytes: int | None = None  # the store's size as this process last counted it, plus its writes since
        self._counting = threading.Lock()  # threads write side by side (scene files loaded in parallel)

    def path(self, kind: str, key: str) -> Path:
        return self.root / kind / f"{key}.npz"

    def get(self, kind: str, key: str) -> dict[str, np.ndarray] | None:
        """The arrays stored under ``key``, or None (absent or damaged)."""
        p = self.path(kind, key)
        try:
            arrays = read_npz(p)
        except (FileNotFoundError, NotADirectoryError):
            return None
        except Exception as e:  # noqa: BLE001 - a damaged file of any kind is a miss
            warnings.warn(f"ignjax cache: {p} is damaged ({type(e).__name__}); computing it again", CacheWarning,
                          stacklevel=2)
            return None
        check, fmt = arrays.pop(_CHECKSUM, None), arrays.pop(_FORMAT, None)
        if fmt is not None and int(fmt) != FORMAT:
            return None  # written by another version: not damaged, computed again and replaced
        if fmt is None or check is None or not np.array_equal(check, _checksum(arrays)):
            warnings.warn(f"ignjax cache: {p} does not match its checksum; computing it again", CacheWarning,
                          stacklevel=2)
            return None
        try:
            os.utime(p)  # last use, for eviction
        except OSError:
            pass
        return arrays

    def put(self, kind: str, key: str, arrays: dict[str, np.ndarray]) -> bool:
        """Store ``arrays`` under ``key``; False (after one warning per
        store) when the folder cannot be written."""
        if self._unwritable:
            return False
        arrays = {n: np.asarray(a) for n, a in arrays.items()}
        buf = io.BytesIO()
        np.savez(buf, **arrays, **{_CHECKSUM: _checksum(arrays), _FORMAT: np.int64(FORMAT)})
        data = buf.getvalue()
        try:
            atomic_write(self.path(kind, key), data)
        except OSError as e:
            self._unwritable = True
            warnings.warn(f"ignjax cache: cannot write under {self.root} ({e.strerror or e}); going on without it",
                          CacheWarning, stacklevel=2)
            return False
        with self._counting:  # the folder is listed once, then again only when the count passes the bound
            self._bytes = self._evict() if self._bytes is None else self._bytes + len(data)
            if self._bytes > self.bound_bytes:
                self._bytes = self._evict()
        return True

    def _evict(self) -> int:
        """Delete the least recently used entries past the bound; the bytes left."""
        entries = []
        for p in self.root.glob("*/*.npz"):
            try:
                st = p.stat()
            except OSError:
                continue
            entries.append((st.st_mtime, st.st_size, p))
        total = sum(s for _, s, _ in entries)
        for _, size, p in sorted(entries):
            if total <= self.bound_bytes:
                break
            p.unlink(missing_ok=True)
            total -= size
        return total


_STORES: dict[Path, ArrayStore] = {}


def derived_store() -> ArrayStore | None:
    """The store of arrays derived from scenes, under the cache folder's
    ``derived/``; None when caching is off."""
    root = cache_root()
    if root is None:
        return None
    root = root / "derived"
    if root not in _STORES:
        _STORES[root] = ArrayStore(root)
    return _STORES[root]


__all__ = ["ArrayStore", "CacheWarning", "array_digest", "DEFAULT_BOUND_BYTES", "FORMAT", "code_digest", "derived_store", "digest"]
