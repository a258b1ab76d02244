"""Navigation grids derived from a compiled scene.

:func:`build_navgrid` turns a :class:`~ignjax.scenes.compile.CompiledScene`
into a :class:`NavGrid` (host-side numpy arrays): a voxel occupancy of every
non-floor geom, height-band occupancy, the navigable mask, a room-id grid,
connected components, and the acceleration structures of the fast ray caster
(stacked on the device by :mod:`ignjax.scenes.raygrid`, read by
:mod:`ignjax.sim.rays.fast`). Geodesic distances on the navigable mask are
:mod:`ignjax.scenes.geodesic`.

Cells
    The grid is axis-aligned, ``resolution`` metres per cell. Rows run along
    +y, columns along +x: cell ``(row, col)`` covers
    ``x in [origin_x + col * res, origin_x + (col + 1) * res)`` and
    ``y in [origin_y + row * res, origin_y + (row + 1) * res)``; its centre is
    ``origin + (col + 1/2, row + 1/2) * res``. ``origin`` (world x, y of the
    lower-left corner of cell (0, 0)) is a multiple of the resolution, so
    walls snapped to the resolution lie on cell boundaries. See
    :meth:`NavGrid.world_to_cell` and :meth:`NavGrid.cell_to_world`.

Bands and navigability
    Band ``b`` (``GridConfig.bands``, heights in metres) is occupied in a cell
    when any slice overlapping the open interval ``(lo, hi)`` is occupied, so
    rugs below the lowest band and lintels above the highest do not block.
    A cell is *blocked* when it is occupied in some band or outside all
    rooms. A cell is *navigable* when it lies in a room and a disc of radius
    ``agent_radius`` around its centre overlaps no blocked cell (exact
    disc/square test). Components are 4-connected, which equals the
    connectivity of the 8-connected grid without corner cutting used by
    :func:`ignjax.scenes.geodesic.geodesic_field`.

Voxels, exact primitives and the ray caster's acceleration structures are
:mod:`ignjax.scenes.voxels`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ignjax.errors import ConfigError, SceneError
from ignjax.scenes.model import Scene
from ignjax.scenes.model.polygons import points_in_polygon
from ignjax.scenes.voxels import march_codes, scene_extent, voxelize


# ---------------------------------------------------------------------------
# Configuration
# ---------------------------------------------------------------------------


def _bad(name: str, reason: str) -> ConfigError:
    return ConfigError(None, f"GridConfig.{name}", reason)


@dataclass(frozen=True)
class GridConfig:
    """Static configuration of navigation grids (validated on construction).

    Attributes:
        resolution: cell size in x and y, metres.
        agent_radius: radius of the agent's footprint disc, metres. 0.18 m is
            a compact wheeled robot (LoCoBot-like); procedural houses keep
            their passages connected for a 0.2 m radius, so anything up to
            that works on them.
        bands: height bands ``(lo, hi)`` in metres, increasing and disjoint:
            by default low furniture (beds, seats: 0.05-0.45 m), table level
            (0.45-1.0 m) and tall furniture (1.0-1.9 m). Geometry below the
            first band (rugs) or above the last (lintels, ceiling lamps) never
            blocks the agent.
        band_names: one name per band.
        margin: free border around the scene's bounds, metres.
        slice_height: voxel height, metres; must divide ``list_band_height``.
        max_height: top of the voxel grid, metres; None (default) covers the
            scene's geometry (rounded up to whole list bands). Geometry above
            it is ignored by the voxel grid and the fast ray caster.
        list_band_height: height of the column segments whose primitive lists
            the fast ray caster tests exactly, metres.
        max_list: at most this many primitives per column segment; fuller
            segments fall back to voxel accuracy (counted in
            :attr:`NavGrid.n_approx`).
        ray_groups: MuJoCo geom groups that are obstacles and ray targets
            (default walls 1, objects 2, structural instances 3; the floor,
            group 0, is handled analytically by the ray caster).
    """

    resolution: float = 0.05
    agent_radius: float = 0.18
    bands: tuple[tuple[float, float], ...] = ((0.05, 0.45), (0.45, 1.0), (1.0, 1.9))
    band_names: tuple[str, ...] = ("low", "table", "tall")
    margin: float = 0.5
    slice_height: float = 0.05
    max_height: float | None = None
    list_band_height: float = 0.25
    max_list: int = 32
    ray_groups: tuple[int, ...] = (1, 2, 3)

    def __post_init__(self):
        def pos(name):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v <= 0:
                raise _bad(name, f"must be a positive number, got {v!r}")
            object.__setattr__(self, name, float(v))

        for name in ("resolution", "slice_height", "list_band_height"):
            pos(name)
        for name in ("agent_radius", "margin"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v < 0:
                raise _bad(name, f"must be a non-negative number, got {v!r}")
            object.__setattr__(self, name, float(v))
        if self.max_height is not None:
            pos("max_height")
        ratio = self.list_band_height / self.slice_height
        if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
            raise _bad("list_band_height",
                       f"must be a whole number of slice_height ({self.slice_height}), got {self.list_band_height}")
        try:
            bands = tuple((float(lo), float(hi)) for lo, hi in self.bands)
        except (TypeError, ValueError):
            raise _bad("bands", f"expected a sequence of (lo, hi) pairs, got {self.bands!r}") from None
        if not bands:
            raise _bad("bands", "needs at least one (lo, hi) band")
        prev = -math.inf
        for lo, hi in bands:
            if not (math.isfinite(lo) and math.isfinite(hi)) or lo < 0 or hi <= lo or lo < prev:
                raise _bad("bands",
                           f"bands must be increasing, disjoint (lo, hi) pairs with 0 <= lo < hi, got {self.bands}")
            prev = hi
        object.__setattr__(self, "bands", bands)
        names = tuple(str(n) for n in self.band_names)
        if len(names) != len(bands):
            names = tuple(f"band_{i}" for i in range(len(bands))) if self.band_names == GridConfig.band_names else names
        if len(names) != len(bands):
            raise _bad("band_names", f"needs one name per band ({len(bands)}), got {len(names)}")
        object.__setattr__(self, "band_names", names)
        if not isinstance(self.max_list, int) or isinstance(self.max_list, bool) or not 1 <= self.max_list <= 255:
            raise _bad("max_list", f"must be an integer in 1..255, got {self.max_list!r}")
        try:
            groups = tuple(int(g) for g in self.ray_groups)
        except (TypeError, ValueError):
            raise _bad("ray_groups", f"expected a sequence of integers, got {self.ray_groups!r}") from None
        if any(g < 0 or g >= mujoco.mjNGROUP for g in groups):
            raise _bad("ray_groups", f"groups must be in 0..{mujoco.mjNGROUP - 1}, got {self.ray_groups}")
        object.__setattr__(self, "ray_groups", groups)

    @property
    def slices_per_list_band(self) -> int:
        return int(round(self.list_band_height / self.slice_height))


# ---------------------------------------------------------------------------
# The grid
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class NavGrid:
    """A scene's navigation grid (host-side numpy). See the module docstring
    for the cell and voxel conventions.

    Attributes:
        scene_id: the scene's id.
        config: the configuration used.
        origin: (2,) float64, world (x, y) of the lower-left corner of cell (0, 0).
        shape: (H, W) = (rows along y, columns along x).
        n_slices: number of voxel slices (Z).
        room_ids: scene room ids; ``room[r, c] = i`` means ``room_ids[i]``.
        occupancy: (Z, H, W) bool voxel occupancy of non-floor geoms.
        bands: (n_bands, H, W) bool band occupancy.
        obstacle: (H, W) bool, occupied in some band.
        room: (H, W) int32 index of the first room (scene order) whose floor
            polygon contains the cell centre, -1 outside all rooms.
        clearance: (H, W) float32, metres from the cell centre to the nearest
            blocked cell's centre (blocked: obstacle or outside all rooms).
        navigable: (H, W) bool.
        components: (H, W) int32 component label of navigable cells, -1 elsewhere.
        n_components: number of components.
        voxcode: (Z, H, W) uint8 march code of each voxel (see :func:`~ignjax.scenes.voxels.march_codes`).
        sub_box: (Z, H, W) uint16 where in each occupied voxel its geometry
            lies (see :func:`~ignjax.scenes.voxels.pack_sub_boxes`); 0 in free voxels.
        prims: (P, 18) float32 exact primitives, see :data:`~ignjax.scenes.voxels.PRIM_COLUMNS`.
        prim_geom: (P,) int32 MuJoCo geom id of each primitive.
        seg_start: (H, W, B) int32 first entry of each column segment in ``seg_prims``.
        seg_count: (H, W, B) uint8 number of primitives of each segment.
        seg_prims: (M,) int32 primitive indices, segment after segment.
        approx: (H, W, B) bool, segment kept at voxel accuracy.
        n_approx: number of approximate segments that are occupied.
    """

    scene_id: str
    config: GridConfig
    origin: np.ndarray
    shape: tuple[int, int]
    n_slices: int
    room_ids: tuple[str, ...]
    occupancy: np.ndarray
    bands: np.ndarray
    obstacle: np.ndarray
    room: np.ndarray
    clearance: np.ndarray
    navigable: np.ndarray
    components: np.ndarray
    n_components: int
    voxcode: np.ndarray
    sub_box: np.ndarray
    prims: np.ndarray
    prim_geom: np.ndarray
    seg_start: np.ndarray
    seg_count: np.ndarray
    seg_prims: np.ndarray
    approx: np.ndarray
    n_approx: int

    @property
    def resolution(self) -> float:
        return self.config.resolution

    @property
    def slice_height(self) -> float:
        return self.config.slice_height

    @property
    def height(self) -> float:
        """Top of the voxel grid, metres."""
        return self.n_slices * self.config.slice_height

    def world_to_cell(self, xy) -> np.ndarray:
        """(..., 2) world (x, y) -> (..., 2) int (row, col); may be out of range."""
        p = np.asarray(xy, dtype=np.float64)
        col = np.floor((p[..., 0] - self.origin[0]) / self.resolution)
        row = np.floor((p[..., 1] - self.origin[1]) / self.resolution)
        return np.stack([row, col], -1).astype(np.int64)

    def cell_to_world(self, rc) -> np.ndarray:
        """(..., 2) (row, col) -> (..., 2) world (x, y) of the cell centres."""
        q = np.asarray(rc, dtype=np.float64)
        x = self.origin[0] + (q[..., 1] + 0.5) * self.resolution
        y = self.origin[1] + (q[..., 0] + 0.5) * self.resolution
        return np.stack([x, y], -1)

    def in_bounds(self, rc) -> np.ndarray:
        """(..., 2) (row, col) -> (...) bool, inside the grid."""
        q = np.asarray(rc)
        return (q[..., 0] >= 0) & (q[..., 0] < self.shape[0]) & (q[..., 1] >= 0) & (q[..., 1] < self.shape[1])

    def cell_centers(self) -> np.ndarray:
        """(H, W, 2) world (x, y) of every cell centre."""
        rows, cols = np.mgrid[0:self.shape[0], 0:self.shape[1]]
        return self.cell_to_world(np.stack([rows, cols], -1))

    def room_index(self, room_id: str | None) -> int:
        """Index of a room id in :attr:`room_ids` (-1 for None)."""
        if room_id is None:
            return -1
        return self.room_ids.index(room_id)

    def navigable_points(self) -> np.ndarray:
        """(M, 2) world (x, y) centres of the navigable cells."""
        return self.cell_to_world(np.argwhere(self.navigable))


# ---------------------------------------------------------------------------
# Bands, rooms, navigability
# ---------------------------------------------------------------------------


def _band_occupancy(occ: np.ndarray, config: GridConfig) -> np.ndarray:
    dz = config.slice_height
    out = []
    for lo, hi in config.bands:
        k0 = int(math.floor(lo / dz + 1e-9))
        k1 = int(math.ceil(hi / dz - 1e-9))  # slices k0..k1-1 overlap (lo, hi)
        k1 = min(k1, occ.shape[0])
        if k1 <= k0:
            out.append(np.zeros(occ.shape[1:], bool))
        else:
            out.append(occ[k0:k1].any(0))
    return np.stack(out)


def _disc_footprint(radius: float, res: float) -> np.ndarray:
    """Offsets (as a boolean kernel) of cells whose square lies within
    ``radius`` of the centre of the kernel's middle cell."""
    n = int(math.ceil(radius / res + 0.5))
    o = np.arange(-n, n + 1)
    dx = np.maximum(np.abs(o)[None, :] - 0.5, 0.0) * res
    dy = np.maximum(np.abs(o)[:, None] - 0.5, 0.0) * res
    return dx**2 + dy**2 < radius**2


