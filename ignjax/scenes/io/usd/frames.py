"""Frames and units of a USD stage: world transforms in metres, Z up, and
the unit of every length value when layers author their own
``metersPerUnit`` (the rules are in :mod:`ignjax.scenes.io.usd.load`);
the small 4x4 matrix helpers the importer uses.
"""

from __future__ import annotations

import math

import numpy as np
from pxr import Sdf, Usd, UsdGeom

from ignjax.errors import SceneError

TIME = Usd.TimeCode.EarliestTime()
"""The time every value is read at."""

_TRANSLATE_OPS = frozenset(
    getattr(UsdGeom.XformOp, n) for n in ("TypeTranslate", "TypeTranslateX", "TypeTranslateY", "TypeTranslateZ", "TypeTransform")
    if hasattr(UsdGeom.XformOp, n)
)
Y_TO_Z = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
"""Y-up -> Z-up: (x, y, z) -> (x, -z, y)."""


def col(gf_matrix) -> np.ndarray:
    """Gf (row-vector) 4x4 -> numpy column-vector convention."""
    return np.array(gf_matrix, dtype=np.float64).T


def scale4(s: float) -> np.ndarray:
    """4x4 uniform scale by ``s``."""
    return np.diag([s, s, s, 1.0])


def pose(position, yaw: float) -> np.ndarray:
    """4x4 rigid transform: turn ``yaw`` about +Z, then move to ``position``."""
    c, s = math.cos(yaw), math.sin(yaw)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:3, 3] = position
    return m


