"""--reproducible / SOURCE_DATE_EPOCH: two identical runs give byte-identical JSON, JUnit and Markdown."""

from __future__ import annotations

import json

import pytest

from compliance.cli import main

REQS = """
schema = "govcheck-requirements/1"
name = "repro"
[operating_points.mid]
initial_position = "50 %stroke"
load = "none"
[procedures.s5]
kind = "steps"
size = "5 %stroke"
dwell = "2 s"
[requirements.TC]
title = "time constant"
clause = "clause unknown"
metric = "time_constant"
comparator = "within"
limit = ["0.10 s", "0.25 s"]
procedures = ["s5"]
operating_points = ["mid"]
"""


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("repro")
    (d / "req.toml").write_text(REQS)
    mp = pytest.MonkeyPatch()
    mp.chdir(d)
    mp.delenv("SOURCE_DATE_EPOCH", raising=False)
    codes = [main(["check", "plant-a", "-r", "req.toml", "--json", "a.json", "--junit", "a.xml", "-q", "-j", "1", "--reproducible"]),
             main(["check", "plant-a", "-r", "req.toml", "--json", "b.json", "--junit", "b.xml", "-q", "-j", "2", "--reproducible"])]
    mp.setenv("SOURCE_DATE_EPOCH", "1700000000")
    codes.append(main(["check", "plant-a", "-r", "req.toml", "--json", "c.json", "-q", "-j", "1"]))
    codes.append(main(["check", "plant-a", "-r", "req.toml", "--json", "d.json", "-q", "-j", "1"]))
    for name in ("e", "f"):
        codes.append(main(["gate", "plant-a", "--baseline", "a.json", "--markdown", f"{name}.md", "--json", f"{name}.json",
                           "-q", "-j", "1", "--reproducible"]))
    mp.undo()
    return d, codes


def test_check_json_and_junit_byte_identical(runs):
    d, codes = runs
    assert codes[:2] == [codes[0], codes[0]] and codes[0] in (0, 1)
    assert (d / "a.json").read_bytes() == (d / "b.json").read_bytes()
    assert (d / "a.xml").read_bytes() == (d / "b.xml").read_bytes()
    data = json.loads((d / "a.json").read_text())
    assert data["created"] == "1970-01-01T00:00:00+00:00" and data["reproducible"] is True
    assert "timing" not in data and all("wall_time" not in r for r in data["runs"])
    assert data["command_line"] == "govcheck check plant-a --requirements req.toml --quiet --reproducible"
    assert 'time="0.000"' in (d / "a.xml").read_text()


def test_source_date_epoch_alone(runs):
    d, _ = runs
    assert (d / "c.json").read_bytes() == (d / "d.json").read_bytes()
    assert json.loads((d / "c.json").read_text())["created"] == "2023-11-14T22:13:20+00:00"


def test_gate_markdown_and_json_byte_identical(runs):
    d, codes = runs
    assert codes[4] == codes[5] == 0
    assert (d / "e.md").read_bytes() == (d / "f.md").read_bytes()
    assert (d / "e.json").read_bytes() == (d / "f.json").read_bytes()


def test_validate_and_linear_json_byte_identical(tmp_path, monkeypatch):
    from tests.bad_inputs import workspace as W

    W.build(tmp_path)
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    for name in ("v1", "v2"):
        assert main(["validate", "plant.toml", "rec.csv", "--json", f"{name}.json", "-q", "--reproducible"]) == 0
    assert (tmp_path / "v1.json").read_bytes() == (tmp_path / "v2.json").read_bytes()
    for name in ("l1", "l2"):
        assert main(["linear", "plant.toml", "--json", f"{name}.json", "-q", "--reproducible"]) == 0
    assert (tmp_path / "l1.json").read_bytes() == (tmp_path / "l2.json").read_bytes()
