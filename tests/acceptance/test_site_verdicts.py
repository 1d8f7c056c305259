"""A site judged by the requirement file: verdicts as the truth has them, coverage said, tests recognised or refused."""

from __future__ import annotations

import gzip
import re

import pytest

from compliance.acceptance.run import accept
from compliance.errors import InputError
from compliance.model.config import load_plant
from compliance.requirements.loading import load_requirements
from tests.acceptance.site_data import SITE, TRUTH, copy_site


@pytest.fixture(scope="module")
def judged():
    r = accept(SITE, load_requirements("shpp-400kw"), load_plant("plant-a"), predict=False)
    return r, {e["id"]: e for e in r["requirements"]}


def test_verdicts_of_the_tested_requirements_are_the_truths(judged):
    _, by_id = judged
    # the truth of site p2 (ANSWERS.json): its failing hold drift (external leakage), the closing time at 12 kN,
    # the time constant of the -2 % step at 128 mm (0.335 s); the positioning error passes
    for rid, status in {"IEC61362-TC": "fail", "IEC61362-TCLOSE": "fail", "IEEE125-TCLOSE": "fail",
                        "SHPP-HOLD-DRIFT": "fail", "IEC61362-POS": "pass", "SHPP-SURGE": "fail"}.items():
        assert by_id[rid]["status"] == status, (rid, by_id[rid]["worst"])
    tc = by_id["IEC61362-TC"]["worst"]
    step = next(s for s in TRUTH["tests"]["steps_1-2pct_point2"]["truth"]["steps"] if s["t_step_s"] == 10.0)
    assert tc["run"] == "steps_1-2pct_point2" and "10.00 s" in tc["which"]
    assert abs(tc["value"] - step["tau_cmd_s"]) <= tc["u"]
    assert by_id["SHPP-HOLD-DRIFT"]["worst"]["run"] == "hold_1"


def test_a_requirement_passed_on_part_of_its_cases_says_so(judged):
    r, by_id = judged
    pos = by_id["IEC61362-POS"]
    assert pos["status"] == "pass" and not pos["coverage"]["complete"]
    assert "steps-2@region1-closing" in pos["coverage"]["not_tested"]
    assert "IEC61362-POS" in r["summary"]["partial"]


def test_what_was_not_tested_is_not_evaluated_with_the_reason(judged):
    _, by_id = judged
    topen = by_id["IEC61362-TOPEN"]  # this reduced site has no opening stroke
    assert topen["status"] == "not_evaluated" and topen["rows"] == []
    assert "none of its 2 cases was tested" in topen["reason"]  # in service and dewatered (shpp-400kw)
    assert by_id["IEC61362-INDEP"]["status"] == "not_evaluated"
    hold_pos = by_id["SHPP-HOLD-POS"]  # the holds ran with the loop open: no closed-loop positioning error
    assert hold_pos["status"] == "not_evaluated"
    assert all("loop was open" in row["reason"] for row in hold_pos["rows"])
    assert any("valve at null" in d for row in hold_pos["rows"] for d in row["departures"])


def _sidecar(folder, name, edit):
    path = folder / f"{name}.toml"
    path.write_text(edit(path.read_text()))


def test_a_test_the_sidecar_does_not_name_is_recognised_from_its_trace(tmp_path):
    site = copy_site(tmp_path / "site", ["steps_1-2pct_point2", "stroke_closing_12kN"])
    for name in ("steps_1-2pct_point2", "stroke_closing_12kN"):
        _sidecar(site, name, lambda t: re.sub(r'^kind = ".*"\n', "", t, flags=re.M))
    r = accept(site, load_requirements("shpp-400kw"), load_plant("plant-a"), predict=False)
    recs = {x["name"]: x for x in r["site"]["recordings"]}
    assert recs["steps_1-2pct_point2"]["test"]["kind"] == "step_series"
    assert recs["stroke_closing_12kN"]["test"]["kind"] == "full_stroke"
    assert all("recognised from the trace" in x["test"]["notes"][0] for x in recs.values())
    tc = next(e for e in r["requirements"] if e["id"] == "IEC61362-TC")
    assert tc["status"] == "fail"  # the same verdict as from the stated test


def test_a_step_series_labelled_as_a_full_stroke_is_judged_as_neither(tmp_path):
    site = copy_site(tmp_path / "site", ["steps_1-2pct_point2"])
    _sidecar(site, "steps_1-2pct_point2",
             lambda t: t.replace('kind = "step_series"', 'kind = "full_stroke"').split("operating_position")[0]
             + 'direction = "closing"\n')
    r = accept(site, load_requirements("shpp-400kw"), load_plant("plant-a"), predict=False)
    rec = r["site"]["recordings"][0]
    assert "sidecar says full stroke but its trace shows a step series" in rec["problem"]
    # a closing stroke at a constant 12 kN is the file's stated variant (SHPP-TCLOSE-CONST), not the in-service case
    tclose = next(e for e in r["requirements"] if e["id"] == "SHPP-TCLOSE-CONST")
    assert tclose["status"] == "not_evaluated"
    assert "judged as neither" in tclose["rows"][0]["reason"]


def test_a_one_percent_step_logged_at_50_hz_cannot_give_a_dead_time(tmp_path):
    site = copy_site(tmp_path / "site", ["steps_1-2pct_point2"])
    src = site / "steps_1-2pct_point2.csv.gz"
    lines = [ln for ln in gzip.open(src, "rt").read().splitlines(keepends=True) if not ln.startswith("#")]
    src.unlink()
    (site / "steps_1-2pct_point2.csv").write_text(lines[0] + "".join(lines[1::10]))  # every 10th sample: 50 Hz
    r = accept(site, load_requirements("shpp-400kw"), load_plant("plant-a"), predict=False)
    first = r["site"]["recordings"][0]["cases"][0]
    assert first["values"]["dead_time"]["value"] is None
    assert "cannot support this dead time" in first["values"]["dead_time"]["reason"]
    assert "logged every 20.0 ms" in first["values"]["dead_time"]["reason"]


def test_a_misspelt_test_key_is_refused_with_the_close_match(tmp_path):
    site = copy_site(tmp_path / "site", ["hold_1"])
    _sidecar(site, "hold_1", lambda t: t.replace("window =", "windw ="))
    with pytest.raises(InputError, match=r"hold_1.toml: test.windw: unknown key; did you mean 'window'\?"):
        accept(site, load_requirements("shpp-400kw"), load_plant("plant-a"), predict=False)


def test_a_key_of_another_kind_names_its_kind(tmp_path):
    site = copy_site(tmp_path / "site", ["hold_1"])
    _sidecar(site, "hold_1", lambda t: t + "direction = \"closing\"\n")
    with pytest.raises(InputError, match="test.direction: belongs to a 'full_stroke' test, not to this 'hold' test"):
        accept(site, load_requirements("shpp-400kw"), load_plant("plant-a"), predict=False)
