"""The compiled fixed-step simulator: RK4 plant, controller on its own sample clock, canonical output.

The plant is integrated with classical RK4 at the pinned step ``simulation.step`` (several
steps per controller sample); the controller runs every ``controller.sample_time`` with a
zero-order hold. Valve and sensor delays use histories sampled on that grid, averaged over
each step so results move continuously with the delay (needed by the diagnosis fits).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from numba import njit

from .config import PlantConfig
from .control import dead_zone_compensation, first_order_filter_gain, pid_step, saturate
from .errors import InputError, SimulationError
from .layout import *  # noqa: F403
from .layout import N_AUX, N_STATES
from .plant import initial_state, load_curve_arrays, parameter_vector, plant_rhs, valve_lag_input
from .profiles import Profile


@dataclass(frozen=True)
class SensorNoise:
    """Measurement noise of a recording (seeded, so runs are deterministic).

    Attributes
    ----------
    position_std : float
        Gaussian noise on the position [m] (the controller sees it).
    position_quantum : float
        Quantisation step of the position [m] (0: none).
    pressure_std : float
        Gaussian noise on the pressures [Pa] (outputs only).
    pressure_quantum : float
        Quantisation step of the pressures [Pa] (0: none).
    """

    position_std: float = 0.0
    position_quantum: float = 0.0
    pressure_std: float = 0.0
    pressure_quantum: float = 0.0


@dataclass(frozen=True)
class Scenario:
    """One simulated test.

    Attributes
    ----------
    duration : float
        [s].
    initial_position : float
        [m].
    reference : Profile or None
        Position set-point for a closed-loop run (constant initial position when None and
        no command is given).
    command : Profile or None
        Valve voltage for a plant-only (open-loop) run [V]; overrides the controller.
    load : float, "curve" or None
        Closing load [N] (> 0 closes), the configuration's load curve, or none.
    flow_control : bool or None
        Override the configuration's flow-control valves.
    noise : SensorNoise or None
    seed : int
    initial_pressures : tuple of float or None
        (p_A, p_B) [Pa abs]; None = at rest balancing the load.
    position_noise : numpy.ndarray or None
        A given additive position-noise sequence per controller sample [m] (e.g. the noise
        estimated from a recording, for a closed-loop replay); replaces the seeded noise.
    """

    duration: float
    initial_position: float
    reference: Profile | None = None
    command: Profile | None = None
    load: float | str | None = None
    flow_control: bool | None = None
    noise: SensorNoise | None = None
    seed: int = 0
    initial_pressures: tuple[float, float] | None = None
    position_noise: np.ndarray | None = field(default=None, compare=False, repr=False)


OUTPUT_COLUMNS = (
    "time", "position", "reference", "valve_command", "pressure_a", "pressure_b", "supply_pressure",
    "position_true", "velocity", "load_force", "friction_force", "flow_a", "flow_b", "opening",
    "temperature_a", "temperature_b", "command_demand",
)
(O_T, O_XM, O_REF, O_U, O_PA, O_PB, O_PS, O_X, O_V, O_LOAD, O_FRIC, O_QA, O_QB, O_OPEN, O_TA, O_TB, O_UD) = range(len(OUTPUT_COLUMNS))
N_OUT = len(OUTPUT_COLUMNS)


@njit(cache=True, error_model="numpy", inline="always")
def _zoh_average(hist, ts, t_a, t_b):
    """Average over [t_a, t_b] of the zero-order-hold signal hist[k] on [k*ts, (k+1)*ts)."""
    n = hist.shape[0]
    ka = int(math.floor(t_a / ts))
    kb = int(math.floor(t_b / ts))
    if ka < 0:
        ka = -1
    if kb < 0:
        kb = -1
    va = hist[0] if ka < 0 else hist[min(ka, n - 1)]
    if ka == kb or t_b <= t_a:
        return va
    vb = hist[0] if kb < 0 else hist[min(kb, n - 1)]
    t_sw = kb * ts
    return (va * (t_sw - t_a) + vb * (t_b - t_sw)) / (t_b - t_a)


@njit(cache=True, error_model="numpy", inline="always")
def _interp_uniform(hist, h, t):
    """Linear interpolation of a signal sampled every ``h`` from t = 0 (held before 0)."""
    if t <= 0.0:
        return hist[0]
    f = t / h
    i = int(math.floor(f))
    n = hist.shape[0]
    if i >= n - 1:
        return hist[n - 1]
    w = f - i
    return hist[i] * (1.0 - w) + hist[i + 1] * w


@njit(cache=True, error_model="numpy", inline="always")
def record_sample(out, k, ts, xm, ref_k, u, u_d, y, aux, P):
    """Write the canonical columns of controller sample ``k`` (shared by every compiled loop)."""
    out[k, O_T] = k * ts
    out[k, O_XM] = xm
    out[k, O_REF] = ref_k
    out[k, O_U] = u
    out[k, O_PA] = y[S_PA]
    out[k, O_PB] = y[S_PB]
    out[k, O_PS] = y[S_PSUP] if P[P_SD_ON] != 0.0 else P[P_PS]
    out[k, O_X] = y[S_X]
    out[k, O_V] = y[S_V]
    out[k, O_LOAD] = aux[A_LOAD]
    out[k, O_FRIC] = aux[A_FRIC]
    out[k, O_QA] = aux[A_QA]
    out[k, O_QB] = aux[A_QB]
    out[k, O_OPEN] = aux[A_OPEN]
    out[k, O_TA] = y[S_TA] if P[P_HT_ON] != 0.0 else P[P_TS]
    out[k, O_TB] = y[S_TB] if P[P_HT_ON] != 0.0 else P[P_TS]
    out[k, O_UD] = u_d


@njit(cache=True, error_model="numpy", inline="always")
def _rk4_step(y, P, u, lx, ly, h, k1, k2, k3, k4, tmp, aux, k1_ready=False):
    """One classical RK4 step in place; ``k1_ready`` reuses a slope already evaluated at (y, u)."""
    n = y.shape[0]
    if not k1_ready:
        plant_rhs(y, P, u, lx, ly, k1, aux)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * h * k1[i]
    plant_rhs(tmp, P, u, lx, ly, k2, aux)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * h * k2[i]
    plant_rhs(tmp, P, u, lx, ly, k3, aux)
    for i in range(n):
        tmp[i] = y[i] + h * k3[i]
    plant_rhs(tmp, P, u, lx, ly, k4, aux)
    for i in range(n):
        y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


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
        u_now = u if valve_delay <= 0.0 else _zoh_average(u_hist, ts, k * ts - valve_delay, k * ts - valve_delay)
        plant_rhs(y, P, u_now, lx, ly, k1, aux)  # also the first RK4 slope when there is no valve delay
        record_sample(out, k, ts, xm, ref[k], u, u_d, y, aux, P)
        if k == n_samples:
            break
        # --- integrate to t_{k+1}
        for j in range(n_sub):
            t0 = (k * n_sub + j) * h
            if valve_delay > 0.0:
                u_step = _zoh_average(u_hist, ts, t0 - valve_delay, t0 + h - valve_delay)
            else:
                u_step = u
            _rk4_step(y, P, u_step, lx, ly, h, k1, k2, k3, k4, tmp, aux, j == 0 and valve_delay <= 0.0)
            step_index += 1
            if sensor:
                x_hist[step_index] = y[S_X]
                xd = _interp_uniform(x_hist, h, step_index * h - sensor_delay)
                # first-order lag integrated exactly for an input linear over the step
                x_sensor = lag_decay * x_sensor + (1.0 - lag_decay) * xd_prev + (xd - xd_prev) * lag_ramp
                xd_prev = xd
        if not (math.isfinite(y[S_X]) and math.isfinite(y[S_PA]) and math.isfinite(y[S_PB])):
            return k
        if y[S_PA] <= 0.0 or y[S_PB] <= 0.0 or abs(y[S_V]) > 100.0:
            return k
    return -1


def _sample_profile(profile: Profile | None, t: np.ndarray, default: float) -> np.ndarray:
    if profile is None:
        return np.full(t.shape, float(default))
    return np.ascontiguousarray(profile.at(t), dtype=float)


def simulate(cfg: PlantConfig, scenario: Scenario) -> pd.DataFrame:
    """Simulate one scenario and return a DataFrame with the canonical recording columns.

    Parameters
    ----------
    cfg : PlantConfig
    scenario : Scenario

    Returns
    -------
    pandas.DataFrame
        One row per controller sample; columns ``OUTPUT_COLUMNS`` (SI, absolute pressures).

    Raises
    ------
    InputError
        Scenario outside the plant (initial position outside the stroke, bad duration).
    SimulationError
        The state became non-finite or non-physical.
    """
    stroke = cfg.p("cylinder.stroke")
    if not (0.0 <= scenario.initial_position <= stroke):
        raise InputError(f"initial position {scenario.initial_position*1e3:.1f} mm is outside the stroke 0..{stroke*1e3:.0f} mm")
    if not (scenario.duration > 0 and math.isfinite(scenario.duration)):
        raise InputError(f"duration must be a positive number of seconds, got {scenario.duration}")
    if scenario.command is None and cfg.options["controller.type"] != "pid":
        return _simulate_state_feedback(cfg, scenario)
    P = parameter_vector(cfg, load=scenario.load, flow_control=scenario.flow_control)
    ts = P[P_TSAMP]
    n_sub = int(round(ts / cfg.p("simulation.step")))
    n_samples = int(round(scenario.duration / ts))
    t = np.arange(n_samples + 1) * ts
    closed = scenario.command is None
    ref = _sample_profile(scenario.reference, t, scenario.initial_position)
    cmd = _sample_profile(scenario.command, t, P[P_UCEN])
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


def _simulate_state_feedback(cfg: PlantConfig, scenario: Scenario) -> pd.DataFrame:
    """Closed loop under the seed 001 state-feedback controller (plant B), via compliance.tracking."""
    from .tracking import AxisReference, simulate_axis

    if isinstance(scenario.load, str):
        raise InputError(f"{cfg.name}: a load curve is not supported with controller.type = '{cfg.options['controller.type']}'")
    ts = cfg.p("controller.sample_time")
    n = int(round(scenario.duration / ts))
    t = np.arange(n + 1) * ts
    r = _sample_profile(scenario.reference, t, scenario.initial_position)
    if abs(r[0] - scenario.initial_position) > 1e-9:
        raise InputError("state-feedback runs start at rest on the reference: the reference must begin at the initial position")
    v = np.gradient(r, ts)  # reference derivatives for the feed-forward terms (seed 001 fig. 6)
    a = np.gradient(v, ts)
    noise = scenario.noise or SensorNoise()
    df = simulate_axis(cfg, AxisReference(r, v, a), load=None if scenario.load is None else float(scenario.load),
                       position_noise=noise.position_std, position_quantum=noise.position_quantum,
                       pressure_noise=noise.pressure_std, seed=scenario.seed)
    df.attrs["plant"] = cfg.name
    df.attrs["closed_loop"] = True
    return df
