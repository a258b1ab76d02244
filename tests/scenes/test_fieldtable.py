"""Goal fields at their own extents (ignjax.scenes.fieldtable): every look-up
reads what the padded (F, H, W) stack read, on the host and traced."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.errors import ConfigError
from ignjax.scenes.fieldtable import MAX_CELLS, FieldTable, padded_cells

SHAPE = (7, 9)
EXTENTS = [(7, 4), (3, 9), (5, 5), (1, 1), (7, 9)]


def _fields(seed: int = 0) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    out = []
    for h, w in EXTENTS:
        f = rng.uniform(0, 20, (h, w)).astype(np.float32)
        f[rng.random((h, w)) < 0.2] = np.inf  # unreachable cells inside the extent stay +inf
        out.append(f)
    return out


def _stack(fields) -> np.ndarray:
    H, W = SHAPE
    out = np.full((len(fields), H, W), np.inf, np.float32)
    for k, f in enumerate(fields):
        out[k, :f.shape[0], :f.shape[1]] = f
    return out


def _cells():
    """Every cell of the padded grid and a margin of cells outside it (clipped, as the stack was read)."""
    H, W = SHAPE
    r, c = np.meshgrid(np.arange(-3, H + 3), np.arange(-3, W + 3), indexing="ij")
    return r.reshape(-1), c.reshape(-1)


def _stack_read(stack, f, r, c):
    H, W = SHAPE
    return stack[f, np.clip(r, 0, H - 1), np.clip(c, 0, W - 1)]


def test_lookups_equal_the_padded_stack_on_host_and_traced():
    fields = _fields()
    stack = _stack(fields)
    table = FieldTable.of(fields, SHAPE)
    dev = jax.device_put(table)
    read = jax.jit(lambda t, f, r, c: t.at(f, r, c))
    r, c = _cells()
    for f in range(len(fields)):
        want = _stack_read(stack, f, r, c)
        got = table.at(f, r, c)
        assert isinstance(got, np.ndarray) and got.dtype == np.float32
        assert got.tobytes() == want.tobytes()
        traced = np.asarray(read(dev, jnp.int32(f), jnp.asarray(r, jnp.int32), jnp.asarray(c, jnp.int32)))
        assert traced.tobytes() == want.tobytes()
    # under vmap over episodes, one field each (as the simulator reads them)
    f = np.arange(len(fields), dtype=np.int32)
    got = jax.vmap(lambda f_, r_, c_: dev.at(f_, r_, c_))(f, np.full(len(f), 2, np.int32), np.arange(len(f), dtype=np.int32))
    assert np.asarray(got).tobytes() == _stack_read(stack, f, 2, np.arange(len(f))).tobytes()


def test_dense_round_trip_and_a_dense_stack_as_a_table():
    fields = _fields(1)
    stack = _stack(fields)
    table = FieldTable.of(fields, SHAPE)
    assert table.dense().tobytes() == stack.tobytes()
    assert len(table) == len(fields) and table.field(2).tobytes() == stack[2].tobytes()
    whole = FieldTable.from_dense(stack)
    r, c = _cells()
    for f in range(len(fields)):
        assert whole.at(f, r, c).tobytes() == table.at(f, r, c).tobytes()
    traced = FieldTable.from_dense(jnp.asarray(stack))
    assert np.asarray(traced.values).tobytes() == stack.reshape(-1).tobytes()


def test_layout_keeps_own_cells_and_pads_to_whole_fields():
    H, W = SHAPE
    cells = sum(h * w for h, w in EXTENTS)
    table = FieldTable.of(_fields(), SHAPE)
    assert table.values.shape == (padded_cells(EXTENTS, SHAPE),)
    assert table.values.shape[0] % (H * W) == 0 and cells <= table.values.shape[0] < cells + H * W
    assert np.isinf(table.values[cells:]).all()
    assert table.nbytes < _stack(_fields()).nbytes
    shapes = FieldTable.shapes(EXTENTS, SHAPE)
    assert jax.tree.map(lambda x: (x.shape, x.dtype), shapes) == jax.tree.map(lambda x: (x.shape, x.dtype), table)
    empty = FieldTable.of([], SHAPE)
    assert len(empty) == 0 and empty.values.shape == (H * W,)


def test_bad_extents_are_refused():
    with pytest.raises(ConfigError, match="padded grid 7 x 9"):
        FieldTable.of([np.zeros((8, 2), np.float32)], SHAPE)
    with pytest.raises(ConfigError, match="bank_mb"):
        FieldTable.layout([(50_000, 50_000)], (50_000, 50_000))
    start, ext, n = FieldTable.layout([(40_000, 40_000)], (40_000, 40_000))  # 1.6e9 cells: within int32's reach
    assert n <= MAX_CELLS and start.tolist() == [0] and ext.tolist() == [[40_000, 40_000]]


def test_world_holds_a_dense_stack_as_a_table(small_world):
    from ignjax.sim.world import World

    table = small_world.fields
    assert isinstance(table, FieldTable)
    stack = table.dense()
    again = World(small_world.bank, jnp.asarray(stack), small_world.config, fine=small_world.fine,
                  packed_obs=small_world.packed_obs)
    assert isinstance(again.fields, FieldTable) and len(again.fields) == len(table)
    assert again.fields.dense().tobytes() == stack.tobytes()
