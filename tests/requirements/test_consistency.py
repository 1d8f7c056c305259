"""Requirement-set consistency: limits that cannot hold together are found before any simulation (issue 22)."""

import pytest

from compliance.cli import main
from compliance.requirements.consistency import CONFLICT, NARROWING, TENSION, consistency_findings
from compliance.requirements.loading import load_requirements

# the strict reading of IEEE 125 5.2.6 (20 ms peak speed on the small steps) beside the IEC 61362 window
STRICT = """
schema = "govcheck-requirements/1"
name = "strict"
[operating_points.mid]
initial_position = "50 %stroke"
load = "none"
[procedures.steps-5]
kind = "steps"
size = "5 %stroke"
[procedures.steps-10]
kind = "steps"
size = "10 %stroke"
[procedures.stroke]
kind = "full_stroke"
[requirements.TC]
title = "time constant"
clause = "IEC 61362:2024 (window as the plant paper quotes it)"
metric = "time_constant"
comparator = "within"
limit = ["0.10 s", "0.25 s"]
procedures = ["steps-5", "steps-10"]
operating_points = ["mid"]
[requirements.NOFASTER]
title = "peak speed"
clause = "IEEE Std 125-2007, 5.2.6"
metric = "max_speed"
comparator = "<="
limit = "20 %stroke/s"
procedures = ["steps-5", "steps-10", "stroke"]
operating_points = ["mid"]
[requirements.TOPEN]
title = "opening time"
clause = "clause unknown"
metric = "opening_time"
comparator = "within"
limit = ["4.75 s", "5.25 s"]
procedures = ["stroke"]
operating_points = ["mid"]
"""


@pytest.fixture()
def strict(tmp_path):
    p = tmp_path / "strict.toml"
    p.write_text(STRICT)
    return p


def test_findings_carry_the_arithmetic(strict):
    found = {(f["kind"], f["procedure"]): f for f in consistency_findings(load_requirements(strict), 0.160)}
    # 10 % of 160 mm = 16 mm: 0.632 x 16 mm / 0.25 s = 40.5 mm/s > 32 mm/s for ANY servo
    c = found[(CONFLICT, "steps-10")]
    assert "40.5 mm/s > 32.0 mm/s" in c["text"] and c["mandatory"]
    # 8 mm: the mean 20.2 mm/s fits, but a first-order answer starts at 8 mm / 0.25 s = 32 mm/s
    assert "32.0 mm/s >= 32.0 mm/s" in found[(TENSION, "steps-5")]["text"]
    assert (CONFLICT, "steps-5") not in found
    # a 4.75 s stroke moves at 33.7 mm/s: the window is narrowed to 5 s .. 5.25 s
    assert "admit only 5 s .. 5.25 s" in found[(NARROWING, "stroke")]["text"]


def test_shipped_files_have_no_conflict():
    for name in ("shpp-400kw", "iec61362", "ieee125", "iec60308"):
        kinds = {f["kind"] for f in consistency_findings(load_requirements(name), 0.160)}
        assert CONFLICT not in kinds and TENSION not in kinds, name


def test_check_refuses_a_conflicting_set_before_simulating(strict, tmp_path, capsys):
    out = tmp_path / "r.json"
    code = main(["check", "plant-a", "-r", str(strict), "--json", str(out), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and "contradicts itself" in err and "40.5 mm/s" in err and "--allow-conflicts" in err
    assert not out.exists()


def test_tau_window_against_the_stroke_rate_limit_across_procedures():
    """shpp-400kw judges the stroke rate (32 mm/s) on full strokes and tau <= 0.25 s on 16 mm steps: 0.632 x 16 mm /
    0.25 s = 40.5 mm/s, so the steps must run faster than the strokes may; a 32 mm/s rate limiter gives tau >= 0.316 s."""
    from compliance.requirements.consistency import RATE_SPLIT

    found = [f for f in consistency_findings(load_requirements("shpp-400kw"), 0.160) if f["kind"] == RATE_SPLIT]
    assert {(f["procedure"], tuple(f["requirements"])) for f in found if f["mandatory"]} == {
        ("steps-10", ("IEC61362-TC", "IEEE125-NOFASTER")), ("steps-10-down", ("IEC61362-TC", "IEEE125-NOFASTER"))}
    f = found[0]
    assert "40.5 mm/s > 32.0 mm/s" in f["text"] and "0.316 s > 0.25 s" in f["text"] and "valves out" in f["text"]


DISJOINT = """
schema = "govcheck-requirements/1"
name = "disjoint"
[operating_points.mid]
initial_position = "50 %stroke"
load = "none"
[operating_points.low]
initial_position = "20 %stroke"
load = "none"
[procedures.steps-5]
kind = "steps"
size = "5 %stroke"
[requirements.TC]
title = "time constant"
clause = "test"
metric = "time_constant"
comparator = "within"
limit = ["0.10 s", "0.25 s"]
procedures = ["steps-5"]
operating_points = ["mid"]
[requirements.TC-B]
title = "time constant, another purchaser"
clause = "test"
metric = "time_constant"
comparator = "within"
limit = ["0.30 s", "0.40 s"]
procedures = ["steps-5"]
operating_points = ["mid", "low"]
"""


def test_disjoint_windows_on_the_same_steps_are_a_conflict(tmp_path):
    p = tmp_path / "d.toml"
    p.write_text(DISJOINT, encoding="utf-8")
    found = consistency_findings(load_requirements(str(p)), 0.16)
    conflicts = [f for f in found if f["kind"] == CONFLICT]
    assert len(conflicts) == 1 and conflicts[0]["requirements"] == ["TC", "TC-B"]
    assert conflicts[0]["low"] == pytest.approx(0.30) and conflicts[0]["high"] == pytest.approx(0.25)
    assert "no value lies in both" in conflicts[0]["text"]


@pytest.mark.parametrize("edit, expected", [
    # overlapping windows narrow each other but admit values: no conflict
    (('["0.30 s", "0.40 s"]', '["0.20 s", "0.40 s"]'), 0),
    # a point shared only at the edge with both ends closed: the edge value passes both
    (('["0.30 s", "0.40 s"]', '["0.25 s", "0.40 s"]'), 0),
    # judged at different operating points only: no shared case, no conflict
    (('operating_points = ["mid", "low"]', 'operating_points = ["low"]'), 0),
    # an upper limit below the other's window: a conflict too
    (('comparator = "within"\nlimit = ["0.30 s", "0.40 s"]', 'comparator = "<="\nlimit = "0.05 s"'), 1),
])
def test_disjoint_windows_only_when_no_value_passes_both(tmp_path, edit, expected):
    p = tmp_path / "d.toml"
    p.write_text(DISJOINT.replace(*edit), encoding="utf-8")
    found = consistency_findings(load_requirements(str(p)), 0.16)
    assert len([f for f in found if f["kind"] == CONFLICT]) == expected
