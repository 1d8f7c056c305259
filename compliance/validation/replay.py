"""The one replay of a recorded test through the model, for ``govcheck validate`` and ``govcheck diagnose``.

A replay is prepared once from the recording (``prepare_replay``: its conditions, start state,
noise and segments) and run on any plant configuration (``run_replay``, on the compiled core).
Validation runs it once per mode and puts it beside the recording (``replay``); the diagnosis
runs it hundreds of times on candidate configurations. Both see the same test:

- **conditions**: the sidecar's controller gains, supply pressure, load, flow-control valves and
  loop switch, each with one fallback (``replay_conditions``);
- **modes** (IEC 61400-27-2 calls them the *full-system* and the *play-back* simulation):
  ``closed_loop``, the model's controller follows the recorded set-point wherever the recording's
  controller acted, and the recorded valve command drives the plant where it did not (after a
  hold test's switch to manual, ``test.valve_null_from``; a recording without a set-point is
  driven by its command throughout); ``plant_only``, the recorded valve command drives the plant
  throughout, so the controller cannot hide a plant error: the position integrates every flow error;
- **noise**: in closed loop the controller acts on the *measured* position, so the recorded valve
  command carries the sensor noise through K_P and the filtered derivative K_D, and each noise-driven
  crossing of the valve dead band lets a little air through. The recording's own position noise
  (``recorded_noise.replay_noise``) is added to the model's measured position, so the replayed
  controller sees the noise the real one saw (on the practice no-effect recording the command
  residual falls from ~0.15 V to ~0.015 V);
- **start**: at rest at the recorded position smoothed at the first sample and the chamber pressures' medians
  over the first 50 ms;
- **segments** (``replay_segments``): the diagnosis re-synchronises with the recorded state at each
  set-point change and every 2 s (multiple shooting); measured states are reset, unmeasured ones
  carried over or set by physics (``replay_reset``), and the controller's integral state is carried
  by shifting the segment's set-point by K_I*I/K_P. Validation replays in one piece; either way a
  segment starts where the loop switches mode.

Everything is simulated on the controller grid ``t0 + k*T_s`` (a recording logged at another rate
is put on it by ``resampling.on_controller_clock``); the simulated channels go through the
recording's declared instruments (``logger_model``) before any comparison.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from compliance.errors import InputError, SimulationError
from compliance.model.config import PlantConfig
from compliance.plants import kind_of
from compliance.model.plant_vector import load_curve_arrays, parameter_vector
from compliance.model.vector_slots import P_KI, P_KP
from compliance.simulation.pid_loop import simulate_core
from compliance.simulation.rk4 import OUTPUT_COLUMNS, output_buffer
from compliance.validation.logger_model import logger_model
from compliance.validation.recorded_noise import NOISE_FREE_STD, replay_noise, robust_std
from compliance.validation.replay_conditions import (command_from_of, flow_control_of, initial_conditions, load_at_start, load_of,
                                                     replay_config, where_of)
from compliance.validation.replay_reset import OUT, reset_state, start_state
from compliance.validation.replay_setup import ReplaySetup, clip_to_full_scale, full_scale, recorded_states, replay_conditions, resolutions
from compliance.validation.replay_segments import MAX_SEGMENT, plan_segments
from compliance.validation.resampling import logged_indices, on_controller_clock

MODES = ("closed_loop", "plant_only")
NOISE_CHOICES = ("auto", "recorded", "none")
SIGNALS = ("position", "pressure_a", "pressure_b", "valve_command", "supply_pressure")
MIN_SAMPLES = 10


def _check_inputs(frame: pd.DataFrame, mode: str, noise: str, src: str) -> None:
    """A known mode and noise choice, the columns the mode needs, enough strictly increasing time stamps."""
    if mode not in MODES:
        raise InputError(f"mode '{mode}' is not one of {', '.join(MODES)}")
    if noise not in NOISE_CHOICES:
        raise InputError(f"noise '{noise}' is not one of {', '.join(NOISE_CHOICES)}")
    need = ("time", "position", "reference" if mode == "closed_loop" else "valve_command")
    missing = [c for c in need if c not in frame.columns]
    if missing:
        raise InputError(
            f"{src}: {mode.replace('_', '-')} replay needs column(s) {', '.join(repr(m) for m in missing)}; "
            f"the recording has {', '.join(map(str, frame.columns))}"
        )
    t = frame["time"].to_numpy(dtype=float)
    if t.size < MIN_SAMPLES:
        raise InputError(f"{src}: only {t.size} samples; a replay needs at least {MIN_SAMPLES}")
    if np.any(np.diff(t) <= 0):
        raise InputError(f"{src}: column 'time' must be strictly increasing")


def prepare_replay(cfg: PlantConfig, frame: pd.DataFrame, meta: dict | None, *, mode: str | None = None, noise: str = "auto",
                   segmented: bool = True, max_segment: float = MAX_SEGMENT) -> ReplaySetup:
    """Prepare the replay of a recording (conditions, start, noise, segments) for ``run_replay``.

    Parameters
    ----------
    cfg : PlantConfig
    frame : pandas.DataFrame
        Canonical recording: ``time`` [s], ``position`` [m], ``valve_command`` [V], ``reference`` [m]
        for a closed-loop test, pressures [Pa abs] when measured; at any rate.
    meta : dict
        Recording metadata (``read_recording``).
    mode : {"closed_loop", "plant_only"}, optional
        Default: closed loop when the recording has a set-point, else plant only (module doc).
    noise : {"auto", "recorded", "none"}
        Feed the recording's estimated position noise to the replayed controller: ``auto`` when the
        recording carries noise (robust std above ``NOISE_FREE_STD``), ``recorded`` always.
    segmented : bool
        Re-synchronise with the recorded state at set-point changes and every ``max_segment``.
    max_segment : float
        [s].

    Raises
    ------
    InputError
        Unknown mode, missing columns, a time base the controller clock cannot follow, a start
        outside the stroke, bad sidecar values.
    """
    meta = meta or {}
    src = where_of(meta) if meta.get("source_path") else "<recording>"
    mode = mode or ("closed_loop" if "reference" in frame.columns else "plant_only")
    _check_inputs(frame, mode, noise, src)
    if mode == "closed_loop":
        kind_of(cfg).check_diagnosable(cfg)  # the replay's closed loop is the PID servo's (simulate_core)
    run_cfg, overrides = replay_config(cfg, meta, frame)
    notes: list[str] = []
    ts = run_cfg.p("controller.sample_time")
    frame, logged = _on_clock(frame, ts, src, notes)
    t = frame["time"].to_numpy(dtype=float)
    closed = mode == "closed_loop"
    switch = command_from_of(meta) if closed else None
    command_from = _command_from(frame, closed, switch, ts, src, notes)
    rec = {s: frame[s].to_numpy(dtype=float) for s in SIGNALS if s in frame.columns}
    init = initial_conditions(frame, run_cfg, src)
    x0, pressures = init["initial_position"], init["initial_pressures"]
    load, load_source = load_of(cfg, meta, pressures)
    if load_source != "sidecar conditions.load_force":
        notes.append(load_source)
    fc = flow_control_of(meta)
    reference = frame["reference"].to_numpy(dtype=float) if "reference" in frame.columns else np.full(t.size, x0)
    command = rec["valve_command"] if "valve_command" in rec else np.full(t.size, run_cfg.p("valve.centre_voltage"))
    if "reference" not in frame.columns:
        notes.append("no reference column: replayed open loop from the recorded valve command")
    resolution = resolutions(rec, logged, meta)
    logger = logger_model(meta)
    share = logger.noise_share("position", ts) if logger is not None else 1.0
    injected = np.zeros(t.size)
    if command_from > 0 and noise != "none":
        injected = _injected(rec["position"], logged, ts, resolution["position"], share, noise == "recorded")
        injected[command_from:] = 0.0  # the controller is not in the loop there
    tt = t - t[0]
    states = recorded_states(rec, reference if closed else None, ts)
    resets = plan_segments(tt, reference, command, states["velocity"], command_from, segmented, max_segment)
    start = min(max(float(states["position"][0]), 0.0), run_cfg.p("cylinder.stroke"))
    conditions = replay_conditions(run_cfg, meta, init, start, load, load_source, overrides, fc, switch)
    return ReplaySetup(
        time=tt, reference=np.ascontiguousarray(reference), command=np.ascontiguousarray(command),
        closed_loop=closed, load=load, initial_position=float(x0), initial_pressures=pressures,
        noise=np.ascontiguousarray(injected), recorded=rec, resets=resets, states=states, overrides=overrides,
        notes=notes, source=src, logged=logged, logger=logger, resolution=resolution, command_from=command_from,
        flow_control=fc, conditions=conditions, noise_replay=bool(np.any(injected)), full_scale=full_scale(rec, logged),
    )


def _on_clock(frame: pd.DataFrame, ts: float, src: str, notes: list) -> tuple[pd.DataFrame, np.ndarray | None]:
    """The recording on the controller's clock, and the controller periods that carry a logged sample (None: all)."""
    t_rec = frame["time"].to_numpy(dtype=float)
    frame, note = on_controller_clock(frame, ts, src)  # one sample per controller period
    if not note:
        return frame, None
    notes.append(note)
    logged = logged_indices(t_rec, ts)
    return frame, logged[logged < len(frame)]


