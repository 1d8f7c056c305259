"""check --linear: the report's linear section is computed for every operating point of the requirement set."""

from __future__ import annotations

from compliance.model.config import load_plant
from compliance.linear.operating_points import linear_for_campaign
from compliance.requirements.loading import load_requirements


def test_linear_for_campaign_covers_the_operating_points():
    cfg = load_plant("plant-a")
    rs = load_requirements("shpp-400kw")
    lin = linear_for_campaign(cfg, rs, with_map=False)
    assert lin["schema"] == "govcheck-linear/1"
    names = {a["requirement_operating_point"] for a in lin["analyses"]}
    with_position = {n for n, op in rs.operating_points.items() if op.initial_position is not None}
    assert names and names <= with_position
    for a in lin["analyses"]:
        # the linear time constant of plant A sits in the tens to hundreds of ms (docs/linear.md)
        assert 0.01 < a["figures"]["time_constant"] < 1.0
    assert lin["governor"] and lin["crosscheck"]


def test_state_feedback_plant_gets_a_note_not_an_error():
    cfg = load_plant("plant-b")
    rs = load_requirements("tracking-robot")
    lin = linear_for_campaign(cfg, rs)
    assert lin["analyses"] == [] and "state_feedback" in lin["notes"][0]
