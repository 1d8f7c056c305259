"""Page 1 of the compliance report, read as the signer reads it (pdftotext): every mandatory requirement not met,
the model's evidence, the loop's stability margins and the requirement set's findings, on one page.

The results are the trimmed real run of ``tests/data/results_fixture.json`` with the sections a check adds
computed for plant A here: its paper's measured figures (``model_evidence``), its stability margins and the
requirement set's findings.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from compliance.model.config import load_plant
from compliance.pipeline.chain import evidence, stability
from compliance.report.render import render_report
from compliance.requirements.consistency import consistency_findings
from compliance.requirements.loading import load_requirements
from compliance.results import CheckResult
from tests.report.test_report import _pdf_pages

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "data" / "results_fixture.json"


@pytest.fixture(scope="module")
def page_one(tmp_path_factory):
    res = json.loads(FIXTURE.read_text(encoding="utf-8"))
    cfg, reqset = load_plant(ROOT / "models" / "plant-a.toml"), load_requirements(ROOT / "requirements" / "shpp-400kw.toml")
    res["findings"] = consistency_findings(reqset, cfg.p("cylinder.stroke"))
    result = CheckResult.from_dict(res)
    result = result.with_(model_evidence=evidence(cfg, result), stability=stability(cfg, reqset, jobs=1))
    out = tmp_path_factory.mktemp("p1") / "r.pdf"
    render_report(result, pdf_path=out)
    pages = _pdf_pages(out)
    # the record read back from its JSON, as a reader of the results file gets it (the sections survive)
    res = json.loads(result.json_text())
    assert CheckResult.from_dict(res).json_text() == result.json_text()
    return res, " ".join(pages[0].split()), pages


def test_page_one_names_every_mandatory_requirement_not_met(page_one):
    res, p1, _ = page_one
    not_met = [e["id"] for e in res["requirements"] if e["severity"] == "mandatory"
               and e["status"] in ("fail", "uncertain", "not_evaluated")]
    assert not_met and all(rid in p1 for rid in not_met)
    assert "Mandatory requirements not met" in p1
    # the failing value with its limit and where (SHPP-TRACK: 2.33 mm against the 1.60 mm of 1 % stroke)
    assert re.search(r"SHPP-TRACK FAIL 2\.33 mm against ≤ 1 % stroke \(1\.60 mm\) \(sine-8mm at region2-80\)", p1)
    for e in res["requirements"]:
        if e["severity"] != "mandatory" and e["status"] == "fail":
            assert e["id"] in p1  # advisory failures named too, apart


def test_page_one_says_the_model_is_contradicted_and_which_verdicts_rest_on_it(page_one):
    res, p1, _ = page_one
    ev = res["model_evidence"]
    assert f"Model validation: CONTRADICTED – {ev['contradict']} of {ev['compared']} independent measured figures" in p1
    # the dead-zone stall band (0.86 mm opening, 0.90 mm closing) against the paper's 0.24 mm
    m = re.search(r"steady error (0\.\d+) mm modelled, 0\.240 mm measured", p1)
    assert m and 0.86 <= float(m.group(1)) <= 0.91
    assert re.search(r"SHPP-TRACK \(FAIL, pessimistic\)", p1)  # the paper tracked better than the model
    assert "contradicted by measurement (pessimistic)" in p1.lower()


def test_page_one_shows_the_stability_margins_against_the_criterion(page_one):
    res, p1, _ = page_one
    pm = [p["phase_margin_deg"] for p in res["stability"]["points"]]
    assert f"phase margin {min(pm):.0f}–{max(pm):.0f}°" in p1 and "below govcheck's 30° / 6 dB criterion" in p1
    assert min(pm) < 30.0  # plant A: about 21 deg at the 16 mm points of critical region 1


def test_page_one_carries_the_requirement_set_findings_and_fits_one_page(page_one):
    _, p1, pages = page_one
    assert "Requirement set: rate split: IEC61362-TC (≤ 0.25 s on 16.0 mm steps) needs 40.5 mm/s" in p1
    assert "admit only strokes of 5–5.25 s" in p1
    assert "Accepted for the plant owner" in p1 and pages[1].lstrip().splitlines()[0].startswith(
        "plant") and "Contents" in pages[1]
    body = " ".join(" ".join(pages[:-1]).split())
    assert "3.5 Findings about the requirement set" in body and "6.1 Measured figures of the plant paper" in body
    # findings on the same figures are one line naming every limit they involve; the arithmetic is given once
    assert "needs 40.5 mm/s, above the 32.0 mm/s of IEEE125-NOFASTER, SHPP-SURGE" in body
    assert body.count("reaching 63.2 % of the step within 0.25 s needs a mean speed") == 1
