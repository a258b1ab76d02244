"""The host-side scene model: what every scene source is turned into.

* :mod:`~ignjax.scenes.model.elements`: the frozen dataclasses (:class:`Scene`, its rooms,
  doors, walls and instances), with the frame and units they share;
* :mod:`~ignjax.scenes.model.polygons`: floor-plane polygon geometry;
* :mod:`~ignjax.scenes.model.validation`: a scene's internal consistency;
* :mod:`~ignjax.scenes.model.scenejson`: the lossless JSON form and the ``inspect`` summary.

Every public name of those modules is importable from here.
"""

from ignjax.scenes.model.elements import (
    GEOM_KINDS,
    Attributes,
    Door,
    Geom,
    Instance,
    MeshData,
    OrientedBox,
    Quat,
    Room,
    Scene,
    SceneMeta,
    Vec3,
    Wall,
    room_containing,
)
from ignjax.scenes.model.polygons import (
    Vec2,
    points_in_polygon,
    polygon_area,
    polygon_centroid,
    polygon_edge_distance,
    polygon_problem,
)
from ignjax.scenes.model.scenejson import SCENE_JSON_VERSION, scene_from_dict, scene_summary, scene_to_dict, scene_to_json
from ignjax.scenes.model.validation import validate_scene

__all__ = [
    "Vec2",
    "Vec3",
    "Quat",
    "GEOM_KINDS",
    "MeshData",
    "Geom",
    "Attributes",
    "OrientedBox",
    "Instance",
    "Room",
    "Door",
    "Wall",
    "SceneMeta",
    "Scene",
    "room_containing",
    "points_in_polygon",
    "polygon_area",
    "polygon_centroid",
    "polygon_edge_distance",
    "polygon_problem",
    "validate_scene",
    "SCENE_JSON_VERSION",
    "scene_to_dict",
    "scene_from_dict",
    "scene_to_json",
    "scene_summary",
]
