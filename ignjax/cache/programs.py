"""Compiled programs kept whole on disk, so that a warm run skips tracing and
lowering as well as compiling.

JAX's persistent compilation cache (:mod:`ignjax.cache.compile`) keys a
program by its lowered form, so a process must trace and lower a program
before it can find the compiled one: for a rollout program (15,000
StableHLO operations) that is about 3.5 s of Python on the 2-core CPU, paid
again by every run, once per agent and batch shape. This store keys a
program instead by everything its trace is a function of, known before
tracing:

- the source of the ``ignjax`` package and the versions of the libraries
  it traces through (:func:`~ignjax.cache.store.code_digest`), the
  backend's platform and version, JAX's tracing settings
  (``jax._src.config.trace_context``), ``XLA_FLAGS`` and the switches
  the caller names (``context``);
- the function and its static arguments, described by :func:`stable`: a
  function by its module, name, default arguments and closure, a
  dataclass by its fields, a mesh by its devices;
- the arguments' pytree structure (with the static metadata of every node,
  less the fields a :func:`~ignjax.arrays.pytree_dataclass` declares
  ``untraced``) and every leaf's type, shape, dtype, weak type and
  placement.

On a hit the serialised executable is loaded (about 1 s for a rollout
program on the 2-core CPU, which :func:`prefetch_programs` starts ahead of
use in a command run again); on a miss the program is lowered and compiled (through JAX's
persistent cache) and then stored. Anything this description cannot
vouch for is never stored: a function or a type from outside ``ignjax``
and the libraries above (an agent written in a notebook: its source is
not in the digest), an object without a faithful description, a program
JAX cannot serialise (host callbacks, closed-over constants). Those
programs compile as before. What a function reads from mutable module
state at trace time is outside the key: ignjax's traced code reads none.

A loaded program is the executable the compiler produced, so outputs are
the same bytes whether it was loaded, compiled through JAX's cache, or
compiled afresh. Entries live in the cache folder's ``programs/`` (an
:class:`~ignjax.cache.store.ArrayStore`: checksummed, written atomically,
least recently used evicted past the bound); they are used exactly when
JAX's persistent cache is on (``--no-compile-cache`` and
``IGNJAX_NO_CACHE`` turn both off). A damaged entry is one warning and a
compile; an entry that will not load (another machine's CPU features) is
one warning, a compile and a rewrite.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import io
import json
import os
import pickle
import threading
import time
import types
import warnings

import numpy as np

from ignjax.cache.clock import PROGRAM_LOAD_EVENT
from ignjax.cache.folder import cache_root
from ignjax.cache.store import ArrayStore, CacheWarning, array_digest, code_digest, digest
from ignjax.fileio import atomic_write

PROGRAMS_BOUND_BYTES = 2 << 30
"""Size bound of the program store (a rollout program is about 6 MB)."""


TRUSTED_MODULES = ("ignjax", "jax", "jaxlib", "numpy", "mujoco", "builtins", "math", "operator")
"""Packages whose functions and types a key may name: their source or
version is in the key (:func:`~ignjax.cache.store.code_digest`)."""


class Unkeyable(Exception):
    """The program cannot be described faithfully before tracing; it compiles without the store."""


def _trusted(module: str | None) -> bool:
    return bool(module) and module.split(".")[0] in TRUSTED_MODULES


def _name(obj) -> str:
    module, name = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    if not _trusted(module) or not name or "<locals>" in name:
        raise Unkeyable(f"{module}.{name}")
    return f"{module}.{name}"


def _function(f) -> tuple:
    closure = tuple(stable(c.cell_contents) for c in (f.__closure__ or ()))
    nested = "<" in f.__qualname__  # a lambda or a function defined in a function
    return ("fn", _local_name(f) if nested else _name(f), stable(f.__defaults__), stable(f.__kwdefaults__), closure)


def _local_name(f) -> str:
    """A nested function or lambda: its module, name and place in the source (its closure is keyed apart)."""
    if not _trusted(f.__module__):
        raise Unkeyable(f"{f.__module__}.{f.__qualname__}")
    return f"{f.__module__}.{f.__qualname__}:{f.__code__.co_firstlineno}"


def _dataclass(x) -> tuple:
    untraced = getattr(type(x), "__untraced__", ())
    return ("dc", _name(type(x)), tuple((f.name, "untraced" if f.name in untraced else stable(getattr(x, f.name)))
                                        for f in dataclasses.fields(x)))


def stable(x):
    """A description of ``x`` built from strings and tuples, equal across
    processes exactly when ``x`` would trace the same (see the module
    docstring).

    Raises:
        Unkeyable: ``x`` holds something without such a description.
    """
    import jax
    from jax.sharding import Mesh, NamedSharding, PartitionSpec, SingleDeviceSharding

    if x is None or isinstance(x, (bool, int, float, complex, str, bytes)):
        return (type(x).__name__, repr(x))
    if isinstance(x, enum.Enum):
        return ("enum", _name(type(x)), x.name)
    if isinstance(x, (tuple, list)) and not hasattr(x, "_fields"):
        return (type(x).__name__,) + tuple(stable(v) for v in x)
    if isinstance(x, tuple):  # a namedtuple
        return ("nt", _name(type(x))) + tuple(stable(v) for v in x)
    if isinstance(x, dict):
        return ("dict",) + tuple((stable(k), stable(v)) for k, v in sorted(x.items(), key=lambda kv: repr(kv[0])))
    if isinstance(x, (frozenset, set)):
        return ("set",) + tuple(sorted(repr(stable(v)) for v in x))
    if isinstance(x, np.ndarray):
        return ("ndarray", x.dtype.str, x.shape, array_digest(x).hex())
    if isinstance(x, np.generic):
        return ("np", x.dtype.str, repr(x.item()))
    if isinstance(x, np.dtype):
        return ("dtype", x.str)
    if isinstance(x, jax.tree_util.PyTreeDef):
        return _treedef(x)
    if isinstance(x, Mesh):
        return ("mesh", tuple(x.axis_names), tuple(x.devices.shape), tuple(_device(d) for d in x.devices.flat),
                tuple(str(t) for t in getattr(x, "axis_types", ())))
    if isinstance(x, NamedSharding):
        return ("named", stable(x.mesh), str(x.spec), str(x.memory_kind))
    if isinstance(x, SingleDeviceSharding):
        return ("single", _device(next(iter(x.device_set))), str(x.memory_kind))
    if isinstance(x, PartitionSpec):
        return ("spec", str(x))
    if isinstance(x, functools.partial):
        return ("partial", stable(x.func), stable(x.args), stable(x.keywords))
    if isinstance(x, types.MethodType):
        return ("method", stable(x.__self__), stable(x.__func__))
    if isinstance(x, types.FunctionType):
        return _function(x)
    if isinstance(x, types.BuiltinFunctionType) or type(x).__name__ in ("PjitFunction", "ufunc"):
        inner = getattr(x, "__wrapped__", None)
        return ("jit", stable(inner)) if isinstance(inner, types.FunctionType) else ("builtin", _name(x))
    if isinstance(x, type):
        return ("type", _name(x))
    if dataclasses.is_dataclass(x):
        return _dataclass(x)
    raise Unkeyable(type(x).__name__)


def _device(d) -> tuple:
    return (d.platform, d.device_kind, d.id, getattr(d, "process_index", 0))


def _treedef(td) -> tuple:
    data = td.node_data()
    if data is None:
        return ("*",)
    typ, aux = data
    untraced = getattr(typ, "__untraced__", ())
    meta = getattr(typ, "__pytree_meta__", None)
    if untraced and meta is not None and isinstance(aux, tuple) and len(aux) == len(meta):
        aux = tuple("untraced" if name in untraced else value for name, value in zip(meta, aux))
    kind = typ.__name__ if typ in (tuple, list, dict, type(None)) else _name(typ)
    return (kind, stable(aux), tuple(_treedef(c) for c in td.children()))


def _leaf(x) -> tuple:
    import jax

    if isinstance(x, (jax.Array, jax.ShapeDtypeStruct)):  # a ShapeDtypeStruct keys as the array it describes
        aval = x.aval if isinstance(x, jax.Array) else x
        return ("array", tuple(aval.shape), str(aval.dtype), bool(aval.weak_type), stable(x.sharding))
    if isinstance(x, (np.ndarray, np.generic)):
        return ("host", np.shape(x), np.asarray(x).dtype.str)
    if isinstance(x, (bool, int, float, complex)):
        return ("scalar", type(x).__name__)
    raise Unkeyable(type(x).__name__)


def _trace_settings() -> tuple:
    """JAX's settings that change a trace, without the entries that have no faithful description."""
    from jax._src import config

    return tuple(r if " at 0x" not in (r := repr(v)) else type(v).__name__ for v in config.trace_context())


