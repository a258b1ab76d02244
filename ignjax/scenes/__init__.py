"""Scenes: the scene model, its sources and its compiled forms.

* :mod:`~ignjax.scenes.model`: the typed host-side scene model.
* :mod:`~ignjax.scenes.vocab`: room labels, categories, attributes.
* :mod:`~ignjax.scenes.graph`: the derived room-object graph.
* :mod:`~ignjax.scenes.io.sources`: read any supported source (:func:`load_scenes`).
* :mod:`~ignjax.scenes.procgen.generate` / :mod:`~ignjax.scenes.procgen.catalogue`: procedural houses.
* :mod:`~ignjax.scenes.io.usd`, :mod:`~ignjax.scenes.io.procthor`, :mod:`~ignjax.scenes.io.meshes`: importers (and USD export).
* :mod:`~ignjax.scenes.compile`, :mod:`~ignjax.scenes.navgrid`, :mod:`~ignjax.scenes.bank`: MuJoCo/MJX models, navigation grids, the SceneBank.
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