def apply(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Points mapped by a 4x4 (column-vector) transform."""
    # Shape: (N, 3) -> (N, 3)
    return pts @ m[:3, :3].T + m[:3, 3]


def wrap(angle: float) -> float:
    """Angle wrapped to (-pi, pi]."""
    a = math.remainder(angle, 2 * math.pi)
    return math.pi if a == -math.pi else a


def quat_from_matrix(r: np.ndarray) -> tuple[float, float, float, float]:
    """(w, x, y, z) unit quaternion of a 3x3 rotation matrix, w >= 0.

    Kept instead of ``scipy.spatial.transform.Rotation.from_matrix``, whose
    quaternions differ from these in the last bits for 58 % of random
    rotations (imported scenes would change).
    """
    m = np.asarray(r, dtype=np.float64)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    q = np.asarray(q)
    q = q / np.linalg.norm(q)
    if q[0] < 0:
        q = -q
    return tuple(float(v) for v in q)


def _authored_mpu(layer) -> float | None:
    root = layer.pseudoRoot
    if root is not None and root.HasInfo("metersPerUnit"):
        try:
            v = float(root.GetInfo("metersPerUnit"))
        except (TypeError, ValueError):
            return None
        return v if math.isfinite(v) and v > 0 else None
    return None


def nodes(prim_index) -> list:
    """The prim index's nodes in strength order (strongest first)."""
    out = []

    def walk(node):
        out.append(node)
        for child in node.children:
            walk(child)

    if prim_index is not None and prim_index.IsValid():
        walk(prim_index.rootNode)
    return out


class Frames:
    """World transforms in metres, Z up, and the unit of each length value.

    ``frame(prim)`` maps the prim's local space, measured in metres, to the
    world (metres, Z up); ``unit(...)`` is how many metres one raw unit of a
    value is. A prim's raw geometry maps to the world by
    ``frame(prim) @ diag(unit, unit, unit, 1)``.
    """

    def __init__(self, stage, path: str, up: str, mpu: float, correct: bool):
        self.stage, self.path, self.mpu = stage, path, mpu
        self.conv = Y_TO_Z.copy() if up == "Y" else np.eye(4)
        self.cache = UsdGeom.XformCache(TIME)
        self._layer_mpu: dict[str, float | None] = {}
        for layer in stage.GetUsedLayers():
            self._layer_mpu[layer.identifier] = _authored_mpu(layer)
        self.mixed = correct and any(v is not None and abs(v / mpu - 1.0) > 1e-9 for v in self._layer_mpu.values())
        self._chain: dict = {}
        self._def_unit: dict = {}

    # -- units ------------------------------------------------------------------
    def layer_unit(self, layer, layer_stack=None) -> float:
        """Metres per unit of a layer: its own, else its layer stack's root layer's, else the stage's."""
        v = self._layer_mpu.get(layer.identifier)
        if v is None and layer.identifier not in self._layer_mpu:
            v = _authored_mpu(layer)
        if v is None and layer_stack is not None:
            root = layer_stack.identifier.rootLayer
            if root is not None:
                v = _authored_mpu(root)
        return self.mpu if v is None else v

    def defining_unit(self, prim) -> float:
        """Unit of the layer holding the weakest ``def`` of the prim."""
        if not self.mixed:
            return self.mpu
        key = prim.GetPath()
        if key not in self._def_unit:
            unit = self.mpu
            for node in reversed(nodes(prim.GetPrimIndex())):
                found = False
                for layer in reversed(node.layerStack.layers):
                    spec = layer.GetPrimAtPath(node.path)
                    if spec is not None and spec.specifier == Sdf.SpecifierDef:
                        unit, found = self.layer_unit(layer, node.layerStack), True
                        break
                if found:
                    break
            self._def_unit[key] = unit
        return self._def_unit[key]

    def attr_unit(self, attr, prim) -> float:
        """Unit of the layer providing ``attr``'s value."""
        if not self.mixed:
            return self.mpu
        info = attr.GetResolveInfo(TIME)
        if info.GetSource() in (Usd.ResolveInfoSourceNone, Usd.ResolveInfoSourceFallback):
            return self.defining_unit(prim)
        node = info.GetNode()
        stack = node.layerStack if node else None
        for spec in attr.GetPropertyStack(TIME):
            if spec.HasDefaultValue() or spec.layer.GetNumTimeSamplesForPath(spec.path) > 0:
                return self.layer_unit(spec.layer, stack)
        return self.defining_unit(prim)

    def unit(self, prim, attr_names) -> float:
        """Unit of a prim's geometry: that of its first authored attribute
        among ``attr_names``, else of the layer that defines the prim."""
        if not self.mixed:
            return self.mpu
        for name in attr_names:
            attr = prim.GetAttribute(name)
            if attr and attr.HasAuthoredValue():
                return self.attr_unit(attr, prim)
        return self.defining_unit(prim)

    # -- transforms -------------------------------------------------------------
    def _local_m(self, prim) -> tuple[np.ndarray, bool]:
        xf = UsdGeom.Xformable(prim)
        if not xf:
            return np.eye(4), False
        m = np.eye(4)
        for op in xf.GetOrderedXformOps():
            om = col(op.GetOpTransform(TIME))
            if op.GetOpType() in _TRANSLATE_OPS:
                om[:3, 3] *= self.attr_unit(op.GetAttr(), prim)
            m = m @ om
        return m, bool(xf.GetResetXformStack())

    def _chain_m(self, prim) -> np.ndarray:
        key = prim.GetPath()
        if key == Sdf.Path.absoluteRootPath:
            return np.eye(4)
        if key not in self._chain:
            local, reset = self._local_m(prim)
            self._chain[key] = local if reset else self._chain_m(prim.GetParent()) @ local
        return self._chain[key]

    def frame(self, prim) -> np.ndarray:
        """The prim's local space (metres) -> world (metres, Z up)."""
        if self.mixed:
            m = self.conv @ self._chain_m(prim)
        else:
            w = col(self.cache.GetLocalToWorldTransform(prim))
            m = self.conv @ scale4(self.mpu) @ w @ scale4(1.0 / self.mpu)
        if not np.all(np.isfinite(m)):
            self._raise_nonfinite(prim)
        return m

    def relative(self, prim, ancestor) -> np.ndarray:
        """``prim``'s local space (metres) -> ``ancestor``'s local space (metres)."""
        if self.mixed:
            m = np.eye(4)
            p = prim
            while p.GetPath() != ancestor.GetPath() and p.GetPath() != Sdf.Path.absoluteRootPath:
                local, reset = self._local_m(p)
                m = local @ m
                if reset:
                    break
                p = p.GetParent()
        else:
            rel, _ = self.cache.ComputeRelativeTransform(prim, ancestor)
            m = scale4(self.mpu) @ col(rel) @ scale4(1.0 / self.mpu)
        if not np.all(np.isfinite(m)):
            self._raise_nonfinite(prim)
        return m

    def _raise_nonfinite(self, prim):
        chain = []
        p = prim
        while p and p.GetPath() != Sdf.Path.absoluteRootPath:
            chain.append(p)
            p = p.GetParent()
        for p in reversed(chain):
            local, _ = self.cache.GetLocalTransformation(p)
            if not np.all(np.isfinite(np.array(local))):
                raise SceneError(self.path, str(p.GetPath()), "transform has NaN or infinite values")
        raise SceneError(self.path, str(prim.GetPath()), "transform has NaN or infinite values")


def decompose(g: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(R, s) with g[:3, :3] == R @ diag(s), R a proper rotation; None when the
    linear part has shear, a mirror or a zero scale."""
    a = g[:3, :3]
    s = np.linalg.norm(a, axis=0)
    if np.any(s <= 1e-12):
        return None
    r = a / s
    if not np.allclose(r.T @ r, np.eye(3), atol=1e-6) or np.linalg.det(r) <= 0:
        return None
    return r, s


def upright_rigid(delta: np.ndarray) -> float | None:
    """Yaw of ``delta`` when it is a rotation about +Z plus a translation."""
    r = delta[:3, :3]
    if not np.allclose(r.T @ r, np.eye(3), atol=1e-6) or not np.allclose(r[:, 2], [0, 0, 1], atol=1e-6):
        return None
    return math.atan2(r[1, 0], r[0, 0])
