"""A validated ``PlantConfig`` -> the compiled core's parameter vector (layout ``vector_slots``).

Declared base and effect parameters are copied to their declared slots; the few entries below
``parameter_vector``'s loops are computed because the core wants them in another form.
"""

from __future__ import annotations

import math

import numpy as np

from compliance.effects import EFFECTS
from compliance.errors import InputError
from compliance.model.config import PlantConfig
from compliance.model.vector_slots import (BASE_SLOTS, EFFECT_SLOTS, N_PARAMS, P_AREA_CAP, P_AREA_ROD, P_ARR,
                                           P_FC_ON, P_FJ, P_FRM, P_KV1, P_LAW, P_LOAD, P_LOADMODE, P_NFR, P_RL_CLOSE,
                                           P_RL_END_RATE, P_RL_ON, P_RL_OPEN, P_VD, P_VD_STAGE)

FLOW_LAWS = {"iso6358": 0, "sanville": 1, "bobrow": 2, "power_law": 3}
FRICTION_MODELS = {"lugre": 0, "variable_viscous": 1, "piecewise_stribeck": 2}
VALVE_STAGES = {"spool": 0, "opening": 1}  # where valve_dynamics acts: on the spool (command) or on the opening


def parameter_vector(cfg: PlantConfig, *, load: float | str | None = None, flow_control: bool | None = None) -> np.ndarray:
    """Flatten a configuration into the core's parameter vector (SI).

    Parameters
    ----------
    cfg : PlantConfig
    load : float, "curve" or None
        Constant closing load [N], the configuration's load curve, or no load.
    flow_control : bool or None
        Override whether the meter-out flow-control valves are installed.

    Raises
    ------
    InputError
        Piecewise Stribeck friction that would aid the motion; an effect switched on without the
        options it needs (``Effect.requires``: linkage compliance on a single cylinder); a load
        curve asked for but not defined.
    """
    p = cfg.params
    P = np.zeros(N_PARAMS)
    for key, idx in BASE_SLOTS.items():
        P[idx] = p[key]
    for name, values in cfg.effects.items():
        flag, slots = EFFECT_SLOTS[name]
        P[flag] = 1.0
        for pname, idx in slots.items():
            P[idx] = values[pname]
    # computed entries: the core works with piston areas, not the diameters a data sheet gives
    d, dr = p["cylinder.piston_diameter"], p["cylinder.rod_diameter"]
    P[P_AREA_CAP] = math.pi * d * d / 4.0
    P[P_AREA_ROD] = P[P_AREA_CAP] - math.pi * dr * dr / 4.0
    # the set-point rate limiter costs one branch per sample when no rate is set
    P[P_RL_ON] = 1.0 if max(P[P_RL_OPEN], P[P_RL_CLOSE], P[P_RL_END_RATE]) > 0.0 else 0.0
    # options (strings in the file) become numeric switches
    tandem = cfg.options["cylinder.arrangement"] == "tandem"
    P[P_ARR] = 0.0 if tandem else 1.0
    P[P_NFR] = 2.0 if tandem else 1.0  # friction parameters are per cylinder
    P[P_LAW] = FLOW_LAWS[cfg.options["valve.flow_law"]]
    P[P_VD_STAGE] = VALVE_STAGES[cfg.options["valve.dynamics_stage"]]
    P[P_FRM] = FRICTION_MODELS[cfg.options["friction.model"]]
    # the caller may override the installed flow control and choose the load of this run
    installed = cfg.flow_control_installed if flow_control is None else bool(flow_control)
    P[P_FC_ON] = 1.0 if installed else 0.0
    if isinstance(load, str):
        if load != "curve":
            raise ValueError(f"load must be a force, 'curve' or None, not {load!r}")
        if cfg.load_curve is None:
            raise InputError(f"{cfg.path or cfg.name}: the scenario asks for the load curve but [load.curve] is not defined")
        P[P_LOADMODE] = 1.0
    else:
        P[P_LOAD] = 0.0 if load is None else float(load)
    if P[P_FRM] == 2.0 and P[P_FJ] - P[P_KV1] * P[P_VD] < 0.0:
        raise InputError(
            f"{cfg.path or cfg.name}: friction.breakaway_force - friction.low_speed_coefficient * friction.critical_velocity "
            f"= {P[P_FJ] - P[P_KV1] * P[P_VD]:g} N; seed 001 eq. (8) needs it >= 0 (friction never aids the motion)"
        )
    for name in cfg.effects:
        for option, value in EFFECTS[name].requires.items():
            if cfg.options[option] != value:
                raise InputError(f"{cfg.path or cfg.name}: effect {name} needs {option} = '{value}'")
    return P


def load_curve_arrays(cfg: PlantConfig) -> tuple[np.ndarray, np.ndarray]:
    """Load-curve arrays for the core (a flat zero curve when none is configured)."""
    if cfg.load_curve is None:
        return np.array([0.0, 1.0]), np.array([0.0, 0.0])
    xs, fs = cfg.load_curve_forces()
    return np.ascontiguousarray(xs, dtype=float), np.ascontiguousarray(fs, dtype=float)
