"""The typed result and its JSON: what a check's campaign writes is what ``CheckResult`` writes, byte for byte,
and a results file read and written again is the same file (schema govcheck-results/1 unchanged)."""

import dataclasses
import json
from pathlib import Path

import pytest

from compliance.campaign.run import run_campaign
from compliance.files.jsonable import json_text
from compliance.model.config import load_plant
from compliance.requirements.loading import load_requirements
from compliance.requirements.verdict import Basis, Overall, Severity, Status
from compliance.results import CheckResult, Qualifier, RequestKey, VerdictRow

SMALL_A = """
schema = "govcheck-requirements/1"
name = "small-a"
[operating_points.mid]
initial_position = "50 %stroke"
load = "none"
[operating_points.high]
initial_position = "120 mm"
load = "5.7 kN"
[procedures.s5]
kind = "steps"
size = "5 %stroke"
dwell = "3 s"
[requirements.TC]
title = "time constant"
clause = "clause unknown"
metric = "time_constant"
comparator = "within"
limit = ["0.10 s", "0.25 s"]
procedures = ["s5"]
operating_points = ["mid", "high"]
[requirements.POS]
title = "positioning"
clause = "assumed design target"
metric = "max_positioning_error"
comparator = "<="
limit = "1 %stroke"
procedures = ["s5"]
operating_points = ["mid"]
[requirements.DT]
title = "dead time"
clause = "clause unknown"
metric = "dead_time"
comparator = "<="
limit = "purchaser"
procedures = ["s5"]
operating_points = ["mid"]
[requirements.DT.options]
detect = "0.5 %stroke"
"""


@pytest.fixture(scope="module")
def plant_a(tmp_path_factory):
    p = tmp_path_factory.mktemp("small") / "small-a.toml"
    p.write_text(SMALL_A)
    return run_campaign(load_plant("plant-a"), load_requirements(p), workers=1, progress=False, uncertainty="local")


@pytest.fixture(scope="module")
def plant_b():
    return run_campaign(load_plant("plant-b"), load_requirements("tracking-robot"), workers=1, progress=False)


@pytest.mark.parametrize("name", ["plant_a", "plant_b"])
def test_the_typed_result_writes_the_campaign_json_byte_for_byte(name, request, tmp_path):
    results = request.getfixturevalue(name)
    text = json_text(results, compact=True)
    typed = CheckResult.of(results)
    assert typed.json_text() == text
    typed.to_json(tmp_path / "r.json")
    again = CheckResult.from_json(tmp_path / "r.json")
    assert again.json_text() == text == (tmp_path / "r.json").read_text()
    assert again == typed  # the records compare equal field by field
    assert not again.extra and all(not e.extra for e in again.requirement_set.requirements)  # every key is typed


def test_rows_carry_si_values_enums_and_tuple_keys(plant_a):
    res = CheckResult.of(plant_a)
    stroke = res.plant.stroke
    ops = res.requirement_set.operating_points
    assert ops["mid"].position == pytest.approx(0.5 * stroke, abs=1e-12)  # "50 %stroke" resolved, not re-parsed later
    assert ops["high"].position == pytest.approx(0.120, abs=1e-12) and ops["high"].load_force == pytest.approx(5700.0)
    tc = res.verdicts["TC"]
    assert tc.severity is Severity.MANDATORY and isinstance(tc.status, Status) and isinstance(tc.basis, Basis)
    assert tc.limit == pytest.approx((0.10, 0.25)) and all(isinstance(r, VerdictRow) for r in tc.rows)
    assert {r.operating_point for r in tc.rows} == {"mid", "high"}
    dt = res.verdicts["DT"]
    assert dt.request_key == RequestKey("dead_time", (("detect", "0.5 %stroke"),))
    assert str(dt.request_key) == "dead_time[detect=0.5 %stroke]" == plant_a["requirements"][2]["request_key"]
    assert dt.open and dt.status is Status.OPEN
    run = res.run("s5@mid")
    assert run.samples(dt.request_key) and run.samples("time_constant")[0].value > 0
    assert res.summary.status in tuple(Overall)


def test_the_qualifier_is_an_enum_joined_in_the_json(plant_b):
    res = CheckResult.of(plant_b)
    assert res.summary.qualifiers == (Qualifier.ASSUMED_TARGETS, Qualifier.ASSUMED_MODEL)
    assert res.as_dict()["summary"]["qualifier"] == "against assumed targets, on a mostly assumed model"


def test_a_result_is_frozen(plant_a):
    res = CheckResult.of(plant_a)
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.summary = None
    with pytest.raises(TypeError):
        res.runs[0].traces[0]["label"] = "edited"  # the sections kept as written are read-only too
    assert res.with_(linear={"schema": "govcheck-linear/1"}).linear["schema"] == "govcheck-linear/1" and res.linear is None


def test_request_key_text_form_round_trips():
    for text in ("time_constant", "time_constant[detect=1 %stroke,settling_band=2 %]", "x[a=1,2]"):
        assert str(RequestKey.parse(text)) == text
    assert RequestKey.of("dead_time", {"detect": "0.5 %stroke"}) == RequestKey.parse("dead_time[detect=0.5 %stroke]")


def test_a_damaged_file_is_named_not_crashed_on(plant_a, tmp_path):
    from compliance.errors import InputError

    data = json.loads(json_text(plant_a, compact=True))
    data["requirements"][0]["rows"][0]["status"] = "passed"
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(data))
    with pytest.raises(InputError, match=r"requirements\[0\]\.rows\[0\]\.status: 'passed' is not one of"):
        CheckResult.from_json(p)
    del data["requirements"][0]["rows"]
    p.write_text(json.dumps(data))
    with pytest.raises(InputError, match="'rows' is missing"):
        CheckResult.from_json(p)
    assert Path(p).exists()


def test_a_compressed_results_file_is_the_same_result(plant_a, tmp_path):
    """``.json.gz`` (a sweep's best candidate, traces and all) holds the same JSON, the same bytes every time,
    and a truncated one is named, not crashed on."""
    import gzip

    from compliance.errors import InputError

    typed = CheckResult.of(plant_a)
    typed.to_json(tmp_path / "r.json.gz")
    first = (tmp_path / "r.json.gz").read_bytes()
    assert gzip.decompress(first).decode() == typed.json_text()
    assert CheckResult.from_json(tmp_path / "r.json.gz") == typed
    typed.to_json(tmp_path / "r.json.gz")
    assert (tmp_path / "r.json.gz").read_bytes() == first  # no timestamp in the gzip header
    (tmp_path / "cut.json.gz").write_bytes(first[: len(first) // 2])
    with pytest.raises(InputError, match=r"cut\.json\.gz: not a JSON results file"):
        CheckResult.from_json(tmp_path / "cut.json.gz")
