"""Import any USD stage into a :class:`~ignjax.scenes.model.Scene`.

:func:`load_usd` is the entry point; this module documents the rules and
runs the import. The pieces live beside it: :mod:`.stage` (opening, axis,
unit, labels), :mod:`.frames` (transforms and layer units),
:mod:`.traversal` (which prims are objects and rooms), :mod:`.parts`
(geometry prims), :mod:`.naming` (categories), :mod:`.instances` and
:mod:`.rooms` (building the scene's parts).

Opening
    ``Usd.Stage.Open(path, load=LoadAll)`` (payloads loaded). A file USD
    cannot open is a :class:`~ignjax.errors.SceneError` of one line naming
    the file and a short reason (``empty file``, or ``not a readable USD
    file (<USD's first cause, at most 100 characters>)``), never the
    library's internals. Composition errors become
    :class:`~ignjax.scenes.io.usd.stage.UsdImportWarning` and whatever
    composes is imported: one missing asset (sublayer, reference, payload,
    a MaterialX document usd-core cannot read) is named with the layer or
    prim that refers to it; several become one line ``N asset references
    could not be resolved (imported without them), e.g. a; b; c; and k
    more``; other composition errors are warned about one by one, or in one
    summary line when there are more than
    :data:`~ignjax.scenes.io.usd.stage.MAX_SEPARATE_WARNINGS`. USD's own
    diagnostics (which it would print to stderr, one line each) are trapped
    and dropped when they repeat a composition error, else reported the
    same way. An authored ``defaultPrim`` that names no prim is warned
    about and ignored (all root prims are imported anyway).

Frame and units
    ``upAxis`` ``Z`` is kept, ``Y`` is rotated to Z-up with
    (x, y, z) -> (x, -z, y); unauthored means USD's fallback (Y); anything
    else is an error. ``metersPerUnit`` is the stage's value, or USD's
    fallback 0.01 (centimetres) when unauthored. Everything is returned in
    metres; ``SceneMeta`` records the original axis and unit.

Layers with their own units (``correct_layer_units=True``, the default)
    Plain USD ignores ``metersPerUnit`` on sublayers and referenced or
    payloaded layers. We do not: when any layer used by the stage authors a
    ``metersPerUnit`` different from the stage's, every length is read in
    the units of the layer its value comes from. Precisely:

    * a translation (``translate*`` ops, and the translation part of
      ``transform`` ops, pivots included) is scaled by the unit of the layer
      holding the strongest opinion for that op's value;
    * a geometry prim's lengths (``points``, ``size``, ``radius``,
      ``height``, ...) by the unit of the layer holding its first authored
      geometry attribute; for unauthored (fallback) values, by the unit of
      the layer that defines the prim (the weakest ``def`` spec: for a
      referenced asset, the asset's layer);
    * PointInstancer ``positions`` by the unit of their layer;
    * rotations and scales are unitless and left alone.

    A layer's unit is its own authored ``metersPerUnit``, else that of the
    root layer of its layer stack (the referenced asset's root layer), else
    the stage's. So a centimetre stage that references a metre asset at
    ``translate = (300, 0, 0)`` puts the asset, at its true metre size,
    3 m from the origin. In ``metersPerUnit_mix.usda`` (stage 100 m/unit,
    cubes defined in sublayers of 1 and 10 m/unit, moved by overs in the
    root layer) the cubes are 2 m, 20 m and 200 m wide at x = 300 m,
    600 m and 0 m; with ``correct_layer_units=False`` all three are 200 m,
    as in a USD viewer. Differing ``upAxis`` in sublayers/references is
    not corrected (a warning is issued).

What is traversed
    Active, defined, loaded, non-abstract prims, through instance proxies
    (so every instance of an instanceable prim is seen). Subtrees that are
    ``invisible`` or whose ``purpose`` is ``guide`` or ``proxy`` are
    skipped, and so are PointInstancer prototypes (they appear once per
    point instead). Geometry: ``Mesh``, ``Cube``, ``Sphere``, ``Cylinder``,
    ``Capsule``, ``Cone``, ``Plane``, ``Cylinder_1``, ``Capsule_1``; other
    gprim types (curves, points, NURBS) are skipped with one warning.

Which prims are object instances (each geometry prim belongs to exactly one)
    1. ``ignjax:kind`` prims written by :func:`~ignjax.scenes.io.usd.export.save_usd`
       (rooms, walls, doors, instances) are restored exactly (an instance
       moved or turned about Z in a USD editor keeps its stored geometry
       and box, moved along; one scaled or tilted is measured again).
    2. A prim with a semantic class label (``ignjax:category``,
       ``semantics:labels:class`` or Isaac ``semantic:*:params:semanticData``
       with ``semanticType == "class"``) owns the geometry below it, down
       to the next labelled prim. A labelled prim below one with the same
       category is part of it (labels applied to every mesh of an object);
       below one with another category it is an object of its own.
    3. Geometry with no labelled ancestor belongs to its topmost ancestor
       whose model Kind is ``component`` (or derives from it, or is a
       custom, unregistered kind such as ``chair``).
    4. Otherwise to the child of its *container* that it lies under
       (``/World/Table`` for ``/World/Table/Leg``), or to the root prim
       itself when a root prim is a geometry prim. Containers are the
       root prims (all of them, the ``defaultPrim`` first) and room prims.
    5. Every point of a ``PointInstancer`` is its own instance, with the
       geometry of its prototype.

Rooms
    Room prims are found in this order:

    1. ``ignjax`` room prims written by :func:`~ignjax.scenes.io.usd.export.save_usd`;
    2. a prim whose semantic class label (as in rule 2 above) names a room
       (``Kitchen``, ``living room``; not an object category such as
       ``toilet``: a prim labelled so is an object);
    3. a prim without a semantic label whose custom string attribute or
       ``customData`` entry gives a room:
       :data:`~ignjax.scenes.io.usd.naming.ROOM_KEYS` (``room``,
       ``roomType``, ``room_type``, ``roomLabel``, ``room_label``,
       ``roomName``, ``room_name``, ``roomCategory``, ``room_category``;
       in any namespace, e.g. ``semantic:room``,
       ``userProperties:roomType``; case, ``_`` and ``-`` ignored) make it
       a room whatever their value (``other`` when it is no known room
       name), :data:`~ignjax.scenes.io.usd.naming.LABEL_KEYS` (``label``,
       ``semanticLabel``) only when their value names a room;
    4. a prim without a semantic label named like a room
       (:func:`~ignjax.scenes.io.names.room_label_from_name`: ``Kitchen``,
       ``Bedroom_2``, ``living_room``, ``LivingRoom``, ``Guest_Bedroom``,
       ``GameRoom``; not ``Lamp_Kitchen`` or ``KitchenIsland``).

    Rules 3 and 4 apply only to prims that are not part of an object (no
    labelled or component ancestor), not themselves components, not named
    like an object that may be a target (``Chair_01`` with
    ``room = "kitchen"`` is a chair that records its room), and not below
    another room prim. A room prim is a container: below it, floors
    (geometry named or labelled ``floor``/``ground``, or the room prim's
    own geometry) make the room's polygon, everything else is furniture by
    rules 2-4 of the instance rules. The polygon is the ``ignjax:polygon``
    when stored; else the outline of the floors' upward-facing faces when
    that is one simple loop; else the convex hull of the floors' footprint;
    else the convex hull of the boxes of the objects below the room prim.
    Without any room prim: one room ``room_0`` labelled ``other`` covering
    the convex hull of all boxes (and walls). ``Instance.room`` is the room
    prim the instance (or its PointInstancer) lies under; else the room
    whose polygon contains the centre of the instance's box footprint;
    else None. Restored instances keep their stored room.

Categories
    From the label; else from a custom Kind (both through
    :func:`vocab.normalize_category`); else from the prim name; else from
    the file stem of the asset the prim references or payloads (both
    through :func:`~ignjax.scenes.io.names.category_from_name`, which
    strips index and side suffixes: ``Chair_01``, ``BishopL``, ``light3``
    are ``chair``, ``bishop``, ``light``). Names that say nothing
    (``Mesh``, ``Cube``, ``Xform``, ``Geom`` ...) are skipped; the last
    resort is ``"unknown"``. For PointInstancer points: the prototype's
    label, the instancer's label, the prototype's kind, the prototype's
    name, the instancer's name, the prototype's asset. ``structural`` is
    :func:`vocab.is_structural` of the category. Ids are the prim names
    (``<instancer>_<k>`` for points), made unique with ``_2``, ``_3``...;
    ``Instance.name`` is the prim path.

Geometry and boxes
    World transforms come from ``UsdGeom.XformCache`` (or, with mixed
    layer units, from the per-op composition above). Mesh faces with more
    than three vertices are triangulated (quads along their inner
    diagonal, larger faces ear-clipped in their best-fit plane, concave
    ones included); meshes are cleaned with trimesh (merged vertices, no
    degenerate faces). ``Cube``, ``Sphere``, ``Cylinder`` and ``Capsule``
    become box/sphere/ellipsoid/cylinder/capsule geoms when the world
    transform is a rotation times a scale along the primitive's own axes
    (and, for cylinders, equal radial scales; for capsules and spheres,
    uniform scale; a non-uniformly scaled sphere is an ellipsoid); anything
    else becomes a mesh. The upright box is the minimum-area rectangle of
    the footprint, or the rectangle aligned with the object's own heading
    (its prim's x axis) when that is within 0.1 % of the minimum.
    ``position`` is the box's footprint centre at its lowest point, ``yaw``
    the prim's heading. Colours from ``primvars:displayColor`` /
    ``displayOpacity``, else the bound ``UsdPreviewSurface``'s
    ``diffuseColor``/``opacity``; the dominant one (by surface area) names
    the instance's colour attribute. Support relations are not inferred.

Scene
    Id: the ``scene_id`` argument, else the id stored by ``save_usd``, else
    the file stem. A stage without geometry, non-finite transforms,
    points, positions or sizes are errors naming the prim.
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
from pathlib import Path

from pxr import Pcp

from ignjax.errors import SceneError
from ignjax.scenes import vocab
from ignjax.scenes.io.usd.frames import Frames
from ignjax.scenes.io.usd.instances import InstanceBuilder
from ignjax.scenes.io.usd.naming import room_label_of
from ignjax.scenes.io.usd.parts import authored, token
from ignjax.scenes.io.usd.rooms import Structure, room_at
from ignjax.scenes.io.usd.stage import (
    ATTR_KIND,
    NS,
    one_line,
    open_stage,
    stage_meters_per_unit,
    stage_up_axis,
    summarize,
    usd_diagnostics,
    warn_import,
    warn_usd_messages,
)
from ignjax.scenes.io.usd.traversal import Owner, traverse
from ignjax.scenes.model import Instance, Room, Scene, SceneMeta
from ignjax.scenes.model.validation import validate_scene


_ASSET_ERRORS = frozenset(getattr(Pcp, name) for name in (
    "ErrorType_InvalidAssetPath", "ErrorType_InvalidSublayerPath", "ErrorType_MutedAssetPath") if hasattr(Pcp, name))
"""Composition errors that are files USD could not find or open."""


def _asset_example(message: str) -> str:
    """A short account of one unresolved asset: its file name and what refers to it."""
    m = re.search(r"sublayer @([^@]+)@ of layer @([^@]+)@", message)
    if m:
        return f"sublayer {_file_name(m.group(1))} of {_file_name(m.group(2))}"
    m = re.search(r"asset @([^@]+)@ for (\w+) introduced by @[^@]*@<([^>]+)>", message)
    if m:
        return f"{_file_name(m.group(1))} ({m.group(2)} on {m.group(3)})"
    m = re.search(r"@([^@]+)@", message)
    return _file_name(m.group(1)) if m else (message if len(message) <= 100 else message[:97] + "...")


def _file_name(asset: str) -> str:
    return Path(asset.split(":SDF_FORMAT_ARGS")[0]).name or asset


def unresolved_summary(messages: list[str], examples: int = 3, note: str = "") -> str:
    """``"N asset references could not be resolved<note>, e.g. a; b; c"`` for
    the messages of unresolved-asset composition errors; the examples are the
    first in sorted order (USD reports them in no fixed order)."""
    n = len(messages)
    listed = "; ".join(sorted(_asset_example(m) for m in messages)[:examples])
    more = f"; and {n - examples} more" if n > examples else ""
    return f"{n} asset reference{'s' if n != 1 else ''} could not be resolved{note}, e.g. {listed}{more}"


class _Importer:
    """One import: the stage, its frame and unit, and the scene built from it."""

    def __init__(self, path: Path, scene_id: str | None, correct_layer_units: bool):
        self.path = path
        self.spath = str(path)
        self.scene_id = scene_id
        self.stage = open_stage(path)
        self.up = stage_up_axis(self.stage, self.spath)
        self.mpu = stage_meters_per_unit(self.stage, self.spath)
        self.correct = correct_layer_units
        self._warn_composition()
        self.frames = Frames(self.stage, self.spath, self.up, self.mpu, correct_layer_units)
        self.instances = InstanceBuilder(self.stage, self.spath, self.frames)
        self.structure = Structure(self.spath, self.frames, self.instances)

    # -- diagnostics --------------------------------------------------------------
    def _warn(self, message: str) -> None:
        warn_import(self.spath, message)

    def _warn_composition(self) -> None:
        errors = self.stage.GetCompositionErrors()
        self.composition_texts = [one_line(e) for e in errors]
        assets = list(dict.fromkeys(one_line(e) for e in errors if e.errorType in _ASSET_ERRORS))
        others = list(dict.fromkeys(one_line(e) for e in errors if e.errorType not in _ASSET_ERRORS))
        self.unresolved = assets
        if len(assets) == 1:
            self._warn(f"composition error, imported without it: {assets[0]}")
        elif assets:  # many missing files (MaterialX documents, textures, sublayers): one line
            self._warn(unresolved_summary(assets, note=" (imported without them)"))
        for line in summarize(others, "composition errors (imported without what they concern)"):
            self._warn(f"composition error, imported without it: {line}" if line in others else line)
        layer = self.stage.GetRootLayer()
        if layer.HasDefaultPrim() and not self.stage.GetDefaultPrim():
            self._warn(f"defaultPrim {layer.defaultPrim!r} names no prim; importing all root prims")
        for used in self.stage.GetUsedLayers():
            root = used.pseudoRoot
            if used is layer or root is None or not root.HasInfo("upAxis"):
                continue
            if str(root.GetInfo("upAxis")) != self.up:
                self._warn(f"layer {used.identifier} is {root.GetInfo('upAxis')}-up but the stage is {self.up}-up; "
                           "its geometry is not re-oriented")

    def stored_scene(self) -> dict:
        """The scene id, wall height and meta stored by ``save_usd`` (on ``/World`` or in the layer data)."""
        for prim in self.stage.GetPseudoRoot().GetChildren():
            if token(prim, ATTR_KIND, "") == "scene":
                return {"sceneId": authored(prim, NS + "sceneId"), "wallHeight": authored(prim, NS + "wallHeight"),
                        "meta": authored(prim, NS + "meta")}
        data = self.stage.GetRootLayer().customLayerData.get("ignjax")
        return dict(data) if isinstance(data, dict) else {}

    def run(self) -> Scene:
        """Traverse the stage and build the validated scene."""
        found = traverse(self.stage)
        if found.unsupported:
            listing = ", ".join(f"{k}: {v}" for k, v in sorted(found.unsupported.items()))
            self._warn(f"skipped prims of unsupported geometry types ({listing})")
        build, structure = self.instances, self.structure
        # (instance, restored from ignjax attributes, room prim it lies under)
        records: list[tuple[Instance, bool, Owner | None]] = []
        # Restored instances first, so that their ids win over generated ones.
        for owner in sorted(found.owners, key=lambda o: o.role != "ignjax_instance"):
            if owner.role == "ignjax_instance":
                inst = build.ignjax_instance(owner)
                if inst is not None:
                    records.append((inst, True, owner.room))
            elif owner.role == "instance" and owner.gprims:
                parts = build.parts(owner)
                if parts:
                    prim = owner.prim
                    records.append((build.generic_instance(
                        parts, self.frames.frame(prim), build.unique_id(prim.GetName()), build.owner_category(owner),
                        str(prim.GetPath()), build.owner_extra(prim)), False, owner.room))
        for prim in found.instancers:
            under = found.instancer_rooms.get(prim.GetPath())
            records += [(inst, False, under) for inst in build.pointinstancer_instances(prim)]
        walls = [w for w in (structure.wall(p) for k, p in found.specials if k == "wall") if w is not None]
        doors = [d for d in (structure.door(p) for k, p in found.specials if k == "door") if d is not None]
        room_owners = [o for o in found.owners if o.role in ("room", "ignjax_room")]
        if build.n_parts == 0 and not walls and not any(o.gprims for o in room_owners):
            note = f"; {unresolved_summary(self.unresolved, 1)}" if self.unresolved else ""
            raise SceneError(self.spath, None, f"the stage has no geometry (no meshes or geometric primitives to import{note})")
        rooms: list[Room] = []
        room_of_owner: dict[int, str] = {}
        room_ids: set[str] = set()
        pending = []
        for owner in room_owners:
            members = [inst for inst, _, r in records if r is owner]
            if owner.role == "ignjax_room":
                room = structure.ignjax_room(owner, members)
                if room is not None:
                    rooms.append(room)
                    room_ids.add(room.id)
                    room_of_owner[id(owner)] = room.id
            else:
                pending.append((owner, members))
        for owner, members in pending:
            poly = structure.room_polygon(owner, members)
            if poly is None:
                self._warn(f"room prim {owner.prim.GetPath()} has no usable floor or objects to outline it; ignored")
                continue
            base = rid = owner.prim.GetName()
            k = 2
            while rid in room_ids:
                rid, k = f"{base}_{k}", k + 1
            room_ids.add(rid)
            room_of_owner[id(owner)] = rid
            rooms.append(Room(rid, room_label_of(owner.label) or vocab.OTHER_ROOM, tuple(poly), owner.prim.GetName()))
        instances = [inst for inst, _, _ in records]
        if not rooms:
            cover = structure.cover(instances, walls)
            if cover is None:
                raise SceneError(self.spath, None, "the stage has no geometry outside room prims with unusable footprints")
            rooms.append(Room("room_0", vocab.OTHER_ROOM, tuple(cover), "all geometry"))
            room_ids.add("room_0")
        scene_rooms = tuple(rooms)
        ids = {i.id for i in instances}
        fixed = []
        for inst, restored, under in records:
            if restored and (inst.room is None or inst.room in room_ids):
                room = inst.room
            else:
                room = room_of_owner.get(id(under)) or room_at(scene_rooms, inst.bbox.center[:2])
            support = inst.support if inst.support in ids else None
            fixed.append(dataclasses.replace(inst, room=room, support=support))
        stored = self.stored_scene()
        meta = {}
        if stored.get("meta"):
            try:
                meta = json.loads(stored["meta"])
            except (TypeError, ValueError):
                meta = {}
        params = meta.get("params") if isinstance(meta.get("params"), str) else json.dumps(
            {"importer": "usd", "correct_layer_units": self.correct}, sort_keys=True)
        scene = Scene(
            id=self.scene_id or stored.get("sceneId") or self.path.stem,
            rooms=scene_rooms,
            doors=tuple(doors),
            walls=tuple(walls),
            instances=tuple(fixed),
            meta=SceneMeta(source=self.spath, source_format="usd", up_axis=self.up, meters_per_unit=self.mpu,
                           seed=meta.get("seed") if isinstance(meta.get("seed"), int) else None, params=params),
            wall_height=float(stored["wallHeight"]) if stored.get("wallHeight") is not None else 2.5,
        )
        return validate_scene(scene, self.spath)


def load_usd(path: str | os.PathLike, *, scene_id: str | None = None, correct_layer_units: bool = True) -> Scene:
    """Read any USD stage into a :class:`Scene` (Z-up, metres).

    Stages written by :func:`~ignjax.scenes.io.usd.export.save_usd` come back without loss; any other
    stage is converted by the rules in this module's docstring
    (which prims are objects, their categories, rooms, units).

    Args:
        path: a ``.usd``/``.usda``/``.usdc``/``.usdz`` file.
        scene_id: the scene's id; default: the id stored by
            :func:`~ignjax.scenes.io.usd.export.save_usd`,
            else the file stem.
        correct_layer_units: rescale geometry and translations that come from
            layers whose own ``metersPerUnit`` differs from the stage's
            (plain USD ignores such layer metadata; see
            this module's docstring).

    Returns:
        A validated scene; ``meta.up_axis`` and ``meta.meters_per_unit``
        record the stage's original up axis and unit.

    Raises:
        SceneError: not a USD file, unsupported ``upAxis``, no geometry,
            NaN/inf transforms or points, malformed meshes, or a scene that
            fails :func:`~ignjax.scenes.model.validation.validate_scene`.

    Warns:
        UsdImportWarning: missing sublayers/references/payloads (the rest is
            imported; many become one summary), an invalid ``defaultPrim``,
            skipped prims, other messages USD issued during the import.
    """
    return read_usd(path, scene_id=scene_id, correct_layer_units=correct_layer_units)[0]


def read_usd(path: str | os.PathLike, *, scene_id: str | None = None,
             correct_layer_units: bool = True) -> tuple[Scene, tuple[Path, ...]]:
    """:func:`load_usd`, and the other files the stage was composed from (its
    used layers other than the root, outside the root file: sublayers,
    references, payloads), for a cache that must know what a scene was read
    from (:mod:`ignjax.scenes.io.remembered`)."""
    importer, reported = None, []
    try:
        with usd_diagnostics() as reported:
            importer = _Importer(Path(path), scene_id, correct_layer_units)
            scene = importer.run()
            root = importer.stage.GetRootLayer()
            files = tuple(sorted({Path(layer.realPath) for layer in importer.stage.GetUsedLayers()
                                  if layer is not root and layer.realPath and "[" not in layer.realPath}))
            return scene, files
    finally:
        if importer is not None:
            warn_usd_messages(importer.spath, reported, importer.composition_texts)

