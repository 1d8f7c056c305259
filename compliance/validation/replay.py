"""Replay a recorded test with the model: same set-point (closed loop) or same valve command (plant only).

Two ways to put the model beside a recording (IEC 61400-27-2 calls them the *full-system*
and the *play-back* simulation approaches):

- ``closed_loop``: the model's controller follows the recorded reference. Gains from the
  sidecar (``controller.kp/ki/kd/sample_time``) override the configuration's. By default the
  position noise the recording carries (its high-pass part) is fed to the simulated sensor, so
  the controller sees the same noise-driven crossings of the valve dead band as the real
  one (see ``estimate_position_noise``); without it a dead-band loop drifts apart from the
  recording for reasons that are not plant physics.
- ``plant_only``: the recorded valve command drives the plant. The controller cannot hide a
  plant error here: the position integrates every flow error.

Everything is simulated on the controller grid ``t0 + k*T_s`` and interpolated back onto the
recording's own time stamps, so the returned frame lines up row by row with the recording.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd

from compliance.errors import InputError
from compliance.model.config import PlantConfig
from compliance.simulation import OUTPUT_COLUMNS, Scenario, SensorNoise
from compliance.plants import simulate
from compliance.simulation.profiles import Profile
from compliance.validation.logger_model import logger_model
from compliance.validation.recorded_noise import NOISE_FREE_STD, estimate_position_noise, position_quantum, robust_std
from compliance.validation.resampling import (
    controller_grid,
    is_uniform,
    on_controller_clock,
    resample_uniform,
    zoh_interval_average,
)

__all__ = [  # the clock and noise helpers live beside this module and stay importable from it
    "MODES", "NOISE_CHOICES", "INITIAL_WINDOW", "NOISE_FREE_STD", "controller_grid", "estimate_position_noise",
    "initial_conditions", "is_uniform", "load_from_metadata", "on_controller_clock", "position_quantum", "replay",
    "replay_config", "resample_uniform", "robust_std", "zoh_interval_average",
]

MODES = ("closed_loop", "plant_only")
NOISE_CHOICES = ("auto", "recorded", "none")
INITIAL_WINDOW = 0.05  # s; initial position = median of the first 50 ms (our choice: a few noise samples, before any motion)
_CONTROLLER_KEYS = {"kp": "controller.kp", "ki": "controller.ki", "kd": "controller.kd", "sample_time": "controller.sample_time"}


# ----------------------------------------------------------------------------------- conditions
def _where(metadata: dict | None) -> str:
    return str((metadata or {}).get("source_path") or "recording")


def _sidecar_number(metadata: dict, section: str, key: str, where: str, positive: bool = False) -> float | None:
    table = metadata.get(section)
    if table is None:
        return None
    if not isinstance(table, dict):
        raise InputError(f"{where}: sidecar [{section}] must be a table")
    if key not in table:
        return None
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{where}: sidecar {section}.{key} = {value!r}; expected a number in SI units")
    if positive and value <= 0:
        raise InputError(f"{where}: sidecar {section}.{key} = {value!r}; expected a positive number")
    return float(value)


def replay_config(cfg: PlantConfig, metadata: dict | None) -> tuple[PlantConfig, dict]:
    """Configuration the recorded test ran with: sidecar controller gains and supply pressure.

    Parameters
    ----------
    cfg : PlantConfig
    metadata : dict or None
        Sidecar metadata from ``read_recording`` (SI floats).

    Returns
    -------
    (PlantConfig, dict)
        The configuration with overrides, and the overrides (dotted key -> SI value).
    """
    metadata = metadata or {}
    where = _where(metadata)
    overrides: dict[str, float] = {}
    for key, dotted in _CONTROLLER_KEYS.items():
        v = _sidecar_number(metadata, "controller", key, where, positive=(key == "sample_time"))
        if v is not None:
            overrides[dotted] = v
    ps = _sidecar_number(metadata, "conditions", "supply_pressure", where, positive=True)
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


def load_from_metadata(metadata: dict | None) -> float | str | None:
    """Closing load of the test from ``conditions.load_force`` [N] (> 0 closes), ``"curve"`` or None."""
    metadata = metadata or {}
    cond = metadata.get("conditions")
    if not isinstance(cond, dict) or "load_force" not in cond:
        return None
    value = cond["load_force"]
    if value == "curve":
        return "curve"
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{_where(metadata)}: sidecar conditions.load_force = {value!r}; expected a force in N (> 0 closes) or \"curve\"")
    return float(value)


def initial_conditions(recording: pd.DataFrame, cfg: PlantConfig, where: str = "recording") -> dict:
    """Initial position and pressures from the recording's first ``INITIAL_WINDOW`` seconds.

    Returns
    -------
    dict
        ``initial_position`` [m] (median of the first 50 ms), ``initial_pressures`` ((p_A, p_B)
        [Pa abs] medians, or None when either side is not measured).
    """
    t = recording["time"].to_numpy(dtype=float)
    first = t <= t[0] + INITIAL_WINDOW
    x0 = float(np.median(recording["position"].to_numpy(dtype=float)[first]))
    stroke = cfg.p("cylinder.stroke")
    if not (-1e-3 * stroke <= x0 <= stroke * (1 + 1e-3)):
        raise InputError(
            f"{where}: column 'position' starts at {x0*1e3:.2f} mm, outside the stroke 0..{stroke*1e3:.0f} mm of "
            f"'{cfg.name}' (is the position in metres, measured from the closed end?)"
        )
    x0 = min(max(x0, 0.0), stroke)
    pressures = None
    if "pressure_a" in recording and "pressure_b" in recording:
        pa = float(np.median(recording["pressure_a"].to_numpy(dtype=float)[first]))
        pb = float(np.median(recording["pressure_b"].to_numpy(dtype=float)[first]))
        for name, p in (("pressure_a", pa), ("pressure_b", pb)):
            if not p > 0:
                raise InputError(f"{where}: column '{name}' starts at {p:.0f} Pa; expected an absolute pressure > 0 (gauge data need a column map with kind = \"gauge\")")
        pressures = (pa, pb)
    return {"initial_position": x0, "initial_pressures": pressures}


# ----------------------------------------------------------------------------------- simulation
def replay(cfg: PlantConfig, recording: pd.DataFrame, metadata: dict | None = None, mode: str = "closed_loop", *, noise: str = "auto") -> pd.DataFrame:
    """Simulate the recorded test with the model, aligned to the recording's time stamps.

    Parameters
    ----------
    cfg : PlantConfig
        The plant model (nominal or a candidate).
    recording : pandas.DataFrame
        Canonical columns (``time`` [s], ``position`` [m], ``reference`` [m], ``valve_command``
        [V], optional ``pressure_a`` / ``pressure_b`` / ``supply_pressure`` [Pa abs]); uniform
        or not, at any rate.
    metadata : dict, optional
        Sidecar metadata (``read_recording``): ``controller.kp/ki/kd/sample_time`` override the
        configuration; ``conditions.load_force`` [N] (> 0 closes) and
        ``conditions.supply_pressure`` [Pa abs] set the test conditions.
    mode : {"closed_loop", "plant_only"}
        Follow the recorded reference with the model's controller, or drive the plant with the
        recorded valve command.
    noise : {"auto", "recorded", "none"}
        Closed loop only: feed the recording's own position noise (``estimate_position_noise``)
        to the simulated sensor. ``auto`` does so when the recording is sampled on the
        controller's clock (otherwise the noise sequence cannot be placed sample by sample) and
        carries noise (robust std above ``NOISE_FREE_STD``).

    Returns
    -------
    pandas.DataFrame
        The simulation's columns (``compliance.simulation.rk4.OUTPUT_COLUMNS``) at the recording's
        time stamps (``time`` equals the recording's). ``attrs`` holds ``mode``,
        ``noise_replay``, ``conditions`` and ``overrides``.

    Raises
    ------
    InputError
        Unknown mode, a column the mode needs is missing, a start outside the stroke, bad sidecar values.
    SimulationError
        The model became non-physical.
    """
    where = _where(metadata)
    _check_replay_inputs(recording, mode, noise, where)
    t_rec = recording["time"].to_numpy(dtype=float)
    run_cfg, overrides = replay_config(cfg, metadata)
    init = initial_conditions(recording, run_cfg, where)
    load = load_from_metadata(metadata)
    ts = run_cfg.p("controller.sample_time")
    tr = t_rec - t_rec[0]
    grid = controller_grid(t_rec, ts)
    duration = float(grid[-1]) if grid.size > 1 else ts
    scenario_kw = dict(duration=duration, initial_position=init["initial_position"], load=load, initial_pressures=init["initial_pressures"])
    noise_used = False
    if mode == "closed_loop":
        scenario = Scenario(reference=Profile(tr, recording["reference"].to_numpy(dtype=float)), **scenario_kw)
        sim, noise_used = _closed_loop_run(run_cfg, scenario, recording, noise, where)
    else:
        edges = np.concatenate((grid, [grid[-1] + ts]))
        u = zoh_interval_average(tr, recording["valve_command"].to_numpy(dtype=float), edges)
        sim = simulate(run_cfg, Scenario(command=Profile(grid, u), **scenario_kw))
    t_sim = sim["time"].to_numpy(dtype=float)
    instruments = logger_model(metadata)
    cols = {c: sim[c].to_numpy(dtype=float) for c in OUTPUT_COLUMNS[1:]}
    if instruments is not None:  # the simulated channels as the recording's logger records them
        cols = instruments.apply(cols, float(np.median(np.diff(t_sim))))
    out = {"time": t_rec}
    for col in OUTPUT_COLUMNS[1:]:
        out[col] = np.interp(tr, t_sim, cols[col])
    frame = pd.DataFrame(out)
    frame.attrs.update(mode=mode, noise_replay=noise_used, overrides=dict(overrides),
                       conditions=_replay_conditions(run_cfg, init, load, overrides))
    return frame


def _check_replay_inputs(recording: pd.DataFrame, mode: str, noise: str, where: str) -> None:
    """A known mode and noise choice, the columns the mode needs, a strictly increasing time."""
    if mode not in MODES:
        raise InputError(f"mode '{mode}' is not one of {', '.join(MODES)}")
    if noise not in NOISE_CHOICES:
        raise InputError(f"noise '{noise}' is not one of {', '.join(NOISE_CHOICES)}")
    need = ("time", "position", "reference" if mode == "closed_loop" else "valve_command")
    missing = [c for c in need if c not in recording.columns]
    if missing:
        raise InputError(
            f"{where}: {mode.replace('_', '-')} replay needs column(s) {', '.join(repr(m) for m in missing)}; "
            f"the recording has {', '.join(map(str, recording.columns))}"
        )
    t_rec = recording["time"].to_numpy(dtype=float)
    if t_rec.size < 2 or np.any(np.diff(t_rec) <= 0):
        raise InputError(f"{where}: column 'time' must be strictly increasing with at least 2 samples")


def _closed_loop_run(run_cfg: PlantConfig, scenario: Scenario, recording: pd.DataFrame, noise: str, where: str):
    """Simulate the closed loop, with the recording's own position noise when asked and possible.

    Returns
    -------
    (pandas.DataFrame, bool)
        The simulation and whether the recorded noise was replayed.
    """
    ts = run_cfg.p("controller.sample_time")
    on_clock = is_uniform(recording["time"].to_numpy(dtype=float), ts)
    use_noise = noise == "recorded" or (noise == "auto" and on_clock)
    if use_noise and not on_clock:
        raise InputError(
            f"{where}: noise='recorded' needs a recording sampled on the controller clock "
            f"({ts*1e3:g} ms); this one is not (use noise='none')"
        )
    x = recording["position"].to_numpy(dtype=float)
    est = estimate_position_noise(x, ts) if use_noise else None
    if est is not None and noise == "auto" and robust_std(est) < NOISE_FREE_STD:
        est = None  # a noise-free recording (e.g. from the model itself): nothing to replay
    if est is None:
        return simulate(run_cfg, scenario), False
    return simulate(run_cfg, replace(scenario, position_noise=est, noise=SensorNoise(position_quantum=position_quantum(x)))), True


def _replay_conditions(run_cfg: PlantConfig, init: dict, load, overrides: dict) -> dict:
    """The test conditions the replay assumed, each with where it came from."""
    return {
        "initial_position": init["initial_position"],
        "initial_position_source": f"median of the recorded position over the first {INITIAL_WINDOW*1e3:.0f} ms",
        "initial_pressures": init["initial_pressures"],
        "initial_pressures_source": (
            f"medians of the recorded pressures over the first {INITIAL_WINDOW*1e3:.0f} ms"
            if init["initial_pressures"] else "at rest balancing the load, mean (p_s + p_atm)/2 (pressures not recorded)"
        ),
        "load_force": load,
        "load_source": "sidecar conditions.load_force" if load is not None else "none given: no load",
        "supply_pressure": run_cfg.p("air.supply_pressure"),
        "supply_pressure_source": "sidecar conditions.supply_pressure" if "air.supply_pressure" in overrides else "configuration",
        "controller": {k: run_cfg.p(d) for k, d in _CONTROLLER_KEYS.items()},
    }
