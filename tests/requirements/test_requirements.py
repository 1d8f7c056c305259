"""Requirement files: the shipped ones, extending and tightening, and every kind of bad input."""

import filecmp
from pathlib import Path

import pytest

from compliance.cli import main
from compliance.errors import InputError
from compliance.files.shipped import shipped_names
from compliance.requirements.loading import check_tightening, load_requirements

ROOT = Path(__file__).resolve().parents[2]
STROKE = 0.160

MINIMAL = """
schema = "govcheck-requirements/1"
name = "mine"
[operating_points.mid]
initial_position = "50 %stroke"
[procedures.s5]
kind = "steps"
size = "5 %stroke"
[requirements.R1]
title = "time constant"
clause = "clause unknown"
metric = "time_constant"
comparator = "within"
limit = ["0.10 s", "0.25 s"]
procedures = ["s5"]
operating_points = ["mid"]
"""


def write(tmp_path, text, name="mine.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_shipped_files_are_identical_to_package_data():
    shipped = sorted(p.name for p in (ROOT / "requirements").glob("*.toml"))
    data = sorted(p.name for p in (ROOT / "compliance" / "data" / "requirements").glob("*.toml"))
    assert shipped == data == ["iec60308.toml", "iec61362.toml", "ieee125.toml", "shpp-400kw.toml", "tracking-robot.toml"]
    for n in shipped:
        assert filecmp.cmp(ROOT / "requirements" / n, ROOT / "compliance" / "data" / "requirements" / n, shallow=False), n
    assert shipped_names("requirements") == [n[:-5] for n in shipped]


@pytest.mark.parametrize("name", ["iec60308", "iec61362", "ieee125", "shpp-400kw"])
def test_shipped_files_load_with_clause_and_severity(name):
    rs = load_requirements(name)
    for r in rs.requirements:
        assert r.clause and r.severity in ("mandatory", "advisory")
        check_tightening(r, STROKE)  # the shipped files only tighten


def test_shpp_limits_in_si():
    rs = load_requirements(ROOT / "requirements" / "shpp-400kw.toml")
    req = {r.id: r for r in rs.requirements}
    assert req["IEC61362-POS"].resolved_limit(STROKE) == (pytest.approx(0.0016),)
    assert req["IEC61362-TC"].resolved_limit(STROKE) == (pytest.approx(0.10), pytest.approx(0.25))
    assert req["IEC61362-TOPEN"].resolved_limit(STROKE) == (pytest.approx(4.75), pytest.approx(5.25))
    assert req["IEEE125-NOFASTER"].resolved_limit(STROKE) == (pytest.approx(0.032),)
    assert rs.operating_points["region1-opening"].load == pytest.approx(-2300.0)
    assert rs.operating_points["curve-mid"].load == "curve"
    assert rs.operating_points["region2-80"].initial_position.resolve(STROKE) == pytest.approx(0.128)
    # the chain is recorded base first, with digests
    assert [Path(p).name for p, _ in rs.files] == ["iec60308.toml", "iec61362.toml", "ieee125.toml", "shpp-400kw.toml"]
    assert all(len(d) == 64 for _, d in rs.files)
    # inherited requirement keeps the standard it came from
    assert req["IEC61362-TC"].standard == "IEC 61362" and req["SHPP-TRACK"].standard == "SHPP-400kW"


def test_extend_by_name_and_path_and_tighten(tmp_path):
    user = write(tmp_path, 'extends = "iec61362"\n[requirements.IEC61362-TC]\nlimit = ["0.10 s", "0.20 s"]\n')
    rs = load_requirements(user)
    tc = {r.id: r for r in rs.requirements}["IEC61362-TC"]
    assert tc.resolved_limit(STROKE) == (pytest.approx(0.10), pytest.approx(0.20))
    assert check_tightening(tc, STROKE) == []
    # by path, relative to the extending file
    write(tmp_path, MINIMAL, "base.toml")
    child = write(tmp_path, 'extends = "base.toml"\n[requirements.R1]\nlimit = ["120 ms", "200 ms"]\n', "child.toml")
    r1 = load_requirements(child).requirements[0]
    assert r1.resolved_limit(STROKE) == (pytest.approx(0.12), pytest.approx(0.2))
    assert check_tightening(r1, STROKE) == []
    # dropping the lower bound is not a tightening even if the upper bound comes down
    child = write(tmp_path, 'extends = "base.toml"\n[requirements.R1]\ncomparator = "<="\nlimit = "200 ms"\n', "child.toml")
    with pytest.raises(InputError, match="widens the limit from 0.10 s .. 0.25 s to <= 200 ms"):
        check_tightening(load_requirements(child).requirements[0], STROKE)


def test_loosening_needs_allow_loosen(tmp_path):
    user = write(tmp_path, 'extends = "iec61362"\n[requirements.IEC61362-TC]\nlimit = ["0.05 s", "0.30 s"]\n')
    tc = {r.id: r for r in load_requirements(user).requirements}["IEC61362-TC"]
    with pytest.raises(InputError, match=r"mine.toml: requirements.IEC61362-TC: widens the limit .*allow_loosen"):
        check_tightening(tc, STROKE)
    user = write(tmp_path, 'extends = "iec61362"\n[requirements.IEC61362-TC]\nlimit = ["0.05 s", "0.30 s"]\nallow_loosen = true\n')
    tc = {r.id: r for r in load_requirements(user).requirements}["IEC61362-TC"]
    notes = check_tightening(tc, STROKE)
    assert len(notes) == 1 and notes[0].startswith("LOOSENED")
    # lowering the severity or disabling is loosening too
    user = write(tmp_path, 'extends = "iec61362"\n[requirements.IEC61362-TC]\nseverity = "advisory"\n')
    with pytest.raises(InputError, match="lowers the severity"):
        check_tightening({r.id: r for r in load_requirements(user).requirements}["IEC61362-TC"], STROKE)
    user = write(tmp_path, 'extends = "iec61362"\n[requirements.IEC61362-TC]\nenabled = false\n')
    with pytest.raises(InputError, match="disables it"):
        check_tightening({r.id: r for r in load_requirements(user).requirements}["IEC61362-TC"], STROKE)
    # a %stroke limit against an absolute one is compared on the plant's stroke: 1 %stroke -> 2 mm widens
    user = write(tmp_path, 'extends = "shpp-400kw"\n[requirements.IEC61362-POS]\nlimit = "2 mm"\n')
    with pytest.raises(InputError, match="widens the limit from <= 1 %stroke to <= 2 mm"):
        check_tightening({r.id: r for r in load_requirements(user).requirements}["IEC61362-POS"], STROKE)


BAD = [
    # (replace this, with that, message pattern)
    ('comparator = "within"', 'comparater = "within"', r"mine.toml: requirements.R1.comparater: unknown key 'comparater'; did you mean 'comparator'\?"),
    ('limit = ["0.10 s", "0.25 s"]', 'limit = ["0.10 kg", "0.25 s"]', r"requirements.R1.limit: '0.10 kg' has unit 'kilogram', expected one convertible to 's'"),
    ('limit = ["0.10 s", "0.25 s"]', 'limit = [0.10, 0.25]', r"requirements.R1.limit: expected a string with a unit such as '1.6 mm'"),
    ('limit = ["0.10 s", "0.25 s"]', 'limit = "0.25 s"', r"'within' needs limit = \[low, high\]"),
    ('limit = ["0.10 s", "0.25 s"]', 'limit = ["0.25 s", "0.10 s"]', r"low limit 0.25 s is above high limit 0.10 s"),
    ('limit = ["0.10 s", "0.25 s"]', 'limit = ["1 %stroke", "2 %stroke"]', r"'%stroke' applies to positions and speeds"),
    ('metric = "time_constant"', 'metric = "time_constsnt"', r"requirements.R1.metric: 'time_constsnt' is not one of .*did you mean 'time_constant'\?"),
    ('procedures = ["s5"]', 'procedures = ["s6"]', r"requirements.R1.procedures: procedure 's6' is not declared"),
    ('operating_points = ["mid"]', 'operating_points = ["middle"]', r"operating point 'middle' is not declared; did you mean 'mid'\?"),
    ('size = "5 %stroke"', 'size = "5"', r"procedures.s5.size: '5' has no unit"),
    ('size = "5 %stroke"', 'size = "5 %stroke"\nduration = "3 s"', r"procedures.s5.duration: unknown setting for a 'steps' procedure"),
    ('kind = "steps"', 'kind = "step"', r"procedures.s5.kind: 'step' is not a procedure kind; did you mean 'steps'\?"),
    ('initial_position = "50 %stroke"', 'initial_position = "50 %stroke"\nlaod = "1 kN"', r"operating_points.mid.laod: unknown key 'laod'; did you mean 'load'\?"),
    ('initial_position = "50 %stroke"', 'initial_position = "50 %stroke"\nload = "1 kg"', r"operating_points.mid.load: '1 kg' has unit 'kilogram', expected one convertible to 'N'"),
    ('metric = "time_constant"', 'metric = "opening_time"', r"metric 'opening_time' cannot be measured by procedure 's5' of kind 'steps'"),
    ('metric = "time_constant"', 'metric = "dead_band"', r"requirements.R1.limit: '0.10 s' has unit 'second', expected one convertible to 'm'"),
    ('schema = "govcheck-requirements/1"', 'schema = "govcheck-requirements/9"', r"schema: 'govcheck-requirements/9' is not supported"),
    ('title = "time constant"\n', '', r"requirements.R1: missing 'title'"),
    ('clause = "clause unknown"\n', '', r"requirements.R1: missing 'clause'"),
    ('comparator = "within"', 'comparator = "=="', r"requirements.R1.comparator: '==' is not one of"),
    ('[requirements.R1]', '[requirements.R1]\noptions = { settling_band = "2 %" }', r"requirements.R1.options.settling_band: metric 'time_constant' takes no option 'settling_band'"),
    ('name = "mine"', 'name = "mine"\nextends = "iec6136"', r"'iec6136' is neither a file nor a reference requirement file; did you mean 'iec61362'\?"),
    ('name = "mine"', 'name = "mine"\n[extra', r"mine.toml: malformed TOML"),
]


@pytest.mark.parametrize("old,new,pattern", BAD)
def test_schema_errors_name_file_and_key(tmp_path, old, new, pattern):
    assert old in MINIMAL
    p = write(tmp_path, MINIMAL.replace(old, new, 1))
    with pytest.raises(InputError, match=pattern):
        load_requirements(p)


def test_extends_cycle_and_no_requirements(tmp_path):
    write(tmp_path, 'extends = "b.toml"\n' + MINIMAL, "a.toml")
    write(tmp_path, 'extends = "a.toml"\n', "b.toml")
    with pytest.raises(InputError, match="extends itself"):
        load_requirements(tmp_path / "a.toml")
    with pytest.raises(InputError, match="declares no requirements"):
        load_requirements(write(tmp_path, 'name = "empty"\n', "empty.toml"))


def test_cli_bad_requirement_file_exits_2(tmp_path, capsys):
    p = write(tmp_path, MINIMAL.replace('comparator = "within"', 'comparater = "within"'))
    assert main(["check", "plant-a", "--requirements", str(p)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("govcheck check: error: ") and "comparater" in err and "Traceback" not in err
    assert main(["check", "plant-a", "--requirements", str(tmp_path / "nope.toml")]) == 2
    assert "not found" in capsys.readouterr().err
