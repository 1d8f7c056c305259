"""The gate hole of issue 16: a mandatory requirement that becomes unmeasurable must trip the gate."""

from __future__ import annotations

from compliance.campaign.regression_gate import compare, gate_markdown, gate_table
from tests.results.build import result, verdict

RATE_LIMITED = "rate limited: valve command reached 6.85 V >= flow saturation 4.00 V before 63.2 %"


def entry(rid, status, margin_pct=None, severity="mandatory", reason=None):
    return verdict(rid, status, margin_pct, 0.2, metric="time_constant", limit_text="0.10 s .. 0.25 s", severity=severity,
                   reasons=(reason,) if reason else (), display="0.2 s")


def results(*entries):
    return result(*entries, digest="d", status="fail")


def test_mandatory_fail_to_not_evaluated_trips_with_the_reason():
    base = results(entry("IEC61362-TC", "fail", -10.0))
    cand = results(entry("IEC61362-TC", "not_evaluated", reason=RATE_LIMITED))
    g = compare(base, cand)
    assert g["status"] == "fail" and g["tripped"] == ["IEC61362-TC"]
    row = g["rows"][0]
    assert row["not_evaluated_reason"] == RATE_LIMITED
    assert "fail -> not_evaluated" in row["reasons"][0] and RATE_LIMITED in row["reasons"][0]
    md = gate_markdown(g)
    assert "**tripped**: fail -> not_evaluated: could not be evaluated: rate limited" in md
    assert "TRIPPED" in gate_table(g)


def test_allowed_explicitly_passes_and_still_says_why():
    base = results(entry("IEC61362-TC", "fail", -10.0))
    cand = results(entry("IEC61362-TC", "not_evaluated", reason=RATE_LIMITED))
    g = compare(base, cand, allow_not_evaluated=["IEC61362-TC"])
    assert g["status"] == "pass" and g["allow_not_evaluated"] == ["IEC61362-TC"]
    md = gate_markdown(g)
    assert "allowed: fail -> not_evaluated allowed explicitly (--allow-not-evaluated IEC61362-TC)" in md
    assert RATE_LIMITED in md


def test_not_evaluated_in_both_or_advisory_fail_does_not_trip():
    both = compare(results(entry("A", "not_evaluated", reason="x")), results(entry("A", "not_evaluated", reason="y")))
    assert both["status"] == "pass" and "(not evaluated: y)" in gate_table(both)
    advisory = compare(results(entry("B", "fail", -3.0, severity="advisory")),
                       results(entry("B", "not_evaluated", severity="advisory", reason="z")))
    assert advisory["status"] == "pass"


def test_unknown_allowance_is_noted():
    g = compare(results(entry("A", "pass", 5.0)), results(entry("A", "pass", 5.0)), allow_not_evaluated=["NOPE"])
    assert any("NOPE" in n for n in g["notes"])
