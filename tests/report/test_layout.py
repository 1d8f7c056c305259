"""No text outside its figure or page, no overprinting: the fixture report, a deliberately broken one, the examples.

Text boxes come from the font's metrics in the SVG figures (``viewBox``) and from pdfplumber's
character boxes in the PDF (``compliance.report.layout_check``). The deliberately overflowing
fixtures prove the checks can fail: a matplotlib label pushed below its figure, two labels drawn
over each other, and a table cell whose unbreakable text runs into the next cell.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from compliance.report.layout_check import html_problems, pdf_problems, svg_problems
from compliance.report.render import render_report
from compliance.report.svg import clean_svg

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "data" / "results_fixture.json"
EXAMPLES = ROOT / "reports" / "examples"
MARKER = '<meta name="govcheck-layout"'  # examples rendered since these checks exist carry it


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    res = json.loads(FIXTURE.read_text(encoding="utf-8"))
    res["plant"]["identity"] = {"site": "SHPP Example", "unit": "Unit 1", "witness": "A. Witness",
                                "equipment": {"servo_valve": {"id": "1V1", "serial": "SN 12345"}}}
    out = tmp_path_factory.mktemp("layout")
    render_report(res, out / "r.html", out / "r.pdf", document={"number": "QA-GOV-0001", "revision": "B"})
    return out / "r.html", out / "r.pdf"


def test_fixture_report_has_no_clipped_or_colliding_label(report):
    html_path, _ = report
    assert html_problems(html_path.read_text(encoding="utf-8")) == []


def test_fixture_report_pdf_has_no_text_off_the_page_or_overprinted(report):
    pytest.importorskip("pdfplumber")
    _, pdf_path = report
    assert pdf_problems(pdf_path) == []


def test_identity_and_a_document_number_remove_the_draft_mark(report, tmp_path):
    html_path, _ = report
    text = html_path.read_text(encoding="utf-8")
    assert 'class="draft-svg"' not in text and "QA-GOV-0001" in text and "SN 12345" in text and "A. Witness" in text
    res = json.loads(FIXTURE.read_text(encoding="utf-8"))  # no [identity]: a draft, whatever the number
    render_report(res, tmp_path / "d.html", appendix="none", document={"number": "QA-GOV-0001"})
    draft = (tmp_path / "d.html").read_text(encoding="utf-8")
    assert 'class="draft-svg"' in draft and "the site, the unit and the equipment are not identified" in draft


def _svg(draw) -> str:
    import io

    import matplotlib
    from matplotlib.figure import Figure

    from compliance.report.svg import STYLE

    with matplotlib.rc_context(STYLE):  # text kept as <text>, as in the report
        fig = Figure(figsize=(4, 2))
        ax = fig.subplots()
        draw(fig, ax)
        buf = io.StringIO()
        fig.savefig(buf, format="svg")  # no tight box: what the report did before the checks
    return clean_svg(buf.getvalue(), "fig-1")


def test_a_label_below_the_figure_is_found():
    def draw(fig, ax):
        ax.set_xlabel("time [s]")
        fig.subplots_adjust(bottom=0.02)  # the label's baseline falls below the viewBox

    problems = svg_problems(_svg(draw))
    assert any("'time [s]' outside the viewBox" in p for p in problems), problems


def test_the_command_line_names_a_clipped_label_and_exits_1(tmp_path, capsys):
    from compliance.report.layout_check import main as layout_main

    def draw(fig, ax):
        ax.set_xlabel("time [s]")
        fig.subplots_adjust(bottom=0.02)

    bad, good = tmp_path / "bad.html", tmp_path / "good.html"
    bad.write_text(f"<html><body><figure>{_svg(draw)}</figure></body></html>", encoding="utf-8")
    good.write_text("<html><body><p>no figure</p></body></html>", encoding="utf-8")
    assert layout_main([str(good)]) == 0
    assert layout_main([str(good), str(bad)]) == 1
    assert "'time [s]' outside the viewBox" in capsys.readouterr().out


def test_two_labels_drawn_over_each_other_are_found():
    def draw(fig, ax):
        ax.text(0.5, 0.5, "command [V]", transform=ax.transAxes)
        ax.text(0.52, 0.5, "speed [mm/s]", transform=ax.transAxes)

    problems = svg_problems(_svg(draw))
    assert any("collides" in p for p in problems), problems


def test_a_tidy_figure_passes():
    def draw(fig, ax):
        ax.plot([0, 1], [0, 1])
        ax.set_xlabel("time [s]")
        ax.set_ylabel("position [mm]")
        fig.subplots_adjust(left=0.2, bottom=0.25)

    assert svg_problems(_svg(draw)) == []


def test_a_table_cell_running_into_the_next_is_found(tmp_path):
    pytest.importorskip("pdfplumber")
    import weasyprint

    cell = '<td style="white-space:nowrap">IEC61362-TCLOSE-WITH-A-LONG-IDENTIFIER</td>'
    html = ('<table style="table-layout:fixed;width:80mm"><col style="width:20mm"><col style="width:60mm">'
            f'<tr>{cell}<td>full-stroke at governor-setup</td></tr></table>')
    pdf = tmp_path / "bad.pdf"
    weasyprint.HTML(string=html).write_pdf(pdf)
    assert any("overprints" in p for p in pdf_problems(pdf))


def _examples(suffix):
    return sorted(EXAMPLES.rglob(f"*{suffix}")) if EXAMPLES.is_dir() else []


@pytest.mark.parametrize("path", _examples(".html"), ids=lambda p: p.name)
def test_example_html_layout(path):
    text = path.read_text(encoding="utf-8")
    if MARKER not in text:
        pytest.skip(f"{path.name} was rendered before the layout checks; regenerate: python reports/examples/regenerate.py")
    assert html_problems(text) == []


@pytest.mark.parametrize("path", _examples(".pdf"), ids=lambda p: p.name)
def test_example_pdf_layout(path):
    pytest.importorskip("pdfplumber")
    html = path.with_suffix(".html")
    if not html.exists() or MARKER not in html.read_text(encoding="utf-8"):
        pytest.skip(f"{path.name} was rendered before the layout checks; regenerate: python reports/examples/regenerate.py")
    assert pdf_problems(path) == []
