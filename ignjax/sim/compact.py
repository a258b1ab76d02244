"""Masked batch maps that pay only for the rows that need the work.

Under ``vmap`` every episode pays for every branch: a batch where 60% of
the episodes MOVE, 12% ASK and the rest have finished still runs the
executor, the oracle and the perception for all of them. :func:`masked_map`
runs a per-row function on the rows a mask selects only: their indices are
compacted (``jnp.nonzero`` with a static size) and processed in fixed-size
chunks inside a loop whose trip count is the number of chunks the mask
needs, so the cost follows the number of selected rows (rounded up to a
chunk) while every shape stays static. Rows outside the mask keep their
``default`` values. The result is the same as ``where(mask, vmap(fn)(args),
default)`` row for row (tested), whatever the chunk size.
"""

from __future__ import annotations

import contextlib

import jax
import jax.numpy as jnp

CHUNKS = 8  # default chunk: 1/CHUNKS of the batch (at most that fraction of a batch is padding)

ONE_PASS = False
"""Read while a program is traced: true gives the batched ray casts and
probes their one-pass forms (every free-space ray, sight line and depth ray
marched to its end; all seven alternative headings of a blocked row probed)
instead of their passes (:func:`ignjax.sim.observation.sight_batch`,
:func:`ignjax.sim.executor.cell_depth_batch`,
:func:`ignjax.sim.executor.first_free_alternative`): the reference the tests
compare the rollouts with. Set it through :func:`one_pass`."""


@contextlib.contextmanager
def one_pass():
    """Programs traced inside take the one-pass forms (:data:`ONE_PASS`).
    JAX's caches are cleared on entry and on exit, so a program compiled in
    one form is never reused in the other."""
    global ONE_PASS
    jax.clear_caches()
    ONE_PASS = True
    try:
        yield
    finally:
        ONE_PASS = False
        jax.clear_caches()


def chunk_size(n_rows: int, chunks: int = CHUNKS) -> int:
    """Rows per chunk for a batch of ``n_rows``: ``ceil(n_rows / chunks)``, at least 1."""
    return max(1, -(-int(n_rows) // int(chunks)))


def even_chunk(n_rows: int, chunk: int) -> int:
    """A chunk size near ``chunk`` that divides ``n_rows`` (the largest
    divisor in [chunk / 2, chunk]), so a chunked map over all rows
    (``lax.map`` with ``batch_size``) has no remainder call to compile;
    ``chunk`` itself when there is none."""
    chunk = max(1, min(int(chunk), int(n_rows)))
    for c in range(chunk, (chunk + 1) // 2 - 1, -1):
        if n_rows % c == 0:
            return c
    return chunk


def masked_map(fn, mask, args, default, chunk: int | None = None, gather_back: bool = False):
    """``where(mask, vmap(fn)(args), default)``, computing ``fn`` on the selected rows only.

    Args:
        fn: one row's ``args`` -> a pytree shaped like one row of ``default``.
        mask: (B,) bool rows to compute.
        args: pytree of arrays with leading axis B.
        default: pytree with leading axis B: the result on unselected rows
            (and its dtypes are the result's).
        chunk: rows per vectorised call (static); default :func:`chunk_size`.
        gather_back: how the results reach their rows (the same values
            either way). False: each chunk's rows are written into
            ``default`` inside the loop (an indexed write, which XLA:CPU runs
            as a loop of one trip per row: cheap, and nothing is done for the
            rows not selected). True: each chunk's results go to a packed
            buffer, one contiguous block per chunk, and every row takes its
            result from there (by its rank in the selection) or from
            ``default`` in one gather and select after the loop: work for
            every row, but no write into ``default`` in the loop. Which is
            faster depends on the program around it (in the rollouts, the
            observation's update is faster gathered back and the ray passes
            are not; ``docs/performance.md``).

    Returns:
        A pytree like ``default``.
    """
    B = mask.shape[0]
    c = chunk_size(B) if chunk is None else max(1, min(int(chunk), B))
    n_chunks = -(-B // c)
    idx = jnp.nonzero(mask, size=n_chunks * c, fill_value=B)[0].astype(jnp.int32)
    n_sel = jnp.sum(mask.astype(jnp.int32))
    trips = (n_sel + c - 1) // c
    row_fn = jax.vmap(fn)

    def chunk_of(i):  # chunk i's rows (B past the selection) and their results
        rows = jax.lax.dynamic_slice(idx, (i * c,), (c,))
        return rows, row_fn(jax.tree.map(lambda a: a[jnp.minimum(rows, B - 1)], args))

    if not gather_back:
        def write(i, out):
            rows, vals = chunk_of(i)
            return jax.tree.map(lambda o, v: o.at[rows].set(v.astype(o.dtype), mode="drop", indices_are_sorted=True),
                                out, vals)

        return jax.lax.fori_loop(0, trips, write, default)

    def pack(i, out):
        vals = chunk_of(i)[1]
        return jax.tree.map(lambda o, v: jax.lax.dynamic_update_slice_in_dim(o, v.astype(o.dtype), i * c, 0), out, vals)

    packed = jax.lax.fori_loop(0, trips, pack, jax.tree.map(lambda d: jnp.zeros((n_chunks * c,) + d.shape[1:], d.dtype),
                                                             default))
    rank = jnp.maximum(jnp.cumsum(mask.astype(jnp.int32)) - 1, 0)  # a selected row's place in the selection
    return jax.tree.map(lambda p, d: jnp.where(mask.reshape((B,) + (1,) * (d.ndim - 1)), p[rank], d), packed, default)


def first_equal(keys, mask):
    """For each row, the smallest index of a ``mask``-ed row whose ``keys``
    all equal its own; rows outside ``mask`` map to themselves.

    Args:
        keys: sequence of (B,) integer or bool arrays, compared exactly.
        mask: (B,) bool rows that take part.

    Returns:
        (B,) int32 representative index per row: ``rep[rep] == rep``, and two
        masked rows share a representative exactly when their keys are equal.
    """
    B = mask.shape[0]
    iota = jnp.arange(B, dtype=jnp.int32)
    ops = [(~mask).astype(jnp.int32)] + [jnp.asarray(k).astype(jnp.int32) for k in keys] + [iota]
    srt = jax.lax.sort(ops, num_keys=len(ops) - 1, is_stable=True)
    key_sorted, order = srt[:-1], srt[-1]
    differs = jnp.zeros(B - 1, bool)
    for k in key_sorted:
        differs = differs | (k[1:] != k[:-1])
    start = jnp.concatenate([jnp.ones(1, bool), differs])
    run_start = jax.lax.cummax(jnp.where(start, iota, 0))
    rep = jnp.zeros(B, jnp.int32).at[order].set(order[run_start], unique_indices=True)
    return jnp.where(mask, rep, iota)
