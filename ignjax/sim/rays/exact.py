"""The exact ray path: ``mjx.ray`` with the cylinder fix, and the C references.

Distances are metres along a unit direction; a miss is ``+inf`` (MuJoCo's
``-1`` is converted) and the geom id of a miss is -1.

:func:`exact_rays` is ``mjx.ray`` on the compiled model, vmapped over rays
and jitted (one compiled function per scene and group selection, kept in a
small bounded cache). ``mjx.ray`` (mujoco-mjx 3.17) has no cylinder
intersection and silently ignores cylinder geoms, so :func:`exact_ray`
intersects the cylinders itself (the fast path's primitive test,
:func:`ignjax.sim.rays.fast.prim_hit`) and keeps the nearer hit; the result
matches ``mujoco.mj_ray``. The C references are :func:`mj_rays` (a loop
over ``mujoco.mj_ray``, any origins) and :func:`mj_multiray`
(``mujoco.mj_multiRay``, one origin). Rays are cast with ``flg_static=1``;
``geomgroup`` selects groups as in MuJoCo (a 6-sequence of flags, None =
every group).
"""

from __future__ import annotations

import functools
import math

import jax
import jax.numpy as jnp
import mujoco
import numpy as np

from ignjax.scenes.voxels import N_PRIM_COLUMNS, geom_prims
from ignjax.sim.rays.fast import prim_hit


def _group_mask(geomgroup) -> np.ndarray | None:
    if geomgroup is None:
        return None
    g = np.zeros(mujoco.mjNGROUP, np.uint8)
    vals = np.asarray(geomgroup).astype(np.uint8).ravel()
    g[:len(vals)] = vals[:mujoco.mjNGROUP]
    return g


def _cylinder_rows(compiled, geomgroup) -> tuple[np.ndarray, np.ndarray]:
    m, d = compiled.model, compiled.data
    mask = _group_mask(geomgroup)
    rows, ids = [], []
    for g in range(m.ngeom):
        if m.geom_type[g] != mujoco.mjtGeom.mjGEOM_CYLINDER:
            continue
        if mask is not None and not mask[min(int(m.geom_group[g]), mujoco.mjNGROUP - 1)]:
            continue
        mat = int(m.geom_matid[g])
        alpha = m.mat_rgba[mat, 3] if mat >= 0 else m.geom_rgba[g, 3]
        if alpha == 0:
            continue
        rows += geom_prims(m, d, g)
        ids.append(g)
    if not rows:
        return np.zeros((0, N_PRIM_COLUMNS), np.float32), np.zeros((0,), np.int32)
    return np.stack(rows).astype(np.float32), np.asarray(ids, np.int32)


def exact_ray(mjx_model, mjx_data, cylinders: jax.Array, cylinder_ids: jax.Array, pnt: jax.Array,
              vec: jax.Array, geomgroup: tuple[int, ...] = ()) -> tuple[jax.Array, jax.Array]:
    """``mjx.ray`` plus the cylinders it ignores, for one ray.

    Args:
        mjx_model, mjx_data: the MJX model and data.
        cylinders: (C, 18) cylinder primitives (:func:`ignjax.scenes.voxels.geom_prims`).
        cylinder_ids: (C,) their geom ids.
        pnt: (3,) origin.
        vec: (3,) direction.
        geomgroup: MuJoCo group flags (static), () for all.

    Returns:
        (dist () float32, +inf on a miss; geomid () int32, -1 on a miss).
    """
    from mujoco import mjx  # imported here: mujoco.mjx adds about 3 s to importing this module

    d, g = mjx.ray(mjx_model, mjx_data, pnt, vec, geomgroup=geomgroup)
    d = jnp.where(d < 0, jnp.inf, d)
    if cylinders.shape[0]:
        tc = jax.vmap(prim_hit, in_axes=(0, None, None))(cylinders, pnt, vec)
        k = jnp.argmin(tc)
        take = tc[k] < d
        d = jnp.where(take, tc[k], d)
        g = jnp.where(take, cylinder_ids[k], g)
    return d, g


