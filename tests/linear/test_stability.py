"""The loop's stability margins on page 1: plant A's linearised loop against govcheck's 30 deg / 6 dB criterion.

At the 16 mm points of critical region 1 (+/-2.3 kN) plant A's loop has a phase margin near 21 deg and a gain
margin near 5.1 dB (``govcheck linear``); with the 5.7 kN set-up load at mid stroke about 28 deg / 6.5 dB. All
are below the criterion; the points the throttles alone tell apart are one point (no flow passes them at rest).
"""

from __future__ import annotations

import pytest

from compliance.linear.stability import MARGIN_CRITERION, stability_margins
from compliance.model.config import load_plant
from compliance.requirements.loading import load_requirements

REQ = """
schema = "govcheck-requirements/1"
name = "two-points"
[operating_points.region1-closing]
initial_position = "16 mm"
load = "2.3 kN"
flow_control = true
[operating_points.tc-region1-closing]
initial_position = "16 mm"
load = "2.3 kN"
flow_control = false
[operating_points.governor-setup]
initial_position = "50 %stroke"
load = "5.7 kN"
[procedures.s]
kind = "steps"
size = "5 %stroke"
[requirements.R]
title = "time constant"
clause = "clause unknown"
metric = "time_constant"
comparator = "<="
limit = "0.25 s"
procedures = ["s"]
operating_points = ["region1-closing", "tc-region1-closing", "governor-setup"]
"""


@pytest.fixture(scope="module")
def margins(tmp_path_factory):
    p = tmp_path_factory.mktemp("req") / "two.toml"
    p.write_text(REQ)
    cfg, reqset = load_plant("plant-a"), load_requirements(p)
    return cfg, reqset, stability_margins(cfg, reqset, workers=1)


def test_plant_a_margins_are_below_govchecks_criterion(margins):
    _, _, st = margins
    assert st["criterion"]["phase_margin_deg"] == MARGIN_CRITERION["phase_margin_deg"] == 30.0
    assert "govcheck's own criterion" in st["criterion"]["basis"]
    pts = {tuple(p["operating_points"]): p for p in st["points"]}
    assert set(pts) == {("region1-closing", "tc-region1-closing"), ("governor-setup",)}
    r1 = pts[("region1-closing", "tc-region1-closing")]
    assert r1["phase_margin_deg"] == pytest.approx(21.4, abs=1.0) and r1["gain_margin_db"] == pytest.approx(5.1, abs=0.3)
    assert r1["stable"] and r1["meets"] is False
    assert pts[("governor-setup",)]["phase_margin_deg"] == pytest.approx(27.8, abs=1.0)
    assert set(st["below"]) == {"region1-closing", "tc-region1-closing", "governor-setup"}
    assert st["summary"].startswith("phase margin 21\u201328\u00b0") and "2 of 2 operating points below" in st["summary"]


def test_linear_analyses_already_made_are_reused(margins):
    cfg, reqset, st = margins
    made = [{"requirement_operating_point": "governor-setup",
             "figures": {"phase_margin_deg": 45.0, "gain_margin_db": 9.0, "stable": True}}]
    again = stability_margins(cfg, reqset, analyses=made)
    by = {tuple(p["operating_points"]): p for p in again["points"]}
    assert by[("governor-setup",)]["meets"] is True and by[("governor-setup",)]["phase_margin_deg"] == 45.0
    assert by[("region1-closing", "tc-region1-closing")]["reason"] == "not linearised"  # not in the analyses given


def test_a_state_feedback_plant_is_not_analysed_and_says_why(margins):
    _, reqset, _ = margins
    st = stability_margins(load_plant("plant-b"), reqset)
    assert st["points"] == [] and "cover the PID only" in st["summary"] and st["summary"].startswith("not analysed")
