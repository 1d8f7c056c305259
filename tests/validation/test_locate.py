"""Residual windows (compliance.validation.locate) and operating regimes (compliance.validation.regimes)."""

from __future__ import annotations


import numpy as np
import pandas as pd
import pytest

from compliance.model.config import load_plant
from compliance.errors import InputError
from compliance.validation.locate import (
    LocateSettings,
    hysteresis_windows,
    locate,
    merge_across_signals,
    smoothed_abs,
)
from compliance.validation.recorded_noise import noise_floor
from compliance.simulation.profiles import Profile
from compliance.recordings.synth import PRACTICE_NOISE, synthesise
from compliance.validation.regimes import REVERSAL_SPAN, compute_regimes
from compliance.validation.replay import replay
from compliance.simulation import Scenario
from compliance.plants import simulate
from compliance.validation.fit_metrics import per_unit_bases

SMOOTHING = LocateSettings().smoothing


@pytest.fixture(scope="module")
def plant():
    return load_plant("plant-a")


@pytest.fixture(scope="module")
def bases(plant):
    return {k: v["value"] for k, v in per_unit_bases(plant).items()}


# ------------------------------------------------------------------------------ building blocks
def test_noise_floor_of_white_noise_with_steps():
    rng = np.random.default_rng(0)
    y = rng.normal(0.0, 0.3, 20000) + np.repeat([0.0, 50.0, -20.0, 10.0], 5000)  # three large jumps
    # MAD of the differences: relative standard error ~ 1.1/sqrt(n) < 1 % for n = 20000; 3 % is > 3 sigma
    assert noise_floor(y) == pytest.approx(0.3, rel=0.03)
    assert noise_floor(np.zeros(100), minimum=1e-3) == 1e-3


def test_noise_floor_uses_the_rest_samples():
    rng = np.random.default_rng(1)
    y = rng.normal(0.0, 1.0, 4000)
    y[:2000] = np.cumsum(rng.normal(0.0, 5.0, 2000))  # a fast random walk while "moving"
    rest = np.r_[np.zeros(2000, bool), np.ones(2000, bool)]
    assert noise_floor(y, rest) == pytest.approx(1.0, rel=0.08)  # 2000 pairs: rel. s.e. ~ 2.5 %


def test_smoothed_abs_hand_values():
    t = np.arange(0.0, 1.0001, 0.001)
    assert np.allclose(smoothed_abs(t, np.full(t.size, -2.0), 0.05), 2.0)
    box = np.where((t >= 0.4) & (t <= 0.6), 1.0, 0.0)
    s = smoothed_abs(t, box, 0.1)
    assert s[500] == pytest.approx(1.0)  # window [0.45, 0.55] inside the box
    assert s[400] == pytest.approx(0.5, abs=0.01)  # half the window on the box edge
    assert s[300] == 0.0


def test_hysteresis_merge_and_minimum_duration():
    t = np.arange(0.0, 2.0, 0.001)
    lv = np.zeros(t.size)
    lv[(t >= 0.2) & (t < 0.5)] = 5.0  # window A
    lv[(t >= 0.5) & (t < 0.6)] = 2.5  # above off: A continues to 0.6
    lv[(t >= 0.65) & (t < 0.8)] = 5.0  # 50 ms gap -> merged with A (gap 0.1 s)
    lv[(t >= 1.2) & (t < 1.22)] = 5.0  # 20 ms: shorter than 50 ms -> dropped
    lv[(t >= 1.5) & (t < 1.7)] = 2.5  # above off but never above on -> no window
    wins = hysteresis_windows(t, lv, on=3.0, off=2.0, min_duration=0.05, merge_gap=0.1)
    assert len(wins) == 1
    a, b = wins[0]
    assert t[a] == pytest.approx(0.2) and t[b] == pytest.approx(0.799)


def test_settings_are_checked():
    with pytest.raises(InputError, match="k_off"):
        LocateSettings(k_on=2.0, k_off=3.0)
    with pytest.raises(InputError, match="smoothing"):
        LocateSettings(smoothing=0.0)


