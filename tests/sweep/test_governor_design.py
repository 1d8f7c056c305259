"""The governor design shared by ``size`` and ``--remedies``: its rules with real numbers, without a long search.

- limiter rates: 0.99 x min(L / T_low, v_limit) = 0.99 x min(160 mm / 4.75 s, 32 mm/s) = 31.68 mm/s;
- the load's share of the cylinders' force: 12 kN / (A (p_s - p_atm)), A = A_cap + A_rod of the tandem pair:
  2 x 125/32 mm at 8 bar abs: 0.72; 2 x 160/40 mm: 0.44; 9 bar gauge: 0.56 (what the remedies stage ranks on);
- corrections: a stroke time off its window scales its direction's rate by T / T_mid, capped at the limit;
  a positioning error narrows the dead-zone inverse's smoothing width by 0.6;
- the size iteration: the next ISO 15552 pair up when a check asks for a lower load share.
"""

import math

import pytest

from compliance.model.config import load_plant
from compliance.requirements.loading import load_requirements
from compliance.sweep.remedies.governor_stage import load_share
from compliance.sweep.sizing.governor_design import LC_FACTOR, RATE_SHARE, TAU_MARGIN, corrections, limiter_settings
from compliance.sweep.sizing.size_servo import size_cylinders


@pytest.fixture(scope="module")
def shpp():
    return load_requirements("shpp-400kw")


def test_limiter_rates_and_backstop(shpp):
    cfg = load_plant("plant-a")
    values, why = limiter_settings(cfg, shpp)
    rate = RATE_SHARE * min(0.160 / 4.75, 0.032)
    assert values["controller.setpoint_opening_rate"] == pytest.approx(rate) == pytest.approx(0.03168)
    assert values["controller.setpoint_closing_rate"] == pytest.approx(rate)
    assert values["controller.setpoint_lead_limit"] == pytest.approx(0.04 * 0.160)  # 6.4 mm ramp hold
    c = cfg.params["valve.sonic_conductance"]
    assert values["flow_control.opening_conductance"] == pytest.approx(2 * c)
    # the series exhaust path keeps 1 / sqrt(1 + 1/4) of the valve's conductance (ISO 6358 series rule)
    assert 1 / math.sqrt(1 / c ** 2 + 1 / (2 * c) ** 2) == pytest.approx(0.894 * c, rel=1e-3)
    # a file without stroke times or a stroke-rate limit sets no limiter
    from tests.sweep.conftest import SMALL_TC

    assert limiter_settings(cfg, load_requirements(SMALL_TC))[0] == {}


def test_load_share_ranks_the_catalogue(shpp):
    cfg = load_plant("plant-a")
    area = math.pi / 4 * (2 * 0.125 ** 2 - 0.032 ** 2)
    assert load_share(cfg, shpp) == pytest.approx(12e3 / (area * (8e5 - 1.013e5)), rel=1e-3) == pytest.approx(0.72, abs=0.005)
    big = cfg.replace(params={"cylinder.piston_diameter": 0.160, "cylinder.rod_diameter": 0.040})
    assert load_share(big, shpp) == pytest.approx(0.44, abs=0.005)
    high = cfg.replace(params={"air.supply_pressure": 9e5 + 1.013e5})
    assert load_share(high, shpp) == pytest.approx(12e3 / (area * 9e5), rel=1e-3) == pytest.approx(0.56, abs=0.005)


def _results(entries):
    return {"requirements": entries}


def _entry(rid, metric, value, limit, which="", op="in-service"):
    return {"id": rid, "metric": metric, "severity": "mandatory", "status": "fail", "limit": limit,
            "worst": {"value": value, "which": which, "operating_point": op, "run": f"full-stroke@{op}"}}


def test_corrections(shpp):
    cfg = load_plant("plant-a").replace(params={"controller.setpoint_opening_rate": 0.0310,
                                                "controller.setpoint_closing_rate": 0.0310})
    # a 5.26 s opening against 4.75-5.25 s (5.00-5.25 s with the 32 mm/s rate limit): the rate scales by
    # 5.26 / 5.125 and is capped at 0.99 x 32 mm/s
    new, why = corrections(cfg, shpp, _results([_entry("IEC61362-TOPEN", "opening_time", 5.26, [4.75, 5.25], "opening")]))
    assert new == {"controller.setpoint_opening_rate": pytest.approx(min(0.0310 * 5.26 / 5.125, RATE_SHARE * 0.032))}
    new, _ = corrections(cfg, shpp, _results([_entry("IEC61362-TCLOSE", "closing_time", 5.20, [4.75, 5.25], "closing")]))
    assert new["controller.setpoint_closing_rate"] == pytest.approx(0.0310 * 5.20 / 5.125)
    new, why = corrections(cfg, shpp, _results([_entry("SHPP-TRACK", "tracking_max_error", 2.2e-3, [1.6e-3])]))
    assert new == {"controller.compensation_width": pytest.approx(LC_FACTOR * 0.4)} and "stall band" in why[0]


def test_spread_limit_and_next_cylinders():
    # the window 0.10-0.25 s with 15 % clear at each end holds at most 0.25 x 0.85 / (0.10 x 1.15) = 1.85:1
    assert 0.25 * (1 - TAU_MARGIN) / (0.10 * (1 + TAU_MARGIN)) == pytest.approx(1.848, abs=1e-3)
    first = size_cylinders(12e3, 8e5, 1.013e5)
    assert (first["bore"], first["rod"]) == (0.125, 0.032)
    nxt = size_cylinders(12e3, 8e5, 1.013e5, min_area=first["area"], count=first["count"])
    assert (nxt["bore"], nxt["rod"], nxt["count"]) == (0.160, 0.040, 2) and nxt["load_ratio"] == pytest.approx(0.44, abs=0.005)
