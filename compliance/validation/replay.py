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
from scipy.signal import savgol_filter

from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.simulation.profiles import Profile
from compliance.simulation import OUTPUT_COLUMNS, Scenario, SensorNoise, simulate

MODES = ("closed_loop", "plant_only")
NOISE_CHOICES = ("auto", "recorded", "none")
INITIAL_WINDOW = 0.05  # s; initial position = median of the first 50 ms (brief, issue 5)
NOISE_SMOOTHING = 0.031  # s; Savitzky-Golay window that separates sensor noise from motion
NOISE_FREE_STD = 1e-7  # m; below 0.1 um (finer than any position transducer) a recording counts as noise-free
_CONTROLLER_KEYS = {"kp": "controller.kp", "ki": "controller.ki", "kd": "controller.kd", "sample_time": "controller.sample_time"}


# ----------------------------------------------------------------------------------- resampling
def is_uniform(time: np.ndarray, step: float | None = None, rtol: float = 1e-3) -> bool:
    """True when the samples are evenly spaced (at ``step`` [s] if given) to ``rtol`` of a step."""
    dt = np.diff(np.asarray(time, dtype=float))
    ref = float(np.median(dt)) if step is None else step
    return bool(dt.size) and bool(np.all(np.abs(dt - ref) <= rtol * ref))


