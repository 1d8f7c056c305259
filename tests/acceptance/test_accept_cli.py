"""``govcheck accept`` end to end: the site JSON, JUnit, gate on it, the predictions beside the verdicts; bad input."""

from __future__ import annotations

import json

import pytest

from compliance.cli import main
from tests.acceptance.site_data import SITE, copy_site


@pytest.fixture(scope="module")
def site_json(tmp_path_factory):
    out = tmp_path_factory.mktemp("accept")
    code = main(["accept", str(SITE), "--requirements", "shpp-400kw", "--json", str(out / "s.json"),
                 "--junit", str(out / "s.xml"), "-j", "2", "-q"])
    return code, out


def test_the_site_json_has_checks_rows_the_prediction_and_the_agreement(site_json):
    code, out = site_json
    assert code == 1  # mandatory failures
    data = json.loads((out / "s.json").read_text())
    assert data["schema"] == "govcheck-site/1"
    by_id = {e["id"]: e for e in data["requirements"]}
    drift = by_id["SHPP-HOLD-DRIFT"]
    assert drift["basis"] == "measured" and drift["status"] == "fail"
    assert {r["run"] for r in drift["rows"]} == {"hold_1", "hold_2"}
    pred = drift["prediction"]
    # the nominal model has no leak: it predicts no drift and passes what the machine fails
    assert pred["status"] == "pass" and not pred["agree"] and not pred["verdicts_agree"]
    assert {d["run"] for d in pred["disagreeing"]} == {"hold_1", "hold_2"}
    assert data["summary"]["agreement"]["tests"][:2] == ["hold_1", "hold_2"]
    tclose = by_id["IEC61362-TCLOSE"]["prediction"]  # the 12 kN closing stroke: model and machine both fail it
    assert tclose["status"] == "fail" and tclose["low"] <= tclose["value"] <= tclose["high"]
    assert "<failure" in (out / "s.xml").read_text()


def test_gate_compares_two_site_results(site_json, tmp_path, capsys):
    _, out = site_json
    data = json.loads((out / "s.json").read_text())
    assert main(["gate", str(out / "s.json"), "--baseline", str(out / "s.json"), "-q"]) == 0
    for e in data["requirements"]:  # a baseline commissioning in which the drift passed
        if e["id"] == "SHPP-HOLD-DRIFT":
            e["status"] = "pass"
    (tmp_path / "before.json").write_text(json.dumps(data))
    capsys.readouterr()
    assert main(["gate", str(out / "s.json"), "--baseline", str(tmp_path / "before.json")]) == 1
    assert "SHPP-HOLD-DRIFT" in capsys.readouterr().out.splitlines()[-1]


def test_the_site_report_renders_from_the_json(site_json, tmp_path):
    from compliance.report.layout_check import html_problems
    from compliance.report.site.document import render_site_report

    _, out = site_json
    render_site_report(json.loads((out / "s.json").read_text()), html_path=tmp_path / "s.html")
    html = (tmp_path / "s.html").read_text()
    assert "Site acceptance report" in html and "hold_1" in html and not html_problems(html)
    assert "{&#39;" not in html  # the software-versions table lists versions, not a printed Python mapping


@pytest.mark.parametrize("argv, fragment", [
    (["accept", "no-such-site", "-r", "shpp-400kw", "--json", "s.json"], "not a folder"),
    (["accept", "empty", "-r", "shpp-400kw", "--json", "s.json"], "no recording found"),
    (["accept", "site", "-r", "shpp-400kw", "--json", "s.json", "--diagnose", "--no-prediction"], "--diagnose needs the prediction"),
])
def test_bad_input_is_one_message_and_exit_2_with_nothing_written(tmp_path, monkeypatch, capsys, argv, fragment):
    (tmp_path / "empty").mkdir()
    copy_site(tmp_path / "site", ["stroke_closing_12kN"])
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err
    assert not (tmp_path / "s.json").exists()


def test_the_diagnosis_names_the_test_the_physics_and_the_refit_agrees(tmp_path):
    """Site p2 fails its hold drift where the model passes: the joint diagnosis of the closed-loop recordings at
    the holds' load finds the external leak (emulator: 1e-9 kg/(s Pa)), and the refitted model predicts the drift."""
    from compliance.acceptance.run import accept
    from compliance.model.config import load_plant
    from compliance.requirements.loading import load_requirements

    r = accept(SITE, load_requirements("shpp-400kw"), load_plant("plant-a"), workers=2,
               diagnose={"effects": ["external_leakage", "internal_leakage"], "recalibrate": False})
    d = r["diagnosis"]
    assert d["targets"] == ["hold_1", "hold_2"] and d["winner"] == "external_leakage"
    assert d["recordings"] == ["steps_1-2pct_point2", "steps_5-10pct_point2"]  # closed loop, the holds' 12 kN
    k = d["fitted"][0]
    assert abs(k["value"] - 1e-9) <= 0.1e-9
    assert d["refit"] and all(x["agree"] for x in d["refit"])
    assert "hold_1" in d["text"] and "leak" in d["physics"]