def program_key(fn, args: tuple, static: dict, context=()) -> str | None:
    """The store's key of ``fn.lower(*args, **static)`` (module docstring),
    or None when it has none. ``context``: values of switches the traced
    code reads besides its arguments (e.g. :data:`ignjax.sim.compact.ONE_PASS`)."""
    import jax

    try:
        leaves, tree = jax.tree.flatten(args)
        backend = jax.devices()[0].client
        return digest(code_digest("ignjax"), backend.platform, backend.platform_version, _trace_settings(),
                      os.environ.get("XLA_FLAGS", ""), stable(fn), stable(static), stable(context), _treedef(tree),
                      tuple(_leaf(x) for x in leaves))
    except (Unkeyable, RecursionError):  # RecursionError: a closure that holds itself
        return None


_STORES: dict = {}


def program_store() -> ArrayStore | None:
    """The store under the cache folder's ``programs/``, or None when JAX's persistent cache is off."""
    import jax

    root = cache_root()
    if root is None or not jax.config.jax_enable_compilation_cache:
        return None
    root = root / "programs"
    if root not in _STORES:
        _STORES[root] = ArrayStore(root, PROGRAMS_BOUND_BYTES)
    return _STORES[root]


def _serialise(lowered, compiled) -> dict[str, np.ndarray] | None:
    from jax.experimental.serialize_executable import serialize

    try:
        payload, _, out_tree = serialize(compiled)
        tree = pickle.dumps(out_tree, protocol=pickle.HIGHEST_PROTOCOL)
        options = json.dumps(list(getattr(lowered._lowering, "_compiler_options_kvs", ()))).encode()
    except Exception:  # noqa: BLE001 - JAX refuses some programs (callbacks, constants): they are not stored
        return None
    devices = np.array([d.id for d in compiled.runtime_executable().local_devices()], np.int64)
    return {"executable": np.frombuffer(payload, np.uint8), "out_tree": np.frombuffer(tree, np.uint8),
            "devices": devices, "options": np.frombuffer(options, np.uint8)}


