"""Verdict arithmetic: margins, the limit itself, converted units, aggregation."""

import pytest

from compliance.requirements.loading import parse_amount
from compliance.requirements.verdict import (
    Status,
    evaluate,
    overall_status,
    requirement_status,
    worst_index,
)

STROKE = 0.160  # plant A [m]


def test_at_the_limit_inclusive_and_strict():
    v = evaluate(0.25, "<=", 0.25)
    assert v.status == Status.PASS and v.margin == 0.0 and v.margin_pct == 0.0
    assert evaluate(0.25, "<", 0.25).status == Status.FAIL
    assert evaluate(0.10, ">=", 0.10).status == Status.PASS
    assert evaluate(0.10, ">", 0.10).status == Status.FAIL
    assert evaluate(0.10, "within", (0.10, 0.25)).status == Status.PASS
    assert evaluate(0.25, "within", (0.10, 0.25)).status == Status.PASS


def test_units_converted_on_both_sides_meet_exactly():
    # 1.6 mm measured against "1 %stroke" of a 160 mm stroke: equal up to float round-off
    value = parse_amount("1.6 mm", "m", "test").value
    limit = parse_amount("1 %stroke", "m", "test").resolve(STROKE)
    assert value == pytest.approx(limit, rel=1e-12)
    v = evaluate(value, "<=", limit)
    assert v.status == Status.PASS and v.margin == 0.0
    # and mm vs m: 0.0016 m against "1.6 mm"
    assert evaluate(0.0016, "<=", parse_amount("1.6 mm", "m", "t").value).status == Status.PASS
    # a speed in %stroke/s: 20 %stroke/s = 32 mm/s
    assert parse_amount("20 %stroke/s", "m/s", "t").resolve(STROKE) == pytest.approx(0.032)
    # just above the limit by a physically meaningful amount fails
    assert evaluate(0.00161, "<=", limit).status == Status.FAIL


def test_margins_in_units_and_percent():
    v = evaluate(0.0009, "<=", 0.0016)
    assert v.margin == pytest.approx(0.0007) and v.margin_pct == pytest.approx(43.75)
    v = evaluate(0.0020, "<=", 0.0016)
    assert v.status == Status.FAIL and v.margin == pytest.approx(-0.0004) and v.margin_pct == pytest.approx(-25.0)
    v = evaluate(0.15, ">=", 0.10)
    assert v.margin == pytest.approx(0.05) and v.margin_pct == pytest.approx(50.0)
    # within: nearer edge binds
    v = evaluate(0.20, "within", (0.10, 0.25))
    assert v.margin == pytest.approx(0.05) and v.margin_pct == pytest.approx(20.0)
    v = evaluate(0.08, "within", (0.10, 0.25))
    assert v.status == Status.FAIL and v.margin == pytest.approx(-0.02) and v.margin_pct == pytest.approx(-20.0)
    v = evaluate(0.30, "within", (0.10, 0.25))
    assert v.status == Status.FAIL and v.margin_pct == pytest.approx(-20.0)
    # zero limit: margin in units only
    v = evaluate(0.01, "<=", 0.0)
    assert v.margin == pytest.approx(-0.01) and v.margin_pct is None


def test_missing_value_is_not_evaluated():
    v = evaluate(None, "<=", 1.0, "stalled")
    assert v.status == Status.NOT_EVALUATED and v.reason == "stalled" and v.margin is None
    assert evaluate(float("nan"), "<=", 1.0).status == Status.NOT_EVALUATED


def test_bad_comparator_or_limit_shape():
    with pytest.raises(ValueError):
        evaluate(1.0, "==", 1.0)
    with pytest.raises(ValueError):
        evaluate(1.0, "within", 1.0)
    with pytest.raises(ValueError):
        evaluate(1.0, "within", (2.0, 1.0))


def test_worst_case_and_statuses():
    vs = [evaluate(0.2, "within", (0.1, 0.25)), evaluate(0.26, "within", (0.1, 0.25)),
          evaluate(0.30, "within", (0.1, 0.25)), evaluate(None, "within", (0.1, 0.25))]
    assert worst_index(vs) == 2  # the fail furthest out
    assert worst_index(vs[:1]) == 0
    assert worst_index(vs[3:]) is None
    assert requirement_status(vs) == Status.FAIL
    assert requirement_status([vs[0], vs[3]]) == Status.NOT_EVALUATED
    assert requirement_status(vs[:1]) == Status.PASS
    assert overall_status([("mandatory", Status.PASS), ("advisory", Status.FAIL)]) == "pass"
    assert overall_status([("mandatory", Status.PASS), ("mandatory", Status.NOT_EVALUATED)]) == "incomplete"
    assert overall_status([("mandatory", Status.FAIL), ("mandatory", Status.NOT_EVALUATED)]) == "fail"
