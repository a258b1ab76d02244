"""The SceneBank: many compiled scenes stacked as one device pytree.

Scenes differ in size, so every per-scene array is padded to the maxima over
the bank (grid rows and columns, voxel slices, instances, rooms, doors,
primitives) and carries a ``valid`` mask or a valid extent, as in waymax's
``MaskedArray``. Code written for one episode indexes the bank with the
episode's ``scene_index`` and can be ``vmap``-ed over episodes from
different scenes; pass the bank itself unbatched (``in_axes=None``) so no
grid is copied per episode.

Padding never creates a path or a hit: padded grid cells are not navigable,
have room -1 and component -1; the fast ray caster clips each ray to its own
scene's grid extent (:class:`~ignjax.scenes.raygrid.RayGrid`); padded instances,
rooms and doors have ``valid = False`` and index -1 everywhere.

Static metadata (not pytree leaves): scene ids, the category vocabulary, the
grid configuration, and, host-side only, the compiled scenes and navigation
grids (for the exact ray path, rendering and debugging).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import jax
import jax.numpy as jnp
import numpy as np

from ignjax.arrays import on_device, pytree_dataclass
from ignjax.errors import ConfigError
from ignjax.scenes import vocab
from ignjax.scenes.compile import CompileOptions, CompiledScene, compile_scene
from ignjax.scenes.derived import cached_navgrid
from ignjax.scenes.geodesic import geodesic_field, seeds_from_box
from ignjax.scenes.graph import room_adjacency
from ignjax.scenes.model import Scene
from ignjax.scenes.navgrid import GridConfig, NavGrid, check_reachable
from ignjax.scenes.raygrid import RayGrid, ray_grid


@pytree_dataclass(static=("resolution",))
class GridTable:
    """2-D navigation grids of S scenes, padded to (H, W).

    Attributes:
        navigable: (S, H, W) bool.
        room: (S, H, W) int32 room index, -1 outside rooms and in padding.
        components: (S, H, W) int32 navigable component, -1 elsewhere.
        origin: (S, 2) float32 world (x, y) of cell (0, 0)'s lower-left corner.
        shape: (S, 2) int32 valid (rows, cols).
        resolution: cell size, metres (static).
    """

    navigable: jax.Array
    room: jax.Array
    components: jax.Array
    origin: jax.Array
    shape: jax.Array
    resolution: float = 0.05


@pytree_dataclass
class InstanceTable:
    """Instances of S scenes, padded to N.

    Attributes:
        valid: (S, N) bool.
        category: (S, N) int32 index into :attr:`SceneBank.categories`, -1 padding.
        center: (S, N, 3) float32 bounding-box centre, world.
        half_extents: (S, N, 3) float32 box half sizes (own x, y; world z).
        yaw: (S, N) float32 box yaw, radians.
        room: (S, N) int32 room index, -1 outside rooms.
        support: (S, N) int32 index of the supporting instance, -1 none.
        structural: (S, N) bool.
        color: (S, N) int32 :data:`vocab.COLOR_INDEX`, -1 unknown.
        material: (S, N) int32 :data:`vocab.MATERIAL_INDEX`, -1 unknown.
        size: (S, N) int32 :data:`vocab.SIZE_INDEX`, -1 unknown.
        state: (S, N) int32 :data:`vocab.STATE_INDEX`, -1 unknown or none.
    """

    valid: jax.Array
    category: jax.Array
    center: jax.Array
    half_extents: jax.Array
    yaw: jax.Array
    room: jax.Array
    support: jax.Array
    structural: jax.Array
    color: jax.Array
    material: jax.Array
    size: jax.Array
    state: jax.Array


@pytree_dataclass
class RoomTable:
    """Rooms of S scenes, padded to R.

    Attributes:
        valid: (S, R) bool.
        label: (S, R) int32 :data:`vocab.ROOM_LABEL_INDEX`, -1 padding.
        center: (S, R, 2) float32 polygon centroid, world.
        adjacency: (S, R, R) bool, rooms joined by a door or opening.
    """

    valid: jax.Array
    label: jax.Array
    center: jax.Array
    adjacency: jax.Array


@pytree_dataclass
class DoorTable:
    """Doors of S scenes, padded to D.

    Attributes:
        valid: (S, D) bool.
        position: (S, D, 2) float32 centre of the opening, world.
        rooms: (S, D, 2) int32 room indices; -1 for the outside.
        width: (S, D) float32 clear width, metres.
    """

    valid: jax.Array
    position: jax.Array
    rooms: jax.Array
    width: jax.Array


@pytree_dataclass(static=("scene_ids", "categories", "config", "compiled", "navgrids"), untraced=("compiled", "navgrids"))
@dataclass(frozen=True, eq=False)
class SceneBank:
    """Many scenes as one pytree (see the module docstring).

    Attributes:
        rays: fast ray caster arrays (:class:`~ignjax.scenes.raygrid.RayGrid`).
        grid: navigation grids (:class:`GridTable`).
        instances: instance table (:class:`InstanceTable`).
        rooms: room table (:class:`RoomTable`).
        doors: door table (:class:`DoorTable`).
        scene_ids: scene ids, in scene-index order (static).
        categories: the category vocabulary, sorted (static).
        config: the grid configuration (static).
        compiled: host-side compiled scenes, for the exact ray path and
            rendering (static, never traced).
        navgrids: host-side navigation grids (static, never traced).
    """

    rays: RayGrid
    grid: GridTable
    instances: InstanceTable
    rooms: RoomTable
    doors: DoorTable
    scene_ids: tuple[str, ...] = ()
    categories: tuple[str, ...] = ()
    config: GridConfig = GridConfig()
    compiled: tuple[CompiledScene, ...] = ()
    navgrids: tuple[NavGrid, ...] = ()

    # -- construction ---------------------------------------------------------
    @classmethod
    def build(cls, scenes: Sequence[Scene], config: GridConfig = GridConfig(),
              compile_options: CompileOptions = CompileOptions(), check: bool = True) -> "SceneBank":
        """Compile scenes, build their grids, check reachability and stack them.

        Args:
            scenes: the scenes (unique ids).
            config: grid configuration shared by the bank.
            compile_options: MuJoCo compile options.
            check: raise :class:`~ignjax.errors.SceneError` when a scene has
                rooms the agent cannot reach (see
                :func:`~ignjax.scenes.navgrid.check_reachable`).
        """
        compiled = [compile_scene(s, compile_options) for s in scenes]
        grids = [cached_navgrid(c, config) for c in compiled]
        if check:
            for s, g in zip(scenes, grids):
                check_reachable(s, g)
        return cls.from_compiled(compiled, grids)

    @classmethod
    def from_compiled(cls, compiled: Sequence[CompiledScene], grids: Sequence[NavGrid],
                      categories: Sequence[str] | None = None, arrays: bool = True) -> "SceneBank":
        """Stack already compiled scenes and their grids (same grid config).

        Args:
            categories: the category vocabulary (sorted, holding every
                category of the scenes); default: the scenes' own. A bucket of
                a larger benchmark (:mod:`ignjax.episodes.stream`) takes the
                whole benchmark's, so category indices mean the same in every
                bucket.
            arrays: False: the host-side lookups only (ids, vocabulary,
                compiled scenes, grids), no device tables; for checking
                episodes and planning before any table is built.
        """
        compiled = tuple(compiled)
        grids = tuple(grids)
        if not compiled:
            raise ConfigError(None, "scenes", "a SceneBank needs at least one scene")
        if len(compiled) != len(grids):
            raise ConfigError(None, "grids", f"got {len(grids)} grids for {len(compiled)} scenes")
        ids = tuple(c.scene.id for c in compiled)
        if len(set(ids)) != len(ids):
            dup = sorted({i for i in ids if ids.count(i) > 1})
            raise ConfigError(None, "scenes", f"scene ids must be unique in a bank; repeated: {dup}")
        config = grids[0].config
        for g in grids[1:]:
            if g.config != config:
                raise ConfigError(None, "grids", f"scene {g.scene_id!r} was built with another GridConfig")
        scenes = [c.scene for c in compiled]
        own = sorted({i.category for s in scenes for i in s.instances})
        if categories is None:
            categories = tuple(own)
        else:
            categories = tuple(categories)
            missing = sorted(set(own) - set(categories))
            if missing or list(categories) != sorted(set(categories)):
                raise ConfigError(None, "categories", "must be sorted, unique and hold every category of the scenes"
                                  + (f"; missing {missing}" if missing else ""))
        if not arrays:
            return cls(rays=None, grid=None, instances=None, rooms=None, doors=None, scene_ids=ids,
                       categories=categories, config=config, compiled=compiled, navgrids=grids)
        return cls(
            rays=ray_grid(grids, compiled),
            grid=_grid_table(grids),
            instances=_instance_table(scenes, categories),
            rooms=_room_table(scenes),
            doors=_door_table(scenes),
            scene_ids=ids, categories=categories, config=config, compiled=compiled, navgrids=grids,
        )

    # -- lookups (host) -------------------------------------------------------
    @property
    def n_scenes(self) -> int:
        return len(self.scene_ids)

    def scene_index(self, scene_id: str) -> int:
        """Index of a scene id."""
        try:
            return self.scene_ids.index(scene_id)
        except ValueError:
            raise KeyError(f"no scene {scene_id!r} in the bank; scenes: {list(self.scene_ids)}") from None

    def instance_index(self, scene: int | str, instance_id: str) -> int:
        """Index of an instance id in its scene's instance table."""
        s = self.scene_index(scene) if isinstance(scene, str) else int(scene)
        for i, inst in enumerate(self.compiled[s].scene.instances):
            if inst.id == instance_id:
                return i
        raise KeyError(f"scene {self.scene_ids[s]!r} has no instance {instance_id!r}")

    def category_index(self, category: str) -> int:
        """Index of a category in :attr:`categories`, -1 if absent."""
        return self.categories.index(category) if category in self.categories else -1

    def scene(self, index: int) -> Scene:
        return self.compiled[index].scene


