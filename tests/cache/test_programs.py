"""The program store (ignjax.cache.programs): programs kept whole on disk,
keyed by what their trace is a function of, loaded back as the executable
the compiler produced, and never stored when the key cannot vouch for them."""

from __future__ import annotations

import dataclasses
import functools
import time
import warnings

import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.agents import get_agent
from ignjax.cache import programs as PR
from ignjax.cache.clock import CompileClock
from ignjax.cache.store import ArrayStore, CacheWarning
from ignjax.sim import compact
from ignjax.sim import rollout as R
from ignjax.sim.rollout import episode_keys, rollout_call


@functools.partial(jax.jit, static_argnames=("n",))
def _scaled(x, y, *, n):
    return {"sum": x * n + y, "first": x[:1]}


N = 3 + time.time_ns() % 1000  # a program no earlier run put in JAX's own cache (the suite's cache folder is kept)


def _call(small_benchmark, n=12, agent="naive_asker"):
    specs = jax.tree.map(lambda a: a[:n], small_benchmark["set"].specs)
    agent = get_agent(agent)
    return specs, agent, agent.default_params(), episode_keys(0, np.arange(n))


@pytest.fixture
def store(tmp_path, monkeypatch):
    """A fresh program store, with this test module's functions trusted (their source is this file)."""
    monkeypatch.setenv("IGNJAX_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(PR, "TRUSTED_MODULES", PR.TRUSTED_MODULES + (__name__.split(".")[0],))
    monkeypatch.setattr(PR, "_STORES", {})
    return PR.program_store()


def _args(n=4):
    return (jnp.arange(n, dtype=jnp.float32), jnp.ones(n, jnp.float32))


def test_a_stored_program_is_loaded_whole_and_gives_the_same_bytes(store):
    args = _args()
    clock = CompileClock().start()
    first = PR.load_or_compile(_scaled, args, {"n": N}, "scaled")
    assert clock.whole == 0 and list((store.root / "scaled").glob("*.npz")), "the compiled program was not stored"
    again = PR.load_or_compile(_scaled, args, {"n": N}, "scaled")
    clock.stop()
    assert clock.whole == 1 and clock.names[-1] == "scaled"
    chex.assert_trees_all_equal(jax.device_get(first(*args)), jax.device_get(again(*args)))
    assert float(again(*args)["sum"][1]) == N + 1
    for p in (store.root / "scaled").glob("*.npz"):
        p.unlink()
    PR.load_or_compile(_scaled, args, {"n": N}, "scaled")  # JAX's memory hands it back: it may be a load, not stored
    assert not list((store.root / "scaled").glob("*.npz"))


def test_the_key_follows_every_input_of_the_trace(store):
    args = _args()
    key = PR.program_key(_scaled, args, {"n": N})
    assert key == PR.program_key(_scaled, _args(), {"n": N})  # equal arguments, equal key
    assert key != PR.program_key(_scaled, args, {"n": N + 1})  # a static argument
    assert key != PR.program_key(_scaled, _args(5), {"n": N})  # a shape
    assert key != PR.program_key(_scaled, (args[0], args[1].astype(jnp.int32)), {"n": N})  # a dtype
    assert key != PR.program_key(_scaled, (args[0], (args[1],)), {"n": N})  # the tree
    assert key != PR.program_key(_scaled, args, {"n": N}, context=(True,))  # a tracing switch
    with jax.numpy_rank_promotion("raise"):  # one of JAX's tracing settings
        assert key != PR.program_key(_scaled, args, {"n": N})


def test_code_it_cannot_vouch_for_is_compiled_and_never_stored(store, monkeypatch):
    monkeypatch.setattr(PR, "TRUSTED_MODULES", tuple(m for m in PR.TRUSTED_MODULES if m != __name__.split(".")[0]))
    assert PR.program_key(_scaled, _args(), {"n": N}) is None  # its source is not in the key
    program = PR.load_or_compile(_scaled, _args(), {"n": N}, "scaled")
    assert float(program(*_args())["sum"][1]) == N + 1 and not (store.root / "scaled").exists()

    class Opaque:  # no faithful description
        pass

    with pytest.raises(PR.Unkeyable):
        PR.stable(Opaque())
    agent = dataclasses.replace(get_agent("random"), act=lambda *a: a)  # an agent written outside ignjax
    with pytest.raises(PR.Unkeyable):
        PR.stable(agent)


def test_a_program_jax_cannot_serialise_runs_and_is_not_stored(store):
    @functools.partial(jax.jit, static_argnames=("n",))
    def with_callback(x, *, n):
        return jax.pure_callback(lambda a: np.asarray(a) + n, jax.ShapeDtypeStruct(x.shape, x.dtype), x)

    program = PR.load_or_compile(with_callback, (jnp.ones(3),), {"n": 2}, "callback")
    assert np.array_equal(np.asarray(program(jnp.ones(3))), [3.0, 3.0, 3.0])
    assert not list(store.root.glob("callback/*.npz"))


def test_a_damaged_or_foreign_entry_is_compiled_again_with_a_warning(store):
    args = _args()  # n = N + 10: a program no earlier test compiled (JAX's memory would hand it back unstored)
    PR.load_or_compile(_scaled, args, {"n": N + 10}, "scaled")
    key = PR.program_key(_scaled, args, {"n": N + 10})
    path = store.path("scaled", key)
    path.write_bytes(path.read_bytes()[:-100])  # truncated: its checksum cannot match
    jax.clear_caches()  # as in a new process (JAX's memory would hand back the executable, which is not stored)
    with pytest.warns(CacheWarning, match="damaged|checksum"):
        program = PR.load_or_compile(_scaled, args, {"n": N + 10}, "scaled")
    assert float(program(*args)["sum"][1]) == N + 11
    entry = ArrayStore(store.root).get("scaled", key)  # rewritten whole by the compile
    entry["executable"] = entry["executable"][::-1].copy()  # a valid entry whose executable will not load
    ArrayStore(store.root).put("scaled", key, entry)
    jax.clear_caches()
    with pytest.warns(CacheWarning, match="does not load"):
        program = PR.load_or_compile(_scaled, args, {"n": N + 10}, "scaled")
    assert float(program(*args)["sum"][1]) == N + 11
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the rewritten entry loads again, quietly
        PR.load_or_compile(_scaled, args, {"n": N + 10}, "scaled")


def test_jax_cache_entries_of_stored_programs_are_their_own(store):
    """A program JAX's own cache already holds (compiled by a plain jit, as an
    earlier version would have) is compiled afresh and stored: JAX's key of a
    program compiled for the store is salted with the store's key. And one that
    JAX does load from its cache (its stored entry deleted) is used, not stored:
    XLA:CPU cannot serialise again an executable it loaded (the copy misses
    kernels and fails in a fresh process)."""
    args = _args(6)
    was = jax.config.jax_persistent_cache_min_compile_time_secs
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    try:
        _scaled.lower(*args, n=N + 2).compile()  # into JAX's cache, unsalted
        jax.clear_caches()  # else JAX hands back the executable it holds in memory
        PR.load_or_compile(_scaled, args, {"n": N + 2}, "scaled")
        stored = list((store.root / "scaled").glob("*.npz"))
        assert len(stored) == 1, "a program JAX's cache held from a plain compile was not compiled for the store"
        stored[0].unlink()
        jax.clear_caches()
        program = PR.load_or_compile(_scaled, args, {"n": N + 2}, "scaled")  # JAX's salted entry: a hit
    finally:
        jax.config.update("jax_persistent_cache_min_compile_time_secs", was)
    assert float(program(*args)["sum"][1]) == N + 3
    assert not list((store.root / "scaled").glob("*.npz"))


def test_a_run_again_loads_its_programs_ahead_and_the_same_bytes(store, monkeypatch):
    """prefetch_programs / start_prefetch: the programs the last run of a
    context used start loading in the next at once; one is used only where
    its key is asked for, every load has ended by the first use, and a wrong
    guess or a damaged record falls back to the usual path."""
    monkeypatch.setattr(PR, "_AHEAD", {"context": None, "used": [], "armed": [], "pending": {}, "pool": None})
    args, n = _args(5), N + 20  # a program no earlier test compiled
    assert PR.prefetch_programs(("run", n)) == 0  # nothing recorded yet
    first = PR.load_or_compile(_scaled, args, {"n": n}, "scaled")  # compiled, stored and recorded
    records = list((store.root / "recent").glob("*.json"))
    assert len(records) == 1
    jax.clear_caches()  # as in a new process
    assert PR.prefetch_programs(("another run", n)) == 0  # another context: its own record (none)
    assert not PR._AHEAD["pending"]
    assert PR.prefetch_programs(("run", n)) == 1 and len(PR._AHEAD["pending"]) == 1  # loading at once
    assert PR.start_prefetch() == 0  # started once
    (ahead,) = PR._AHEAD["pending"].values()
    assert ahead.result() is not None  # loaded in the background
    clock = CompileClock().start()
    again = PR.load_or_compile(_scaled, args, {"n": n}, "scaled")
    clock.stop()
    assert clock.whole == 1 and clock.programs == 1 and not PR._AHEAD["pending"]
    chex.assert_trees_all_equal(jax.device_get(first(*args)), jax.device_get(again(*args)))
    # a guess that does not fit (other shapes under the same context) is never used: that call compiles
    jax.clear_caches()
    assert PR.prefetch_programs(("run", n)) == 1
    other = PR.load_or_compile(_scaled, _args(7), {"n": n}, "scaled")
    assert np.asarray(other(*_args(7))["sum"]).tolist() == [n * k + 1.0 for k in range(7)]
    (guess,) = PR._AHEAD["pending"].values()
    assert guess.done()  # waited for at the first use: no load runs past it; the guess stays unused
    records[0].write_text("{not json")  # a damaged record: nothing ahead, no error
    assert PR.prefetch_programs(("run", n)) == 0


def test_the_store_is_off_with_the_compilation_cache(store):
    was = jax.config.jax_enable_compilation_cache
    jax.config.update("jax_enable_compilation_cache", False)  # what --no-compile-cache does
    try:
        assert PR.program_store() is None
    finally:
        jax.config.update("jax_enable_compilation_cache", was)
    assert PR.program_store() is not None


def test_a_rollout_program_key_ignores_the_host_side_scenes_only(small_benchmark, small_world):
    """The scene bank's compiled MuJoCo scenes and navigation grids are
    declared untraced: the rollout program lowers to the same text without
    them, so the key leaves them out; every traced static field (scene ids,
    the one-pass switch) changes it."""
    specs, agent, params, keys = _call(small_benchmark)
    args, static = rollout_call(small_world, specs, agent, params, keys, parts=1)
    bare_bank = dataclasses.replace(small_world.bank, compiled=(), navgrids=())
    bare = (dataclasses.replace(args[0], bank=bare_bank),) + tuple(args[1:])
    key = PR.program_key(R._run_sharded, args, static)
    assert key is not None and key == PR.program_key(R._run_sharded, bare, static)
    renamed = dataclasses.replace(args[0], bank=dataclasses.replace(
        small_world.bank, scene_ids=tuple(s + "_b" for s in small_world.bank.scene_ids)))
    assert key != PR.program_key(R._run_sharded, (renamed,) + tuple(args[1:]), static)
    assert key != PR.program_key(R._run_sharded, args, static, context=(not compact.ONE_PASS,))
    assert key != PR.program_key(R._run_sharded, args, dict(static, agent=get_agent("eig")))
    text = R._run_sharded.lower(*args, **static).as_text()
    assert text == R._run_sharded.lower(*bare, **static).as_text()


def test_usd_libraries_load_only_once_the_loads_ahead_have_ended():
    """start_prefetch's guard: ignjax.scenes.io.usd waits for every load in flight before USD's
    libraries load (they take Python's lock under the dynamic loader's; a load running beside them
    deadlocked). A fresh process, so that USD is not imported yet."""
    import subprocess
    import sys
    import textwrap

    script = textwrap.dedent("""
        import sys, threading, time
        from concurrent.futures import ThreadPoolExecutor
        from ignjax.cache import programs as PR
        assert "pxr" not in sys.modules
        started = threading.Event()
        def load():
            started.set()
            time.sleep(1.0)
            return "pxr" in sys.modules
        with PR._AHEAD_LOCK:
            PR._AHEAD["pending"]["a load in flight"] = ahead = ThreadPoolExecutor(1).submit(load)
        started.wait()
        import ignjax.scenes.io.usd
        assert "pxr" in sys.modules and ahead.done() and ahead.result() is False
        print("ok")
    """)
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and p.stdout.strip() == "ok", p.stderr[-2000:]
