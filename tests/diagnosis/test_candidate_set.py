"""Candidate explanations as a type: parsed once from their canonical ``a+b+base`` name."""

from compliance.diagnosis.verdicts.candidate_set import BASE, CandidateSet


def test_name_round_trips_and_keeps_the_order_found():
    s = CandidateSet.parse("valve_dynamics+internal_leakage+base")
    assert s.terms == ("valve_dynamics", "internal_leakage", "base")
    assert s.name == str(s) == "valve_dynamics+internal_leakage+base"
    assert CandidateSet.of(["internal_leakage", "valve_dynamics"]).name == "internal_leakage+valve_dynamics"
    assert CandidateSet.parse(None).terms == () and CandidateSet.parse("").name == ""


def test_effects_are_the_declared_ones_only():
    s = CandidateSet.parse("valve_dynamics+base")
    assert s.effects == ["valve_dynamics"] and s.first == "valve_dynamics"
    assert CandidateSet.parse("nominal").effects == [] and CandidateSet.parse("instrument:logger_delay").effects == []


def test_same_physics_ignores_the_recalibration_and_the_order():
    a, b = CandidateSet.parse("valve_dynamics+internal_leakage"), CandidateSet.parse("internal_leakage+valve_dynamics+base")
    assert a.same_physics(b) and not a.same_physics(CandidateSet.parse("valve_dynamics"))
    assert CandidateSet.parse("valve_dynamics").plus(BASE).name == "valve_dynamics+base"


def test_nested_and_inside():
    one, two = CandidateSet.parse("valve_dynamics"), CandidateSet.parse("valve_dynamics+base")
    assert one.nested(two) and two.nested(one) and one.inside(two) and not two.inside(one) and not one.inside(one)
    assert not one.nested(CandidateSet.parse("internal_leakage"))
