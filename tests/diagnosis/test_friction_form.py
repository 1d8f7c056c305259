"""The friction law's other form as the base of the diagnosis (servo/friction_form.py).

A bench whose friction is the variable-viscous law with a stick phase (seed 000 eq. 7) while the
declared plant has LuGre bristles with the same steady-state map: the nominal replay with the other
form must be a strong, material improvement (select.beats) and be adopted; a LuGre recording must
keep its declared form. Steps-only practice recordings, no effect fitted: a few replays each.
"""

from __future__ import annotations

import pytest

from compliance.model.config import load_plant
from compliance.diagnosis.servo.stage import prepare_recording
from compliance.diagnosis.servo.candidates import effect_params
from compliance.model.parameters import apply
from compliance.diagnosis.servo.fit import FitResult, chi2_parts
from compliance.diagnosis.servo.friction_form import OPTION, form_after_effects, friction_form_check, form_words
from compliance.validation.replay import run_replay
from compliance.validation.replay_conditions import load_at_start
from compliance.diagnosis.servo.selection import MIN_GAIN, SIGNIFICANCE
from compliance.recordings.synth import PRACTICE_NOISE, synthesise


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def _check(cfg, bench, x0=0.05, load=6000.0, seed=5):
    frame, meta = synthesise(bench, "steps", x0=x0, load=load_at_start(bench, load, x0), kd=20.0, noise=PRACTICE_NOISE,
                             seed=seed, duration=17.0)
    meta["conditions"]["load_force"] = load
    st = prepare_recording(cfg, frame, meta, 5, 1)
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


# a slow valve (case 9 of the two-effect benchmark: w_n 30 rad/s, zeta 0.7, 4 ms delay) dominates the misfit
LAG = {"natural_frequency": 30.0, "damping": 0.7, "delay": 0.004}


def _after_effects(cfg, form):
    """form_after_effects on a steps recording of a bench with the slow valve and friction law ``form``, the declared
    (LuGre) form's search standing for a valve-lag fit at the bench's values."""
    bench = cfg.replace(options={OPTION: form}, effects={"valve_dynamics": LAG})
    x0, load = 0.05, 6000.0
    frame, meta = synthesise(bench, "steps", x0=x0, load=load_at_start(bench, load, x0), kd=20.0, noise=PRACTICE_NOISE,
                             seed=5, duration=17.0)
    meta["conditions"]["load_force"] = load
    st = prepare_recording(cfg, frame, meta, 5, 1)
    check = friction_form_check(st.rc, st.setup, st.model, st.fits["nominal"])
    params = effect_params("valve_dynamics")
    values = [LAG[fp.name.split(".")[-1]] for fp in params]
    chi2, parts = chi2_parts(st.model, st.model.vector(run_replay(apply(st.rc, params, values), st.setup)))
    lag = FitResult("valve_dynamics", params, values, [0.0] * 3, chi2, parts, st.model.size, 1, 0.0, "at the bench's values")
    return check, form_after_effects(check, st.rc, st.setup, st.model, {"nominal": st.fits["nominal"], "valve_dynamics": lag}, 1)


def test_a_form_hidden_by_a_valve_lag_is_adopted_with_the_lag_refitted_under_it(cfg):
    check, again = _after_effects(cfg, "variable_viscous")
    assert check["adopted"] is None  # the lag dominates: the other form alone does not beat the nominal
    after = again["after"]
    assert again["adopted"] == "variable_viscous" and after["best"] == "valve_dynamics"
    # under LuGre the lag at the bench's values replays worse than the nominal (what hides it from the declared
    # search); replayed with the other form it replays better
    assert after["reference"] == "nominal" and after["screened"]["valve_dynamics"] < after["chi2_reference"]
    # the rule every candidate meets: BIC lower by SIGNIFICANCE and MIN_GAIN of what the declared form's best leaves
    assert after["delta_bic"] >= SIGNIFICANCE and after["share_of_excess"] >= MIN_GAIN
    assert "with valve_dynamics refitted under it" in form_words(again)


def test_a_lugre_bench_with_a_valve_lag_keeps_the_declared_form(cfg):
    check, again = _after_effects(cfg, "lugre")
    assert check["adopted"] is None and again["adopted"] is None
    # replayed with the other form the lag at its values fits worse, so nothing is refitted (one replay)
    assert again["after"]["screened"] == {} and again["after"]["refitted"] == {}
    assert again["replays"] == check["replays"] + 1
