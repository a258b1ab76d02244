"""Names in a stage: the object category of a prim (from its label, kind,
name or referenced asset), whether a label, a room attribute or a prim name
names a room, and whether a prim's model kind makes it a component.
"""

from __future__ import annotations

import re
from pathlib import Path

from pxr import Kind, Pcp, Usd

from ignjax.scenes import vocab
from ignjax.scenes.io.names import category_from_name, room_label_from_name
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


def category_chain(labels=(), names=()) -> str:
    """The first meaningful category: of the ``labels`` (semantic labels,
    custom kinds; :func:`vocab.normalize_category`), else of the ``names``
    (prim names, asset stems; :func:`~ignjax.scenes.io.names.category_from_name`),
    else ``unknown``."""
    for texts, normalize in ((labels, vocab.normalize_category), (names, category_from_name)):
        for c in texts:
            if c:
                cat = _meaningful(normalize(c))
                if cat:
                    return cat
    return vocab.UNKNOWN_CATEGORY


ROOM_KEYS = ("room", "roomType", "room_type", "roomLabel", "room_label", "roomName", "room_name",
             "roomCategory", "room_category")
"""Attribute and ``customData`` names that say which room a prim *is*: any
non-empty string value makes the prim a room (labelled ``other`` when the
value is no known room name). Matched on the name's last ``:`` component,
ignoring case, ``_`` and ``-``, so ``room``, ``semantic:room``,
``semantics:roomType`` and ``userProperties:room_label`` all count."""
LABEL_KEYS = ("label", "semanticLabel", "semantic_label")
"""Generic label names, matched the same way: they make the prim a room
only when their value names a room (``label = "Kitchen"`` does,
``label = "chair"`` does not)."""


def _key(name: str) -> str:
    return re.sub(r"[_-]", "", str(name).rsplit(":", 1)[-1]).lower()


_ROOM_KEYS = frozenset(_key(k) for k in ROOM_KEYS)
_LABEL_KEYS = frozenset(_key(k) for k in LABEL_KEYS)


def _text(value) -> str | None:
    """A string value, or the first non-empty string of a string array, stripped; else None."""
    if isinstance(value, str):
        return value.strip() or None
    if value is not None and not isinstance(value, (bytes, dict)) and hasattr(value, "__iter__"):
        for v in value:
            if not isinstance(v, str):
                return None
            if v.strip():
                return v.strip()
    return None


def _flatten(data, prefix: str = ""):
    """(``outer:inner`` name, value) pairs of nested dictionaries."""
    for k, v in (data or {}).items():
        name = f"{prefix}:{k}" if prefix else str(k)
        if isinstance(v, dict):
            yield from _flatten(v, name)
        else:
            yield name, v


def room_attribute_label(prim) -> str | None:
    """The room label a custom string attribute or ``customData`` entry of
    the prim gives it, or None.

    Authored attributes are read first (in name order), then ``customData``
    (nested dictionaries as ``outer:inner``); in each, the :data:`ROOM_KEYS`
    before the :data:`LABEL_KEYS`.
    """
    found: list[tuple[int, str]] = []
    for name in prim.GetAuthoredPropertyNames():
        key = _key(name)
        if key in _ROOM_KEYS or key in _LABEL_KEYS:
            attr = prim.GetAttribute(name)
            text = _text(attr.Get()) if attr else None
            if text:
                found.append((0 if key in _ROOM_KEYS else 1, text))
    for name, value in _flatten(prim.GetCustomData()):
        key = _key(name)
        text = _text(value)
        if text and (key in _ROOM_KEYS or key in _LABEL_KEYS):
            found.append((2 if key in _ROOM_KEYS else 3, text))
    for rank, text in sorted(found, key=lambda t: t[0]):
        if rank in (0, 2):
            return vocab.normalize_room_label(text)
        label = room_label_of(text)
        if label:
            return label
    return None


def names_object(prim) -> bool:
    """The prim's name is an object category that may be a target
    (``Chair_01``): such a prim is an object even with a room attribute
    (objects often record the room they stand in)."""
    return vocab.is_target_eligible(category_from_name(prim.GetName()))


def room_name_label(prim) -> str | None:
    """The room label the prim's name gives it
    (:func:`~ignjax.scenes.io.names.room_label_from_name`), or None."""
    return room_label_from_name(prim.GetName())
