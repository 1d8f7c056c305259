"""Plant-file ranges and derivation targets, read with units at the edge (issue 22)."""

import pytest

from compliance.errors import InputError
from compliance.model.config import load_plant

ROOT_PLANT = load_plant("plant-a")


def _with(tmp_path, old, new):
    src = open(ROOT_PLANT.path, encoding="utf-8").read()
    assert old in src
    p = tmp_path / "p.toml"
    p.write_text(src.replace(old, new), encoding="utf-8")
    return p


def test_plant_a_declares_ranges_and_the_throttle_targets():
    a = ROOT_PLANT.assumptions
    assert a["friction.static_force"]["range"]["low"] == pytest.approx(336.0)
    assert a["friction.static_force"]["range"]["high"] == pytest.approx(504.0)
    assert "20 %" in a["friction.static_force"]["range"]["note"]
    der = a["flow_control.closing_conductance"]["derived_for"]
    assert der["metric"] == "closing_time" and der["load"] == pytest.approx(5700.0)


@pytest.mark.parametrize("old,new,words", [
    ('static_force = { value = "420 N", source = "assumed", range = ["336 N", "504 N"]',
     'static_force = { value = "420 N", source = "assumed", range = ["436 N", "504 N"]', "must contain the value"),
    ('range = ["336 N", "504 N"], range_note = "seal friction of one cylinder type scatters by about +/-20 % with lubrication, temperature and wear (govcheck\'s range; no friction test of this unit)"',
     'range = ["336 N", "504 N"]', "range_note: missing"),
    ('range = ["336 N", "504 N"]', 'range = ["336 mm", "504 N"]', "friction.static_force.range"),
    ('derived_for = { metric = "closing_time", value = "5.0 s", load = "5.7 kN" }',
     'derived_for = { metric = "closing_time", at = "5.7 kN" }', "derived_for.at: unknown field"),
])
def test_bad_ranges_and_targets_name_the_key(tmp_path, old, new, words):
    with pytest.raises(InputError) as exc:
        load_plant(_with(tmp_path, old, new))
    assert words in str(exc.value) and "p.toml" in str(exc.value)
