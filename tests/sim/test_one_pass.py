"""docs/performance.md ("Paying for the samples a ray needs"): the rollout marches its
rays in passes and probes a blocked row's alternative headings in order,
and "the ``eig`` and ``random`` rollouts of the shipped benchmark at
B = 4,096 are bitwise equal to those of the one-pass code".

The one-pass forms are what :func:`ignjax.sim.compact.one_pass` traces
(every free-space ray, sight line and depth ray marched to its end, all
seven alternatives probed). The batch is the bench's: the shipped episodes
repeated to 4,096 rows, the bench's keys (:func:`ignjax.bench.rollouts.bench_steps`).
Four rollouts of 4,096 episodes take many minutes on a small CPU, so the
comparison is a ``slow`` test; the default run compares each piece with its
one-pass form (tests/sim/test_sim.py, tests/sim/test_executor_geometry.py).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.agents import get_agent
from ignjax.episodes.dataset import load_benchmark
from ignjax.evaluate.runner import make_world
from ignjax.sim import env as E
from ignjax.sim import executor as X
from ignjax.sim.compact import one_pass
from ignjax.sim.observation import sight_batch
from ignjax.sim.rollout import episode_keys, rollout
from ignjax.data.shipped import EPISODES as SHIPPED_BENCHMARK

B = 4096


@pytest.fixture(scope="module")
def shipped():
    es = load_benchmark(SHIPPED_BENCHMARK)
    return es, make_world(es)


def _rollout(es, world, name):
    agent = get_agent(name)
    idx = np.arange(B) % len(es)
    specs = jax.tree.map(lambda a: a[idx], es.specs)
    res = rollout(world, specs, agent, agent.default_params(), episode_keys(0, np.arange(B)))
    return jax.tree.map(np.asarray, res)


def _programs(es, world) -> list[str]:
    """The traced programs of the three pieces that have a one-pass form, on 8 rows."""
    states = jax.vmap(lambda sp: E.reset(world, sp))(jax.tree.map(lambda a: a[:8], es.specs))
    s, pose, mask = states.episode.scene, states.pose, jnp.ones(8, bool)
    i = jnp.zeros(8, jnp.int32)
    return [str(jax.make_jaxpr(fn)()) for fn in (
        lambda: sight_batch(world, states, mask),
        lambda: X.cell_depth_batch(world, s, pose, i, i + 4, i + 1, mask),
        lambda: X.first_free_alternative(world, s, pose[:, :2], pose[:, 2], mask))]


def _bitwise_equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.slow
@pytest.mark.parametrize("name", ["eig", "random"])
def test_shipped_rollouts_equal_the_one_pass_code(shipped, name):
    es, world = shipped
    two = _programs(es, world)
    got = _rollout(es, world, name)
    with one_pass():
        one = _programs(es, world)
        want = _rollout(es, world, name)
    assert all(a != b for a, b in zip(one, two))  # the switch does give other programs
    leaves, ref = jax.tree_util.tree_leaves_with_path(got), jax.tree.leaves(want)
    assert len(leaves) == len(ref) > 20
    differ = [jax.tree_util.keystr(path) for (path, a), b in zip(leaves, ref) if not _bitwise_equal(a, b)]
    assert not differ, differ
    assert int(got[0].steps.sum()) > B  # episodes took decisions
