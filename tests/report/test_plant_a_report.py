"""The plant-A report as the README's main command renders it: a body of at most BODY_PAGES_MAX (28) pages with every section.

Renders the real thing (``govcheck check models/plant-a.toml --requirements requirements/shpp-400kw.toml
--linear --pdf``, about 25 s on two idle cores once the simulator is compiled), so a section that
grows (a longer table, another figure) is caught here and not by the signer. The committed example
is held to the same limit by ``reports/examples/regenerate.py --check-only``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from compliance.cli import main
from compliance.report.layout_check import BODY_PAGES_MAX, body_pages, pdf_problems

ROOT = Path(__file__).resolve().parents[2]
pdfplumber = pytest.importorskip("pdfplumber")

# the sections of an acceptance-test report (issue 25), each in the body
SECTIONS = ("1. Scope, references and test object", "1.1 Scope", "1.2 Test object and identity",
            "2. Test conditions, instrumentation and method", "2.1 Operating points", "2.2 Instrumentation and method",
            "3. Results against the guarantees", "3.1 Departures from the test code", "3.2 Model assumptions",
            "3.3 Conditions not tested", "4. Evidence per requirement", "5. Linear analysis", "6. Model validation",
            "7. Conclusions, disposition, parties and revisions", "7.1 Conclusions and disposition",
            "7.2 Parties and witnesses", "7.3 Document control and revision history")


@pytest.fixture(scope="module")
def plant_a(tmp_path_factory):
    out = tmp_path_factory.mktemp("plant-a")
    code = main(["check", str(ROOT / "models/plant-a.toml"), "--requirements", str(ROOT / "requirements/shpp-400kw.toml"),
                 "--linear", "--pdf", str(out / "a.pdf"), "--json", str(out / "a.json"), "--quiet"])
    assert code == 1  # plant A fails five mandatory requirements, its stroke times in service (README)
    with pdfplumber.open(str(out / "a.pdf")) as pdf:
        pages = [p.extract_text() or "" for p in pdf.pages]
    return out / "a.pdf", pages, json.loads((out / "a.json").read_text())


@pytest.mark.slow
def test_plant_a_body_is_at_most_body_pages_max_with_every_section(plant_a):
    pdf, pages, _ = plant_a
    n = body_pages(pdf)
    assert n["body"] <= BODY_PAGES_MAX, f"plant-A body has {n['body']} pages (appendix {n['appendix']}, total {n['total']})"
    assert n["appendix"] > 0
    body = pages[:n["body"]]
    for heading in SECTIONS:
        assert any(re.search(rf"^\s*{re.escape(heading)}\s*$", p, re.M) for p in body), heading
    # no developer instruction in what the signer reads: no documentation path, TOML table or option
    assert not re.search(r"docs/|\[identity\]|\s--[a-z]", "\n".join(body))
    # no page of the body ends on a heading with nothing under it (the footer line "Page n of m" excepted)
    for i, p in enumerate(body, 1):
        lines = [ln for ln in p.splitlines() if ln.strip() and not re.search(r"Page \d+ of \d+\s*$", ln)]
        assert not re.match(r"^\d+(\.\d+)? [A-Z]", lines[-1]), f"page {i} ends on the heading {lines[-1]!r}"


@pytest.mark.slow
def test_plant_a_page_one_counts_cases_as_the_json_and_prints_clean(plant_a):
    pdf, pages, res = plant_a
    cov = res["summary"]["coverage"]
    p1 = " ".join(pages[0].split())
    assert f"{cov['evaluated']} of {cov['rows']} judged test cases evaluated, " in p1
    assert f"{cov['excluded']} excluded by an eligibility rule the requirement states (IEC61362-TC" in p1
    assert f"{cov['not_evaluated']} NOT EVALUATED" in p1
    assert cov["rows"] == cov["evaluated"] + cov["excluded"] + cov["not_evaluated"] and cov["basis"].split(";")[0][:30] in p1
    assert pdf_problems(pdf) == []


@pytest.mark.slow
def test_plant_a_results_carry_the_model_evidence_and_page_one_says_it(plant_a):
    pdf, pages, res = plant_a
    ev = res["model_evidence"]
    assert ev["status"] == "contradicted" and ev["compared"] == 16 and ev["contradict"] >= 10
    p1 = " ".join(pages[0].split())
    assert "Model validation: CONTRADICTED" in p1 and "Verdicts resting on figures the measurements contradict" in p1
    not_met = [e["id"] for e in res["requirements"] if e["severity"] == "mandatory"
               and e["status"] in ("fail", "uncertain", "not_evaluated")]
    assert not_met and all(rid in p1 for rid in not_met)
    # with --linear the margins are the linear analyses' own, one per distinct operating point
    pm = [p["phase_margin_deg"] for p in res["stability"]["points"] if p["phase_margin_deg"] is not None]
    assert pm and f"phase margin {min(pm):.0f}–{max(pm):.0f}°" in p1 and "Requirement set:" in p1
    assert "Accepted for the plant owner" in p1 and "Contents" in pages[1]  # page 1 fits one page


@pytest.mark.slow
def test_plant_a_every_row_has_a_band_and_no_failure_prints_as_its_limit(plant_a):
    _, _, res = plant_a
    rows = [(e, r) for e in res["requirements"] if e["source"] == "simulation" for r in e["rows"]
            if r.get("value") is not None]
    assert len(rows) > 80 and all(r.get("band") for _, r in rows)
    for e, r in rows:
        b = r["band"]
        assert b["low"] <= r["value"] <= b["high"], (e["id"], r["run"])
        if r.get("margin_pct") is not None and b["margin_low_pct"] is not None:
            assert b["margin_low_pct"] <= r["margin_pct"] <= b["margin_high_pct"], (e["id"], r["run"])
        if r["status"] == "fail":
            shown, limit = r["display"]["value"], r["display"]["limit"]
            assert shown not in limit.split(" .. "), (e["id"], r["run"], shown, limit)
