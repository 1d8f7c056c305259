"""The compiled tracking loop of one plant-B axis: RK4 plant, seed 001 controller, canonical output.

The plant is ``compliance.model.assembly.plant_rhs`` integrated by ``compliance.simulation.rk4.rk4_step``
(the same physics and integrator as ``govcheck simulate``); the controller
(:mod:`compliance.model.state_feedback`) runs every ``controller.sample_time`` with a
zero-order hold. In PID mode the loop reproduces the PID loop (``compliance.simulation.pid_loop``) sample for
sample (tests), so the two controllers are compared on one footing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from numba import njit

from compliance.effects import EFFECTS
from compliance.model.config import PlantConfig
from compliance.model.pid_controller import pid_sample, saturate
from compliance.errors import InputError, SimulationError
from compliance.model.vector_slots import N_STATES, P_UCEN, P_ULIM, S_PA, S_PB, S_V, S_X
from compliance.model.assembly import plant_rhs, settle_valve
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state
from compliance.simulation.rk4 import OUTPUT_COLUMNS, measured_position, non_physical, output_buffer, output_frame, record_sample
from compliance.simulation.rk4 import rk4_step, rk4_workspace
from compliance.simulation.scenario import Scenario, SensorNoise, sample_profile
from compliance.model.state_feedback import (
    C_AO_IN, C_AO_LV, C_AO_LX, C_AO_POLE, C_AO_SV, C_AO_SX, C_AREA_RATIO, C_FO_IN, C_FO_L, C_FO_POLE, C_FO_SV, C_KD, C_KI,
    C_KP, C_LOAD_PRESSURE, C_RATE_ALPHA, C_MODE, C_PATM, C_VISCOUS, C_PID_ALPHA, C_TS, C_VEL_ALPHA, ControllerDesign, controller_vector, state_feedback_command,
)
from compliance.model.observers import gauge_pressure_input, observer_foh_step

EXTRA_COLUMNS = (
    "reference_velocity", "reference_acceleration", "acceleration", "velocity_estimate", "acceleration_estimate",
    "friction_estimate", "compensation_command",
)
COLUMNS = OUTPUT_COLUMNS + EXTRA_COLUMNS
N_COL = len(COLUMNS)
_COL = {c: i for i, c in enumerate(COLUMNS)}
(O_T, O_XM, O_REF, O_U, O_PA, O_PB, O_PS, O_X, O_V, O_LOAD, O_FRIC, O_QA, O_QB, O_OPEN, O_TA, O_TB, O_UD,
 O_RV, O_RA, O_ACC, O_VH, O_AH, O_FH, O_UF) = range(N_COL)


# the seed 001 estimator's memory between samples (one small array, so one helper can advance it)
(E_XPREV, E_VHAT, E_VPREV, E_UPPREV, E_WA, E_WF, E_FNL_PREV, E_FRATE) = range(8)
N_EST = 8


@njit(cache=True, error_model="numpy", inline="always")
def estimator_step(C, est, k, pid, xm, u_p, u_rel):
    """Advance the seed 001 estimates to sample ``k``: velocity filter, acceleration and friction observers.

    Parameters
    ----------
    C : ndarray
        Controller vector.
    est : ndarray
        (N_EST,) estimator memory, updated in place (zeros before sample 0).
    k : int
        Sample index; at k = 0 the observers start from rest (a^ = 0, F^ = 0).
    pid : bool
        PID mode: the observers are not advanced (as the PID does not read them).
    xm : float
        Measured position [m].
    u_p : float
        Gauge pressure input of the friction observer (load pressure removed) [Pa].
    u_rel : float
        Command held over the last period, relative to the valve centre [V].

    Returns
    -------
    tuple
        (v^ [m/s], a^ [m/s^2], F^ [N], filtered d(F^ - viscous)/dt [N/s]).
    """
    ts = C[C_TS]
    if k == 0:
        est[E_XPREV] = xm
        est[E_WA] = -(C[C_AO_LX] * xm)  # a^ = 0 at rest
        est[E_WF] = 0.0  # F^ = 0 at rest
    # velocity: differentiated and filtered position (seed 001, "status variable v")
    v_prev = est[E_VHAT]
    v_hat = v_prev + C[C_VEL_ALPHA] * ((xm - est[E_XPREV]) / ts - v_prev)
    if k > 0 and not pid:
        # observers advance over [t_{k-1}, t_k]: command held, measurements on a straight line
        base_a = C[C_AO_IN] * u_rel
        est[E_WA] = observer_foh_step(est[E_WA], C[C_AO_POLE], base_a + C[C_AO_SX] * est[E_XPREV] + C[C_AO_SV] * v_prev,
                                      base_a + C[C_AO_SX] * xm + C[C_AO_SV] * v_hat, ts)
        est[E_WF] = observer_foh_step(est[E_WF], C[C_FO_POLE], C[C_FO_IN] * est[E_UPPREV] + C[C_FO_SV] * v_prev,
                                      C[C_FO_IN] * u_p + C[C_FO_SV] * v_hat, ts)
    est[E_XPREV] = xm
    est[E_UPPREV] = u_p
    est[E_VHAT] = v_hat
    a_hat = est[E_WA] + C[C_AO_LX] * xm + C[C_AO_LV] * v_hat  # seed 001 eq. (10): a^ = w + K1 x1
    f_hat = est[E_WF] + C[C_FO_L] * v_hat  # seed 001 eq. (11): F^ = w + K_f v
    f_nl = f_hat - C[C_VISCOUS] * v_hat  # friction beyond the linear model's viscous part
    if k == 0:
        est[E_FNL_PREV] = f_nl
    # d/dt by a backward difference, low-passed (controller.RATE_FILTER_FACTOR x the observer's
    # bandwidth): the derivative would otherwise pass the differentiated position noise to the valve
    est[E_FRATE] += C[C_RATE_ALPHA] * ((f_nl - est[E_FNL_PREV]) / ts - est[E_FRATE])
    est[E_FNL_PREV] = f_nl
    return v_hat, a_hat, f_hat, est[E_FRATE]


@njit(cache=True, error_model="numpy", inline="always")
def record_estimates(out, k, dref_k, ddref_k, acc, v_hat, a_hat, f_hat, u_f):
    """Write the tracking loop's extra columns (``EXTRA_COLUMNS``) of sample ``k``."""
    out[k, O_RV] = dref_k
    out[k, O_RA] = ddref_k
    out[k, O_ACC] = acc
    out[k, O_VH] = v_hat
    out[k, O_AH] = a_hat
    out[k, O_FH] = f_hat
    out[k, O_UF] = u_f


