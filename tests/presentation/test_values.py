"""The one formatter of metric values and limits: the terminal/JSON text and the report's text of the same numbers."""

from compliance.presentation.values import OPEN_LIMIT, limit_as_written, metric_text, resolved_limit, row_texts

STROKE_LIMIT = {"limit_text": "<= 1 %stroke", "limit_display": "<= 1.60 mm", "limit": [0.0016]}  # plant A: 160 mm stroke


def test_a_metric_value_in_its_display_unit_with_three_digits():
    assert metric_text(0.0016, "max_positioning_error") == "1.60 mm"  # m -> mm, trailing zero says the precision
    assert metric_text(-0.0016, "max_positioning_error", unicode=False) == "-1.60 mm"
    assert metric_text(-0.0016, "max_positioning_error") == "\u22121.60 mm"  # the report's typographic minus
    assert metric_text(None, "max_positioning_error", unicode=False) == "-"


def test_a_numerical_zero_reads_zero_everywhere():
    # 1e-13 m is 1e-10 mm: a body at rest in stiction, not a measurement below the 0.001 mm resolution
    assert metric_text(1e-13, "max_positioning_error") == metric_text(1e-13, "max_positioning_error", unicode=False) == "0 mm"
    assert metric_text(4e-7, "max_positioning_error") == "< 0.001 mm"  # 0.0004 mm: real, but below the resolution


def test_a_verdict_row_and_a_resolved_limit():
    row = {"value": 0.0012, "limit": [0.0016], "margin": 0.0004, "margin_pct": 25.0}
    assert row_texts(row, "max_positioning_error", unicode=False) == {
        "value": "1.20 mm", "limit": "1.60 mm", "margin": "0.400 mm", "margin_pct": "+25.0 %"}
    assert row_texts({"value": 0.0012}, "max_positioning_error")["limit"] is None  # an open limit
    assert resolved_limit("<=", [0.0016], "max_positioning_error") == "<= 1.60 mm"


def test_a_limit_as_written_with_its_resolved_value_beside_a_stroke_relative_one():
    assert limit_as_written(STROKE_LIMIT, unicode=False) == "<= 1 %stroke (1.60 mm)"
    assert limit_as_written(STROKE_LIMIT) == "\u2264 1 % stroke (1.60 mm)"
    absolute = {"limit_text": "within 0.1 s .. 0.25 s", "limit_display": "within 0.100 s .. 0.250 s", "limit": [0.1, 0.25]}
    assert limit_as_written(absolute, unicode=False) == "within 0.1 s .. 0.25 s"  # nothing to resolve: as written
    assert limit_as_written(absolute) == "within 0.1 s \u2013 0.25 s"
    assert limit_as_written({"limit_text": "open", "limit": None}) == OPEN_LIMIT
