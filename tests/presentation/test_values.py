"""The one formatter of metric values and limits: the terminal/JSON text and the report's text of the same numbers."""

from compliance.presentation.values import OPEN_LIMIT, band_pct_text, limit_as_written, metric_text, resolved_limit, row_texts

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


def test_a_failing_value_never_prints_as_its_limit():
    # IEEE125-NOFASTER at the 5.7 kN set-up load of plant A: 32.007 mm/s against <= 32.0 mm/s (the run's figure)
    row = {"value": 0.032007422987028356, "limit": [0.032], "comparator": "<=", "status": "fail",
           "margin": -7.422987e-6, "margin_pct": -0.0232}
    texts = row_texts(row, "stroke_speed", unicode=False)
    assert texts["value"] == "32.01 mm/s" and texts["limit"] == "32.0 mm/s"
    assert float(texts["value"].split()[0]) > 32.0  # read back, the printed value fails as the row does
    assert texts["margin"] == "-0.0074 mm/s"  # below the 0.01 mm/s resolution, still negative
    assert texts["margin_pct"] == "-0.023 %"  # not "-0.0 %"
    assert row_texts(row, "stroke_speed")["margin"] == "\u22120.0074 mm/s"
    # an uncertain row (its band straddles the limit) still prints its point value on the failing side
    assert row_texts(dict(row, status="uncertain"), "stroke_speed", unicode=False)["value"] == "32.01 mm/s"
    # a value 0.4 ms beyond a 0.25 s limit needs four digits; one far beyond keeps three
    tau = {"value": 0.2504, "limit": [0.1, 0.25], "comparator": "within", "status": "fail", "margin": -4e-4, "margin_pct": -0.16}
    assert row_texts(tau, "time_constant", unicode=False)["value"] == "0.2504 s"
    assert row_texts(dict(tau, value=0.273), "time_constant", unicode=False)["value"] == "0.273 s"
    # a passing value at a strict limit's rounding gets the digits that show it inside
    strict = {"value": 0.0319996, "limit": [0.032], "comparator": "<", "status": "pass", "margin": 4e-7, "margin_pct": 0.001}
    assert float(row_texts(strict, "stroke_speed", unicode=False)["value"].split()[0]) < 32.0


def test_a_printed_band_contains_the_point_margin():
    # a within limit: the margin peaks inside the value band, so the ends alone may miss the point margin
    assert band_pct_text({"margin_low_pct": 1.2, "margin_high_pct": 4.6}, 5.06) == "[+1..+6 %]"
    assert band_pct_text({"margin_low_pct": -27.6, "margin_high_pct": -26.2}, -27.4) == "[-28..-26 %]"
    assert band_pct_text({"margin_low_pct": -27.6, "margin_high_pct": -26.2}, -27.4, unicode=True) == "[\u221228..\u221226 %]"
    assert band_pct_text(None, 3.0) is None