@njit(cache=True, error_model="numpy")
def tracking_core(P, C, y0, ref, dref, ddref, pos_noise, pos_quantum, pa_noise, pb_noise, lx, ly, n_samples, n_sub, out):
    """Integrate one axis under the seed 001 controller (or the PID) for ``n_samples`` periods.

    Parameters
    ----------
    P : ndarray
        Plant parameter vector (``compliance.model.assembly.parameter_vector``).
    C : ndarray
        Controller vector (``controller.controller_vector``).
    y0 : ndarray
        Initial plant state.
    ref, dref, ddref : ndarray
        Reference position [m], velocity [m/s] and acceleration [m/s^2] per sample.
    pos_noise : ndarray
        Additive position noise per sample [m]; ``pos_quantum`` its quantisation [m].
    pa_noise, pb_noise : ndarray
        Additive chamber-pressure noise per sample [Pa] (the friction observer sees it).
    lx, ly : ndarray
        Load curve.
    n_samples, n_sub : int
        Controller periods and RK4 steps per period.
    out : ndarray
        (n_samples + 1, N_COL) output (``rk4.output_buffer``), filled in place.

    Returns
    -------
    int
        -1 on success, else the sample at which the state became non-physical.
    """
    ts = C[C_TS]
    h = ts / n_sub
    y = y0.copy()
    k1, k2, k3, k4, tmp, aux = rk4_workspace()
    dy = np.zeros(N_STATES)
    est = np.zeros(N_EST)
    pid = C[C_MODE] == 0.0
    x_filt = 0.0
    integral = 0.0
    u_rel = 0.0
    settle_valve(P, y, P[P_UCEN])  # the valve's lag at rest on the centre command
    for k in range(n_samples + 1):
        # --- measurements and estimates at t_k
        xm = measured_position(y[S_X], pos_noise[k], pos_quantum)
        u_p = gauge_pressure_input(y[S_PA] + pa_noise[k], y[S_PB] + pb_noise[k], C[C_AREA_RATIO], C[C_PATM]) - C[C_LOAD_PRESSURE]
        if k == 0:
            x_filt = xm
        v_hat, a_hat, f_hat, f_rate = estimator_step(C, est, k, pid, xm, u_p, u_rel)
        # --- controller
        u_f = 0.0
        if pid:
            u_d, u_c, x_filt, integral = pid_sample(P, xm, ref[k], x_filt, integral, C[C_PID_ALPHA], C[C_KP], C[C_KI], C[C_KD], ts)
        else:
            u_d, u_f = state_feedback_command(C, ref[k], dref[k], ddref[k], xm, v_hat, a_hat, f_hat, f_rate)
            u_c = u_d
        u_rel = saturate(u_c, P[P_ULIM])
        u = u_rel + P[P_UCEN]
        # --- record
        plant_rhs(y, P, u, lx, ly, dy, aux)
        record_sample(out, k, ts, xm, ref[k], u, u_d, y, aux, P)
        record_estimates(out, k, dref[k], ddref[k], dy[S_V], v_hat, a_hat, f_hat, u_f)
        if k == n_samples:
            break
        # --- integrate the plant to t_{k+1}
        for j in range(n_sub):
            rk4_step(y, P, u, lx, ly, h, k1, k2, k3, k4, tmp, aux)
        if non_physical(y):
            return k
    return -1


