"""A report a signer can follow: no file or module of the code base, no "seed", no reference to a missing section.

Checked over the extracted text (HTML and PDF) of the fixture report and of every example under
reports/examples/ rendered since the check exists; a deliberately bad text shows each check fails.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from compliance.report.render import render_report
from compliance.report.text_check import html_text, repository_names, text_problems

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "data" / "results_fixture.json"
EXAMPLES = ROOT / "reports" / "examples"
MARKER = '<meta name="govcheck-layout"'


def _inputs(text: str) -> list[str]:
    """The inputs a report cites in its document control (they may be named): the paths in its sha256 table."""
    paths = re.findall(r'<td class="small mono path">([^<]+)</td>', text) + re.findall(r'<span class="mono small">([^<]+)</span>', text)
    return paths + [p.rsplit("/", 1)[-1] for p in paths]  # a line break may split a path in the PDF


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    res = json.loads(FIXTURE.read_text(encoding="utf-8"))
    out = tmp_path_factory.mktemp("text")
    render_report(res, out / "r.html", out / "r.pdf", appendix="summary")
    return out / "r.html", out / "r.pdf"


def test_fixture_report_text_is_self_contained(rendered):
    html_path, _ = rendered
    raw = html_path.read_text(encoding="utf-8")
    text, headings = html_text(raw)
    assert text_problems(text, headings, repo_names=repository_names(ROOT), allowed=_inputs(raw)) == []
    # what the signer needs to read the verdicts: the plant paper cited in full, HYGOV and pu/s explained,
    # the stability criterion stated as our choice, the operating points defined before the evidence
    assert "Development of a high power pneumatic servo-positioning system" in text
    assert "per unit of stroke per second" in text and "HYGOV is the hydro turbine-governor model" in text
    assert "our own choice" in text and "IEC 62006:2010" in text
    assert headings.index("2.1 Operating points") < headings.index("4. Evidence per requirement")


def test_fixture_report_pdf_text_is_self_contained(rendered):
    pdfplumber = pytest.importorskip("pdfplumber")
    html_path, pdf_path = rendered
    raw = html_path.read_text(encoding="utf-8")
    _, headings = html_text(raw)
    with pdfplumber.open(str(pdf_path)) as pdf:
        text = " ".join(" ".join((p.extract_text() or "").split()) for p in pdf.pages)
    assert text_problems(text, headings, repo_names=repository_names(ROOT), allowed=_inputs(raw)) == []


def test_each_kind_of_reference_a_signer_cannot_follow_is_found():
    text = ("See reference-plant.md 'Known tension'; computed by compliance.linear.analysis; the seed paper says so; "
            "details in section 9.4 and appendix E; Figure 99 shows it.")
    problems = text_problems(text, ["1. Scope", "A. Configuration"], repo_names={"reference-plant.md"})
    kinds = ["reference-plant.md", "compliance.linear", "'seed'", "section 9.4", "appendix E", "Figure 99"]
    for k in kinds:
        assert any(k in p for p in problems), (k, problems)
    assert text_problems("section 5.2 of the plant paper; plant paper section 5.2; section 1", ["1. Scope"]) == []


def _examples():
    return sorted(EXAMPLES.rglob("*.html")) if EXAMPLES.is_dir() else []


@pytest.mark.parametrize("path", _examples(), ids=lambda p: p.name)
def test_example_text_is_self_contained(path):
    raw = path.read_text(encoding="utf-8")
    if MARKER not in raw:
        pytest.skip(f"{path.name} was rendered before the text checks; regenerate: python reports/examples/regenerate.py")
    text, headings = html_text(raw)
    assert text_problems(text, headings, repo_names=repository_names(ROOT), allowed=_inputs(raw)) == []