def resample_uniform(time: np.ndarray, values: np.ndarray, step: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Linear interpolation of a (possibly non-uniform) signal onto an even grid from ``time[0]``.

    Parameters
    ----------
    time : ndarray
        Strictly increasing sample times [s].
    values : ndarray
        Samples.
    step : float, optional
        Grid step [s]; default the median sample spacing.

    Returns
    -------
    (ndarray, ndarray)
        Grid times [s] and the interpolated values.
    """
    time = np.asarray(time, dtype=float)
    step = float(np.median(np.diff(time))) if step is None else float(step)
    n = int(math.floor((time[-1] - time[0]) / step + 1e-9)) + 1
    grid = time[0] + step * np.arange(n)
    return grid, np.interp(grid, time, np.asarray(values, dtype=float))


HELD_COLUMNS = ("reference", "valve_command")  # written by the controller: constant between its samples
MAX_LOG_INTERVAL = 4.0  # controller periods; a coarser log cannot show the loop's transients


def on_controller_clock(frame: pd.DataFrame, ts: float, where: str) -> tuple[pd.DataFrame, str | None]:
    """The recording on the controller's clock t_0 + k*ts (a replay needs one sample per period).

    Measured signals (position, pressures) are interpolated linearly at the controller's
    instants; the set-point and the valve command, which the controller holds over its period,
    take the last logged value at or before each instant. A recording already on the clock
    is returned unchanged.

    Parameters
    ----------
    frame : pandas.DataFrame
        Canonical recording (strictly increasing ``time`` [s]).
    ts : float
        Controller sample time [s].
    where : str
        File name for messages.

    Returns
    -------
    (pandas.DataFrame, str or None)
        The recording on the clock, and a note saying what was resampled (None if nothing).

    Raises
    ------
    InputError
        The log is coarser than ``MAX_LOG_INTERVAL`` controller periods.
    """
    t = frame["time"].to_numpy(dtype=float)
    if is_uniform(t, ts):
        return frame, None
    dt = np.diff(t)
    med = float(np.median(dt))
    if med > MAX_LOG_INTERVAL * ts:
        raise InputError(
            f"{where}: time: logged every {med*1e3:.3g} ms (median); replaying the {ts*1e3:g} ms controller needs at "
            f"least one sample per {MAX_LOG_INTERVAL:g} controller periods"
        )
    n = int(math.floor((t[-1] - t[0]) / ts + 1e-9)) + 1
    grid = t[0] + ts * np.arange(n)
    held = np.clip(np.searchsorted(t, grid + 1e-6 * ts, side="right") - 1, 0, t.size - 1)
    out = {"time": grid}
    for col in frame.columns:
        if col == "time":
            continue
        v = frame[col].to_numpy(dtype=float)
        out[col] = v[held] if col in HELD_COLUMNS else np.interp(grid, t, v)
    note = (f"resampled onto the {ts*1e3:g} ms controller clock: {t.size} samples at {dt.min()*1e3:.3g}..{dt.max()*1e3:.3g} ms "
            f"-> {n}; measured signals interpolated, set-point and command held")
    return pd.DataFrame(out), note


def zoh_interval_average(time: np.ndarray, values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Average of a zero-order-hold signal over each interval [edges[k], edges[k+1]).

    The recorded valve command is what a ZOH controller output looked like to the logger:
    each sample holds until the next. Averaging that staircase over each controller period
    returns the recorded values exactly when the logger ran at the controller's rate and clock,
    and conserves the time integral of the command (hence the valve's mass flow to first order)
    for any other sampling.

    Parameters
    ----------
    time : ndarray
        Sample times [s] (strictly increasing).
    values : ndarray
        Samples (held until the next sample; the last one held for ever, the first one before).
    edges : ndarray
        Interval edges [s], increasing, length n + 1.

    Returns
    -------
    ndarray
        n interval averages.
    """
    time = np.asarray(time, dtype=float)
    values = np.asarray(values, dtype=float)
    # integral of the staircase from time[0]: piecewise linear with knots at the sample times
    cum = np.concatenate(([0.0], np.cumsum(values[:-1] * np.diff(time))))

    def integral(t):
        t = np.asarray(t, dtype=float)
        inside = np.interp(np.clip(t, time[0], time[-1]), time, cum)
        before = np.minimum(t - time[0], 0.0) * values[0]
        after = np.maximum(t - time[-1], 0.0) * values[-1]
        return inside + before + after

    f = integral(edges)
    width = np.diff(edges)
    return np.diff(f) / width


def controller_grid(time: np.ndarray, sample_time: float) -> np.ndarray:
    """Controller sample instants relative to the first recorded sample, covering the recording [s]."""
    span = float(time[-1] - time[0])
    n = int(math.ceil(span / sample_time - 1e-9))
    return sample_time * np.arange(n + 1)


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


# ----------------------------------------------------------------------------------- noise
def position_quantum(position: np.ndarray) -> float:
    """Quantisation step of a recorded position [m] (0 when the values are not on a grid).

    The step is the smallest positive difference between distinct values; it is accepted when
    every value lies on its grid to 1e-3 of a step.
    """
    u = np.unique(np.asarray(position, dtype=float))
    if u.size < 3:
        return 0.0
    q = float(np.min(np.diff(u)))
    if not q > 0:
        return 0.0
    k = u / q
    if np.max(np.abs(k - np.round(k))) > 1e-3 or np.any(np.abs(k) > 1e12):
        return 0.0
    return q


def estimate_position_noise(position: np.ndarray, sample_time: float) -> np.ndarray:
    """Sensor noise realisation of a position recorded at the controller rate [m].

    The recording minus its Savitzky-Golay smoothing (cubic, ``NOISE_SMOOTHING`` window): the
    servo's motion (time constants >= 0.1 s) passes the smoother, white sensor noise does not.
    """
    x = np.asarray(position, dtype=float)
    w = int(round(NOISE_SMOOTHING / sample_time)) | 1
    if x.size <= w or w < 5:
        return np.zeros_like(x)
    return x - savgol_filter(x, w, 3)


def robust_std(values: np.ndarray) -> float:
    """Standard deviation of Gaussian noise from the median absolute deviation (1.4826 * MAD)."""
    v = np.asarray(values, dtype=float)
    return float(1.4826 * np.median(np.abs(v - np.median(v)))) if v.size else 0.0


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
    run_cfg, overrides = replay_config(cfg, metadata)
    init = initial_conditions(recording, run_cfg, where)
    load = load_from_metadata(metadata)
    supply_source = "sidecar conditions.supply_pressure" if "air.supply_pressure" in overrides else "configuration"
    ts = run_cfg.p("controller.sample_time")
    tr = t_rec - t_rec[0]
    grid = controller_grid(t_rec, ts)
    duration = float(grid[-1]) if grid.size > 1 else ts
    scenario_kw = dict(duration=duration, initial_position=init["initial_position"], load=load, initial_pressures=init["initial_pressures"])
    noise_used = False
    if mode == "closed_loop":
        ref = Profile(tr, recording["reference"].to_numpy(dtype=float))
        scenario = Scenario(reference=ref, **scenario_kw)
        on_clock = is_uniform(t_rec, ts)
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
        if est is not None:
            sim = simulate(run_cfg, replace(scenario, position_noise=est,
                                            noise=SensorNoise(position_quantum=position_quantum(x))))
            noise_used = True
        else:
            sim = simulate(run_cfg, scenario)
    else:
        edges = np.concatenate((grid, [grid[-1] + ts]))
        u = zoh_interval_average(tr, recording["valve_command"].to_numpy(dtype=float), edges)
        sim = simulate(run_cfg, Scenario(command=Profile(grid, u), **scenario_kw))
    t_sim = sim["time"].to_numpy(dtype=float)
    out = {"time": t_rec}
    for col in OUTPUT_COLUMNS[1:]:
        out[col] = np.interp(tr, t_sim, sim[col].to_numpy(dtype=float))
    frame = pd.DataFrame(out)
    frame.attrs.update(
        mode=mode,
        noise_replay=noise_used,
        overrides=dict(overrides),
        conditions={
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
            "supply_pressure_source": supply_source,
            "controller": {k: run_cfg.p(d) for k, d in _CONTROLLER_KEYS.items()},
        },
    )
    return frame