# ------------------------------------------------------------------------------ regimes
def test_regimes_on_a_hand_made_recording(plant):
    t = np.arange(0.0, 3.0, 0.001)
    v = 0.01  # m/s
    x = np.where(t < 1.0, 0.045 + v * t, np.where(t < 2.0, 0.055, 0.055 - v * (t - 2.0)))
    u = np.where(t < 1.0, 5.0, np.where(t < 2.0, 0.3, -2.0))
    # opening (U > 0: P->A, B->T): p_A/p_s = 0.375 <= 0.528 choked; p_atm/p_B = 0.675 > 0.528 subsonic
    pa = np.where(t < 2.0, 3.0e5, 2.5e5)
    pb = np.where(t < 2.0, 1.5e5, 6.0e5)  # closing (P->B, A->T): p_B/p_s = 0.75 subsonic; p_atm/p_A = 0.405 choked
    rec = pd.DataFrame({"time": t, "position": x, "valve_command": u, "pressure_a": pa, "pressure_b": pb})
    rg = compute_regimes(rec, plant, load=7000.0, supply_pressure=8.0e5)
    m = rg.masks

    def share(name, a, b):
        sel = (t >= a) & (t < b)
        return float(np.mean(m[name][sel]))

    # well inside each segment (the 51 ms velocity filter blurs the corners by ~25 ms)
    assert share("opening", 0.1, 0.9) == 1.0 and share("closing", 0.1, 0.9) == 0.0
    assert share("at_rest", 1.1, 1.9) == 1.0 and share("holding_under_load", 1.1, 1.9) == 1.0  # 7 kN > 2 x 420 N
    assert share("closing", 2.1, 2.9) == 1.0
    assert share("valve_saturated", 0.0, 1.0) == 1.0  # 5 V >= 4 V full opening
    assert share("valve_dead_band", 1.0, 2.0) == 1.0 and share("valve_dead_band", 2.0, 3.0) == 0.0
    assert share("a_choked", 0.0, 1.0) == 1.0 and share("b_subsonic", 0.0, 1.0) == 1.0
    assert share("b_subsonic", 2.0, 3.0) == 1.0 and share("a_choked", 2.0, 3.0) == 1.0
    assert share("a_choked", 1.0, 2.0) == 0.0  # dead band: no path open, no flow regime
    assert share("after_reversal", 2.1, 2.0 + REVERSAL_SPAN - 0.05) == 1.0
    assert share("after_reversal", 2.6, 3.0) == 0.0 and share("after_reversal", 0.0, 1.95) == 0.0
    # x = 45..55 mm on a 160 mm stroke: 28 % (low) then 34 % (mid) past 53.3 mm
    assert share("region_low", 0.1, 0.8) == 1.0 and share("region_mid", 1.1, 1.9) == 1.0


# ------------------------------------------------------------------------------ located windows
@pytest.mark.parametrize("noise", [None, PRACTICE_NOISE], ids=["clean", "noisy"])
def test_a_sensor_bump_is_located_where_it_was_put(plant, bases, noise):
    rec, meta = synthesise(plant, x0=0.06, load=7000.0, kd=6.0, noise=noise, seed=4)
    t = rec["time"].to_numpy()
    bumped = rec.copy()
    bumped.loc[(t >= 12.0) & (t < 12.5), "pressure_a"] += 3000.0  # 10 x the practice pressure noise
    sim = replay(plant, bumped, meta, "plant_only")
    rg = compute_regimes(bumped, plant, 7000.0)
    wins, floors, _ = locate(bumped, sim, rg, bases, exclude=("valve_command",))
    assert "valve_command" not in floors  # the plant-only input is not compared
    # the plant-only replay of the model's own recording leaves only the bump (and the noise)
    assert [w.signal for w in wins] == ["pressure_a"]
    w = wins[0]
    # the centred moving average moves the threshold crossings by at most half its window (25 ms)
    assert abs(w.start - 12.0) <= 0.05 and abs(w.end - 12.5) <= 0.05
    assert w.mean_residual == pytest.approx(3000.0, rel=0.1)


def test_an_unmodelled_disturbance_is_located_at_its_onset(plant, bases):
    rec, meta = synthesise(plant, x0=0.06, load=7000.0, kd=6.0, noise=None)
    t = rec["time"].to_numpy()
    u = rec["valve_command"].to_numpy().copy()
    u[(t >= 12.0) & (t < 12.2)] += 2.0  # the bench's valve got 2 V more than the logged command
    truth = simulate(plant, Scenario(duration=30.0, initial_position=0.06, command=Profile(t, u), load=7000.0))
    bench = rec.copy()
    for c in ("position", "pressure_a", "pressure_b"):
        bench[c] = truth[c].to_numpy()
    sim = replay(plant, bench, meta, "plant_only")
    rg = compute_regimes(bench, plant, 7000.0)
    wins, _, _ = locate(bench, sim, rg, bases, exclude=("valve_command",))
    assert wins, "the disturbance was not located"
    first = min(w.start for w in wins)
    assert abs(first - 12.0) <= 0.05  # causal: nothing differs before 12.0 s
    assert {"pressure_a", "pressure_b", "position"} <= {w.signal for w in wins}
    events = merge_across_signals(wins, rg)
    assert len(events) == 1 and events[0]["start"] == first
