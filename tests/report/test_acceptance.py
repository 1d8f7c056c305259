"""The acceptance sections from the results alone: what the basis counts, the criterion, the disposition rows.

Numbers are plant A's (tests/data/results_fixture.json): the selected model uses the ISO 6358 valve
law, LuGre friction and a PID; the Sanville/Bobrow/power-law valve parameters, the piecewise
Stribeck friction of plant B and the state-feedback controller are not part of it.
"""

from __future__ import annotations

import json
from pathlib import Path

from compliance.report import acceptance as A
from compliance.report import signoff as S
from compliance.report.analysis_sections import distinct_points, linear_section
from compliance.report.fit_bounds import at_bound
from compliance.results import CheckResult
from compliance.presentation.numbers import fmt_si

FIXTURE = Path(__file__).resolve().parents[1] / "data" / "results_fixture.json"


def _results() -> dict:
    return json.loads(FIXTURE.read_text(encoding="utf-8"))


def _typed(res: dict) -> CheckResult:
    """The fixture, edited as a dict by a test, read as the report reads it."""
    return CheckResult.from_dict(res)


def test_basis_counts_only_the_parameters_the_selected_model_uses():
    res = _results()
    b = S.basis(_typed(res))
    keys = {p["key"] for p in res["plant"]["parameters"]}
    unused = {k for k in keys if not S.used_by_model(k, res["plant"]["options"])}
    # 12 parameters of laws plant A does not select: three valve laws (6), plant B's friction (4 + its
    # limit velocity, read only by the Karnopp forms), the state-feedback controller (5 listed in the table)
    assert {"valve.effective_area", "valve.bobrow_coefficient", "friction.breakaway_force",
            "controller.closed_loop_bandwidth", "friction.limit_velocity"} <= unused
    assert not unused & {"valve.sonic_conductance", "friction.static_force", "friction.bristle_stiffness", "controller.kp"}
    assert b["n_params"] == len(keys) - len(unused) and b["n_unused"] == len(unused)
    # what decides plant A's verdicts: its assumed friction values and the assumed load curve are named
    assert any(d.startswith("every friction value") and "bristle stiffness" in d for d in b["deciding"])


def test_deciding_parameters_of_verdict_bands_are_named_first():
    res = _results()
    res["requirements"][0]["band"] = {"low": 0.2, "high": 0.3, "deciding": ["friction.static_force", "load.curve"]}
    assert S.basis(_typed(res))["deciding"][:2] == ["friction.static_force", "load.curve"]


def test_linear_points_are_distinct_named_and_judged_against_the_stated_criterion():
    res = _typed(_results())
    lin = res.linear_section
    pts = distinct_points(lin.all_analyses, res)
    keys = [(round(a.operating_point.position, 6), str(a.operating_point.load)) for _, a, _ in pts]
    assert len(keys) == len(set(keys))
    ctx, _ = linear_section(lin, 1, res)
    assert ctx["criterion"]["pm"] == 30.0 and ctx["criterion"]["gm"] == 6.0
    for p in ctx["points"]:
        pm, gm = float(p["phase_margin"]), float(p["gain_margin"])
        assert p["stability"] == ("meets" if pm >= 30.0 and gm >= 6.0 else "below"), p
    # plant A's margins are 21-28 deg at most points: below a 30 deg criterion, never a bare PASS
    assert ctx["criterion"]["below"] >= 1


def test_conditions_define_every_operating_point_with_throttles_in_or_out():
    res = _results()
    cond = A.conditions(_typed(res))
    assert {r["name"] for r in cond["operating_points"]} == set(res["requirement_set"]["operating_points"])
    by = {r["name"]: r for r in cond["operating_points"]}
    for name, op in res["requirement_set"]["operating_points"].items():
        if op.get("flow_control") is not None:
            assert by[name]["throttles"] == ("in" if op["flow_control"] else "out")
    assert cond["supply"] == "8.00 bar abs"


def test_every_decision_needing_requirement_gets_a_disposition_row():
    res = _results()
    rows = A.conclusions(_typed(res))
    need = [e["id"] for e in res["requirements"] if e["status"] in ("fail", "not_evaluated", "open", "uncertain")]
    assert [r["id"] for r in rows] == need


def test_document_is_draft_without_identity_or_number():
    res = _results()
    assert S.document_control(_typed(res))["draft"]
    res["plant"]["identity"] = {"site": "x"}
    assert S.document_control(_typed(res))["draft_reason"].startswith("no document number")
    d = S.document_control(_typed(res), {"number": "QA-1", "revision": "B", "results": {"path": "r.json", "digest": "ab"}})
    assert not d["draft"] and d["revision"] == "B"
    files = {f["what"]: f for f in d["files"]}
    assert files["Results file"]["digest"] == "ab" and files["Plant configuration"]["digest"] == res["plant"]["digest"]
    assert "Recording" in files  # the fixture carries a validation: its recording is an input too


def test_si_prefixes_and_fit_bounds():
    assert fmt_si(1.66e-6, "N/Pa", 2.2e-7) == "1.66 \u00b1 0.22 \u00b5N/Pa"
    assert fmt_si(24337.0, "N/m") == "24.3 kN/m"
    assert fmt_si(0.93, "N") == "0.930 N"
    # the Zillen O-ring's Stribeck velocity ends on its 1e-4 m/s lower bound (standard error 3e-14 m/s)
    assert at_bound(1.0000041e-4, 1e-4, 0.05, True)
    assert not at_bound(4.7e-3, 1e-4, 0.05, True)
    assert at_bound(0.0, 0.0, 1000.0) and not at_bound(3.2, 0.0, 1000.0)


# --------------------------------------------------------------------------- issue 25: verdicts on assumptions
def _plant_b_like(res: dict, share_assumed: float, limits_assumed: bool = True) -> dict:
    """The fixture turned into a PASS against assumed targets with a given share of assumed parameters."""
    from compliance.campaign.basis import verdict_qualifier

    res["summary"].update(status="pass", failed_mandatory=[], qualifier=None)
    for e in res["requirements"]:
        e["status"], e["severity"], e["limit_assumed"] = "pass", "mandatory", limits_assumed
    used = [p for p in res["plant"]["parameters"] if S.used_by_model(p["key"], res["plant"]["options"])]
    n = round(share_assumed * len(used))
    for i, p in enumerate(used):
        p["source"] = "assumed" if i < n else "paper"
    res["summary"]["qualifier"] = verdict_qualifier(res)  # decided once, by the campaign, as check() does
    return res


def test_a_pass_against_assumed_targets_on_a_mostly_assumed_model_is_not_a_plain_pass():
    from compliance.campaign.results_files import summary_lines
    from compliance.results import Qualifier

    res = _typed(_plant_b_like(_results(), 0.8))
    assert res.summary.qualifiers == (Qualifier.ASSUMED_TARGETS, Qualifier.ASSUMED_MODEL)
    v = S.qualified_verdict(res)
    assert v["css"] == "warn" and v["qualifier"] == "against assumed targets, on a mostly assumed model"
    b = S.basis(res)
    assert f"{b['assumed']} of the {b['n_params']} parameters the model uses are assumed" in v["why"]
    assert "not figures of a standard or of the plant owner" in v["why"]
    assert summary_lines(res)[-1] == "VERDICT: PASS (against assumed targets, on a mostly assumed model)"
    # limits from a standard and a model mostly from the paper: a plain PASS
    res = _typed(_plant_b_like(_results(), 0.3, limits_assumed=False))
    assert not res.summary.qualifiers and S.qualified_verdict(res)["css"] is None
    assert summary_lines(res)[-1] == "VERDICT: PASS"
