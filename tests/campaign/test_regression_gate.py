"""The regression gate: comparison rules on synthetic results, then a degraded plant end to end."""

import json
from pathlib import Path

import pytest

from compliance.cli import main
from compliance.campaign.regression_gate import compare, gate_markdown
from tests.results.build import result, verdict

ROOT = Path(__file__).resolve().parents[2]

REQS = """
schema = "govcheck-requirements/1"
name = "gate-test"
[operating_points.mid]
initial_position = "50 %stroke"
load = "none"
[procedures.s5]
kind = "steps"
size = "5 %stroke"
dwell = "3 s"
[requirements.POS]
title = "positioning"
clause = "clause unknown"
metric = "max_positioning_error"
comparator = "<="
limit = "1 %stroke"
procedures = ["s5"]
operating_points = ["mid"]
[requirements.TC]
title = "time constant"
clause = "clause unknown"
metric = "time_constant"
comparator = "within"
limit = ["0.10 s", "0.25 s"]
procedures = ["s5"]
operating_points = ["mid"]
"""


def entry(rid, status, margin_pct, value=1.0):
    return verdict(rid, status, margin_pct, value)


def results(*entries, digest="d1"):
    return result(*entries, digest=digest)


def test_rules():
    base = results(entry("A", "pass", 40.0), entry("B", "pass", 10.0), entry("C", "fail", -5.0), entry("D", "pass", 30.0))
    same = compare(base, base, max_margin_loss=5)
    assert same["status"] == "pass" and same["tripped"] == []
    cand = results(entry("A", "pass", 33.0), entry("B", "fail", -1.0), entry("C", "fail", -50.0),
                   entry("E", "fail", -3.0))
    g = compare(base, cand, max_margin_loss=5)
    rows = {r["id"]: r for r in g["rows"]}
    assert rows["A"]["tripped"] and "margin lost 7.0 pp" in rows["A"]["reasons"][0]
    assert rows["B"]["tripped"] and "pass -> fail" in rows["B"]["reasons"]
    assert rows["C"]["preexisting_failure"] and rows["C"]["tripped"]  # still failing, but lost 45 pp
    assert rows["D"]["tripped"] and "removed" in rows["D"]["reasons"][0]
    assert rows["E"]["tripped"] and "new requirement fails" in rows["E"]["reasons"]
    assert g["status"] == "fail"
    # without a threshold only status changes count; a margin loss alone does not trip
    g = compare(base, results(entry("A", "pass", 1.0), entry("B", "pass", 10.0), entry("C", "fail", -90.0),
                              entry("D", "pass", 30.0)))
    assert g["status"] == "pass" and g["max_margin_loss"] is None
    # a pass that is no longer evaluated is a regression (a check must not silently stop)
    g = compare(base, results(entry("A", "not_evaluated", None), entry("B", "pass", 10.0), entry("C", "fail", -5.0),
                              entry("D", "pass", 30.0)))
    assert g["tripped"] == ["A"]
    # exactly at the threshold is allowed
    g = compare(base, results(entry("A", "pass", 35.0), entry("B", "pass", 10.0), entry("C", "fail", -5.0),
                              entry("D", "pass", 30.0)), max_margin_loss=5)
    assert g["status"] == "pass"


def test_markdown_is_a_table_with_the_verdict():
    base = results(entry("A", "pass", 40.0))
    md = gate_markdown(compare(base, results(entry("A", "fail", -10.0), digest="d2"), 5))
    assert md.startswith("### govcheck gate: FAILED - 1 regression(s)")
    assert "| `A` A | <= 1 | PASS 1.0 (+40.0 %) | FAIL 1.0 (-10.0 %) | -50.0 pp | **tripped**" in md
    assert "requirement files differ" in md


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("gate")
    (d / "reqs.toml").write_text(REQS)
    text = (ROOT / "models" / "plant-a.toml").read_text()
    assert 'kp = { value = "280 V/m"' in text
    (d / "half-kp.toml").write_text(text.replace('kp = { value = "280 V/m"', 'kp = { value = "140 V/m"'))
    assert main(["check", "plant-a", "-r", str(d / "reqs.toml"), "--json", str(d / "base.json"), "-q", "-j", "1"]) in (0, 1)
    return d


