"""Replay of recordings with the model (compliance.validation.replay) and the synthetic recordings it is tested on."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from compliance.model.config import load_plant
from compliance.errors import InputError
from compliance.recordings.synth import (
    PRACTICE_NOISE,
    practice_profile,
    synthesise,
    write_recording,
)
from compliance.recordings.reader import read_recording
from compliance.validation.recorded_noise import position_noise_estimate, position_quantum, robust_std
from compliance.validation.replay import replay
from compliance.validation.resampling import zoh_interval_average
from compliance.validation.fit_metrics import fit_percent

SHARED = Path(__file__).resolve().parents[3] / "shared" / "practice-recordings"
OUTPUTS = ("position", "pressure_a", "pressure_b")


@pytest.fixture(scope="module")
def plant():
    return load_plant("plant-a")


@pytest.fixture(scope="module")
def clean(plant, tmp_path_factory):
    """Noise-free practice test of the nominal model, written and read back as a user's file would be."""
    rec, meta = synthesise(plant, x0=0.06, load=7000.0, kd=6.0, noise=None)
    path = tmp_path_factory.mktemp("rec") / "clean.csv.gz"
    write_recording(rec, meta, path)
    return read_recording(path)


def _fits(rec, sim, signals):
    return {s: fit_percent(rec[s].to_numpy(), sim[s].to_numpy()) for s in signals}


# ------------------------------------------------------------------------------ self replay
@pytest.mark.parametrize("mode", ["closed_loop", "plant_only"])
def test_model_replays_its_own_noise_free_recording(plant, clean, mode):
    rec, meta = clean
    sim = replay(plant, rec, meta, mode)
    assert np.array_equal(sim["time"].to_numpy(), rec["time"].to_numpy())  # aligned row by row
    signals = OUTPUTS + (("valve_command",) if mode == "closed_loop" else ())
    fits = _fits(rec, sim, signals)
    # same model, same conditions: only the CSV's 10 significant digits differ (1e-10 relative),
    # far inside the 99 % (a 0.1 % misfit would already be a 10^6 times larger error)
    for s, f in fits.items():
        assert f > 99.9, (mode, s, f)
    assert sim.attrs["noise_replay"] is False  # a noise-free recording has no noise to replay


def test_sidecar_gains_override_the_configuration(plant, clean):
    rec, meta = clean
    cfg20 = plant.replace(params={"controller.kd": 20.0})  # the file's configuration says Kd = 20
    with_meta = replay(cfg20, rec, meta, "closed_loop")
    assert with_meta.attrs["conditions"]["controller"]["kd"] == 6.0
    assert fit_percent(rec["valve_command"], with_meta["valve_command"]) > 99.9
    no_gains = {k: v for k, v in meta.items() if k != "controller"}
    without = replay(cfg20, rec, no_gains, "closed_loop")
    # Kd 20 instead of 6 adds 14 V*s/m x tens of mm/s = several 0.1 V to the command during every step
    assert fit_percent(rec["valve_command"], without["valve_command"]) < 99.0


def test_supply_and_load_from_the_sidecar(plant, tmp_path):
    bench = plant.replace(params={"air.supply_pressure": 7.0e5})
    rec, meta = synthesise(bench, x0=0.09, load=4000.0, noise=None, duration=12.0, profile_kind="steps")
    assert meta["conditions"]["supply_pressure"] == 7.0e5
    sim = replay(plant, rec, meta, "plant_only")  # the nominal file says 8 bar
    assert sim.attrs["conditions"]["supply_pressure"] == 7.0e5
    assert sim.attrs["conditions"]["load_force"] == 4000.0
    for s, f in _fits(rec, sim, OUTPUTS).items():
        assert f > 99.9, (s, f)


# ------------------------------------------------------------------------------ resampling
def test_zoh_interval_average_hand_values():
    t = np.array([0.0, 1.0, 2.0])
    u = np.array([1.0, 3.0, 5.0])
    # [0,0.5): 1; [0.5,1.5): half 1 half 3 -> 2; [1.5,2.5): half 3 half 5 -> 4; before t0 the first value holds
    got = zoh_interval_average(t, u, np.array([-1.0, 0.0, 0.5, 1.5, 2.5]))
    assert np.allclose(got, [1.0, 1.0, 2.0, 4.0], atol=1e-12)