def _executable(entry: dict[str, np.ndarray]) -> tuple:
    """The executable of a stored entry, loaded for the devices it was
    compiled for and with the compile options it was compiled with (XLA:CPU
    finds its kernels by names that depend on them:
    ``xla_cpu_use_fusion_emitters``), with what :func:`_program` needs to
    wrap it: the slow half of a load (about 1 s for a rollout program on the
    2-core CPU, without Python's lock), which :func:`prefetch_programs` runs
    ahead of use."""
    import jax
    from jax._src import compiler
    from jax._src.lib import xla_client as xc
    from jax.experimental.serialize_executable import _JaxPjrtUnpickler

    by_id = {d.id: d for d in jax.local_devices()}
    devices = [by_id[int(i)] for i in entry["devices"]]  # the devices it was compiled for (a KeyError: not here)
    backend = devices[0].client
    options = compiler.get_compile_options(
        num_replicas=1, num_partitions=len(devices), device_assignment=np.array(devices, object).reshape(1, -1),
        env_options_overrides=dict(json.loads(entry["options"].tobytes())), backend=backend)

    class Unpickler(_JaxPjrtUnpickler):
        def persistent_load(self, pid):
            if pid[0] == "exec":
                return self.backend.deserialize_executable(pid[1], xc.DeviceList(tuple(devices)), options)
            return super().persistent_load(pid)

    unloaded, args_info_flat, no_kwargs = Unpickler(io.BytesIO(entry["executable"].tobytes()), backend,
                                                    devices).load()
    out_tree = pickle.load(io.BytesIO(entry["out_tree"].tobytes()))
    return unloaded.load(), args_info_flat, no_kwargs, out_tree


def _program(loaded: tuple, args: tuple):
    """The compiled program of an :func:`_executable`, for arguments of its key's structure."""
    import jax

    executable, args_info_flat, no_kwargs, out_tree = loaded
    args_info = jax.tree.structure((tuple(args), {})).unflatten(args_info_flat)
    return jax.stages.Compiled(executable, [], args_info, out_tree, no_kwargs=no_kwargs)


