"""The environment's spaces, gymnax-style: a :class:`Box` of observations
and a :class:`Discrete` set of actions, each with a jittable ``sample`` and
a ``contains`` check (the Gymnasium adapter turns them into Gymnasium's)."""

from __future__ import annotations

from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np


@dataclass(frozen=True, eq=False)
class Box:
    """Real vectors of ``shape`` between ``low`` and ``high`` (numpy arrays of that shape; inf for unbounded)."""

    low: np.ndarray
    high: np.ndarray
    shape: tuple[int, ...]
    dtype: type = np.float32

    def sample(self, key: jax.Array) -> jax.Array:
        """A value drawn uniformly within the bounds (unbounded entries: a standard normal, folded onto their side)."""
        lo, hi = jnp.asarray(self.low), jnp.asarray(self.high)
        u = jax.random.uniform(key, self.shape, minval=jnp.where(jnp.isfinite(lo), lo, 0.0),
                               maxval=jnp.where(jnp.isfinite(hi), hi, 1.0))
        z = jnp.abs(jax.random.normal(jax.random.fold_in(key, 1), self.shape))
        return jnp.where(jnp.isfinite(hi), u, jnp.where(jnp.isfinite(lo), lo + z, z)).astype(self.dtype)

    def contains(self, x) -> bool:
        x = np.asarray(x)
        return x.shape == self.shape and bool(np.all((x >= self.low) & (x <= self.high)))


@dataclass(frozen=True)
class Discrete:
    """The integers ``0 .. n - 1``."""

    n: int
    dtype: type = np.int32

    @property
    def shape(self) -> tuple[int, ...]:
        return ()

    def sample(self, key: jax.Array, mask=None) -> jax.Array:
        """A uniform draw; with ``mask`` ((n,) bool) among the allowed values only."""
        logits = jnp.zeros(self.n) if mask is None else jnp.where(mask, 0.0, -jnp.inf)
        return jax.random.categorical(key, logits).astype(self.dtype)

    def contains(self, x) -> bool:
        x = np.asarray(x)
        return x.shape == () and np.issubdtype(x.dtype, np.integer) and 0 <= int(x) < self.n


__all__ = ["Box", "Discrete"]