@dataclass(frozen=True)
class AxisReference:
    """Reference of one axis sampled at the controller period.

    Attributes
    ----------
    position, velocity, acceleration : ndarray
        [m], [m/s], [m/s^2], one value per sample (t = k * sample_time).
    """

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray

    def __post_init__(self):
        arrays = [np.ascontiguousarray(np.asarray(a, float)) for a in (self.position, self.velocity, self.acceleration)]
        if any(a.ndim != 1 or a.shape != arrays[0].shape for a in arrays) or arrays[0].size < 2:
            raise InputError("axis reference: position, velocity and acceleration must be 1-D arrays of one length >= 2")
        if not all(np.all(np.isfinite(a)) for a in arrays):
            raise InputError("axis reference: values must be finite")
        object.__setattr__(self, "position", arrays[0])
        object.__setattr__(self, "velocity", arrays[1])
        object.__setattr__(self, "acceleration", arrays[2])


def simulate_axis(cfg: PlantConfig, reference: AxisReference, *, mode: str | None = None, compensation: bool | None = None,
                  feedforward: bool | None = None, load: float | None = None, design: ControllerDesign | None = None,
                  compensation_form: str = "inverse", position_noise: float = 0.0, position_quantum: float = 0.0, pressure_noise: float = 0.0,
                  seed: int = 0) -> pd.DataFrame:
    """Simulate one plant-B axis following ``reference`` under the seed 001 controller.

    Parameters
    ----------
    cfg : PlantConfig
        Single-cylinder configuration.
    reference : AxisReference
        Sampled at ``controller.sample_time``; the run lasts ``len - 1`` samples and starts at
        rest at ``reference.position[0]``.
    mode : {"state_feedback", "pid"}, optional
        The seed 001 state feedback (default), or the configuration's PID on the same loop (comparison).
    compensation, feedforward : bool, optional
        Default from the configuration.
    load : float, optional
        Constant closing load [N] (> 0 pushes towards x = 0; gravity on a vertical axis).
    design : ControllerDesign, optional
        A precomputed design (else designed here at the start position).
    compensation_form : {"inverse", "static"}
        Form of the friction compensation (``controller.controller_vector``).
    position_noise, position_quantum : float
        Gaussian std and quantisation of the position sensor [m].
    pressure_noise : float
        Gaussian std of the pressure sensors [Pa].
    seed : int
        Noise seed (deterministic).

    Returns
    -------
    pandas.DataFrame
        Canonical columns (``compliance.simulation.rk4.OUTPUT_COLUMNS``) plus ``EXTRA_COLUMNS``;
        ``attrs["controller"]`` holds the design summary.

    Raises
    ------
    InputError
        Reference outside the stroke, unsupported effects, bad controller settings.
    SimulationError
        Non-physical state.
    """
    where = cfg.path or cfg.name
    for e, values in cfg.effects.items():  # the declarations say what this loop can run (Effect.loop_states, input_delay)
        if EFFECTS[e].loop_states:  # this loop differentiates the raw position: it holds no sampled filter of its own
            raise InputError(f"{where}: effect {e} is not supported by the tracking loop (use govcheck simulate)")
        if EFFECTS[e].input_delay and values.get(EFFECTS[e].input_delay, 0.0) > 0.0:
            raise InputError(f"{where}: a {e} delay is not supported by the tracking loop")
    stroke = cfg.p("cylinder.stroke")
    r = reference
    if np.min(r.position) < 0.0 or np.max(r.position) > stroke:
        raise InputError(f"{where}: reference {np.min(r.position)*1e3:.1f}..{np.max(r.position)*1e3:.1f} mm leaves the stroke 0..{stroke*1e3:.0f} mm")
    x0 = float(r.position[0])
    if design is None:
        design = controller_vector(cfg, mode=mode, compensation=compensation, feedforward=feedforward, x0=x0, load=load,
                                   compensation_form=compensation_form)
    P = parameter_vector(cfg, load=load)
    ts = design.vector[C_TS]
    n_sub = int(round(ts / cfg.p("simulation.step")))
    n_samples = r.position.size - 1
    rng = np.random.default_rng(seed)
    n = n_samples + 1
    pos_noise = rng.normal(0.0, position_noise, n) if position_noise > 0 else np.zeros(n)
    pa_noise = rng.normal(0.0, pressure_noise, n) if pressure_noise > 0 else np.zeros(n)
    pb_noise = rng.normal(0.0, pressure_noise, n) if pressure_noise > 0 else np.zeros(n)
    y0 = initial_state(cfg, P, x0)
    lx, ly = load_curve_arrays(cfg)
    out = output_buffer(n, N_COL)
    status = tracking_core(P, design.vector, y0, r.position, r.velocity, r.acceleration, pos_noise, float(position_quantum),
                           pa_noise, pb_noise, lx, ly, n_samples, n_sub, out)
    if status >= 0:
        raise SimulationError(f"the tracking simulation of '{cfg.name}' became non-physical at t = {status*ts:.3f} s; "
                              f"check the controller settings or reduce simulation.step")
    df = output_frame(out, COLUMNS)
    df.attrs["plant"] = cfg.name
    df.attrs["closed_loop"] = True
    df.attrs["controller"] = design.as_dict()
    return df


def simulate_state_feedback(cfg: PlantConfig, scenario: Scenario) -> pd.DataFrame:
    """Closed loop under the seed 001 state-feedback controller (plant B), seed 001 figs. 5-6."""
    if isinstance(scenario.load, str):
        raise InputError(f"{cfg.name}: a load curve is not supported by the state-feedback loop (a constant load is)")
    ts = cfg.p("controller.sample_time")
    n = int(round(scenario.duration / ts))
    t = np.arange(n + 1) * ts
    r = sample_profile(scenario.reference, t, scenario.initial_position)
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


def warm_up(cfg: PlantConfig) -> None:
    """Compile (or load from the numba cache) the state-feedback loop once, before workers fork."""
    x0 = 0.5 * cfg.p("cylinder.stroke")
    r = np.full(11, x0)
    simulate_axis(cfg, AxisReference(r, 0.0 * r, 0.0 * r), mode="pid")
