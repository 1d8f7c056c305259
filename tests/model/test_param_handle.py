"""The one parameter handle: one canonical path from any spelling, declared bounds and scale, apply."""

from __future__ import annotations

import math

import pytest

from compliance.effects import EFFECTS
from compliance.errors import InputError
from compliance.model.config import load_plant
from compliance.model.parameters import BASE_BY_KEY, ParamHandle, apply, param_handle
from compliance.sweep.candidates.spec import load_sweep

LEAK = "effects.internal_leakage.conductance"


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def test_every_spelling_gives_the_same_handle():
    long, short = param_handle(LEAK, "t"), param_handle("internal_leakage.conductance", "t")
    assert long == short and hash(long) == hash(short)
    assert long.path == LEAK  # canonical: the key path of a plant file
    assert (long.kind, long.effect, long.name, long.key) == ("effect", "internal_leakage", "conductance",
                                                             "internal_leakage.conductance")
    kp = param_handle("controller.kp", "t")
    assert (kp.path, kp.key, kp.kind, kp.effect) == ("controller.kp", "controller.kp", "base", None)


def test_bounds_unit_and_scale_are_the_declarations():
    leak = param_handle(LEAK, "t")
    decl = EFFECTS["internal_leakage"].param("conductance")
    assert (leak.unit, (leak.low, leak.high), leak.log, leak.nominal) == (decl.unit, decl.bounds, decl.log_scale, decl.default)
    supply = param_handle("air.supply_pressure", "t")
    assert supply.pressure and (supply.low, supply.high) == BASE_BY_KEY["air.supply_pressure"].bounds
    # log scale: the geometric middle of 1e-13 .. 1e-8 kg/(s*Pa) is the middle of the search coordinate
    assert leak.to_unit(10 ** -10.5) == pytest.approx(0.5, abs=1e-12)
    assert leak.from_unit(0.25) == pytest.approx(10 ** -11.75, rel=1e-12)
    # a narrowed handle keeps its identity and says why
    narrow = leak.within(1e-11, 1e-9, reason="bench")
    assert (narrow.path, narrow.low, narrow.high, narrow.log, narrow.reason) == (LEAK, 1e-11, 1e-9, True, "bench")
    assert narrow.from_unit(0.5) == pytest.approx(1e-10, rel=1e-12)
    lin = param_handle("controller.kp", "t").within(100.0, 500.0)
    assert lin.to_unit(200.0) == pytest.approx(0.25) and lin.from_unit(2.0) == 500.0  # clipped to the bounds


def test_apply_sets_what_the_three_old_appliers_set(cfg):
    kp, leak, static = (param_handle(p, "t") for p in ("controller.kp", LEAK, "friction.static_force"))
    got = apply(cfg, (kp, leak), (400.0, 2e-10))
    # as the sweep and the diagnosis did: base value set (source user), effect switched on at its defaults
    want = cfg.replace(params={"controller.kp": 400.0}, effects={"internal_leakage": {"conductance": 2e-10}})
    assert dict(got.params) == dict(want.params) and dict(got.sources) == dict(want.sources)
    assert {k: dict(v) for k, v in got.effects.items()} == {k: dict(v) for k, v in want.effects.items()}
    assert kp.value_in(got) == 400.0 and leak.value_in(got) == 2e-10
    assert leak.value_in(cfg) == EFFECTS["internal_leakage"].param("conductance").default  # off: its default
    # as the calibration did: the source of every base value set is given
    cal = apply(cfg, (static,), (cfg.p("friction.static_force") * 1.1,), source="calibrated")
    assert cal.sources["friction.static_force"] == "calibrated" and cal.p("friction.static_force") == pytest.approx(
        1.1 * cfg.p("friction.static_force"), rel=1e-15)
    # as the diagnosis did: one factor on the static and Coulomb forces; instrument handles are not plant values
    level = ParamHandle("friction.level", "", 0.25, 4.0, True, scales=("friction.static_force", "friction.coulomb_force"))
    gauge = ParamHandle("instrument:pressure_gain.pressure_a", "", 0.9, 1.1, kind="instrument", nominal=1.0)
    both = apply(cfg, (level, gauge), (1.5, 1.05))
    assert both.p("friction.static_force") == pytest.approx(1.5 * cfg.p("friction.static_force"), rel=1e-15)
    assert both.p("friction.coulomb_force") == pytest.approx(1.5 * cfg.p("friction.coulomb_force"), rel=1e-15)
    assert apply(cfg, (gauge,), (1.05,)) is cfg  # nothing set on the plant
    assert leak.apply(cfg, 3e-10).effects["internal_leakage"]["conductance"] == 3e-10


def test_prior_and_standard_error_follow_the_scale():
    h = param_handle("cylinder.moving_mass", "t").within(5.0, 300.0, log=True)
    from dataclasses import replace

    h = replace(h, nominal=40.0, prior=True)
    assert h.prior_residual(80.0) == pytest.approx(1.0)  # a factor of 2 is one prior standard deviation
    # d value / d u of a log coordinate: value * ln 10 * decades spanned
    assert h.stderr(40.0, 0.01) == pytest.approx(40.0 * math.log(10.0) * math.log10(60.0) * 0.01)


@pytest.mark.parametrize("path, words", [
    ("effects.internal_leakge.conductance", "did you mean 'internal_leakage'"),
    ("internal_leakage.conductanse", "effect internal_leakage has no parameter 'conductanse'"),
    ("controller.kpp", "did you mean 'controller.kp'"),
    ("internal_leakge.conductance", "did you mean 'effects.internal_leakage.conductance'"),
    ("valve.power_law_c1", "bare power-law coefficient"),
])
def test_a_wrong_path_is_one_message_naming_where(path, words):
    with pytest.raises(InputError) as err:
        param_handle(path, "s.toml: adjust")
    assert str(err.value).startswith("s.toml: adjust: ") and words in str(err.value)


SWEEP = """schema = "govcheck-sweep/1"
name = "t"
base = "plant-a"
requirements = "shpp-400kw"
[search]
method = "grid"
[adjust."controller.kp"]
values = ["280 V/m", "400 V/m"]
[adjust."{a}"]
range = ["1e-11 kg/(s*Pa)", "1e-9 kg/(s*Pa)"]
"""


def test_a_sweep_file_may_use_either_spelling_but_not_both(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(SWEEP.format(a="internal_leakage.conductance"))
    spec = load_sweep(f)
    assert list(spec.paths) == ["controller.kp", LEAK]
    f.write_text(SWEEP.format(a=LEAK) + '[adjust."internal_leakage.conductance"]\nvalues = ["1e-10 kg/(s*Pa)"]\n')
    with pytest.raises(InputError, match="the same parameter as"):
        load_sweep(f)
