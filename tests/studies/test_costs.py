"""Cost derivation on the paper's published statistics and on annotation files."""

import json

import numpy as np
import pytest

from ignjax.studies import cost_derivation as C
from ignjax.errors import ConfigError, InputError


def test_published_statistics_complete_the_taxonomy():
    st = C.published_statistics()
    assert set(st.cues) == set(C.CUES) and len(st.cues) == 17
    assert st.mentions.sum() == pytest.approx(135128)
    assert set(st.assumed) == {"shape", "size", "material", "state", "support_placement"}
    row = {r["cue"]: r for r in st.as_rows()}
    assert row["target_identity"]["top1_rate"] == pytest.approx(7803 / 18385)
    assert row["direction_action"]["avg_score"] == pytest.approx(0.7975)
    assert len(C.published_statistics("drop").cues) == 12


def test_derivation_by_hand_for_one_type():
    st = C.published_statistics("drop")
    lam = (0.5, 0.3, 0.2)
    d = C.derive_costs(st, lam)
    # Type 4 has a single cue: U_4 = U_disambiguation
    u4 = 0.5 * 0.5985 + 0.3 * 0.229 + 0.2 * (154 / 18385)
    assert d.type_utility[3] == pytest.approx(u4)
    # Type 3: mention-weighted mean over its four cues
    rows = {"direction_action": (16957, .7975, .596, 5567), "path_sequence": (7813, .7905, .664, 952),
            "room_to_room_relation": (7649, .6661, .100, 154), "landmark": (9476, .6367, .055, 67)}
    num = sum(m * (0.5 * s + 0.3 * h + 0.2 * t / 18385) for m, s, h, t in rows.values())
    assert d.type_utility[2] == pytest.approx(num / sum(r[0] for r in rows.values()))
    # linear rescale: min utility -> 0.103, max -> 0.240
    assert d.costs.min() == pytest.approx(0.103) and d.costs.max() == pytest.approx(0.240)
    lo, hi = d.type_utility.min(), d.type_utility.max()
    np.testing.assert_allclose(d.costs, 0.103 + (d.type_utility - lo) / (hi - lo) * 0.137)


def test_published_statistics_reproduce_the_locked_ordering():
    d = C.derive_costs()
    assert d.locked_ordering == (3, 1, 2, 4)
    assert d.same_ordering
    fit = C.fit_lambdas()
    assert fit.rmse <= d.rmse
    assert sum(fit.lambdas) == pytest.approx(1.0)


def test_fit_recovers_known_lambdas():
    st = C.published_statistics()
    truth = C.derive_costs(st, (0.2, 0.5, 0.3))
    fit = C.fit_lambdas(st, locked=tuple(truth.costs), step=0.05)
    assert fit.rmse < 1e-9
    np.testing.assert_allclose(fit.lambdas, (0.2, 0.5, 0.3), atol=1e-9)


def _write(path, records):
    path.write_text("\n".join(json.dumps(r) for r in records) + "\n")
    return path


def test_statistics_from_annotation_file(tmp_path):
    recs = [
        {"id": "a", "disambiguation_needed": True, "rank": ["color", "room_name"],
         "priors": [{"cue": "color", "evidence": "red", "importance": 0.8, "gain": "high"},
                    {"cue": "room_name", "evidence": "kitchen", "importance": 0.4, "gain": "low"}]},
        {"id": "b", "disambiguation_needed": False, "rank": ["room_name"],
         "priors": [{"cue": "room_name", "evidence": "bedroom", "importance": 0.6, "gain": "high"},
                    {"cue": "color", "evidence": "", "importance": 1.0, "gain": "high"}]},  # no evidence: not counted
        {"id": "c", "rank": [], "priors": [{"cue": "disambiguation_cue", "evidence": "the other one", "importance": 0.5, "gain": "medium"},
                                           {"cue": "direction_action", "evidence": "turn left", "importance": 0.9, "gain": "high"},
                                           {"cue": "target_identity", "evidence": "mug", "importance": 1.0, "gain": "high"}]},
    ]
    st = C.statistics_from_annotations(_write(tmp_path / "ann.jsonl", recs))
    row = {r["cue"]: r for r in st.as_rows()}
    assert st.n_records == 3
    assert row["color"]["mentions"] == 1 and row["color"]["avg_score"] == pytest.approx(0.8)
    assert row["room_name"]["mentions"] == 2 and row["room_name"]["avg_score"] == pytest.approx(0.5)
    assert row["room_name"]["high_gain"] == pytest.approx(0.5)
    assert row["room_name"]["top1_rate"] == pytest.approx(1 / 3) and row["color"]["top1_rate"] == pytest.approx(1 / 3)
    d = C.derive_costs(st)
    assert d.costs.shape == (4,)


@pytest.mark.parametrize("record,field", [
    ({"priors": [{"cue": "smell", "evidence": "x", "importance": 0.5, "gain": "high"}]}, "cue"),
    ({"priors": [{"cue": "color", "evidence": "x", "importance": 1.5, "gain": "high"}]}, "importance"),
    ({"priors": [{"cue": "color", "evidence": "x", "importance": 0.5, "gain": "huge"}]}, "gain"),
    ({"priors": [], "rank": "color"}, "rank"),
])
def test_bad_annotation_records(tmp_path, record, field):
    with pytest.raises(InputError, match=f"line 2.*{field}"):
        C.statistics_from_annotations(_write(tmp_path / "bad.jsonl", [{"priors": []}, record]))


def test_bad_inputs(tmp_path):
    (tmp_path / "broken.jsonl").write_text('{"priors": [}\n')
    with pytest.raises(InputError, match="line 1"):
        C.statistics_from_annotations(tmp_path / "broken.jsonl")
    (tmp_path / "empty.jsonl").write_text("\n")
    with pytest.raises(InputError, match="no annotation records"):
        C.statistics_from_annotations(tmp_path / "empty.jsonl")
    with pytest.raises(ConfigError, match="lambdas"):
        C.derive_costs(lambdas=(0, 0, 0))
    with pytest.raises(ConfigError, match="assumption"):
        C.published_statistics("guess")
