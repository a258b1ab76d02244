"""Scenes: the scene model, its sources and its compiled forms.

* :mod:`~ignjax.scenes.model`: the typed host-side scene model.
* :mod:`~ignjax.scenes.vocab`: room labels, categories, attributes.
* :mod:`~ignjax.scenes.graph`: the derived room-object graph.
* :mod:`ignjax.scenes.io`: read any supported source (:func:`~ignjax.scenes.io.sources.load_scenes`,
  a registry of readers by suffix): USD (import and export), ProcTHOR, glTF/GLB/OBJ, manifests.
* :mod:`ignjax.scenes.procgen`: procedural houses (params, layout, furnish with roomspace,
  placement, companions and distractors, generate) and the object catalogue.
* :mod:`~ignjax.scenes.compile`: MuJoCo/MJX models; :mod:`~ignjax.scenes.voxels`,
  :mod:`~ignjax.scenes.navgrid`, :mod:`~ignjax.scenes.geodesic`, :mod:`~ignjax.scenes.raygrid`:
  voxels, navigation grids, geodesic fields, the ray caster's arrays;
  :mod:`~ignjax.scenes.bank`: the SceneBank (many scenes as one device pytree).
* :mod:`ignjax.scenes.viz`: top-down maps, first-person views, the catalogue gallery.

The lowest layer above :mod:`ignjax.protocol`, :mod:`ignjax.arrays`,
:mod:`ignjax.errors` and :mod:`ignjax.fileio`: it imports nothing else of ignjax.
"""

from ignjax.scenes.model import (  # noqa: F401
    Attributes,
    Door,
    Geom,
    Instance,
    MeshData,
    OrientedBox,
    Room,
    Scene,
    SceneMeta,
    Wall,
    validate_scene,
)
