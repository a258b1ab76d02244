"""Target descriptions, their acceptance check, and Type-1/Type-2 oracle facts.

A description is written from **facts**: the target's category, some of its
structured attributes (colour, material, size class, state) and relations to
its anchors (the instance it stands on, instances next to it or standing on
it). Facts are chosen greedily until no same-category distractor satisfies
all of them; a target that cannot be separated gets no description (and no
episode). The text never names a room.

:func:`check_description` judges any text (ours or someone else's, e.g. a
captioning model's) against the scene: it rejects a description that is
empty, names a room, names the wrong category, or does not separate the
target from its distractors under the stored attributes and relations.
Because attributes and categories come from closed vocabularies, the text
can be read back into facts exactly (:func:`read_facts`).
"""

from __future__ import annotations

import re
import zlib
from dataclasses import dataclass

from ignjax.scenes import vocab
from ignjax.scenes.model import Instance, Scene

MATERIAL_ADJECTIVE = {
    "wood": "wooden", "metal": "metal", "fabric": "fabric", "leather": "leather", "plastic": "plastic",
    "glass": "glass", "ceramic": "ceramic", "stone": "stone", "wicker": "wicker",
}
_ADJ_TO_MATERIAL = {v: k for k, v in MATERIAL_ADJECTIVE.items()} | {"wood": "wood", "metallic": "metal"}
STATE_PHRASE = {
    "open": "open", "closed": "closed", "on": "switched on", "off": "switched off",
    "full": "full", "empty": "empty", "made": "neatly made", "unmade": "unmade",
}
SIZE_WORD = {"small": "small", "medium": "medium-sized", "large": "large"}
_SIZE_FROM_WORD = {"small": "small", "little": "small", "medium": "medium", "medium-sized": "medium",
                   "large": "large", "big": "large"}


@dataclass(frozen=True)
class Facts:
    """What a description asserts about its target.

    Attributes:
        category: the target category.
        color, material, size, state: asserted attribute values (None: not said).
        on: category of the instance the target stands on, if said.
        near: categories of anchors said to be next to (or on) the target.
    """

    category: str
    color: str | None = None
    material: str | None = None
    size: str | None = None
    state: str | None = None
    on: str | None = None
    near: tuple[str, ...] = ()

    def as_dict(self) -> dict:
        return {"category": self.category, "color": self.color, "material": self.material, "size": self.size,
                "state": self.state, "on": self.on, "near": list(self.near)}


def _anchor_categories(scene: Scene, anchors: dict[str, tuple[str, ...]], inst: Instance) -> set[str]:
    by_id = {i.id: i for i in scene.instances}
    return {by_id[a].category for a in anchors.get(inst.id, ())}


def satisfies(scene: Scene, anchors: dict[str, tuple[str, ...]], inst: Instance, facts: Facts) -> bool:
    """Whether ``inst`` satisfies every fact (using stored attributes/relations)."""
    if inst.category != facts.category:
        return False
    a = inst.attributes
    for name in ("color", "material", "size", "state"):
        want = getattr(facts, name)
        if want is not None and getattr(a, name) != want:
            return False
    if facts.on is not None:
        if inst.support is None:
            return False
        try:
            if scene.instance(inst.support).category != facts.on:
                return False
        except KeyError:
            return False
    near = _anchor_categories(scene, anchors, inst)
    return all(c in near for c in facts.near)


def choose_facts(scene: Scene, anchors: dict[str, tuple[str, ...]], target: Instance,
                 distractors: list[Instance], unique_anchor_ids: tuple[str, ...] = ()) -> Facts | None:
    """Greedy fact selection: colour first, then the support, material,
    state, size and anchor categories (unique anchors first), each added only
    while some distractor still satisfies the facts so far. Always states the
    colour (when known) and, for a supported object, its support. Returns None
    when the stored attributes and relations cannot separate the target."""
    by_id = {i.id: i for i in scene.instances}
    a = target.attributes
    support_cat = by_id[target.support].category if target.support and target.support in by_id else None
    # relations only to categories :func:`read_facts` can read back (the closed target vocabulary);
    # a relation to any other category would be lost on reading and the check would reject the text
    if support_cat not in vocab.TARGET_WHITELIST_SET:
        support_cat = None
    options: list[tuple[str, object]] = []
    if a.color:
        options.append(("color", a.color))
    if support_cat:
        options.append(("on", support_cat))
    for name in ("material", "state", "size"):
        v = getattr(a, name)
        if v:
            options.append((name, v))
    anchor_cats: list[str] = []
    for aid in list(unique_anchor_ids) + [x for x in anchors.get(target.id, ()) if x not in unique_anchor_ids]:
        c = by_id[aid].category
        if (c != support_cat and c not in anchor_cats and not by_id[aid].structural
                and c in vocab.TARGET_WHITELIST_SET):
            anchor_cats.append(c)
    options += [("near", c) for c in anchor_cats]

    facts = Facts(target.category)
    remaining = [d for d in distractors if satisfies(scene, anchors, d, facts)]
    must = {"color", "on"}
    for kind, value in options:
        if not remaining and kind not in must:
            continue
        if kind == "near":
            new = Facts(**{**facts.__dict__, "near": facts.near + (value,)})
        else:
            new = Facts(**{**facts.__dict__, kind: value})
        new_remaining = [d for d in remaining if satisfies(scene, anchors, d, new)]
        if kind in must or len(new_remaining) < len(remaining):
            facts, remaining = new, new_remaining
    if remaining:
        return None
    if facts.on is None and not facts.near and anchor_cats:
        facts = Facts(**{**facts.__dict__, "near": (anchor_cats[0],)})  # one relation reads more naturally
    return facts