PREFETCH_MAX = 8
"""The most programs :func:`prefetch_programs` loads ahead."""
_AHEAD_LOCK = threading.Lock()
_AHEAD: dict = {"context": None, "used": [], "armed": [], "pending": {}, "pool": None}


def _recent_path(store: ArrayStore, context: str):
    return store.root / "recent" / f"{context}.json"


def prefetch_programs(context) -> int:
    """Load ahead the stored programs that the last run with the same
    ``context`` used (a command passes its name and options, less where it
    writes), and record the programs this run uses under ``context`` for the
    next. The loads start at once in background threads (:func:`start_prefetch`;
    XLA loads an executable without Python's lock, 1-2 s for a rollout
    program here), so a command run again loads its programs while it imports
    its modules and builds its benchmark's tables instead of after. Only a program whose key
    (:func:`program_key`, computed from the real arguments when the program
    is needed) equals a loaded one's is taken from them, so a wrong guess
    (another benchmark at the same path, other shapes) costs background work
    and never a result; the outputs are the same bytes either way.

    Returns:
        How many loads started (0 when the store is off or the context
        has no record).
    """
    store = program_store()
    if store is None:
        return 0
    ctx = digest("prefetch", context)
    try:
        recent = json.loads(_recent_path(store, ctx).read_text())["programs"][:PREFETCH_MAX]
        recent = [(str(n), str(k)) for n, k in recent]
    except (OSError, ValueError, KeyError, TypeError):
        recent = []
    with _AHEAD_LOCK:
        _AHEAD.update(context=ctx, used=[], armed=recent, pending={})
    return start_prefetch()


def start_prefetch() -> int:
    """Start the loads :func:`prefetch_programs` armed (once; later calls
    start nothing). A load in a background thread must not run while the
    main thread first imports USD, whose libraries take Python's lock while
    the dynamic loader's is held (a deadlock, reproduced under load):
    :mod:`ignjax.scenes.io.usd` waits for the loads (:func:`settle_prefetch`)
    before it imports them, which a run whose scene files are all remembered
    (:mod:`ignjax.scenes.io.remembered`) never does. Returns how many started."""
    store = program_store()
    with _AHEAD_LOCK:
        todo, _AHEAD["armed"] = _AHEAD["armed"], []
    if not todo or store is None:
        return 0
    import jax
    from concurrent.futures import ThreadPoolExecutor

    from ignjax.devices import available_cores

    jax.local_devices()  # the backend starts here, not in a worker

    def load(name: str, key: str):
        entry = store.get(name, key)
        return None if entry is None else _executable(entry)

    with _AHEAD_LOCK:
        if _AHEAD["pool"] is None:
            _AHEAD["pool"] = ThreadPoolExecutor(max(1, available_cores()), thread_name_prefix="ignjax-prefetch")
        for name, key in todo:
            _AHEAD["pending"][key] = _AHEAD["pool"].submit(load, name, key)
    return len(todo)


def settle_prefetch() -> None:
    """Wait for every load :func:`start_prefetch` started, so that none runs
    past the loading of a benchmark, the first program's use or an import
    of USD (:func:`start_prefetch`'s reason).
    :meth:`ignjax.episodes.dataset.BenchmarkScenes.with_fields` and
    :mod:`ignjax.scenes.io.usd` call it."""
    with _AHEAD_LOCK:
        pending = list(_AHEAD["pending"].values())
    for f in pending:
        f.exception()  # waits; a failed or unused guess is only left unused


def _take_prefetched(key: str):
    """The :func:`_executable` loaded ahead under ``key``, or None, once every load started ahead has ended."""
    with _AHEAD_LOCK:
        fut = _AHEAD["pending"].pop(key, None)
    settle_prefetch()
    if fut is None:
        return None
    try:
        return fut.result()
    except Exception:  # noqa: BLE001 - an entry that did not load is loaded (or compiled) the usual way
        return None


def _note_used(name: str, key: str) -> None:
    """Add a program to the record of this run's context (:func:`prefetch_programs`)."""
    store = program_store()
    with _AHEAD_LOCK:
        ctx, used = _AHEAD["context"], _AHEAD["used"]
        if ctx is None or store is None or [name, key] in used:
            return
        used.append([name, key])
        try:
            atomic_write(_recent_path(store, ctx), json.dumps({"programs": used}))
        except OSError:
            pass  # the store's own writes warn when the folder cannot be written


