"""Fixed vocabularies: room labels, object categories, attributes.

Everything that names a room or an object goes through the normalisers here,
so procedural houses, USD stages, ProcTHOR houses and mesh scenes all speak
the same labels.

Room labels
    The eleven goal-room labels of the benchmark (:data:`ROOM_LABELS`) plus
    ``"other"`` for rooms that do not map onto any of them (a storage room, a
    balcony, a room with no label). ``"other"`` rooms are never goal rooms.

Categories
    Canonical category names are lower-case ``snake_case`` nouns in the
    singular (``office_chair``, ``potted_plant``). :func:`normalize_category`
    maps prim names, asset ids and free text onto them. :data:`TARGET_WHITELIST`
    lists the categories that are discrete, visually identifiable and natural
    as "Find a ..." goals; :data:`STRUCTURAL_CATEGORIES` are never targets, and
    neither is ``"unknown"``.

Attributes
    Colour, material, size class and state, each from a closed set so that
    descriptions and the oracle's Type-1 facts can be compared exactly.
"""

from __future__ import annotations

import re
from types import MappingProxyType

# ---------------------------------------------------------------------------
# Rooms
# ---------------------------------------------------------------------------

ROOM_LABELS: tuple[str, ...] = (
    "bedroom",
    "bathroom",
    "kitchen",
    "living_room",
    "dining_room",
    "office",
    "hallway",
    "laundry_room",
    "entryway",
    "closet",
    "garage",
)
"""The eleven normalised goal-room labels."""

OTHER_ROOM = "other"
ALL_ROOM_LABELS: tuple[str, ...] = ROOM_LABELS + (OTHER_ROOM,)
ROOM_LABEL_INDEX = MappingProxyType({label: i for i, label in enumerate(ALL_ROOM_LABELS)})

_ROOM_ALIASES = MappingProxyType(
    {
        "bedroom": "bedroom",
        "bed_room": "bedroom",
        "master_bedroom": "bedroom",
        "guest_room": "bedroom",
        "guestroom": "bedroom",
        "kids_room": "bedroom",
        "nursery": "bedroom",
        "bathroom": "bathroom",
        "bath": "bathroom",
        "toilet": "bathroom",
        "restroom": "bathroom",
        "washroom": "bathroom",
        "powder_room": "bathroom",
        "wc": "bathroom",
        "kitchen": "kitchen",
        "kitchenette": "kitchen",
        "living_room": "living_room",
        "livingroom": "living_room",
        "lounge": "living_room",
        "family_room": "living_room",
        "sitting_room": "living_room",
        "den": "living_room",
        "dining_room": "dining_room",
        "diningroom": "dining_room",
        "dining": "dining_room",
        "office": "office",
        "study": "office",
        "study_room": "office",
        "home_office": "office",
        "library": "office",
        "workroom": "office",
        "hallway": "hallway",
        "hall": "hallway",
        "corridor": "hallway",
        "passage": "hallway",
        "laundry_room": "laundry_room",
        "laundry": "laundry_room",
        "laundryroom": "laundry_room",
        "utility_room": "laundry_room",
        "utility": "laundry_room",
        "entryway": "entryway",
        "entry": "entryway",
        "entrance": "entryway",
        "foyer": "entryway",
        "lobby": "entryway",
        "vestibule": "entryway",
        "mudroom": "entryway",
        "closet": "closet",
        "walk_in_closet": "closet",
        "wardrobe_room": "closet",
        "storage": "closet",
        "storage_room": "closet",
        "pantry": "closet",
        "garage": "garage",
        "carport": "garage",
        "workshop": "garage",
    }
)

ROOM_DISPLAY = MappingProxyType({label: label.replace("_", " ") for label in ALL_ROOM_LABELS})
"""How a room label reads in text: ``living_room`` -> ``living room``."""


def _snake(text: str) -> str:
    """CamelCase / spaced / hyphenated text -> lower snake_case."""
    text = text.strip()
    text = re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", text)
    text = re.sub(r"([A-Z]+)([A-Z][a-z])", r"\1_\2", text)
    text = re.sub(r"[^0-9A-Za-z]+", "_", text)
    return text.strip("_").lower()


