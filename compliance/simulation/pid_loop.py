"""The compiled PID loop of plant A (seed 000): RK4 plant, controller on its own sample clock.

The controller runs every ``controller.sample_time`` with a zero-order hold: the set-point rate
limiter (when a rate is set), PID, dead-zone compensation (seed 000 eq. 3), saturation; the same loop runs plant-only from a recorded or
profiled valve command.
"""

from __future__ import annotations


import numpy as np
import pandas as pd
from numba import njit

from compliance.errors import SimulationError
from compliance.model.assembly import plant_rhs, valve_lag_input
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state
from compliance.model.config import PlantConfig
from compliance.model.pid_controller import first_order_filter_gain, limiter_sample, pid_sample, saturate
from compliance.effects.sensor_lag import P_SL_ON, P_SL_TD
from compliance.effects.valve_dynamics import P_VD_ON, P_VD_TD, S_SP
from compliance.model.vector_slots import P_FILT, P_KD, P_KI, P_KP, P_RL_ON, P_TSAMP, P_UCEN, P_ULIM, S_V, S_X
from compliance.simulation.rk4 import O_PA, O_PB, O_PS, measured_position, non_physical, output_buffer, output_frame, record_sample
from compliance.simulation.rk4 import rk4_step, rk4_workspace
from compliance.simulation.rk4 import sensor_lag_advance, sensor_lag_coefficients, sensor_lag_start, zoh_average
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
    pos_noise, pos_quantum : ndarray, float
        Additive position noise per sample and position quantisation [m].
    lx, ly : ndarray
        Load curve.
    n_samples, n_sub : int
        Number of controller periods and RK4 steps per period.
    out : ndarray
        (n_samples + 1, N_OUT) output array (``rk4.output_buffer``), filled in place.

    Returns
    -------
    int
        -1 on success, else the sample index at which the state became non-physical.
    """
    ts = P[P_TSAMP]
    h = ts / n_sub
    y = y0.copy()
    k1, k2, k3, k4, tmp, aux = rk4_workspace()
    u_hist = np.zeros(n_samples + 1)
    sensor = P[P_SL_ON] != 0.0
    x_hist = np.zeros(n_samples * n_sub + 1) if sensor else np.zeros(1)
    x_hist[0] = y[S_X]
    lag_decay, lag_ramp = sensor_lag_coefficients(P, h)
    x_sensor, xd_prev, v0 = sensor_lag_start(P, y[S_X], y[S_V], sensor)
    alpha = first_order_filter_gain(P[P_FILT], ts)
    x_filt, integral = 0.0, 0.0
    limiter, r_lim = P[P_RL_ON] != 0.0, y0[S_X]  # the limiter starts at the gate (bumpless: a step at t = 0 ramps)
    valve_delay = P[P_VD_TD] if P[P_VD_ON] != 0.0 else 0.0
    sensor_delay = P[P_SL_TD] if sensor else 0.0
    if P[P_VD_ON] != 0.0:
        y[S_SP] = valve_lag_input(P, cmd[0] if not closed_loop else P[P_UCEN])
    step_index = 0
    for k in range(n_samples + 1):
        # --- measurement and controller at t_k
        xm = measured_position(x_sensor if sensor else y[S_X], pos_noise[k], pos_quantum)
        u_d = 0.0
        if closed_loop:
            if k == 0:
                x_filt = xm
            if limiter:
                r_lim = limiter_sample(P, ref[k], r_lim, xm, ts)
            u_d, u_c, x_filt, integral = pid_sample(P, xm, r_lim if limiter else ref[k], x_filt, integral, alpha,
                                                    P[P_KP], P[P_KI], P[P_KD], ts)
            u = saturate(u_c, P[P_ULIM]) + P[P_UCEN]
        else:
            u = cmd[k]
        if k == 0 and P[P_VD_ON] != 0.0 and closed_loop:
            y[S_SP] = valve_lag_input(P, u)
        u_hist[k] = u
        # --- record the sample; its slope is also the first RK4 slope when there is no valve delay
        u_now = u if valve_delay <= 0.0 else zoh_average(u_hist, ts, k * ts - valve_delay, k * ts - valve_delay)
        plant_rhs(y, P, u_now, lx, ly, k1, aux)
        record_sample(out, k, ts, xm, ref[k], u, u_d, y, aux, P)
        if k == n_samples:
            break
        # --- integrate to t_{k+1}
        for j in range(n_sub):
            t0 = (k * n_sub + j) * h
            u_step = u if valve_delay <= 0.0 else zoh_average(u_hist, ts, t0 - valve_delay, t0 + h - valve_delay)
            rk4_step(y, P, u_step, lx, ly, h, k1, k2, k3, k4, tmp, aux, j == 0 and valve_delay <= 0.0)
            step_index += 1
            if sensor:
                x_sensor, xd_prev = sensor_lag_advance(x_hist, step_index, y[S_X], h, sensor_delay, x_sensor, xd_prev,
                                                       lag_decay, lag_ramp, v0)
        if non_physical(y):
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
    rng = np.random.default_rng(scenario.seed) if noise else None  # drawn from only with noise
    pos_noise = rng.normal(0.0, noise.position_std, t.size) if noise and noise.position_std > 0 else np.zeros(t.size)
    if scenario.position_noise is not None:
        given = np.asarray(scenario.position_noise, dtype=float)
        pos_noise = np.zeros(t.size)
        pos_noise[: min(t.size, given.size)] = given[: t.size]
    y0 = initial_state(cfg, P, scenario.initial_position, scenario.initial_pressures)
    lx, ly = load_curve_arrays(cfg)
    out = output_buffer(n_samples + 1)
    status = simulate_core(P, y0, ref, cmd, closed, pos_noise, noise.position_quantum if noise else 0.0, lx, ly, n_samples, n_sub, out)
    if status >= 0:
        raise SimulationError(
            f"the simulation of '{cfg.name}' became non-physical at t = {status*ts:.3f} s "
            f"(non-finite or non-positive pressure); check the parameters or reduce simulation.step"
        )
    if noise and (noise.pressure_std > 0 or noise.pressure_quantum > 0):
        for col in (O_PA, O_PB, O_PS):
            vals = out[:, col] + rng.normal(0.0, noise.pressure_std, t.size)
            if noise.pressure_quantum > 0:
                vals = noise.pressure_quantum * np.round(vals / noise.pressure_quantum)
            out[:, col] = vals
    df = output_frame(out)
    df.attrs["plant"] = cfg.name
    df.attrs["closed_loop"] = closed
    return df

