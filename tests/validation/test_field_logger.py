"""A field logger between the plant and the file: its clock, its anti-alias filter, delays, calibration, resolution."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from compliance.errors import InputError
from compliance.validation.logger_model import LoggerModel, first_order_filter, logger_model
from compliance.validation.recorded_noise import noise_floor, quantisation_std, sensor_noise_std
from compliance.validation.resampling import logged_indices, on_controller_clock


def _log(step: float, duration: float = 2.0) -> pd.DataFrame:
    # time stamps as a CSV parser returns them: 0.004 * k is not exactly k * 4 * 0.001
    t = np.array([float(f"{k * step:.3f}") for k in range(int(round(duration / step)) + 1)])
    ref = np.where(t >= 1.0, 0.07, 0.06) + np.where(t < 0.5, 0.0, np.minimum(t - 0.5, 0.25) * 0.004)
    return pd.DataFrame({"time": t, "position": 0.06 + 0.0 * t, "reference": ref, "valve_command": np.sin(t)})


@pytest.mark.parametrize("step", [0.001, 0.002, 0.004, 0.005, 0.010])
def test_every_logger_rate_from_100_hz_to_the_controllers_is_read(step):
    """250 Hz stamps parsed from text sit at 0.004 +- 1e-16 s: never refused for it (tolerant comparison)."""
    frame = _log(step)
    out, note = on_controller_clock(frame, 1e-3, "rec.csv")
    assert out["time"].size == 2001
    assert (note is None) == (step == 0.001)
    idx = logged_indices(frame["time"].to_numpy(), 1e-3)
    assert np.array_equal(idx, np.arange(0, 2001, int(round(step * 1e3))))


def test_a_log_slower_than_100_hz_is_refused_with_a_consistent_message():
    with pytest.raises(InputError, match=r"logged every 20 ms \(median\), slower than 100 Hz"):
        on_controller_clock(_log(0.020), 1e-3, "rec.csv")


def test_set_point_steps_hold_and_ramps_keep_ramping_between_logged_samples():
    out, _ = on_controller_clock(_log(0.004), 1e-3, "rec.csv")
    t, ref = out["time"].to_numpy(), out["reference"].to_numpy()
    exact = np.where(t >= 1.0, 0.07, 0.06) + np.where(t < 0.5, 0.0, np.minimum(t - 0.5, 0.25) * 0.004)
    ramp = (t > 0.51) & (t < 0.74)
    assert np.max(np.abs(ref[ramp] - exact[ramp])) < 1e-9  # a ramp is interpolated
    assert ref[np.searchsorted(t, 0.999)] == pytest.approx(exact[np.searchsorted(t, 0.996)])  # a step is held
    assert ref[np.searchsorted(t, 1.0)] == pytest.approx(0.071)


def test_first_order_anti_alias_filter_delays_slow_signals_by_one_over_two_pi_fc():
    ts, fc = 1e-3, 80.0
    t = np.arange(0.0, 4.0, ts)
    x = np.sin(2 * np.pi * 0.5 * t)
    y = first_order_filter(x, fc, ts)
    lag = 1.0 / (2 * np.pi * fc)  # 1.99 ms
    tail = t > 1.0
    # prewarping the cutoff shortens the low-frequency lag by (pi fc ts)^2 / 3 = 2 % (40 us): 1.3e-4 at 0.5 Hz
    assert np.max(np.abs(y[tail] - np.sin(2 * np.pi * 0.5 * (t[tail] - lag)))) < 2e-4
    assert np.allclose(first_order_filter(np.full(50, 3.0), fc, ts), 3.0)  # starts at rest


def test_logger_model_applies_declared_delay_and_gauge_gain():
    meta = {"logger": {"anti_alias_cutoff": 200.0},
            "channels": {"pressure_a": {"delay": 0.003, "gain": 1.01}, "position": {"anti_alias_cutoff": 100.0}}}
    m = logger_model(meta)
    assert m.cutoff == {"position": 100.0, "valve_command": 200.0, "pressure_a": 200.0, "pressure_b": 200.0, "supply_pressure": 200.0}
    bare = LoggerModel(delay={"pressure_a": 0.003}, gain={"pressure_b": 1.01})
    ts = 1e-3
    p = 5e5 + 1e5 * np.sin(np.arange(1000) * ts * 2 * np.pi)
    out = bare.apply({"pressure_a": p, "pressure_b": p, "reference": p}, ts)
    assert out["pressure_a"][500] == pytest.approx(p[497])
    assert out["pressure_b"][0] - 101325.0 == pytest.approx(1.01 * (p[0] - 101325.0))  # on gauge pressure
    assert out["reference"] is p
    assert logger_model({}) is None


def test_noise_floors_never_fall_below_the_quantisation():
    """50 um transducer, 20 um noise: most differences are zero, but the floor stays >= q/sqrt(12) = 14.4 um."""
    rng = np.random.default_rng(1)
    q = 50e-6
    x = np.round((0.07 + rng.normal(0.0, 20e-6, 20000)) / q) * q
    assert quantisation_std(x) == pytest.approx(q / math.sqrt(12.0), rel=1e-6)
    assert noise_floor(x) >= q / math.sqrt(12.0) * (1 - 1e-6)  # the lattice step as float differences give it
    assert noise_floor(np.full(100, 0.07), resolution=q) == pytest.approx(q / math.sqrt(12.0))
    s = sensor_noise_std(x)
    assert math.sqrt(20e-6**2 + q * q / 12.0) * 0.8 < s < math.sqrt(20e-6**2 + q * q / 12.0) * 1.25


def test_noise_share_is_what_the_filter_passes_of_white_noise():
    """The controller read the transducer's noise; the DAQ logged it through its filter (80 Hz at 1 kHz: ~0.45 of it)."""
    rng = np.random.default_rng(2)
    n = rng.normal(0.0, 1.0, 200000)
    m = LoggerModel(cutoff={"position": 80.0})
    share = m.noise_share("position", 1e-3)
    assert share == pytest.approx(np.std(first_order_filter(n, 80.0, 1e-3)), rel=0.02)
    assert 0.40 < share < 0.50 and m.noise_share("pressure_a", 1e-3) == 1.0


