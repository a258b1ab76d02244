"""JAX's persistent compilation cache, on by default for ignjax's commands.

:func:`use_compile_cache` points JAX at ``<cache folder>/jax`` (see
:func:`~ignjax.cache.folder.cache_root`), caches every program whatever its
compile time (a command compiles hundreds of small ones) and bounds the
folder (JAX deletes the least recently used entries past the bound). A
folder of the user's own in ``JAX_COMPILATION_CACHE_DIR`` is used as it is.
JAX keys each entry by the program, the compile options, the JAX/XLA
version and the devices, so an entry of another version or machine is never
loaded, and it turns a failed read or write into a warning; a folder that
cannot be written is one warning here and the run goes on compiling.
Outputs do not depend on whether an entry was hit (a loaded program is the
one the compiler produced).
"""

from __future__ import annotations

import os
import tempfile
import warnings
from pathlib import Path

import jax

from ignjax.cache.folder import cache_root
from ignjax.cache.store import CacheWarning

COMPILE_CACHE_BOUND_BYTES = 4 << 30
"""Size bound of the compilation cache folder (JAX evicts the least recently used entries)."""


def use_compile_cache(enabled: bool = True) -> Path | None:
    """Turn JAX's persistent compilation cache on (or off) for this process;
    call it before the first program compiles (JAX decides once per process).

    Returns:
        The folder in use, or None when the cache is off (``enabled`` False,
        ``IGNJAX_NO_CACHE`` set, or a folder that cannot be written).
    """
    if not enabled or cache_root() is None:
        jax.config.update("jax_enable_compilation_cache", False)
        return None
    own = os.environ.get("JAX_COMPILATION_CACHE_DIR", "").strip()
    folder = Path(own) if own else cache_root() / "jax"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError as e:
        warnings.warn(f"ignjax: the compilation cache folder {folder} cannot be written ({e.strerror or e}); "
                      "compiling without it", CacheWarning, stacklevel=2)
        jax.config.update("jax_enable_compilation_cache", False)
        return None
    jax.config.update("jax_enable_compilation_cache", True)
    if not own:
        jax.config.update("jax_compilation_cache_dir", str(folder))
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
        jax.config.update("jax_compilation_cache_max_size", COMPILE_CACHE_BOUND_BYTES)
    return folder


__all__ = ["COMPILE_CACHE_BOUND_BYTES", "use_compile_cache"]
