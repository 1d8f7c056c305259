"""What the remedies summaries print: no point of a Pareto front from a case not evaluated, no empty
change table, margins with the report's formatter (capped, a minus sign U+2212), units typeset."""

from __future__ import annotations

import pandas as pd

from compliance.sweep.candidates.results import pareto_front
from compliance.report.render import section_page as section_html
from compliance.sweep.summary_text import remedies_markdown


def test_a_not_evaluated_margin_is_no_point_of_the_pareto_front():
    df = pd.DataFrame({"candidate": [0, 1, 2],
                       "A.margin_pct": [-10.0, -20.0, 50.0], "A.status": ["fail", "fail", "not_evaluated"],
                       "B.margin_pct": [-30.0, -5.0, 50.0], "B.status": ["fail", "fail", "pass"]})
    # candidate 2 would dominate both if its not-evaluated margin of A counted
    assert pareto_front(df, "A", "B") == [0, 1]


def _closest(changes):
    return {"status": "none_found", "note": "no candidate passes", "evaluated": 3,
            "sensitivities": [{"requirement": "IEC61362-TCLOSE", "margin_pct": -419.3,
                               "by_parameter": [{"path": "flow_control.closing_conductance", "step": 4.6e-10,
                                                 "unit": "m^3/(s*Pa)", "delta_margin_pct": -4.3}]}],
            "closest": {"changes": changes, "change": 0.0, "binding": "IEC61362-TCLOSE", "binding_margin_pct": -27.4,
                        "failed_mandatory": ["IEC61362-TCLOSE"]}}


def test_the_configuration_as_given_is_a_sentence_not_an_empty_table():
    md = remedies_markdown(_closest([]))
    assert "| parameter | from | to |" not in md and "the configuration as given" in md
    html = section_html("t", remedies=_closest([]))
    assert "Change to</th>" not in html and "the configuration as given" in html


def test_remedies_margins_and_units_are_typeset():
    rem = _closest([{"path": "air.supply_pressure", "from": 8e5, "to": 9.2e5, "unit": "Pa"}])
    html = section_html("t", remedies=rem)
    md = remedies_markdown(rem)
    for text in (html, md):
        assert "-419.3" not in text and "far beyond (" in text and "\u2212100 %)" in text  # capped, minus sign
        assert "\u221227.4 %" in text and "-27.4" not in text
        assert "m^3/(s*Pa)" not in text and "8e+05" not in text and "800 kPa" in text
    assert "\u22124.3" in html and "m³/(s·Pa)" in html


def test_a_plant_that_passes_gets_no_closest_candidate():
    """'nothing to change' is the whole answer: no 'closest candidate (does not pass)' after it."""
    rem = {"status": "already_passes", "note": "every mandatory requirement passes as configured: nothing to change",
           "evaluated": 1, "sensitivities": [], "remedy": None,
           "closest": {"changes": [], "change": 0.0, "binding": "TC", "binding_margin_pct": 12.0, "failed_mandatory": []}}
    for text in (remedies_markdown(rem), section_html("t", remedies=rem)):
        assert "nothing to change" in text
        assert "does not pass" not in text and "Closest candidate" not in text
