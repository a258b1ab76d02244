"""What ignjax keeps on disk between runs so that a second run of a command
does not redo the work of the first: compiled programs (JAX's persistent
compilation cache, :func:`~ignjax.cache.compile.use_compile_cache`) and
arrays derived from scenes (navigation grids, goal fields, probe maps, in
:class:`~ignjax.cache.store.ArrayStore`), both under the cache folder
(:func:`~ignjax.cache.folder.cache_root`). ``ignjax.cache.compile`` is
imported on its own: it loads JAX, which a command's ``--help`` should not wait for.

A cache only ever saves time: every entry is keyed by a digest of what it
is computed from (the inputs, the code that computes them and the library
versions), checked against a checksum when read, and recomputed when it is
missing, stale or damaged, so results are the same bytes with the cache
cold, warm or off.
"""

from ignjax.cache.folder import CACHE_DIR_ENV, NO_CACHE_ENV, cache_root
from ignjax.cache.options import add_cache_arguments, apply_cache_arguments, prefetch_command_programs
from ignjax.cache.store import ArrayStore, CacheWarning, array_digest, code_digest, derived_store, digest

__all__ = ["ArrayStore", "array_digest", "CACHE_DIR_ENV", "CacheWarning", "NO_CACHE_ENV", "cache_root", "code_digest",
           "derived_store", "digest", "add_cache_arguments", "apply_cache_arguments", "prefetch_command_programs"]
