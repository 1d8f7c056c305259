"""Bench characterisation: derivative, flow-law fits on synthetic charging data, friction maps.

Synthetic data are generated from known coefficients and the fits must recover them within
a few of their own standard errors (and those errors must be small), so a biased estimator
or a wrong uncertainty both fail. Real-data checks use physical bounds, explained inline.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.signal import savgol_filter

from compliance.characterise import (
    FlowFit,
    bin_friction,
    characterise_friction,
    characterise_valve,
    fit_friction_map,
    friction_from_force,
    iso6358_mass_flow,
    piston_area,
    prepare_run,
    sanville_mass_flow,
    smoothed_derivative,
    stribeck_friction,
    synthetic_charging,
    synthetic_friction_run,
)
from compliance.characterise.derivative import noise_std
from compliance.cli import characterise as cli_characterise
from compliance.errors import GovcheckError, InputError
from compliance.physics import friction as phys_friction
from compliance.physics import valve_flow as phys_flow
from compliance.recordings.reader import read_recording

DATA = Path(__file__).resolve().parents[1] / "data"
ATM = 101325.0
K_SIGMA = 4.0  # |estimate - truth| < 4 standard errors: a false failure has probability ~6e-5 per check
ISO_TRUE = {"conductance": 2.33e-8, "critical_ratio": 0.3}  # plant A's valve rating, a typical real b
CHARGE = dict(volume=5e-3, supply_pressure=8e5, initial_pressure=ATM, duration=4.0, sample_time=1e-3, delay=0.2)


# ----------------------------------------------------------------------------- derivative
def test_derivative_matches_savgol_on_uniform_grid():
    t = np.arange(400) * 1e-3
    y = np.sin(7.0 * t) + 0.01 * np.random.default_rng(3).normal(size=t.size)
    value, slope = smoothed_derivative(t, y, 21, 3)
    # same estimator as scipy's on a uniform grid; only round-off differs
    np.testing.assert_allclose(value, savgol_filter(y, 21, 3, mode="interp"), atol=1e-10)
    np.testing.assert_allclose(slope, savgol_filter(y, 21, 3, deriv=1, delta=1e-3, mode="interp"), atol=1e-7)


def test_derivative_exact_for_cubic_on_jittered_times():
    rng = np.random.default_rng(1)
    t = np.cumsum(0.01 + 0.001 * rng.integers(0, 2, 300))  # 10/11 ms like the Zillen logger
    y = 2.0 - 3.0 * t + 0.5 * t**2 - 0.25 * t**3
    _, slope = smoothed_derivative(t, y, 15, 3)
    # a cubic is reproduced exactly by a cubic local fit: only round-off remains
    np.testing.assert_allclose(slope, -3.0 + t - 0.75 * t**2, rtol=0, atol=1e-8)


def test_noise_estimate():
    t = np.arange(20000) * 1e-3
    y = 5e5 + 1e4 * np.sin(t) + np.random.default_rng(2).normal(0.0, 300.0, t.size)
    # relative standard error of a std estimated from 20000 samples is 1/sqrt(2n) = 0.5 %
    assert noise_std(t, y, 31, 3) == pytest.approx(300.0, rel=0.03)


# ----------------------------------------------------------------------------- flow laws
def test_vectorised_laws_are_the_simulator_kernels():
    p_down = np.array([1e5, 3e5, 5e5, 7.9e5])
    vec = iso6358_mass_flow(8e5, p_down, 293.15, 2.33e-8, 0.3)
    scalar = [phys_flow.iso6358_mass_flow(1.0, 2.33e-8, 8e5, p, 293.15, 0.3, 1.204, 293.15) for p in p_down]
    np.testing.assert_allclose(vec, scalar, rtol=1e-15)
    # choked ISO flow, seed 000 eq. (1) with w = 1, computed by hand
    assert vec[0] == pytest.approx(2.33e-8 * 8e5 * 1.204, rel=1e-12)
    vec = sanville_mass_flow(8e5, p_down, 293.15, 1e-5)
    scalar = [phys_flow.sanville_mass_flow(1e-5, 8e5, p, 293.15, 1.4, 287.0) for p in p_down]
    np.testing.assert_allclose(vec, scalar, rtol=1e-15)


def test_noiseless_iso_charging_recovers_coefficients():
    data = synthetic_charging("iso6358", ISO_TRUE, **CHARGE)
    fit = characterise_valve(data, CHARGE["volume"], laws=("iso6358",)).best
    # without noise only the cubic derivative's truncation error and the ISO kernel's
    # regularisation above a = 0.999 (outside the fitted range a <= 0.97) remain: 1e-4 is
    # far above both and far below the 1 % a valve rating is known to
    assert fit.params["conductance"] == pytest.approx(ISO_TRUE["conductance"], rel=1e-4)
    assert fit.params["critical_ratio"] == pytest.approx(ISO_TRUE["critical_ratio"], abs=1e-4)


@pytest.mark.parametrize(
    "law, params, mode",
    [
        ("iso6358", ISO_TRUE, "charge"),
        ("bobrow", {"coefficient": 1.5e-5}, "discharge"),
        ("power", {"cf1": 2e-4, "exponent": 0.4}, "charge"),
        ("sanville", {"area": 1e-5}, "charge"),
    ],
)
def test_noisy_charging_ranks_true_law_first_and_recovers_it(law, params, mode):
    opts = dict(CHARGE)
    if mode == "discharge":
        opts["initial_pressure"] = 8e5
    # 300 Pa white noise at 1 kHz: a 10 bar transducer of 0.03 % FS noise
    data = synthetic_charging(law, params, mode=mode, noise_std=300.0, seed=11, **opts)
    result = characterise_valve(data, opts["volume"], mode="auto")
    assert result.mode == mode
    assert result.best.law == law
    fit = result.best
    for name, true in params.items():
        assert abs(fit.params[name] - true) < K_SIGMA * fit.stderr[name], (name, fit.params[name], fit.stderr[name])
        # ... and the uncertainty is tight enough to mean something (< 2 % of the value)
        assert fit.stderr[name] < 0.02 * abs(true)


def test_standard_errors_match_the_scatter_of_repeated_fits():
    clean = synthetic_charging("bobrow", {"coefficient": 1.5e-5}, **CHARGE)
    estimates, errors = [], []
    for seed in range(20):
        noisy = clean.copy()
        noisy["pressure_a"] += np.random.default_rng(seed).normal(0.0, 300.0, len(noisy))
        fit = characterise_valve(noisy, CHARGE["volume"], laws=("bobrow",)).best
        estimates.append(fit.params["coefficient"])
        errors.append(fit.stderr["coefficient"])
    ratio = np.mean(errors) / np.std(estimates, ddof=1)
    # the sample std of 20 draws scatters by 1/sqrt(2*19) = 16 %: 0.65..1.5 is > 2.5 sigma
    assert 0.65 < ratio < 1.5


def test_valve_bad_input():
    data = synthetic_charging("iso6358", ISO_TRUE, **CHARGE).drop(columns="supply_pressure")
    with pytest.raises(InputError, match="supply pressure"):
        characterise_valve(data, CHARGE["volume"], mode="charge", source="x.csv")
    flat = data.assign(pressure_a=5e5)
    with pytest.raises(InputError, match="never changes"):
        characterise_valve(flat, 1e-3, supply_pressure=8e5)
    with pytest.raises(InputError, match="not known"):
        characterise_valve(data, 1e-3, supply_pressure=8e5, laws=("sanvile",))


def test_valve_wrong_options_name_their_cause():
    data = synthetic_charging("iso6358", ISO_TRUE, **CHARGE).drop(columns="supply_pressure")
    # the good twin: the right supply pressure fits
    assert characterise_valve(data, CHARGE["volume"], supply_pressure=8e5).fits
    # a supply given in psi where bar was meant: 8 psi = 0.552 bar abs, below the 8 bar recorded
    with pytest.raises(InputError, match=r"above the supply 0.552 bar abs \(--supply-pressure\)"):
        characterise_valve(data, CHARGE["volume"], supply_pressure=8 * 6894.757)
    with pytest.raises(InputError, match="give --mode charge"):
        characterise_valve(data, CHARGE["volume"], supply_pressure=8e5, mode="discharge")
    with pytest.raises(InputError, match=r"the exhaust 9 bar abs \(--exhaust-pressure\)"):
        falling = synthetic_charging("iso6358", ISO_TRUE, **(CHARGE | dict(initial_pressure=8e5)), mode="discharge")
        characterise_valve(falling, CHARGE["volume"], exhaust_pressure=9e5)
    with pytest.raises(InputError, match="leaves no samples after the valve opening"):
        late = synthetic_charging("iso6358", ISO_TRUE, **(CHARGE | dict(duration=1.0, delay=0.8)))
        characterise_valve(late, CHARGE["volume"], window=401)
    with pytest.raises(InputError, match="'time' is not a pressure"):
        characterise_valve(data, CHARGE["volume"], supply_pressure=8e5, pressure_column="time")


# ----------------------------------------------------------------------------- friction
def test_vectorised_map_is_the_plant_map():
    v = np.array([-0.05, -0.004, -0.0005, 0.0005, 0.004, 0.05])
    vec = stribeck_friction(v, 300.0, 420.0, 0.005, 650.0)
    scalar = [phys_friction.stribeck_map(x, 420.0, 300.0, 0.005, 650.0) for x in v]
    np.testing.assert_allclose(vec, scalar, rtol=1e-14)


def test_friction_from_force_is_zillen_eq3():
    area = piston_area(0.0257)
    assert area == pytest.approx(math.pi * 0.0257**2 / 4, rel=1e-15)
    # 7 bar gauge on 25.7 mm: p*A = 363.1 N; 370 N measured -> 6.9 N of friction
    assert friction_from_force(370.0, 7e5 + ATM, area) == pytest.approx(370.0 - 7e5 * area, rel=1e-12)


TRUE_MAP = dict(coulomb=300.0, static=420.0, stribeck_velocity=0.005, viscous=650.0)  # plant A, reference-plant.md
SPEEDS = [0.001, 0.002, 0.004, 0.008, 0.016, 0.032, 0.064, 0.128]
K_P = 2e-5  # N/Pa: +2 N per bar


def _runs(offset=0.0, pressures=(1e5, 4e5, 7e5), speeds=SPEEDS):
    area = piston_area(0.0257)
    runs = []
    for i, pg in enumerate(pressures):
        df = synthetic_friction_run(speeds, TRUE_MAP, area=area, pressure_gauge=pg, stroke=0.03, sample_time=0.005,
                                    accel=2.0, force_noise=5.0, position_noise=2e-6, seed=i, pressure_coefficient=K_P)
        df["force"] += offset
        runs.append(prepare_run(f"run{i}", df, area, window_s=0.05))
    return runs


def test_friction_map_recovers_known_parameters():
    result = characterise_friction(_runs(), asymmetric=False, v_min=5e-4)
    fit = result.fits["pressure-dependent"]
    assert fit.fixed == {}
    expected = {"coulomb": 300.0, "stribeck_drop": 120.0, "stribeck_velocity": 0.005, "viscous": 650.0,
                "pressure_coefficient": K_P}
    for name, true in expected.items():
        assert abs(fit.params[name] - true) < K_SIGMA * fit.stderr[name], (name, fit.params[name], fit.stderr[name])
    # Coulomb and the pressure term are the figures a governor model is sensitive to: known
    # to about 1 % with 5 N force noise; the viscous slope only shows 80 N over these speeds
    assert fit.stderr["coulomb"] < 6.0 and fit.stderr["pressure_coefficient"] < 0.05 * K_P
    assert fit.stderr["viscous"] < 0.5 * 650.0
    # leaving the pressure term out must cost: runs 3 bar apart differ by 6 N of Coulomb level
    assert result.fits["pressure-independent"].rms_bins > 3 * fit.rms_bins


def test_asymmetric_fit_separates_a_force_offset():
    fit = characterise_friction(_runs(offset=4.0), asymmetric=True, v_min=5e-4).fits["pressure-dependent"]
    assert abs(fit.params["direction_offset"] - 4.0) < K_SIGMA * fit.stderr["direction_offset"]
    assert abs(fit.params["coulomb_mean"] - 300.0) < K_SIGMA * fit.stderr["coulomb_mean"]


def test_unidentifiable_terms_are_fixed_and_explained():
    # one speed per direction: viscous and Stribeck terms cannot be told from Coulomb
    runs = _runs(pressures=(3e5,), speeds=[0.01])
    result = characterise_friction(runs, asymmetric=False, v_min=5e-4)
    fit = result.fits["pressure-independent"]
    assert "pressure-dependent" not in result.fits  # one pressure
    assert set(fit.fixed) == {"stribeck_drop", "viscous"} and "span" in fit.fixed["viscous"]
    # the Coulomb level then absorbs the map at 10 mm/s: F_C + (F_S-F_C) e^-2 + b*0.01 + k_p*p
    level = 300.0 + 120.0 * math.exp(-2.0) + 650.0 * 0.01 + K_P * 3e5
    assert abs(fit.params["coulomb"] - level) < max(K_SIGMA * fit.stderr["coulomb"], 1.0)


def test_no_populated_bins_is_an_input_error():
    bins = bin_friction(np.full(50, 1e-5), np.zeros(50), np.zeros(50), np.zeros(50))
    with pytest.raises(InputError, match="no populated"):
        fit_friction_map(bins)


def test_min_speed_above_every_run_is_named():
    runs = _zillen_runs()[:1]
    assert characterise_friction(runs, v_min=1e-3).fits  # the good twin: 1 mm/s leaves map points
    # Zillen's fastest constant-speed stroke is ~16 mm/s; 1 m/s (a unit slip for 1 mm/s) leaves none
    with pytest.raises(InputError, match=r"--min-speed 1000 mm/s is above every constant-speed part .*fastest 1[0-9]\.?\d* mm/s"):
        characterise_friction(runs, v_min=1.0)
    # a run that accelerates throughout (x = a t^2 / 2, a = 0.05 m/s^2) has no constant-speed part
    t = np.arange(2000) * 1e-3
    ramp = pd.DataFrame({"time": t, "position": 0.025 * t**2, "pressure_a": np.full(t.size, 2e5),
                         "force": np.full(t.size, 50.0)})
    with pytest.raises(InputError, match="no constant-speed part in the runs"):
        characterise_friction([prepare_run("ramp", ramp, 5e-4, window_s=0.2)])


def _zillen_runs():
    runs = []
    for name in ("O-ring257_1bar_head1000.csv", "O-ring257_7bar_head1000.csv"):
        df, meta = read_recording(DATA / "zillen" / name, "zillen-friction",
                                  required=("time", "position", "pressure_a", "force"))
        runs.append(prepare_run(name, df, piston_area(meta["bore"])))
    return runs


def test_real_zillen_friction_is_positive_and_plausible():
    result = characterise_friction(_zillen_runs(), asymmetric=True)
    area = piston_area(0.0257)
    for name, pressure, fit in result.per_run:
        # friction dissipates: it opposes the motion in both directions (positive magnitudes)
        assert fit.params["coulomb_pos"] > 0 and fit.params["coulomb_neg"] > 0, name
        # the actuator extends under its own pressure at 1 bar, so seal friction must stay
        # below the 1 bar pressure force p*A = 52 N
        assert fit.params["coulomb_mean"] < 1e5 * area, name
    (_, p1, low), (_, p7, high) = result.per_run
    assert p1 == pytest.approx(1e5, abs=0.1e5) and p7 == pytest.approx(7e5, abs=0.1e5)  # as logged
    # pressure behind an elastomer seal loads its lip: friction rises with pressure
    assert high.params["coulomb_mean"] > low.params["coulomb_mean"]
    dep = result.fits["pressure-dependent"]
    # k_p = mu * (pressure-loaded contact band) <= 1 * pi * D * 3 mm for an O-ring in a 25.7 mm bore
    assert 0 < dep.params["pressure_coefficient"] < math.pi * 0.0257 * 0.003
    assert dep.rms_samples < result.fits["pressure-independent"].rms_samples


# ----------------------------------------------------------------------------- CLI
def main(argv) -> int:
    """``govcheck`` restricted to this command, with the dispatcher's error -> exit-code mapping.

    The real dispatcher imports every command module; going through this one alone keeps
    these tests independent of the other commands.
    """
    parser = argparse.ArgumentParser(prog="govcheck")
    cli_characterise.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(argv)
    try:
        return cli_characterise.run(args)
    except GovcheckError as exc:
        print(f"govcheck {args.command}: error: {exc}", file=sys.stderr)
        return exc.exit_code


def test_cli_friction_on_real_fixture(tmp_path, capsys):
    files = [str(DATA / "zillen" / f"O-ring257_{p}bar_head1000.csv") for p in (1, 7)]
    out_json, out_png = tmp_path / "f.json", tmp_path / "f.png"
    code = main(["characterise", "friction", *files, "--column-map", "zillen-friction",
                 "--json", str(out_json), "--plot", str(out_png)])
    assert code == 0
    text = capsys.readouterr().out
    assert "pressure-dependent" in text and "coulomb_pos" in text
    data = json.loads(out_json.read_text())
    assert set(data["fits"]) == {"pressure-independent", "pressure-dependent"}
    assert out_png.stat().st_size > 10_000


def test_cli_valve_on_synthetic_recording(tmp_path, capsys):
    rec = tmp_path / "charge.csv"
    synthetic_charging("iso6358", ISO_TRUE, noise_std=300.0, seed=5, **CHARGE).to_csv(rec, index=False)
    out_json = tmp_path / "v.json"
    code = main(["characterise", "valve", str(rec), "--volume", "5 L", "--json", str(out_json),
                 "--plot", str(tmp_path / "v.png")])
    assert code == 0
    assert "iso6358" in capsys.readouterr().out
    ranking = json.loads(out_json.read_text())["ranking"]
    assert ranking[0]["law"] == "iso6358"


def test_cli_bad_input_exit_2(tmp_path, capsys):
    rec = tmp_path / "nohead.csv"
    rec.write_text("0,1\n1,2\n")
    assert main(["characterise", "valve", str(rec), "--volume", "1 L"]) == 2
    assert "no header" in capsys.readouterr().err
    assert main(["characterise", "valve", str(rec), "--volume", "1 kg"]) == 2
    fixture = str(DATA / "zillen" / "O-ring257_1bar_head1000.csv")
    assert main(["characterise", "friction", fixture, "--column-map", "no-such-map"]) == 2
    assert "neither a file nor a shipped map" in capsys.readouterr().err


def test_flowfit_predict_is_the_law():
    fit = FlowFit("bobrow", "", {"coefficient": 2e-5}, {}, {}, 0.0, 0.0, 0, 0.0)
    assert fit.predict(8e5, 4e5, 293.15)[0] == pytest.approx(2e-5 * math.sqrt(4e5), rel=1e-12)
