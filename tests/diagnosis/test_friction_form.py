"""The friction law's other form as the base of the diagnosis (friction_form.py).

A bench whose friction is the variable-viscous law with a stick phase (seed 000 eq. 7) while the
declared plant has LuGre bristles with the same steady-state map: the nominal replay with the other
form must be a strong, material improvement (select.beats) and be adopted; a LuGre recording must
keep its declared form. Steps-only practice recordings, no effect fitted: a few replays each.
"""

from __future__ import annotations

import pytest

from compliance.model.config import load_plant
from compliance.diagnosis.engine import _prepare
from compliance.diagnosis.friction_form import OPTION, friction_form_check, form_words
from compliance.diagnosis.operating_point import load_at_start
from compliance.diagnosis.select import MIN_GAIN, SIGNIFICANCE
from compliance.recordings.synth import PRACTICE_NOISE, synthesise


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def _check(cfg, bench, x0=0.05, load=6000.0, seed=5):
    frame, meta = synthesise(bench, "steps", x0=x0, load=load_at_start(bench, load, x0), kd=20.0, noise=PRACTICE_NOISE,
                             seed=seed, duration=17.0)
    meta["conditions"]["load_force"] = load
    st = _prepare(cfg, frame, meta, 5, 1)
    return friction_form_check(st.rc, st.setup, st.model, st.fits["nominal"])


def test_a_variable_viscous_bench_gets_its_friction_form_as_the_base(cfg):
    check = _check(cfg, cfg.replace(options={OPTION: "variable_viscous"}))
    assert check["declared"] == "lugre"
    assert check["adopted"] == "variable_viscous"
    assert check["delta_bic"] >= SIGNIFICANCE and check["share_of_excess"] >= MIN_GAIN
    assert check["tried"]["variable_viscous"] < check["chi2_declared"]
    assert "fits better as variable_viscous than lugre" in form_words(check)


def test_a_lugre_bench_keeps_the_declared_form(cfg):
    check = _check(cfg, cfg)
    assert check["adopted"] is None
    # the other form replays the LuGre recording worse than LuGre itself does
    assert check["tried"]["variable_viscous"] > check["chi2_declared"]
    assert form_words(check) == ""


def test_a_form_outside_the_same_map_has_no_alternative(cfg):
    rc = cfg.replace(options={OPTION: "piecewise_stribeck"})
    assert friction_form_check(rc, None, None, None) is None
