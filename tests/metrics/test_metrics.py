"""Metrics on synthetic signals whose answers are known in closed form."""

import math

import control
import numpy as np
import pandas as pd
import pytest

from compliance import metrics as M
from compliance.errors import InputError

DT = 1e-3  # 1 kHz, the controller rate of plant A
# Linear interpolation between 1 ms samples of curves with time scales >= 0.1 s is exact to
# ~dt^2/(8 tau) ~ 1e-6 s; crossings are allowed a fifth of a sample.
T_TOL = 2e-4


def first_order(t, t_step, dead, tau, x0, dx):
    """x0 + dx (1 - exp(-(t - t_step - dead)/tau)) after the dead time."""
    s = np.clip(t - t_step - dead, 0.0, None)
    return x0 + dx * (1.0 - np.exp(-s / tau))


def second_order(t, t_step, zeta, wn, x0, dx):
    """Unit-step response of wn^2/(s^2 + 2 zeta wn s + wn^2), scaled (underdamped, analytic)."""
    s = np.clip(t - t_step, 0.0, None)
    wd = wn * math.sqrt(1 - zeta**2)
    phi = math.acos(zeta)
    y = 1 - np.exp(-zeta * wn * s) / math.sqrt(1 - zeta**2) * np.sin(wd * s + phi)
    return x0 + dx * y


@pytest.fixture
def grid():
    return np.arange(0, 6.0 + DT / 2, DT)


@pytest.mark.parametrize("direction", [+1, -1])
def test_first_order_dead_time_and_time_constant(grid, direction):
    tau, dead, x0, dx = 0.2, 0.05, 0.08, direction * 0.008
    x = first_order(grid, 1.0, dead, tau, x0, dx)
    r = np.where(grid >= 1.0, x0 + dx, x0)
    (ev,) = M.find_steps(grid, r)
    assert ev.t_step == pytest.approx(1.0, abs=DT)
    # with a vanishing detection threshold the dead time and tau are the textbook ones
    sm = M.step_response(grid, x, ev, detect=1e-9)
    assert sm.dead_time == pytest.approx(dead, abs=T_TOL)
    assert sm.time_constant == pytest.approx(tau, abs=T_TOL)
    # default threshold: motion detected at 1 % of the step -> dead + tau ln(1/0.99); tau reads
    # low by the same amount (the documented bias of the definition)
    sm = M.step_response(grid, x, ev)
    shift = tau * math.log(1 / 0.99)
    assert sm.dead_time == pytest.approx(dead + shift, abs=T_TOL)
    assert sm.time_constant == pytest.approx(tau - shift, abs=T_TOL)
    # 10-90 % rise time of a first-order lag is tau ln 9
    assert sm.rise_time == pytest.approx(tau * math.log(9), abs=T_TOL)
    # settling into +/-2 % of the final value: dead + tau ln(50), reported on the sample grid
    assert sm.settling_time == pytest.approx(dead + tau * math.log(50), abs=DT + T_TOL)
    assert sm.overshoot == pytest.approx(0.0, abs=1e-9)
    assert sm.steady_state_error == pytest.approx(0.0, abs=abs(dx) * 1e-6)
    assert not sm.rate_limited
    assert sm.marks["tau_632"][0] == pytest.approx(1.0 + dead + tau, abs=T_TOL)


def test_overshoot_rise_settling_match_step_info(grid):
    zeta, wn, x0, dx = 0.3, 10.0, 0.05, 0.01
    x = second_order(grid, 1.0, zeta, wn, x0, dx)
    r = np.where(grid >= 1.0, x0 + dx, x0)
    (ev,) = M.find_steps(grid, r)
    sm = M.step_response(grid, x, ev)
    expected_os = math.exp(-math.pi * zeta / math.sqrt(1 - zeta**2))  # 37.2 %
    # the peak is sampled every 1 ms; near the peak the curve is flat to ~(wn dt)^2/2 ~ 5e-5
    assert sm.overshoot == pytest.approx(expected_os, abs=1e-4)
    i = grid >= 1.0
    info = control.step_info((x[i] - x0), T=grid[i] - 1.0, yfinal=dx)
    assert 100 * sm.overshoot == pytest.approx(info["Overshoot"], abs=0.01)
    # step_info takes the first sample at or after each crossing; we interpolate: within a sample
    assert sm.rise_time == pytest.approx(info["RiseTime"], abs=DT)
    assert sm.settling_time == pytest.approx(info["SettlingTime"], abs=DT)


