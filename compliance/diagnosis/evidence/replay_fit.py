"""Replay a recording through the model, fast, with its own sensor noise, in re-synchronised segments.

The diagnosis simulates the same recording hundreds of times, so the replay is prepared once
(``prepare_replay``) and run many times on candidate configurations (``run_replay``),
calling the compiled core directly.

Two devices make the replay residual a good objective for fitting:

1. Matched noise. In a closed loop the controller acts on the *measured* position, so the
   recorded valve command carries the sensor noise through K_P and the filtered derivative
   K_D. The recording's position noise is estimated as what a Savitzky-Golay smoother leaves,
   n_hat = x_meas - S x_meas, and added to the model's measured position, so the replayed
   controller sees the noise the real one saw (``compliance.validation.replay`` does the same). On the
   practice no-effect recording the command residual falls from ~0.15 V to ~0.015 V.
2. Re-synchronisation (multiple shooting, Bock & Plitt 1984). A servo with a dead zone and
   stiction decides where it stalls on tiny differences, so one long replay of a slightly
   wrong model wanders off for seconds and the residual becomes a rugged function of the
   parameters (local minima every few per cent). The replay is therefore cut into segments
   that each start from the *recorded* state: at rest just before each set-point change, and
   every ``MAX_SEGMENT`` seconds otherwise. Measured states (position, its smoothed velocity,
   chamber and supply pressures) are reset; unmeasured ones are carried over from the previous
   segment (gas temperatures) or set by physics (LuGre bristle deflection from the force
   balance, the spool at the command, hoses at the chamber pressures). The controller's
   integral state is carried by shifting the segment's set-point by K_I*I/K_P. On the practice
   valve-dynamics recording this turns a landscape with a dozen local minima into one bowl.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.signal import savgol_filter

from compliance.model.config import PlantConfig
from compliance.errors import InputError, SimulationError
from compliance.effects.base import ReplayPoint
from compliance.effects.structure import reading_lags, reset_for_replay
from compliance.model.vector_slots import P_KI, P_KP, P_STROKE, S_V
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.rest_state import initial_state, set_rest_internal_states
from compliance.diagnosis.evidence.operating_point import load_at_start
from compliance.simulation.rk4 import N_OUT, OUTPUT_COLUMNS, output_buffer
from compliance.simulation.pid_loop import simulate_core
from compliance.validation.recorded_noise import position_noise_estimate, sensor_noise_std
from compliance.validation.logger_model import logger_model
from compliance.validation.recorded_noise import position_quantum

SIGNALS = ("position", "pressure_a", "pressure_b", "valve_command", "supply_pressure")
_OUT = {name: i for i, name in enumerate(OUTPUT_COLUMNS)}
MAX_SEGMENT = 2.0  # s; longest stretch replayed without re-synchronising
MIN_SEGMENT = 0.5  # s; a set-point change closer than this to the last reset does not start a new segment
PRE_STEP = 0.1  # s; a segment starts this long before a set-point change (the servo is still at rest)
_STATE_WINDOW = 41  # samples; Savitzky-Golay window for the states read from the recording
FILL_SEED = 20240  # seed of the readings drawn between a slow logger's samples (``_injected_noise``)
_VELOCITY_WINDOW = 81  # samples; cubic S-G derivative: 20 um noise at 1 kHz -> ~0.25 mm/s velocity noise


@dataclass
class ReplaySetup:
    """Everything a replay needs besides the plant configuration.

    Attributes
    ----------
    time : ndarray
        Controller-sample grid [s] from 0 (the recording's own time base).
    reference : ndarray
        Set-point per sample [m].
    command : ndarray
        Recorded valve command [V] (the input of an open-loop replay).
    closed_loop : bool
    load : float or "curve"
        Constant closing load [N] or the configuration's load curve.
    initial_position : float
        [m].
    initial_pressures : tuple or None
        Measured (p_A, p_B) at the start [Pa abs], else the at-rest trim.
    noise : ndarray
        Position noise injected into the model's measurement [m].
    recorded : dict
        Canonical signal -> recorded array (measured signals only).
    resets : ndarray
        Sample indices where a segment starts (first is 0).
    states : dict
        Smoothed recorded states used at the resets: position, velocity, pressure_a,
        pressure_b, supply_pressure (those measured), integral (the controller's integral of
        the recorded error [m*s]).
    overrides : dict
        Base-parameter overrides from the recording's sidecar.
    notes : list of str
    source : str
    logged : ndarray or None
        Controller periods at which the logger wrote a sample (None: every period); residuals,
        noise floors and the injected noise use these samples only.
    logger : LoggerModel or None
        What the logger did to the signals (``validation.logger_model``), applied to every replay.
    resolution : dict
        Measured signal -> quantisation step [SI]: declared (``metadata["channels"]``) or the
        lattice of the logged samples (0 when none).
    """

    time: np.ndarray
    reference: np.ndarray
    command: np.ndarray
    closed_loop: bool
    load: float | str
    initial_position: float
    initial_pressures: tuple[float, float] | None
    noise: np.ndarray
    recorded: dict
    resets: np.ndarray
    states: dict
    overrides: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    source: str = "<recording>"
    logged: np.ndarray | None = None
    logger: object = None
    resolution: dict = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        """Number of controller periods simulated."""
        return self.time.size - 1

    @property
    def samples(self) -> np.ndarray:
        """Indices of the controller grid that carry a logged sample."""
        return np.arange(self.time.size) if self.logged is None else self.logged


def segment_starts(time: np.ndarray, reference: np.ndarray, speed: np.ndarray | None = None,
                   max_segment: float = MAX_SEGMENT) -> np.ndarray:
    """Sample indices where a re-synchronised segment starts.

    A segment starts ``PRE_STEP`` before each set-point change (the servo is at rest then),
    unless the last start is less than ``MIN_SEGMENT`` ago. A stretch longer than
    ``max_segment`` without one is cut where the recorded speed is lowest (a stuck or slow
    moment, whose state the recording gives best).
    """
    n = time.size
    dt = float(np.median(np.diff(time))) if n > 1 else 1.0
    jumps = np.flatnonzero(np.abs(np.diff(reference)) > 1e-9)
    jump_set = set(jumps.tolist())
    # a continuous profile (sine, ramp) changes every sample: only isolated changes count as steps
    steps = [k for k in jumps if not (k - 1 in jump_set and k + 1 in jump_set)]
    pre = int(round(PRE_STEP / dt))
    gap = int(round(MIN_SEGMENT / dt))
    longest = max(int(round(max_segment / dt)), 2 * gap)
    spd = np.zeros(n) if speed is None else np.abs(np.asarray(speed, dtype=float))

    def cut(a: int, b: int) -> int:
        """Quietest sample in [a + gap, min(a + longest, b - gap)]."""
        lo, hi = a + gap, min(a + longest, b - gap)
        if hi <= lo:
            return a + longest
        return lo + int(np.argmin(spd[lo:hi + 1]))

    starts = [0]
    for c in sorted(set(max(k + 1 - pre, 0) for k in steps)) + [n - 1 + gap]:
        while c - starts[-1] > longest:
            starts.append(cut(starts[-1], c))
        if c - starts[-1] >= gap and c < n - 1:
            starts.append(c)
    return np.array(starts, dtype=int)


def _smooth(values: np.ndarray, deriv: int = 0, dt: float = 1.0, window: int = _STATE_WINDOW) -> np.ndarray:
    w = min(window, values.size - (1 - values.size % 2))
    if w < 5:
        return np.gradient(values, dt) if deriv else values.copy()
    return savgol_filter(values, w, 3, deriv=deriv, delta=dt)


def prepare_replay(cfg: PlantConfig, frame: pd.DataFrame, meta: dict, *, inject_noise: bool = True,
                   segmented: bool = True, max_segment: float = MAX_SEGMENT) -> ReplaySetup:
    """Build the replay of a recording on a plant configuration.

    Conditions follow ``compliance.validation.replay`` (sidecar controller gains and supply pressure
    override the configuration; load from ``conditions.load_force``; initial position and
    pressures from the first 50 ms), so ``govcheck validate`` and the diagnosis replay the same test.

    Parameters
    ----------
    cfg : PlantConfig
    frame : pandas.DataFrame
        Canonical recording: ``time``, ``position``, ``valve_command`` and, for a
        closed-loop run, ``reference``; pressures when measured.
    meta : dict
        Recording metadata (``read_recording``).
    inject_noise : bool
        Feed the recording's estimated position noise to the replayed controller.
    segmented : bool
        Re-synchronise with the recorded state at set-point changes and every ``max_segment``.
    max_segment : float
        [s].

    Raises
    ------
    InputError
        Missing columns, a time base the controller clock cannot follow.
    """
    from compliance.validation.replay import initial_conditions, load_from_metadata, on_controller_clock, replay_config as _overrides_of
    from compliance.validation.resampling import logged_indices

    src = str(meta.get("source_path", "<recording>"))
    for col in ("time", "position", "valve_command"):
        if col not in frame.columns:
            raise InputError(f"{src}: column '{col}' is needed to replay the recording through the model")
    t = frame["time"].to_numpy(dtype=float)
    if t.size < 10:
        raise InputError(f"{src}: only {t.size} samples; a replay needs at least 10")
    run_cfg, overrides = _overrides_of(cfg, meta)
    notes: list[str] = []
    ts = run_cfg.p("controller.sample_time")
    frame, note = on_controller_clock(frame, ts, src)  # one sample per controller period
    logged = None
    if note:
        notes.append(note)
        logged = logged_indices(t, ts)
        t = frame["time"].to_numpy(dtype=float)
        logged = logged[logged < t.size]
    closed = "reference" in frame.columns
    rec = {s: frame[s].to_numpy(dtype=float) for s in SIGNALS if s in frame.columns}
    init = initial_conditions(frame, run_cfg, src)
    x0 = init["initial_position"]
    pressures = init["initial_pressures"]
    load = _test_load(cfg, load_from_metadata(meta), pressures, notes)
    if closed:
        reference = frame["reference"].to_numpy(dtype=float)
    else:
        reference = np.full(t.size, x0)
        notes.append("no reference column: replayed open loop from the recorded valve command")
    resolution = _resolutions(rec, logged, meta)
    logger = logger_model(meta)
    share = logger.noise_share("position", ts) if logger is not None else 1.0
    noise = (_injected_noise(rec["position"], logged, ts, resolution["position"], share) if (closed and inject_noise)
             else np.zeros(t.size))
    tt = t - t[0]
    states = {"position": _smooth(rec["position"]), "velocity": _smooth(rec["position"], 1, ts, _VELOCITY_WINDOW)}
    resets = (segment_starts(tt, reference if closed else rec["valve_command"], states["velocity"], max_segment)
              if segmented else np.array([0]))
    for s in ("pressure_a", "pressure_b", "supply_pressure"):
        if s in rec:
            states[s] = _smooth(rec[s])
    if closed:
        err = reference - rec["position"]
        states["integral"] = np.concatenate([[0.0], np.cumsum(err)[:-1] * ts])  # the controller's I state at each sample
    return ReplaySetup(
        time=tt, reference=np.ascontiguousarray(reference), command=np.ascontiguousarray(rec["valve_command"]),
        closed_loop=closed, load=load, initial_position=float(x0), initial_pressures=pressures,
        noise=np.ascontiguousarray(noise), recorded=rec, resets=resets, states=states, overrides=overrides,
        notes=notes, source=src, logged=logged, logger=logger, resolution=resolution,
    )


def _test_load(cfg: PlantConfig, load, pressures, notes: list):
    """The sidecar's load, else the initial pressure difference's (tandem), else none (noted)."""
    if load is not None:
        return load
    if pressures is not None and cfg.option("cylinder.arrangement") == "tandem":
        load = (pressures[0] - pressures[1]) * (cfg.piston_area + cfg.rod_side_area)
        notes.append(f"no load in the sidecar: {load/1e3:.2f} kN estimated from the initial pressure difference")
        return load
    notes.append("no load in the sidecar and no pressures to estimate it: replayed without load")
    return 0.0


def _resolutions(rec: dict, logged: np.ndarray | None, meta: dict) -> dict:
    """Signal -> quantisation step [SI]: the channel's declared resolution, else the logged samples' lattice."""
    channels = meta.get("channels") or {}
    out = {}
    for s, v in rec.items():
        declared = (channels.get(s) or {}).get("resolution")
        out[s] = float(declared) if declared else position_quantum(v if logged is None else v[logged])
    return out


def _injected_noise(position: np.ndarray, logged: np.ndarray | None, ts: float, quantum: float = 0.0,
                    share: float = 1.0) -> np.ndarray:
    """The position noise the controller saw, estimated where the logger sampled it [m].

    On a log slower than the controller the noise is known only at the logged instants: it is
    estimated on those samples (smoother windows in seconds, not samples). Between them the
    controller saw other, independent readings: they are drawn (seeded, ``FILL_SEED``) with the
    noise level the logged samples show and quantised like the transducer. Interpolating instead
    would hand the replayed controller a smoother signal than the real one read: on a 250 Hz
    trend log of a valve-offset servo (50 um transducer) its derivative term then dithered the
    valve with 0.29 V instead of the recorded 0.35 V, and a 30 ms sensor lag fitted as well as
    the true offset; with drawn readings the replay dithers 0.35 V and the offset's 1 s mean
    command misfit falls from 0.08 V to 0.04 V. Behind an anti-alias filter (``share`` < 1: the
    share of white noise it passes, ``LoggerModel.noise_share``) no logged sample is a reading
    the controller saw: every reading is drawn, at the logged noise level divided by ``share``.
    """
    if logged is None and share == 1.0:
        return position_noise_estimate(position)
    logged = np.arange(position.size) if logged is None else logged
    x = position[logged]
    est = position_noise_estimate(x, dt=float(np.median(np.diff(logged))) * ts)
    out = np.interp(np.arange(position.size), logged, est)
    between = np.ones(position.size, dtype=bool)
    if share == 1.0:
        between[logged] = False
    sigma = sensor_noise_std(x, resolution=quantum) / share
    sigma = float(np.sqrt(max(sigma * sigma - quantum * quantum / 12.0, 0.0)))  # the noise beyond the quantisation
    base = position[between] - out[between]  # the interpolated reading without noise
    draw = base + np.random.default_rng(FILL_SEED).normal(0.0, sigma, int(between.sum()))
    out[between] = (np.round(draw / quantum) * quantum if quantum > 0 else draw) - base
    return out


def replay_config(cfg: PlantConfig, setup: ReplaySetup) -> PlantConfig:
    """The configuration with the recording's controller and supply overrides applied."""
    return cfg.replace(params=setup.overrides) if setup.overrides else cfg


def _reset_state(cfg, P, setup: ReplaySetup, k: int, previous: np.ndarray, lx, ly) -> np.ndarray:
    """State at sample ``k`` read from the recording (measured) and the previous segment (the rest)."""
    st = setup.states
    x = float(st["position"][k])
    v = float(st["velocity"][k])
    lags = reading_lags(P)
    if lags:
        # the recorded position is the sensor's, which trails the piston by its total lag (exactly for a
        # delay, to first order for the lag): the piston is where the reading arrives that much later
        later = setup.time[k]
        for lag in lags:
            later = later + lag
        x = float(np.interp(later, setup.time, st["position"]))
        v = float(np.interp(later, setup.time, st["velocity"]))
    pa = float(st["pressure_a"][k]) if "pressure_a" in st else float(previous[k, _OUT["pressure_a"]])
    pb = float(st["pressure_b"][k]) if "pressure_b" in st else float(previous[k, _OUT["pressure_b"]])
    y = initial_state(cfg, P, min(max(x, 0.0), P[P_STROKE]), (pa, pb))
    y[S_V] = v
    # the effects' states at the restart: measured ones from the recording, the others carried over
    measured = {s: float(st[s][k]) for s in SIGNALS if s in st}
    reset_for_replay(P, y, ReplayPoint(v, measured, dict(zip(OUTPUT_COLUMNS, previous[k].tolist()))))
    set_rest_internal_states(P, y, lx, ly, v)  # bristles carry the net force, the link its share
    return y


def run_replay(cfg: PlantConfig, setup: ReplaySetup, *, noise: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Simulate the replay; returns canonical signal -> array on the recording's grid.

    ``cfg`` must already carry the recording's overrides (``replay_config``).

    Raises
    ------
    SimulationError
        The state became non-physical (the fit treats it as a very poor fit).
    """
    P = parameter_vector(cfg, load=load_at_start(cfg, setup.load, setup.initial_position))
    ts = cfg.p("controller.sample_time")
    n_sub = int(round(ts / cfg.p("simulation.step")))
    lx, ly = load_curve_arrays(cfg)
    n = setup.n_samples
    out = np.zeros((N_OUT, n + 1)).T  # by column, as the loop writes it: each signal contiguous
    nz = setup.noise if noise is None else noise
    bounds = list(setup.resets) + [n]
    kp, ki = P[P_KP], P[P_KI]
    for i in range(len(setup.resets)):
        k0, k1 = int(bounds[i]), int(bounds[i + 1])
        if k1 <= k0:
            continue
        if i == 0:
            # held at rest where the recording starts: a settled servo sits off its set-point by its
            # steady error (a generated case: 10 um), which the piston, stuck, keeps until it moves
            x0 = float(setup.states["position"][0]) if "position" in setup.states else setup.initial_position
            y0 = initial_state(cfg, P, min(max(x0, 0.0), P[P_STROKE]), setup.initial_pressures)
            ref = setup.reference[k0:k1 + 1]
        else:
            y0 = _reset_state(cfg, P, setup, k0, out, lx, ly)
            ref = setup.reference[k0:k1 + 1]
            if setup.closed_loop and kp > 0.0 and ki != 0.0:
                ref = ref + ki * setup.states["integral"][k0] / kp  # carries the integral state (see module doc)
        seg = output_buffer(k1 - k0 + 1)  # the layout the loop is compiled for
        # writable copies: a read-only input (pandas' to_numpy) would compile the loop once more for it
        status = simulate_core(P, y0, np.array(ref), np.array(setup.command[k0:k1 + 1]),
                               setup.closed_loop, np.array(nz[k0:k1 + 1]), 0.0, lx, ly, k1 - k0, n_sub, seg)
        if status >= 0:
            raise SimulationError(f"replay of {setup.source} became non-physical at t = {(k0 + status)*ts:.3f} s")
        out[k0:k1 + 1] = seg
    sim = {s: out[:, _OUT[s]] for s in SIGNALS} | {c: out[:, _OUT[c]] for c in ("position_true", "temperature_a", "temperature_b")}
    return setup.logger.apply(sim, ts) if setup.logger is not None else sim  # as the logger recorded it
