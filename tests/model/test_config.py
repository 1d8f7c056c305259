"""Plant configuration files: units, validation messages, reference copies, CLI exit codes."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from compliance.cli import main
from compliance.model.config import load_plant, save_plant
from compliance.errors import InputError
from compliance.units import parse_quantity

ROOT = Path(__file__).resolve().parents[2]


def test_reference_sheet_values_in_si():
    cfg = load_plant(ROOT / "models" / "plant-a.toml")
    assert cfg.p("cylinder.stroke") == pytest.approx(0.160)
    assert cfg.piston_area == pytest.approx(1.22718e-2, rel=1e-5)  # reference-plant.md A_cap
    assert cfg.rod_side_area == pytest.approx(1.14676e-2, rel=1e-5)  # A_rod
    assert cfg.p("cylinder.dead_volume") == pytest.approx(98.17e-5)
    assert cfg.p("air.supply_pressure") == pytest.approx(8.0e5)  # "8.0 bar abs"
    assert cfg.p("valve.sonic_conductance") == pytest.approx(2.33e-8)  # 2.33 dm^3/(s*bar)
    assert cfg.p("controller.filter_cutoff") == pytest.approx(50.0)
    assert cfg.sources["cylinder.stroke"] == "paper"
    assert cfg.sources["friction.static_force"] == "assumed"
    xs, fs = cfg.load_curve
    assert xs[-1] == pytest.approx(0.160) and fs[4] == pytest.approx(12000.0)


def test_models_and_package_copies_identical():
    for f in (ROOT / "models").glob("*.toml"):
        packaged = ROOT / "compliance" / "data" / "plants" / f.name
        if packaged.exists():
            assert packaged.read_bytes() == f.read_bytes(), f"{f.name}: models/ and package data differ"
    assert (ROOT / "compliance" / "data" / "plants" / "plant-a.toml").exists()


def test_units_from_the_cached_definitions_read_as_pints_own(tmp_path):
    """The registry parses pint's definitions once into its disk cache; a registry read from that cache, and one
    made cold in a fresh folder (the first run on a machine), convert exactly as pint without a cache does."""
    import pint

    from compliance.units.quantities import _definitions_cache, registry

    cold = pint.UnitRegistry(autoconvert_offset_to_baseunit=True, cache_folder=str(tmp_path / "first"))
    plain = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    for text, unit in (("125 mm", "m"), ("8 bar", "Pa"), ("20 degC", "K"), ("3.5 l/min", "m^3/s"), ("12 kN", "N"),
                       ("0.7 psi", "Pa"), ("2.2e-9 m^3/(s*Pa)", "m^3/(s*Pa)"), ("45 ms", "s")):
        want = plain.Quantity(text).to(unit).magnitude
        assert registry().Quantity(text).to(unit).magnitude == want
        assert cold.Quantity(text).to(unit).magnitude == want
    folder = _definitions_cache(pint)
    assert folder is None or Path(folder).is_dir() and any(Path(folder).glob("*.pickle"))


def test_gauge_and_absolute_pressures():
    assert parse_quantity("7 bar gauge", "Pa", "x", pressure=True) == pytest.approx(7e5 + 101325.0)
    assert parse_quantity("8 bar abs", "Pa", "x", pressure=True) == pytest.approx(8e5)
    with pytest.raises(InputError, match="ambiguous"):
        parse_quantity("8 bar", "Pa", "x", pressure=True)


def _write(tmp_path, text, name="p.toml"):
    src = (ROOT / "models" / "plant-a.toml").read_text()
    p = tmp_path / name
    p.write_text(text(src))
    return p


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda s: s.replace('stroke = { value = "160 mm"', 'strok = { value = "160 mm"'), "unknown key 'strok'.*did you mean 'stroke'"),
        (lambda s: s.replace('"125 mm"', '"125 kg"'), "cylinder.piston_diameter.*expected one convertible to 'm'"),
        (lambda s: s.replace('"98.17e-5 m^3"', '"-1e-3 m^3"'), "cylinder.dead_volume.*not physical"),
        (lambda s: s.replace('"98.17e-5 m^3"', '"0 m^3"'), "cylinder.dead_volume.*not physical"),
        (lambda s: s.replace('"8.0 bar abs"', '"0.5 bar abs"'), "supply_pressure.*must be above"),
        (lambda s: s.replace('"8.0 bar abs"', '"8.0 bar"'), "ambiguous"),
        (lambda s: s.replace('moving_mass = { value = "30 kg", source = "paper" }\n', ""), "missing value cylinder.moving_mass"),
        (lambda s: s.replace('model = "lugre"', 'model = "lugr"'), "friction.model.*did you mean 'lugre'"),
        (lambda s: s + "\n[effects.heat_transfr]\nconductance = \"5 W/K\"\n", "heat_transfr.*did you mean 'heat_transfer'"),
        (lambda s: s + "\n[effects.heat_transfer]\nconductance = \"5 kg\"\n", "effects.heat_transfer.conductance"),
        (lambda s: s.replace("[cylinder]", "[cylinder\n"), "malformed TOML"),
        (lambda s: s.replace('source = "paper" }', 'source = "papr" }', 1), "source.*not one of"),
    ],
)
def test_bad_configuration_messages(tmp_path, edit, message):
    p = _write(tmp_path, edit)
    with pytest.raises(InputError, match=message) as exc:
        load_plant(p)
    assert str(p) in str(exc.value)


def test_cli_exit_code_2_on_bad_file(tmp_path, capsys):
    p = _write(tmp_path, lambda s: s.replace('"125 mm"', '"125 kg"'))
    code = main(["simulate", str(p), "--steps", "2%@0.1s", "--duration", "0.2", "-o", str(tmp_path / "o.csv")])
    assert code == 2
    err = capsys.readouterr().err
    assert "piston_diameter" in err and "Traceback" not in err
    assert not (tmp_path / "o.csv").exists()


def test_cli_unknown_plant_name(capsys):
    assert main(["simulate", "--plant", "plant-z", "--duration", "0.1", "-o", "/tmp/never.csv"]) == 2
    assert "plant-z" in capsys.readouterr().err


def test_save_roundtrip_and_no_overwrite(tmp_path):
    cfg = load_plant("plant-a").replace(effects={"internal_leakage": {"conductance": 2e-10}},
                                         provenance={"parent_digest": "abc", "recording": "r.csv"})
    out = save_plant(cfg, tmp_path / "fitted.toml")
    back = load_plant(out)
    for k, v in cfg.params.items():
        assert math.isclose(back.params[k], v, rel_tol=1e-12, abs_tol=1e-300), k
    assert back.effects["internal_leakage"]["conductance"] == pytest.approx(2e-10)
    assert back.provenance["parent_digest"] == "abc"
    with pytest.raises(InputError, match="exists already"):
        save_plant(cfg, out)


def test_simulate_cli_writes_csv(tmp_path):
    out = tmp_path / "run.csv"
    assert main(["simulate", "--plant", "plant-a", "--x0", "136 mm", "--load", "11.4 kN", "--steps", "2%@0.2s",
                 "--duration", "1", "-o", str(out)]) == 0
    import pandas as pd

    df = pd.read_csv(out)
    assert list(df.columns[:7]) == ["time", "position", "reference", "valve_command", "pressure_a", "pressure_b", "supply_pressure"]
    assert len(df) == 1001
    assert df.reference.iloc[-1] == pytest.approx(0.136 + 0.0032)


def test_a_saved_configuration_keeps_the_ranges_and_targets_of_the_values_it_did_not_change(tmp_path):
    """A remedy or a sized proposal written to a file keeps the plant file's declared ranges (its verdicts' bands)
    and derivation targets, except for the values it changed: those were stated about the old value."""
    cfg = load_plant("plant-a")
    ranged = {k for k, a in cfg.assumptions.items() if a.get("range")}
    derived = {k for k, a in cfg.assumptions.items() if a.get("derived_for")}
    assert {"valve.saturation_voltage", "friction.static_force"} <= ranged and derived
    moved = cfg.replace(params={"friction.static_force": 400.0, "controller.kp": 300.0})
    back = load_plant(save_plant(moved, tmp_path / "moved.toml"))
    assert set(back.assumptions) == set(cfg.assumptions) - {"friction.static_force"}
    for k in back.assumptions:
        a, b = cfg.assumptions[k], back.assumptions[k]
        assert b["derived_for"] == a["derived_for"]
        if a["range"]:
            assert b["range"]["note"] == a["range"]["note"]
            assert b["range"]["low"] == pytest.approx(a["range"]["low"], rel=1e-9)
            assert b["range"]["high"] == pytest.approx(a["range"]["high"], rel=1e-9)


def test_a_changed_design_does_not_carry_the_measurements_of_the_plant_it_came_from(tmp_path):
    """Plant A's paper measured plant A at its own gains and hardware: a configuration with any value changed
    (a remedy, a sized proposal) names no measurement, and its saved file none; an unchanged copy keeps them."""
    from compliance.model.config import load_plant, plant_to_toml

    cfg = load_plant("plant-a")
    assert cfg.model_evidence["paper"]  # plant A answers to its paper
    assert cfg.replace(name="copy").model_evidence["paper"] == cfg.model_evidence["paper"]
    same = cfg.replace(params={"controller.kp": cfg.params["controller.kp"]})
    assert same.model_evidence["paper"] == cfg.model_evidence["paper"]
    changed = cfg.replace(params={"controller.kp": 1.5 * cfg.params["controller.kp"]})
    assert changed.model_evidence["paper"] is None and changed.model_evidence["recordings"] == ()
    assert "[model_evidence]" not in plant_to_toml(changed) and "[model_evidence]" in plant_to_toml(cfg)
