"""Optional [identity] table of a plant configuration: read, carried into the results, bad fields named."""

import pytest

from compliance.errors import InputError
from compliance.model.config import load_plant, plant_from_dict
from compliance.model.identity import identity_dict, parse_identity


def test_identity_is_optional_and_read_when_given():
    cfg = load_plant("plant-a")
    assert cfg.identity["site"].startswith("Reference SHPP")
    assert identity_dict(cfg.identity)["equipment"]["servo_valve"]["id"].startswith("1V1")
    assert dict(parse_identity(None, "x")) == {}


@pytest.mark.parametrize("raw, named", [({"serial": "1"}, "identity: unknown field 'serial'"),
                                        ({"equipment": {"valve": {"sn": "1"}}}, "identity.equipment.valve: unknown field 'sn'"),
                                        ({"site": ["a"]}, "identity.site: expected text")])
def test_bad_identity_fields_are_named(raw, named):
    with pytest.raises(InputError, match=named.replace(".", r"\.")):
        parse_identity(raw, "plant.toml")


def test_identity_does_not_change_the_physics():
    import tomllib
    from pathlib import Path

    data = tomllib.loads((Path(__file__).resolve().parents[2] / "models" / "plant-a.toml").read_text())
    bare = dict(data)
    bare.pop("identity")
    a, b = plant_from_dict(data, "<a>"), plant_from_dict(bare, "<b>")
    assert dict(a.params) == dict(b.params) and not b.identity
