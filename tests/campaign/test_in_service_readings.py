"""The in-service readings: the evaluation rule, and INDEP modelled through the set-point rate limiter.

The limiter of the PID governor sets the rate of a full stroke (IEEE PES TR 2013 gate-rate limits, one
per direction). Halving the opening rate doubles the full-rate opening time (the gate follows the ramp:
adjusted change (2T - T) / T = 100 %, within the few per cent the gate lags the ramp by) and leaves the
closing stroke alone: the cross change is the model's prediction, not a missing-physics zero.
"""

import pytest

from compliance.campaign.judge import evaluated_status
from compliance.campaign.run import run_campaign
from compliance.model.config import load_plant
from compliance.requirements.loading import load_requirements
from compliance.requirements.verdict import Status, Verdict

REQ = """
schema = "govcheck-requirements/1"
name = "indep"
[operating_points.dewatered]
initial_position = "50 %stroke"
load = "none"
flow_control = true
[procedures.adjust]
kind = "independent_adjustment"
adjust = ["opening"]
[requirements.INDEP]
title = "independent adjustment"
clause = "clause unknown"
metric = "cross_adjustment_change"
comparator = "<="
limit = "5 %"
procedures = ["adjust"]
operating_points = ["dewatered"]
[requirements.ACTS]
title = "the adjustment acts"
clause = "clause unknown"
metric = "adjusted_time_change"
comparator = ">="
limit = "10 %"
procedures = ["adjust"]
operating_points = ["dewatered"]
"""


@pytest.fixture(scope="module")
def reqset(tmp_path_factory):
    p = tmp_path_factory.mktemp("indep") / "indep.toml"
    p.write_text(REQ)
    return load_requirements(p)


def test_indep_is_modelled_through_the_limiter_rates(reqset):
    a = load_plant("plant-a")
    c = a.params["valve.sonic_conductance"]
    cfg = a.replace(params={"controller.setpoint_opening_rate": 0.0317, "controller.setpoint_closing_rate": 0.0317,
                            "controller.setpoint_lead_limit": 0.0128,
                            "flow_control.opening_conductance": 2 * c, "flow_control.closing_conductance": 2 * c})
    res = run_campaign(cfg, reqset, workers=1, progress=False)
    ent = {e["id"]: e for e in res["requirements"]}
    indep, acts = ent["INDEP"]["rows"][0], ent["ACTS"]["rows"][0]
    detail = indep["samples"][0]["detail"]
    assert detail["device"] == "limiter" and detail["parameter"] == "controller.setpoint_opening_rate"
    assert indep["value"] < 0.01 and indep["basis"] == "modelled" and "rate limiter" in indep["basis_reason"]
    assert acts["value"] == pytest.approx(1.0, abs=0.1)
    # without a limiter the throttle is the device, and with an ideal supply its cross change is by construction
    res = run_campaign(a, reqset, workers=1, progress=False)
    row = {e["id"]: e for e in res["requirements"]}["INDEP"]["rows"][0]
    assert row["samples"][0]["detail"]["device"] == "throttle" and row["basis"] == "by_construction"


def _row(op, status, excluded=None, extended=False):
    return {"operating_point": op, "status": status, "excluded": excluded, "extended": extended}


def _v(status):
    return Verdict(None, "within", (0.1, 0.25), None, None, status)


def test_evaluation_rule():
    P, F, N = Status.PASS, Status.FAIL, Status.NOT_EVALUATED
    req = None
    # every point has an evaluated case and the rest are excluded by a rule: evaluated
    rows = [_row("a", P), _row("a", N, "saturated"), _row("b", P), _row("b", N, "dead-zone dominated")]
    assert evaluated_status(req, rows, [_v(r["status"]) for r in rows]) == P
    # a point with only excluded cases: not evaluated
    rows = [_row("a", P), _row("b", N, "saturated")]
    assert evaluated_status(req, rows, [_v(r["status"]) for r in rows]) == N
    # a case that could not be measured (no rule excluded it): not evaluated
    rows = [_row("a", P), _row("a", N)]
    assert evaluated_status(req, rows, [_v(r["status"]) for r in rows]) == N
    # any evaluated failure fails, whatever else
    rows = [_row("a", F), _row("b", N)]
    assert evaluated_status(req, rows, [_v(r["status"]) for r in rows]) == F
    # extended rows (other points) do not count towards the listed points
    rows = [_row("a", P), _row("b", N, "saturated"), _row("b", P, extended=True)]
    assert evaluated_status(req, rows, [_v(r["status"]) for r in rows]) == N
