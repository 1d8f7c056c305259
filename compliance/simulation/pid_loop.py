"""The compiled PID loop of plant A (seed 000): RK4 plant, controller on its own sample clock.

The controller runs every ``controller.sample_time`` with a zero-order hold: PID, dead-zone
compensation (seed 000 eq. 3), saturation; the same loop runs plant-only from a recorded or
profiled valve command.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from numba import njit

from compliance.errors import SimulationError
from compliance.model.assembly import initial_state, load_curve_arrays, parameter_vector, plant_rhs, valve_lag_input
from compliance.model.config import PlantConfig
from compliance.model.pid_controller import dead_zone_compensation, first_order_filter_gain, pid_step, saturate
from compliance.model.vector_slots import *  # noqa: F403
from compliance.model.vector_slots import N_AUX, N_STATES
from compliance.simulation.rk4 import N_OUT, OUTPUT_COLUMNS, interp_uniform, record_sample, rk4_step, zoh_average
from compliance.simulation.scenario import Scenario, sample_profile


@njit(cache=True, error_model="numpy")
def simulate_core(P, y0, ref, cmd, closed_loop, pos_noise, pos_quantum, lx, ly, n_samples, n_sub, out):
    """Integrate the plant with its controller for ``n_samples`` controller periods.

    Parameters
    ----------
    P : ndarray
        Parameter vector.
    y0 : ndarray
        Initial state.
    ref, cmd : ndarray
        Reference [m] and open-loop command [V] per controller sample (length n_samples + 1).
    closed_loop : bool
        Run the PID (True) or apply ``cmd`` (False).
    pos_noise : ndarray
        Additive position noise per sample [m].
    pos_quantum : float
        Position quantisation [m].
    lx, ly : ndarray
        Load curve.
    n_samples, n_sub : int
        Number of controller periods and RK4 steps per period.
    out : ndarray
        (n_samples + 1, N_OUT) output array, filled in place.

    Returns
    -------
    int
        -1 on success, else the sample index at which the state became non-physical.
    """
    ts = P[P_TSAMP]
    h = ts / n_sub
    y = y0.copy()
    k1 = np.zeros(N_STATES)
    k2 = np.zeros(N_STATES)
    k3 = np.zeros(N_STATES)
    k4 = np.zeros(N_STATES)
    tmp = np.zeros(N_STATES)
    aux = np.zeros(N_AUX)
    u_hist = np.zeros(n_samples + 1)
    sensor = P[P_SL_ON] != 0.0
    x_hist = np.zeros(n_samples * n_sub + 1) if sensor else np.zeros(1)
    x_hist[0] = y[S_X]
    x_sensor = y[S_X]
    xd_prev = y[S_X]
    lag_decay = 0.0  # exp(-h/tau): 0 = no lag
    lag_ramp = 1.0  # tau -> 0 limit: the sensor reads the (delayed) position itself
    if sensor and P[P_SL_TAU] > 0.0:
        lag_decay = math.exp(-h / P[P_SL_TAU])
        lag_ramp = 1.0 - P[P_SL_TAU] / h * (1.0 - lag_decay)
    alpha = first_order_filter_gain(P[P_FILT], ts)
    x_filt = 0.0
    integral = 0.0
    valve_delay = P[P_VD_TD] if P[P_VD_ON] != 0.0 else 0.0
    sensor_delay = P[P_SL_TD] if sensor else 0.0
    if P[P_VD_ON] != 0.0:
        y[S_SP] = valve_lag_input(P, cmd[0] if not closed_loop else P[P_UCEN])
    step_index = 0
    for k in range(n_samples + 1):
        # --- measurement at t_k
        xm = x_sensor if sensor else y[S_X]
        xm += pos_noise[k]
        if pos_quantum > 0.0:
            xm = pos_quantum * math.floor(xm / pos_quantum + 0.5)
        # --- controller
        u_d = 0.0
        if closed_loop:
            if k == 0:
                x_filt = xm
            x_new = x_filt + alpha * (xm - x_filt)
            rate = (x_new - x_filt) / ts
            x_filt = x_new
            u_d, integral = pid_step(ref[k] - xm, rate, integral, P[P_KP], P[P_KI], P[P_KD], ts)
            if P[P_LC] > 0.0:
                u_c = dead_zone_compensation(u_d, P[P_CDZP], P[P_CDZN], P[P_CSLP], P[P_CSLN], P[P_LC])
            else:
                u_c = u_d
            u = saturate(u_c, P[P_ULIM]) + P[P_UCEN]
        else:
            u = cmd[k]
        if k == 0 and P[P_VD_ON] != 0.0 and closed_loop:
            y[S_SP] = valve_lag_input(P, u)
        u_hist[k] = u
        # --- record the sample
        u_now = u if valve_delay <= 0.0 else zoh_average(u_hist, ts, k * ts - valve_delay, k * ts - valve_delay)
        plant_rhs(y, P, u_now, lx, ly, k1, aux)  # also the first RK4 slope when there is no valve delay
        record_sample(out, k, ts, xm, ref[k], u, u_d, y, aux, P)
        if k == n_samples:
            break
        # --- integrate to t_{k+1}
        for j in range(n_sub):
            t0 = (k * n_sub + j) * h
            if valve_delay > 0.0:
                u_step = zoh_average(u_hist, ts, t0 - valve_delay, t0 + h - valve_delay)
            else:
                u_step = u
            rk4_step(y, P, u_step, lx, ly, h, k1, k2, k3, k4, tmp, aux, j == 0 and valve_delay <= 0.0)
            step_index += 1
            if sensor:
                x_hist[step_index] = y[S_X]
                xd = interp_uniform(x_hist, h, step_index * h - sensor_delay)
                # first-order lag integrated exactly for an input linear over the step
                x_sensor = lag_decay * x_sensor + (1.0 - lag_decay) * xd_prev + (xd - xd_prev) * lag_ramp
                xd_prev = xd
        if not (math.isfinite(y[S_X]) and math.isfinite(y[S_PA]) and math.isfinite(y[S_PB])):
            return k
        if y[S_PA] <= 0.0 or y[S_PB] <= 0.0 or abs(y[S_V]) > 100.0:
            return k
    return -1


def simulate_pid(cfg: PlantConfig, scenario: Scenario) -> pd.DataFrame:
    """Run ``scenario`` through the PID loop (or plant-only from its command); see :func:`simulate`."""
    P = parameter_vector(cfg, load=scenario.load, flow_control=scenario.flow_control)
    ts = P[P_TSAMP]
    n_sub = int(round(ts / cfg.p("simulation.step")))
    n_samples = int(round(scenario.duration / ts))
    t = np.arange(n_samples + 1) * ts
    closed = scenario.command is None
    ref = sample_profile(scenario.reference, t, scenario.initial_position)
    cmd = sample_profile(scenario.command, t, P[P_UCEN])
    noise = scenario.noise
    rng = np.random.default_rng(scenario.seed)
    pos_noise = rng.normal(0.0, noise.position_std, t.size) if noise and noise.position_std > 0 else np.zeros(t.size)
    if scenario.position_noise is not None:
        given = np.asarray(scenario.position_noise, dtype=float)
        pos_noise = np.zeros(t.size)
        pos_noise[: min(t.size, given.size)] = given[: t.size]
    y0 = initial_state(cfg, P, scenario.initial_position, scenario.initial_pressures)
    lx, ly = load_curve_arrays(cfg)
    out = np.zeros((n_samples + 1, N_OUT))
    status = simulate_core(P, y0, ref, cmd, closed, pos_noise, noise.position_quantum if noise else 0.0, lx, ly, n_samples, n_sub, out)
    if status >= 0:
        raise SimulationError(
            f"the simulation of '{cfg.name}' became non-physical at t = {status*ts:.3f} s "
            f"(non-finite or non-positive pressure); check the parameters or reduce simulation.step"
        )
    df = pd.DataFrame(out, columns=list(OUTPUT_COLUMNS))
    if noise and (noise.pressure_std > 0 or noise.pressure_quantum > 0):
        for col in ("pressure_a", "pressure_b", "supply_pressure"):
            vals = df[col].to_numpy() + rng.normal(0.0, noise.pressure_std, t.size)
            if noise.pressure_quantum > 0:
                vals = noise.pressure_quantum * np.round(vals / noise.pressure_quantum)
            df[col] = vals
    df.attrs["plant"] = cfg.name
    df.attrs["closed_loop"] = closed
    return df