def test_stalled_step_has_no_time_constant(grid):
    # a 1.6 mm step that stops after 0.7 mm (valve dead zone): 63.2 % is never reached
    x = first_order(grid, 1.0, 0.05, 0.1, 0.08, 0.0007)
    r = np.where(grid >= 1.0, 0.0816, 0.08)
    (ev,) = M.find_steps(grid, r)
    sm = M.step_response(grid, x, ev)
    assert sm.time_constant is None
    assert "stalled" in sm.reasons["time_constant"]
    assert sm.steady_state_error == pytest.approx(0.0009, abs=1e-7)


def test_rate_limited_step_is_flagged(grid):
    x = first_order(grid, 1.0, 0.02, 0.15, 0.08, 0.016)
    r = np.where(grid >= 1.0, 0.096, 0.08)
    u = np.where((grid >= 1.0) & (grid < 1.1), 5.0, 0.5)
    (ev,) = M.find_steps(grid, r)
    sm = M.step_response(grid, x, ev, valve_command=u, command_saturation=4.0)
    assert sm.rate_limited
    assert sm.reasons["time_constant"].startswith("saturated:")
    sm = M.step_response(grid, x, ev, valve_command=np.minimum(u, 3.9), command_saturation=4.0)
    assert not sm.rate_limited


def test_find_steps_sequence(grid):
    r = np.full(grid.shape, 0.1)
    r[grid >= 1.0] = 0.108
    r[grid >= 4.0] = 0.1
    ev = M.find_steps(grid, r)
    assert [round(e.t_step, 6) for e in ev] == [1.0, 4.0]
    assert ev[0].size == pytest.approx(0.008) and ev[1].size == pytest.approx(-0.008)
    assert ev[0].t_end == pytest.approx(4.0)
    # a sinusoid is not a step sequence
    assert M.find_steps(grid, 0.1 + 0.008 * np.sin(2 * np.pi * 0.05 * grid)) == []


def test_ramp_speed_and_stroke_time():
    t = np.arange(0, 8.0, DT)
    L, v = 0.16, 0.032  # 5 s full stroke
    x = np.clip(v * (t - 0.5), 0, L)
    vmax, vo, vc = M.speed_extremes(t, x)
    assert vmax == pytest.approx(v, rel=1e-9) and vo == pytest.approx(v, rel=1e-9) and vc == 0.0
    T, t1, t2, why = M.stroke_time(t, x, L, "opening")
    assert why is None
    assert T == pytest.approx(L / v, abs=1e-6)  # linear interpolation of a ramp is exact
    assert (t1, t2) == (pytest.approx(0.5 + 0.25 * L / v), pytest.approx(0.5 + 0.75 * L / v))
    # a cushion slowing the last 10 % does not change the 25-75 % time
    xc = np.where(x > 0.9 * L, 0.9 * L + 0.3 * (x - 0.9 * L), x)
    assert M.stroke_time(t, xc, L, "opening")[0] == pytest.approx(L / v, abs=1e-6)
    # closing
    Tc = M.stroke_time(t, L - x, L, "closing")[0]
    assert Tc == pytest.approx(L / v, abs=1e-6)
    # a stroke that stops half way has no time, with a reason
    T, _, _, why = M.stroke_time(t, np.minimum(x, 0.5 * L), L, "opening")
    assert T is None and "50 %" in why