def _article(word: str) -> str:
    return "an" if word[:1].lower() in "aeiou" else "a"


def render_description(facts: Facts, variant: int = 0) -> str:
    """Turn facts into one or two plain sentences (three template variants)."""
    adj = []
    if facts.size is not None:
        adj.append(SIZE_WORD[facts.size])
    if facts.color is not None:
        adj.append(facts.color)
    if facts.material is not None:
        adj.append(MATERIAL_ADJECTIVE[facts.material])
    noun = " ".join(adj + [vocab.category_display(facts.category)])
    state = f" that is {STATE_PHRASE[facts.state]}" if facts.state else ""
    rel = []
    if facts.on is not None:
        rel.append(f"resting on {_article(facts.on)} {vocab.category_display(facts.on)}")
    for c in facts.near:
        rel.append(f"next to {_article(c)} {vocab.category_display(c)}")
    rel_text = ", ".join(rel[:-1]) + (" and " if len(rel) > 1 else "") + rel[-1] if rel else ""
    variant %= 3
    if variant == 0:
        text = f"{_article(noun).capitalize()} {noun}{state}"
        return text + (f", {rel_text}." if rel_text else ".")
    if variant == 1:
        text = f"Look for the {noun}{state}"
        return text + (f"; it is {rel_text}." if rel_text else ".")
    text = f"The one I mean is the {noun}{state}"
    return text + (f", {rel_text}." if rel_text else ".")


def describe_target(scene: Scene, anchors: dict[str, tuple[str, ...]], target: Instance,
                    distractors: list[Instance], unique_anchor_ids: tuple[str, ...] = ()) -> tuple[str, Facts] | None:
    """Description text and its facts, or None when none separates the target.

    The template variant is a stable function of the target id, so the same
    scene always yields the same text.
    """
    facts = choose_facts(scene, anchors, target, distractors, unique_anchor_ids)
    if facts is None:
        return None
    variant = zlib.crc32(f"{scene.id}/{target.id}".encode()) % 3
    return render_description(facts, variant), facts


# ---------------------------------------------------------------------------
# Reading text back and checking it
# ---------------------------------------------------------------------------

def _category_patterns() -> list[tuple[str, re.Pattern]]:
    names = set(vocab.TARGET_WHITELIST)
    pats = []
    for c in sorted(names, key=lambda c: -len(vocab.category_display(c))):
        words = vocab.category_display(c).split()
        body = r"\s+".join(re.escape(w) for w in words[:-1] + [words[-1]])
        pats.append((c, re.compile(rf"\b{body}(?:s|es)?\b", re.I)))
    return pats


_CATEGORY_PATTERNS = _category_patterns()
_ROOM_WORDS = sorted({w for w in list(vocab._ROOM_ALIASES) + list(vocab.ROOM_LABELS)}, key=len, reverse=True)
_ROOM_PATTERNS = [re.compile(r"\b" + r"[\s_-]*".join(re.escape(p) for p in w.split("_")) + r"s?\b", re.I) for w in _ROOM_WORDS]


def _mentions(text: str) -> list[tuple[int, str]]:
    """(position, category) of every category mention, longest names first."""
    taken = [False] * len(text)
    found = []
    for cat, pat in _CATEGORY_PATTERNS:
        for m in pat.finditer(text):
            if not any(taken[m.start():m.end()]):
                found.append((m.start(), cat))
                for k in range(m.start(), m.end()):
                    taken[k] = True
    return sorted(found)


def _strip_categories(text: str) -> str:
    out = text
    for _, pat in _CATEGORY_PATTERNS:
        out = pat.sub(" ", out)
    return out


