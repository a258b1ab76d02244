"""Object instances from a stage: an owner's geometry placed and measured
(box, position, heading, colour, category), an ``ignjax`` instance restored
from its stored attributes, and one instance per PointInstancer point.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from pxr import Usd, UsdGeom

from ignjax.errors import SceneError
from ignjax.scenes import vocab
from ignjax.scenes.io.footprint import min_area_rect, rect_extents, rect_from
from ignjax.scenes.io.usd.frames import TIME, Frames, apply, col, pose, quat_from_matrix, scale4, upright_rigid, wrap
from ignjax.scenes.io.usd.mesh import triangulate_faces
from ignjax.scenes.io.usd.naming import asset_stem, category_chain, custom_kind
from ignjax.scenes.io.usd.parts import GEOM_ATTRS, Part, Source, authored, gprim_type, place, read_source, token
from ignjax.scenes.io.usd.stage import ATTR_ID, ATTR_KIND, NS, prim_semantic_label, warn_import
from ignjax.scenes.io.usd.traversal import Owner, hidden
from ignjax.scenes.model import Attributes, Geom, Instance, MeshData, OrientedBox


class InstanceBuilder:
    """Makes the instances of one stage; keeps the ids given so far unique and
    counts the geometry parts imported."""

    def __init__(self, stage, spath: str, frames: Frames):
        self.stage, self.spath, self.frames = stage, spath, frames
        self._sources: dict[str, Source | None] = {}
        self._ids: set[str] = set()
        self.n_parts = 0

    # -- parts --------------------------------------------------------------------
    def source(self, prim) -> Source | None:
        """The prim's raw geometry (read once per prim)."""
        key = str(prim.GetPath())
        if key not in self._sources:
            self._sources[key] = read_source(prim, self.spath)
        return self._sources[key]

    def part(self, prim, to_world: np.ndarray | None = None) -> Part | None:
        """The prim's geometry placed in the world (``to_world``: its frame, default the prim's own); None when empty.
"""
        src = self.source(prim)
        if src is None:
            return None
        unit = self.frames.unit(prim, GEOM_ATTRS.get(src.usd_type, ()))
        frame = self.frames.frame(prim) if to_world is None else to_world
        part = place(src, frame @ scale4(unit))
        if part is not None and len(part.faces):
            self.n_parts += 1
            return part
        return None

    def parts(self, owner: Owner) -> list[Part]:
        """The placed geometry of every geometry prim the owner owns."""
        return [p for p in (self.part(g) for g in owner.gprims) if p is not None]

    # -- ids ----------------------------------------------------------------------
    def unique_id(self, base: str) -> str:
        """``base``, or ``base_2``, ``base_3``... when already taken."""
        base = base or "object"
        iid, k = base, 2
        while iid in self._ids:
            iid = f"{base}_{k}"
            k += 1
        self._ids.add(iid)
        return iid

    # -- instances ------------------------------------------------------------------
    def generic_instance(self, parts: list[Part], heading: np.ndarray, iid: str, category: str, name: str,
                         extra: dict | None = None) -> Instance:
        """An instance measured from its placed parts: box, position, heading (``heading``'s x axis) and colour."""
        verts = np.concatenate([p.verts for p in parts])
        zmin, zmax = float(verts[:, 2].min()), float(verts[:, 2].max())
        xy = verts[:, :2]
        x_axis = heading[:2, 0]
        yaw = math.atan2(x_axis[1], x_axis[0]) if np.hypot(*x_axis) > 1e-9 else 0.0
        yaw = wrap(yaw)
        center, half, byaw = min_area_rect(xy)
        lo, hi = rect_extents(xy, np.array([yaw]))
        if np.prod(hi[0] - lo[0]) <= np.prod(2 * half) * (1 + 1e-3) + 1e-12:
            center, half, byaw = rect_from(lo[0], hi[0], yaw)
        bbox = OrientedBox((center[0], center[1], (zmin + zmax) / 2), (half[0], half[1], (zmax - zmin) / 2), byaw)
        position = (float(center[0]), float(center[1]), zmin)
        inv = np.linalg.inv(pose(position, yaw))
        geoms = tuple(self.to_geom(p, inv) for p in parts if p.role == "geom")
        colored = [p for p in parts if p.has_color and p.role == "geom"]
        attrs = dict(color=None, material=None, size=None, state=None)
        if colored:
            weights = np.array([max(p.area, 1e-12) for p in colored])
            rgb = (np.array([p.rgba[:3] for p in colored]) * weights[:, None]).sum(0) / weights.sum()
            attrs["color"] = vocab.nearest_color(rgb)
        attrs.update({k: v for k, v in (extra or {}).items() if v is not None})
        return Instance(id=iid, category=category, position=position, yaw=yaw, bbox=bbox,
                        attributes=Attributes(**attrs), structural=vocab.is_structural(category), geoms=geoms, name=name)

    @staticmethod
    def to_geom(part: Part, inv: np.ndarray) -> Geom:
        """A part as a geom in the instance frame (``inv``: world -> instance)."""
        if part.pose is not None:
            local = inv @ part.pose
            return Geom(part.kind, part.size, tuple(local[:3, 3]), quat_from_matrix(local[:3, :3]), part.rgba)
        v = apply(inv, part.verts)
        c = (v.min(0) + v.max(0)) / 2
        return Geom("mesh", (1.0, 1.0, 1.0), tuple(c), (1.0, 0.0, 0.0, 0.0), part.rgba,
                    mesh=MeshData(v - c, part.faces))

    def owner_category(self, owner: Owner) -> str:
        """The owner's category: its label, else its kind, name or referenced asset."""
        prim = owner.prim
        if owner.label and vocab.normalize_category(owner.label) != vocab.UNKNOWN_CATEGORY:
            return vocab.normalize_category(owner.label)
        return category_chain((owner.label, custom_kind(prim)), (prim.GetName(), asset_stem(prim, self.stage)))

    def owner_extra(self, prim) -> dict:
        """The ``ignjax:`` colour/material/size/state attributes authored on the prim."""
        return {k: authored(prim, NS + k) for k in ("color", "material", "size", "state")}

    def restore_geom(self, prim) -> Geom | None:
        """A geom stored by :func:`~ignjax.scenes.io.usd.export.save_usd`, or None."""
        kind = authored(prim, NS + "geom:kind")
        size, pos, quat = authored(prim, NS + "geom:size"), authored(prim, NS + "geom:pos"), authored(prim, NS + "geom:quat")
        if kind is None or size is None or pos is None or quat is None:
            return None
        rgba = authored(prim, NS + "geom:rgba") or (0.7, 0.7, 0.7, 1.0)
        mesh = None
        if kind == "mesh":
            m = UsdGeom.Mesh(prim)
            exact = authored(prim, NS + "geom:vertices")
            pts = m.GetPointsAttr().Get(TIME)
            verts = np.asarray(exact if exact is not None else pts, dtype=np.float64).reshape(-1, 3)
            if not np.all(np.isfinite(verts)):
                raise SceneError(self.spath, f"{prim.GetPath()}.points", "points have NaN or infinite values")
            faces = triangulate_faces(verts, m.GetFaceVertexCountsAttr().Get(TIME) or [],
                                      m.GetFaceVertexIndicesAttr().Get(TIME) or [], path=self.spath,
                                      where=f"{prim.GetPath()}.faceVertexIndices")
            mesh = MeshData(verts, faces)
        q = (quat[0], quat[1], quat[2], quat[3])
        return Geom(str(kind), tuple(size), tuple(pos), q, tuple(rgba[i] for i in range(4)),
                    str(authored(prim, NS + "geom:part") or ""), authored(prim, NS + "geom:material"), mesh)

    def ignjax_instance(self, owner: Owner) -> Instance | None:
        """An instance stored by :func:`~ignjax.scenes.io.usd.export.save_usd`, moved along when it was moved or turned
        about Z, measured again when scaled or tilted."""
        prim = owner.prim
        iid = authored(prim, ATTR_ID) or prim.GetName()
        category = authored(prim, NS + "category") or self.owner_category(owner)
        pos, yaw = authored(prim, NS + "position"), authored(prim, NS + "yaw")
        bc, bh, by = authored(prim, NS + "bbox:center"), authored(prim, NS + "bbox:halfExtents"), authored(prim, NS + "bbox:yaw")
        extra = self.owner_extra(prim)
        keep = dict(room=authored(prim, NS + "room"), support=authored(prim, NS + "support"),
                    structural=bool(authored(prim, NS + "structural")) or vocab.is_structural(category),
                    name=str(authored(prim, NS + "name") or prim.GetPath()))
        frame = self.frames.frame(prim)
        theta, moved, delta = None, False, np.eye(4)
        if None not in (pos, yaw, bc, bh, by):
            pos, bc, bh = tuple(map(float, pos)), tuple(map(float, bc)), tuple(map(float, bh))
            delta = frame @ np.linalg.inv(pose(pos, float(yaw)))
            moved = not np.allclose(delta, np.eye(4), atol=1e-6)
            theta = upright_rigid(delta) if moved else 0.0
        if theta is None:  # moved, scaled or sheared after export: measure it again
            parts = self.parts(owner)
            if not parts:
                return None
            inst = self.generic_instance(parts, frame, self.unique_id(str(iid)), str(category), keep["name"], extra)
            return dataclasses.replace(inst, **{k: v for k, v in keep.items() if k != "name"})
        geoms, others = [], []
        for g in owner.gprims:
            kind = token(g, ATTR_KIND, "")
            restored = self.restore_geom(g) if kind == "geom" else None
            if restored is not None:
                geoms.append((int(authored(g, NS + "geom:index") or 0), restored))
            elif kind != "bbox":
                others.append(g)
        geoms = [g for _, g in sorted(geoms, key=lambda t: t[0])]
        position, iyaw, bbox = pos, float(yaw), OrientedBox(bc, bh, float(by))
        if moved:
            position = tuple(apply(delta, np.array([pos]))[0])
            bcenter = tuple(apply(delta, np.array([bc]))[0])
            iyaw, bbox = wrap(iyaw + theta), OrientedBox(bcenter, bh, wrap(float(by) + theta))
        if others:
            inv = np.linalg.inv(pose(position, iyaw))
            geoms += [self.to_geom(p, inv) for p in (self.part(g) for g in others) if p is not None]
        self.n_parts += 1
        attrs = Attributes(**{k: (None if v is None else str(v)) for k, v in extra.items()})
        return Instance(id=self.unique_id(str(iid)), category=str(category), position=position, yaw=iyaw, bbox=bbox,
                        room=keep["room"], attributes=attrs, support=keep["support"], structural=keep["structural"],
                        geoms=tuple(geoms), name=keep["name"])

    def pointinstancer_instances(self, prim) -> list[Instance]:
        """One instance per (unmasked) point of a PointInstancer."""
        pi = UsdGeom.PointInstancer(prim)
        where = str(prim.GetPath())
        protos = [self.stage.GetPrimAtPath(t) for t in pi.GetPrototypesRel().GetForwardedTargets()]
        indices = pi.GetProtoIndicesAttr().Get(TIME)
        positions = pi.GetPositionsAttr().Get(TIME)
        if indices is None or len(indices) == 0:
            return []
        if positions is not None and not np.all(np.isfinite(np.asarray(positions, dtype=np.float64))):
            raise SceneError(self.spath, f"{where}.positions", "positions have NaN or infinite values")
        xforms = pi.ComputeInstanceTransformsAtTime(TIME, TIME, UsdGeom.PointInstancer.ExcludeProtoXform,
                                                    UsdGeom.PointInstancer.IgnoreMask)
        if xforms is None or len(xforms) != len(indices):
            raise SceneError(self.spath, where, "PointInstancer has inconsistent protoIndices, positions, "
                                                "orientations or scales")
        mask = list(pi.ComputeMaskAtTime(TIME) or [])
        unit = self.frames.attr_unit(pi.GetPositionsAttr(), prim)
        frame = self.frames.frame(prim)
        pred = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
        per_proto = []
        for proto in protos:
            if not proto or not proto.IsValid():
                per_proto.append(None)
                continue
            gprims = []
            it = iter(Usd.PrimRange(proto, pred))
            for g in it:
                if hidden(g):
                    it.PruneChildren()
                    continue
                if gprim_type(g) and self.source(g) is not None:
                    src = self.source(g)
                    rel = self.frames.relative(g, proto.GetParent())
                    gprims.append((g, rel @ scale4(self.frames.unit(g, GEOM_ATTRS.get(src.usd_type, ())))))
            root_rel = self.frames.relative(proto, proto.GetParent())
            category = category_chain((prim_semantic_label(proto), prim_semantic_label(prim), custom_kind(proto)),
                                       (proto.GetName(), prim.GetName(), asset_stem(proto, self.stage)))
            per_proto.append((gprims, root_rel, category))
        out = []
        for k, (pidx, m) in enumerate(zip(indices, xforms)):
            if mask and not mask[k]:
                continue
            if not (0 <= pidx < len(per_proto)) or per_proto[pidx] is None:
                warn_import(self.spath, f"{where}: point {k} uses prototype index {pidx}, which does not exist; skipped")
                continue
            gprims, root_rel, category = per_proto[pidx]
            inst_m = col(m)
            inst_m[:3, 3] *= unit
            if not np.all(np.isfinite(inst_m)):
                raise SceneError(self.spath, f"{where} (point {k})", "instance transform has NaN or infinite values")
            base = frame @ inst_m
            parts = []
            for g, rel in gprims:
                part = place(self.source(g), base @ rel)
                if part is not None and len(part.faces):
                    parts.append(part)
            if not parts:
                continue
            self.n_parts += len(parts)
            out.append(self.generic_instance(parts, base @ root_rel, self.unique_id(f"{prim.GetName()}_{k}"),
                                             category, f"{where}[{k}]"))
        return out
