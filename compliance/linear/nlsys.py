"""govcheck plants as python-control objects: the nonlinear plant (active states only) and its linearisation.

- :func:`to_nlsys` wraps THE plant right-hand side (``compliance.model.assembly.plant_rhs``) in a
  ``control.NonlinearIOSystem`` whose states are only those the configuration makes live: position,
  velocity, both chamber pressures, the LuGre bristle of each moving body, and the declared states of
  the effects switched on (an effect that is off has no state here). States and outputs are named
  with their SI unit (``position_m``, ``pressure_a_Pa``); the parameter vector is exposed through
  ``params`` (core names of ``compliance.model.vector_slots.PARAM_NAMES``, SI);
- :func:`operating_point` gives the state and valve input at rest at a position and load (the trim
  govcheck's linear analysis uses); ``compliance.linear.nlsys_loop`` adds the controller, the closed
  loop and a physically checked ``find_operating_point``;
- :func:`to_statespace` gives the linearisation as a ``control.StateSpace`` u_d [V] -> position [m]:
  the model ``govcheck linear`` analyses (``compliance.linear.linear_model.linear_model`` adds its loop
  and closed loop, ready for ``control.margin``, ``step_info``, ``dcgain`` and ``bandwidth``).

The valve's pure delays (an effect's ``delay`` parameters) are applied by the simulator outside
the right-hand side and are not part of the NonlinearIOSystem; add ``control.pade`` if needed.
See docs/python-control.md for a worked example.
"""

from __future__ import annotations

import numpy as np

from compliance.effects.catalogue import ALL_EFFECTS
from compliance.model.assembly import plant_rhs
from compliance.model.config import PlantConfig
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state
from compliance.model.vector_slots import (AUX_NAMES, EFFECT_SLOTS, N_AUX, N_STATES, P_FRM, P_UCEN, PARAM_NAMES,
                                           S_PA, S_PB, S_V, S_X, S_Z1, S_Z2, SHADOWS, STATE_INDEX, STATE_NAMES)

__all__ = ["INPUT", "OPENING_INPUT", "OUTPUTS", "STATE_UNITS", "active_states", "labelled", "operating_point",
           "to_nlsys", "to_statespace", "valve_command_for_opening"]

INPUT = "valve_command_V"  # [V] at the valve (after compensation, saturation and the centre voltage)
# [-] the same command expressed as the static opening it gives (signed, > 0 opens); not "opening_1", the name of
# the plant's own opening output: control.interconnect joins equal names, and would feed the output back to the input
OPENING_INPUT = "command_opening_1"
OUTPUTS = ("position", "pressure_a", "pressure_b") + AUX_NAMES  # then the aux signals (SI)
# SI unit of every state and output, for the labels (our own table; the core stores bare SI floats)
STATE_UNITS = {"position": "m", "velocity": "m_s", "pressure_a": "Pa", "pressure_b": "Pa", "temperature_a": "K",
               "temperature_b": "K", "bristle_1": "m", "bristle_2": "m", "position_2": "m", "velocity_2": "m_s",
               "spool_position": "V", "spool_velocity": "V_s", "supply_pressure": "Pa", "line_pressure_a": "Pa",
               "line_pressure_b": "Pa"}
OUTPUT_UNITS = {"position": "m", "pressure_a": "Pa", "pressure_b": "Pa", "friction_force": "N", "load_force": "N",
                "flow_a": "kg_s", "flow_b": "kg_s", "opening": "1", "pneumatic_force": "N", "supply_flow": "kg_s"}
_PLANT_PARAMS = tuple(n for n in PARAM_NAMES if n not in ("kp", "ki", "kd", "ts", "filt_hz", "lc", "cdz_pos", "cdz_neg",
                                                          "cslope_pos", "cslope_neg", "u_lim"))


def labelled(name: str, units: dict = STATE_UNITS) -> str:
    """``position`` -> ``position_m``: a signal name with its SI unit (python-control names cannot hold brackets)."""
    return f"{name}_{units[name]}"