def room_grid(scene: Scene, origin, shape, res: float) -> np.ndarray:
    """(H, W) int32 index of the first room containing each cell centre, -1 if none."""
    H, W = shape
    out = np.full((H, W), -1, np.int32)
    for i, room in enumerate(scene.rooms):
        poly = np.asarray(room.polygon, dtype=np.float64)
        if len(poly) < 3:
            continue
        c0 = max(int(math.floor((poly[:, 0].min() - origin[0]) / res)) - 1, 0)
        c1 = min(int(math.ceil((poly[:, 0].max() - origin[0]) / res)) + 1, W)
        r0 = max(int(math.floor((poly[:, 1].min() - origin[1]) / res)) - 1, 0)
        r1 = min(int(math.ceil((poly[:, 1].max() - origin[1]) / res)) + 1, H)
        if c1 <= c0 or r1 <= r0:
            continue
        xs = origin[0] + (np.arange(c0, c1) + 0.5) * res
        ys = origin[1] + (np.arange(r0, r1) + 0.5) * res
        pts = np.stack(np.meshgrid(xs, ys), -1)
        inside = points_in_polygon(pts, poly)
        sub = out[r0:r1, c0:c1]
        sub[(sub < 0) & inside] = i
    return out


def build_navgrid(compiled, config: GridConfig = GridConfig()) -> NavGrid:
    """Build a scene's navigation grid from its compiled MuJoCo model.

    Args:
        compiled: a :class:`~ignjax.scenes.compile.CompiledScene` (geom world
            poses are read from ``compiled.data`` after ``mj_forward``).
        config: grid configuration.

    Returns:
        The :class:`NavGrid`.
    """
    from scipy import ndimage  # here, not at import: a warm run reads its grids from the cache (0.27 s)
    if not isinstance(config, GridConfig):
        raise ConfigError(None, "config", f"expected GridConfig, got {type(config).__name__}")
    scene: Scene = compiled.scene
    origin, shape, n_slices = scene_extent(compiled, config)
    occ, occ_ray, full, sub_box, prims, prim_geom, (seg_start, seg_count, seg_prims), approx = voxelize(
        compiled, config, origin, shape, n_slices)
    bands = _band_occupancy(occ, config)
    obstacle = bands.any(0)
    room = room_grid(scene, origin, shape, config.resolution)
    blocked = obstacle | (room < 0)
    clearance = ndimage.distance_transform_edt(~blocked, sampling=config.resolution).astype(np.float32)
    if not blocked.any():
        clearance[:] = np.inf
    near = ndimage.binary_dilation(blocked, structure=_disc_footprint(config.agent_radius, config.resolution)) \
        if config.agent_radius > 0 else blocked
    navigable = (room >= 0) & ~near & ~blocked
    labels, n = ndimage.label(navigable)
    components = (labels - 1).astype(np.int32)
    voxcode = march_codes(occ, occ_ray, full)
    n_approx = int(approx.sum())
    return NavGrid(
        scene_id=scene.id, config=config, origin=origin, shape=shape, n_slices=n_slices,
        room_ids=tuple(r.id for r in scene.rooms), occupancy=occ, bands=bands, obstacle=obstacle,
        room=room, clearance=clearance, navigable=navigable, components=components, n_components=int(n),
        voxcode=voxcode, sub_box=sub_box, prims=prims, prim_geom=prim_geom, seg_start=seg_start,
        seg_count=seg_count, seg_prims=seg_prims, approx=approx, n_approx=n_approx,
    )


