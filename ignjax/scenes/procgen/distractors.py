"""The per-house distractor plan, for the furnisher
(:mod:`ignjax.scenes.procgen.furnish`, whose docstring gives the rules): which
target-eligible categories get several instances, how many, in which rooms,
and with which attributes (the first instance's colour copied or avoided).
"""

from __future__ import annotations

import dataclasses
from typing import Mapping

import numpy as np

from ignjax.scenes import vocab
from ignjax.scenes.model import Attributes
from ignjax.scenes.procgen.catalogue import CategorySpec
from ignjax.scenes.procgen.params import HouseParams
from ignjax.scenes.procgen.placement import Furnisher, weighted_pick
from ignjax.scenes.procgen.roomspace import RoomCtx

__all__ = ["Required", "eligible", "plan_distractors"]

Required = dict[int, list[tuple[CategorySpec, Attributes]]]
"""Per room index, the distractor instances planned for it: (spec, attributes)."""


def eligible(spec: CategorySpec, label: str, catalogue: Mapping[str, CategorySpec]) -> bool:
    """Whether ``spec`` can be placed in a room labelled ``label`` (an
    ``on_support`` category: when one of its supports can)."""
    if spec.rooms.get(label, 0.0) <= 0:
        return False
    if spec.placement != "on_support":
        return True
    return any(s in catalogue and catalogue[s].placement != "on_support" and catalogue[s].rooms.get(label, 0.0) > 0
               for s in spec.supports)


def plan_distractors(f: Furnisher, ctxs: list[RoomCtx]) -> tuple[list[str], Required]:
    """Draw the distractor categories of a house and plan their instances.

    Returns:
        The distractor categories, in the order drawn, and the instances
        planned for each room.
    """
    multi = _draw_categories(f, ctxs)
    f.exclude = set(multi)
    required: Required = {k: [] for k in range(len(ctxs))}
    first_attrs: dict[str, Attributes] = {}
    for name in multi:
        spec = f.cat[name]
        for j, k in enumerate(_rooms_of(f, ctxs, spec)):
            attrs = spec.sample_attributes(f.rng) if j == 0 else _attributes_like(f.rng, f.params, spec, first_attrs[name])
            if j == 0:
                first_attrs[name] = attrs
            required[k].append((spec, attrs))
    return multi, required


def _draw_categories(f: Furnisher, ctxs: list[RoomCtx]) -> list[str]:
    """``multi_categories`` target-eligible categories that some room can hold, drawn without
    replacement, small ones and ones that fit many rooms more often."""
    params, catalogue = f.params, f.cat
    cands, weights = [], []
    for name, spec in catalogue.items():
        if not vocab.is_target_eligible(name):
            continue
        n_el = sum(eligible(spec, c.label, catalogue) for c in ctxs)
        if n_el == 0:
            continue
        b = f.probe(spec)
        foot = 4 * b.half_extents[0] * b.half_extents[1]
        cands.append(name)
        weights.append(min(n_el, params.instances_per_multi[1]) / (0.3 + foot))
    multi: list[str] = []
    while len(multi) < params.multi_categories and cands:
        name = weighted_pick(f.rng, cands, weights)
        k = cands.index(name)
        cands.pop(k)
        weights.pop(k)
        multi.append(name)
    return multi


def _rooms_of(f: Furnisher, ctxs: list[RoomCtx], spec: CategorySpec) -> list[int]:
    """The room index of each planned instance of ``spec``: an extra instance goes into a room
    that already holds one with ``same_room_prob``, else into another eligible room."""
    params, rng = f.params, f.rng
    el = [k for k, c in enumerate(ctxs) if eligible(spec, c.label, f.cat)]
    w = [spec.rooms.get(ctxs[k].label, 0.0) for k in el]
    m = int(rng.integers(params.instances_per_multi[0], params.instances_per_multi[1] + 1))
    used = [weighted_pick(rng, el, w)]
    for _ in range(m - 1):
        others = [k for k in el if k not in used]
        if rng.random() < params.same_room_prob or not others:
            used.append(used[int(rng.integers(len(used)))])
        else:
            used.append(weighted_pick(rng, others, [spec.rooms.get(ctxs[k].label, 0.0) for k in others]))
    return used


def _attributes_like(rng: np.random.Generator, params: HouseParams, spec: CategorySpec,
                     first: Attributes | None) -> Attributes:
    """Attributes of an extra instance of a distractor category."""
    attrs = spec.sample_attributes(rng)
    if first is None or first.color is None:
        return attrs
    if rng.random() < params.similar_appearance_prob:
        return dataclasses.replace(attrs, color=first.color)
    others = [c for c in spec.colors if c != first.color]
    if others:
        return dataclasses.replace(attrs, color=str(rng.choice(others)))
    return attrs
