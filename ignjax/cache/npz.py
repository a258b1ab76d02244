"""Reading an uncompressed ``.npz`` (what ``np.savez`` writes) straight into
arrays: each member's ``.npy`` data is read with one ``readinto`` into a
64-byte-aligned array (:func:`ignjax.arrays.host_empty`), which CPU devices
then take without a copy.

``np.load`` reads a member through ``zipfile`` in 256 KiB pieces, each a new
bytes object copied into the array and run through the zip's CRC-32; for
the quarter gigabyte of derived arrays a warm load of the shipped benchmark
reads, that was about twice the time and a second pass over the memory.
The zip's own CRC is not checked here: the store's entries carry a SHA-256
checksum of their arrays (:mod:`ignjax.cache.store`), which the caller checks.
"""

from __future__ import annotations

import os
import struct
import zipfile

import numpy as np

from ignjax.arrays import host_empty

_LOCAL_HEADER = struct.Struct("<4s22xHH")  # signature, ..., file name length, extra field length
_LOCAL_SIGNATURE = b"PK\x03\x04"


class NpzError(ValueError):
    """The file is not an uncompressed ``.npz`` of whole, non-object arrays."""


def read_npz(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """The arrays of the ``.npz`` at ``path`` by name.

    Raises:
        NpzError: a compressed member, an object array, a member that is not
            an ``.npy``, or one whose data is shorter than its header says.
        zipfile.BadZipFile, OSError: not a zip file (e.g. truncated), or unreadable.
    """
    out = {}
    with open(path, "rb") as f:
        with zipfile.ZipFile(f) as z:
            members = z.infolist()
        for info in members:
            if info.compress_type != zipfile.ZIP_STORED or not info.filename.endswith(".npy"):
                raise NpzError(f"member {info.filename!r} is compressed or not an .npy")
            f.seek(info.header_offset)
            sig, name_len, extra_len = _LOCAL_HEADER.unpack(f.read(_LOCAL_HEADER.size))
            if sig != _LOCAL_SIGNATURE:
                raise NpzError(f"member {info.filename!r} has no local header")
            start = info.header_offset + _LOCAL_HEADER.size + name_len + extra_len
            f.seek(start)
            out[info.filename[:-4]] = _read_npy(f, info, start)
    return out


def _read_npy(f, info: zipfile.ZipInfo, start: int) -> np.ndarray:
    version = np.lib.format.read_magic(f)
    header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
    shape, fortran, dtype = header(f)
    if dtype.hasobject:
        raise NpzError(f"member {info.filename!r} holds Python objects")
    a = host_empty(shape[::-1] if fortran else shape, dtype)
    if f.tell() - start + a.nbytes != info.file_size:
        raise NpzError(f"member {info.filename!r}: {info.file_size} bytes, its header says "
                       f"{f.tell() - start + a.nbytes}")
    if a.nbytes and f.readinto(memoryview(a.reshape(-1).view(np.uint8))) != a.nbytes:
        raise NpzError(f"member {info.filename!r} is cut short")
    return a.T if fortran else a


__all__ = ["NpzError", "read_npz"]
