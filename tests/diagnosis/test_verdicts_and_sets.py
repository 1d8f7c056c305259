"""Honest verdicts, several effects, ambiguity with a designed test, effects anchored where the data is,
and the empirical term outside the library (issue 13).

Recordings are generated with the model on the 17 s steps-only practice profile with a restricted
candidate library, so each test stays within a few seconds of replays.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from compliance.model.config import load_plant
from compliance.diagnosis.evidence.discriminating_test import design_test
from compliance.diagnosis.evidence.empirical_force import sparse_fit
from compliance.diagnosis.servo.diagnose import diagnose
from compliance.diagnosis.servo.candidates import effect_params
from compliance.diagnosis.servo.stage import prepare_recording
from compliance.diagnosis.servo.effect_sets import ADD_GAIN, BURST_WINDOW, NO_WORSE, adds_enough, screen_addition
from compliance.diagnosis.servo.fit import FitContext, FitResult, chi2_parts, scan_points
from compliance.validation.replay_conditions import load_at_start
from compliance.diagnosis.servo.selection import RESIDUAL_LIMIT, Score, ambiguity_set, honest
from compliance.recordings.synth import PRACTICE_NOISE, synthesise

DURATION = 17.0  # s: the practice steps without the sinusoid


@pytest.fixture(scope="module")
def cfg():
    return load_plant("plant-a")


def _recording(cfg, effects, x0=0.06, load=7000.0, seed=3):
    """A noisy steps recording of ``cfg`` with ``effects``; the stated load holds at the start position."""
    truth = cfg.replace(effects=effects)
    frame, meta = synthesise(truth, "steps", x0=x0, load=load_at_start(truth, load, x0), kd=20.0, noise=PRACTICE_NOISE,
                             seed=seed, duration=DURATION)
    meta["conditions"]["load_force"] = load
    return frame, meta


# ----------------------------------------------------------------------------- verdict rules
def test_a_complete_verdict_needs_every_signal_within_the_stated_multiple_of_its_floor():
    ok = {"position": 1.1, "pressure_a": RESIDUAL_LIMIT * 0.99}
    assert honest("missing_physics", "x", "x explains 90 %", ok)[0] == "missing_physics"
    left = {"position": 1.1, "pressure_b": RESIDUAL_LIMIT * 1.5}
    v, reason = honest("parameters_only", "base", "recalibrating explains", left)
    assert v == "partially_explained"
    assert "pressure_b" in reason and "position" not in reason
    assert honest("unexplained", None, "nothing", left)[0] == "unexplained"


def test_ambiguity_set_holds_rivals_within_the_margin_and_merges_variants():
    def sc(name, bic, explained=0.9):
        return Score(name, 0.0, 1, 0.0, bic, 0.0, explained)

    scores = {"nominal": sc("nominal", 500.0, 0.0), "a": sc("a", 100.0), "a+base": sc("a+base", 104.0),
              "b": sc("b", 105.0), "b+base": sc("b+base", 106.0), "c": sc("c", 140.0), "d": sc("d", 101.0, 0.2)}
    assert ambiguity_set(scores, "a") == ["a", "b"]  # a+base is the same physics; c is far; d explains too little
    scores["b"] = sc("b", 200.0)
    scores["b+base"] = sc("b+base", 200.0)
    assert ambiguity_set(scores, "a") == []


def test_an_added_effect_that_makes_a_signal_worse_is_not_kept():
    n = 10000  # residuals over two signals, n/2 each: chi2 of a signal = (n/2) x its normalised mean square

    def fit(name, ms_position, ms_pressure):
        parts = {"position": ms_position * n / 2, "pressure_a": ms_pressure * n / 2}
        return FitResult(name, (None,) * name.count("+"), [], [], sum(parts.values()), parts, n)

    cur = fit("a", 1.0, 20.0)
    assert adds_enough(fit("a+b", 1.0, 2.0), cur, n, math.log(n), 1.0)[0]
    # the pooled chi-square falls, but the position ends 5 x worse, far above the limit: rejected
    kept, why = adds_enough(fit("a+c", 5.0, 1.0), cur, n, math.log(n), 1.0)
    assert not kept and "position" in why
    # the position 1.3 x worse but still within the limit (RMS 1.14 < 2): kept
    assert NO_WORSE < 1.3 < RESIDUAL_LIMIT ** 2
    assert adds_enough(fit("a+d", 1.3, 4.0), cur, n, math.log(n), 1.0)[0]


def test_one_burst_neither_hides_a_second_effect_nor_is_the_only_evidence_for_one():
    """30 s of residuals at 5 ms; the current set leaves 2.5 x the floor everywhere (above the completeness limit
    of 2) and one 2 s burst at 30 x (a stick-slip event the replay makes and the bench did not, which
    holds most of the excess). An addition that brings everything outside the burst to the floor is kept
    although it removes little of the pooled excess; one that fits only the burst is not, although it
    removes most of it."""
    t = np.arange(0.0, 30.0, 0.005)
    burst = (t >= 22.0) & (t < 22.0 + BURST_WINDOW)
    cur = np.where(burst, 30.0, 2.5)
    real, burst_fit = np.where(burst, 30.0, 1.0), np.where(burst, 1.0, 2.5)
    n = t.size

    def fit(name, vec):
        return FitResult(name, (None,) * (name.count("+") + 1), [], [], float(vec @ vec), {"position": float(vec @ vec)}, n)

    current = fit("a", cur)
    pooled_real = (current.chi2 - fit("a+b", real).chi2) / (current.chi2 - n)
    assert pooled_real < ADD_GAIN  # the pooled share alone would reject it
    kept, why = adds_enough(fit("a+b", real), current, n, math.log(n), 1.0, (cur, real, t))
    assert kept and "outside" in why
    kept, why = adds_enough(fit("a+c", burst_fit), current, n, math.log(n), 1.0, (cur, burst_fit, t))
    assert not kept and "outside" in why
    # nothing left outside the burst (the floor there): the pooled excess decides, as without the residuals
    cur_only_burst = np.where(burst, 30.0, 1.0)
    assert adds_enough(fit("a+c", np.ones(n)), fit("a", cur_only_burst), n, math.log(n), 1.0,
                       (cur_only_burst, np.ones(n), t))[0]


# ----------------------------------------------------------------------------- whole diagnoses
def test_a_load_stiffness_fits_a_recording_taken_far_from_mid_stroke(cfg):
    """The core's load stiffness acts about mid-stroke (80 mm); a recording at 25 mm states its load
    there. Anchored at the start position, the stiffness comes back within 10 % (the fit resolves
    0.2 % of its range, the residual noise a few %)."""
    k = 6e4
    frame, meta = _recording(cfg, {"position_dependent_load": {"stiffness": k}}, x0=0.025, load=4000.0)
    d = diagnose(cfg, frame, meta, effects=["position_dependent_load", "valve_offset"], jobs=1, recalibrate=False)
    assert d.verdict == "missing_physics"
    assert d.winner == "position_dependent_load"
    assert d.fits[d.winner].value("position_dependent_load.stiffness") == pytest.approx(k, rel=0.10)


def test_two_effects_switched_on_are_both_named(cfg):
    """A valve null shift (command) and external leakage (both pressures) at once: the search adds
    the second effect to the first and reports each one's own contribution."""
    effects = {"valve_offset": {"offset": 0.25}, "external_leakage": {"conductance": 3e-10}}
    frame, meta = _recording(cfg, effects, x0=0.05, load=6000.0)
    d = diagnose(cfg, frame, meta, effects=["valve_offset", "external_leakage", "heat_transfer"], jobs=1,
                 recalibrate=False)
    assert set(d.winner.split("+")) == {"valve_offset", "external_leakage"}
    assert d.verdict == "missing_physics"
    assert set(d.contributions) == {"valve_offset", "external_leakage"}
    assert all(c["share_of_excess"] > 0.05 for c in d.contributions.values())
    assert d.fits[d.winner].value("valve_offset.offset") == pytest.approx(0.25, rel=0.15)


