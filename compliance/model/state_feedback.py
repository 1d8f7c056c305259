"""Plant-B controller: state feedback on (x, v, a), observers, friction compensation, PID.

The controller's numbers live in one float vector (indices ``C_*``) so the compiled loop
reads them at no cost; :func:`controller_vector` fills it from a configuration with the gains
designed in :mod:`compliance.model.axis_design` (nothing hand-typed).

Structure (seed 001 fig. 6, decoded in docs/plant-b.md):

    u = K [r - x, r' - v^, r'' - a^]  +  (d1 r' + d2 r'') / n0  +  d(F_f^ - c v^)/dt / (M n0)
        state feedback                    reference feed-forward     friction compensation

with v^ the filtered derivative of the measured position, a^ from the acceleration observer
(eq. 10), F_f^ from the friction-force observer (eq. 11), c the viscous slope kept in the
linear model. The compensation is seed 001's G_f(s) = -1/(K_0 G(s)) with K_0 G(s) = M n0 / s,
the valve-command-to-piston-force path of the linear model: a valve meters flow, so the force
is the integral of the command, and the exact inverse of that path is a derivative.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from compliance.model.config import PlantConfig
from compliance.model.pid_controller import first_order_filter_gain
from compliance.errors import InputError
from compliance.model import axis_design as design

# ---- controller vector layout
_NAMES = (
    "mode",  # 0 PID, 1 state feedback
    "compensation",  # 0 off, 1 friction compensation on
    "feedforward",  # 0 off, 1 reference feed-forward on
    "kx", "kv", "ka",
    "d0", "d1", "d2", "n0",
    "ao_lx", "ao_lv", "ao_pole", "ao_in", "ao_sx", "ao_sv",
    "fo_l", "fo_pole", "fo_in", "fo_sv",
    "area_ratio", "p_atm", "load_pressure",
    "force_gain", "force_rate_gain", "viscous", "rate_alpha",
    "vel_alpha",
    "kp", "ki", "kd", "pid_alpha",
    "sample_time",
)
N_CTRL = len(_NAMES)
(C_MODE, C_COMP, C_FF, C_KX, C_KV, C_KA, C_D0, C_D1, C_D2, C_N0, C_AO_LX, C_AO_LV, C_AO_POLE, C_AO_IN, C_AO_SX, C_AO_SV,
 C_FO_L, C_FO_POLE, C_FO_IN, C_FO_SV, C_AREA_RATIO, C_PATM, C_LOAD_PRESSURE, C_FORCE_GAIN, C_FORCE_RATE_GAIN, C_VISCOUS, C_RATE_ALPHA, C_VEL_ALPHA, C_KP, C_KI, C_KD, C_PID_ALPHA,
 C_TS) = range(N_CTRL)
STATE_FEEDBACK = 1.0  # C_MODE of the seed 001 controller; 0.0: the configuration's PID on the same loop (comparison)
MODES = {"pid": 0.0, "state_feedback": STATE_FEEDBACK}
# "inverse": G_f(s) = -1/(K_0 G(s)) with the valve -> force path an integrator (the default);
# "static": F_f^ through the loop's static force gain (fails: docs/plant-b.md, kept for that figure)
COMPENSATION_FORMS = {"inverse": 1.0, "static": 2.0}
# dF^/dt is low-passed at this multiple of the friction observer's bandwidth: slower adds lag to
# the compensation (the character's path error grows 0.19 -> 0.27 mm at 1x), faster passes the
# differentiated position noise to the valve (command jitter x1.9 at 10x); docs/plant-b.md
RATE_FILTER_FACTOR = 3.0


@dataclass(frozen=True)
class ControllerDesign:
    """What :func:`controller_vector` designed (for reports and tests).

    Attributes
    ----------
    mode : str
        ``pid`` or ``state_feedback``.
    compensation, feedforward : bool
    model : design.AxisModel
    gains : ndarray
        [k_x, k_v, k_a] (state feedback).
    poles : ndarray
        Placed closed-loop poles [rad/s].
    acceleration_observer, friction_observer : design.ReducedObserver
    force_gain : float
        K_F [N/V].
    pid : tuple of float
        (K_P, K_I, K_D) used in PID mode.
    vector : ndarray
        The compiled loop's controller vector.
    """

    mode: str
    compensation: bool
    feedforward: bool
    model: design.AxisModel
    gains: np.ndarray
    poles: np.ndarray
    acceleration_observer: design.ReducedObserver
    friction_observer: design.ReducedObserver
    force_gain: float
    pid: tuple
    vector: np.ndarray

    def as_dict(self) -> dict:
        """Plain-JSON summary (SI)."""
        m = self.model
        return {
            "mode": self.mode,
            "friction_compensation": self.compensation,
            "feedforward": self.feedforward,
            "model": {"n0": m.n0, "d0": m.d0, "d1": m.d1, "d2": m.d2, "velocity_gain": m.velocity_gain,
                      "natural_frequency": m.natural_frequency, "mass": m.mass},
            "gains": [float(g) for g in self.gains],
            "poles": [[float(p.real), float(p.imag)] for p in self.poles],
            "acceleration_observer_gain": [float(g) for g in self.acceleration_observer.gain],
            "friction_observer_gain": float(self.friction_observer.gain[0]),
            "force_gain": self.force_gain,
            "pid": [float(g) for g in self.pid],
        }


def controller_vector(cfg: PlantConfig, *, mode: str | None = None, compensation: bool | None = None,
                      feedforward: bool | None = None, x0: float | None = None, load: float | None = None,
                      compensation_form: str = "inverse") -> ControllerDesign:
    """Design the controller of one axis and pack it for the compiled loop.

    Parameters
    ----------
    cfg : PlantConfig
    mode : {"state_feedback", "pid"}, optional
        The seed 001 state feedback (default), or the configuration's PID on the same loop (comparison).
    compensation, feedforward : bool, optional
        Default ``controller.friction_compensation`` / ``controller.feedforward``.
    x0 : float, optional
        Trim position of the design model [m] (default mid-stroke).
    load : float, optional
        Constant closing load at the trim [N].
    compensation_form : {"inverse", "static"}
        ``inverse``: u_f = d(F_f^ - c v^)/dt / (M n0), the exact inverse of the valve-to-force
        integrator (seed 001's G_f(s) = -1/(K_0 G(s))); ``static``: u_f = F_f^ / K_F.
    """
    if compensation_form not in COMPENSATION_FORMS:
        raise InputError(f"compensation form '{compensation_form}' is not one of {', '.join(COMPENSATION_FORMS)}")
    mode = "state_feedback" if mode is None else mode
    if mode not in MODES:
        raise InputError(f"controller mode '{mode}' is not one of {', '.join(MODES)}")
    state_feedback = MODES[mode] == STATE_FEEDBACK
    if compensation is None:  # the configured compensation belongs to the state feedback only
        comp = cfg.options["controller.friction_compensation"] == "true" and state_feedback
    else:
        comp = bool(compensation)
    ff = cfg.options["controller.feedforward"] == "true" if feedforward is None else bool(feedforward)
    p = cfg.p
    ts = p("controller.sample_time")
    model = design.axis_model(cfg, x0=x0, load=load)
    C = np.zeros(N_CTRL)
    C[C_MODE] = MODES[mode]
    C[C_TS] = ts
    C[C_D0], C[C_D1], C[C_D2], C[C_N0] = model.d0, model.d1, model.d2, model.n0
    C[C_AREA_RATIO] = model.area_b / model.area_a
    C[C_PATM] = model.atmosphere
    C[C_LOAD_PRESSURE] = 0.0 if load is None else float(load) / model.area_a  # a known load is not friction
    C[C_VEL_ALPHA] = first_order_filter_gain(p("controller.velocity_filter_cutoff"), ts)
    C[C_KP], C[C_KI], C[C_KD] = p("controller.kp"), p("controller.ki"), p("controller.kd")
    C[C_PID_ALPHA] = first_order_filter_gain(p("controller.filter_cutoff"), ts)
    C[C_FF] = 1.0 if ff else 0.0
    where = cfg.path or cfg.name
    needs_sf = state_feedback or comp
    if needs_sf:
        poles, gains, ao, fo, force_gain = _state_feedback_design(cfg, model, where)
    else:
        gains, poles, force_gain = np.zeros(3), np.zeros(0), 0.0
        ao = fo = design.ReducedObserver(np.zeros(2), -1.0, np.zeros(1), np.zeros(2))
    if comp and not state_feedback:
        raise InputError(f"{where}: controller.friction_compensation needs controller.type = 'state_feedback' (seed 001 fig. 6)")
    C[C_KX], C[C_KV], C[C_KA] = gains
    _pack_observers(C, ao, fo)
    C[C_FORCE_GAIN] = force_gain
    C[C_FORCE_RATE_GAIN] = model.mass * model.n0
    C[C_VISCOUS] = model.viscous
    C[C_RATE_ALPHA] = 1.0 - math.exp(RATE_FILTER_FACTOR * fo.pole * ts) if needs_sf else 1.0  # low-pass of dF^/dt
    C[C_COMP] = COMPENSATION_FORMS[compensation_form] if comp else 0.0
    pid = (C[C_KP], C[C_KI], C[C_KD])
    return ControllerDesign(mode, comp, ff, model, gains, poles, ao, fo, force_gain, pid, C)


def _state_feedback_design(cfg: PlantConfig, model, where: str):
    """Seed 001's design: placed poles, state-feedback gains, both observers, friction force gain.

    Returns
    -------
    tuple
        (poles [rad/s], gains [k_x, k_v, k_a], acceleration observer, friction observer, K_F [N/V]).
    """
    p = cfg.p
    ts = p("controller.sample_time")
    for key in ("controller.closed_loop_bandwidth", "controller.acceleration_observer_bandwidth",
                "controller.friction_observer_bandwidth"):
        if not p(key) > 0:
            raise InputError(f"{where}: {key} must be > 0 for the state-feedback controller (seed 001)")
    bw = p("controller.closed_loop_bandwidth")
    zeta = p("controller.closed_loop_damping")
    poles = design.design_poles(bw, zeta)
    gains = design.state_feedback_gains(model, bw, zeta)
    ao = design.acceleration_observer(model, p("controller.acceleration_observer_bandwidth"))
    fo = design.friction_observer(model, p("controller.friction_observer_bandwidth"))
    force_gain = design.friction_compensation_gain(model, gains)
    for pole, key in ((ao.pole, "acceleration"), (fo.pole, "friction")):
        if abs(pole) * ts > 1.0:
            raise InputError(f"{where}: controller.{key}_observer_bandwidth {abs(pole):.0f} rad/s is too fast for "
                             f"controller.sample_time {ts*1e3:g} ms (needs bandwidth * sample time <= 1)")
    return poles, gains, ao, fo, force_gain


def _pack_observers(C: np.ndarray, ao, fo) -> None:
    """Write the two reduced observers into the controller vector."""
    C[C_AO_LX], C[C_AO_LV] = ao.gain
    C[C_AO_POLE] = ao.pole
    C[C_AO_IN] = ao.input_gain[0]
    C[C_AO_SX], C[C_AO_SV] = ao.state_gain
    C[C_FO_L] = fo.gain[0]
    C[C_FO_POLE] = fo.pole
    C[C_FO_IN] = fo.input_gain[0]
    C[C_FO_SV] = fo.state_gain[0]


@njit(cache=True, error_model="numpy", inline="always")
def state_feedback_command(C, r, dr, ddr, x, v_hat, a_hat, f_hat, f_rate):
    """Valve command about the centre of the seed 001 controller [V] (before saturation).

    Parameters
    ----------
    C : ndarray
        Controller vector.
    r, dr, ddr : float
        Reference position [m], velocity [m/s], acceleration [m/s^2].
    x, v_hat, a_hat : float
        Measured position [m], estimated velocity [m/s] and acceleration [m/s^2].
    f_hat : float
        Observed friction force F_f^ [N] (eq. 11).
    f_rate : float
        Rate of the observed friction beyond the model's viscous part, d(F_f^ - c v^)/dt [N/s].

    Returns
    -------
    tuple of float
        (total command, friction-compensation part) [V].
    """
    u = C[C_KX] * (r - x) + C[C_KV] * (dr - v_hat) + C[C_KA] * (ddr - a_hat)  # state feedback on x, v, a
    if C[C_FF] != 0.0:
        u += (C[C_D1] * dr + C[C_D2] * ddr) / C[C_N0]  # inverse of the linear model (d0 = 0 at a shut valve; jerk neglected)
    u_f = 0.0
    if C[C_COMP] == 1.0:
        u_f = f_rate / C[C_FORCE_RATE_GAIN]  # G_f(s) = -1/(K_0 G(s)) with K_0 G(s) = M n0 / s (valve -> piston force)
    elif C[C_COMP] == 2.0:
        u_f = f_hat / C[C_FORCE_GAIN]  # static-gain variant, kept to show why it fails (docs/plant-b.md)
    return u + u_f, u_f
