"""Writing output files so that a reader never sees a partial one, and checking them by their SHA-256."""

from __future__ import annotations

import hashlib
import os
import threading
from pathlib import Path

_TMP = ".tmp-"  # between a file's name and the writing process's and thread's ids


def atomic_write(path: str | os.PathLike, data: bytes | str) -> Path:
    """Write ``data`` (text is UTF-8 encoded) to a temporary name in the same
    folder, then rename it over ``path``; the folder is created if needed."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.with_name(f".{p.name}{_TMP}{os.getpid()}-{threading.get_ident()}")
    try:
        tmp.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
        os.replace(tmp, p)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return p


def remove_leftover_temporaries(folder: str | os.PathLike) -> int:
    """Delete the temporary files that :func:`atomic_write` leaves when its
    process is killed mid-write (SIGKILL skips the clean-up), anywhere under
    ``folder``; call it only on a folder no other live process writes into.

    Returns:
        How many files were deleted.
    """
    n = 0
    for tmp in Path(folder).rglob(f".*{_TMP}*"):
        if tmp.is_file():
            tmp.unlink(missing_ok=True)
            n += 1
    return n


def file_sha256(path: str | os.PathLike) -> str:
    """The SHA-256 of a file's bytes, hex, read a megabyte at a time."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


__all__ = ["atomic_write", "file_sha256", "remove_leftover_temporaries"]