def test_the_screen_finds_a_small_leak_whose_single_fit_a_dominant_valve_lag_dragged_off(cfg):
    """A valve lag dominates (nominal chi2/N in the hundreds) and a small external leak completes it.
    The leak's own single fit lands about twice too large, where it makes the set worse, as does its
    declared default; switched on over its grid the screen finds the side that helps (3e-11 against a
    true 4.5e-11: the grid's spacing is a factor 3) and the set's chi-square falls."""
    leak = 4.5e-11
    frame, meta = _recording(cfg, {"valve_dynamics": {"natural_frequency": 50.7, "damping": 0.63, "delay": 0.0124},
                                   "external_leakage": {"conductance": leak}}, x0=0.027, load=6000.0)
    st = prepare_recording(cfg, frame, meta, 5, 1)
    ctx, n = FitContext(st.rc, st.setup, st.model), st.model.size
    pv, pl = effect_params("valve_dynamics"), effect_params("external_leakage")
    lag = [44.4, 0.6, 0.00814]  # the lag's single fit: it absorbs part of the leak's signature
    chi, parts = chi2_parts(st.model, ctx.residual(pv, lag)[0])
    current = FitResult("valve_dynamics", pv, lag, [], chi, parts, n)
    single = FitResult("external_leakage", pl, [2.1 * leak], [], math.inf, {}, n)
    # the two starts of a screen without the grid: the single optimum and the declared default (1e-10)
    assert min(scan_points(ctx, pv + pl, [lag + [2.1 * leak], lag + [pl[0].nominal]])) > chi
    name, screened, start, replays = screen_addition(ctx, current, single)
    assert name == "external_leakage" and replays >= 6
    assert screened < 0.8 * chi
    assert start[-1] == pytest.approx(leak, rel=0.5)


