"""masked_map: the selected rows computed, the others kept, for any chunk size."""

from __future__ import annotations

import re

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.sim.compact import chunk_size, even_chunk, first_equal, masked_map


def _fn(x):
    a, b = x
    return {"sum": jnp.sum(a * b) + jnp.sin(b[0]), "pair": jnp.stack([a[0], b[-1]]), "flag": a[1] > b[1]}


@pytest.mark.parametrize("gather_back", [False, True])
@pytest.mark.parametrize("chunk", [None, 1, 3, 7, 40])
@pytest.mark.parametrize("density", [0.0, 0.1, 0.5, 1.0])
def test_masked_map_equals_where_of_vmap(chunk, density, gather_back):
    rng = np.random.default_rng(int(density * 10) + (chunk or 0))
    B = 37
    a = jnp.asarray(rng.normal(size=(B, 5)), jnp.float32)
    b = jnp.asarray(rng.normal(size=(B, 5)), jnp.float32)
    mask = jnp.asarray(rng.random(B) < density)
    default = {"sum": jnp.full(B, -7.0), "pair": jnp.zeros((B, 2)), "flag": jnp.ones(B, bool)}
    got = jax.jit(lambda m, x, d: masked_map(_fn, m, x, d, chunk, gather_back))(mask, (a, b), default)
    full = jax.vmap(_fn)((a, b))
    want = jax.tree.map(lambda f, d: jnp.where(mask.reshape((B,) + (1,) * (f.ndim - 1)), f, d), full, default)
    for k in want:  # floats to rounding: XLA may vectorise a chunk of one row differently from a wide one
        if want[k].dtype.kind == "f":
            np.testing.assert_allclose(np.asarray(got[k]), np.asarray(want[k]), rtol=1e-6, atol=1e-6, err_msg=k)
        else:
            np.testing.assert_array_equal(np.asarray(got[k]), np.asarray(want[k]), err_msg=k)
        assert got[k].dtype == default[k].dtype


@pytest.mark.parametrize("density", [0.0, 0.03, 0.5, 1.0])
def test_masked_map_gathered_back_gives_the_written_bits(density):
    """Both ways of putting the rows back give every row the same bits (each row computed in the same chunk)."""
    rng = np.random.default_rng(int(density * 100))
    B, c = 1000, 128
    mask = jnp.asarray(rng.random(B) < density)
    x = jnp.asarray(rng.normal(size=(B, 3)), jnp.float32)
    default = (jnp.full((B, 3), 9.0, jnp.float32), jnp.arange(B, dtype=jnp.int32))

    def fn(r):
        return jnp.sin(r) * 2.0 + 1.0, jnp.argmax(r).astype(jnp.int32)

    run = jax.jit(lambda m, a, d, g: masked_map(fn, m, a, d, c, g), static_argnums=3)
    written, gathered = run(mask, x, default, False), run(mask, x, default, True)
    for w, g, d in zip(written, gathered, default):
        np.testing.assert_array_equal(np.asarray(g), np.asarray(w))
        assert g.dtype == d.dtype
    np.testing.assert_array_equal(np.asarray(gathered[1])[~np.asarray(mask)], np.arange(B)[~np.asarray(mask)])


def test_masked_map_gathered_back_writes_nothing_into_default():
    """``gather_back``: no indexed write (a scatter) in the compiled program; the default form has one."""
    B = 512
    mask = jnp.arange(B) % 3 == 0
    args = jnp.ones((B, 4), jnp.float32)
    default = jnp.zeros(B, jnp.float32)

    def scatters(g):
        text = jax.jit(lambda m, a, d: masked_map(jnp.sum, m, a, d, 64, g)).lower(mask, args, default).compile().as_text()
        return [line for line in text.splitlines() if re.search(r'op_name="[^"]*/scatter"', line)]

    assert scatters(False) and not scatters(True)


def test_masked_map_runs_fn_only_on_the_chunks_it_needs():
    """The loop's trip count follows the selected rows: fn sees ceil(n / chunk) chunks."""
    B, c = 20, 4
    calls = []

    def fn(x):
        jax.debug.callback(lambda v: calls.append(int(v)), x)
        return x * 2

    mask = jnp.zeros(B, bool).at[jnp.array([1, 5, 6, 19, 13])].set(True)
    out = masked_map(fn, mask, jnp.arange(B), jnp.zeros(B, jnp.int32), c)
    jax.block_until_ready(out)
    np.testing.assert_array_equal(np.asarray(out), np.where(np.asarray(mask), np.arange(B) * 2, 0))
    assert sorted(calls)[:5] == [1, 5, 6, 13, 19] and len(calls) == 2 * c  # 5 rows -> 2 chunks of 4


def test_chunk_size():
    assert chunk_size(1) == 1 and chunk_size(8) == 1 and chunk_size(9) == 2 and chunk_size(4096) == 512


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_first_equal_is_the_first_masked_row_with_equal_keys(seed):
    rng = np.random.default_rng(seed)
    B = 50
    keys = [rng.integers(0, 3, B), rng.integers(-1, 2, B), rng.random(B) < 0.5]
    mask = rng.random(B) < 0.8
    got = np.asarray(jax.jit(first_equal)([jnp.asarray(k) for k in keys], jnp.asarray(mask)))
    for r in range(B):
        if not mask[r]:
            assert got[r] == r
            continue
        same = [s for s in range(B) if mask[s] and all(k[s] == k[r] for k in keys)]
        assert got[r] == same[0], (r, got[r], same)
    assert np.all(got[got] == got)


def test_even_chunk_divides_the_rows_when_it_can():
    assert even_chunk(4096, 512) == 512
    assert even_chunk(500, 63) == 50 and 500 % 50 == 0
    assert even_chunk(97, 13) == 13  # a prime: no divisor in [7, 13], the chunk itself
    assert even_chunk(10, 40) == 10