def test_dead_band_of_a_backlash():
    """Play operator of width w: the loop width is w."""
    w = 0.0017
    rate, a, x0 = 5e-4, 0.0032, 0.08
    leg = a / rate
    t = np.arange(0, 6 * leg + 1.0, DT)
    knots_t = [0, 0.5, 0.5 + leg, 0.5 + 3 * leg, 0.5 + 5 * leg, 0.5 + 6 * leg]
    knots_x = [x0, x0, x0 + a, x0 - a, x0 + a, x0]
    r = np.interp(t, knots_t, knots_x)
    x = np.empty_like(r)
    x[0] = x0
    for i in range(1, r.size):
        x[i] = min(max(x[i - 1], r[i] - w / 2), r[i] + w / 2)
    db = M.dead_band(t, x, r)
    # the reference moves 0.5 um per sample: first crossings are exact to one sample
    assert db.width == pytest.approx(w, abs=2 * rate * DT)
    assert db.width_max == pytest.approx(w, abs=2 * rate * DT)
    with pytest.raises(InputError):
        M.dead_band(t, x, np.linspace(0, 1, t.size))  # never falls


def test_hold_drift_and_limit_cycle():
    t = np.arange(3.0, 13.0, DT)
    d, a, f = 0.0004, 0.0002, 1.0  # 0.4 mm drift over 10 s, 0.2 mm limit cycle at 1 Hz
    # cosine over whole periods is orthogonal to the line, so the line fit sees the drift only
    x = 0.128 + d * (t - 3.0) / 10.0 + a * np.cos(2 * np.pi * f * (t - 3.0))
    h = M.hold(t, x, np.full(t.shape, 0.128), 3.0, 13.0)
    assert h.drift == pytest.approx(d * (t[-1] - t[0]) / 10.0, rel=2e-3)
    assert h.limit_cycle_amplitude == pytest.approx(a, rel=2e-3)
    assert h.steady_state_error == pytest.approx(d / 2, rel=2e-3)


def test_tracking_and_saturation():
    t = np.arange(0, 40.0, DT)
    r = 0.08 + 0.008 * np.sin(2 * np.pi * 0.05 * t)
    rms, mx = M.tracking_errors(t, r - 0.0005, r, 10.0)
    assert rms == pytest.approx(0.0005) and mx == pytest.approx(0.0005)
    u = 10.0 * np.sin(2 * np.pi * 0.05 * t)
    # |10 sin| >= 4 V for 1 - (2/pi) asin(0.4) of the time
    frac = M.saturation_fraction(t, u, 4.0)
    assert frac == pytest.approx(1 - 2 / np.pi * math.asin(0.4), abs=1e-3)


def test_independent_adjustment_arithmetic():
    cross, own = M.independent_adjustment({"opening": 5.0, "closing": 5.0}, {"opening": 10.0, "closing": 5.1}, "opening")
    assert cross == pytest.approx(0.02) and own == pytest.approx(1.0)


def test_frame_columns_names_missing_column():
    df = pd.DataFrame({"time": [0.0, 1.0], "position": [0.0, 0.0]})
    with pytest.raises(InputError, match="case7.csv: column 'reference'"):
        M.frame_columns(df, "time", "reference", where="case7.csv")


def test_same_functions_on_a_dataframe(grid):
    """One implementation: a DataFrame with canonical columns gives the numbers arrays give."""
    x = first_order(grid, 1.0, 0.05, 0.2, 0.08, 0.008)
    r = np.where(grid >= 1.0, 0.088, 0.08)
    df = pd.DataFrame({"time": grid, "position": x, "reference": r, "valve_command": np.zeros_like(grid)})
    tt, xx, rr = M.frame_columns(df, "time", "position", "reference")
    (ev,) = M.find_steps(tt, rr)
    assert M.step_response(tt, xx, ev).time_constant == M.step_response(grid, x, M.find_steps(grid, r)[0]).time_constant