# ---------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------


def _pad_stack(items: Sequence[np.ndarray], fill, dtype) -> np.ndarray:
    shape = tuple(max(s) for s in zip(*[np.shape(x) for x in items]))
    out = np.full((len(items),) + shape, fill, dtype=dtype)
    for i, x in enumerate(items):
        x = np.asarray(x)
        out[(i,) + tuple(slice(0, n) for n in x.shape)] = x
    return out


def _grid_table(grids: Sequence[NavGrid]) -> GridTable:
    return GridTable(
        navigable=on_device(_pad_stack([g.navigable for g in grids], False, bool)),
        room=on_device(_pad_stack([g.room for g in grids], -1, np.int32)),
        components=on_device(_pad_stack([g.components for g in grids], -1, np.int32)),
        origin=on_device(np.stack([g.origin for g in grids]).astype(np.float32)),
        shape=on_device(np.array([g.shape for g in grids], np.int32)),
        resolution=grids[0].config.resolution,
    )


def _index(mapping, value) -> int:
    return int(mapping[value]) if value is not None and value in mapping else -1


def _instance_table(scenes: Sequence[Scene], categories: tuple[str, ...]) -> InstanceTable:
    n = max(max(len(s.instances) for s in scenes), 1)
    S = len(scenes)
    cat_index = {c: i for i, c in enumerate(categories)}
    keys = ("category", "room", "support", "color", "material", "size", "state")
    f = {k: np.full((S, n), -1, np.int32) for k in keys}
    valid = np.zeros((S, n), bool)
    structural = np.zeros((S, n), bool)
    center = np.zeros((S, n, 3), np.float32)
    half = np.zeros((S, n, 3), np.float32)
    yaw = np.zeros((S, n), np.float32)
    for s, scene in enumerate(scenes):
        room_of = {r.id: i for i, r in enumerate(scene.rooms)}
        inst_of = {inst.id: i for i, inst in enumerate(scene.instances)}
        for i, inst in enumerate(scene.instances):
            valid[s, i] = True
            structural[s, i] = inst.structural
            f["category"][s, i] = cat_index[inst.category]
            f["room"][s, i] = room_of.get(inst.room, -1) if inst.room is not None else -1
            f["support"][s, i] = inst_of.get(inst.support, -1) if inst.support is not None else -1
            a = inst.attributes
            f["color"][s, i] = _index(vocab.COLOR_INDEX, a.color)
            f["material"][s, i] = _index(vocab.MATERIAL_INDEX, a.material)
            f["size"][s, i] = _index(vocab.SIZE_INDEX, a.size)
            f["state"][s, i] = _index(vocab.STATE_INDEX, a.state)
            center[s, i] = inst.bbox.center
            half[s, i] = inst.bbox.half_extents
            yaw[s, i] = inst.bbox.yaw
    return InstanceTable(valid=on_device(valid), center=on_device(center), half_extents=on_device(half),
                         yaw=on_device(yaw), structural=on_device(structural),
                         **{k: on_device(v) for k, v in f.items()})