def _command_from(frame: pd.DataFrame, closed: bool, switch: float | None, ts: float, src: str, notes: list) -> int:
    """First sample the recorded valve command drives (``ReplaySetup.command_from``)."""
    n = len(frame)
    if not closed:
        return 0
    if switch is None:
        return n
    notes.append(f"the recorded valve command drives the plant from {switch:g} s (sidecar test.valve_null_from: the positioner in manual)")
    if "valve_command" not in frame.columns:
        raise InputError(f"{src}: the recorded valve command drives the plant from {switch:g} s, but there is no column 'valve_command'")
    return min(max(int(round(switch / ts)), 0), n)


def _injected(position: np.ndarray, logged, ts: float, quantum: float, share: float, always: bool) -> np.ndarray:
    """The recording's position noise for the replayed controller, or zeros when it carries none (and not ``always``)."""
    est = replay_noise(position, logged, ts, quantum, share)
    if always or robust_std(est if logged is None else est[logged]) >= NOISE_FREE_STD:
        return est
    return np.zeros(position.size)


def run_replay(cfg: PlantConfig, setup: ReplaySetup, *, noise: np.ndarray | None = None, stop=None) -> dict[str, np.ndarray] | None:
    """Simulate the replay; returns output column -> array on the recording's controller grid.

    ``cfg`` must already carry the recording's overrides (``ReplaySetup.config``).

    Parameters
    ----------
    noise : ndarray, optional
        Position noise to inject instead of the recording's [m].
    stop : callable, optional
        ``stop(out, k)`` after each segment (``out``: the (n + 1, N_OUT) outputs, filled up to sample
        ``k``, samples before ``k`` final; the simulated values, before the logger and the transducers'
        full scale): True ends the replay there and ``run_replay`` returns None (a residual that has
        already decided; ``diagnosis.evidence.residuals.Bound``).

    Raises
    ------
    SimulationError
        The state became non-physical (the fit treats it as a very poor fit).
    """
    P = parameter_vector(cfg, load=load_at_start(cfg, setup.load, setup.initial_position), flow_control=setup.flow_control)
    ts = cfg.p("controller.sample_time")
    n_sub = int(round(ts / cfg.p("simulation.step")))
    lx, ly = load_curve_arrays(cfg)
    n = setup.n_samples
    out = output_buffer(n + 1)  # by column, as the loop writes it: each signal contiguous
    nz = setup.noise if noise is None else np.ascontiguousarray(noise, dtype=float)
    quiet = np.zeros(n + 1)
    bounds = list(setup.resets) + [n]
    kp, ki = P[P_KP], P[P_KI]
    for i in range(len(setup.resets)):
        k0, k1 = int(bounds[i]), int(bounds[i + 1])
        if k1 <= k0:
            continue
        closed = setup.closed_loop and k0 < setup.command_from
        ref = setup.reference[k0:k1 + 1]
        if i == 0:
            y0 = start_state(cfg, P, setup)
        else:
            y0 = reset_state(cfg, P, setup, k0, out, lx, ly)
            if closed and kp > 0.0 and ki != 0.0:
                ref = ref + ki * setup.states["integral"][k0] / kp  # carries the integral state (module doc)
        seg = output_buffer(k1 - k0 + 1)  # the layout the loop is compiled for
        pos_noise = nz[k0:k1 + 1] if closed else quiet[k0:k1 + 1]
        # writable copies: a read-only input (pandas' to_numpy) would compile the loop once more for it
        status = simulate_core(P, y0, np.array(ref), np.array(setup.command[k0:k1 + 1]), closed, np.array(pos_noise), 0.0,
                               lx, ly, k1 - k0, n_sub, seg)
        if status >= 0:
            raise SimulationError(f"replay of {setup.source} became non-physical at t = {(k0 + status)*ts:.3f} s")
        out[k0:k1 + 1] = seg
        if stop is not None and k1 < n and stop(out, k1):
            return None
    sim = {c: out[:, OUT[c]] for c in OUTPUT_COLUMNS[1:]}
    sim = setup.logger.apply(sim, ts) if setup.logger is not None else sim  # as the logger recorded it ...
    for s, levels in setup.full_scale.items():  # ... and as a transducer at its full scale read it
        sim[s] = clip_to_full_scale(sim[s], levels)
    return sim


