"""Commissioned settings: the loop gain made again by measurement at each end of a declared range.

Small case: plant A's time constant on 5 % steps up and down at mid stroke, no load, limiting devices
not acting, against the 0.10-0.25 s window; one declared range, the valve's saturation voltage 3-5 V
(the paper gives no opening curve). The valve opens linearly from its dead zone dz ~ 0.65 V to fully
open at U_sat, so its flow gain per volt is ~ 1 / (U_sat - dz) and the loop's time constant ~ (U_sat -
dz) / K_P (type-1 loop, piston integrating the flow). Commissioning K_P on the measured steps must
therefore give K_P(3 V) / K_P(5 V) ~ (3 - dz) / (5 - dz) = 0.54, and put every commissioned plant's
range at the window's centre, so a band that straddles the window with the paper's K_P on all plants
no longer does once each plant is commissioned.
"""

import dataclasses
import math
from types import MappingProxyType

import pytest

from compliance.campaign.commissioning import CENTRE_TOLERANCE, commission, tau_range
from compliance.campaign.run import run_campaign
from compliance.errors import InputError
from compliance.model.config import load_plant, plant_from_dict, plant_to_toml
from compliance.requirements.loading import load_requirements

REQ = """
schema = "govcheck-requirements/1"
name = "tau"
[operating_points.tc-mid]
initial_position = "50 %stroke"
load = "none"
flow_control = false
setpoint_limiter = false
[procedures.s5]
kind = "steps"
size = "5 %stroke"
pattern = ["up"]
[procedures.s5-down]
kind = "steps"
size = "5 %stroke"
pattern = ["down"]
[requirements.TC]
title = "time constant"
clause = "clause unknown"
metric = "time_constant"
comparator = "within"
limit = ["0.10 s", "0.25 s"]
options = { travel = "achieved" }
procedures = ["s5", "s5-down"]
operating_points = ["tc-mid"]
"""


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    cfg = load_plant("plant-a")
    keep = {"valve.saturation_voltage": cfg.assumptions["valve.saturation_voltage"]}
    cfg = dataclasses.replace(cfg, assumptions=MappingProxyType(keep))
    p = tmp_path_factory.mktemp("req") / "tau.toml"
    p.write_text(REQ)
    return cfg, load_requirements(p)


def _centre(t):
    vals = [v for d in ("up", "down") if t[d] for v in t[d]]
    return math.sqrt(min(vals) * max(vals))


def test_loop_gain_follows_the_valve_opening_curve(case):
    cfg, reqset = case
    kp, centres = {}, {}
    for u in (3.0, 5.0):
        done = commission(cfg.replace(params={"valve.saturation_voltage": u}), reqset, ["loop_gain"], workers=1)
        kp[u] = done.params["controller.kp"]
        centres[u] = _centre(tau_range(done, reqset, workers=1))
        # K_I, K_D and the dead-zone inverse's width follow K_P: the loop keeps its shape and its stall band in mm
        for k in ("controller.ki", "controller.kd", "controller.compensation_width"):
            assert done.params[k] / kp[u] == pytest.approx(cfg.params[k] / cfg.params["controller.kp"], rel=1e-9)
    window_centre = math.sqrt(0.10 * 0.25)
    for u in (3.0, 5.0):  # each commissioned plant's measured range sits at the window's centre
        assert abs(math.log(centres[u] / window_centre)) < CENTRE_TOLERANCE
    dz = 0.5 * (cfg.params["valve.dead_zone_positive"] + cfg.params["valve.dead_zone_negative"])
    # tau ~ (U_sat - dz) / K_P: the gain a 3 V valve takes against a 5 V one, within the small steps' dead-zone share
    assert kp[3.0] / kp[5.0] == pytest.approx((3.0 - dz) / (5.0 - dz), rel=0.2)


def test_bands_are_those_of_the_commissioned_machine(case):
    cfg, reqset = case
    raw = run_campaign(cfg, reqset, workers=1, progress=False, uncertainty="local")
    comm = run_campaign(cfg.with_commissioning(["loop_gain"]), reqset, workers=1, progress=False, uncertainty="local")
    b_raw, b_comm = raw["requirements"][0]["band"], comm["requirements"][0]["band"]
    # with the paper's K_P on every plant the valve's opening curve moves tau by about +/-25 %
    assert b_raw["high"] / b_raw["low"] > 1.3
    rec = comm["uncertainty"]["commissioning"]
    assert rec["settings"] == ["loop_gain"] and len(rec["corners"]) == 2 and not rec["failed"]
    lo, hi = rec["spans"]["controller.kp"]
    assert hi / lo > 1.45  # the gain moved with the valve: (5 - 0.65) / (3 - 0.65) = 1.85, within the 20 % above
    # each end commissioned to the window's centre: the band is narrower and inside the window
    assert (b_comm["high"] - b_comm["low"]) < 0.5 * (b_raw["high"] - b_raw["low"])
    assert 0.10 < b_comm["low"] and b_comm["high"] < 0.25
    assert "bands after commissioning" in comm["summary"]["commissioned"]
    assert "commissioned" not in raw["summary"]
    # a verdict on the test that sets the gain says what it shows: the adjustment reaches the window
    judged = [r for r in comm["requirements"][0]["rows"] if r.get("basis") == "modelled"]
    assert judged and all("sets loop_gain on site by this test" in r["basis_reason"] for r in judged)
    assert all("on site" not in (r.get("basis_reason") or "") for r in raw["requirements"][0]["rows"])


def test_commissioning_table_is_data(tmp_path):
    cfg = load_plant("plant-a").with_commissioning(["limiter_rates", "loop_gain"])
    assert cfg.commissioning == ("loop_gain", "limiter_rates")  # commissioning order: the gain first
    text = plant_to_toml(cfg)
    assert '[commissioning]\nsettings = ["loop_gain", "limiter_rates"]' in text
    import tomllib

    again = plant_from_dict(tomllib.loads(text), "<again>")
    assert again.commissioning == cfg.commissioning
    assert again.replace(params={"controller.kp": 100.0}).commissioning == cfg.commissioning  # a changed design keeps it
    data = tomllib.loads(text)
    data["commissioning"]["settings"] = ["loop_gian"]
    with pytest.raises(InputError, match="'loop_gian' is not a setting govcheck can commission.*loop_gain"):
        plant_from_dict(data, "p.toml")
    data["commissioning"] = {"setting": ["loop_gain"]}
    with pytest.raises(InputError, match="commissioning.setting: unknown key"):
        plant_from_dict(data, "p.toml")
