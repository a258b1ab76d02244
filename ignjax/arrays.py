"""Array helpers shared by every layer: the one pytree-dataclass decorator,
the numpy / jax.numpy dispatch of functions that accept either, functions
over whole pytrees (select, host copy, a batch of one and back) and numeric
vectors parsed from command-line text."""

from __future__ import annotations

import dataclasses
import mmap
import tomllib
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.errors import ConfigError


def pytree_dataclass(cls=None, *, static: tuple[str, ...] = (), untraced: tuple[str, ...] = ()):
    """Make ``cls`` a frozen dataclass registered as a JAX pytree.

    Every field is a pytree leaf (traced, batched by ``vmap``) except those
    named in ``static``, which are hashable metadata (part of the tree's
    structure, e.g. a configuration). ``cls`` may already be a dataclass
    (``@pytree_dataclass`` over ``@dataclass(frozen=True)``); otherwise it is
    made a frozen one. Use as ``@pytree_dataclass`` or
    ``@pytree_dataclass(static=("config",))``; change instances with
    :func:`dataclasses.replace`.

    ``untraced`` names static fields that traced code never reads
    (host-side objects kept beside the arrays): a compiled program's disk
    key leaves them out (:mod:`ignjax.cache.programs`), so they need no
    faithful description.
    """

    def wrap(c):
        if not dataclasses.is_dataclass(c):
            c = dataclasses.dataclass(frozen=True)(c)
        names = [f.name for f in dataclasses.fields(c)]
        unknown = set(static) - set(names)
        if unknown:
            raise TypeError(f"{c.__name__}: static fields {sorted(unknown)} are not fields")
        if set(untraced) - set(static):
            raise TypeError(f"{c.__name__}: untraced fields {sorted(set(untraced) - set(static))} are not static")
        meta = [n for n in names if n in static]
        c.__pytree_meta__, c.__untraced__ = tuple(meta), tuple(untraced)
        return jax.tree_util.register_dataclass(c, data_fields=[n for n in names if n not in static], meta_fields=meta)

    return wrap if cls is None else wrap(cls)


def xp(*arrays):
    """``numpy`` when every input is a numpy array or a Python scalar/sequence, else ``jax.numpy``.

    Functions written against the returned namespace run eagerly on host
    arrays (exact float64 where given) and trace under ``jit``/``vmap``.
    """
    host = (np.ndarray, np.generic, int, float, tuple, list)
    return np if all(isinstance(a, host) for a in arrays) else jnp


DEVICE_ALIGN = 64
"""Byte alignment at which a CPU device takes a host array as its buffer without a copy."""

HUGE_PAGES_FROM = 4 << 20
"""Size from which :func:`host_empty` asks the kernel for huge pages."""


def host_empty(shape, dtype) -> np.ndarray:
    """An uninitialised host array whose data is :data:`DEVICE_ALIGN`-byte
    aligned. ``jax.device_put`` gives CPU devices such an array itself as
    their buffer (on every device of a replicated placement) instead of a
    copy, so the large tables of a benchmark (the scene bank's ray grids,
    the goal fields) are built once in memory and never copied to the
    devices. Elsewhere it is an ordinary array. The array must not be
    written after it is put on a device."""
    dtype = np.dtype(dtype)
    n = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
    if n >= HUGE_PAGES_FROM and hasattr(mmap, "MADV_HUGEPAGE"):
        pages = mmap.mmap(-1, n)  # page-aligned; freed with the last array that views it
        try:
            pages.madvise(mmap.MADV_HUGEPAGE)
        except OSError:  # a kernel without transparent huge pages: ordinary pages
            pass
        return np.frombuffer(pages, np.uint8, n).view(dtype).reshape(shape)
    raw = np.empty(n + DEVICE_ALIGN, np.uint8)
    skip = -raw.ctypes.data % DEVICE_ALIGN
    return raw[skip:skip + n].view(dtype).reshape(shape)


def on_device(x, dtype=None) -> jax.Array:
    """Host data (numpy arrays, lists, scalars) as a device array, like
    ``jnp.asarray(x, dtype)`` (the same dtype, 64-bit types narrowed unless
    x64 is on) but copied by ``jax.device_put``: ``jnp.asarray`` of host data
    runs a small compiled program per shape and dtype, each compiled or
    looked up in the compilation cache, which adds up when a benchmark's
    tables are loaded."""
    return jax.device_put(np.asarray(x, dtype))


