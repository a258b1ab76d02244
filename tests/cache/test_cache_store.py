"""The on-disk cache: where it lives, its entries (checksummed, atomic,
evicted oldest first), and the scene arrays read through it, which are the
same bytes whether the cache was cold, warm or off."""

from __future__ import annotations

import dataclasses
import os
import time
import warnings

import numpy as np
import pytest

from ignjax.cache import ArrayStore, CacheWarning, cache_root, derived_store
from ignjax.scenes.compile import compile_scene
from ignjax.scenes.derived import cached_goal_fields, cached_navgrid
from ignjax.scenes.geodesic import goal_fields
from ignjax.scenes.navgrid import NavGrid, build_navgrid


def test_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.delenv("IGNJAX_NO_CACHE", raising=False)
    monkeypatch.setenv("IGNJAX_CACHE_DIR", str(tmp_path / "c"))
    assert cache_root() == tmp_path / "c" and derived_store().root == tmp_path / "c" / "derived"
    monkeypatch.delenv("IGNJAX_CACHE_DIR")
    assert cache_root().name == "ignjax"  # the platform's per-user cache folder
    for off in ("1", "yes", "true"):
        monkeypatch.setenv("IGNJAX_NO_CACHE", off)
        assert cache_root() is None and derived_store() is None
    monkeypatch.setenv("IGNJAX_NO_CACHE", "0")
    assert cache_root() is not None