@pytest.mark.parametrize("delay", [0.0, 0.0025, -0.0035])
def test_logged_prefix_gives_the_whole_replays_logged_values_from_final_samples_only(delay):
    """A replay stopped early is judged on what the logger makes of the samples simulated so far: the same
    numbers, bit for bit, as the logger on the whole replay (filter state carried across chunks, delays
    interpolated between the same samples), and never a sample not simulated yet (NaN beyond ``final``)."""
    from compliance.validation.logger_model import LoggedPrefix

    ts, n = 1e-3, 3001
    rng = np.random.default_rng(3)
    sim = {"position": 0.06 + np.cumsum(rng.normal(0.0, 1e-5, n)), "pressure_a": 4e5 + np.cumsum(rng.normal(0.0, 300.0, n))}
    lg = LoggerModel(cutoff={"position": 150.0, "pressure_a": 80.0}, delay={"position": delay, "pressure_a": -delay},
                     gain={"pressure_a": 1.01}, offset={"position": 2e-5})
    whole = lg.apply(sim, ts)
    prefix = LoggedPrefix(lg, ts, n)
    assert prefix.lead == (math.ceil(abs(delay) / ts) + 1 if delay else 0)
    for final in (400, 401, 1700, 3001):  # the checks a stopping replay makes as its segments end
        idx = np.arange(0, final - prefix.lead, 4)
        for name, x in sim.items():
            partial = np.where(np.arange(n) < final, x, np.nan)  # what is not simulated yet
            got = prefix.values(name, partial, final, idx)
            assert np.array_equal(got, whole[name][idx]), (name, final)