_EXACT_CACHE_SIZE = 16  # compiled (scene, group selection) functions kept process-wide


@functools.lru_cache(maxsize=_EXACT_CACHE_SIZE)  # bounded; lru_cache's bookkeeping is thread-safe
def _exact_fn(compiled, key: tuple[int, ...] | None):
    """The jitted, vmapped :func:`exact_ray` of one compiled scene and group selection."""
    cyl, cid = _cylinder_rows(compiled, key)
    mx, dx = compiled.mjx_model, compiled.mjx_data
    cyl_j, cid_j = jnp.asarray(cyl), jnp.asarray(cid)
    gg = key or ()
    return jax.jit(jax.vmap(lambda p, v: exact_ray(mx, dx, cyl_j, cid_j, p, v, gg)))


def exact_rays(compiled, pnts, vecs, geomgroup=None) -> tuple[jax.Array, jax.Array]:
    """Exact distances of many rays with ``mjx.ray`` (jitted, vmapped).

    Args:
        compiled: a :class:`~ignjax.scenes.compile.CompiledScene`.
        pnts: (N, 3) origins.
        vecs: (N, 3) unit directions.
        geomgroup: MuJoCo group flags (6 values) or None for every group.

    Returns:
        dist: (N,) float32, +inf on a miss; geomid: (N,) int32, -1 on a miss.
    """
    key = None if geomgroup is None else tuple(int(bool(x)) for x in _group_mask(geomgroup))
    return _exact_fn(compiled, key)(jnp.asarray(pnts, jnp.float32), jnp.asarray(vecs, jnp.float32))


def mj_rays(compiled, pnts, vecs, geomgroup=None) -> tuple[np.ndarray, np.ndarray]:
    """C reference: ``mujoco.mj_ray`` for each ray (``flg_static=1``).

    Returns:
        dist: (N,) float64, +inf on a miss; geomid: (N,) int32, -1 on a miss.
    """
    m, d = compiled.model, compiled.data
    mask = _group_mask(geomgroup)
    pnts = np.asarray(pnts, np.float64).reshape(-1, 3)
    vecs = np.asarray(vecs, np.float64).reshape(-1, 3)
    out = np.empty(len(pnts))
    ids = np.empty(len(pnts), np.int32)
    gid = np.zeros(1, np.int32)
    for i in range(len(pnts)):
        out[i] = mujoco.mj_ray(m, d, pnts[i], vecs[i], mask, 1, -1, gid)
        ids[i] = gid[0]
    return np.where(out < 0, np.inf, out), ids


def mj_multiray(compiled, pnt, vecs, geomgroup=None, cutoff: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
    """C reference for rays from one point: ``mujoco.mj_multiRay``.

    Args:
        compiled: compiled scene.
        pnt: (3,) common origin.
        vecs: (N, 3) unit directions.
        geomgroup: group flags or None.
        cutoff: MuJoCo's ``cutoff``: geoms whose bounding sphere lies farther
            are skipped (a speed-up; hits beyond it can still be returned).

    Returns:
        dist: (N,) float64, +inf on a miss; geomid: (N,) int32, -1 on a miss.
    """
    m, d = compiled.model, compiled.data
    vecs = np.ascontiguousarray(np.asarray(vecs, np.float64).reshape(-1, 3))
    n = len(vecs)
    dist = np.empty(n)
    gid = np.empty(n, np.int32)
    cut = float(cutoff) if math.isfinite(cutoff) else mujoco.mjMAXVAL
    mujoco.mj_multiRay(m, d, np.asarray(pnt, np.float64), vecs.ravel(), _group_mask(geomgroup), 1, -1, gid, dist,
                       None, n, cut)
    return np.where(dist < 0, np.inf, dist), gid
