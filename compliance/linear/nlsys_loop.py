"""govcheck's controller and closed loop as python-control systems, and a physically checked rest point.

- :func:`controller_nlsys`: plant A's PID (derivative on the filtered measured position), the
  smoothed dead-zone inverse (seed 000 eq. 3, ``model.pid_controller.dead_zone_compensation``, the
  simulator's own function) and the command saturation, as a continuous-time NonlinearIOSystem
  (the simulator samples it at 1 ms; continuous here so it interconnects with the continuous plant);
- :func:`closed_loop_nlsys`: plant and controller joined by their signal names;
- :func:`find_rest_point`: ``control.find_operating_point`` with the position, one chamber pressure
  and the bristles held (a shut valve and pre-sliding friction leave them free otherwise), and the
  answer refused when it is not a physical rest state (:func:`check_physical`).

A plant kind without govcheck's closed-loop linear model (plant B's state feedback,
``PlantKind.linear_support``) is refused.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from compliance.errors import InputError
from compliance.linear.nlsys import OPENING_INPUT, to_nlsys
from compliance.model.config import PlantConfig
from compliance.model.pid_controller import dead_zone_compensation, saturate
from compliance.plants import kind_of

__all__ = ["CONTROLLER_STATES", "check_physical", "closed_loop_nlsys", "controller_nlsys", "find_rest_point"]

CONTROLLER_STATES = ("error_integral_m_s", "position_filtered_m")
_CTRL_KEYS = {"kp": "controller.kp", "ki": "controller.ki", "kd": "controller.kd", "filter_hz": "controller.filter_cutoff",
              "lc": "controller.compensation_width", "cdz_pos": "controller.compensation_dead_zone_positive",
              "cdz_neg": "controller.compensation_dead_zone_negative", "cslope_pos": "controller.compensation_slope_positive",
              "cslope_neg": "controller.compensation_slope_negative", "u_lim": "valve.command_limit",
              "u_centre": "valve.centre_voltage"}


def controller_nlsys(cfg: PlantConfig, *, name: str = "controller"):
    """Plant A's controller as a ``control.NonlinearIOSystem`` (continuous time).

    u_d = K_P e + K_I int(e) - K_D dx_f/dt, x_f' = w_f (x - x_f), e = r - x (``model.pid_controller.pid_step``);
    u_c = the smoothed dead-zone inverse of u_d (none when lc = 0, as in the simulator); the valve
    command = clip(u_c, +-u_lim) + the valve's centre voltage.

    Returns
    -------
    control.NonlinearIOSystem
        Inputs ``reference_m``, ``position_m`` (measured); states ``error_integral_m_s``,
        ``position_filtered_m``; outputs ``u_d_V`` (demand before compensation), ``valve_command_V``;
        ``params``: kp [V/m], ki [V/(m s)], kd [V s/m], filter_hz, lc [V], cdz_pos/neg [V],
        cslope_pos/neg, u_lim [V], u_centre [V].

    Raises
    ------
    InputError
        A controller other than the PID, or no position filter (the derivative needs one).
    """
    import control

    kind_of(cfg).check_linear(cfg)  # a plant kind without the PID has no python-control form here
    defaults = {k: float(cfg.p(v)) for k, v in _CTRL_KEYS.items()}
    if defaults["filter_hz"] <= 0.0:
        raise InputError(f"{cfg.path or cfg.name}: controller.filter_cutoff must be > 0 for the continuous controller")

    def _demand(x, u, p):
        r, xm = u[0], u[1]
        wf = 2.0 * math.pi * p["filter_hz"]
        rate = wf * (xm - x[1])  # derivative of the filtered position
        return p["kp"] * (r - xm) + p["ki"] * x[0] - p["kd"] * rate, rate

    def updfcn(t, x, u, params):
        p = {**defaults, **(params or {})}
        return np.array([u[0] - u[1], _demand(x, u, p)[1]])

    def outfcn(t, x, u, params):
        p = {**defaults, **(params or {})}
        u_d = _demand(x, u, p)[0]
        u_c = dead_zone_compensation(u_d, p["cdz_pos"], p["cdz_neg"], p["cslope_pos"], p["cslope_neg"], p["lc"]) \
            if p["lc"] > 0.0 else u_d
        return np.array([u_d, saturate(u_c, p["u_lim"]) + p["u_centre"]])

    return control.nlsys(updfcn, outfcn, inputs=["reference_m", "position_m"], outputs=["u_d_V", "valve_command_V"],
                         states=list(CONTROLLER_STATES), name=name, params=defaults)


def closed_loop_nlsys(cfg: PlantConfig, *, load: float | str | None = None, flow_control: bool | None = None,
                      name: str | None = None):
    """Plant and controller closed by their signal names (``control.interconnect``).

    Returns
    -------
    control.InterconnectedSystem
        Input ``reference_m``; outputs ``position_m``, ``pressure_a_Pa``, ``pressure_b_Pa``, ``u_d_V``,
        ``valve_command_V``; states: the plant's active states then the controller's.
    """
    import control

    plant = to_nlsys(cfg, load=load, flow_control=flow_control, name="plant")
    ctrl = controller_nlsys(cfg)
    return control.interconnect([plant, ctrl], inputs=["reference_m"],
                                outputs=["position_m", "pressure_a_Pa", "pressure_b_Pa", "u_d_V", "valve_command_V"],
                                name=name or f"{cfg.name}-closed-loop")


def check_physical(sys, x, where: str = "state") -> None:
    """Refuse a plant state that no rest or motion of the servo can have (``InputError`` naming the state).

    Pressures must be absolute and positive, chambers at rest between atmosphere and supply;
    temperatures above 0 K; the position inside the stroke (end-stop spring deflection aside).
    """
    p = sys.params
    ps, patm, stroke = p["p_supply"], p["p_atm"], p["stroke"]
    for label, v in zip(sys.state_labels, np.asarray(x, float)):
        if label.endswith("_Pa") and not (patm * (1.0 - 1e-6) <= v <= ps * (1.0 + 1e-6)):
            raise InputError(f"{where}: {label} = {v:.6g} Pa abs is not physical (expected absolute pressure "
                             f"between atmosphere {patm:.6g} Pa and supply {ps:.6g} Pa)")
        if label.endswith("_K") and not v > 0.0:
            raise InputError(f"{where}: {label} = {v:.6g} K is not physical (expected > 0 K)")
        if label in ("position_m", "position_2_m") and not (-1e-3 * stroke <= v <= stroke * (1.0 + 1e-3)):
            raise InputError(f"{where}: {label} = {v:.6g} m is outside the stroke 0..{stroke:.6g} m")


def find_rest_point(sys, position: float, *, guess=None, pressure_b: float | None = None, tol: float = 1e-6):
    """The plant at rest at ``position`` [m]: ``control.find_operating_point`` with the physics' own constraints.

    A shut valve leaves the chambers' common pressure level free and pre-sliding friction leaves
    the bristle free, so the position, p_B and the bristles are held and the rest is solved (the
    velocity, p_A balancing the load, any effect states) with the valve at its centre.

    Parameters
    ----------
    sys : control.NonlinearIOSystem
        From :func:`compliance.linear.nlsys.to_nlsys`.
    guess : array, optional
        Initial state (the active states); default govcheck's rest convention p_A + p_B = p_s + p_atm.
    pressure_b : float, optional
        p_B to hold [Pa abs]; default the guess's.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        States and input at rest.

    Raises
    ------
    InputError
        A guess or an answer that is not physical (negative or out-of-range absolute pressure, ...),
        or no rest state within ``tol`` (per second, relative to each state's scale).
    """
    import control

    labels = list(sys.state_labels)
    x0 = np.array(sys.rest_state(position) if guess is None else guess, dtype=float)
    x0[labels.index("position_m")] = position
    if pressure_b is not None:
        x0[labels.index("pressure_b_Pa")] = pressure_b
    check_physical(sys, x0, "rest-point guess")
    held = [i for i, n in enumerate(labels) if n in ("position_m", "pressure_b_Pa") or n.startswith("bristle")]
    u0 = [0.0] if sys.input_labels == [OPENING_INPUT] else [sys.params["u_centre"]]
    # one equation per free state: p_A's own rate is zero with the valve shut whatever p_A is, so the
    # velocity's rate (the force balance) and the position's rate (v = 0) determine v and p_A
    free = [i for i in range(len(labels)) if i not in held]
    eqs = [i for i in free if labels[i] != "pressure_a_Pa"] + [labels.index("position_m")]
    with warnings.catch_warnings():  # python-control 0.10 counts the unconstrained outputs as constraints
        warnings.filterwarnings("ignore", message="number of constraints")
        op = control.find_operating_point(sys, x0, u0, ix=held, iu=[0], idx=eqs)
    x, u = np.asarray(op.states, float), np.asarray(op.inputs, float)
    check_physical(sys, x, "rest point found")
    scale = np.array([_scale(sys.params, n) for n in labels])
    resid = np.max(np.abs(sys._rhs(0.0, x, u)) / scale)
    if not resid <= tol:
        raise InputError(f"no rest state at {position:.6g} m: the largest state rate is {resid:.3g} of its scale per second")
    return x, u


def _scale(p: dict, label: str) -> float:
    unit = label.rsplit("_", 1)[-1]
    return {"Pa": p["p_supply"], "K": p["t_supply"], "m": p["stroke"], "s": 0.1, "V": 1.0}.get(unit, 1.0)

