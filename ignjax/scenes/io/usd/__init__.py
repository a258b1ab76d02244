"""USD stages: export a :class:`~ignjax.scenes.model.Scene` and import any stage.

Public API
    :func:`save_usd` writes a scene as a stage (``.usda``, ``.usdc``, ``.usd``
    or ``.usdz``); :func:`load_usd` reads any stage into a scene. Small
    helpers: :func:`open_stage`, :func:`stage_up_axis`,
    :func:`stage_meters_per_unit`, :func:`prim_semantic_label`,
    :func:`triangulate_faces`.

Modules
    ===============  ======================================================
    ``stage``        opening a stage, up axis, unit, semantic labels, the
                     attribute names export and import share, warnings
                     (USD's own diagnostics trapped and summarised)
    ``mesh``         triangulating faces; meshes of USD's primitives
    ``export``       :func:`save_usd`, :func:`scene_to_stage` (and the
                     exported layout)
    ``load``         :func:`load_usd` (and the import rules)
    ``frames``       world transforms, layer units
    ``traversal``    which prims become instances and rooms
    ``parts``        geometry prims placed in the world
    ``naming``       categories and room labels from labels, room
                     attributes and names (the name rules themselves are
                     :mod:`ignjax.scenes.io.names`, shared with the mesh
                     importer)
    ``instances``    building instances
    ``rooms``        building rooms, walls and doors
    ===============  ======================================================
"""

from ignjax.cache.programs import settle_prefetch

settle_prefetch()  # no program may load ahead while USD's libraries load (ignjax.cache.programs.start_prefetch)

from ignjax.scenes.io.formats import USD_SUFFIXES  # noqa: E402
from ignjax.scenes.io.usd.export import USD_FORMAT, USD_FORMAT_VERSION, save_usd, scene_to_stage
from ignjax.scenes.io.usd.load import load_usd
from ignjax.scenes.io.usd.mesh import triangulate_faces
from ignjax.scenes.io.usd.stage import (
    ATTR_ID,
    ATTR_KIND,
    ISAAC_DATA_ATTR,
    ISAAC_TYPE_ATTR,
    LABELS_ATTR,
    LABELS_TAXONOMY,
    NS,
    UsdImportWarning,
    open_stage,
    prim_semantic_label,
    stage_meters_per_unit,
    stage_up_axis,
)

__all__ = [
    "ATTR_ID", "ATTR_KIND", "ISAAC_DATA_ATTR", "ISAAC_TYPE_ATTR", "LABELS_ATTR", "LABELS_TAXONOMY", "NS",
    "USD_FORMAT", "USD_FORMAT_VERSION", "USD_SUFFIXES", "UsdImportWarning", "load_usd", "open_stage",
    "prim_semantic_label", "save_usd", "scene_to_stage", "stage_meters_per_unit", "stage_up_axis", "triangulate_faces",
]