def active_states(P: np.ndarray) -> list[int]:
    """Indices of the states that move for this parameter vector (state-vector order).

    x, v, p_A, p_B always; the LuGre bristle of each body (bristle_2 only while an effect frees it,
    ``Effect.frees``: a compliant linkage; otherwise it copies bristle_1, as position_2/velocity_2
    copy position/velocity, ``vector_slots.SHADOWS``); the declared states of every effect switched on.
    """
    keep = {S_X, S_V, S_PA, S_PB}
    on = [eff for eff in ALL_EFFECTS if P[EFFECT_SLOTS[eff.name][0]]]
    if P[P_FRM] == 0.0:  # LuGre (compliance.model.assembly._body_friction)
        keep |= {S_Z1} | ({STATE_INDEX[n] for eff in on for n in eff.frees} & {S_Z2})
    for eff in on:
        keep |= {s.index for s in eff.states}
    return sorted(keep)


def valve_command_for_opening(P: np.ndarray, opening: float) -> float:
    """The valve command [V] whose static opening is ``opening`` (inverse of ``physics.valve_opening``).

    The path opening is (u - dz)/(u_sat - dz) beyond the dead zone (the slope md cancels), so
    u = centre + dz + o (u_sat - dz) for o > 0, mirrored with zme for o < 0, the centre at o = 0.
    """
    from compliance.model.vector_slots import P_DZN, P_DZP, P_USAT

    if opening > 0.0:
        return P[P_UCEN] + P[P_DZP] + opening * (P[P_USAT] - P[P_DZP])
    if opening < 0.0:
        return P[P_UCEN] - abs(P[P_DZN]) + opening * (P[P_USAT] - abs(P[P_DZN]))
    return P[P_UCEN]


def to_nlsys(cfg: PlantConfig, *, load: float | str | None = None, flow_control: bool | None = None,
             name: str | None = None, input: str = "valve_command"):
    """The nonlinear plant as a ``control.NonlinearIOSystem`` with only its active states.

    Parameters
    ----------
    cfg : PlantConfig
        A loaded configuration (``compliance.model.config.load_plant("plant-a")``).
    load : float, "curve" or None
        Constant closing load [N] (> 0 closes), the configuration's load curve, or none.
    flow_control : bool or None
        Install / remove the meter-out flow-control valves (None: as configured).
    name : str, optional
        System name (default: the plant's name).
    input : {"valve_command", "opening"}
        The valve command [V] (``valve_command_V``), or the same command as the static opening it
        gives [-] (``opening``; > 0 opens, 0 at the centre): linearising at the null through the
        ``opening`` input gives the flow just past the dead-zone edge, where the voltage input sees
        the dead zone's zero slope.

    Returns
    -------
    control.NonlinearIOSystem
        Continuous time; states ``labelled(name)`` of :func:`active_states` (``position_m``,
        ``velocity_m_s``, ``pressure_a_Pa`` absolute, ...); outputs ``position_m``, ``pressure_a_Pa``,
        ``pressure_b_Pa``, ``friction_force_N``, ``load_force_N``, ``flow_a_kg_s``, ``flow_b_kg_s``,
        ``opening_1``, ``pneumatic_force_N``, ``supply_flow_kg_s``; ``params``: the plant's core
        parameter vector entries by name (SI), e.g. ``{"p_supply": 8e5, "mass": 30.0}``. The inactive
        states are held at the configuration's rest values (``template`` attribute: the full vector).
    """
    import control

    P0 = parameter_vector(cfg, load=load, flow_control=flow_control)
    lx, ly = load_curve_arrays(cfg)
    keep = np.array(active_states(P0))
    kept = set(keep.tolist())
    template = initial_state(cfg, P0, 0.5 * cfg.p("cylinder.stroke"))
    index = {n: i for i, n in enumerate(PARAM_NAMES)}
    defaults = {n: float(P0[index[n]]) for n in _PLANT_PARAMS}
    by_opening = input == "opening"
    if input not in ("valve_command", "opening"):
        raise ValueError(f"input must be 'valve_command' or 'opening', not {input!r}")

    def _vector(params):
        if not params:
            return P0
        P = P0.copy()
        for k, v in params.items():
            if k in defaults and v != defaults[k]:
                P[index[k]] = v
        return P

    def _eval(x, u, params):
        P = _vector(params)
        y = template.copy()
        y[keep] = x
        for copy, of in SHADOWS.items():  # shadow copies of the rigid linkage (assembly.plant_rhs writes them alike)
            if copy not in kept:
                y[copy] = y[of]
        u0 = float(np.ravel(u)[0])
        cmd = valve_command_for_opening(P, u0) if by_opening else u0
        dy = np.zeros(N_STATES)
        aux = np.zeros(N_AUX)
        plant_rhs(y, P, cmd, lx, ly, dy, aux)
        return dy[keep], y, aux

    def updfcn(t, x, u, params):
        return _eval(x, u, params)[0]

    def outfcn(t, x, u, params):
        _, y, aux = _eval(x, u, params)
        return np.concatenate(([y[S_X], y[S_PA], y[S_PB]], aux))

    sys = control.nlsys(updfcn, outfcn, inputs=[OPENING_INPUT if by_opening else INPUT],
                        outputs=[labelled(n, OUTPUT_UNITS) for n in OUTPUTS],
                        states=[labelled(STATE_NAMES[i]) for i in keep], name=name or cfg.name, params=defaults)
    sys.template = template
    sys.core_index = keep  # where each state sits in the full STATE_NAMES vector
    sys.rest_state = lambda position: initial_state(cfg, P0, position)[keep]  # govcheck's rest convention
    return sys


