"""The RL environment's parameters (:class:`EnvParams`), their checks and
the per-episode cost distribution (:func:`draw_costs`).

The parameters are a pytree passed to every ``reset`` / ``step`` (the
gymnax convention): the world (scene bank and the targets' geodesic fields),
the pool of episodes that resets draw from, the question costs and how they
are drawn, and the reward's settings. The world is an argument rather than
a constant of the environment so that a jitted program takes it as an input
(the shipped bank is about half a gigabyte) and a sharded one holds one copy
per device.

**Episode pool and sampling rule.** Every reset draws its episode uniformly
with replacement from ``pool`` (any episode file: the shipped benchmark, a
procedural or an imported one, loaded with
:func:`ignjax.episodes.dataset.load_benchmark`), with the reset's key; the
episode's perception noise (``SimConfig.miss_rate``, ``confusion_rate``)
comes from the same key.

**Cost distribution** (``sample_costs``, on by default for training): each
episode's costs are ``costs * s`` with one scale ``s`` drawn log-uniformly in
``cost_scale`` = [0.25, 8] and shared by the four types; with probability
``per_type_prob`` (0.25) each type draws a scale of its own instead (same
range), so a policy sees the types' costs move apart as well as together.
The range is the in-the-loop cost sweep's (x0.25 .. x8), so one policy
serves every point of it. ``sample_costs=False`` charges ``costs`` as they
are (evaluation at fixed costs).
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.arrays import pytree_dataclass
from ignjax.errors import ConfigError
from ignjax.protocol import LOCKED_COSTS, N_QUESTION_TYPES
from ignjax.sim import types as T
from ignjax.sim.env import check_specs
from ignjax.sim.world import World

COST_SCALE = (0.25, 8.0)
"""Default range of the per-episode cost scale (log-uniform), the in-the-loop sweep's."""
PER_TYPE_PROB = 0.25
"""Default probability that an episode's four types draw their scales apart."""
TAU = 1.5
"""Default success threshold of the reward, metres (the paper's WSR@1.5 column)."""
GAMMA = 0.99
"""Default discount the shaping term is consistent with."""
SHAPING_CAP = 10.0
"""Metres at which the shaping potential's distance is capped (unreachable points read as this far)."""


@pytree_dataclass
class EnvParams:
    """Everything ``reset`` / ``step`` read besides the state.

    Attributes:
        world: the simulator's :class:`~ignjax.sim.world.World` (its
            ``config`` is the environment's).
        pool: :class:`~ignjax.sim.types.EpisodeSpec` with a leading axis E
            (E >= 1, every episode valid): the episodes resets draw from.
        costs: (4,) float32 the per-type question costs (the locked costs by
            default); the centre of the drawn costs when ``sample_costs``.
        sample_costs: () bool draw each episode's costs (:func:`draw_costs`).
        cost_scale: (2,) float32 (low, high) of the log-uniform cost scale.
        per_type_prob: () float32 probability of a scale per type.
        tau: () float32 success threshold of the reward, metres.
        shaping: () float32 weight of the potential-based shaping term
            (0: off, the default).
        gamma: () float32 the discount the shaping term is consistent with.
    """

    world: World
    pool: T.EpisodeSpec
    costs: jax.Array
    sample_costs: jax.Array
    cost_scale: jax.Array
    per_type_prob: jax.Array
    tau: jax.Array
    shaping: jax.Array
    gamma: jax.Array


