"""govcheck's own linear model as python-control objects, in one call.

``linear_model(cfg, position, load, mode="mean")`` returns what ``govcheck linear`` analyses at an
operating point (``compliance.linear.analysis.analyse``), with every signal named with its unit:

- ``plant``: the linearised plant u_d [V] -> position [m], every state (``position_m``,
  ``velocity_m_s``, ``pressure_a_Pa``, ...). It has two poles at s = 0: the piston's integrator
  (position is the integral of velocity) and the **common pressure level** of both chambers,
  which a valve at its null neither moves nor the position sees;
- ``plant_minimal``: the same with the modes the position cannot see or the valve cannot move
  removed (the common-level pole at 0), as ``govcheck linear`` does; its states are
  combinations of the physical ones (``z0``, ``z1``...: no single unit);
- ``loop``: the loop broken at the valve command, L(s) = C(s) G(s) with govcheck's PID
  (derivative on the filtered measurement) and the declared delays as Pade approximants: input
  ``u_d_V`` injected at the valve, output ``u_d_return_V`` from the controller; it is type 2 (the
  piston's integrator and the PID's), so ``control.margin`` applies and ``dcgain`` is infinite;
- ``closed_loop``: reference_m -> position_m, built on the minimal plant, so ``step_info``,
  ``dcgain`` (1: the integral action leaves no steady error) and ``bandwidth`` work on it. Built on
  the full plant, the common-level pole at 0 would stay in the closed loop (uncontrollable and
  unobservable) and make ``dcgain`` and ``step_info`` NaN;
- ``loop_sampled`` / ``closed_loop_sampled``: the same at the controller's sample time (plant by
  ZOH, the simulator's exact difference-equation PID): govcheck's headline margins are these;
- ``figures``: govcheck's own figures at the point (``time_constant`` [s], ``gain_margin_db``,
  ``phase_margin_deg``, their ``*_continuous`` values, ``bandwidth_hz``, ...), and ``removed``:
  what the minimal realisation took out and why.

``mode`` is the valve slope of the model: ``"mean"`` (govcheck's default: the mean of the opening
and closing slopes just past the dead zone, one linearisation per side averaged), ``"opening"`` or
``"closing"``. docs/python-control.md has a worked example.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import control
import numpy as np

from compliance.errors import InputError
from compliance.linear.nlsys import STATE_UNITS, labelled

__all__ = ["MODES", "LinearModel", "linear_model"]

MODES = ("mean", "opening", "closing")


@dataclass
class LinearModel:
    """govcheck's linear model at one operating point as python-control systems (see the module note)."""

    plant: control.StateSpace
    plant_minimal: control.StateSpace
    loop: control.StateSpace
    closed_loop: control.StateSpace
    loop_sampled: control.StateSpace
    closed_loop_sampled: control.StateSpace
    figures: dict
    operating_point: dict
    mode: str
    removed: list = field(default_factory=list)

    def poles(self) -> np.ndarray:
        """Closed-loop poles [1/s], fastest first (what ``govcheck linear`` prints as 'closed-loop poles')."""
        return np.array(sorted(control.poles(self.closed_loop), key=lambda p: (p.real, p.imag)))


def _named(sys, inputs, outputs, states=None, name=None, dt=None):
    """A copy of ``sys`` with its signals named (python-control names carry the unit after the last underscore)."""
    states = states if states is not None else [f"z{i}" for i in range(sys.nstates)]
    return control.ss(sys.A, sys.B, sys.C, sys.D, sys.dt if dt is None else dt, inputs=inputs, outputs=outputs,
                      states=states, name=name)


def _state_label(name: str) -> str:
    return labelled(name) if name in STATE_UNITS else name


def linear_model(cfg, position, load=None, *, mode: str = "mean", flow_control: bool | None = None) -> LinearModel:
    """govcheck's linear model of ``cfg`` at rest at ``position`` under ``load`` (see the module note).

    Parameters
    ----------
    cfg : PlantConfig or str
        A configuration, or a file / reference name (``"plant-a"``) to load.
    position : float or str
        Operating point [m], or a quantity (``"136 mm"``).
    load : float, str or None
        Closing force [N] (> 0 closes), a quantity (``"11.4 kN"``), ``"curve"`` or None (no load).
    mode : {"mean", "opening", "closing"}
        Valve slope of the model (``govcheck linear --gain``).
    flow_control : bool or None
        Meter-out flow-control valves in / out (None: as configured).

    Returns
    -------
    LinearModel

    Raises
    ------
    InputError
        An unknown mode, a position outside the stroke, a load the actuator cannot hold, a
        controller other than the PID.
    """
    from compliance.linear.analysis import analyse
    from compliance.model.config import load_plant
    from compliance.units import parse_quantity

    if mode not in MODES:
        raise InputError(f"linear_model: mode {mode!r} is not one of {', '.join(MODES)}")
    if isinstance(cfg, str):
        cfg = load_plant(cfg)
    x = parse_quantity(position, "m", "linear_model: position") if isinstance(position, str) else float(position)
    if isinstance(load, str) and load.strip().lower() not in ("curve", "none", ""):
        load = parse_quantity(load, "N", "linear_model: load")
    elif isinstance(load, str) and load.strip().lower() in ("none", ""):
        load = None
    a = analyse(cfg, x, load, flow_control=flow_control, gain=mode)
    plant = _named(a.plant, ["u_d_V"], ["position_m"], [_state_label(s) for s in a.plant.state_labels],
                   name=f"{cfg.name}-plant")
    plant_min = _named(a.plant_minimal, ["u_d_V"], ["position_m"], name=f"{cfg.name}-plant-minimal")
    removed = sorted(set(np.round(plant.poles(), 9)) - set(np.round(plant_min.poles(), 9)), key=abs) or []
    n_removed = plant.nstates - plant_min.nstates
    why = []
    if n_removed:
        why.append({"modes": n_removed, "poles": [complex(p) for p in np.atleast_1d(removed)] or [0j],
                    "why": "the common pressure level of both chambers (and any other mode the valve cannot move or the "
                           "position cannot see at this point): a pole at s = 0 that no controller acts on; kept, it makes "
                           "dcgain and step_info of the closed loop NaN"})
    return LinearModel(
        plant=plant, plant_minimal=plant_min,
        loop=_named(a.loop, ["u_d_V"], ["u_d_return_V"], name=f"{cfg.name}-loop"),
        closed_loop=_named(a.closed_loop, ["reference_m"], ["position_m"], name=f"{cfg.name}-closed-loop"),
        loop_sampled=_named(a.loop_discrete, ["u_d_V"], ["u_d_return_V"], name=f"{cfg.name}-loop-sampled"),
        closed_loop_sampled=_named(a.closed_loop_discrete, ["reference_m"], ["position_m"],
                                   name=f"{cfg.name}-closed-loop-sampled"),
        figures=dict(a.figures), operating_point=a.op.to_dict(), mode=mode, removed=why)
