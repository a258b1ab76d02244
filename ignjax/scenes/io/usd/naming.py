"""Names in a stage: the object category of a prim (from its label, kind,
name or referenced asset), whether a label names a room, and whether a
prim's model kind makes it a component.
"""

from __future__ import annotations

import re
from pathlib import Path

from pxr import Kind, Pcp, Usd

from ignjax.scenes import vocab
from ignjax.scenes.io.usd.frames import nodes

_BUILTIN_KINDS = frozenset({"model", "group", "assembly", "component", "subcomponent"})
_GENERIC_NAMES = frozenset({
    "unknown", "xform", "mesh", "cube", "sphere", "cylinder", "capsule", "cone", "plane", "geom", "geometry",
    "geo", "object", "obj", "prim", "model", "root", "group", "scope", "node", "instance", "prototype",
    "proto", "default", "asset", "shape", "world", "scene", "body", "part", "component", "looks", "render",
    "primitive", "polygon", "poly", "poly_surface", "polysurface", "transform", "null", "empty", "item",
    "point_instancer", "instancer", "material", "visual", "visuals", "collision", "collisions", "main",
})

def snake(text: str) -> str:
    """``snake_case`` words of a name (``FloorSlab_01`` -> ``floor_slab_01``)."""
    text = re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", text.strip())
    text = re.sub(r"([A-Z]+)([A-Z][a-z])", r"\1_\2", text)
    return re.sub(r"[^0-9A-Za-z]+", "_", text).strip("_").lower()


def room_label_of(text: str | None) -> str | None:
    """The room label that ``text`` names (``"Kitchen_2"`` -> ``kitchen``),
    or None when it names no room or names an object category."""
    if not text:
        return None
    label = vocab.normalize_room_label(text)
    if label == vocab.OTHER_ROOM or vocab.is_target_eligible(vocab.normalize_category(text)):
        return None
    key = re.sub(r"(_?\d+)+$", "", snake(text))
    words = [w for w in key.split("_") if w]
    if not words:
        return None
    last = words[-1]
    if last == "room" or vocab.normalize_room_label(last) != vocab.OTHER_ROOM \
            or vocab.normalize_room_label(key.replace("_", "")) != vocab.OTHER_ROOM:
        return label
    return None


def custom_kind(prim) -> str | None:
    """The prim's model kind when it is not a registered kind (``chair``), else None."""
    kind = str(Usd.ModelAPI(prim).GetKind() or "")
    if not kind or kind in _BUILTIN_KINDS:
        return None
    if Kind.Registry.HasKind(kind):
        return None
    return kind


def is_component(prim) -> bool:
    """The prim's model kind is ``component``, derives from it, or is custom."""
    kind = str(Usd.ModelAPI(prim).GetKind() or "")
    if not kind:
        return False
    if kind in _BUILTIN_KINDS:
        return kind == "component"
    if Kind.Registry.HasKind(kind):
        return bool(Kind.Registry.IsA(kind, Kind.Tokens.component))
    return True


def _meaningful(category: str) -> str | None:
    """The category, or None for names that say nothing (generic or one or two letters)."""
    if category in _GENERIC_NAMES or category == vocab.UNKNOWN_CATEGORY or len(category) <= 2:
        return None
    return category


def asset_stem(prim, stage) -> str | None:
    """File stem of the first asset the prim references or payloads."""
    root_id = stage.GetRootLayer().identifier
    for node in nodes(prim.GetPrimIndex()):
        if node.arcType not in (Pcp.ArcTypeReference, Pcp.ArcTypePayload):
            continue
        layer = node.layerStack.identifier.rootLayer
        if layer is None or layer.identifier == root_id:
            continue
        ident = re.sub(r"\[.*\]$", "", layer.identifier)
        return Path(ident).stem
    return None


def category_chain(*candidates) -> str:
    """The first candidate that normalizes to a meaningful category, else ``unknown``."""
    for c in candidates:
        if c:
            cat = _meaningful(vocab.normalize_category(c))
            if cat:
                return cat
    return vocab.UNKNOWN_CATEGORY
