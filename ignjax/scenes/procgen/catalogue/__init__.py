"""The object catalogue of procedural houses.

Each category is a :class:`CategorySpec`: where it goes (rooms, floor / wall
/ on a support), which attribute values it can take, and a ``build`` function
that turns sampled :class:`~ignjax.scenes.model.Attributes` into geometry: a
recognisable composition of MuJoCo primitives (a chair is a seat, a back and
four legs; a laptop a base and a screen, open or closed).

Attributes are expressed in the geometry:

* colour -> the RGBA of the object's main parts (:data:`vocab.COLORS`);
* material -> :attr:`Geom.material` (rendered with that material's
  reflectance) and, for wood/metal/glass parts without a colour of their
  own, their tint;
* size class -> a scale (:data:`vocab.SIZE_SCALE`) of the default
  dimensions; tall furniture (wardrobes, refrigerators, bookshelves, lamps)
  scales its height by half as much so that it stays under the ceiling, and
  curtains only scale their width;
* state -> the shape (an open laptop has a raised screen, a closed one a
  flat lid; an open wardrobe shows its doors swung out and the clothes
  inside; a lamp, television or monitor that is on has a bright shade or
  screen; a full bookshelf holds rows of books; a made bed has a flat
  blanket, an unmade one the covers bunched at its foot).

Builder frame: origin at the centre of the object's footprint at its lowest
point, z up, +x is the object's *front* (where a chair faces, where a
painting looks, the side a wardrobe opens to). Objects that stand against a
wall are placed with their back (-x) to the wall. Wall-mounted objects are
built with z = 0 at their lowest point and hung at ``mount_height``.
Builders compose parts in whatever frame is natural and end with
:func:`~ignjax.scenes.procgen.catalogue.parts.finish`, which moves the parts
so that the tight axis-aligned box of all parts is centred at (0, 0, hz)
with its bottom at z = 0; so ``Built.half_extents`` always contains every
part, and the back of a ``floor_wall``/``wall`` object lies at x = -hx.

Support surfaces (:class:`Surface`) are free of parts: nothing of the object
rises above a surface inside its rectangle, up to ``clearance`` (the next
shelf board for shelves).

Modules:

* :mod:`~ignjax.scenes.procgen.catalogue.parts`: what a builder returns and
  the part / geometry helpers builders share.
* one module of builders per furniture family:
  :mod:`~ignjax.scenes.procgen.catalogue.seating`, ``tables``, ``storage``,
  ``appliances``, ``electronics``, ``fixtures``, ``wall``, ``floor`` and
  ``small`` (objects placed on supports).
* :mod:`~ignjax.scenes.procgen.catalogue.registry`: :class:`CategorySpec`,
  :data:`PLACEMENTS` and :data:`CATALOGUE`, an immutable mapping name ->
  spec; add a category by writing its builder in its family module and
  listing it in ``registry._SPECS``.
* :mod:`~ignjax.scenes.procgen.catalogue.placing`: built objects placed in a
  house (:func:`instantiate`, :func:`surfaces_world`).
"""

from ignjax.scenes.procgen.catalogue.parts import (
    Built,
    Builder,
    Surface,
    box,
    geom_aabb,
    glow,
    rgba,
    scale_of,
)
from ignjax.scenes.procgen.catalogue.placing import instantiate, surfaces_world
from ignjax.scenes.procgen.catalogue.registry import CATALOGUE, PLACEMENTS, CategorySpec

__all__ = [
    "CATALOGUE",
    "PLACEMENTS",
    "Built",
    "Builder",
    "CategorySpec",
    "Surface",
    "box",
    "geom_aabb",
    "glow",
    "instantiate",
    "rgba",
    "scale_of",
    "surfaces_world",
]
