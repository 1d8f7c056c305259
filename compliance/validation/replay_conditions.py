"""The conditions a recorded test ran under, read once for every replay of it (validate and diagnose).

A replay puts the model where the recording's servo was: the controller gains it ran with, the
supply it was fed, the load it carried, the flow-control valves as they were set, the moment its
positioner went to manual, and the state it started from. Each comes from one source, in this
order, and the replay says which (``ReplaySetup.conditions``):

- controller gains and sample time: the sidecar's ``[controller]``, else the configuration;
- supply pressure: the sidecar's ``conditions.supply_pressure``, else the median of the recorded
  supply pressure, else the configuration;
- load: the sidecar's ``conditions.load_force`` (> 0 closes, or ``"curve"``), else the force the
  initial pressure difference holds on a tandem actuator at rest, else none;
- flow-control valves (meter-out throttles 2V2/2V3): the sidecar's ``test.flow_control``
  (``"open"``: needles fully open, no restriction; ``"set"``: as commissioned, the
  configuration's conductances), else the configuration;
- the valve command drives the plant from ``test.valve_null_from`` [s] on (a hold test: the
  positioner switched to manual with the valve at null), else the controller runs throughout;
- start: the operating point (position, chamber pressures) as the medians of the first ``INITIAL_WINDOW``; the
  replay itself starts at rest at the smoothed recorded position (``replay_reset.start_state``).

A recording's sidecar gives the load *there*, at the operating point the test starts from. The
core's ``position_dependent_load`` adds its stiffness about mid-stroke (compliance/model/assembly.py),
so switched on in a replay of a test that starts elsewhere it would also shift the load at the
start by k (x0 - stroke/2), and no stiffness could fit both the load and its slope (an effect
anchored at a fixed point, not where the data is). Every replay, null recording and predicted test
therefore passes the constant load through ``load_at_start``: the constant part is set so that
the total load at the start position is the stated one, and the stiffness acts about the
recording's own operating point.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from compliance.effects import EFFECTS
from compliance.errors import InputError
from compliance.model.config import PlantConfig

INITIAL_WINDOW = 0.05  # s; start state = medians of the first 50 ms (our choice: a few noise samples, before any motion)
CONTROLLER_KEYS = {"kp": "controller.kp", "ki": "controller.ki", "kd": "controller.kd", "sample_time": "controller.sample_time"}
FLOW_CONTROL = {"open": False, "set": True}  # sidecar test.flow_control -> throttles installed
LOAD_EFFECT = "position_dependent_load"


def where_of(metadata: dict | None) -> str:
    """The recording's file name for messages."""
    return str((metadata or {}).get("source_path") or "recording")


def _table(metadata: dict, section: str, where: str) -> dict | None:
    table = metadata.get(section)
    if table is not None and not isinstance(table, dict):
        raise InputError(f"{where}: sidecar [{section}] must be a table")
    return table


def _sidecar_number(metadata: dict, section: str, key: str, where: str, positive: bool = False) -> float | None:
    table = _table(metadata, section, where)
    if table is None or key not in table:
        return None
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{where}: sidecar {section}.{key} = {value!r}; expected a number in SI units")
    if positive and value <= 0:
        raise InputError(f"{where}: sidecar {section}.{key} = {value!r}; expected a positive number")
    return float(value)


def replay_config(cfg: PlantConfig, metadata: dict | None, frame: pd.DataFrame | None = None) -> tuple[PlantConfig, dict]:
    """Configuration the recorded test ran with: sidecar controller gains and the supply pressure.

    Parameters
    ----------
    cfg : PlantConfig
    metadata : dict or None
        Sidecar metadata from ``read_recording`` (SI floats).
    frame : pandas.DataFrame, optional
        The recording: its recorded supply pressure (median) when the sidecar gives none.

    Returns
    -------
    (PlantConfig, dict)
        The configuration with overrides, and the overrides (dotted key -> SI value).
    """
    metadata = metadata or {}
    where = where_of(metadata)
    overrides: dict[str, float] = {}
    for key, dotted in CONTROLLER_KEYS.items():
        v = _sidecar_number(metadata, "controller", key, where, positive=(key == "sample_time"))
        if v is not None:
            overrides[dotted] = v
    ps = _sidecar_number(metadata, "conditions", "supply_pressure", where, positive=True)
    if ps is None and frame is not None and "supply_pressure" in frame.columns:
        ps = float(np.median(frame["supply_pressure"].to_numpy(dtype=float)))
    if ps is not None:
        overrides["air.supply_pressure"] = ps
    if "controller.sample_time" in overrides:
        # keep the configured RK4 step if it divides the recorded sample time, else the largest that does
        ts = overrides["controller.sample_time"]
        h = cfg.p("simulation.step")
        if abs(ts / h - round(ts / h)) > 1e-6 or h > ts:
            overrides["simulation.step"] = ts / max(1, math.ceil(ts / h))
    if not overrides:
        return cfg, overrides
    try:
        return cfg.replace(params=overrides), overrides
    except InputError as exc:
        raise InputError(f"{where}: the sidecar's values do not fit the plant: {exc}") from None


def supply_source(metadata: dict | None, overrides: dict) -> str:
    """Where the replay's supply pressure came from (words)."""
    if "air.supply_pressure" not in overrides:
        return "configuration"
    cond = (metadata or {}).get("conditions")
    return ("sidecar conditions.supply_pressure" if isinstance(cond, dict) and "supply_pressure" in cond
            else "median of the recorded supply pressure (none in the sidecar)")