def test_entry_round_trip_and_damage_is_a_miss(tmp_path):
    store = ArrayStore(tmp_path)
    arrays = {"a": np.arange(12, dtype=np.float32).reshape(3, 4), "b": np.array([True, False]), "n": np.int64(7)}
    assert store.get("k", "x") is None  # absent: a quiet miss
    assert store.put("k", "x", arrays)
    got = store.get("k", "x")
    assert set(got) == set(arrays) and all(np.array_equal(got[n], arrays[n]) and got[n].dtype == np.asarray(arrays[n]).dtype
                                           for n in arrays)
    p = store.path("k", "x")
    assert not list(p.parent.glob(".*.tmp-*"))  # written under a temporary name, then renamed
    whole = p.read_bytes()
    p.write_bytes(whole[: len(whole) // 2])  # truncated
    with pytest.warns(CacheWarning, match="damaged"):
        assert store.get("k", "x") is None
    flipped = bytearray(whole)
    at = whole.index(np.arange(12, dtype=np.float32).tobytes())  # inside array a's data: its checksum fails
    flipped[at + 5] ^= 0xFF
    p.write_bytes(bytes(flipped))
    with pytest.warns(CacheWarning, match="checksum"):
        assert store.get("k", "x") is None
    compressed = tmp_path / "compressed.npz"  # not what the store writes: a damaged entry, never read
    np.savez_compressed(compressed, **{n: np.asarray(a) for n, a in arrays.items()})
    p.write_bytes(compressed.read_bytes())
    with pytest.warns(CacheWarning, match="damaged"):
        assert store.get("k", "x") is None
    p.write_bytes(whole)
    with np.load(p) as z:
        raw = {n: z[n] for n in z.files}
    raw["a"] = raw["a"] + 1  # a whole zip whose arrays do not match the checksum they carry
    np.savez(p, **raw)
    with pytest.warns(CacheWarning, match="checksum"):
        assert store.get("k", "x") is None
    p.write_bytes(whole)
    assert np.array_equal(store.get("k", "x")["a"], arrays["a"])


def test_unwritable_folder_warns_once_and_goes_on(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    store = ArrayStore(blocker / "cache")
    with pytest.warns(CacheWarning, match="cannot write") as caught:
        assert not store.put("k", "x", {"a": np.zeros(3)})
        assert not store.put("k", "y", {"a": np.zeros(3)})
    assert len(caught) == 1 and store.get("k", "x") is None


def test_eviction_deletes_the_least_recently_used_first(tmp_path):
    one = {"a": np.zeros(1000, np.float64)}
    size = None
    store = ArrayStore(tmp_path, bound_bytes=10**9)
    for i, name in enumerate(("old", "used", "new")):
        store.put("k", name, one)
        os.utime(store.path("k", name), (1000.0 + i, 1000.0 + i))
        size = store.path("k", name).stat().st_size
    store.get("k", "old")  # a hit counts as a use: "old" is now the most recent
    store.bound_bytes = 3 * size
    store.put("k", "newest", one)
    assert not store.path("k", "used").exists()
    assert all(store.path("k", n).exists() for n in ("old", "new", "newest"))


def _grid_arrays(g: NavGrid) -> dict:
    return {f.name: getattr(g, f.name) for f in dataclasses.fields(NavGrid)}


def _same_grid(a: NavGrid, b: NavGrid) -> None:
    for name, x in _grid_arrays(a).items():
        y = getattr(b, name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), name
        else:
            assert x == y and type(x) is type(y), name


def test_grid_and_fields_are_the_same_bytes_cold_warm_and_off(two_room_scene, monkeypatch, tmp_path):
    compiled = compile_scene(two_room_scene)
    reference = build_navgrid(compiled)
    targets = [i for i, inst in enumerate(two_room_scene.instances) if not inst.structural][:3]
    rooms = [reference.room_index(two_room_scene.instances[i].room) for i in targets]
    direct = goal_fields(reference, [two_room_scene.instances[i].bbox for i in targets], rooms, 1.0)
    # on a larger padded grid (a bank's, shared by all its scenes): the same bytes, so one entry serves both
    H, W = reference.shape
    wide = goal_fields(reference, [two_room_scene.instances[i].bbox for i in targets], rooms, 1.0, (H + 45, W + 70))
    assert wide.tobytes() == direct.tobytes()
    monkeypatch.setenv("IGNJAX_NO_CACHE", "1")
    _same_grid(cached_navgrid(compiled), reference)
    monkeypatch.delenv("IGNJAX_NO_CACHE")
    monkeypatch.setenv("IGNJAX_CACHE_DIR", str(tmp_path))
    with warnings.catch_warnings():
        warnings.simplefilter("error", CacheWarning)
        cold = cached_navgrid(compiled)
        warm = cached_navgrid(compiled)
        _same_grid(cold, reference)
        _same_grid(warm, reference)
        assert len(list((tmp_path / "derived" / "navgrid").glob("*.npz"))) == 1
        # fields: one cached first, then all three (the two missing ones in a padded batch)
        first = cached_goal_fields(compiled, warm, targets[:1], rooms[:1], 1.0, batch=4)
        every = cached_goal_fields(compiled, warm, targets, rooms, 1.0, batch=4)
        again = cached_goal_fields(compiled, warm, targets, rooms, 1.0, batch=4)
    assert first[0].tobytes() == direct[0].tobytes()
    assert [f.tobytes() for f in every] == [f.tobytes() for f in again] == [f.tobytes() for f in direct]
    # a copy of the scene under another name is the same entry
    copy = dataclasses.replace(compiled, scene=dataclasses.replace(compiled.scene, id="copy"))
    assert cached_navgrid(copy).scene_id == "copy"
    assert len(list((tmp_path / "derived" / "navgrid").glob("*.npz"))) == 1


def test_a_damaged_grid_entry_is_rebuilt(two_room_scene, monkeypatch, tmp_path):
    monkeypatch.setenv("IGNJAX_CACHE_DIR", str(tmp_path))
    compiled = compile_scene(two_room_scene)
    reference = cached_navgrid(compiled)
    (entry,) = (tmp_path / "derived" / "navgrid").glob("*.npz")
    entry.write_bytes(entry.read_bytes()[:-100])
    stamp = entry.stat().st_mtime_ns
    time.sleep(0.01)
    with pytest.warns(CacheWarning, match="damaged"):
        rebuilt = cached_navgrid(compiled)
    _same_grid(rebuilt, reference)
    assert entry.stat().st_mtime_ns != stamp
    with warnings.catch_warnings():
        warnings.simplefilter("error", CacheWarning)
        _same_grid(cached_navgrid(compiled), reference)  # the rewritten entry is whole