def take_rows(tree, idx):
    """Rows ``idx`` of every leaf of a pytree of arrays, cut on the host and
    put on the device (:func:`on_device`'s reason: indexing device arrays
    runs one small compiled program per leaf shape and dtype)."""
    return jax.device_put(jax.tree.map(lambda a: np.asarray(a)[idx], tree))


def stack_copies(tree, n: int):
    """Every leaf of a pytree repeated along a new leading axis of ``n`` (a
    sweep's settings), built on the host and put on the device."""
    return jax.device_put(jax.tree.map(lambda a: np.broadcast_to(np.asarray(a), (n,) + np.shape(a)).copy(), tree))


def tree_select(pred, on_true, on_false):
    """Elementwise ``where`` over two pytrees of the same structure; ``pred``
    selects along the leading axes (a () pred a whole tree, a (B,) pred rows
    of a batch)."""
    pred = jnp.asarray(pred)
    return jax.tree.map(lambda a, b: jnp.where(pred.reshape(pred.shape + (1,) * (jnp.ndim(a) - pred.ndim)), a, b),
                        on_true, on_false)


def numpy_tree(tree):
    """A pytree of device arrays as numpy arrays (host copy)."""
    return jax.tree.map(lambda a: np.asarray(a), tree)


def batch_of_one(tree):
    """A pytree with a leading batch axis of size 1 added to every leaf."""
    return jax.tree.map(lambda x: x[None], tree)


def only_row(tree):
    """Row 0 of a pytree with a leading batch axis (the inverse of :func:`batch_of_one`)."""
    return jax.tree.map(lambda x: x[0], tree)


def ragged_index(counts) -> tuple[np.ndarray, np.ndarray]:
    """``(owner, offset)`` of ``sum(counts)`` items laid out group after
    group: item ``i`` is number ``offset[i]`` of the ``counts[owner[i]]``
    items of group ``owner[i]`` (a ragged loop as flat arrays)."""
    counts = np.asarray(counts, np.int64)
    owner = np.repeat(np.arange(len(counts)), counts)
    starts = np.cumsum(counts) - counts
    return owner, np.arange(len(owner)) - starts[owner]


def parse_floats(text, n: int, where: str) -> tuple[float, ...]:
    """Numbers from comma-separated text (a command-line option).

    Args:
        text: e.g. ``"0.5,1.5,3"``.
        n: how many numbers are expected; 0 accepts any count.
        where: the option's name, for the error.

    Raises:
        ConfigError: naming ``where``, when a field is not a number or the count is wrong.
    """
    try:
        vals = tuple(float(v) for v in str(text).split(","))
    except ValueError as e:
        raise ConfigError(None, where, f"expected {n or 'some'} comma-separated numbers, got {text!r}") from e
    if n and len(vals) != n:
        raise ConfigError(None, where, f"expected {n} comma-separated numbers, got {len(vals)} in {text!r}")
    return vals


def parse_assignment(item: str, where: str = "--set") -> tuple[str, Any]:
    """``name=value`` from the command line: the dotted name and the value
    read as TOML (``3``, ``0.5``, ``true``, ``[1, 2]``, ``"text"``; a bare
    word is a string).

    Raises:
        ConfigError: naming ``where``, when there is no ``=`` or no dotted name.
    """
    if "=" not in item or "." not in item.split("=", 1)[0]:
        raise ConfigError(None, where, f"expected section.key=value, got {item!r}")
    name, raw = item.split("=", 1)
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return name.strip(), value


def field_docs(cls: type) -> dict[str, str]:
    """``field -> description`` from the ``Attributes:`` section of ``cls``'s
    docstring (a dataclass documented in the Google style); a docstring
    without that section may list ``name: text`` lines instead."""
    docs: dict[str, str] = {}
    lines = (cls.__doc__ or "").splitlines()
    start = next((i for i, line in enumerate(lines) if line.strip() == "Attributes:"), None)
    if start is None:
        for line in lines:
            if ":" in line:
                name, text = line.strip().split(":", 1)
                if name.isidentifier():
                    docs[name] = text.strip()
        return docs
    indent, name = None, None
    for line in lines[start + 1:]:
        if not line.strip():
            break
        depth = len(line) - len(line.lstrip())
        indent = depth if indent is None else indent
        if depth < indent:
            break
        if depth == indent and ":" in line:
            name, text = line.strip().split(":", 1)
            docs[name] = text.strip()
        elif name is not None:
            docs[name] += " " + line.strip()
    return docs


__all__ = ["batch_of_one", "field_docs", "numpy_tree", "on_device", "only_row", "parse_assignment", "parse_floats",
           "pytree_dataclass", "stack_copies", "take_rows", "tree_select", "xp"]
