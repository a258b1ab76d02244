"""What Type-3 questions asked (:func:`ignjax.studies.interaction.classify_question`,
:func:`~ignjax.studies.interaction.type3_content`): the classifier on
hand-written questions of each class, the split from question events and
texts, questions without text, and the split not applicable to agents that
write no question text. The split from a real MLLM run against the scripted
server is checked in ``tests/sweep/test_sweep_llm.py``."""

from __future__ import annotations

import numpy as np
import pytest

from ignjax.studies import interaction as IA
from ignjax.studies import interaction_plots as IP

QUESTIONS = {
    "route": ["Which way should I go to reach the kitchen?", "How do I get to the bedroom from here?",
              "Is there a path out of this room?", "What is my next turn?", "Where should I head now?",
              "Which way is the kitchen?", "Can you give me directions to the office?"],
    "goal_room_position": ["Where is the kitchen?", "Which room is the target in?", "Is the kitchen to my left?",
                           "Am I near the goal room?", "How far is the bathroom?", "In which part of the house is it?",
                           "Where\u2019s the laundry room located?"],
    "room_relations": ["What is next to the kitchen?", "Which rooms connect to this hallway?",
                       "Is the bedroom beyond the living room?", "Where is the kitchen relative to the hallway?",
                       "What lies between the hall and the office?", "Is the office behind the kitchen?",
                       "Which room is adjacent to the dining room?"],
    "unclassified": ["Hello?", "", "Can you help me?", "Is it the red one?"],
}


@pytest.mark.parametrize("cls, text", [(c, q) for c, qs in QUESTIONS.items() for q in qs])
def test_classifier_on_hand_written_questions(cls, text):
    assert IA.CONTENT_CLASSES[IA.classify_question(text)] == cls


def _events(types, steps, episodes, difficulty=(0, 2)):
    return {"episode": np.asarray(episodes), "type": np.asarray(types), "step": np.asarray(steps),
            "charged": np.ones(len(types), bool), "steps_used": np.full(len(difficulty), 10),
            "difficulty": np.asarray(difficulty), "episode_id": np.asarray(["a", "b"])}


def test_split_counts_shares_and_questions_without_text():
    ev = _events(types=[3, 1, 3, 3, 3, 3], steps=[0, 1, 2, 0, 4, 5], episodes=[0, 0, 0, 1, 1, 1])
    texts = {(0, 0): "Which way to the kitchen?", (0, 1): "What colour is it?", (0, 2): "Where is the kitchen?",
             (1, 0): "Where is the bedroom?", (1, 4): "Hmm?"}  # (1, 5): asked without text
    r = IA.type3_content(ev, texts)
    assert r["applicable"] and r["n"] == 5 and r["n_without_text"] == 1
    assert r["counts"].tolist() == [1, 2, 0, 1]  # route, goal-room position, relations, unclassified
    np.testing.assert_allclose(r["fractions"], [1 / 3, 2 / 3, 0.0])
    assert r["cls"].tolist() == [0, 1, 1, 3, IA.UNKNOWN]
    assert r["counts_by_difficulty"].tolist() == [[1, 1, 0, 0], [0, 0, 0, 0], [0, 1, 0, 1]]
    # no Type-3 question: applicable, nothing counted, shares undefined
    empty = IA.type3_content(_events([1], [0], [0]), {})
    assert empty["n"] == 0 and empty["counts"].sum() == 0 and np.isnan(empty["fractions"]).all()


def test_split_not_applicable_without_texts():
    ev = _events(types=[3, 3], steps=[0, 1], episodes=[0, 1])
    r = IA.type3_content(ev, None, reason="`vlm` names the question type only")
    assert r == {"applicable": False, "reason": "`vlm` names the question type only", "classes": IA.CONTENT_CLASSES,
                 "n": 2}


def test_plot_with_the_content_panel(tmp_path):
    ev = _events(types=[3, 3], steps=[0, 1], episodes=[0, 1])
    loc = {"fractions": np.array([0.5, 0.5, 0, 0]), "counts": np.array([1, 1, 0, 0]), "n_unknown": 0}
    for content in (IA.type3_content(ev, {(0, 0): "Which way?", (1, 1): "Where is the kitchen?"}),
                    IA.type3_content(ev, None, reason="no texts")):
        path = IP.plot_location_classes(loc, tmp_path / f"loc_{content['applicable']}.png", content=content)
        assert path.is_file() and path.stat().st_size > 0