def replay(cfg: PlantConfig, recording: pd.DataFrame, metadata: dict | None = None, mode: str = "closed_loop", *,
           noise: str = "auto") -> pd.DataFrame:
    """Simulate the recorded test in one piece, aligned to the recording's own time stamps (validation's view).

    Parameters
    ----------
    cfg : PlantConfig
        The plant model (nominal or a candidate).
    recording : pandas.DataFrame
        Canonical columns (``time`` [s], ``position`` [m], ``reference`` [m], ``valve_command``
        [V], optional ``pressure_a`` / ``pressure_b`` / ``supply_pressure`` [Pa abs]); uniform
        or not, at any rate.
    metadata : dict, optional
        Sidecar metadata (``read_recording``; ``replay_conditions`` reads it).
    mode : {"closed_loop", "plant_only"}
        Module doc.
    noise : {"auto", "recorded", "none"}
        Closed loop: feed the recording's own position noise to the simulated sensor (``prepare_replay``).

    Returns
    -------
    pandas.DataFrame
        The simulation's columns (``compliance.simulation.rk4.OUTPUT_COLUMNS``) at the recording's
        time stamps (``time`` equals the recording's). ``attrs`` holds ``mode``,
        ``noise_replay``, ``conditions``, ``overrides`` and ``notes``.

    Raises
    ------
    InputError
        Unknown mode, a column the mode needs is missing, a start outside the stroke, bad sidecar values.
    SimulationError
        The model became non-physical.
    """
    setup = prepare_replay(cfg, recording, metadata, mode=mode, noise=noise, segmented=False)
    sim = run_replay(setup.config(cfg), setup)
    t_rec = recording["time"].to_numpy(dtype=float)
    tr = t_rec - t_rec[0]
    frame = pd.DataFrame({"time": t_rec} | {c: np.interp(tr, setup.time, sim[c]) for c in OUTPUT_COLUMNS[1:]})
    frame.attrs.update(mode=mode, noise_replay=setup.noise_replay, overrides=dict(setup.overrides),
                       conditions=setup.conditions, notes=list(setup.notes))
    return frame


__all__ = ["MODES", "NOISE_CHOICES", "SIGNALS", "ReplaySetup", "prepare_replay", "replay", "run_replay"]
