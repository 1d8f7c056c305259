"""``govcheck sweep`` end to end on a small sweep: table, summary, best results, yield; the report partial renders."""

import json
from pathlib import Path

import jinja2
import pandas as pd
import pytest

from compliance.campaign.results_files import read_results
from compliance.cli import main
from compliance.sweep.tolerance.yield_mc import wilson

from tests.sweep.conftest import sweep_text

TEMPLATES = Path(__file__).resolve().parents[2] / "compliance" / "report" / "templates"


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sweep")
    f = folder / "s.toml"
    f.write_text(sweep_text())
    out = folder / "out"
    code = main(["sweep", str(f), "--out", str(out), "-j", "2", "-q"])
    return code, f, out


def test_sweep_writes_table_summary_and_best_results(swept):
    code, _, out = swept
    assert code == 0  # a candidate passes: kp above ~300 V/m overcomes static friction in time
    df = pd.read_parquet(out / "results.parquet")
    assert len(df) == 8 and len(pd.read_csv(out / "results.csv")) == 8
    assert {"controller.kp", "controller.kd", "TC.value", "TC.margin", "TC.status", "status", "shortfall"} <= set(df)
    s = json.loads((out / "summary.json").read_text())
    assert s["passing"] == int((df["status"] == "pass").sum()) > 0
    assert s["executor"]["done"] >= 1 and s["executor"]["failed"] == 0
    assert s["pareto"]["requirements"] == ["TC", "POS"] or s["pareto"]["requirements"] == ["POS", "TC"]
    best = s["best"]
    assert best["verified_status"] == "pass" and df.loc[best["candidate"], "status"] == "pass"
    # the best passing candidate is the one closest to the base settings (kp 280, kd 20)
    passing = df[df["status"] == "pass"]
    assert best["change"] == pytest.approx(passing["change"].min())
    res = read_results(out / "best-results.json.gz")
    assert res.passed and res.sweep["candidate"] == best["candidate"]


def test_summary_text_reads_as_a_document(swept):
    """The Markdown summary: counts say what they count, values carry prefixed typeset units, no "seed",
    and every file it points at is one the sweep wrote next to it."""
    import re

    from compliance.report.text_check import repository_names, text_problems

    _, _, out = swept
    s = json.loads((out / "summary.json").read_text())
    md = (out / "summary.md").read_text()
    assert f"**{s['passing']} of the {s['candidates']} drawn candidates pass**" in md
    assert not re.search(r"\bseeds?\b", md, re.I) and "random-number start" in md
    assert not re.search(r"\d[eE][+-]\d", md) and "^" not in md and "*(" not in md  # no 8e+05, m^3, V*s
    for p in s["parameters"]:  # each parameter's value printed with its unit
        assert f"| {p['path']} |" in md
    assert "V/m" in md  # controller.kp in V/m, typeset
    named = re.findall(r"[\w.-]+\.(?:json(?:\.gz)?|csv|parquet|md|html)\b", md)
    assert named and all((out / n).exists() for n in named), named
    heads = [line.lstrip("# ") for line in md.splitlines() if line.startswith("#")]
    assert text_problems(md, heads, repo_names=repository_names(Path(__file__).resolve().parents[2])) == []


def test_yield_of_best_is_seeded_and_bounded(swept):
    _, f, out = swept
    assert main(["sweep", str(f), "--out", str(out), "--yield", "best", "-q", "-j", "2"]) == 0
    y = json.loads((out / "yield-best" / "yield.json").read_text())
    assert y["units"] == 12 and y["valid"] + y["invalid"] + y["failed_tasks"] == 12
    a = y["all_mandatory"]
    assert a["ci"][0] <= a["fraction"] <= a["ci"][1]
    assert [d["path"] for d in y["drivers"]] and len(y["requirements"]) == 2
    res = read_results(out / "yield-best" / "results.json")
    assert json.loads(res.json_text())["tolerance_yield"]["all_mandatory"] == a
    units = pd.read_parquet(out / "yield-best" / "results.parquet")
    again = main(["sweep", str(f), "--out", str(out), "--yield", "best", "-q", "-j", "1"])
    assert again == 0
    pd.testing.assert_frame_equal(units, pd.read_parquet(out / "yield-best" / "results.parquet"))
    _render_partial(res.tolerance_yield)
    assert "Tolerance yield" in (out / "yield-best" / "yield.html").read_text()  # the report section of both remedies and yield renders


def test_yield_without_earlier_sweep_is_exit_2(tmp_path, swept, capsys):
    _, f, _ = swept
    assert main(["sweep", str(f), "--out", str(tmp_path / "empty"), "--yield", "best"]) == 2
    assert "no sweep results" in capsys.readouterr().err


def test_wilson_interval():
    lo, hi = wilson(0, 8, 0.95)  # zero successes: the interval still reaches ~32 %
    assert lo == 0.0 and hi == pytest.approx(0.324, abs=0.002)
    lo, hi = wilson(50, 100, 0.95)
    assert (lo, hi) == (pytest.approx(0.404, abs=0.002), pytest.approx(0.596, abs=0.002))


def _render_partial(tolerance_yield):
    rem = {"status": "none_found", "note": "no candidate passes", "evaluated": 3, "space": [],
           "sensitivities": [{"requirement": "TC", "margin_pct": -10.0,
                              "by_parameter": [{"path": "controller.kp", "unit": "V/m", "step": 30.0, "delta_margin_pct": 4.0}]}],
           "remedy": None, "closest": {"changes": [{"path": "controller.kp", "unit": "V/m", "from": 280.0, "to": 300.0}],
                                       "change": 0.1, "binding": "TC", "binding_margin_pct": -2.0, "failed_mandatory": ["TC"]}}
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(TEMPLATES), autoescape=True, undefined=jinja2.StrictUndefined)
    from compliance.presentation.numbers import fmt_margin_pct, fmt_si

    env.filters["si"] = lambda v, u: fmt_si(v, u or "")  # the report's filters: values with units, capped margins
    env.filters["margin"] = lambda v: fmt_margin_pct(v) or "\u2013"
    html = env.get_template("_remedies.html.j2").render(remedies=rem, tolerance_yield=tolerance_yield)
    assert "What would make it pass" in html and "Closest candidate" in html and "controller.kp" in html
    assert "Tolerance yield" in html and html.count("<svg") == 2
    assert env.get_template("_remedies.html.j2").render(remedies=None, tolerance_yield=None).strip() == ""