def make_params(world: World, pool: T.EpisodeSpec, *, costs=LOCKED_COSTS, sample_costs: bool = True,
                cost_scale=COST_SCALE, per_type_prob: float = PER_TYPE_PROB, tau: float = TAU, shaping: float = 0.0,
                gamma: float = GAMMA) -> EnvParams:
    """Checked parameters (:func:`check_params`); the pool's invalid rows (batch padding) are dropped first.

    Raises:
        ConfigError: a value out of range, or no valid episode in the pool.
    """
    valid = np.asarray(pool.valid, bool).reshape(-1)
    if valid.size and not valid.all():
        pool = jax.tree.map(lambda a: a[np.flatnonzero(valid)], pool)
    f32 = lambda v: jnp.asarray(v, jnp.float32)  # noqa: E731
    params = EnvParams(world=world, pool=pool, costs=f32(costs), sample_costs=jnp.asarray(bool(sample_costs)),
                       cost_scale=f32(cost_scale), per_type_prob=f32(per_type_prob), tau=f32(tau), shaping=f32(shaping),
                       gamma=f32(gamma))
    check_params(params)
    return params


def _fail(name: str, reason: str):
    raise ConfigError(None, f"rl.{name}", reason)


def _scalar(params: EnvParams, name: str, lo: float, hi: float, lo_open: bool, hi_open: bool = False) -> float:
    v = np.asarray(getattr(params, name), np.float64)
    if v.shape != ():
        _fail(name, f"must be a number, got shape {v.shape}")
    x = float(v)
    ok = math.isfinite(x) and (x > lo if lo_open else x >= lo) and (x < hi if hi_open else x <= hi)
    if not ok:
        _fail(name, f"must lie in {'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}, got {x:g}")
    return x


def check_params(params: EnvParams) -> None:
    """Reject parameters out of range (host side, before anything is traced).

    Raises:
        ConfigError: naming the parameter (``rl.costs``, ``rl.pool``, ...) and the allowed range.
    """
    costs = np.asarray(params.costs, np.float64)
    if costs.shape != (N_QUESTION_TYPES,):
        _fail("costs", f"must be {N_QUESTION_TYPES} per-type costs, got shape {costs.shape}")
    if not np.all(np.isfinite(costs)) or np.any(costs < 0):
        _fail("costs", f"must be finite and >= 0, got {costs.tolist()}")
    scale = np.asarray(params.cost_scale, np.float64)
    if scale.shape != (2,) or not np.all(np.isfinite(scale)) or not 0 < scale[0] <= scale[1]:
        _fail("cost_scale", f"must be (low, high) with 0 < low <= high, got {scale.tolist()}")
    _scalar(params, "per_type_prob", 0.0, 1.0, False)
    _scalar(params, "tau", 0.0, math.inf, True, True)
    _scalar(params, "gamma", 0.0, 1.0, True)
    _scalar(params, "shaping", 0.0, math.inf, False, True)
    n = int(np.shape(params.pool.scene)[0]) if np.ndim(params.pool.scene) else 0
    if n == 0:
        _fail("pool", "is empty: the environment needs at least one valid episode to reset to")
    if not np.all(np.asarray(params.pool.valid)):
        _fail("pool", "holds invalid (padding) episodes; build the parameters with make_params, which drops them")
    check_specs(params.world, params.pool)


def draw_costs(key: jax.Array, params: EnvParams) -> jax.Array:
    """(4,) float32 one episode's costs (module docstring); ``params.costs`` when ``sample_costs`` is off."""
    k_shared, k_types, k_mode = jax.random.split(key, 3)
    lo, hi = jnp.log(params.cost_scale[0]), jnp.log(params.cost_scale[1])
    shared = jax.random.uniform(k_shared, (), minval=lo, maxval=hi)
    per_type = jax.random.uniform(k_types, (N_QUESTION_TYPES,), minval=lo, maxval=hi)
    apart = jax.random.uniform(k_mode) < params.per_type_prob
    scale = jnp.exp(jnp.where(apart, per_type, shared))
    return jnp.where(params.sample_costs, params.costs * scale, params.costs).astype(jnp.float32)


def pool_size(params: EnvParams) -> int:
    """Episodes in the pool."""
    return int(params.pool.scene.shape[0])


__all__ = ["COST_SCALE", "EnvParams", "GAMMA", "PER_TYPE_PROB", "SHAPING_CAP", "TAU", "check_params", "draw_costs",
           "make_params", "pool_size"]