def normalize_room_label(text: str | None) -> str:
    """Map a free-form room name onto :data:`ALL_ROOM_LABELS`.

    ``"LivingRoom"``, ``"living room"`` and ``"Lounge_2"`` all become
    ``"living_room"``; anything unrecognised becomes ``"other"``.
    """
    if not text:
        return OTHER_ROOM
    key = _snake(text)
    key = re.sub(r"(_?\d+)+$", "", key)
    if key in _ROOM_ALIASES:
        return _ROOM_ALIASES[key]
    for part in reversed(key.split("_")):
        if part in _ROOM_ALIASES:
            return _ROOM_ALIASES[part]
    return OTHER_ROOM


# ---------------------------------------------------------------------------
# Categories
# ---------------------------------------------------------------------------

UNKNOWN_CATEGORY = "unknown"

STRUCTURAL_CATEGORIES: frozenset[str] = frozenset(
    {
        "wall",
        "floor",
        "ceiling",
        "door",
        "doorway",
        "doorframe",
        "window",
        "ceiling_light",
        "light_switch",
        "stairs",
        "railing",
        "column",
        "beam",
        "baseboard",
        "room",
    }
)
"""Categories that belong to the building, not to its contents; never targets."""

TARGET_WHITELIST: tuple[str, ...] = (
    # large furniture
    "bed", "sofa", "armchair", "chair", "office_chair", "stool", "bench", "ottoman",
    "dining_table", "coffee_table", "side_table", "desk", "nightstand", "dresser",
    "wardrobe", "cabinet", "bookshelf", "shelf", "tv_stand", "kitchen_island", "crib",
    "dog_bed",
    # appliances and fixtures that are objects
    "refrigerator", "stove", "oven", "dishwasher", "washing_machine", "dryer",
    "toilet", "sink", "bathtub", "shower", "microwave", "toaster", "kettle",
    "coffee_machine", "television", "monitor", "computer", "printer", "speaker",
    "fan", "radiator", "fireplace", "piano", "vacuum_cleaner", "safe",
    # wall-mounted
    "mirror", "painting", "wall_clock", "curtain", "towel_rack", "coat_rack",
    # floor objects
    "shoe_rack", "potted_plant", "floor_lamp", "rug", "trash_can", "laundry_basket",
    "workbench", "toolbox", "bicycle", "ladder", "storage_box",
    # small objects on supports
    "laptop", "book", "vase", "bowl", "cup", "mug", "plate", "bottle", "wine_bottle",
    "table_lamp", "candle", "alarm_clock", "keyboard", "pot", "pan", "cutting_board",
    "pillow", "teddy_bear", "basket", "picture_frame", "soap_dispenser", "towel",
    "tissue_box", "globe", "sculpture", "remote_control", "spray_bottle", "dish_rack",
    "fruit_bowl", "watering_can", "dumbbell", "basketball", "tennis_racket",
    "baseball_bat", "headphones", "houseplant_small",
)
"""Categories that may be chosen as targets ("Find a laptop")."""

TARGET_WHITELIST_SET: frozenset[str] = frozenset(TARGET_WHITELIST)

