"""Ranking that cannot make things worse, and a hardware remedy saved as a configuration check accepts."""

from __future__ import annotations

import json

import pandas as pd

import pytest

from compliance.cli import main
from compliance.model.config import load_plant
from compliance.sweep.candidates.ranking import candidate_passes, failing_mandatory, rank_key
from compliance.sweep.remedies.finish import _never_worse
from compliance.sweep.candidates.results import best_index

from tests.sweep.conftest import SMALL_TC, sweep_text


def _row(margins: dict, **extra) -> dict:
    reqs = {rid: {"severity": "mandatory", "status": "pass" if m >= 0 else "fail", "margin_pct": m} for rid, m in margins.items()}
    for rid, fields in extra.items():
        reqs[rid].update(fields)
    return {"status": "pass" if all(m >= 0 for m in margins.values()) else "fail", "requirements": reqs}


GIVEN = _row({"A": -80.0, "B": -50.0, "C": -30.0, "D": 10.0, "E": 10.0, "F": 10.0, "G": 10.0})  # fails 3, far off
SEVEN = _row({k: -1.0 for k in "ABCDEFG"})  # fails all 7, each by only 1 %: the old 'closest' by worst shortfall


def test_more_failing_requirements_never_rank_first():
    assert rank_key(GIVEN, 0.0) < rank_key(SEVEN, 0.0)
    df = pd.DataFrame({"candidate": [0, 1], "failing": [3.0, 7.0], "total_shortfall": [1.6, 0.07], "change": [0.0, 0.1],
                       "status": ["fail", "fail"], "shortfall": [0.8, 0.01]})
    assert best_index(df) == 0


def test_uncertain_and_by_construction_are_not_passes():
    row = _row({"A": 5.0, "B": 5.0}, A={"basis": "by_construction"})
    assert failing_mandatory(row) == ["A"] and not candidate_passes(row)
    row = _row({"A": 5.0})
    row["requirements"]["A"]["status"] = "uncertain"
    assert failing_mandatory(row) == ["A"]


def test_closest_worse_than_given_is_replaced_by_the_configuration_as_given():
    from compliance.sweep.remedies.smallest_change import describe_candidate

    rem = {"evaluated": 10, "closest": describe_candidate((), {}, {}, SEVEN)}
    given = {"row": GIVEN, "candidate": describe_candidate((), {}, {}, GIVEN)}
    _never_worse(rem, given)
    assert rem["closest"]["failed_mandatory"] == ["A", "B", "C"]
    assert "as given" in rem["closest"]["note"]


def test_hardware_remedy_is_saved_and_checks_clean(tmp_path, write_sweep, capsys):
    """Gains alone cannot reach the time constant (kp <= 260 V/m): a larger valve can; its file passes check."""
    sweep = write_sweep(sweep_text(adjust='[adjust."controller.kp"]\nrange = ["150 V/m", "260 V/m"]\n'))
    remedy, out = tmp_path / "remedy.toml", tmp_path / "r.json"
    code = main(["check", "plant-a", "-r", str(SMALL_TC), "--remedies", str(sweep), "--save-remedy", str(remedy),
                 "--yield-units", "4", "--json", str(out), "-j", "2", "-q"])
    assert code == 1  # the configuration as given still fails
    rem = json.loads(out.read_text())["remedies"]
    assert rem["status"] == "found" and rem["remedy"]["hardware"][0]["group"] == "servo_valve"
    assert rem["remedy"]["hardware_values"]["valve.sonic_conductance"] > 2.33e-8  # a larger valve than the 700 NL/min
    assert rem["tolerance_yield"]["units"] == 4 and 0.0 <= rem["tolerance_yield"]["lower_bound"] <= 1.0
    assert {n["option"] for n in rem["not_modelled"]} >= {"meter-in-throttles", "exhaust-back-pressure-valve"}
    # accepted unchanged, and passes at its values; it keeps plant A's declared ranges of the values it did not
    # change (its verdicts' bands), and drops the range of the valve conductance it changed
    assert main(["check", str(remedy), "-r", str(SMALL_TC), "-q", "--uncertainty", "0"]) == 0
    saved = load_plant(remedy)
    assert "valve.saturation_voltage" in saved.assumptions and "valve.sonic_conductance" not in saved.assumptions


