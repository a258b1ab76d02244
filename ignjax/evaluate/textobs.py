"""The observation in words: the ``text`` observation of MLLM agents (an
ablation: the simulator's ground-truth perception, instance ids, metres and
the room label included) and the executor's report of the last move."""

from __future__ import annotations

import numpy as np

from ignjax.agents.llm.agent import MOVE, MOVED_M
from ignjax.scenes import vocab


def observation_text(obs: dict, r: int, categories: tuple[str, ...], names: tuple[str, ...], cells=None) -> str:
    """Row ``r`` of the symbolic observation as text (the ``text`` observation of MLLM agents, an ablation:
    ground truth, instance ids, metres and the room label included): per view, the free distance ahead and the
    objects in sight with their perceived attributes; with ``cells`` (K, 2)
    (:func:`ignjax.evaluate.candidates.front_cells`), the front-view grid cell of each object that appears in the
    front view (what a Type-4 question names)."""
    lines = []
    fs = obs["free_space"][r]
    handles, cats, views, ranges, attrs = (obs[k][r] for k in ("visible_handle", "visible_category", "visible_view",
                                                                "visible_range", "visible_attrs"))
    for k in range(fs.shape[0]):
        seen = []
        for j in np.flatnonzero((handles >= 0) & (views == k)):
            words = [vocab.attribute_word(a, int(attrs[j, a])) for a in range(4) if attrs[j, a] >= 0]
            words = [w for w in words if w]
            cat = vocab.category_display(categories[int(cats[j])]) if 0 <= cats[j] < len(categories) else "object"
            where = (f", front view column {int(cells[j, 0])} row {int(cells[j, 1])}"
                     if cells is not None and cells[j, 0] > 0 else "")
            seen.append(f"{' '.join(words + [cat])} (object {int(handles[j])}, about {float(ranges[j]):.1f} m{where})")
        name = names[k] if k < len(names) else f"view {k}"
        lines.append(f"- {name}: open floor for about {float(fs[k].min()):.1f} m; "
                     + (f"you see {', '.join(seen)}" if seen else "nothing of note"))
    room = int(obs["room_label"][r])
    if 0 <= room < len(vocab.ALL_ROOM_LABELS):
        lines.insert(0, f"You seem to be in a {vocab.ROOM_DISPLAY[vocab.ALL_ROOM_LABELS[room]]}.")
    return "\n".join(lines)


def last_move_text(obs: dict, r: int, kind: int) -> str:
    """What the executor reported about the last MOVE of row ``r`` ("" after another action)."""
    if kind != MOVE:
        return ""
    moved = float(obs["last_move"][r])
    if moved < MOVED_M:
        return "the way was blocked; you did not move."
    return f"you moved {moved:.1f} m" + ("; part of the way was blocked." if obs["blocked"][r].any() else ".")


__all__ = ["last_move_text", "observation_text"]
