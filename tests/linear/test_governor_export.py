"""The governor-model export (compliance.linear.governor_model / governor_formats, `govcheck linear --governor`)."""

from __future__ import annotations

import json

import pytest

from compliance.cli import main
from compliance.linear.governor_formats import HYGOV_DYR_ORDER
from compliance.model.config import load_plant


@pytest.fixture(scope="module")
def gov():
    from compliance.linear.governor_model import governor_parameters

    return governor_parameters(load_plant("plant-a"))


def test_rates_from_rest_are_faster_than_strokes_from_the_end_stop(gov):
    """Same throttles, same load curve: from rest the exhaust side starts at its rest pressure (about
    (p_s + p_atm)/2 +/- the load) instead of atmosphere, so the gate crosses 25-75 % faster."""
    ends = {m["direction"]: m["rate_pu_per_s"] for m in gov.end_stop}
    assert gov.UO > 1.3 * ends["opening"] and -gov.UC > 1.3 * ends["closing"]
    assert all(m["from"] == "rest" for m in gov.moves) and all(m["from"] == "end stop" for m in gov.end_stop)
    # the lower starts open, the upper ones close, each across the whole 25-75 % span
    assert all(m["start_pu"] <= 0.25 for m in gov.moves if m["direction"] == "opening")
    assert all(m["start_pu"] >= 0.75 for m in gov.moves if m["direction"] == "closing")
    s = gov.servo()
    assert s["UO_peak"] > s["UO"] and s["UC_peak"] < s["UC"] < 0  # the start-of-move surge, beside the 25-75 % rate
    assert gov.VELM == max(gov.UO, -gov.UC)


def test_tg_is_measured_with_the_same_circuit_and_the_dead_time_subtracted(gov):
    assert gov.flow_control is True and gov.stroke_load == "curve"
    assert gov.point["position"] == pytest.approx(0.136, abs=1e-3) and gov.point["load"] == "curve"
    assert gov.point["load_force"] == pytest.approx(12000.0, rel=1e-3)  # nominal load on the curve
    for s in gov.steps:
        assert 0.005 < s["dead_time"] < 0.05 and not s["rate_limited"]
    assert gov.Tg == pytest.approx(sum(s["time_constant"] for s in gov.steps) / 2)
    # IEC 61362 window for the servo time constant; the nonlinear steps are slower than the linear model (friction)
    assert 0.15 < gov.Tg < 0.35 and gov.Tg > gov.Tg_linear
    # dead-zone steady error: the stall band of model.pid_controller.stall_error, 0.86/0.90 mm for plant A
    assert gov.steady_error["opening"] == pytest.approx(0.86e-3, abs=0.01e-3)


def test_json_states_every_basis_and_the_forms(gov):
    d = json.loads(gov.to_json())
    assert set(d["parameters"]) == {"Tg", "VELM", "GMAX", "GMIN"}
    assert d["rate_limits"]["UC"] < 0 and d["units"]["UC"].startswith("pu/s")
    assert "machine base" in d["conventions"]["base"] and "stroke" in d["conventions"]["gate_pu"]
    assert d["basis"]["circuit"].endswith("in") and d["basis"]["Tg_point"]["load"] == "curve"
    assert d["left_out"]["dead_time"]["value"] == pytest.approx(gov.dead_time)
    assert d["family"]["recommended"] == "HYGOV4" and "IEEEG3" in " ".join(d["family"]["notes"])
    assert d["HYGOV4"]["UO"] == pytest.approx(gov.UO) and d["HYGOV4"]["Tp"] == pytest.approx(gov.dead_time)
    assert d["andes"]["HYGOV"]["VELM"] == pytest.approx(gov.VELM)
    assert d["ieee_pes_tr_2013"]["U_C"] == pytest.approx(gov.UC)
    rec = d["psse_dyr"]["HYGOV"]
    head, comment = rec.split("/", 1)
    fields = head.split()
    assert fields[:3] == ["1", "'HYGOV'", "'1'"] and len(fields) == 3 + len(HYGOV_DYR_ORDER)
    values = dict(zip(HYGOV_DYR_ORDER, map(float, fields[3:])))
    assert values["Tg"] == pytest.approx(gov.Tg, rel=1e-5) and values["VELM"] == pytest.approx(gov.VELM, rel=1e-5)
    # every CON a number for the bare positioner (no placeholder left to replace by hand), its basis in the comment
    a = d["andes"]["HYGOV"]
    assert values["R"] == pytest.approx(a["R"]) and values["r"] == pytest.approx(a["r"]) and values["qNL"] == 0.0
    assert values["R"] == pytest.approx(100.0) and values["At"] == pytest.approx(1.0)  # Tn = Sb, dispatch = Tn x gate
    assert "MBASE 100 MVA" in comment and "transparent" in comment


def test_andes_settings_are_numbers_on_the_machine_base_with_their_basis(gov):
    a = gov.andes(rating_mva=50.0, system_mva=100.0, dispatch_mw=90.0)
    h4 = a["HYGOV4"]
    assert all(isinstance(v, float) for v in h4.values())
    assert h4["Tn"] == 50.0 and h4["Rperm"] == pytest.approx(0.5) and h4["Hdam"] == pytest.approx(2.0)
    assert h4["Rtemp"] == 0.0 and h4["qNL"] == 0.0
    x0 = gov.point["position"] / gov.stroke
    assert a["gate0"] == pytest.approx(x0) and h4["At"] == pytest.approx((90.0 / 50.0) / x0)  # gate starts at x0
    assert a["setpoint"]["HYGOV4"] == pytest.approx(0.5) and a["gate_output"]["per_pu_gate"] == pytest.approx(0.5)
    assert a["HYGOV"]["R"] == pytest.approx(50.0) and a["setpoint"]["HYGOV"] == pytest.approx(50.0)
    assert set(a["basis"]) >= {"Tn", "Sb", "Rperm", "Rtemp", "Hdam", "At", "qNL", "HYGOV_R", "HYGOV_r"}


def test_cli_header_is_the_governor_operating_point(tmp_path, capsys):
    out = tmp_path / "hygov.json"
    assert main(["linear", "plant-a", "--governor", "--governor-json", str(out)]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert "136.0 mm" in first and "curve" in first and "flow-control valves in" in first
    d = json.loads(out.read_text())
    assert d["basis"]["Tg_point"]["position"] == pytest.approx(0.136, abs=1e-3)
    assert d["Tg_linear"] is not None and d["parameters"]["Tg"] > d["Tg_linear"]


def test_cli_bad_stroke_load_is_refused_before_work(tmp_path, capsys):
    out = tmp_path / "hygov.json"
    assert main(["linear", "plant-a", "--governor", "--stroke-load", "lots", "--governor-json", str(out)]) == 2
    assert "--stroke-load" in capsys.readouterr().err and not out.exists()
