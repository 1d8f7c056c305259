"""Which steps measure the time constant (metrics.step_eligibility), on first-order responses with known answers.

A first-order loop x' = (r - x) / tau driven by a set-point step of h, or by the same step through a
rate limiter of rate R (a ramp of duration T_r = h / R): its 63.2 % point comes later by
tau ln(tau (exp(T_r / tau) - 1) / T_r) ~ T_r / 2 when T_r << tau, which is why a ramp longer than 10 % of
tau (a shift over 5 % of tau) makes a step *ramped*: it is no longer a step test.
"""

import math

import numpy as np
import pytest

from compliance import metrics as M
from compliance.metrics.step_eligibility import RAMP_FRACTION, StepLimits, time_constant_eligibility, time_constant_value

DT = 1e-4
TAU = 0.15
H = 0.008  # a 5 % step of a 160 mm stroke


def _response(rate=None, stop_short=1.0, t_end=3.0):
    """Set-point step of H at 1 s (through a ramp of ``rate`` when given); the loop settles at ``stop_short`` x H."""
    t = np.arange(0.0, t_end, DT)
    r_raw = np.where(t >= 1.0, H, 0.0)
    r = r_raw if rate is None else np.clip((t - 1.0) * rate, 0.0, H)
    x = np.zeros_like(t)
    for k in range(1, t.size):
        x[k] = x[k - 1] + DT * (stop_short * r[k - 1] - x[k - 1]) / TAU
    return t, x, r_raw


def _measure(t, x, r, **kw):
    (ev,) = M.find_steps(t, r)
    sm = M.step_response(t, x, ev, **kw)
    return ev, sm


def test_ramp_shifts_the_632_point_by_half_the_ramp():
    t, x, r = _response()
    ev0, sm0 = _measure(t, x, r)
    t63_step = sm0.marks["tau_632"][0] - ev0.t_step
    assert t63_step == pytest.approx(TAU, rel=0.002)
    for ramp in (RAMP_FRACTION * TAU, 0.2 * TAU, TAU):
        t, xr, r = _response(rate=H / ramp)
        ev, sm = _measure(t, xr, r)
        shift = sm.marks["tau_632"][0] - ev.t_step - t63_step
        assert shift == pytest.approx(TAU * math.log(TAU * (math.exp(ramp / TAU) - 1) / ramp), rel=0.01)
        if ramp <= 0.2 * TAU:
            assert shift == pytest.approx(ramp / 2, rel=0.05)
    # at the threshold the 63.2 % point moves by RAMP_FRACTION / 2 = 5 % of tau


def test_a_ramped_step_is_excluded_and_says_so():
    t, x, r = _response(rate=H / (0.3 * TAU))  # a limiter at 178 mm/s on an 8 mm step: 0.045 s ramp
    ev, sm = _measure(t, x, r)
    ok, why, detail = time_constant_eligibility(0, 1, ev, sm, StepLimits(ramp_rate={+1: H / (0.3 * TAU), -1: 0.0}))
    assert not ok and why.startswith("ramped:") and detail["excluded"] == "ramped"
    # the same step with the limiter not acting (injected downstream of it) measures tau
    t, x, r = _response()
    ev, sm = _measure(t, x, r)
    ok, why, detail = time_constant_eligibility(0, 1, ev, sm, StepLimits())
    assert ok and why is None and "excluded" not in detail
    # first-order: tau to 63.2 % of the travel, less the 1 % motion-detection bias tau ln(1/0.99)
    assert time_constant_value(sm)[0] == pytest.approx(TAU * (1 - math.log(1 / 0.99)), rel=0.01)


def test_saturated_and_not_from_rest_and_dead_zone_steps_are_excluded():
    t, x, r = _response()
    u = np.where((t >= 1.0) & (t < 1.05), 5.0, 0.5)  # the command passes 4 V before 63.2 %
    ev, sm = _measure(t, x, r, valve_command=u, command_saturation=4.0)
    ok, why, detail = time_constant_eligibility(0, 1, ev, sm, StepLimits(command_saturation={+1: 4.0, -1: 4.0}))
    assert not ok and why.startswith("saturated:") and detail["command_peak"] == pytest.approx(5.0)
    ok, why, detail = time_constant_eligibility(1, 2, ev, sm, StepLimits())
    assert not ok and detail["excluded"] == "not_from_rest"
    # 0.368 x 8 mm = 2.94 mm from the set-point: inside 2 x a 1.5 mm stall band
    ok, why, detail = time_constant_eligibility(0, 1, ev, sm, StepLimits(stall={+1: 1.5e-3, -1: 1.5e-3}))
    assert not ok and detail["excluded"] == "dead_zone"


def test_achieved_and_commanded_readings_of_a_servo_stopping_short():
    t, x, r = _response(stop_short=0.89)  # stops 11 % short, as plant A's steps do in the dead zone
    ev, sm = _measure(t, x, r)
    tau_a, _ = time_constant_value(sm, "achieved")
    tau_c, _ = time_constant_value(sm, "commanded")
    detect = TAU * math.log(1 / 0.99)
    assert tau_a == pytest.approx(TAU - detect, rel=0.01)
    # 63.2 % of the commanded step is 0.632 / 0.89 = 71 % of the travel made: -tau ln(1 - 0.632 / 0.89)
    assert tau_c == pytest.approx(-TAU * math.log(1 - 0.632 / 0.89) - detect, rel=0.01)
