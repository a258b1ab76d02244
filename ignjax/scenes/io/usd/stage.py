"""Opening a USD stage and reading what every stage states: its up axis, its
unit, the semantic class labels on its prims; the ``ignjax:`` and semantic
attribute names that export and import share; import warnings.
"""

from __future__ import annotations

import math
import os
import re
import sys
import warnings
from pathlib import Path

from pxr import Tf, Usd, UsdGeom

from ignjax.errors import SceneError

NS = "ignjax:"
ATTR_KIND = NS + "kind"
"""Token naming what an ``ignjax`` prim is: scene, room, wall, door,
instance, geom or bbox."""
ATTR_ID = NS + "id"

ISAAC_TYPE_ATTR = "semantic:Semantics:params:semanticType"
ISAAC_DATA_ATTR = "semantic:Semantics:params:semanticData"
LABELS_TAXONOMY = "class"
LABELS_ATTR = f"semantics:labels:{LABELS_TAXONOMY}"

_SCENES_DIR = str(Path(__file__).parents[2])
"""``ignjax/scenes``: import warnings point at the first caller outside it."""


class UsdImportWarning(UserWarning):
    """Something in a stage was skipped or repaired on import (a missing
    sublayer, reference or payload, an invalid ``defaultPrim``, prims of
    unsupported types)."""


def warn_import(source: str, message: str) -> None:
    """Issue a :class:`UsdImportWarning` about ``source``, attributed to the
    first caller outside ``ignjax.scenes``."""
    frame, level = sys._getframe(0), 1
    while frame is not None and frame.f_code.co_filename.startswith(_SCENES_DIR):
        frame, level = frame.f_back, level + 1
    warnings.warn(f"{source}: {message}", UsdImportWarning, stacklevel=level)


def open_stage(path: str | os.PathLike):
    """Open a stage with all payloads loaded.

    Raises:
        SceneError: the file is missing or is not a USD file USD can open.
    """
    p = Path(path)
    if not p.exists():
        raise SceneError(p, None, "no such file")
    if p.is_dir():
        raise SceneError(p, None, "is a directory, not a USD file")
    try:
        stage = Usd.Stage.Open(str(p), load=Usd.Stage.LoadAll)
    except Tf.ErrorException as e:
        reason = " ".join(str(e).split())
        raise SceneError(p, None, f"not a readable USD file ({reason[:300]})") from e
    if stage is None:
        raise SceneError(p, None, "not a readable USD file")
    return stage


def stage_up_axis(stage, path: str | os.PathLike | None = None) -> str:
    """The stage's ``upAxis``: ``"Y"`` or ``"Z"`` (unauthored: USD's fallback, Y).

    Raises:
        SceneError: any other authored value (``X``, or an invalid token),
            naming the file, ``upAxis`` and the value.
    """
    if stage.HasAuthoredMetadata("upAxis"):
        value = str(stage.GetMetadata("upAxis"))
    else:
        value = str(UsdGeom.GetFallbackUpAxis())
    if value not in ("Y", "Z"):
        raise SceneError(path or stage.GetRootLayer().identifier, "upAxis",
                         f"unsupported upAxis {value!r}: USD stages must be Y-up or Z-up")
    return value


def stage_meters_per_unit(stage, path: str | os.PathLike | None = None) -> float:
    """The stage's ``metersPerUnit`` (unauthored: USD's fallback, 0.01).

    Raises:
        SceneError: the value is not a positive finite number.
    """
    value = float(UsdGeom.GetStageMetersPerUnit(stage))
    if not math.isfinite(value) or value <= 0:
        raise SceneError(path or stage.GetRootLayer().identifier, "metersPerUnit",
                         f"metersPerUnit must be a positive number, got {value!r}")
    return value


_ISAAC_TYPE_RE = re.compile(r"^semantic:(?P<inst>[^:]+):params:semanticType$")


def prim_semantic_label(prim) -> str | None:
    """The class label authored on ``prim`` itself, or None.

    Looked up in this order: ``ignjax:category``; ``UsdSemantics.LabelsAPI``
    ``semantics:labels:class`` (first non-empty token); Isaac-style
    ``semantic:<name>:params:semanticType == "class"`` with its
    ``semanticData`` (the part before a comma when it lists several).
    """
    attr = prim.GetAttribute(NS + "category")
    if attr and attr.HasAuthoredValue():
        value = attr.Get()
        if value:
            return str(value)
    names = prim.GetAuthoredPropertyNames()
    for name in names:
        if name.startswith("semantics:labels:") and name.split(":", 2)[2].lower() == LABELS_TAXONOMY:
            value = prim.GetAttribute(name).Get()
            for token in (value or ()):
                if str(token).strip():
                    return str(token).strip()
    for name in names:
        m = _ISAAC_TYPE_RE.match(name)
        if not m:
            continue
        if str(prim.GetAttribute(name).Get() or "").strip().lower() != LABELS_TAXONOMY:
            continue
        data = prim.GetAttribute(f"semantic:{m.group('inst')}:params:semanticData")
        value = str(data.Get() or "").split(",")[0].strip() if data else ""
        if value:
            return value
    return None