def test_a_pair_is_identifiable_on_a_model_bench_and_not_under_a_stick_band_friction(cfg):
    """``truth_share``: the true pair replayed with the fitted model removes almost all the nominal
    excess when the bench is the model, and less than the half a winner must remove when the bench's
    friction is the variable-viscous stick band (seed 000 eq. 7) where the model has LuGre: that
    case's right outcome is an honest incomplete verdict, which ``score_pair`` scores."""
    from types import SimpleNamespace

    from compliance.diagnosis.scoring.two_effect_cases import bench_config, score_pair, truth_share

    params = {"valve_offset": {"offset": 0.25}, "external_leakage": {"conductance": 3e-10}}
    shares = {}
    for variant in ("fine_step", "friction_form"):
        frame, meta = _recording(bench_config(cfg, variant), params, x0=0.05, load=6000.0)
        case = {"pair": list(params), "variant": variant, "params": params, "operating_point": {}, "frame": frame, "meta": meta}
        shares[variant] = truth_share(cfg, case)
    assert shares["fine_step"] > 0.9
    assert shares["friction_form"] < 0.5
    diag = SimpleNamespace(winner=None, verdict="unexplained", seconds=1.0, ambiguous=[], signals_left={})
    row = score_pair(case, diag, shares["friction_form"])
    assert not row["identifiable"] and row["honest"] and not row["both_named"]


def test_physics_outside_the_library_names_the_signal_left_and_an_empirical_force(cfg):
    """A load stiffness diagnosed with a library that lacks it: no complete verdict, the pressures named
    as what is left, and the empirical force term finds a position-proportional force of the right size."""
    k = 8e4
    frame, meta = _recording(cfg, {"position_dependent_load": {"stiffness": k}}, x0=0.06, load=6000.0)
    d = diagnose(cfg, frame, meta, effects=["heat_transfer", "internal_leakage"], jobs=1, recalibrate=False)
    assert d.verdict in ("unexplained", "partially_explained")
    if d.verdict == "partially_explained":
        assert set(d.signals_left) & {"pressure_a", "pressure_b", "valve_command"}
    terms = {t["feature"]: t["coefficient"] for t in d.empirical["terms"]}
    assert "position" in terms
    # closing load grows with position: the missing opening force is -k (x - x0)
    assert -terms["position"] == pytest.approx(k, rel=0.25)
    assert "empirical suggestion" in d.empirical["label"]


def test_indistinguishable_explanations_get_a_test_that_separates_them(cfg):
    """Friction raised by a fixed amount, or friction rising with chamber pressure by the same amount at
    this test's mean pressure: the same test predicts nearly the same signals; a test at another supply
    pressure moves the mean pressure and separates them by several noise floors."""
    coef = 1.5e-6  # relative rise per Pa of mean gauge pressure (0.15 per bar)
    p_mean = 0.5 * (cfg.p("air.supply_pressure") + cfg.p("air.atmospheric_pressure")) - cfg.p("air.atmospheric_pressure")
    scale = 1.0 + coef * p_mean
    a = cfg.replace(params={"friction.static_force": cfg.p("friction.static_force") * scale,
                            "friction.coulomb_force": cfg.p("friction.coulomb_force") * scale})
    b = cfg.replace(effects={"pressure_dependent_friction": {"coefficient": coef}})
    floors = {"position": 2e-5, "pressure_a": 300.0, "pressure_b": 300.0, "valve_command": 0.01}  # the practice sensors
    out = design_test(a, b, floors, x0=0.06, load=7000.0, names=("friction level", "pressure-dependent friction"))
    same = next(r for r in out["tests"] if r["key"] == "same")
    rec = out["recommended"]
    assert out["separates"]
    assert rec["key"] != "same"
    supply = next(r for r in out["tests"] if r["key"] == "supply")
    # the mean chamber pressure follows the supply; the fixed friction does not (a slow ramp, along which the
    # mean pressure drifts with the chamber volumes, may separate them more on the command)
    assert supply["difference"] > 2.0 * same["difference"]
    assert rec["difference"] >= supply["difference"]
    assert set(rec["traces"][rec["signal"]]) == {"friction level", "pressure-dependent friction"}


