"""Host arrays that CPU devices share instead of copying (``ignjax.arrays.host_empty``), and the cache's
``.npz`` reader that fills them (``ignjax.cache.npz.read_npz``)."""

import zipfile

import jax
import numpy as np
import pytest
from jax.sharding import Mesh, NamedSharding, PartitionSpec as P

from ignjax.arrays import DEVICE_ALIGN, HUGE_PAGES_FROM, host_empty
from ignjax.cache.npz import NpzError, read_npz


@pytest.mark.parametrize("shape,dtype", [((3, 5), np.int32), ((0, 4), np.float32), ((HUGE_PAGES_FROM // 2 + 7,), np.uint16),
                                         ((7,), np.bool_)])
def test_host_empty_is_aligned_writable_and_of_its_shape(shape, dtype):
    a = host_empty(shape, dtype)
    assert a.shape == shape and a.dtype == np.dtype(dtype) and a.flags.writeable and a.flags.c_contiguous
    assert a.ctypes.data % DEVICE_ALIGN == 0 or a.size == 0  # an empty array has no data to align
    a.fill(1)
    assert int(a.sum()) == a.size


def test_cpu_devices_share_a_host_empty_array_instead_of_copying_it():
    cpus = jax.devices("cpu")
    a = host_empty((1000, 3), np.float32)
    a[:] = np.arange(3000, dtype=np.float32).reshape(1000, 3)
    one = jax.device_put(a, cpus[0])
    assert one.unsafe_buffer_pointer() == a.ctypes.data
    every = jax.device_put(a, NamedSharding(Mesh(np.array(cpus), ("d",)), P()))
    assert all(s.data.unsafe_buffer_pointer() == a.ctypes.data for s in every.addressable_shards)
    assert np.array_equal(np.asarray(every), a)


def test_read_npz_gives_what_np_load_gives_in_aligned_arrays(tmp_path):
    arrays = {"a": np.arange(12, dtype=np.float32).reshape(3, 4), "b": np.array([True, False]), "n": np.int64(7),
              "fortran": np.asfortranarray(np.arange(6.0).reshape(2, 3)), "empty": np.zeros((0, 3), np.int16),
              "text": np.array(["ab", "c"]), "big": np.arange(HUGE_PAGES_FROM // 4 + 5, dtype=np.int32)}
    p = tmp_path / "x.npz"
    np.savez(p, **arrays)
    got = read_npz(p)
    with np.load(p) as z:
        ref = {n: z[n] for n in z.files}
    assert set(got) == set(ref)
    for n in ref:
        assert got[n].dtype == ref[n].dtype and got[n].shape == ref[n].shape and np.array_equal(got[n], ref[n]), n
        assert got[n].ctypes.data % DEVICE_ALIGN == 0 or got[n].size == 0


def test_read_npz_refuses_what_the_store_never_writes(tmp_path):
    p = tmp_path / "x.npz"
    np.savez_compressed(p, a=np.arange(10))
    with pytest.raises(NpzError, match="compressed"):
        read_npz(p)
    np.savez(p, a=np.array([{"x": 1}], dtype=object))
    with pytest.raises(NpzError, match="Python objects"):
        read_npz(p)
    np.savez(p, a=np.arange(1000, dtype=np.int64))
    whole = p.read_bytes()
    p.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(zipfile.BadZipFile):  # the zip's directory is gone
        read_npz(p)
    with zipfile.ZipFile(p, "w") as z:  # a member whose header promises more data than it holds
        z.writestr("a.npy", whole[whole.index(b"\x93NUMPY"):][:300])
    with pytest.raises(NpzError, match="header says"):
        read_npz(p)
