"""Where ignjax's caches live: one folder per user, moved or turned off by
environment variables.

- ``IGNJAX_CACHE_DIR``: the folder (default: the platform's per-user cache
  folder, e.g. ``~/.cache/ignjax`` on Linux, from ``platformdirs``).
- ``IGNJAX_NO_CACHE``: any value other than ``""``, ``0``, ``false`` or
  ``no`` turns every cache off.

The command lines add ``--no-compile-cache`` (:mod:`ignjax.cache.options`);
the folder itself is a machine-local setting, read from the environment only.
"""

from __future__ import annotations

import os
from pathlib import Path

import platformdirs

CACHE_DIR_ENV = "IGNJAX_CACHE_DIR"
NO_CACHE_ENV = "IGNJAX_NO_CACHE"


def cache_root() -> Path | None:
    """The cache folder (not created here), or None when caching is off."""
    if os.environ.get(NO_CACHE_ENV, "").strip().lower() not in ("", "0", "false", "no"):
        return None
    where = os.environ.get(CACHE_DIR_ENV, "").strip()
    return Path(where).expanduser() if where else Path(platformdirs.user_cache_dir("ignjax", appauthor=False))


__all__ = ["CACHE_DIR_ENV", "NO_CACHE_ENV", "cache_root"]