def test_sparse_regression_finds_the_terms_it_was_built_from():
    rng = np.random.default_rng(2)
    n = 4000
    x = rng.uniform(-0.02, 0.02, n)
    v = rng.normal(0, 0.02, n)
    feats = {"constant": np.ones(n), "position": x, "velocity": v, "direction": np.sign(v)}
    y = -5e4 * x + 80.0 * np.sign(v) + rng.normal(0, 20.0, n)
    fit = sparse_fit(y, feats)
    got = {t["feature"]: t["coefficient"] for t in fit["terms"]}
    assert set(got) == {"position", "direction"}
    assert got["position"] == pytest.approx(-5e4, rel=0.05)
    assert got["direction"] == pytest.approx(80.0, rel=0.05)
    assert fit["rms_after"] == pytest.approx(20.0, rel=0.1)


def test_friction_level_and_pressure_dependent_friction_at_one_supply_are_ambiguous(cfg):
    """Friction levels 1.12 x the data sheet, diagnosed with the recalibration and pressure-dependent
    friction: at one supply pressure both bring every signal within the limit (1.1 and 1.7 x the
    floors), so the verdict is ``ambiguous`` with both named, and the designed test (70 % supply: the
    mean chamber pressure moves, a fixed friction does not) separates them by more than 3 noise floors."""
    truth = cfg.replace(params={"friction.static_force": 1.12 * cfg.p("friction.static_force"),
                                "friction.coulomb_force": 1.12 * cfg.p("friction.coulomb_force")})
    frame, meta = synthesise(truth, "steps", x0=0.06, load=7000.0, kd=20.0, noise=PRACTICE_NOISE, seed=4,
                             duration=DURATION)
    d = diagnose(cfg, frame, meta, effects=["pressure_dependent_friction"], jobs=1)
    assert d.verdict == "ambiguous"
    assert {"base", "pressure_dependent_friction"} <= {e for k in d.ambiguous for e in k.split("+")}
    test = d.suggested_test
    assert test["separates"] and test["recommended"]["key"] != "same"
    same = next(r for r in test["tests"] if r["key"] == "same")
    assert test["recommended"]["difference"] > 2.0 * same["difference"]
    data = d.to_dict()
    assert data["ambiguity"]["explanations"] == d.ambiguous
    assert "Suggested test" in d.explanation


def test_a_slow_spool_is_judged_against_its_own_null_floors(cfg):
    """The floors come from the declared plant's null bootstrap. A plant with a 34 rad/s spool (the
    generated case that, fitted within 1 %, left its position 2.3 x the declared floor) amplifies the
    error of the injected noise estimate more: its own null bootstrap leaves more position error, so
    judged against the larger floor its leftovers fall, and never rise."""
    from compliance.model.parameters import apply
    from compliance.diagnosis.evidence.residuals import own_floor_objective

    spool = {"valve_dynamics": {"natural_frequency": 34.4, "damping": 0.79, "delay": 0.0093}}
    truth_cfg = cfg.replace(effects=spool)
    frame, meta = synthesise(truth_cfg, "practice", x0=0.0488, load=1551.0, kd=20.0, noise=PRACTICE_NOISE, seed=2)
    st = prepare_recording(cfg, frame, meta, 5, 1)
    params = effect_params("valve_dynamics")
    truth = [34.4, 0.79, 0.0093]
    vec, _ = FitContext(st.rc, st.setup, st.model).residual(params, truth)
    m = st.model.index.size
    declared = {s: math.sqrt(float(r @ r) / m) for s, r in st.model.split(vec).items()}
    own = own_floor_objective(st.model, apply(st.rc, params, truth), st.setup, vec)
    assert all(own[s] <= declared[s] + 1e-12 for s in declared)
    assert own["position"] < 0.9 * declared["position"]
