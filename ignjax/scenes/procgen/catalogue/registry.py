"""The catalogue registry: :class:`CategorySpec` (where a category goes, which
attributes it takes, its builder), :data:`PLACEMENTS` and :data:`CATALOGUE`,
the immutable mapping name -> spec of every category procedural houses can
place. Add a category by writing its builder in the family module it belongs
to and listing it in ``_SPECS``.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Mapping

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue.parts import Builder
from ignjax.scenes.procgen.catalogue.seating import (
    build_chair, build_sofa, build_armchair, build_office_chair, build_stool, build_bench, build_ottoman,
    build_dog_bed,
)
from ignjax.scenes.procgen.catalogue.tables import (
    build_dining_table, build_coffee_table, build_side_table, build_desk, build_kitchen_island, build_workbench,
)
from ignjax.scenes.procgen.catalogue.storage import (
    build_nightstand, build_dresser, build_wardrobe, build_cabinet, build_bookshelf, build_shelf, build_tv_stand,
    build_crib, build_bed, build_storage_box, build_shoe_rack,
)
from ignjax.scenes.procgen.catalogue.appliances import (
    build_refrigerator, build_stove, build_oven, build_dishwasher, build_washing_machine, build_dryer,
    build_microwave, build_toaster, build_kettle, build_coffee_machine,
)
from ignjax.scenes.procgen.catalogue.electronics import (
    build_television, build_monitor, build_computer, build_printer, build_speaker, build_fan, build_vacuum_cleaner,
)
from ignjax.scenes.procgen.catalogue.fixtures import (
    build_toilet, build_sink, build_bathtub, build_shower, build_radiator, build_fireplace, build_piano, build_safe,
)
from ignjax.scenes.procgen.catalogue.wall import (
    build_painting, build_mirror, build_wall_clock, build_curtain, build_towel_rack,
)
from ignjax.scenes.procgen.catalogue.floor import (
    build_coat_rack, build_potted_plant, build_houseplant_small, build_floor_lamp, build_rug, build_trash_can,
    build_laundry_basket, build_toolbox, build_bicycle, build_ladder, build_dumbbell, build_basketball,
)
from ignjax.scenes.procgen.catalogue.small import (
    build_laptop, build_book, build_vase, build_bowl, build_fruit_bowl, build_cup, build_mug, build_plate,
    build_bottle, build_wine_bottle, build_table_lamp, build_candle, build_alarm_clock, build_keyboard, build_pot,
    build_pan, build_cutting_board, build_pillow, build_teddy_bear, build_basket, build_picture_frame,
    build_soap_dispenser, build_towel, build_tissue_box, build_globe, build_sculpture, build_remote_control,
    build_spray_bottle, build_dish_rack, build_watering_can, build_tennis_racket, build_baseball_bat,
    build_headphones,
)


PLACEMENTS = ("floor", "floor_wall", "wall", "on_support")
"""``floor``: free-standing in the room; ``floor_wall``: on the floor with
its back against a wall; ``wall``: hung on a wall at ``mount_height``;
``on_support``: standing on a support surface of another instance."""


@dataclass(frozen=True)
class CategorySpec:
    """How one category appears in procedural houses.

    Attributes:
        name: canonical category (must be in :data:`vocab.TARGET_WHITELIST`).
        placement: one of :data:`PLACEMENTS`.
        rooms: room label -> relative weight of appearing in that room.
        colors: colours it can take (names from :data:`vocab.COLORS`).
        materials: materials it can take.
        states: states it can take; empty when the category has none.
        sizes: size classes it can take.
        supports: for ``on_support``: categories it may stand on.
        mount_height: for ``wall``: height of its lowest point, metres.
        build: the builder.
    """

    name: str
    placement: str
    rooms: Mapping[str, float]
    colors: tuple[str, ...]
    materials: tuple[str, ...]
    build: Builder
    states: tuple[str, ...] = ()
    sizes: tuple[str, ...] = vocab.SIZES
    supports: tuple[str, ...] = ()
    mount_height: float = 0.0

    def sample_attributes(self, rng: np.random.Generator) -> Attributes:
        """Draw colour, material, size and state uniformly from the allowed sets."""
        return Attributes(
            color=str(rng.choice(self.colors)) if self.colors else None,
            material=str(rng.choice(self.materials)) if self.materials else None,
            size=str(rng.choice(self.sizes)) if self.sizes else None,
            state=str(rng.choice(self.states)) if self.states else None,
        )


_ALL_COLORS = tuple(vocab.COLORS)
_NEUTRAL = ("white", "black", "gray", "brown", "beige")
_APPLIANCE = ("white", "gray", "black")
_COUNTERS = ("cabinet", "kitchen_island")
_ON_OFF = ("on", "off")
_OPEN_CLOSED = ("open", "closed")
_FULL_EMPTY = ("full", "empty")


def _spec(name: str, placement: str, rooms: Mapping[str, float], colors, materials, build: Builder, **kw) -> CategorySpec:
    return CategorySpec(name, placement, MappingProxyType(dict(rooms)), tuple(colors), tuple(materials), build, **kw)


_SPECS: tuple[CategorySpec, ...] = (
    # -- large furniture ---------------------------------------------------
    _spec("bed", "floor_wall", {"bedroom": 5}, _ALL_COLORS, ("wood", "metal", "fabric"), build_bed, states=("made", "unmade")),
    _spec("sofa", "floor_wall", {"living_room": 5, "office": 0.5, "bedroom": 0.3}, _ALL_COLORS, ("fabric", "leather"), build_sofa),
    _spec("armchair", "floor", {"living_room": 4, "bedroom": 1.5, "office": 1}, _ALL_COLORS, ("fabric", "leather"), build_armchair),
    _spec("chair", "floor", {"dining_room": 3, "kitchen": 1, "office": 1, "bedroom": 0.5, "living_room": 0.5},
          _ALL_COLORS, ("wood", "metal", "plastic"), build_chair),
    _spec("office_chair", "floor", {"office": 5, "bedroom": 0.7}, ("black", "gray", "blue", "red", "white", "green"),
          ("fabric", "leather", "plastic"), build_office_chair),
    _spec("stool", "floor", {"kitchen": 4, "garage": 1, "bathroom": 0.5, "dining_room": 0.5, "laundry_room": 0.5},
          ("brown", "black", "white", "gray", "red", "blue"), ("wood", "metal", "plastic"), build_stool),
    _spec("bench", "floor_wall", {"entryway": 4, "hallway": 2, "bedroom": 1, "garage": 0.5, "dining_room": 0.5, "closet": 0.5},
          ("brown", "white", "black", "gray", "beige"), ("wood", "metal"), build_bench),
    _spec("ottoman", "floor", {"living_room": 3, "bedroom": 1.5, "closet": 0.5}, _ALL_COLORS, ("fabric", "leather"), build_ottoman),
    _spec("dining_table", "floor", {"dining_room": 3, "kitchen": 1},
          ("brown", "white", "black", "gray"), ("wood", "stone", "glass"), build_dining_table),
    _spec("coffee_table", "floor", {"living_room": 5, "office": 0.3}, ("brown", "white", "black", "gray"),
          ("wood", "glass", "stone", "metal"), build_coffee_table),
    _spec("side_table", "floor", {"living_room": 3, "bedroom": 1, "office": 1, "hallway": 1.5, "entryway": 1.5},
          ("brown", "white", "black", "gray", "green", "blue"), ("wood", "metal", "glass", "stone"), build_side_table),
    _spec("desk", "floor_wall", {"office": 5, "bedroom": 2, "living_room": 0.5}, ("brown", "white", "black", "gray"),
          ("wood", "metal", "glass"), build_desk),
    _spec("nightstand", "floor_wall", {"bedroom": 5}, ("brown", "white", "black", "gray", "beige", "blue"), ("wood", "metal"),
          build_nightstand),
    _spec("dresser", "floor_wall", {"bedroom": 4, "closet": 1.5, "hallway": 0.5},
          ("brown", "white", "black", "gray", "beige", "blue", "green"), ("wood", "metal"), build_dresser, states=_OPEN_CLOSED),
    _spec("wardrobe", "floor_wall", {"bedroom": 3, "closet": 4, "hallway": 1, "entryway": 0.5},
          ("brown", "white", "black", "gray", "beige"), ("wood", "metal"), build_wardrobe, states=_OPEN_CLOSED),
    _spec("cabinet", "floor_wall", {"kitchen": 5, "laundry_room": 2, "garage": 1.5, "bathroom": 1, "office": 1, "living_room": 0.5,
                                    "dining_room": 0.5},
          ("white", "brown", "gray", "black", "beige", "blue", "green"), ("wood", "stone", "metal"), build_cabinet, states=_OPEN_CLOSED),
    _spec("bookshelf", "floor_wall", {"office": 4, "living_room": 3, "bedroom": 1, "hallway": 0.5},
          ("brown", "white", "black", "gray"), ("wood", "metal"), build_bookshelf, states=_FULL_EMPTY),
    _spec("shelf", "floor_wall", {"garage": 3, "laundry_room": 3, "closet": 2.5, "kitchen": 1, "office": 1, "bathroom": 1,
                                  "living_room": 0.5},
          ("gray", "white", "black", "brown"), ("metal", "wood", "plastic"), build_shelf),
    _spec("tv_stand", "floor_wall", {"living_room": 5, "bedroom": 1}, ("brown", "black", "white", "gray"), ("wood", "glass", "metal"),
          build_tv_stand),
    _spec("kitchen_island", "floor", {"kitchen": 5}, ("white", "gray", "brown", "black", "blue", "green"), ("stone", "wood"),
          build_kitchen_island),
    _spec("crib", "floor_wall", {"bedroom": 1.5}, ("white", "brown", "gray", "pink", "blue"), ("wood",), build_crib),
    _spec("dog_bed", "floor", {"living_room": 2, "bedroom": 1, "hallway": 0.5, "kitchen": 0.3, "entryway": 0.5},
          ("brown", "gray", "beige", "blue", "red", "green"), ("fabric",), build_dog_bed),
    # -- appliances and fixtures --------------------------------------------
    _spec("refrigerator", "floor_wall", {"kitchen": 5, "garage": 0.5}, ("white", "gray", "black", "beige", "red"), ("metal", "plastic"),
          build_refrigerator),
    _spec("stove", "floor_wall", {"kitchen": 5}, _APPLIANCE, ("metal",), build_stove, states=_ON_OFF),
    _spec("oven", "floor_wall", {"kitchen": 3}, _APPLIANCE, ("metal", "glass"), build_oven, states=_ON_OFF),
    _spec("dishwasher", "floor_wall", {"kitchen": 3}, _APPLIANCE, ("metal", "plastic"), build_dishwasher),
    _spec("washing_machine", "floor_wall", {"laundry_room": 5, "bathroom": 1, "kitchen": 0.5, "garage": 0.5}, _APPLIANCE,
          ("metal", "plastic"), build_washing_machine, states=_OPEN_CLOSED),
    _spec("dryer", "floor_wall", {"laundry_room": 5, "garage": 0.3, "closet": 0.3}, _APPLIANCE, ("metal", "plastic"), build_dryer,
          states=_OPEN_CLOSED),
    _spec("toilet", "floor_wall", {"bathroom": 6}, ("white", "beige", "black", "gray"), ("ceramic",), build_toilet, states=_OPEN_CLOSED),
    _spec("sink", "floor_wall", {"bathroom": 5, "laundry_room": 2, "kitchen": 1},
          ("white", "gray", "brown", "black", "beige", "blue", "green"), ("ceramic", "stone", "metal"), build_sink),
    _spec("bathtub", "floor_wall", {"bathroom": 4}, ("white", "beige", "gray", "black", "blue"), ("ceramic", "stone", "metal"),
          build_bathtub),
    _spec("shower", "floor_wall", {"bathroom": 3}, ("white", "gray", "beige", "blue", "black", "green"), ("ceramic", "stone", "glass"),
          build_shower),
    _spec("microwave", "on_support", {"kitchen": 5, "office": 0.3}, ("black", "white", "gray", "red"), ("metal", "plastic"),
          build_microwave, states=_ON_OFF, supports=_COUNTERS),
    _spec("toaster", "on_support", {"kitchen": 4}, ("gray", "white", "black", "red", "blue", "yellow", "green"), ("metal", "plastic"),
          build_toaster, supports=_COUNTERS + ("dining_table",)),
    _spec("kettle", "on_support", {"kitchen": 4, "office": 0.3}, ("white", "black", "gray", "red", "blue", "green", "yellow"),
          ("metal", "plastic", "glass"), build_kettle, supports=_COUNTERS + ("stove", "dining_table")),
    _spec("coffee_machine", "on_support", {"kitchen": 4, "office": 1}, ("black", "gray", "red", "white"), ("metal", "plastic"),
          build_coffee_machine, supports=_COUNTERS + ("shelf", "desk")),
    _spec("television", "on_support", {"living_room": 5, "bedroom": 2, "kitchen": 0.3, "office": 0.3}, ("black", "gray", "white"),
          ("plastic", "metal"), build_television, states=_ON_OFF, supports=("tv_stand", "dresser", "desk")),
    _spec("monitor", "on_support", {"office": 5, "bedroom": 1, "living_room": 0.3}, ("black", "gray", "white"), ("plastic", "metal"),
          build_monitor, states=_ON_OFF, supports=("desk",)),
    _spec("computer", "on_support", {"office": 4, "bedroom": 1}, ("black", "white", "gray"), ("metal", "plastic"), build_computer,
          supports=("desk", "shelf")),
    _spec("printer", "on_support", {"office": 4, "living_room": 0.3}, ("white", "black", "gray"), ("plastic",), build_printer,
          supports=("desk", "cabinet")),
    _spec("speaker", "floor_wall", {"living_room": 4, "office": 1, "bedroom": 0.5}, ("black", "white", "brown", "gray"),
          ("wood", "plastic"), build_speaker),
    _spec("fan", "floor", {"bedroom": 3, "living_room": 2, "office": 2, "garage": 0.5}, ("white", "black", "gray", "blue"),
          ("plastic", "metal"), build_fan),
    _spec("radiator", "floor_wall", {"bathroom": 2, "hallway": 2, "living_room": 1, "bedroom": 1, "office": 1, "entryway": 1,
                                     "kitchen": 0.5, "dining_room": 0.5},
          ("white", "gray", "black"), ("metal",), build_radiator),
    _spec("fireplace", "floor_wall", {"living_room": 3, "dining_room": 0.5, "bedroom": 0.3},
          ("white", "gray", "black", "beige", "red", "brown"), ("stone", "wood", "metal"), build_fireplace, states=_ON_OFF),
    _spec("piano", "floor_wall", {"living_room": 2, "office": 0.5}, ("black", "brown", "white"), ("wood",), build_piano),
    _spec("vacuum_cleaner", "floor", {"closet": 3, "hallway": 1, "laundry_room": 1, "living_room": 0.5, "garage": 0.5},
          ("red", "purple", "gray", "yellow", "black", "blue"), ("plastic", "metal"), build_vacuum_cleaner),
    _spec("safe", "floor_wall", {"closet": 2, "office": 2, "bedroom": 1, "garage": 0.5}, ("black", "gray", "green", "beige"), ("metal",),
          build_safe),
    # -- wall-mounted -------------------------------------------------------
    _spec("mirror", "wall", {"bathroom": 4, "entryway": 4, "bedroom": 2, "hallway": 2, "closet": 1.5},
          ("brown", "black", "white", "gray", "yellow"), ("wood", "metal", "plastic"), build_mirror, mount_height=1.05),
    _spec("painting", "wall", {"living_room": 3, "bedroom": 2, "hallway": 2, "dining_room": 2, "office": 1.5, "entryway": 1},
          _ALL_COLORS, ("wood", "metal"), build_painting, mount_height=1.2),
    _spec("wall_clock", "wall", {"kitchen": 3, "living_room": 2, "office": 2, "dining_room": 2, "hallway": 1, "bedroom": 0.5,
                                 "garage": 0.5},
          ("black", "white", "brown", "gray", "red", "blue"), ("wood", "metal", "plastic"), build_wall_clock, mount_height=1.75),
    _spec("curtain", "wall", {"bedroom": 4, "living_room": 3, "dining_room": 1, "office": 1, "bathroom": 0.3}, _ALL_COLORS,
          ("fabric",), build_curtain, states=_OPEN_CLOSED, mount_height=0.08),
    _spec("towel_rack", "wall", {"bathroom": 5, "kitchen": 1, "laundry_room": 0.5}, ("gray", "black", "white", "yellow"),
          ("metal", "wood"), build_towel_rack, mount_height=0.65),
    _spec("coat_rack", "floor", {"entryway": 5, "hallway": 2, "bedroom": 0.5, "closet": 0.5}, ("brown", "black", "white", "gray"),
          ("wood", "metal"), build_coat_rack),
    # -- floor objects ------------------------------------------------------
    _spec("shoe_rack", "floor_wall", {"entryway": 5, "closet": 3, "hallway": 2, "bedroom": 0.5}, ("brown", "black", "white", "gray"),
          ("wood", "metal", "plastic"), build_shoe_rack),
    _spec("potted_plant", "floor", {"living_room": 4, "office": 2, "hallway": 2, "entryway": 2, "bedroom": 1, "dining_room": 1,
                                    "bathroom": 0.5, "kitchen": 0.5},
          ("green",), ("ceramic", "plastic", "stone", "wicker"), build_potted_plant),
    _spec("floor_lamp", "floor", {"living_room": 4, "bedroom": 2, "office": 2, "hallway": 0.5},
          ("white", "beige", "black", "gray", "red", "blue", "green", "yellow", "orange"), ("metal", "wood"), build_floor_lamp,
          states=_ON_OFF),
    _spec("rug", "floor", {"living_room": 4, "bedroom": 3, "dining_room": 2, "hallway": 2, "entryway": 2, "office": 1, "bathroom": 1},
          _ALL_COLORS, ("fabric", "wicker"), build_rug),
    _spec("trash_can", "floor", {"kitchen": 4, "bathroom": 3, "office": 3, "garage": 3, "bedroom": 1, "laundry_room": 1,
                                 "living_room": 0.5},
          ("gray", "black", "white", "blue", "green", "red"), ("metal", "plastic"), build_trash_can),
    _spec("laundry_basket", "floor", {"laundry_room": 5, "closet": 3, "bedroom": 2, "bathroom": 2},
          ("beige", "white", "gray", "brown", "blue", "pink"), ("wicker", "plastic", "fabric"), build_laundry_basket, states=_FULL_EMPTY),
    _spec("workbench", "floor_wall", {"garage": 6, "laundry_room": 0.3}, ("gray", "red", "blue", "black", "green"), ("metal", "wood"),
          build_workbench),
    _spec("toolbox", "on_support", {"garage": 5, "laundry_room": 0.5, "closet": 0.5},
          ("red", "blue", "black", "gray", "yellow", "orange", "green"), ("metal", "plastic"), build_toolbox,
          supports=("workbench", "shelf", "cabinet")),
    _spec("bicycle", "floor", {"garage": 5, "entryway": 1, "hallway": 0.5}, _ALL_COLORS, ("metal",), build_bicycle),
    _spec("ladder", "floor", {"garage": 4, "laundry_room": 1, "closet": 1}, ("gray", "yellow", "orange", "red", "blue"),
          ("metal", "wood"), build_ladder),
    _spec("storage_box", "floor", {"closet": 4, "garage": 4, "bedroom": 1, "laundry_room": 1, "office": 0.5},
          ("blue", "white", "gray", "black", "green", "red", "beige", "pink", "brown"), ("plastic", "wood", "wicker", "fabric"),
          build_storage_box),
    _spec("dumbbell", "floor", {"garage": 3, "bedroom": 2, "living_room": 1, "office": 0.5},
          ("black", "gray", "red", "blue", "green", "pink", "purple", "yellow"), ("metal", "plastic"), build_dumbbell),
    _spec("basketball", "floor", {"garage": 3, "bedroom": 2, "hallway": 1, "closet": 1, "entryway": 1}, ("orange", "brown", "red", "blue"),
          ("leather", "plastic"), build_basketball),
    # -- small objects on supports ------------------------------------------
    _spec("laptop", "on_support", {"office": 3, "living_room": 1, "bedroom": 1, "dining_room": 0.5},
          ("gray", "black", "white", "blue", "pink"), ("metal", "plastic"), build_laptop,
          states=_OPEN_CLOSED, supports=("desk", "dining_table", "coffee_table", "bed", "side_table")),
    _spec("book", "on_support", {"office": 3, "living_room": 3, "bedroom": 3, "dining_room": 0.3, "hallway": 0.3}, _ALL_COLORS,
          ("fabric", "leather"), build_book,
          supports=("bookshelf", "shelf", "nightstand", "desk", "coffee_table", "side_table", "dining_table", "bed", "dresser")),
    _spec("vase", "on_support", {"living_room": 3, "dining_room": 3, "entryway": 2, "hallway": 1, "bedroom": 1, "kitchen": 0.5},
          _ALL_COLORS, ("ceramic", "glass", "metal", "stone"), build_vase, states=_FULL_EMPTY,
          supports=("dining_table", "coffee_table", "side_table", "tv_stand", "dresser", "fireplace", "shelf", "bookshelf", "piano",
                    "kitchen_island", "nightstand")),
    _spec("bowl", "on_support", {"kitchen": 4, "dining_room": 3, "living_room": 0.5},
          ("white", "beige", "blue", "green", "red", "black", "gray", "brown", "yellow"), ("ceramic", "glass", "wood", "plastic", "metal"),
          build_bowl, states=_FULL_EMPTY, supports=("dining_table", "kitchen_island", "cabinet", "coffee_table", "shelf")),
    _spec("cup", "on_support", {"kitchen": 3, "dining_room": 3, "office": 1, "living_room": 1, "bedroom": 0.5, "bathroom": 0.5},
          _ALL_COLORS, ("ceramic", "glass", "plastic"), build_cup,
          supports=("dining_table", "kitchen_island", "cabinet", "coffee_table", "desk", "side_table", "nightstand", "sink")),
    _spec("mug", "on_support", {"kitchen": 3, "office": 3, "dining_room": 1, "living_room": 1, "bedroom": 0.3}, _ALL_COLORS,
          ("ceramic",), build_mug,
          supports=("dining_table", "kitchen_island", "cabinet", "coffee_table", "desk", "side_table", "nightstand", "shelf")),
    _spec("plate", "on_support", {"dining_room": 4, "kitchen": 4, "living_room": 0.3},
          ("white", "beige", "blue", "green", "black", "gray", "red", "yellow"), ("ceramic", "glass", "plastic"), build_plate,
          supports=("dining_table", "kitchen_island", "cabinet", "coffee_table")),
    _spec("bottle", "on_support", {"kitchen": 3, "dining_room": 1, "office": 0.5, "garage": 0.5, "bathroom": 0.5, "bedroom": 0.5},
          ("blue", "green", "white", "gray", "red", "pink", "black", "orange"), ("plastic", "glass", "metal"), build_bottle,
          supports=("dining_table", "kitchen_island", "cabinet", "desk", "nightstand", "shelf", "workbench")),
    _spec("wine_bottle", "on_support", {"kitchen": 3, "dining_room": 4, "living_room": 0.5}, ("green", "black", "brown", "red", "white"),
          ("glass",), build_wine_bottle, supports=("dining_table", "kitchen_island", "cabinet", "shelf", "coffee_table")),
    _spec("table_lamp", "on_support", {"bedroom": 4, "living_room": 3, "office": 3, "hallway": 0.5, "entryway": 0.5},
          ("white", "beige", "black", "gray", "blue", "green", "red", "yellow"), ("ceramic", "metal", "glass"), build_table_lamp,
          states=_ON_OFF, supports=("nightstand", "side_table", "desk", "dresser")),
    _spec("candle", "on_support", {"dining_room": 3, "living_room": 2, "bathroom": 1, "bedroom": 1},
          ("white", "beige", "red", "yellow", "purple", "pink", "blue", "green", "orange"), ("metal", "glass", "ceramic"), build_candle,
          states=_ON_OFF, supports=("dining_table", "coffee_table", "side_table", "fireplace", "nightstand", "dresser", "sink", "shelf")),
    _spec("alarm_clock", "on_support", {"bedroom": 5, "office": 0.3}, ("red", "black", "white", "blue", "green", "yellow", "pink"),
          ("metal", "plastic"), build_alarm_clock, supports=("nightstand", "dresser", "desk")),
    _spec("keyboard", "on_support", {"office": 5, "bedroom": 0.5}, ("black", "white", "gray"), ("plastic",), build_keyboard,
          supports=("desk",)),
    _spec("pot", "on_support", {"kitchen": 5}, ("gray", "black", "red", "blue", "orange", "white"), ("metal", "ceramic", "stone"),
          build_pot, supports=("stove",) + _COUNTERS),
    _spec("pan", "on_support", {"kitchen": 5}, ("black", "gray", "red", "blue", "orange"), ("metal", "ceramic"), build_pan,
          supports=("stove",) + _COUNTERS),
    _spec("cutting_board", "on_support", {"kitchen": 5}, ("brown", "white", "beige", "green", "black", "blue", "red"),
          ("wood", "plastic", "stone"), build_cutting_board, supports=_COUNTERS + ("dining_table",)),
    _spec("pillow", "on_support", {"bedroom": 4, "living_room": 4, "office": 0.3}, _ALL_COLORS, ("fabric", "leather"), build_pillow,
          supports=("bed", "sofa", "armchair", "ottoman")),
    _spec("teddy_bear", "on_support", {"bedroom": 5, "living_room": 0.5}, ("brown", "beige", "white", "pink", "blue", "gray", "yellow"),
          ("fabric",), build_teddy_bear,
          supports=("bed", "crib", "sofa", "armchair", "shelf", "bookshelf", "dresser", "nightstand")),
    _spec("basket", "on_support", {"kitchen": 2, "living_room": 1.5, "dining_room": 1, "bathroom": 1, "laundry_room": 1, "entryway": 1},
          ("beige", "brown", "white", "black", "gray"), ("wicker", "fabric", "plastic", "metal"), build_basket,
          supports=("dining_table", "kitchen_island", "shelf", "bench", "coffee_table", "cabinet", "washing_machine", "dryer")),
    _spec("picture_frame", "on_support", {"living_room": 3, "bedroom": 3, "office": 2, "hallway": 0.5, "entryway": 0.5},
          ("black", "white", "brown", "gray", "yellow", "red", "blue"), ("wood", "metal", "plastic", "glass"), build_picture_frame,
          supports=("nightstand", "desk", "dresser", "side_table", "shelf", "bookshelf", "fireplace", "piano", "tv_stand")),
    _spec("soap_dispenser", "on_support", {"bathroom": 5, "kitchen": 2, "laundry_room": 0.5},
          ("white", "gray", "black", "green", "blue", "pink", "yellow", "beige"), ("ceramic", "glass", "plastic", "metal"),
          build_soap_dispenser, supports=("sink",) + _COUNTERS),
    _spec("towel", "on_support", {"bathroom": 5, "laundry_room": 2, "closet": 1, "kitchen": 0.5, "bedroom": 0.5}, _ALL_COLORS,
          ("fabric",), build_towel, supports=("shelf", "cabinet", "bench", "bed", "washing_machine", "dryer")),
    _spec("tissue_box", "on_support", {"bathroom": 2, "bedroom": 2, "living_room": 2, "office": 1}, _ALL_COLORS,
          ("plastic", "wood", "ceramic"), build_tissue_box,
          supports=("nightstand", "side_table", "coffee_table", "desk", "cabinet", "sink", "dresser")),
    _spec("globe", "on_support", {"office": 4, "bedroom": 1, "living_room": 1}, ("blue", "beige", "black", "green"),
          ("wood", "metal", "plastic"), build_globe, supports=("desk", "shelf", "side_table", "dresser")),
    _spec("sculpture", "on_support", {"living_room": 3, "entryway": 2, "hallway": 1, "office": 1, "dining_room": 0.5},
          ("white", "black", "gray", "beige", "brown", "yellow", "blue", "green", "red"), ("stone", "metal", "ceramic", "wood", "glass"),
          build_sculpture,
          supports=("coffee_table", "side_table", "shelf", "bookshelf", "fireplace", "tv_stand", "dresser", "piano")),
    _spec("remote_control", "on_support", {"living_room": 5, "bedroom": 1}, ("black", "gray", "white"), ("plastic",),
          build_remote_control, supports=("coffee_table", "sofa", "side_table", "tv_stand", "armchair", "nightstand", "bed")),
    _spec("spray_bottle", "on_support", {"laundry_room": 4, "kitchen": 2, "bathroom": 2, "garage": 1},
          ("blue", "green", "white", "yellow", "pink", "orange", "purple", "red"), ("plastic",), build_spray_bottle,
          supports=("shelf", "washing_machine", "dryer", "cabinet", "sink", "workbench")),
    _spec("dish_rack", "on_support", {"kitchen": 5}, ("gray", "white", "black", "green", "blue", "red"), ("metal", "plastic", "wood"),
          build_dish_rack, supports=_COUNTERS),
    _spec("fruit_bowl", "on_support", {"kitchen": 4, "dining_room": 4, "living_room": 0.5},
          ("white", "brown", "beige", "black", "gray", "blue", "green"), ("ceramic", "wood", "glass", "metal", "wicker"),
          build_fruit_bowl, states=_FULL_EMPTY, supports=("dining_table", "kitchen_island", "cabinet", "coffee_table")),
    _spec("watering_can", "on_support", {"garage": 2, "laundry_room": 2, "living_room": 1, "kitchen": 1},
          ("green", "red", "blue", "yellow", "gray", "orange", "white"), ("plastic", "metal"), build_watering_can,
          supports=("shelf", "cabinet", "workbench", "bench")),
    _spec("tennis_racket", "on_support", {"garage": 2, "bedroom": 2, "closet": 2, "entryway": 1, "hallway": 0.5}, _ALL_COLORS,
          ("metal", "plastic", "wood"), build_tennis_racket,
          supports=("shelf", "bench", "bed", "workbench", "storage_box", "dresser")),
    _spec("baseball_bat", "on_support", {"garage": 3, "bedroom": 1, "closet": 2, "entryway": 1},
          ("brown", "black", "beige", "gray", "red", "blue"), ("wood", "metal"), build_baseball_bat,
          supports=("bench", "bed", "workbench")),
    _spec("headphones", "on_support", {"office": 3, "bedroom": 3, "living_room": 1}, ("black", "white", "gray", "red", "blue", "pink"),
          ("plastic", "metal", "leather"), build_headphones,
          supports=("desk", "nightstand", "bed", "sofa", "side_table", "coffee_table", "shelf")),
    _spec("houseplant_small", "on_support", {"living_room": 2, "kitchen": 2, "bathroom": 2, "office": 2, "bedroom": 2, "dining_room": 1,
                                             "entryway": 1},
          ("red", "pink", "yellow", "purple", "white", "orange", "blue"), ("ceramic", "plastic", "stone", "wicker"),
          build_houseplant_small,
          supports=("desk", "side_table", "shelf", "bookshelf", "nightstand", "dining_table", "kitchen_island", "cabinet", "sink",
                    "dresser", "coffee_table", "tv_stand")),
)

CATALOGUE: Mapping[str, CategorySpec] = MappingProxyType({s.name: s for s in _SPECS})
"""Category name -> spec, for every category procedural houses can place."""