_CATEGORY_ALIASES = MappingProxyType(
    {
        # ProcTHOR / AI2-THOR object types and common synonyms
        "arm_chair": "armchair",
        "couch": "sofa",
        "settee": "sofa",
        "loveseat": "sofa",
        "fridge": "refrigerator",
        "tv": "television",
        "tv_set": "television",
        "tvstand": "tv_stand",
        "t_v_stand": "tv_stand",
        "tv_cabinet": "tv_stand",
        "house_plant": "potted_plant",
        "houseplant": "potted_plant",
        "plant": "potted_plant",
        "flower_pot": "potted_plant",
        "garbage_can": "trash_can",
        "trashcan": "trash_can",
        "waste_bin": "trash_can",
        "bin": "trash_can",
        "laundry_hamper": "laundry_basket",
        "hamper": "laundry_basket",
        "desk_lamp": "table_lamp",
        "lamp": "table_lamp",
        "desktop": "computer",
        "desktop_computer": "computer",
        "pc": "computer",
        "footstool": "ottoman",
        "pouf": "ottoman",
        "statue": "sculpture",
        "figurine": "sculpture",
        "ornament": "sculpture",
        "poster": "painting",
        "picture": "painting",
        "artwork": "painting",
        "frame": "picture_frame",
        "photo_frame": "picture_frame",
        "clock": "wall_clock",
        "bookcase": "bookshelf",
        "book_shelf": "bookshelf",
        "shelving_unit": "shelf",
        "shelves": "shelf",
        "night_stand": "nightstand",
        "bedside_table": "nightstand",
        "end_table": "side_table",
        "chest_of_drawers": "dresser",
        "closet_cabinet": "wardrobe",
        "armoire": "wardrobe",
        "table": "dining_table",
        "kitchen_table": "dining_table",
        "cooktop": "stove",
        "range": "stove",
        "stove_burner": "stove_burner",
        "washer": "washing_machine",
        "tumble_dryer": "dryer",
        "clothes_dryer": "dryer",
        "bath_tub": "bathtub",
        "tub": "bathtub",
        "shower_stall": "shower",
        "soap_bottle": "soap_dispenser",
        "cushion": "pillow",
        "drapes": "curtain",
        "curtains": "curtain",
        "carpet": "rug",
        "mat": "rug",
        "teddy": "teddy_bear",
        "stuffed_animal": "teddy_bear",
        "remote": "remote_control",
        "cell_phone": "cell_phone",
        "mobile_phone": "cell_phone",
        "wine": "wine_bottle",
        "chopping_board": "cutting_board",
        "dish_drainer": "dish_rack",
        "storage_bin": "storage_box",
        "box": "storage_box",
        "crate": "storage_box",
        "tool_box": "toolbox",
        "bike": "bicycle",
        "computer_monitor": "monitor",
        "screen": "monitor",
        "notebook_computer": "laptop",
        "coffee_maker": "coffee_machine",
        "espresso_machine": "coffee_machine",
        "ceiling_lamp": "ceiling_light",
        "pendant_light": "ceiling_light",
        "light_fixture": "ceiling_light",
        "door_frame": "doorframe",
        "door_way": "doorway",
        "wall_panel": "wall",
        "floor_plane": "floor",
        "ground": "floor",
        "ground_plane": "floor",
        "towel_holder": "towel_rack",
        "hand_towel_holder": "towel_rack",
        "hand_towel": "towel",
        "baby_bed": "crib",
        "cot": "crib",
        "ottoman_bench": "ottoman",
        "barstool": "stool",
        "bar_stool": "stool",
        "swivel_chair": "office_chair",
        "desk_chair": "office_chair",
        "dining_chair": "chair",
        "sofa_chair": "armchair",
        "easy_chair": "armchair",
        "basket_ball": "basketball",
    }
)

_IRREGULAR_PLURALS = MappingProxyType(
    {
        "shelves": "shelf",
        "knives": "knife",
        "leaves": "leaf",
        "glasses": "glass",
        "dishes": "dish",
        "boxes": "box",
        "benches": "bench",
        "couches": "couch",
        "brushes": "brush",
        "stairs": "stairs",
        "blinds": "blinds",
        "drapes": "drapes",
        "curtains": "curtain",
        "headphones": "headphones",
        "dumbbells": "dumbbell",
    }
)

_KEEP_S = frozenset({"glass", "bus", "dress", "mattress", "grass", "press", "canvas", "stairs", "blinds", "headphones", "boots", "glasses"})


def _singular(word: str) -> str:
    if word in _IRREGULAR_PLURALS:
        return _IRREGULAR_PLURALS[word]
    if word in _KEEP_S or len(word) <= 3:
        return word
    if word.endswith("shelves"):
        return word[:-3] + "f"
    if word.endswith("ies"):
        return word[:-3] + "y"
    if word.endswith(("ches", "shes", "sses", "xes")):
        return word[:-2]
    if word.endswith("s") and not word.endswith(("ss", "us", "is")):
        return word[:-1]
    return word


def normalize_category(text: str | None) -> str:
    """Map a prim name, asset id, node name or free text onto a category.

    Strips paths, file extensions, trailing numbers and ids
    (``/World/Chair_03`` -> ``chair``, ``Laptop_5.usd`` -> ``laptop``), splits
    CamelCase, singularises the last word and applies synonyms
    (``Fridge`` -> ``refrigerator``, ``HousePlant`` -> ``potted_plant``).
    Returns ``"unknown"`` for empty or purely numeric input.
    """
    if text is None:
        return UNKNOWN_CATEGORY
    text = str(text).strip()
    if not text:
        return UNKNOWN_CATEGORY
    text = text.replace("\\", "/").rstrip("/").rsplit("/", 1)[-1]
    text = re.sub(r"\.(usd[acz]?|gltf|glb|obj|fbx|ply|stl|json)$", "", text, flags=re.I)
    key = _snake(text)
    # drop trailing numeric ids and short hash-like suffixes: chair_03, laptop_5_a
    key = re.sub(r"(_(\d+[a-z]?|[a-z]?\d+))+$", "", key)
    key = re.sub(r"^(sm|geo|mesh|obj|inst|instance|prop)_", "", key)
    if not key or key.isdigit():
        return UNKNOWN_CATEGORY
    words = key.split("_")
    words[-1] = _singular(words[-1])
    key = "_".join(w for w in words if w)
    if key in _CATEGORY_ALIASES:
        return _CATEGORY_ALIASES[key]
    if key in TARGET_WHITELIST_SET or key in STRUCTURAL_CATEGORIES:
        return key
    compact = key.replace("_", "")
    for name in TARGET_WHITELIST:
        if name.replace("_", "") == compact:
            return name
    return key