# ---------------------------------------------------------------------------
# Reachability
# ---------------------------------------------------------------------------


def unreachable_rooms(scene: Scene, grid: NavGrid) -> list[str]:
    """Ids of rooms with no navigable cell in the main component.

    The main component is the navigable component touching the most rooms
    (ties: the larger one). A room is reachable when some navigable cell of
    it lies in the main component.
    """
    labels = grid.components
    n_rooms = len(grid.room_ids)
    if n_rooms == 0:
        return []
    if grid.n_components == 0:
        return list(grid.room_ids)
    nav = grid.navigable
    pairs = np.unique(np.stack([grid.room[nav], labels[nav]], -1), axis=0)
    pairs = pairs[pairs[:, 0] >= 0]
    rooms_per_comp = np.bincount(pairs[:, 1], minlength=grid.n_components)
    size = np.bincount(labels[nav], minlength=grid.n_components)
    main = int(np.lexsort((size, rooms_per_comp))[-1])
    reached = set(pairs[pairs[:, 1] == main, 0].tolist())
    return [grid.room_ids[i] for i in range(n_rooms) if i not in reached]


def check_reachable(scene: Scene, grid: NavGrid, path: str | None = None) -> None:
    """Raise :class:`~ignjax.errors.SceneError` unless every room has a
    navigable cell in one common navigable component.

    Args:
        scene: the scene the grid was built from.
        grid: its navigation grid.
        path: the source file to name in the error (default ``scene.meta.source``).

    Raises:
        SceneError: naming every unreachable room (id, label, and whether it
            has no navigable cells at all).
    """
    bad = unreachable_rooms(scene, grid)
    if not bad:
        return
    parts = []
    for rid in bad:
        i = grid.room_index(rid)
        n_cells = int((grid.navigable & (grid.room == i)).sum())
        label = scene.room(rid).label
        why = "has no navigable cells" if n_cells == 0 else f"is cut off from the rest ({n_cells} navigable cells)"
        parts.append(f"{rid} ({label}) {why}")
    reached = [r for r in grid.room_ids if r not in bad]
    raise SceneError(
        path or scene.meta.source, f"scene {scene.id!r} navigation grid",
        f"rooms not reachable from the others for an agent of radius {grid.config.agent_radius} m: "
        + "; ".join(parts) + (f" (reachable: {', '.join(reached)})" if reached else ""),
    )