def _room_table(scenes: Sequence[Scene]) -> RoomTable:
    R = max(max(len(s.rooms) for s in scenes), 1)
    S = len(scenes)
    valid = np.zeros((S, R), bool)
    label = np.full((S, R), -1, np.int32)
    center = np.zeros((S, R, 2), np.float32)
    adj = np.zeros((S, R, R), bool)
    for s, scene in enumerate(scenes):
        idx = {r.id: i for i, r in enumerate(scene.rooms)}
        for i, r in enumerate(scene.rooms):
            valid[s, i] = True
            label[s, i] = vocab.ROOM_LABEL_INDEX.get(r.label, vocab.ROOM_LABEL_INDEX[vocab.OTHER_ROOM])
            center[s, i] = r.centroid
        for a, nbrs in room_adjacency(scene).items():
            for b in nbrs:
                if a in idx and b in idx:
                    adj[s, idx[a], idx[b]] = True
    return RoomTable(valid=on_device(valid), label=on_device(label), center=on_device(center),
                     adjacency=on_device(adj))


def _door_table(scenes: Sequence[Scene]) -> DoorTable:
    D = max(max(len(s.doors) for s in scenes), 1)
    S = len(scenes)
    valid = np.zeros((S, D), bool)
    pos = np.zeros((S, D, 2), np.float32)
    rooms = np.full((S, D, 2), -1, np.int32)
    width = np.zeros((S, D), np.float32)
    for s, scene in enumerate(scenes):
        idx = {r.id: i for i, r in enumerate(scene.rooms)}
        for i, d in enumerate(scene.doors):
            valid[s, i] = True
            pos[s, i] = d.position
            rooms[s, i] = [idx.get(r, -1) if r is not None else -1 for r in d.rooms]
            width[s, i] = d.width
    return DoorTable(valid=on_device(valid), position=on_device(pos), rooms=on_device(rooms),
                     width=on_device(width))


