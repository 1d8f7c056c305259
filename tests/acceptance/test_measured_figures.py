"""Measured figures of the practice site p2 against the emulator's noise-free truth, within their stated uncertainty.

The truth comes from the emulator's true piston position (no noise, no quantisation, no logger);
a measurement from the logged channels should land within its expanded uncertainty of it, and that
uncertainty within the acceptance tolerances (tau within 10 % or 5 ms, stroke times within 2 %,
drift within 0.1 mm).
"""

from __future__ import annotations

import pytest

from compliance.acceptance.measure.recording import measure_test
from compliance.acceptance.site.folder import read_site
from compliance.acceptance.site.prepared import prepare
from compliance.model.config import load_plant
from tests.acceptance.site_data import SITE, truth


@pytest.fixture(scope="module")
def measured():
    cfg = load_plant("plant-a")
    return {r.name: measure_test(prepare(r, cfg), cfg) for r in read_site(SITE)}


def _within(m, true, tolerance):
    assert m.value is not None, m.reason
    assert abs(m.value - true) <= m.u + 1e-12, f"{m.value} vs truth {true}: outside its uncertainty {m.u}"
    assert m.u <= tolerance, f"uncertainty {m.u} wider than the tolerance {tolerance}"


@pytest.mark.parametrize("name", ["steps_1-2pct_point2", "steps_5-10pct_point2"])
def test_time_constant_of_every_judged_step_lies_within_its_uncertainty(measured, name):
    steps = truth(name)["steps"]
    judged = 0
    for case, st in zip(measured[name], steps):
        tau = case.values["time_constant"]
        assert tau.eligible == st["tc_eligible"] or abs(st["size_pct"]) in (1,), (case.label, tau.reason)
        if st["tc_eligible"]:
            _within(tau, st["tau_cmd_s"], max(0.1 * st["tau_cmd_s"], 0.005))
            judged += 1
    assert judged == 2  # the 2 % (or 5 %) steps away from the operating position, both ways


def test_step_back_is_reported_not_judged(measured):
    back = [c for c in measured["steps_1-2pct_point2"] if c.conditions["role"] == "return"]
    assert len(back) == 4
    assert all(not c.values["time_constant"].eligible for c in back)
    assert all("towards the operating position" in (c.values["time_constant"].reason or "")
               or "not reached" in (c.values["time_constant"].reason or "") for c in back)


def test_closing_stroke_time_speed_and_start_delay(measured):
    (case,) = measured["stroke_closing_12kN"]
    t = truth("stroke_closing_12kN")
    _within(case.values["closing_time"], t["T2575x2_s"], 0.02 * t["T2575x2_s"])
    _within(case.values["stroke_speed"], t["v_mean_mps"], 0.02 * t["v_mean_mps"])
    _within(case.values["start_delay"], t["start_delay_s"], 0.02 * t["start_delay_s"])
    _within(case.values["max_speed"], t["v_peak_mps"], 0.05 * t["v_peak_mps"])
    assert case.departures == ()  # open loop at full command from the open end stop: the standard stroke


@pytest.mark.parametrize("name", ["hold_1", "hold_2"])
def test_hold_drift_with_the_valve_at_null(measured, name):
    (case,) = measured[name]
    t = truth(name)
    assert case.conditions["loop"] == "open"
    _within(case.values["drift"], t["drift_fit_m"], 1e-4)
    _within(case.values["drift_excursion"], t["drift_max_m"], 1e-4)
    assert case.values["max_positioning_error"].value is None  # a closed-loop figure: not measured by this test
    assert "loop was open" in case.values["max_positioning_error"].reason
