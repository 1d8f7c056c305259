"""HTML and PDF reports: self-contained, escaped, complete, atomic; checked as a reader would.

The fixture ``tests/data/results_fixture.json`` is a trimmed real run (see ``regenerate``
at the bottom: ``python -m tests.report.test_report --regenerate`` rebuilds it from
``govcheck check plant-a -r shpp-400kw``, ``govcheck linear`` and ``govcheck validate``).
"""

from __future__ import annotations

import copy
import html.parser
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from compliance.cli import main
from compliance.errors import InputError
from compliance.report import render as R
from compliance.report.figures import decimate
from compliance.report.render import render_report, render_validation_report
from compliance.report.requirement_pages import requirement_pages
from compliance.results import CheckResult

FIXTURE = Path(__file__).resolve().parents[1] / "data" / "results_fixture.json"
EVIL = "<script>alert(1)</script>"


def _results() -> dict:
    return json.loads(FIXTURE.read_text(encoding="utf-8"))


class _Doc(html.parser.HTMLParser):
    """Collect tags, attributes and text of an HTML document."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags, self.attrs, self.text, self.ids = [], [], [], []
        self._stack = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.attrs.append((tag, dict(attrs)))
        d = dict(attrs)
        if "id" in d:
            self.ids.append(d["id"])

    def handle_data(self, data):
        self.text.append(data)


def _parse(text: str) -> _Doc:
    d = _Doc()
    d.feed(text)
    return d


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """The full fixture rendered once (HTML + PDF) with a hostile plant name."""
    res = _results()
    res["plant"]["name"] = EVIL
    res["requirements"][0]["title"] = 'dead time <img src="x" onerror="alert(2)"> & "quotes"'
    out = tmp_path_factory.mktemp("report")
    html_path, pdf_path = out / "r.html", out / "r.pdf"
    render_report(res, html_path, pdf_path, appendix="full")
    return res, html_path, pdf_path


# --------------------------------------------------------------------------- HTML
def test_html_is_self_contained_with_every_figure_inline(rendered):
    res, html_path, _ = rendered
    text = html_path.read_text(encoding="utf-8")
    doc = _parse(text)
    # one <figure> per trace of every run, per linear plot and per validation overlay, each an inline <svg>
    n_traces = sum(len(r["traces"]) for r in res["runs"])
    n_val = sum(len(m["overlays"]) for m in res["validation"]["modes"].values())
    n_lin = 3 + 2  # three maps (time constant, gain and phase margins) + Bode + poles
    n_pages = len(requirement_pages(CheckResult.from_dict(res))[1])  # the worst case of each requirement page whose run is in the fixture
    assert n_pages >= 3
    assert doc.tags.count("figure") == n_pages + n_traces + n_val + n_lin
    draft = sum(1 for tag, a in doc.attrs if tag == "svg" and a.get("class") == "draft-svg")  # the DRAFT watermark
    assert draft == 1  # the fixture's configuration has no document number
    assert doc.tags.count("svg") - draft == doc.tags.count("figure")
    # nothing outside the file: no scheme, no import, no src/href to anything but an in-page anchor
    assert "http:" not in text and "https:" not in text
    assert "@import" not in text and "url(http" not in text
    for tag in ("script", "link", "img", "iframe", "object"):
        assert tag not in doc.tags, tag
    for tag, attrs in doc.attrs:
        for k, v in attrs.items():
            if k in ("src", "href", "xlink:href"):
                assert v.startswith("#"), (tag, k, v)
    # ids unique across the whole document (figure ids are prefixed per figure)
    assert len(doc.ids) == len(set(doc.ids))


def test_user_strings_are_escaped(rendered):
    _, html_path, _ = rendered
    text = html_path.read_text(encoding="utf-8")
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text
    assert "<script" not in text
    assert '<img src="x"' not in text and "&lt;img src=&#34;x&#34;" in text
    doc = _parse(text)
    assert "script" not in doc.tags and "img" not in doc.tags
    assert EVIL in "".join(doc.text)  # shown to the reader as text


def test_contents_in_order_and_every_requirement_in_summary(rendered):
    res, html_path, _ = rendered
    text = html_path.read_text(encoding="utf-8")
    sections = ("cover", "scope", "conditions", "summary", "procedures", "linear", "validation", "conclusions", "appendix")
    pos = [text.index(f'id="{s}"') for s in sections]
    assert pos == sorted(pos)
    summary = text[text.index('id="summary"'):text.index('id="procedures"')]
    for e in res["requirements"]:
        assert e["id"] in summary
    # the cover cites the sha256 digests (abbreviated) and the verdict; section 7.3 gives them in full
    cover = text[:text.index('id="contents"')]
    assert res["plant"]["digest"][:16] in cover and res["requirement_set"]["digest"][:16] in cover
    assert res["summary"]["status"].upper() in cover
    control = text[text.index('id="conclusions"'):text.index('id="appendix"')]
    assert res["plant"]["digest"] in control and res["requirement_set"]["digest"] in control
    # every operating point is defined in section 2.1, before the evidence uses it
    conditions = text[text.index('id="conditions"'):text.index('id="summary"')]
    for name in res["requirement_set"]["operating_points"]:
        assert name in conditions, name
    # appendix: every parameter the model uses with its source (laws not selected are left out), the command line
    from compliance.report.signoff import used_by_model

    appendix = text[text.index('id="appendix"'):]
    used = [p for p in res["plant"]["parameters"] if used_by_model(p["key"], res["plant"]["options"])]
    assert 0 < len(used) < len(res["plant"]["parameters"])
    for p in res["plant"]["parameters"]:
        assert (p["key"] in appendix) == (p in used), p["key"]
    assert "govcheck check" in appendix


def test_measured_points_are_marked_on_the_plots(rendered):
    _, html_path, _ = rendered
    text = html_path.read_text(encoding="utf-8")
    # legend entries of the marks drawn by figures.trace_figure (text kept as <text> in the SVG)
    for label in ("63.2 % point", "settling instant", "settling band", "tolerance", "full opening", "chamber A"):
        assert label in text, label
    assert "outside 100" in text  # the time-constant map outlines the IEC 61362 window 100-250 ms


def test_absent_sections_say_not_run(tmp_path):
    res = _results()
    del res["linear"], res["validation"]
    res["runs"] = res["runs"][:1]
    out = tmp_path / "r.html"
    render_report(res, out)
    text = out.read_text(encoding="utf-8")
    assert "Linear analysis (govcheck linear): not run." in text
    assert "Model validation against recordings (govcheck validate): not run." in text
    assert _parse(text).tags.count("svg") == len(res["runs"][0]["traces"]) + 1  # + the DRAFT watermark


# --------------------------------------------------------------------------- PDF
def test_pdf_has_pages_verdict_and_every_requirement(rendered):
    pypdf = pytest.importorskip("pypdf")
    res, _, pdf_path = rendered
    reader = pypdf.PdfReader(str(pdf_path))
    # cover + contents + summary + at least one page per run figure pair + linear + validation + appendix
    assert len(reader.pages) >= 8
    text = "\n".join(p.extract_text() for p in reader.pages)
    assert res["summary"]["status"].upper() in reader.pages[0].extract_text()
    for e in res["requirements"]:
        assert e["id"] in text, e["id"]
    # running footer with page numbers and a table of contents with page numbers
    assert f"Page 2 of {len(reader.pages)}" in text
    toc = reader.pages[1].extract_text()
    assert re.search(r"3\. Results against the guarantees[ .]*\d+", toc)
    assert re.search(r"7\. Conclusions, disposition, parties and revisions[ .]*\d+", toc)


def _png_stats(path):
    from PIL import Image

    im = np.asarray(Image.open(path).convert("L"), dtype=float)
    return im.shape, float(im.std())


def test_pdf_first_page_is_not_blank(rendered, tmp_path):
    if shutil.which("pdftoppm") is None:
        pytest.skip("pdftoppm not installed (Debian package poppler-utils)")
    _, _, pdf_path = rendered
    subprocess.run(["pdftoppm", "-r", "50", "-png", "-f", "1", "-l", "1", "-singlefile", str(pdf_path),
                    str(tmp_path / "p1")], check=True, timeout=60)
    shape, std = _png_stats(tmp_path / "p1.png")
    # A4 at 50 dpi is 413 x 585 px; text, the verdict box and rules give a grey-level spread far
    # above a blank page's 0 (a white page with a few lines of text already exceeds 10)
    assert abs(shape[1] - 413) <= 2 and abs(shape[0] - 585) <= 2
    assert std > 10.0


def test_html_renders_in_headless_chromium(rendered, tmp_path):
    exe = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if exe is None:
        pytest.skip("headless Chromium not installed (Debian packages chromium chromium-driver)")
    _, html_path, _ = rendered
    png = tmp_path / "shot.png"
    cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
           "--disable-background-networking", "--disable-component-update", "--disable-sync",
           f"--user-data-dir={tmp_path / 'profile'}", f"--screenshot={png}", "--window-size=1280,2000",
           html_path.resolve().as_uri()]
    subprocess.run(cmd, check=False, timeout=120, capture_output=True)
    if not png.exists():
        pytest.skip("chromium ran but wrote no screenshot (sandbox restrictions of this machine)")
    shape, std = _png_stats(png)
    assert shape == (2000, 1280)
    assert std > 10.0  # the cover: title, verdict box, tables - not a blank page


# --------------------------------------------------------------------------- what a signer reads
# patterns a careful reader found in earlier reports (issue 15): split words, units set wrong,
# Python literals, exponents on millimetres, uncapped margins, internal ids in captions
_BAD_PDF_TEXT = [
    (r"\bpositionin g\b|\badjustmen t\b|\bperfor mance\b", "a word split across lines"),
    (r"%stroke", "'%stroke' without a space"),
    (r"\bDB\b|\bHZ\b", "dB / Hz upper-cased"),
    (r"\bTrue\b|\bFalse\b|\bNone\b|\{'|'\}|\[\]", "a Python literal"),
    (r"\de-?\d+ ?(mm|s|N|%)", "an exponent on a value with a unit (1e-06 mm)"),
    (r"[+\-\u2212](?:[2-9]\d\d|1\d[1-9]|1[1-9]\d|\d{4,})\.\d %", "an uncapped margin (+920.7 %)"),
    (r"samples plotted", "plotting internals in a caption"),
    (r"a_subsonic|b_choked|seed 00\d", "internal names"),
]


@pytest.fixture(scope="module")
def pdf_text(tmp_path_factory):
    """Pages of the default (appendix summary) PDF of the fixture as text (poppler's pdftotext, else pdfplumber)."""
    out = tmp_path_factory.mktemp("signoff")
    res = _results()
    render_report(res, pdf_path=out / "r.pdf")
    return res, _pdf_pages(out / "r.pdf")


def _pdf_pages(path) -> list[str]:
    if shutil.which("pdftotext") is not None:
        text = subprocess.run(["pdftotext", "-layout", str(path), "-"], capture_output=True, text=True,
                              check=True, timeout=60).stdout
        return text.split("\f")
    pdfplumber = pytest.importorskip("pdfplumber", reason="neither pdftotext (poppler-utils) nor pdfplumber installed")
    with pdfplumber.open(str(path)) as pdf:
        return [p.extract_text() or "" for p in pdf.pages]


@pytest.mark.parametrize("pattern, what", _BAD_PDF_TEXT)
def test_pdf_text_has_no_known_failure_pattern(pdf_text, pattern, what):
    _, pages = pdf_text
    for i, page in enumerate(pages, 1):
        m = re.search(pattern, page)
        assert m is None, f"page {i}: {what}: ...{page[max(0, m.start() - 60):m.end() + 60]}..."


def test_page_one_states_basis_failures_and_not_evaluated(pdf_text):
    res, pages = pdf_text
    p1 = " ".join(pages[0].split())
    assert "simulation, not measurement" in p1 and "Model validation" in p1
    # the judged cases on the basis of the terminal and JSON summaries (requirements with a limit only)
    judged = [r for e in res["requirements"] if e.get("limit") is not None for r in e["rows"]]
    n_ne = sum(1 for r in judged if r["status"] == "not_evaluated")
    assert f"{len(judged) - n_ne} of {len(judged)} judged test cases evaluated, {n_ne} NOT EVALUATED" in p1
    assert "open requirements (no limit) are not counted" in p1
    for rid in res["summary"]["failed"]:
        assert rid in p1, rid
    assert "What would make it pass: not searched (the remedies search was not run)" in p1  # no remedies in the results: says so, in words
    assert res["plant"]["digest"][:16] in p1.replace(" ", "")
    assert "Accepted for the plant owner" in p1


def test_body_is_at_most_25_pages_and_appendix_levels(pdf_text, tmp_path):
    _, pages = pdf_text
    body = next(i for i, p in enumerate(pages) if re.search(r"^\s*Appendix\s*$", p, re.M))
    start = next(i for i, p in enumerate(pages) if re.search(r"^\s*6\. Model validation\s*$", p, re.M))
    end = next(i for i, p in enumerate(pages)
               if re.search(r"^\s*7\. Conclusions, disposition, parties and revisions\s*$", p, re.M))
    # plant A's report carries no validation (the fixture adds one to test that section)
    validation = end - start
    assert body - validation <= 25, f"body without the validation section has {body - validation} pages"
    for heading in ("1. Scope, references and test object", "2.1 Operating points", "2.2 Instrumentation and method",
                    "3.1 Departures from the test code", "3.3 Conditions not tested", "7.1 Conclusions and disposition",
                    "7.2 Parties and witnesses", "7.3 Document control and revision history"):
        assert any(heading in p for p in pages[:body]), heading
    res = _results()
    render_report(res, pdf_path=tmp_path / "none.pdf", appendix="none")
    none = _pdf_pages(tmp_path / "none.pdf")
    # without an appendix: no appendix heading and none of its tables (the body's page breaks may fall differently)
    assert "Configuration parameters of" not in "".join(none)
    assert not any(re.search(r"^\s*Appendix\s*$", p, re.M) for p in none)
    with pytest.raises(InputError, match="--appendix"):
        render_report(res, pdf_path=tmp_path / "x.pdf", appendix="all")


def test_steps_that_cannot_fail_are_marked_with_coverage():
    res = _results()
    pos = next(e for e in res["requirements"] if e["id"] == "IEC61362-POS")
    row = copy.deepcopy(pos["rows"][0])
    row["samples"] = [{"label": "step 1 up 1.60 mm", "value": 0.00086, "eligible": True, "reason": None,
                       "detail": {"size": 0.0016, "x_start": 0.08, "x_final": 0.08074}}]
    row["limit"] = [0.0016]
    pos["rows"] = [row]
    page = next(p for p in requirement_pages(CheckResult.from_dict(res))[0] if "IEC61362-POS" in p["ids"])
    case = page["cases"][0]
    assert case["cannot_fail"]  # tolerance 1.6 mm >= step 1.6 mm: the error cannot exceed it
    assert "moved 46 % of the step" in case["steps"][0]["text"]  # 0.74 of 1.6 mm


# --------------------------------------------------------------------------- validation report
def test_validation_report_renders(tmp_path):
    val = _results()["validation"]
    val["recording"]["description"] = EVIL
    out_h, out_p = tmp_path / "v.html", tmp_path / "v.pdf"
    render_validation_report(val, out_h, out_p)
    text = out_h.read_text(encoding="utf-8")
    doc = _parse(text)
    draft = sum(1 for tag, a in doc.attrs if tag == "svg" and a.get("class") == "draft-svg")  # no document number
    assert doc.tags.count("svg") - draft == sum(len(m["overlays"]) for m in val["modes"].values())
    assert "Diagnosis (govcheck diagnose): not run." in text
    assert "mismatch window" in text  # located windows shaded on the overlays
    assert "script" not in doc.tags and "&lt;script&gt;" in text
    assert out_p.read_bytes().startswith(b"%PDF")


def test_validation_report_shows_before_after_and_fitted_physics(tmp_path):
    val = _results()["validation"]
    val["diagnosis"] = {
        "after": copy.deepcopy(val),
        "added": [{"name": "internal_leakage", "meaning": "laminar leak across the piston seals",
                   "params": [{"name": "conductance", "value": 3.2e-10, "unit": "kg/(s*Pa)", "bounds": [0.0, 1e-8]}]}],
        "explanation": "pressures drift towards each other while holding",
    }
    out = tmp_path / "v.html"
    render_validation_report(val, out)
    text = out.read_text(encoding="utf-8")
    assert "simulated (after)" in text and "simulated (before)" in text  # overlays: recording, before, after
    assert "internal_leakage" in text and "kg/(s·Pa)" in text and "3.2×10⁻¹⁰" in text
    assert "not run" not in text.split("Physics added")[1]


# --------------------------------------------------------------------------- bad input, atomicity
@pytest.mark.parametrize("path, key", [(("plant", "digest"), "digest"), (("summary",), "summary"),
                                       (("requirements", 0, "rows"), "rows"), (("runs", 0, "traces"), "traces")])
def test_missing_key_is_an_input_error_naming_it(tmp_path, path, key):
    res = _results()
    obj = res
    for k in path[:-1]:
        obj = obj[k]
    del obj[path[-1]]
    with pytest.raises(InputError, match=f"'{key}'"):
        render_report(res, tmp_path / "x.html")
    assert not (tmp_path / "x.html").exists()


def test_wrong_schema_version_exit_2(tmp_path, capsys):
    res = _results()
    res["schema"] = "govcheck-results/0"
    bad = tmp_path / "old.json"
    bad.write_text(json.dumps(res))
    code = main(["report", str(bad), "--html", str(tmp_path / "x.html")])
    assert code == 2
    err = capsys.readouterr().err
    assert "old.json" in err and "'schema'" in err and "govcheck-results/1" in err
    assert not (tmp_path / "x.html").exists()


def test_failed_render_leaves_previous_report_intact(tmp_path, monkeypatch):
    res = _results()
    res["runs"] = res["runs"][:1]
    h, p = tmp_path / "r.html", tmp_path / "r.pdf"
    h.write_text("previous html")
    p.write_bytes(b"previous pdf")

    def boom(html):
        raise RuntimeError("layout failed")

    monkeypatch.setattr(R, "_pdf_bytes", boom)
    with pytest.raises(RuntimeError):
        render_report(res, h, p)
    assert h.read_text() == "previous html" and p.read_bytes() == b"previous pdf"
    assert sorted(os.listdir(tmp_path)) == ["r.html", "r.pdf"]  # no temporary file left behind


def test_cli_report_rerenders_without_simulating(tmp_path, monkeypatch, capsys):
    import compliance.plants.kind as sim  # every simulation passes through its two loops
    import compliance.plants.pid_servo as pid
    import compliance.simulation.state_feedback_loop as sf  # (imported by the state-feedback drive when a run needs it)

    def no_sim(*a, **k):
        raise AssertionError("govcheck report must not simulate")

    monkeypatch.setattr(sim, "simulate_pid", no_sim)
    monkeypatch.setattr(pid, "simulate_pid", no_sim)
    monkeypatch.setattr(sf, "simulate_state_feedback", no_sim)
    res = _results()
    res["runs"] = res["runs"][:1]
    del res["linear"], res["validation"]
    src = tmp_path / "res.json"
    src.write_text(json.dumps(res))
    assert main(["report", str(src), "--jobs", "1"]) == 0  # default: HTML next to the results
    assert (tmp_path / "res.html").read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    assert "res.html" in capsys.readouterr().out
    assert main(["report", str(src), "--html", str(tmp_path / "no" / "x.html")]) == 2


# --------------------------------------------------------------------------- numerics of the plots
def test_decimation_keeps_extremes_and_bounds_points():
    t = np.linspace(0.0, 10.0, 20001)
    y = np.sin(2 * np.pi * 0.3 * t)
    y[12345] = 5.0  # a one-sample spike must survive: it may be the evidence of a fault
    y[777] = -4.0
    td, yd = decimate(t, y, buckets=250)
    assert td.size <= 3 * 250 + 1
    assert yd.max() == 5.0 and yd.min() == -4.0
    assert np.all(np.diff(td) > 0)
    # the decimated curve stays on the signal: every kept point is an original sample
    assert np.array_equal(np.interp(td, t, y), yd)


# --------------------------------------------------------------------------- regeneration
def regenerate(path: Path = FIXTURE) -> None:  # pragma: no cover - run by hand
    """Rebuild the fixture from real runs (simulates; ~1 min on 2 cores)."""
    tmp = Path(os.environ.get("TMPDIR", "/tmp")) / "govcheck-fixture"
    tmp.mkdir(exist_ok=True)
    py = [sys.executable, "-m", "compliance"]
    subprocess.run(py + ["check", "plant-a", "--requirements", "requirements/shpp-400kw.toml", "--json", str(tmp / "r.json"), "-q"])
    subprocess.run(py + ["linear", "plant-a", "--map", "--crosscheck", "--governor", "--json", str(tmp / "lin.json")],
                   check=True, stdout=subprocess.DEVNULL)
    root = FIXTURE.parents[2]
    subprocess.run(py + ["validate", "plant-a", str(root / "tests/data/practice/practice_internal_leakage.csv.gz"),
                        "--json", str(tmp / "val.json")], stdout=subprocess.DEVNULL)
    res = json.loads((tmp / "r.json").read_text())
    keep = ("steps-5@mid-no-load", "steps-10@region2-80", "full-stroke@governor-setup", "sine-8mm@region2-80",
            "hold@region2-90", "dead-band@mid-no-load")
    res["runs"] = [r for r in res["runs"] if r["id"] in keep]
    for r in res["runs"]:
        for tr in r["traces"]:
            n = len(tr["time"])
            idx = np.unique(np.linspace(0, n - 1, min(n, 300)).round().astype(int))
            for k, v in list(tr.items()):
                if isinstance(v, list) and len(v) == n:
                    tr[k] = [v[i] for i in idx]
            tr["points"] = int(idx.size)
        r["metrics"] = {}
    lin = json.loads((tmp / "lin.json").read_text())
    a = lin["analysis"]
    b = a["bode"]
    sel = np.unique(np.linspace(0, len(b["frequency_hz"]) - 1, 60).round().astype(int))
    a["bode"] = {k: [v[i] for i in sel] for k, v in b.items()}
    for k in ("nyquist", "step", "plant"):
        a.pop(k, None)
    res["linear"] = lin
    val = json.loads((tmp / "val.json").read_text())
    for m in val["modes"].values():
        m.pop("residuals", None)
        m["window_metrics"] = m["window_metrics"][:10]
        for ov in m["overlays"].values():
            n = len(ov["time"])
            sel = np.unique(np.linspace(0, n - 1, min(n, 300)).round().astype(int))
            for k in ("time", "recorded", "simulated"):
                ov[k] = [ov[k][i] for i in sel]
    res["validation"] = val
    res["fixture_provenance"] = (
        "trimmed real run: govcheck check plant-a -r requirements/shpp-400kw.toml --json; runs " + ", ".join(keep)
        + " kept with traces cut to 300 points; 'linear' = govcheck linear plant-a --map --crosscheck --governor --json "
        "(Bode cut to 60 points); 'validation' = govcheck validate practice_internal_leakage.csv.gz --plant plant-a "
        "--json (overlays cut to 300 points); rebuilt by python -m tests.report.test_report --regenerate")
    path.write_text(json.dumps(res, separators=(",", ":")) + "\n", encoding="utf-8")
    print(f"wrote {path} ({path.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":  # pragma: no cover
    if "--regenerate" in sys.argv:
        regenerate()


def test_diagnosis_finding_states_verdict_parameters_with_errors_and_next_step():
    from compliance.report.analysis_sections import diagnosis_finding

    diag = {"verdict": "missing_physics", "winner": "valve_dynamics", "explanation": "the valve lags",
            "effects_ranked": [
                {"name": "valve_dynamics", "delta_bic": 0.0,
                 "parameters": [{"name": "valve_dynamics.natural_frequency", "value": 37.8, "stderr": 1.2, "unit": "rad/s"}]},
                {"name": "internal_leakage", "delta_bic": 4.0, "parameters": []}]}
    f = diagnosis_finding(diag)
    assert f["word"] == "MISSING PHYSICS FOUND" and f["effect"] == "valve_dynamics"
    assert f["params"][0]["text"] == "37.8 ± 1.2 rad/s"
    # BIC 4 apart: the data do not decide between the two; the report says so and asks for a separating test
    assert f["next"].startswith("Ambiguous between valve_dynamics and internal_leakage")


def test_reproducible_html_is_byte_identical_and_dated_by_the_results(tmp_path, monkeypatch):
    res = _results()
    res["runs"] = res["runs"][:2]
    res["reproducible"], res["created"] = True, "2023-11-14T22:13:20+00:00"
    a, b = tmp_path / "a.html", tmp_path / "b.html"
    render_report(copy.deepcopy(res), a, workers=1, appendix="none")
    render_report(copy.deepcopy(res), b, workers=1, appendix="none")
    assert a.read_bytes() == b.read_bytes()
    assert "2023-11-14" in a.read_text()  # the rendering date is the results' fixed date, not today


def test_page_one_fix_lines_come_from_the_remedies_section():
    from compliance.report.signoff import failures

    res = _results()
    failed = [e["id"] for e in res["requirements"] if e["status"] == "fail"]
    assert failed, "the fixture has failures"
    res["remedies"] = {"failed": failed, "out_of_reach": [failed[0]], "remedy": None, "sensitivities": []}
    lines = {f["id"]: f["remedy"] for f in failures(CheckResult.from_dict(res))}
    assert "hardware" in lines[failed[0]]
    res["remedies"] = {"failed": failed, "remedy": {"changes": [{"path": "controller.kp", "from": 280.0, "to": 400.0, "unit": "V/m"}],
                                                     "verified": {"status": "pass"}}}
    assert all("from 280 V/m to 400 V/m" in f["remedy"] and "pass" in f["remedy"] for f in failures(CheckResult.from_dict(res)))


def test_remedies_are_section_3_4_and_page_one_points_there(tmp_path):
    res = _results()
    failed = [e["id"] for e in res["requirements"] if e["status"] == "fail"]
    res["remedies"] = {"status": "none_found", "failed": failed, "out_of_reach": [], "remedy": None, "evaluated": 5,
                       "note": "no candidate passes",
                       "sensitivities": [{"requirement": failed[0], "margin_pct": -419.3, "by_parameter": [
                           {"path": "controller.kp", "step": 75.0, "unit": "V/m", "delta_margin_pct": 2.5},
                           {"path": "controller.ki", "step": 20.0, "unit": "V/(m*s)", "delta_margin_pct": 0.01}]}],
                       "closest": {"changes": [], "change": 0.0, "binding": failed[0], "binding_margin_pct": -419.3,
                                   "failed_mandatory": failed}}
    render_report(res, tmp_path / "r.html", appendix="none")
    text = re.sub(r"<[^>]+>", " ", (tmp_path / "r.html").read_text(encoding="utf-8"))
    cover, body = text.split("Contents", 1)
    assert "What would make it pass: section 3.4." in " ".join(cover.split())
    at = body.index("3.4 What would make it pass")
    assert body.index("3.3 Conditions not tested") < at < body.index("4. Evidence per requirement", at)
    section = body[at:body.index("4. Evidence per requirement", at)]
    # the sensitivities keep the parameters that move the margin; the configuration as given is a sentence
    assert "controller.kp" in section and "controller.ki" not in section
    assert "the configuration as given" in section and "-419" not in section and "far beyond" in section