def test_oversampled_recording_replays_like_the_original(plant, clean):
    rec, meta = clean
    t = rec["time"].to_numpy()
    k = 4  # a logger at 4 kHz sampling the 1 kHz zero-order-hold command
    tf = (t[:-1, None] + np.arange(k)[None, :] * (1e-3 / k)).ravel()
    tf = np.concatenate((tf, t[-1:]))
    idx = np.minimum(np.searchsorted(t, tf + 1e-12, side="right") - 1, t.size - 1)
    fine = pd.DataFrame({"time": tf, "valve_command": rec["valve_command"].to_numpy()[idx],
                         "reference": rec["reference"].to_numpy()[idx]})
    for s in OUTPUTS:
        fine[s] = np.interp(tf, t, rec[s].to_numpy())
    sim = replay(plant, fine, meta, "plant_only")
    assert len(sim) == len(fine)
    # the ZOH average over each controller period recovers the 1 kHz command exactly
    for s, f in _fits(fine, sim, OUTPUTS).items():
        assert f > 99.9, (s, f)
    cl = replay(plant, fine, meta, "closed_loop")
    assert cl.attrs["noise_replay"] is False  # not on the controller clock
    assert fit_percent(fine["position"], cl["position"]) > 99.9


def test_jittered_clock(plant, clean):
    rec, meta = clean
    rng = np.random.default_rng(7)
    jit = rec.copy()
    jit["time"] = rec["time"] + np.r_[0.0, rng.uniform(-1e-4, 1e-4, len(rec) - 1)]  # logger jitter +/-0.1 ms
    sim = replay(plant, jit, meta, "plant_only")
    assert np.array_equal(sim["time"].to_numpy(), jit["time"].to_numpy())
    # at most 10 % of each 1 ms command value leaks into the neighbouring controller period:
    # a flow error of ~0.1 % of the command's sample-to-sample change, well below 0.5 % of fit
    for s, f in _fits(jit, sim, OUTPUTS).items():
        assert f > 99.5, (s, f)


