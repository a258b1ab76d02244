"""One walk over a stage that decides which prims become object instances
and rooms (:class:`Owner`, each with the geometry prims it owns), and which
are ``ignjax`` walls and doors or PointInstancers.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import NamedTuple

from pxr import Usd, UsdGeom

from ignjax.scenes import vocab
from ignjax.scenes.io.usd.frames import TIME
from ignjax.scenes.io.usd.naming import (
    is_component,
    names_object,
    room_attribute_label,
    room_label_of,
    room_name_label,
    snake,
)
from ignjax.scenes.io.usd.parts import authored, gprim_type, token
from ignjax.scenes.io.usd.stage import ATTR_KIND, NS, prim_semantic_label


@dataclass(eq=False)
class Owner:
    """A prim that becomes an object instance or a room, and the geometry prims it owns."""

    prim: object
    role: str  # "instance" | "room" | "ignjax_instance" | "ignjax_room"
    label: str | None = None
    gprims: list = field(default_factory=list)
    room: "Owner | None" = None  # the room prim this owner lies under, if any

    @functools.cached_property
    def is_floor(self) -> bool:
        """Named or labelled as a floor (``Floor``, ``FloorSlab``, ``ground_01``)."""
        text = self.label or self.prim.GetName()
        words = set(snake(text).split("_"))
        return vocab.normalize_category(text) == "floor" or bool(words & {"floor", "ground", "flooring"})


class _Ctx(NamedTuple):
    label: Owner | None = None  # nearest labelled (or ignjax instance) owner
    label_cat: str | None = None
    kind: Owner | None = None  # topmost component-kind owner
    root: Owner | None = None  # child of the nearest container
    room: Owner | None = None  # nearest room prim
    container: bool = False  # children of this prim are objects (root prims, room prims)


def hidden(prim) -> bool:
    """The prim is invisible, or a guide or proxy (its subtree is not imported)."""
    if not prim.IsA(UsdGeom.Imageable):
        return False
    img = UsdGeom.Imageable(prim)
    if img.GetVisibilityAttr().Get(TIME) == UsdGeom.Tokens.invisible:
        return True
    return img.GetPurposeAttr().Get(TIME) in (UsdGeom.Tokens.guide, UsdGeom.Tokens.proxy)


@dataclass
class Traversal:
    """What :func:`traverse` found."""

    owners: list[Owner] = field(default_factory=list)
    specials: list[tuple[str, object]] = field(default_factory=list)  # ("wall" | "door", prim)
    instancers: list = field(default_factory=list)  # PointInstancer prims
    instancer_rooms: dict = field(default_factory=dict)  # PointInstancer path -> the room Owner it lies under
    unsupported: dict[str, int] = field(default_factory=dict)  # gprim type -> count of skipped prims

    def new_owner(self, prim, role: str, label: str | None = None) -> Owner:
        """Record and return a new owner."""
        o = Owner(prim, role, label)
        self.owners.append(o)
        return o


def traverse(stage) -> Traversal:
    """Walk the stage once and sort its prims (see "What is traversed" and
    "Which prims are object instances" in :mod:`ignjax.scenes.io.usd.load`)."""
    t = Traversal()
    pred = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
    proto_roots: set = set()
    for prim in stage.Traverse(pred):
        if prim.IsA(UsdGeom.PointInstancer):
            proto_roots.update(UsdGeom.PointInstancer(prim).GetPrototypesRel().GetForwardedTargets())
    roots = list(stage.GetPseudoRoot().GetFilteredChildren(pred))
    default = stage.GetDefaultPrim()
    if default:
        roots.sort(key=lambda p: p.GetPath() != default.GetPath())
    ctx: dict = {}
    for root in roots:
        it = iter(Usd.PrimRange(root, pred))
        for prim in it:
            p = prim.GetPath()
            if p in proto_roots or hidden(prim):
                it.PruneChildren()
                continue
            parent = ctx.get(p.GetParentPath(), _Ctx(container=True))
            c = parent._replace(container=False)
            ikind = token(prim, ATTR_KIND, "")
            if ikind in ("wall", "door"):
                t.specials.append((ikind, prim))
                it.PruneChildren()
                continue
            gtype = gprim_type(prim)
            room = None
            if ikind == "instance":
                cat = authored(prim, NS + "category")
                c = c._replace(label=t.new_owner(prim, "ignjax_instance", cat), label_cat=cat)
            elif ikind == "room":
                room = t.new_owner(prim, "ignjax_room")
            elif ikind not in ("scene", "geom", "bbox"):
                label = prim_semantic_label(prim)
                if label and room_label_of(label):
                    room = t.new_owner(prim, "room", label)
                elif label:
                    cat = vocab.normalize_category(label)
                    if c.label is None or c.label_cat != cat:
                        c = c._replace(label=t.new_owner(prim, "instance", label), label_cat=cat)
                elif c.label is None and c.kind is None and c.room is None and not is_component(prim) \
                        and not names_object(prim):
                    # no semantic label, not part of an object or room: a room attribute, else a room name
                    text = room_attribute_label(prim) or room_name_label(prim)
                    if text:
                        room = t.new_owner(prim, "room", text)
            if room is not None:
                # A room prim is a container: its floors make the room, its
                # other children are objects.
                c = _Ctx(room=room, container=True)
            else:
                if c.kind is None and is_component(prim):
                    c = c._replace(kind=t.new_owner(prim, "instance"))
                if parent.container:
                    if p.pathElementCount == 1 and not gtype:
                        c = c._replace(root=None, container=True)
                    else:
                        c = c._replace(root=t.new_owner(prim, "instance"))
            if prim.IsA(UsdGeom.PointInstancer):
                t.instancers.append(prim)
                t.instancer_rooms[p] = c.room
                it.PruneChildren()
                continue
            if gtype:
                owner = c.label or c.kind or c.root
                if owner is None or (c.room is not None and owner.is_floor):
                    owner = c.room
                if owner is not None:
                    owner.gprims.append(prim)
                    if owner is not c.room:
                        owner.room = c.room
            elif prim.IsA(UsdGeom.Gprim):
                kind = str(prim.GetTypeName())
                t.unsupported[kind] = t.unsupported.get(kind, 0) + 1
            ctx[p] = c
    return t