def test_halved_kp_trips_the_gate(files, capsys):
    """Halving K_P doubles the dead-zone stall error (zmd lc / ((zmd + lc) K_P): 0.86 -> 1.73 mm)."""
    d = files
    code = main(["gate", "--baseline", str(d / "base.json"), "--candidate", str(d / "half-kp.toml"),
                 "--max-margin-loss", "10", "--markdown", str(d / "gate.md"), "--json", str(d / "gate.json"), "-j", "1"])
    out = capsys.readouterr().out
    assert code == 1
    g = json.loads((d / "gate.json").read_text())
    assert g["status"] == "fail" and "POS" in g["tripped"]
    pos = {r["id"]: r for r in g["rows"]}["POS"]
    assert pos["candidate"]["value"] > pos["baseline"]["value"]
    assert "GATE: FAIL" in out and "POS" in (d / "gate.md").read_text()


def test_same_plant_passes_the_gate(files, capsys):
    d = files
    assert main(["gate", "--baseline", str(d / "base.json"), "--candidate", "plant-a", "--max-margin-loss", "0", "-q", "-j", "1"]) == 0
    assert capsys.readouterr().out.strip() == "GATE: PASS"
    # two results files compare without running anything
    assert main(["gate", "--baseline", str(d / "base.json"), "--candidate", str(d / "base.json"), "-q"]) == 0
    # a compressed results file (as a sweep stores its best candidate) is a results file too, not a plant
    import gzip

    packed = d / "base.json.gz"
    packed.write_bytes(gzip.compress((d / "base.json").read_bytes()))
    assert main(["gate", "--baseline", str(packed), "--candidate", str(d / "base.json"), "-q"]) == 0


def test_gate_bad_inputs(files, tmp_path, capsys):
    d = files
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"schema": "something-else"}))
    assert main(["gate", "--baseline", str(bad), "--candidate", "plant-a"]) == 2
    assert "schema" in capsys.readouterr().err
    (tmp_path / "broken.json").write_text("{not json")
    assert main(["gate", "--baseline", str(tmp_path / "broken.json"), "--candidate", "plant-a"]) == 2
    assert main(["gate", "--baseline", "plant-a", "--candidate", "plant-a"]) == 2  # no requirement file
    assert "--requirements is needed" in capsys.readouterr().err
    assert main(["gate", "--baseline", str(d / "base.json"), "--candidate", "plant-a", "--max-margin-loss", "-1"]) == 2


def test_uncertain_baseline_that_fails_in_the_candidate_trips_and_no_fail_reads_ok():
    """A baseline whose band straddles the limit may pass; a candidate failing outright is a regression, and a
    failing candidate row is never labelled 'ok'."""
    from compliance.campaign.regression_gate import gate_table

    base = results(entry("A", "uncertain", 5.0), entry("B", "not_evaluated", None), entry("C", "uncertain", 2.0))
    cand = results(entry("A", "fail", -5.0), entry("B", "fail", -3.0), entry("C", "uncertain", 1.0))
    g = compare(base, cand)
    rows = {r["id"]: r for r in g["rows"]}
    assert rows["A"]["tripped"] and "uncertain -> fail" in rows["A"]["reasons"][0]
    assert not rows["B"]["tripped"] and not rows["C"]["tripped"]
    table = gate_table(g)
    line_b = next(line for line in table.splitlines() if line.startswith("B "))
    assert " ok" not in line_b and "candidate fails" in line_b
    assert "candidate uncertain" in next(line for line in table.splitlines() if line.startswith("C "))