def names_room(text: str) -> str | None:
    """The room word a text uses (category names such as "office chair" or
    "dining table" excepted), or None."""
    rest = _strip_categories(text)
    for w, pat in zip(_ROOM_WORDS, _ROOM_PATTERNS):
        m = pat.search(rest)
        if m:
            return m.group(0)
    return None


def read_facts(text: str) -> Facts | None:
    """Read the facts a text asserts (subject = first category mentioned).

    Returns None when no category is mentioned.
    """
    mentions = _mentions(text)
    if not mentions:
        return None
    subject = mentions[0][1]
    lower = _strip_categories(text).lower()
    words = re.findall(r"[a-z][a-z\-]*", lower)
    color = next((vocab.normalize_color(w) for w in words if vocab.normalize_color(w) and w not in ("wooden",)), None)
    material = next((_ADJ_TO_MATERIAL[w] for w in words if w in _ADJ_TO_MATERIAL), None)
    size = next((_SIZE_FROM_WORD[w] for w in words if w in _SIZE_FROM_WORD), None)
    state = None
    if re.search(r"\b(switched|turned)\s+on\b", lower):
        state = "on"
    elif re.search(r"\b(switched|turned)\s+off\b", lower):
        state = "off"
    else:
        for w, s in (("unmade", "unmade"), ("open", "open"), ("closed", "closed"), ("full", "full"),
                     ("filled", "full"), ("empty", "empty"), ("made", "made")):
            if re.search(rf"\b{w}\b", lower):
                state = s
                break
    on = None
    near: list[str] = []
    for pos, cat in mentions[1:]:
        before = text[max(0, pos - 30):pos].lower()
        if on is None and re.search(r"\b(on|on top of|upon|atop)\s+(a|an|the)\s*$", before):
            on = cat
        elif cat not in near:
            near.append(cat)
    return Facts(subject, color, material, size, state, on, tuple(near))


@dataclass(frozen=True)
class DescriptionCheck:
    ok: bool
    reason: str = ""


def check_description(text: str | None, scene: Scene, anchors: dict[str, tuple[str, ...]], target: Instance,
                      distractors: list[Instance]) -> DescriptionCheck:
    """Accept or reject a description of ``target``.

    Rejected when: empty; names a room; names no category or a category other
    than the target's as its subject; asserts something false of the target;
    or some distractor satisfies everything it asserts.
    """
    if text is None or not text.strip():
        return DescriptionCheck(False, "empty description")
    room = names_room(text)
    if room:
        return DescriptionCheck(False, f"names a room ({room!r})")
    facts = read_facts(text)
    if facts is None:
        return DescriptionCheck(False, "names no object category")
    if facts.category != target.category:
        return DescriptionCheck(False, f"names the wrong category ({facts.category!r}, target is {target.category!r})")
    if not satisfies(scene, anchors, target, facts):
        return DescriptionCheck(False, "asserts something that is not true of the target")
    confusable = [d.id for d in distractors if satisfies(scene, anchors, d, facts)]
    if confusable:
        return DescriptionCheck(False, f"does not separate the target from distractor(s) {confusable}")
    return DescriptionCheck(True)


def instruction_text(category: str) -> str:
    """The coarse goal given to the agent: ``Find a laptop.``"""
    name = vocab.category_display(category)
    return f"Find {_article(name)} {name}."


def region_text(scene: Scene, anchors: dict[str, tuple[str, ...]], target: Instance) -> str:
    """Type-2 fact: the goal room and a coarse region inside it (the largest
    nearby piece of furniture of another category), without any appearance
    detail of the target."""
    return region_fact(scene, anchors, target)[0]


def region_fact(scene: Scene, anchors: dict[str, tuple[str, ...]], target: Instance) -> tuple[str, str | None]:
    """:func:`region_text` and the category of the region's anchor (or None)."""
    room_label = scene.room(target.room).label if target.room else vocab.OTHER_ROOM
    room_name = vocab.ROOM_DISPLAY[room_label]
    by_id = {i.id: i for i in scene.instances}
    cands = [by_id[a] for a in anchors.get(target.id, ()) if by_id[a].support is None and not by_id[a].structural]
    if target.support and target.support in by_id:
        cands.insert(0, by_id[target.support])
    if room_label == vocab.OTHER_ROOM:
        where = "It is not in any of the usual rooms"
    else:
        where = f"It is in the {room_name}"
    if cands:
        big = max(cands, key=lambda i: i.bbox.half_extents[0] * i.bbox.half_extents[1]) if not target.support else cands[0]
        prep = "on" if big.id == target.support else "near"
        return f"{where}, {prep} the {vocab.category_display(big.category)}.", big.category
    return f"{where}.", None
