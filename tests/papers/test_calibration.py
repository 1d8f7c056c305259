"""Calibration to reported figures: recovers hidden parameters from the model's own figures; saves with provenance."""

from __future__ import annotations

import pytest

from compliance.campaign.run import plant_section
from compliance.model.config import load_plant
from compliance.papers.calibration import calibrate
from compliance.papers.calibration_objective import rows_of
from compliance.papers.calibration_report import save_calibrated
from compliance.model.parameters import apply, param_handle
from compliance.papers.calibration_table import UNSTATED
from compliance.papers.plant_a import DEFAULT_CONDITIONS, conditions_of

PREFIX = "calibrated to seed 000 figures"


def test_calibration_recovers_hidden_parameters_from_model_figures():
    """Figures generated with known throttle settings and valve saturation are fitted back from the published
    values. Tolerance 5 %: the compass search stops at 1/64 of the search range (1/128 decade for the log-scaled
    conductances, 1.8 %; 0.125 V of 8 V for the saturation voltage, 2.3 %)."""
    cfg = load_plant("plant-a")
    truth = {"flow_control.opening_conductance": 6.0e-9, "flow_control.closing_conductance": 5.0e-9,
             "valve.saturation_voltage": 5.5}
    rows = rows_of(apply(cfg, [param_handle(k, "test") for k in truth], truth.values()), DEFAULT_CONDITIONS)
    targets = {(r.test, r.metric): r.simulated for r in rows if r.paper is not None}
    table = tuple(u for u in UNSTATED if u.path in truth)
    cal = calibrate(cfg, workers=1, sobol_points=8, table=table, conditions=DEFAULT_CONDITIONS, profiles=False,
                    targets=targets, compass_iterations=12, starts=1)
    assert cal.cost_before > 10.0  # the published values are far from the hidden ones
    for key, value in truth.items():
        assert cal.values[key] == pytest.approx(value, rel=0.05), key


def test_calibrated_file_validates_and_records_provenance(tmp_path):
    cfg = load_plant("plant-a")
    table = tuple(u for u in UNSTATED if u.path == "valve.saturation_voltage")
    cal = calibrate(cfg, workers=1, sobol_points=2, table=table, profiles=False, compass_iterations=1, starts=1,
                    conditions={"fig9_sequence": "staircase", "full_stroke_start": "end_stop"})
    path = save_calibrated(cal, tmp_path / "plant-a-calibrated.toml")
    back = load_plant(path)
    assert back.name == "plant-a-calibrated"
    assert back.p("valve.saturation_voltage") == pytest.approx(cal.best.p("valve.saturation_voltage"))
    assert back.sources["valve.saturation_voltage"].startswith(PREFIX)
    assert back.sources["cylinder.stroke"] == "paper"  # what the paper states is not touched
    assert conditions_of(back) == {"fig9_sequence": "staircase", "full_stroke_start": "end_stop"}
    section = plant_section(back)
    assert "calibrated" in section["name"] and "calibrated" in section["description"]
    sources = {p["key"]: p["source"] for p in section["parameters"]}
    assert sources["valve.saturation_voltage"].startswith(PREFIX)
    assert section["provenance"]["calibrated_from"].startswith("plant-a")


def test_unknown_source_text_is_still_refused(tmp_path):
    from compliance.errors import InputError

    text = (tmp_path / "p.toml")
    src = load_plant("plant-a").path
    text.write_text(open(src).read().replace('source = "assumed" }', 'source = "guessed" }', 1))
    with pytest.raises(InputError, match="source"):
        load_plant(text)


def test_committed_calibrated_plant_records_what_changed():
    """models/plant-a-calibrated.toml: every fitted value (all that differ from plant A among them) says it was
    calibrated; the rest keeps its source; the test conditions and the null-flow effect's origin are recorded."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    base = load_plant(root / "models" / "plant-a.toml")
    cal = load_plant(root / "models" / "plant-a-calibrated.toml")
    changed = [k for k in base.params if abs(cal.params[k] - base.params[k]) > 1e-9 * max(1.0, abs(base.params[k]))]
    assert changed, "the calibration changed nothing"
    fitted = {u.path for u in UNSTATED}
    for k in base.params:
        if k in changed:
            assert cal.sources[k].startswith(PREFIX), k
        if k in fitted:  # a fitted value is calibrated even where the fit confirmed the published one
            assert cal.sources[k].startswith(PREFIX), k
        else:
            assert cal.sources[k] == base.sources[k], k
    for k in ("cylinder.stroke", "controller.kp", "controller.compensation_width", "valve.dead_zone_positive"):
        assert k not in changed  # stated by the paper
    assert set(conditions_of(cal)) == set(DEFAULT_CONDITIONS)
    assert all(f"condition_{c}" in cal.provenance for c in DEFAULT_CONDITIONS)
    if "valve_null_flow" in cal.effects:
        assert cal.provenance["effect_valve_null_flow"].startswith(PREFIX)


def test_unwritable_output_is_refused_before_any_work(capsys):
    from compliance.cli import main

    assert main(["reproduce", "plant-a", "--calibrate", "/proc/no-such-folder/plant.toml"]) == 2
    assert "does not exist (govcheck does not create folders)" in capsys.readouterr().err