def sidecar_load(metadata: dict | None) -> float | str | None:
    """Closing load of the test from ``conditions.load_force`` [N] (> 0 closes), ``"curve"`` or None."""
    metadata = metadata or {}
    cond = metadata.get("conditions")
    if not isinstance(cond, dict) or "load_force" not in cond:
        return None
    value = cond["load_force"]
    if value == "curve":
        return "curve"
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{where_of(metadata)}: sidecar conditions.load_force = {value!r}; expected a force in N (> 0 closes) or \"curve\"")
    return float(value)


def load_of(cfg: PlantConfig, metadata: dict | None, pressures: tuple[float, float] | None) -> tuple[float | str, str]:
    """The test's load and where it came from: the sidecar's, else the initial pressures' (tandem), else none.

    Returns
    -------
    (float or "curve", str)
        Closing load [N] (> 0 closes) or the configuration's load curve, and its source in words.
    """
    load = sidecar_load(metadata)
    if load is not None:
        return load, "sidecar conditions.load_force"
    if pressures is not None and cfg.option("cylinder.arrangement") == "tandem":
        # at rest the pneumatic force (p_A - p_B)(A_cap + A_rod) holds the load (seed 000 eq. 6, friction aside)
        load = (pressures[0] - pressures[1]) * (cfg.piston_area + cfg.rod_side_area)
        return load, f"no load in the sidecar: {load/1e3:.2f} kN estimated from the initial pressure difference"
    return 0.0, "no load in the sidecar and no pressures to estimate it: replayed without load"


def load_at_start(cfg: PlantConfig, load, x0: float):
    """Constant load [N] to hand the core so that its total load at ``x0`` is ``load``.

    Parameters
    ----------
    cfg : PlantConfig
        Configuration (with any effects switched on).
    load : float or "curve"
        The recording's stated load at its start position [N] (a load curve is left alone).
    x0 : float
        Start position [m].
    """
    if isinstance(load, str) or load is None or LOAD_EFFECT not in cfg.effects:
        return load
    k = dict(EFFECTS[LOAD_EFFECT].defaults(), **cfg.effects[LOAD_EFFECT])["stiffness"]
    return float(load) - k * (float(x0) - 0.5 * cfg.p("cylinder.stroke"))  # assembly.py: k (x - stroke/2)


def flow_control_of(metadata: dict | None) -> bool | None:
    """Flow-control valves installed in the test (sidecar ``test.flow_control``), or None (as configured)."""
    metadata = metadata or {}
    test = _table(metadata, "test", where_of(metadata))
    if not test or "flow_control" not in test:
        return None
    value = test["flow_control"]
    if value not in FLOW_CONTROL:
        raise InputError(f"{where_of(metadata)}: sidecar test.flow_control = {value!r}; expected one of "
                         f"{', '.join(repr(k) for k in FLOW_CONTROL)}")
    return FLOW_CONTROL[value]


def command_from_of(metadata: dict | None) -> float | None:
    """Recording time [s, from the first sample] from which the recorded valve command drives the plant, or None.

    A hold test (sidecar ``test.valve_null_from``): the position loop holds until then, after which
    the positioner is in manual with the valve command at null; the model's controller must not act
    there, or it would hold a position the real servo let drift.
    """
    metadata = metadata or {}
    return _sidecar_number(metadata, "test", "valve_null_from", where_of(metadata))


def initial_conditions(recording: pd.DataFrame, cfg: PlantConfig, where: str = "recording") -> dict:
    """Initial position and pressures from the recording's first ``INITIAL_WINDOW`` seconds.

    Returns
    -------
    dict
        ``initial_position`` [m] (median of the first 50 ms, within the stroke),
        ``initial_pressures`` ((p_A, p_B) [Pa abs] medians, or None when either side is not measured).
    """
    t = recording["time"].to_numpy(dtype=float)
    first = t <= t[0] + INITIAL_WINDOW
    x0 = float(np.median(recording["position"].to_numpy(dtype=float)[first]))
    stroke = cfg.p("cylinder.stroke")
    if not (-0.01 * stroke <= x0 <= stroke * 1.01):
        raise InputError(
            f"{where}: column 'position' starts at {x0*1e3:.2f} mm, outside the stroke 0..{stroke*1e3:.0f} mm of "
            f"'{cfg.name}' (is the position in metres, measured from the closed end?)"
        )
    x0 = min(max(x0, 0.0), stroke)  # a transducer offset at an end stop reads a little beyond it
    pressures = None
    if "pressure_a" in recording and "pressure_b" in recording:
        pa = float(np.median(recording["pressure_a"].to_numpy(dtype=float)[first]))
        pb = float(np.median(recording["pressure_b"].to_numpy(dtype=float)[first]))
        for name, p in (("pressure_a", pa), ("pressure_b", pb)):
            if not p > 0:
                raise InputError(f"{where}: column '{name}' starts at {p:.0f} Pa; expected an absolute pressure > 0 (gauge data need a column map with kind = \"gauge\")")
        pressures = (pa, pb)
    return {"initial_position": x0, "initial_pressures": pressures}


__all__ = ["CONTROLLER_KEYS", "FLOW_CONTROL", "INITIAL_WINDOW", "LOAD_EFFECT", "command_from_of", "flow_control_of",
           "initial_conditions", "load_at_start", "load_of", "replay_config", "sidecar_load", "supply_source", "where_of"]