def test_missing_samples(plant, clean):
    rec, meta = clean
    rng = np.random.default_rng(3)
    keep = np.sort(np.r_[0, len(rec) - 1, rng.choice(np.arange(1, len(rec) - 1), size=(9 * len(rec)) // 10, replace=False)])
    sparse = rec.iloc[keep].reset_index(drop=True)
    sim = replay(plant, sparse, meta, "plant_only")
    assert len(sim) == len(sparse)
    # a missing sample holds the previous command for one extra period. The pressures follow the
    # command within the chamber time constants (tens of ms), so they stay within 1 % of fit;
    # the plant-only position integrates every dead-band-edge decision and is not asserted here
    for s in ("pressure_a", "pressure_b"):
        assert fit_percent(sparse[s], sim[s]) > 99.0


# ------------------------------------------------------------------------------ initial state
def test_operating_point_is_the_median_of_the_first_50_ms_and_the_replay_starts_at_the_smoothed_position(plant, clean):
    rec, meta = clean
    spiky = rec.copy()
    spiky.loc[1, "pressure_a"] += 5e4  # a single glitch in the first 50 ms
    sim = replay(plant, spiky, meta, "closed_loop")
    c = sim.attrs["conditions"]
    assert c["initial_position"] == pytest.approx(0.06, abs=1e-9)  # at rest: every sample is x0
    assert c["initial_pressures"][0] == pytest.approx(rec["pressure_a"].iloc[2:50].median(), rel=1e-9)
    # the replay starts where every re-synchronised segment does: the smoothed recorded position (a cubic fit
    # through a resting servo's samples returns its position to round-off)
    assert c["start_position"] == pytest.approx(0.06, abs=1e-9)


# ------------------------------------------------------------------------------ noise
def test_recorded_noise_replay_tracks_the_dead_band_crossings(plant):
    rec, meta = synthesise(plant, x0=0.06, load=7000.0, kd=6.0, noise=PRACTICE_NOISE, seed=11, duration=20.0, profile_kind="steps")
    x = rec["position"].to_numpy()
    assert position_quantum(x) == pytest.approx(10e-6, rel=1e-6)
    # the Savitzky-Golay high-pass keeps most of 20 um white noise: the 41 ms cubic smoother passes 5.5 % of its
    # power (std share 0.972 left), the 0.3 s one used while the servo holds 0.7 % (0.996 left)
    assert 0.93 * 20e-6 < robust_std(position_noise_estimate(x, 1e-3)) < 1.03 * 20e-6
    with_noise = replay(plant, rec, meta, "closed_loop")
    without = replay(plant, rec, meta, "closed_loop", noise="none")
    assert with_noise.attrs["noise_replay"] and not without.attrs["noise_replay"]
    f_with = fit_percent(rec["valve_command"], with_noise["valve_command"])
    f_without = fit_percent(rec["valve_command"], without["valve_command"])
    # the noise moves the command across the valve dead band: replaying it reproduces the command
    assert f_with > f_without + 5.0, (f_with, f_without)


# ------------------------------------------------------------------------------ bad input
def test_bad_input(plant, clean):
    rec, meta = clean
    with pytest.raises(InputError, match="reference"):
        replay(plant, rec.drop(columns=["reference"]), meta, "closed_loop")
    with pytest.raises(InputError, match="valve_command"):
        replay(plant, rec.drop(columns=["valve_command"]), meta, "plant_only")
    with pytest.raises(InputError, match="mode"):
        replay(plant, rec, meta, "open_loop")
    with pytest.raises(InputError, match="outside the stroke"):
        replay(plant, rec.assign(position=rec["position"] * 1e3), meta, "plant_only")  # millimetres
    bad = dict(meta, controller={"kd": "six"})
    with pytest.raises(InputError, match="controller.kd"):
        replay(plant, rec, bad, "closed_loop")
    with pytest.raises(InputError, match="load_force"):
        replay(plant, rec, dict(meta, conditions={"load_force": "heavy"}), "closed_loop")


# ------------------------------------------------------------------------------ synthetic recordings
def test_practice_profile_matches_the_practice_recording():
    csv = SHARED / "practice_no_effect.csv.gz"
    if not csv.is_file():
        pytest.skip("shared practice recordings not present")
    df, meta = read_recording(csv)
    prof = practice_profile(meta["conditions"]["initial_position"], 0.160)
    # the sine is stored every 5 ms: chord error A*(w*dt)^2/8 = 8e-3*(0.157*0.005)^2/8 < 1e-9 m;
    # the file prints the reference to 0.1 um
    assert np.max(np.abs(prof.at(df["time"].to_numpy()) - df["reference"].to_numpy())) < 1e-7


def test_write_recording_round_trip(plant, tmp_path):
    rec, meta = synthesise(plant, x0=0.1, load=3000.0, seed=2, duration=3.0)
    path = tmp_path / "run.csv"
    csv, side = write_recording(rec, meta, path)
    assert side == tmp_path / "run.toml"
    back, m2 = read_recording(csv)
    assert list(back.columns) == ["time", "position", "reference", "valve_command", "pressure_a", "pressure_b", "supply_pressure"]
    assert np.allclose(back.to_numpy(), rec.to_numpy(), rtol=1e-9, atol=0)  # 10 significant digits
    assert m2["conditions"] == meta["conditions"] and m2["controller"] == meta["controller"]
    # the practice sensors: 10 um position steps, 1e6/65535 Pa pressure steps
    assert np.allclose(np.round(back["position"] / 10e-6) * 10e-6, back["position"], atol=1e-12)
    with pytest.raises(InputError, match="exists"):
        write_recording(rec, meta, path)
    with pytest.raises(InputError, match="csv"):
        write_recording(rec, meta, tmp_path / "run.parquet")


def test_synthesise_is_deterministic(plant):
    a, _ = synthesise(plant, seed=5, duration=2.0)
    b, _ = synthesise(plant, seed=5, duration=2.0)
    c, _ = synthesise(plant, seed=6, duration=2.0)
    assert a.equals(b)
    assert not a["pressure_a"].equals(c["pressure_a"])
    assert math.isclose(a["time"].iloc[-1], 2.0)


def test_recording_time_need_not_start_at_zero_and_pressures_are_optional(plant, clean):
    rec, meta = clean
    late = rec[["time", "position", "reference", "valve_command"]].copy()
    late["time"] += 100.0  # a logger clock that started earlier than the test
    for mode in ("closed_loop", "plant_only"):
        sim = replay(plant, late, meta, mode)
        assert sim["time"].iloc[0] == 100.0
        # no pressures recorded: the replay starts at rest balancing the load, as the synthetic test did
        assert sim.attrs["conditions"]["initial_pressures"] is None
        assert fit_percent(late["position"], sim["position"]) > 99.9