# ---------------------------------------------------------------------------
# Geodesic fields of targets
# ---------------------------------------------------------------------------


def target_field(bank: SceneBank, scene_index: jax.Array, instance_index: jax.Array,
                 seed_radius: float = 1.0) -> jax.Array:
    """Geodesic distance field to one instance of one scene (jnp, vmappable).

    Seeds are the navigable cells of the instance's room within
    ``seed_radius`` of its footprint (see
    :func:`~ignjax.scenes.geodesic.seeds_from_box`), so the field reads as
    "geodesic distance to the object".

    Args:
        bank: the scene bank (unbatched under vmap).
        scene_index: () int32.
        instance_index: () int32.
        seed_radius: metres (static).

    Returns:
        (H, W) float32 metres on the bank's padded grid, +inf where the
        object cannot be reached (and in padding).
    """
    s = jnp.asarray(scene_index, jnp.int32)
    i = jnp.asarray(instance_index, jnp.int32)
    g = bank.grid
    inst = bank.instances
    nav = g.navigable[s]
    seeds = seeds_from_box(nav, g.room[s], g.origin[s], g.resolution, inst.center[s, i], inst.half_extents[s, i],
                           inst.yaw[s, i], inst.room[s, i], seed_radius)
    seeds = jnp.where(inst.valid[s, i], seeds, jnp.inf)
    return geodesic_field(nav, seeds, g.resolution)


def target_fields(bank: SceneBank, scene_index: jax.Array, instance_index: jax.Array,
                  seed_radius: float = 1.0) -> jax.Array:
    """Geodesic distance fields of a batch of (scene, instance) targets.

    Args:
        bank: the scene bank.
        scene_index: (B,) int32.
        instance_index: (B,) int32.
        seed_radius: metres (static).

    Returns:
        (B, H, W) float32 fields (see :func:`target_field`).
    """
    with jax.named_scope("target_fields"):
        return jax.vmap(lambda s, i: target_field(bank, s, i, seed_radius))(
            jnp.asarray(scene_index, jnp.int32), jnp.asarray(instance_index, jnp.int32))


def field_at(bank: SceneBank, field: jax.Array, scene_index: jax.Array, xy: jax.Array) -> jax.Array:
    """Value of a (padded) per-scene grid field at a world point (jnp).

    Args:
        bank: the scene bank.
        field: (H, W) field on the bank's padded grid.
        scene_index: () int32 scene the field belongs to.
        xy: (2,) world point.

    Returns:
        () the field at the cell containing ``xy``; +inf outside the scene's grid.
    """
    g = bank.grid
    res = g.resolution
    col = jnp.floor((xy[0] - g.origin[scene_index, 0]) / res).astype(jnp.int32)
    row = jnp.floor((xy[1] - g.origin[scene_index, 1]) / res).astype(jnp.int32)
    inside = (row >= 0) & (col >= 0) & (row < g.shape[scene_index, 0]) & (col < g.shape[scene_index, 1])
    val = field[jnp.clip(row, 0, field.shape[0] - 1), jnp.clip(col, 0, field.shape[1] - 1)]
    return jnp.where(inside, val, jnp.inf).astype(field.dtype)
