"""Object categories and room labels from the names files give things: USD
prim names and referenced asset stems, glTF/OBJ node and mesh names.

Every importer that derives a category from a *name* goes through
:func:`category_from_name`, so ``Chair_01``, ``chair.002``, ``BishopL`` and
``light3`` mean the same in a USD stage and in a glTF file. Text meant as a
label (semantic class labels, custom kinds, sidecar categories) is read
with :func:`vocab.normalize_category` as it is. :func:`room_label_from_name`
is the stricter rule for telling a room by its name alone.
"""

from __future__ import annotations

import re

from ignjax.scenes import vocab

_EXTENSION = re.compile(r"\.(usd[acz]?|gltf|glb|obj|fbx|ply|stl|json)$", re.I)
_SUFFIXES = (
    re.compile(r"[ ._-]*\d+$"),  # chair.002, Chair_01, light0
    re.compile(r"[ ._-]+[LlRr]$"),  # Bishop_L, bishop.r, Lamp-R, Lamp L
    re.compile(r"(?<=[a-z])[LR]$"),  # BishopL, BishopR (not Bowl, Bell, Chair, BOWL)
    re.compile(r"[ ._-]+(?:left|right)$", re.I),  # lamp_left, Lamp.RIGHT
    re.compile(r"(?<=[a-z0-9])(?:Left|Right)$"),  # LampLeft (not Copyright, Upright)
)


def name_stem(name: str | None) -> str:
    """A name without its path, file extension and index or side suffixes:
    steps 1 and 2 of :func:`category_from_name`."""
    text = str(name or "").strip().replace("\\", "/").rstrip("/").rsplit("/", 1)[-1]
    text = _EXTENSION.sub("", text)
    stem = text
    while True:
        shorter = stem
        for pattern in _SUFFIXES:
            shorter = pattern.sub("", shorter)
        if shorter == stem:
            break
        stem = shorter
    return stem if re.search(r"[A-Za-z]", stem) else text


def category_from_name(name: str | None) -> str:
    """The object category a prim, node, mesh or asset name stands for.

    One rule for every importer:

    1. keep the last path component and drop a file extension
       (``/World/Chair_01`` -> ``Chair_01``, ``Laptop_5.usd`` -> ``Laptop_5``);
    2. strip, at the end and repeatedly, trailing digits with the separators
       before them (``chair.002``, ``Chair_01``, ``light0``); a side letter
       after a separator (``_L``, ``_R``, ``.L``, ``-R``, any case); a
       capital ``L`` or ``R`` right after a lower-case letter (``BishopL``);
       ``left``/``right`` after a separator (``lamp_left``, any case) or a
       capitalised ``Left``/``Right`` right after a lower-case letter or
       digit (``LampLeft``). A final lower-case letter is part of the word
       (``Bowl``, ``Bell``, ``Chair``, ``Shelf``, ``Mirror``), and so is a
       capital after a capital (``BOWL``, ``TV``); nothing is stripped when
       no letter would remain (``L``, ``001``);
    3. map the rest with :func:`vocab.normalize_category`: CamelCase and
       separators split into lower-case ``snake_case`` words, the last word
       singular, synonyms applied (``Fridge`` -> ``refrigerator``).

    So ``BishopL``, ``Bishop_R`` and ``bishop.L.001`` are all ``bishop``;
    ``light0`` .. ``light3`` are ``light``; ``Chair_01``, ``chair.002`` and
    ``Chairs`` are ``chair``. Index letters are kept (``Chair_A`` is
    ``chair_a``), and so are side words at the front (``LeftLamp``).

    Args:
        name: the name as the file gives it; None or empty for none.

    Returns:
        The category, or ``"unknown"`` for an empty or purely numeric name.
    """
    return vocab.normalize_category(name_stem(name))


def room_label_from_name(name: str | None) -> str | None:
    """The room label a prim's *name* gives it, or None when it names no room.

    Stricter than reading a label, since object names often mention rooms
    (``Lamp_Kitchen``, ``KitchenIsland``). The name, without trailing
    numbers, is split into lower-case words at CamelCase and separators
    (``Bedroom_2`` -> ``bedroom``, ``LivingRoom`` -> ``living room``). It
    names a room when

    * its words, run together or joined by ``_``, are a room name of
      :func:`vocab.normalize_room_label` (``Kitchen``, ``living_room``,
      ``Livingroom``, ``Foyer``, ``powder_room``), or
    * its last word is one (``Guest_Bedroom``, ``Kitchen_Dining``) and no
      earlier word names an object or a part of the building
      (``Lamp_Kitchen`` and ``Floor_Kitchen`` are not rooms), or
    * its last word is ``room`` (``GameRoom``, ``Room_3``): a room labelled
      ``other`` unless the vocabulary knows it;

    and never when the whole name is an object category that may be a
    target (``Toilet`` is an object, not a bathroom; ``KitchenIsland`` an
    island).

    Returns:
        One of :data:`vocab.ALL_ROOM_LABELS` (``"other"`` only for names
        whose last word is ``room``), or None.
    """
    if not name:
        return None
    words = _words(str(name))
    while len(words) > 1 and words[-1].isdigit():
        words.pop()
    words[-1:] = [re.sub(r"\d+$", "", w) or w for w in words[-1:]]
    if not words or vocab.is_target_eligible(category_from_name(name)):
        return None
    for key in ("".join(words), "_".join(words)):
        if _is_room_key(key):
            return vocab.normalize_room_label(key)
    last = words[-1]
    if last != "room" and not _is_room_key(last):
        return None
    for w in words[:-1]:
        cat = vocab.normalize_category(w)
        if vocab.is_target_eligible(cat) or vocab.is_structural(cat):
            return None
    return vocab.normalize_room_label(last) if last != "room" else vocab.OTHER_ROOM


def _words(text: str) -> list[str]:
    """Lower-case words of a name split at CamelCase and separators."""
    text = re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", text)
    text = re.sub(r"([A-Z]+)([A-Z][a-z])", r"\1_\2", text)
    return [w for w in re.sub(r"[^0-9A-Za-z]+", "_", text).lower().split("_") if w]


def _is_room_key(key: str) -> bool:
    """The snake_case key is a room name as a whole, not only through one of
    its words (:func:`vocab.normalize_room_label` accepts either)."""
    if vocab.normalize_room_label(key) == vocab.OTHER_ROOM:
        return False
    words = key.split("_")
    return len(words) == 1 or all(vocab.normalize_room_label(w) == vocab.OTHER_ROOM for w in words)
