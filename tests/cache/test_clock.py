"""The time split of ``time_to_result`` (ignjax.cache.clock): phases that
nest count once, compile spans are taken out of load spans, and the clock
counts programs compiled and loaded from JAX's events."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.cache.clock import CompileClock, in_phase, phase, phase_spans, split, union_seconds


def test_union_of_spans():
    assert union_seconds([]) == 0
    assert union_seconds([(0, 2), (1, 3), (5, 6), (5.5, 5.7)]) == pytest.approx(4)
    assert union_seconds([(4, 5), (0, 10)]) == pytest.approx(10)


def test_split_takes_compile_time_out_of_load_time():
    # load 0..10 and 20..25; compile 2..4 (inside), 9..12 (across the end), 30..31 (outside)
    got = split([(0, 10), (20, 25)], [(2, 4), (9, 12), (30, 31)])
    assert got["compile_s"] == pytest.approx(6)
    assert got["load_s"] == pytest.approx(10 - 2 - 1 + 5)


def test_nested_spans_of_a_phase_count_once():
    before = len(phase_spans("test-nested"))

    @in_phase("test-nested")
    def inner():
        with phase("test-nested"):
            return 3

    with phase("test-nested"):
        assert inner() == 3
    assert inner() == 3
    spans = phase_spans("test-nested")[before:]
    assert len(spans) == 2 and all(a <= b for a, b in spans)
    assert spans[0][1] <= spans[1][0]


def test_the_clock_counts_each_program_once_and_only_while_started():
    clock = CompileClock().start()
    f = jax.jit(lambda x: jnp.sin(x) * 3 + 1)
    f(np.ones(7, np.float32)).block_until_ready()
    f(np.ones(7, np.float32)).block_until_ready()  # the same program: no new event
    assert clock.programs == 1  # inputs from numpy: no program but f's
    n = clock.programs
    f(np.ones(9, np.float32)).block_until_ready()  # another shape: another program
    assert clock.programs == n + 1 and clock.names == ["jit(<lambda>)"] * (n + 1)
    assert clock.spans and union_seconds(clock.spans) > 0
    clock.stop()
    f(np.ones(11, np.float32)).block_until_ready()
    assert clock.programs == n + 1
