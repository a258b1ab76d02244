"""Instance inventory and target candidates of a scene.

For each scene we take its room-object graph (:mod:`ignjax.scenes.graph`)
and list the **candidate targets**: non-structural instances of
whitelisted categories (:data:`ignjax.scenes.vocab.TARGET_WHITELIST`; walls,
floors, doors, windows, ceiling lights and ``unknown`` are never targets).

Frequent categories are **capped per scene** with a room round-robin rule:
when a category has more than ``category_cap`` instances, targets are taken
one room at a time (rooms in scene order, instances in scene order within a
room) until the cap is reached, so the benchmark neither collapses onto a
few high-count categories nor onto one room. Capped-out instances still
count as distractors.

For every candidate we record its same-category **distractors** (all other
non-structural instances of the category in the scene), those in the same
room, its **anchors** (nearby non-structural instances of other
categories, footprint distance <= ``anchor_radius``; the instance it
stands on and those standing on it are anchors at distance 0) and
**rho**, the fraction of its anchors whose category is found among the
anchors of none of its distractors (see :mod:`ignjax.episodes.difficulty`
for the edge cases).
"""

from __future__ import annotations

from dataclasses import dataclass

from ignjax.errors import ConfigError
from ignjax.episodes.difficulty import context_rho
from ignjax.scenes import vocab
from ignjax.scenes.graph import nearby_instances
from ignjax.scenes.model import Scene


@dataclass(frozen=True)
class InventoryConfig:
    """Options of candidate selection.

    Attributes:
        anchor_radius: footprint distance (m) within which other objects
            are the target's anchors.
        category_cap: most targets per category per scene (round-robin
            over rooms beyond it).
        whitelist: categories that may be targets.
    """

    anchor_radius: float = 1.5
    category_cap: int = 6
    whitelist: tuple[str, ...] = vocab.TARGET_WHITELIST

    def __post_init__(self):
        if not (self.anchor_radius > 0):
            raise ConfigError(None, "inventory.anchor_radius", f"must be positive, got {self.anchor_radius!r}")
        if not (isinstance(self.category_cap, int) and self.category_cap >= 1):
            raise ConfigError(None, "inventory.category_cap", f"must be an integer >= 1, got {self.category_cap!r}")
        bad = [c for c in self.whitelist if vocab.is_structural(c) or c == vocab.UNKNOWN_CATEGORY]
        if bad:
            raise ConfigError(None, "inventory.whitelist", f"structural or unknown categories cannot be targets: {bad}")


@dataclass(frozen=True)
class Candidate:
    """A candidate target and its ambiguity structure.

    Attributes:
        scene_id: the scene.
        target_id: the target instance id.
        category: its category.
        room: its room id (None when outside every room).
        distractors: ids of the other instances of its category (scene order).
        same_room_distractors: those in the target's room.
        anchors: ids of nearby instances of other categories.
        unique_anchors: anchors whose category no distractor has nearby.
        rho: unique-anchor fraction with the edge cases of the difficulty module.
    """

    scene_id: str
    target_id: str
    category: str
    room: str | None
    distractors: tuple[str, ...]
    same_room_distractors: tuple[str, ...]
    anchors: tuple[str, ...]
    unique_anchors: tuple[str, ...]
    rho: float


@dataclass(frozen=True)
class Inventory:
    """A scene's inventory: candidates plus the derived graph it used.

    Attributes:
        scene: the scene.
        candidates: candidate targets after whitelist and caps.
        anchors: instance id -> anchor ids (every non-structural instance).
        category_counts: category -> number of non-structural instances.
        capped: category -> number of instances left out by the cap.
    """

    scene: Scene
    candidates: tuple[Candidate, ...]
    anchors: dict[str, tuple[str, ...]]
    category_counts: dict[str, int]
    capped: dict[str, int]


def _anchor_map(scene: Scene, radius: float) -> dict[str, tuple[str, ...]]:
    near = nearby_instances(scene, radius)
    by_id = {i.id: i for i in scene.instances}
    out: dict[str, tuple[str, ...]] = {}
    for iid, others in near.items():
        cat = by_id[iid].category
        ids = set(o for o in others if by_id[o].category != cat)
        inst = by_id[iid]
        if inst.support is not None and inst.support in by_id and not by_id[inst.support].structural:
            if by_id[inst.support].category != cat:
                ids.add(inst.support)
        order = {x.id: k for k, x in enumerate(scene.instances)}
        out[iid] = tuple(sorted(ids, key=order.__getitem__))
    for inst in scene.objects:  # objects standing on others are anchors of their support
        if inst.support is not None and inst.support in out and inst.category != by_id[inst.support].category:
            if inst.id not in out[inst.support]:
                order = {x.id: k for k, x in enumerate(scene.instances)}
                out[inst.support] = tuple(sorted(out[inst.support] + (inst.id,), key=order.__getitem__))
    return out


def _round_robin(scene: Scene, ids: list[str], cap: int) -> list[str]:
    """Pick ``cap`` of ``ids`` cycling over rooms (scene order)."""
    if len(ids) <= cap:
        return ids
    by_id = {i.id: i for i in scene.instances}
    room_order = [r.id for r in scene.rooms] + [None]
    queues = {r: [i for i in ids if by_id[i].room == r] for r in room_order}
    picked: list[str] = []
    while len(picked) < cap:
        for r in room_order:
            if queues[r] and len(picked) < cap:
                picked.append(queues[r].pop(0))
    order = {x: k for k, x in enumerate(ids)}
    return sorted(picked, key=order.__getitem__)


def build_inventory(scene: Scene, config: InventoryConfig = InventoryConfig()) -> Inventory:
    """Inventory and candidate targets of one scene (deterministic)."""
    whitelist = frozenset(config.whitelist)
    anchors = _anchor_map(scene, config.anchor_radius)
    by_id = {i.id: i for i in scene.instances}
    by_cat: dict[str, list[str]] = {}
    for inst in scene.objects:
        by_cat.setdefault(inst.category, []).append(inst.id)
    counts = {c: len(v) for c, v in sorted(by_cat.items())}
    candidates: list[Candidate] = []
    capped: dict[str, int] = {}
    for cat, ids in by_cat.items():
        if cat not in whitelist or vocab.is_structural(cat) or cat == vocab.UNKNOWN_CATEGORY:
            continue
        chosen = _round_robin(scene, ids, config.category_cap)
        if len(chosen) < len(ids):
            capped[cat] = len(ids) - len(chosen)
        for tid in chosen:
            target = by_id[tid]
            distractors = tuple(i for i in ids if i != tid)
            same_room = tuple(i for i in distractors if target.room is not None and by_id[i].room == target.room)
            t_anchor_cats = {by_id[a].category for a in anchors[tid]}
            d_anchor_cats = {by_id[a].category for d in distractors for a in anchors[d]}
            unique = tuple(a for a in anchors[tid] if by_id[a].category not in d_anchor_cats)
            del t_anchor_cats
            rho = float(context_rho(len(anchors[tid]), len(unique), len(distractors)))
            candidates.append(Candidate(scene.id, tid, cat, target.room, distractors, same_room, anchors[tid], unique, rho))
    order = {x.id: k for k, x in enumerate(scene.instances)}
    candidates.sort(key=lambda c: order[c.target_id])
    return Inventory(scene, tuple(candidates), anchors, counts, capped)
