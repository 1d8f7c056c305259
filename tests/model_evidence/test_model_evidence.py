"""The model's evidence beside the verdicts: the plant paper's measured figures and the recordings a plant file names.

Plant A as published leaves a dead-zone stall band of 0.61 V x 0.4 V / ((0.61 V + 0.4 V) x 280 V/m) = 0.863 mm,
where the paper measured steady errors of 0.24-0.32 mm: those figures must come out contradicted, with the
verdicts on positioning error resting on them. A recording the model itself made must agree; one made by a plant
whose valve dead zone is twice as wide must not.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from types import MappingProxyType, SimpleNamespace

import pytest

from compliance.errors import InputError
from compliance.model.config import load_plant, plant_from_dict
from compliance.model.toml_file import read_toml
from compliance.model_evidence import check_sources, model_evidence
from compliance.recordings.synth import synthesise, write_recording
from compliance.results import ModelEvidence

ROOT = Path(__file__).resolve().parents[2]
# the judged requirements of a check as model_evidence reads them (id, metric, comparator, status, severity)
_ENTRIES = [
    {"id": "POS", "title": "positioning error", "metric": "max_positioning_error", "comparator": "<=", "status": "pass",
     "severity": "mandatory"},
    {"id": "TRACK", "title": "tracking error", "metric": "tracking_max_error", "comparator": "<=", "status": "uncertain",
     "severity": "mandatory"},
    {"id": "TOPEN", "title": "opening time", "metric": "opening_time", "comparator": "within", "status": "pass",
     "severity": "mandatory"},
]
RESULT = SimpleNamespace(requirements=[SimpleNamespace(**e) for e in _ENTRIES])  # the verdicts' fields it reads


def _evidence(cfg) -> dict:
    """The section as its JSON has it, read back into its record and written again (it survives the round trip)."""
    ev = model_evidence(cfg, RESULT)
    data = json.loads(json.dumps(ev.as_dict()))
    assert ModelEvidence.from_dict(data) == ev
    return data


@pytest.fixture(scope="module")
def plant_a_evidence():
    cfg = load_plant(ROOT / "models" / "plant-a.toml")
    return _evidence(cfg)


def test_plant_a_is_contradicted_by_its_papers_steady_errors(plant_a_evidence):
    ev = plant_a_evidence
    assert ev["status"] == "contradicted" and not ev["validated"]
    paper = ev["sources"][0]
    assert paper["kind"] == "paper" and all(f["independent"] for f in paper["figures"])  # not fitted to them
    fig10 = next(f for f in paper["figures"] if f["test"] == "fig. 10, positive step" and f["metric"] == "steady error")
    stall = 0.61 * 0.4 / ((0.61 + 0.4) * 280.0) * 1e3  # mm: the compensated valve shuts inside this
    assert fig10["modelled"] == pytest.approx(stall, abs=0.05) and fig10["measured"] == pytest.approx(0.24)
    assert fig10["agreement"] == "contradicts" and "max_positioning_error" in fig10["bears_on"]
    # 16 measured figures count (the stroke times at 5.7 kN are the throttles' derivation target: by construction)
    assert ev["compared"] == 16 and paper["by_construction"] == 2
    assert {f["metric"] for f in paper["figures"] if f["by_construction"]} == {"opening time t_a", "closing time t_f"}
    assert ev["contradict"] >= 10  # settling times and steady errors of figs. 9-12, the peak speed, the tracking error
    assert any(x.startswith("steady error 0.") and "0.240 mm measured" in x for x in ev["examples"])


def test_the_verdicts_resting_on_contradicted_figures_say_which_way_the_model_errs(plant_a_evidence):
    by_id = {c["requirement"]: c for c in plant_a_evidence["contradicted"]}
    assert set(by_id) == {"POS", "TRACK"}  # the opening time agrees at 5.7 kN by construction: no evidence either way
    # the paper's tracking errors (0.5-0.8 % of the 160 mm stroke = 0.8-1.28 mm) lie under the modelled 1.61 mm
    track = by_id["TRACK"]
    assert track["direction"] == ["above"] and "pessimistic" in track["consequence"]
    assert "0.800\u20131.28 mm measured" in track["text"]
    assert by_id["POS"]["direction"] == ["above"]


def test_a_calibrated_plant_counts_only_the_figures_it_was_not_fitted_to():
    cfg = load_plant(ROOT / "models" / "plant-a-calibrated.toml")
    ev = _evidence(cfg)
    paper = ev["sources"][0]
    fitted = [f for f in paper["figures"] if not f["independent"]]
    assert fitted and all(f["metric"] not in ("max tracking error", "max steady error") for f in fitted)
    assert ev["compared"] == 2  # the paper's overall errors over steps and sinusoid (0.5-0.8 % of stroke)
    assert "calibrated" in paper["independence"]


def _plant_naming(tmp_path, recordings: list[str], paper: str | None = None):
    data, _ = read_toml(ROOT / "models" / "plant-a.toml")
    data["model_evidence"] = {"recordings": [{"path": r} for r in recordings], **({"paper": paper} if paper else {})}
    return plant_from_dict(data, str(tmp_path / "plant.toml"))


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    d = tmp_path_factory.mktemp("recs")
    plant = load_plant("plant-a")
    wide = plant.replace(params={"valve.dead_zone_positive": 1.2, "valve.dead_zone_negative": 1.3})
    for name, cfg in (("same.csv", plant), ("wide-dead-zone.csv", wide)):
        df, meta = synthesise(cfg, x0=0.06, load=7000.0, kd=6.0, noise=None, duration=8.0, profile_kind="steps")
        write_recording(df, meta, d / name)
    return d


def test_a_recording_the_model_made_validates_it(recordings):
    cfg = _plant_naming(recordings, ["same.csv"])  # relative to the plant file's folder
    ev = _evidence(cfg)
    rec = ev["sources"][0]
    assert ev["status"] == "validated" and ev["compared"] == 1 and ev["contradicted"] == []
    assert rec["agreement"] == "agrees" and all(m["pass"] for m in rec["modes"].values())
    assert rec["modes"]["closed_loop"]["fits"]["position"] > 99.9


def test_a_recording_of_a_wider_dead_zone_contradicts_the_positioning_verdicts(recordings):
    cfg = _plant_naming(recordings, ["same.csv", "wide-dead-zone.csv"])
    ev = _evidence(cfg)
    wide = ev["sources"][1]
    assert ev["status"] == "contradicted" and ev["compared"] == 2 and ev["contradict"] == 1
    assert wide["agreement"] == "contradicts" and "max_positioning_error" in wide["bears_on"]
    steady = [w for m in wide["modes"].values() for w in m["failed_windows"] if w["kind"] == "steady"]
    assert steady and all(w["signal"] in ("position", "valve_command", "pressure_a", "pressure_b") for w in steady)
    assert "POS" in {c["requirement"] for c in ev["contradicted"]}


def test_no_declared_source_is_not_validated_and_bad_declarations_are_refused(tmp_path):
    cfg = load_plant("plant-a")
    bare = dataclasses.replace(cfg, model_evidence=MappingProxyType({"paper": None, "recordings": ()}))
    ev = _evidence(bare)
    assert ev["status"] == "not validated" and ev["sources"] == [] and "names no measurement" in ev["summary"]
    with pytest.raises(InputError, match=r"model_evidence.recordings\[0\].path: .*missing.csv: file not found"):
        _plant_naming(tmp_path, ["missing.csv"])
    unknown = dataclasses.replace(cfg, model_evidence=MappingProxyType({"paper": "plant-z", "recordings": ()}))
    with pytest.raises(InputError, match="model_evidence.paper = 'plant-z'"):
        check_sources(unknown)
    data, _ = read_toml(ROOT / "models" / "plant-a.toml")
    data["model_evidence"] = {"papers": "plant-a"}
    with pytest.raises(InputError, match="model_evidence.papers: unknown key"):
        plant_from_dict(data, "x.toml")