def operating_point(cfg: PlantConfig, position: float, load: float | str | None = None, *,
                    flow_control: bool | None = None, full: bool = False) -> tuple[np.ndarray, float]:
    """State and valve input of the plant at rest at ``position`` [m] under ``load`` (the linear trim).

    Returns
    -------
    (numpy.ndarray, float)
        The active states (:func:`active_states`, the layout of :func:`to_nlsys`; the full
        ``STATE_NAMES`` vector with ``full``) and the valve command at rest [V] (the valve null).

    Raises
    ------
    InputError
        Position outside the stroke, or a load the actuator cannot hold.
    """
    from compliance.linear.trim import trim

    op = trim(cfg, position, load, flow_control=flow_control)
    P = parameter_vector(cfg, load=load, flow_control=flow_control)
    state = initial_state(cfg, P, position, (op.pressure_a, op.pressure_b))
    return (state if full else state[active_states(P)]), float(op.valve_null)


def to_statespace(cfg: PlantConfig, position: float, load: float | str | None = None, *, gain: str = "mean",
                  flow_control: bool | None = None, minimal: bool = False):
    """The linearised plant at rest at ``position`` [m] as a ``control.StateSpace`` u_d [V] -> position [m].

    The Jacobians are numerical derivatives of ``plant_rhs`` itself at the trim (``compliance.linear.trim``);
    friction enters through its viscous part only, and the input is the controller output through
    the dead-zone compensation (``gain``: mean of both directions, or "opening" / "closing").

    With ``minimal`` the modes the position cannot see or the valve cannot move (at a valve null the
    common level of both chamber pressures) are removed (``compliance.linear.trim.minimal_realisation``,
    python-control's ``minreal`` needs slycot); the states are then combinations, named ``z0``, ``z1``...

    Returns
    -------
    control.StateSpace
        Input ``u_d_V``, output ``position_m``; states named with their unit (``position_m``, ``pressure_a_Pa``...),
        or ``z0``, ``z1``... with ``minimal`` (combinations of the physical states, no single unit).
        ``compliance.linear.linear_model.linear_model`` gives the loop and closed loop around it as well.
    """
    import control

    from compliance.linear.trim import linearise_plant, minimal_realisation, trim

    op = trim(cfg, position, load, flow_control=flow_control)
    A, B, C, names, info = linearise_plant(op, cfg, gain)
    if minimal:
        A, B, C = minimal_realisation(A, B, C, np.asarray(info["state_scales"]))
        names = [f"z{i}" for i in range(A.shape[0])]
    else:
        names = [labelled(n) if n in STATE_UNITS else n for n in names]
    return control.ss(A, B, C, np.zeros((1, 1)), inputs=["u_d_V"], outputs=["position_m"], states=list(names),
                      name=f"{cfg.name}-linear-{position*1e3:.0f}mm")
