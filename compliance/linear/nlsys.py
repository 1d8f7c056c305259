"""govcheck plants as python-control objects: the nonlinear plant and its linearisation.

- :func:`to_nlsys` wraps THE plant right-hand side (``compliance.model.assembly.plant_rhs``)
  and the configuration's parameter vector in a ``control.NonlinearIOSystem`` with named
  states, input and outputs, for simulation or analysis in a user's own python-control code;
- :func:`operating_point` gives the state and valve input at rest at a position and load
  (the trim govcheck's linear analysis uses), to start ``control.input_output_response`` or
  ``control.linearize`` from;
- :func:`to_statespace` gives the linearisation as a ``control.StateSpace`` from the controller
  output u_d [V] to the position [m]: the same model ``govcheck linear`` analyses (the valve's
  dead zone seen through the dead-zone compensation as an effective gain, docs/linear.md).

The valve's pure delays (an effect's ``delay`` parameters) are applied by the simulator outside
the right-hand side and are not part of the NonlinearIOSystem; add ``control.pade`` if needed.
See docs/python-control.md for a worked example.
"""

from __future__ import annotations

import numpy as np

from compliance.model.assembly import plant_rhs

from compliance.model.plant_vector import load_curve_arrays, parameter_vector

from compliance.model.rest_state import initial_state
from compliance.model.config import PlantConfig
from compliance.model.vector_slots import AUX_NAMES, N_AUX, N_STATES, STATE_NAMES

__all__ = ["INPUT", "OUTPUTS", "operating_point", "to_nlsys", "to_statespace"]

INPUT = "valve_command"  # [V] at the valve (after compensation and saturation)
OUTPUTS = ("position", "pressure_a", "pressure_b") + AUX_NAMES  # [m], [Pa abs], then the aux signals (SI)
_STATE_INDEX = {n: i for i, n in enumerate(STATE_NAMES)}


def to_nlsys(cfg: PlantConfig, *, load: float | str | None = None, flow_control: bool | None = None,
             name: str | None = None):
    """The nonlinear plant as a ``control.NonlinearIOSystem``.

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

    Returns
    -------
    control.NonlinearIOSystem
        Continuous time; states ``STATE_NAMES`` (position [m], velocity [m/s], pressures [Pa abs],
        temperatures [K], bristle deflections [m], ...; states of effects that are off stay
        constant); input ``valve_command`` [V]; outputs ``OUTPUTS`` (position [m], chamber
        pressures [Pa abs], friction and load force [N], mass flows [kg/s], valve opening [-],
        pneumatic force [N], supply flow [kg/s]).
    """
    import control

    P = parameter_vector(cfg, load=load, flow_control=flow_control)
    lx, ly = load_curve_arrays(cfg)

    def _eval(x, u):
        dy = np.zeros(N_STATES)
        aux = np.zeros(N_AUX)
        plant_rhs(np.ascontiguousarray(x, dtype=float), P, float(np.ravel(u)[0]), lx, ly, dy, aux)
        return dy, aux

    def updfcn(t, x, u, params):
        return _eval(x, u)[0]

    def outfcn(t, x, u, params):
        aux = _eval(x, u)[1]
        return np.concatenate(([x[_STATE_INDEX["position"]], x[_STATE_INDEX["pressure_a"]], x[_STATE_INDEX["pressure_b"]]], aux))

    return control.nlsys(updfcn, outfcn, inputs=[INPUT], outputs=list(OUTPUTS), states=list(STATE_NAMES),
                         name=name or cfg.name)


def operating_point(cfg: PlantConfig, position: float, load: float | str | None = None, *,
                    flow_control: bool | None = None) -> tuple[np.ndarray, float]:
    """State and valve input of the plant at rest at ``position`` [m] under ``load`` (the linear trim).

    Returns
    -------
    (numpy.ndarray, float)
        The full state (layout ``STATE_NAMES``) and the valve command at rest [V] (the valve null).

    Raises
    ------
    InputError
        Position outside the stroke, or a load the actuator cannot hold.
    """
    from compliance.linear.trim import trim

    op = trim(cfg, position, load, flow_control=flow_control)
    state = initial_state(cfg, parameter_vector(cfg, load=load, flow_control=flow_control), position,
                          (op.pressure_a, op.pressure_b))
    return state, float(op.valve_null)


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
        States named as in ``STATE_NAMES`` (those of the linear model), input ``u_d``, output ``position``.
    """
    import control

    from compliance.linear.trim import linearise_plant, minimal_realisation, trim

    op = trim(cfg, position, load, flow_control=flow_control)
    A, B, C, names, info = linearise_plant(op, cfg, gain)
    if minimal:
        A, B, C = minimal_realisation(A, B, C, np.asarray(info["state_scales"]))
        names = [f"z{i}" for i in range(A.shape[0])]
    return control.ss(A, B, C, np.zeros((1, 1)), inputs=["u_d"], outputs=["position"], states=list(names),
                      name=f"{cfg.name}-linear-{position*1e3:.0f}mm")
