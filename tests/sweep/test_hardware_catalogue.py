"""The hardware catalogue: validated at the edge, options become parameter values, the unmodelled named."""

from __future__ import annotations

from pathlib import Path

import pytest

from compliance.errors import InputError
from compliance.model.config import load_plant
from compliance.physics.valve_rating import conductance_of_rating, rating_of_conductance
from compliance.sweep.sizing.hardware_catalogue import load_catalogue

ROOT = Path(__file__).resolve().parents[2]


def test_shipped_catalogue_is_the_models_copy():
    assert (ROOT / "models/hardware-catalogue.toml").read_bytes() == (ROOT / "compliance/data/hardware/catalogue.toml").read_bytes()


def test_valve_rating_gives_plant_a_conductance():
    """700 NL/min at 6 bar gauge and 1 bar drop is plant A's derived C = 2.33 dm^3/(s*bar) (to its 3 digits)."""
    assert conductance_of_rating(700.0, 101300.0) == pytest.approx(2.33e-8, rel=0.005)
    assert rating_of_conductance(conductance_of_rating(1400.0, 101300.0), 101300.0) == pytest.approx(1400.0)


def test_options_set_parameters_and_unmodelled_ones_are_named():
    cat = load_catalogue()
    cfg = load_plant("plant-a")
    by = {o.name: o for o in cat.options}
    assert by["valve-1400"].values(cfg)["valve.sonic_conductance"] == pytest.approx(2 * 2.33e-8, rel=0.01)
    assert by["cylinders-160"].values(cfg) == {"cylinder.piston_diameter": 0.16, "cylinder.rod_diameter": 0.04}
    assert by["supply-9bar"].values(cfg)["air.supply_pressure"] == pytest.approx(9e5 + 101300.0)
    assert "supply_droop" in by["receiver-50l"].applies_to(cfg)  # plant A's ideal supply: no receiver to size
    assert {"meter-in-throttles", "exhaust-back-pressure-valve"} <= {n for n, _, _ in cat.not_modelled}
    assert set(cat.groups()) == {"servo_valve", "cylinder_bore", "supply_pressure", "air_receiver"}


@pytest.mark.parametrize("body, message", [
    ('[options.x]\ngroup = "servo_valve"\ntitle = "t"\ncost = 1\nvalve_rating = "700 L/min"', "NL/min"),
    ('[options.x]\ngroup = "gearbox"\ntitle = "t"\ncost = 1\nsets = { "cylinder.stroke" = "1 m" }', "gearbox"),
    ('[options.x]\ngroup = "cylinder_bore"\ntitle = "t"\ncost = 1\nsets = { "cylinder.bore" = "1 m" }', "cylinder.bore"),
    ('[options.x]\ngroup = "cylinder_bore"\ntitle = "t"\ncost = 1\nsets = { "cylinder.piston_diameter" = "1 s" }', "piston_diameter"),
    ('[options.x]\ngroup = "cylinder_bore"\ntitle = "t"\ncost = -1\nsets = { "cylinder.piston_diameter" = "1 m" }', "cost"),
])
def test_bad_catalogue_is_one_input_error(tmp_path, body, message):
    f = tmp_path / "cat.toml"
    f.write_text('schema = "govcheck-hardware/1"\n' + body + "\n")
    with pytest.raises(InputError, match=message):
        load_catalogue(f)