_THREAD = threading.local()
_HOOKED = []


def _hooks() -> None:
    """Install, once per process, a listener counting each thread's loads from JAX's persistent cache and a
    salt of JAX's cache key that is this thread's program key while :func:`load_or_compile` compiles.

    XLA:CPU cannot serialise again an executable it loaded from a serialised form: the copy misses kernels,
    and a fresh process that loads it fails when it runs ("Function ... not found"). So a program is stored
    only when it was compiled in the run. The salt makes JAX's entry of a stored program its own: a program
    JAX's cache holds from before (an earlier ignjax version, the same program) is then a miss there and
    compiles afresh once, and is stored, instead of loading from JAX's cache after tracing on every run. The
    counts catch what the salt cannot (a stored entry deleted while JAX's stayed, or the executable JAX keeps
    in memory from such a load): such a program is used, not stored. The salt goes through ``jax._src.cache_key.custom_hook``, JAX's hook for additions to its key,
    chained to any hook already there; other programs' keys are unchanged."""
    if _HOOKED:
        return
    import jax
    from jax._src import cache_key

    def count(event, **_):
        if event == "/jax/compilation_cache/cache_hits":
            _THREAD.hits = getattr(_THREAD, "hits", 0) + 1

    def count_compiles(event, start, end, **_):
        if event == "/jax/core/compile/backend_compile_duration":
            _THREAD.compiles = getattr(_THREAD, "compiles", 0) + 1

    prior = cache_key.custom_hook

    def salted() -> str:
        salt = getattr(_THREAD, "salt", "")
        return prior() + (f"ignjax-program:{salt}" if salt else "")

    jax.monitoring.register_event_listener(count)
    jax.monitoring.register_event_time_span_listener(count_compiles)
    cache_key.custom_hook = salted
    _HOOKED.append((count, salted))


def _compile_fresh(lowered, key: str | None):
    """``lowered.compile()`` with JAX's key salted by ``key``; and whether the backend compiled it here (not
    loaded from JAX's persistent cache, nor handed back from JAX's memory, where it may be such a load):
    see :func:`_hooks`."""
    _hooks()
    hits, compiles = getattr(_THREAD, "hits", 0), getattr(_THREAD, "compiles", 0)
    _THREAD.salt = key or ""
    try:
        program = lowered.compile()
    finally:
        _THREAD.salt = ""
    return program, getattr(_THREAD, "hits", 0) == hits and getattr(_THREAD, "compiles", 0) == compiles + 1


def load_or_compile(fn, args: tuple, static: dict, name: str, context=()):
    """``fn.lower(*args, **static).compile()``, loaded from the program
    store when it holds it, else compiled and stored (module docstring).
    ``name`` is the program's name in the compile clock's record;
    ``context`` as in :func:`program_key`."""
    store = program_store()
    key = program_key(fn, args, static, context) if store is not None else None
    if key is not None:
        t0 = time.time()
        loaded = _take_prefetched(key)
        entry = store.get(name, key) if loaded is None else None
        if entry is not None:
            try:
                loaded = _executable(entry)
            except Exception as e:  # noqa: BLE001 - an entry that will not load is compiled again
                warnings.warn(f"ignjax cache: a stored program in {store.path(name, key)} does not load "
                              f"({type(e).__name__}); compiling it again", CacheWarning, stacklevel=2)
        if loaded is not None:
            import jax

            program = _program(loaded, args)
            jax.monitoring.record_event_time_span(PROGRAM_LOAD_EVENT, t0, time.time(), fun_name=name)
            _note_used(name, key)
            return program
    lowered = fn.lower(*args, **static)
    program, fresh = _compile_fresh(lowered, key)
    if key is not None and fresh:
        entry = _serialise(lowered, program)
        if entry is not None and store.put(name, key, entry):
            _note_used(name, key)
    return program


__all__ = ["PREFETCH_MAX", "PROGRAMS_BOUND_BYTES", "TRUSTED_MODULES", "Unkeyable", "load_or_compile",
           "prefetch_programs", "program_key", "program_store", "settle_prefetch", "stable", "start_prefetch"]