def is_structural(category: str) -> bool:
    """True for walls, floors, doors, windows, ceiling lights and the like."""
    return category in STRUCTURAL_CATEGORIES


def is_target_eligible(category: str) -> bool:
    """True when ``category`` may be a target (whitelisted, not structural)."""
    return category in TARGET_WHITELIST_SET


def category_display(category: str) -> str:
    """How a category reads in text: ``office_chair`` -> ``office chair``."""
    return category.replace("_", " ")


# ---------------------------------------------------------------------------
# Attributes
# ---------------------------------------------------------------------------

COLORS = MappingProxyType(
    {
        "white": (0.92, 0.92, 0.90),
        "black": (0.08, 0.08, 0.09),
        "gray": (0.50, 0.50, 0.52),
        "brown": (0.45, 0.28, 0.14),
        "beige": (0.85, 0.78, 0.62),
        "red": (0.78, 0.12, 0.12),
        "orange": (0.93, 0.50, 0.12),
        "yellow": (0.93, 0.82, 0.18),
        "green": (0.20, 0.58, 0.25),
        "blue": (0.15, 0.32, 0.75),
        "purple": (0.50, 0.24, 0.62),
        "pink": (0.92, 0.55, 0.68),
    }
)
"""Colour names and the RGB (0..1) that procedural houses paint them with."""

MATERIALS: tuple[str, ...] = ("wood", "metal", "fabric", "leather", "plastic", "glass", "ceramic", "stone", "wicker")
SIZES: tuple[str, ...] = ("small", "medium", "large")
SIZE_SCALE = MappingProxyType({"small": 0.8, "medium": 1.0, "large": 1.25})
"""Geometric scale that a size class applies to an object's default dimensions."""
STATES: tuple[str, ...] = ("open", "closed", "on", "off", "full", "empty", "made", "unmade")

COLOR_INDEX = MappingProxyType({c: i for i, c in enumerate(COLORS)})
MATERIAL_INDEX = MappingProxyType({m: i for i, m in enumerate(MATERIALS)})
SIZE_INDEX = MappingProxyType({s: i for i, s in enumerate(SIZES)})
STATE_INDEX = MappingProxyType({s: i for i, s in enumerate(STATES)})

_COLOR_ALIASES = MappingProxyType(
    {"grey": "gray", "silver": "gray", "charcoal": "black", "cream": "beige", "tan": "beige",
     "ivory": "white", "navy": "blue", "teal": "green", "maroon": "red", "violet": "purple",
     "gold": "yellow", "golden": "yellow", "wooden": "brown"}
)


def attribute_word(kind: int, code: int) -> str | None:
    """The word of attribute ``kind`` (0 colour, 1 material, 2 size, 3 state,
    the order of the simulator's attribute codes) with index ``code``; None
    for -1 or an unknown code."""
    words = (tuple(COLORS), MATERIALS, SIZES, STATES)[kind]
    return words[code] if 0 <= code < len(words) else None


def normalize_color(text: str | None) -> str | None:
    """Map a colour word onto :data:`COLORS` (``grey`` -> ``gray``); None if unknown."""
    if not text:
        return None
    key = _snake(text)
    key = _COLOR_ALIASES.get(key, key)
    return key if key in COLORS else None


def nearest_color(rgb) -> str:
    """Name of the palette colour nearest to an RGB triple in 0..1."""
    r, g, b = (float(v) for v in tuple(rgb)[:3])
    return min(COLORS, key=lambda c: (COLORS[c][0] - r) ** 2 + (COLORS[c][1] - g) ** 2 + (COLORS[c][2] - b) ** 2)