def test_save_remedy_needs_remedies(tmp_path):
    assert main(["check", "plant-a", "-r", str(SMALL_TC), "--save-remedy", str(tmp_path / "x.toml")]) == 2
    assert not (tmp_path / "x.toml").exists()


def test_requirement_set_conflict_arithmetic_of_the_shipped_file():
    """shpp-400kw: tau <= 0.25 s on 16 mm steps needs a mean 40.5 mm/s > the 32 mm/s stroke rate limit; a rate limiter
    at 32 mm/s gives tau >= 0.316 s. The explanation is the consistency check's finding, not arithmetic of its own."""
    from compliance.model.config import load_plant
    from compliance.requirements.consistency import RATE_SPLIT
    from compliance.requirements.loading import load_requirements
    from compliance.sweep.remedies.binding_physics import explain_closest, set_findings

    reqset = load_requirements("shpp-400kw")
    found = {(f["procedure"], f["requirements"][1]): f for f in set_findings(reqset, 0.16, ["IEC61362-TC"])}
    f = found[("steps-10", "IEEE125-NOFASTER")]
    assert f["kind"] == RATE_SPLIT and f["mandatory"]
    assert f["mean_speed"] == pytest.approx(0.632 * 0.016 / 0.25, rel=1e-3) and f["v_max"] == pytest.approx(0.032)
    assert f["ramp_tau_min"] == pytest.approx(0.632 * 0.016 / 0.032, rel=1e-3)
    assert ("steps-5", "IEEE125-NOFASTER") not in found  # 0.632 x 8 mm / 0.25 s = 20.2 mm/s fits under 32 mm/s
    text = explain_closest({"failed_mandatory": ["IEC61362-TC"], "binding": "IEC61362-TC", "binding_where": "steps-10@tc-mid"},
                           load_plant("plant-a"), reqset, True)
    assert "0.316 s" in text and "steps-10" in text and "40.5 mm/s > 32.0 mm/s" in text


def test_explanation_names_a_pass_by_construction():
    """A closest candidate that fails only because a mandatory requirement passes by construction says so."""
    from compliance.model.config import load_plant
    from compliance.requirements.loading import load_requirements
    from compliance.sweep.remedies.binding_physics import explain_closest

    closest = {"failed_mandatory": ["IEC61362-INDEP"], "by_construction": ["IEC61362-INDEP"], "binding": "IEC61362-INDEP",
               "binding_where": "independent-adjustment@governor-setup"}
    text = explain_closest(closest, load_plant("plant-a"), load_requirements("shpp-400kw"), True)
    assert "IEC61362-INDEP pass only by construction" in text

def test_a_rate_limited_time_constant_is_explained_by_the_ramp():
    """With the set-point limiter at 31.2 mm/s a 16 mm step reaches 63.2 % no sooner than 0.632 x 16 / 31.2 = 0.324 s."""
    from compliance.model.config import load_plant
    from compliance.requirements.loading import load_requirements
    from compliance.sweep.remedies.binding_physics import explain

    cfg = load_plant("plant-a").replace(params={"controller.setpoint_opening_rate": 0.0312,
                                                "controller.setpoint_closing_rate": 0.0315})
    shpp = load_requirements("shpp-400kw")
    text = explain("IEC61362-TC", "steps-10@mid-no-load", cfg, shpp, True)  # a point where the limiter acts
    assert "0.324 s" in text and "31.2 mm/s" in text
    # at a tc-* point the step is injected downstream of the limiter: the ramp is not the explanation
    assert "ramps" not in explain("IEC61362-TC", "steps-10-down@tc-mid", cfg, shpp, True)
