"""Difficulty factors, scores and bins (paper Appendix B, Eq. difficulty)."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from ignjax.episodes import difficulty as dif
from ignjax.errors import ConfigError


def test_factors_follow_documented_normalisations():
    norms = dif.FactorNorms(distractor_cap=16, room_cap=4, start_cap=15)
    f = dif.difficulty_factors(np.array([0, 2, 16, 40]), np.array([0, 1, 4, 9]), np.array([1.0, 0.25, 0.0, 0.5]),
                               np.array([0.0, 7.5, 15.0, 30.0]), norms)
    assert f.shape == (4, 4) and f.dtype == np.float64
    np.testing.assert_allclose(f[:, 0], [0, math.log(3) / math.log(17), 1, 1])
    np.testing.assert_allclose(f[:, 1], [0, math.log(2) / math.log(5), 1, 1])
    np.testing.assert_allclose(f[:, 2], [0, 0.75, 1, 0.5])
    np.testing.assert_allclose(f[:, 3], [0, 0.5, 1, 1])
    assert np.all((f >= 0) & (f <= 1))


def test_rho_edge_cases():
    # no distractors -> nothing to disambiguate; distractors but no anchors -> relations cannot help
    np.testing.assert_allclose(dif.context_rho(np.array([3, 0, 4, 0]), np.array([1, 0, 2, 0]), np.array([0, 0, 2, 3])),
                               [1.0, 1.0, 0.5, 0.0])


def test_score_is_alpha_dot_factors_and_bins_use_thresholds():
    rng = np.random.default_rng(0)
    f = rng.uniform(0, 1, (200, 4))
    d = dif.difficulty_score(f)
    manual = np.array([sum(a * x for a, x in zip(dif.DEFAULT_ALPHA, row)) for row in f])
    np.testing.assert_allclose(d, manual, rtol=0, atol=1e-12)
    bins = dif.difficulty_bin(d)
    assert np.all(bins[manual < 0.30] == 0)
    assert np.all(bins[(manual >= 0.30) & (manual < 0.60)] == 1)
    assert np.all(bins[manual >= 0.60] == 2)
    # boundaries belong to the upper bin
    np.testing.assert_array_equal(dif.difficulty_bin(np.array([0.2999, 0.30, 0.5999, 0.60])), [0, 1, 1, 2])


def test_batched_settings_match_per_setting_loop_and_jit_vmap():
    rng = np.random.default_rng(1)
    f = rng.uniform(0, 1, (50, 4))
    alphas = rng.dirichlet(np.ones(4), size=7)
    thr = np.sort(rng.uniform(0.1, 0.9, (7, 2)), axis=1)
    d, b = dif.score_and_bin(f, alphas, thr)
    assert d.shape == (7, 50) and b.shape == (7, 50)
    for k in range(7):
        np.testing.assert_allclose(d[k], f @ alphas[k], atol=1e-12)
        np.testing.assert_array_equal(b[k], dif.difficulty_bin(f @ alphas[k], thr[k]))
    dj, bj = jax.jit(dif.score_and_bin)(jnp.asarray(f), jnp.asarray(alphas), jnp.asarray(thr))
    np.testing.assert_allclose(np.asarray(dj), d, atol=1e-5)
    vm = jax.vmap(lambda a, t: dif.difficulty_bin(dif.difficulty_score(jnp.asarray(f, jnp.float32), a), t))
    agree = np.mean(np.asarray(vm(jnp.asarray(alphas, jnp.float32), jnp.asarray(thr, jnp.float32))) == b)
    assert agree > 0.99  # float32 vs float64 only differ exactly at a boundary


@pytest.mark.parametrize("alpha,msg", [((0.5, 0.5, 0.5, -0.5), "negative"), ((0.2, 0.2, float("nan"), 0.6), "NaN"),
                                       ((0.3, 0.3, 0.3, 0.3), "sum to 1"), ((0.5, 0.5), "4 entries")])
def test_bad_alpha_rejected(alpha, msg):
    with pytest.raises(ConfigError, match=msg):
        dif.validate_alpha(alpha)


def test_alpha_normalised_only_on_request():
    assert dif.validate_alpha((1, 1, 1, 1), normalize=True) == (0.25, 0.25, 0.25, 0.25)
    assert dif.validate_alpha(dif.DEFAULT_ALPHA) == dif.DEFAULT_ALPHA


@pytest.mark.parametrize("thr", [(0.6, 0.3), (0.3, 0.3), (-0.1, 0.5), (0.2, float("inf"))])
def test_bad_thresholds_rejected(thr):
    with pytest.raises(ConfigError, match="thresholds"):
        dif.validate_thresholds(thr)
