"""Replay residuals: normalised by each signal's noise floor, subsampled, summarised per signal and window.

The fitted residual vector stacks, for every measured signal s, (recorded - model)/floor_s(t) at
every ``stride``-th sample. A correct model leaves values of about one (validation/recorded_noise.py). The
floor varies along the test: where a correct model's replay cannot follow the recording (slow
stick-slip, where noise decides when the servo breaks away) it is as large as that replay's
local error, so such stretches weigh in the fit by what they can tell (weighted least squares
with a heteroscedastic error model from a parametric bootstrap).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from compliance.model.config import PlantConfig
from compliance.errors import InputError, SimulationError
from compliance.validation.recorded_noise import QUANTISED_SHARE, sensor_noise_std
from compliance.validation.replay_conditions import load_at_start
from compliance.validation.replay import ReplaySetup, prepare_replay, run_replay
from compliance.validation.replay_setup import clip_to_full_scale
from compliance.validation.fit_metrics import nrmse
from compliance.validation.logger_model import LoggedPrefix
from compliance.simulation.rk4 import OUTPUT_COLUMNS

# lowest floors we accept (instrument resolution a logger rarely beats): keeps one signal from
# dominating when its noise estimate comes out implausibly small
MIN_FLOOR = {"position": 1e-6, "pressure_a": 50.0, "pressure_b": 50.0, "supply_pressure": 50.0, "valve_command": 0.005}
UNITS = {"position": "m", "pressure_a": "Pa", "pressure_b": "Pa", "supply_pressure": "Pa", "valve_command": "V"}
FAILED_RESIDUAL = 30.0  # normalised residual of every sample of a replay that diverged (at least; see with_fail_level)
NULL_PRE_ROLL = 1.0  # s of hold the null recording settles in before its test starts
NULL_SEEDS = (7, 8)  # noise draws of the null bootstrap (their squared errors are averaged)
LOCAL_WINDOW = 1.0  # s; moving window of the local null error (about one stick-slip episode)


@dataclass(frozen=True)
class ResidualModel:
    """How replays are compared with a recording.

    Attributes
    ----------
    signals : tuple of str
        Signals compared (measured, and not the replay's input).
    floors : dict
        Signal -> noise floor [SI unit of the signal].
    sensor_noise : dict
        Signal -> estimated sensor noise alone [SI].
    index : ndarray
        Sample indices used in the fit (every ``stride``-th).
    """

    signals: tuple[str, ...]
    floors: dict
    sensor_noise: dict
    index: np.ndarray
    recorded: dict
    fail_level: float = FAILED_RESIDUAL
    local: dict | None = None  # signal -> floor at each fitted sample (index) [SI]; None: the constant floor

    @property
    def size(self) -> int:
        """Length of the residual vector."""
        return len(self.signals) * self.index.size

    def vector(self, sim: dict | None) -> np.ndarray:
        """Stacked normalised residuals; a failed replay (None) gives a large constant vector."""
        if sim is None:
            return np.full(self.size, self.fail_level)
        parts = [(self.recorded[s][self.index] - sim[s][self.index]) / self.scale(s) for s in self.signals]
        return np.concatenate(parts)

    def scale(self, signal: str):
        """Floor of ``signal`` at the fitted samples: an array (time-resolved) or the constant floor."""
        if self.local is not None and signal in self.local:
            return self.local[signal]
        return self.floors[signal]

    def split(self, vec: np.ndarray) -> dict:
        """Signal -> its part of a residual vector."""
        n = self.index.size
        return {s: vec[i * n:(i + 1) * n] for i, s in enumerate(self.signals)}


def with_fail_level(model: ResidualModel, nominal_vector: np.ndarray) -> ResidualModel:
    """The model with failed replays scored ten times worse than the nominal model, so a fit never
    prefers a diverging parameter set to a poor but physical one."""
    rms = float(np.sqrt(np.mean(nominal_vector ** 2))) if nominal_vector.size else 0.0
    return dataclasses.replace(model, fail_level=max(FAILED_RESIDUAL, 10.0 * rms))


def compared_signals(setup: ReplaySetup) -> tuple[str, ...]:
    """Measured signals a replay can be compared on (the command is the input of an open-loop replay)."""
    out = [s for s in ("position", "pressure_a", "pressure_b", "supply_pressure", "valve_command") if s in setup.recorded]
    if not setup.closed_loop and "valve_command" in out:
        out.remove("valve_command")
    return tuple(out)


def null_replay_errors(cfg: PlantConfig, setup: ReplaySetup, sensor: dict, seed: int = 7) -> dict:
    """How far a *correct* model's replay stays from its recording, signal by signal [SI].

    A parametric bootstrap of the null hypothesis: the nominal model records the same test
    (set-point or command, load, start) with sensors like the recording's (noise and
    quantisation estimated from it), and that synthetic recording is replayed exactly as the
    real one is (matched noise, re-synchronised segments). Its errors contain the sensor
    noise, the error of the noise estimate, the state read at each re-synchronisation and the
    stall points a dead zone decides on noise.

    Returns
    -------
    dict
        signal -> (recorded - replayed) of the null recording at every sample [SI].
    """
    syn_setup = null_recording(cfg, setup, sensor, seed)
    frame = syn_setup.recorded
    n = syn_setup.time.size
    out = run_replay(cfg, syn_setup)
    return {s_: frame[s_] - out[s_][:n] for s_ in frame if s_ in setup.recorded}


def null_recording(cfg: PlantConfig, setup: ReplaySetup, sensor: dict, seed: int = 7) -> ReplaySetup:
    """The same test recorded by the nominal model with sensors like the recording's, prepared for replay."""
    import pandas as pd

    from compliance.simulation import SensorNoise

    rec, res = setup.recorded, setup.resolution
    qx, qp = res.get("position", 0.0), max(res.get("pressure_a", 0.0), res.get("pressure_b", 0.0))
    if setup.logger is not None:  # the transducers' own noise, before the logger's filter took its share
        ts_ = float(np.median(np.diff(setup.time)))
        sensor = {k: v / setup.logger.noise_share(k, ts_) for k, v in sensor.items()}
    noise = SensorNoise(position_std=_beyond_quantisation(sensor.get("position", 0.0), qx), position_quantum=qx,
                        pressure_std=_beyond_quantisation(max(sensor.get("pressure_a", 0.0), sensor.get("pressure_b", 0.0)), qp),
                        pressure_quantum=qp)
    t = setup.time
    ts = float(np.median(np.diff(t)))
    pre = min(int(round(NULL_PRE_ROLL / ts)), t.size)  # a recording shorter than the pre-roll settles for as long as it lasts
    load = load_at_start(cfg, setup.load, setup.initial_position)
    syn = _null_run(cfg, setup, pre, load, noise, seed)
    n = min(len(syn["position"]), t.size)
    frame = pd.DataFrame({"time": t[:n], "position": syn["position"][:n], "valve_command": syn["valve_command"][:n]})
    if setup.closed_loop:
        frame["reference"] = setup.reference[:n]
    for s_ in ("pressure_a", "pressure_b", "supply_pressure"):
        if s_ in rec:
            frame[s_] = syn[s_][:n] if s_ not in setup.full_scale else clip_to_full_scale(syn[s_][:n], setup.full_scale[s_])
    if setup.logger is not None:  # through the recording's instruments (filter, delays, calibration) ...
        logged = setup.logger.apply({c: frame[c].to_numpy() for c in frame.columns}, ts)
        frame = pd.DataFrame({c: logged[c] for c in frame.columns})
    if setup.logged is not None:  # ... at the instants it logged
        frame = frame.iloc[setup.logged[setup.logged < n]].reset_index(drop=True)
    test = {} if setup.flow_control is None else {"flow_control": "set" if setup.flow_control else "open"}
    if setup.closed_loop and setup.command_from < t.size:
        test["valve_null_from"] = float(t[setup.command_from])
    meta = {"conditions": {"load_force": setup.load}, "source_path": "<null replay>"} | ({"test": test} if test else {})
    return dataclasses.replace(prepare_replay(cfg, frame, meta), logger=setup.logger)


def _null_run(cfg: PlantConfig, setup: ReplaySetup, pre: int, load, noise, seed: int) -> dict:
    """The nominal model run through the recorded test with sensors like the recording's (signal -> array from t = 0).

    The bench settles first (``pre`` samples of hold before the test, like a real recording). A
    test whose valve command drives the plant from ``command_from`` (a hold test's switch to manual)
    is recorded in two runs: the closed loop up to the switch, then the command from the state the
    loop left the servo in (at rest: its position and pressures).
    """
    from compliance.plants import simulate
    from compliance.simulation import Scenario
    from compliance.simulation.profiles import Profile

    t = setup.time
    ts = float(np.median(np.diff(t)))
    switch = setup.command_from if setup.closed_loop else 0
    tt = np.concatenate([t[:pre], t + pre * ts]) if pre else t
    common = dict(load=load, noise=noise, seed=seed, flow_control=setup.flow_control)
    if switch == 0:
        cmd = np.concatenate([np.full(pre, setup.command[0]), setup.command])
        sc = Scenario(duration=float(tt[-1]), initial_position=setup.initial_position, command=Profile(tt, cmd), **common)
        syn = simulate(cfg, sc).iloc[pre:]
        return {c: syn[c].to_numpy() for c in syn.columns}
    last = min(switch, t.size - 1)
    ref = np.concatenate([np.full(pre, setup.reference[0]), setup.reference[:last + 1]])
    sc = Scenario(duration=float(tt[pre + last]), initial_position=setup.initial_position, reference=Profile(tt[:pre + last + 1], ref),
                  **common)
    first = simulate(cfg, sc).iloc[pre:]
    out = {c: first[c].to_numpy() for c in first.columns}
    if switch >= t.size:
        return out
    held = (float(first["pressure_a"].iloc[-1]), float(first["pressure_b"].iloc[-1]))
    x_held = min(max(float(first["position_true"].iloc[-1]), 0.0), cfg.p("cylinder.stroke"))
    rest = setup.command[switch:]
    tr = t[switch:] - t[switch]
    sc2 = Scenario(duration=float(tr[-1]), initial_position=x_held, command=Profile(tr, rest), initial_pressures=held,
                   **dict(common, seed=seed + 1))
    second = simulate(cfg, sc2)
    return {c: np.concatenate([out[c][:switch], second[c].to_numpy()]) for c in out}


def _beyond_quantisation(std: float, q: float) -> float:
    """The noise a simulated sensor adds before quantising at ``q``, from the recorded noise ``std`` [SI].

    A coarse transducer's quantisation is part of the recorded spread (q^2/12 of its variance) and
    the simulated sensor quantises on top of its noise, so its noise is what the spread holds beyond
    that; a fine one's share (below ``QUANTISED_SHARE`` of the spread) is left in, as lab-grade
    recordings were always replayed.
    """
    if q <= 0.0 or q / math.sqrt(12.0) <= QUANTISED_SHARE * std:
        return std
    return math.sqrt(max(std * std - q * q / 12.0, 0.0))


def null_replay_floors(cfg: PlantConfig, setup: ReplaySetup, sensor: dict) -> tuple[dict, dict]:
    """Constant and time-resolved floors from the null bootstrap (``null_replay_errors``).

    Returns
    -------
    floors : dict
        signal -> RMS error of the null replays [SI].
    local : dict
        signal -> local RMS error at every sample [SI]: the squared errors of the draws
        averaged and smoothed over ``LOCAL_WINDOW``.
    """
    draws = [null_replay_errors(cfg, setup, sensor, seed) for seed in NULL_SEEDS]
    t = setup.time
    ts = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    w = max(1, int(round(LOCAL_WINDOW / ts)))
    floors, local = {}, {}
    for s_ in draws[0]:
        n = min(d[s_].size for d in draws)
        sq = np.mean([d[s_][:n] ** 2 for d in draws], axis=0)
        floors[s_] = float(np.sqrt(np.mean(sq)))
        kernel = np.ones(min(w, n)) / min(w, n)
        loc = np.sqrt(np.convolve(sq, kernel, mode="same"))
        full = np.full(t.size, floors[s_])
        full[:n] = loc
        local[s_] = full
    return floors, local





def own_floor_objective(model: ResidualModel, cfg: PlantConfig, setup: ReplaySetup, vec: np.ndarray) -> dict:
    """Signal -> normalised RMS of an explanation's residual ``vec`` against its *own* floors.

    The floors are what a correct model's replay leaves; ``build_residual_model`` measures them
    with the declared (nominal) model. When the explanation is a plant with slower dynamics (a
    spool at 35 rad/s, say), its replay amplifies the error of the injected noise estimate more, so
    its own null bootstrap (``cfg``: the explanation's replay configuration) leaves more; each
    sample is then judged against the larger of the two floors.
    """
    _, own = null_replay_floors(cfg, setup, model.sensor_noise)
    m = model.index.size
    out = {}
    for i, s in enumerate(model.signals):
        base = model.scale(s)
        scale = np.maximum(base, own[s][model.index]) if s in own else base
        r = vec[i * m:(i + 1) * m] * base / scale
        out[s] = float(np.sqrt(np.mean(r * r))) if m else 0.0
    return out


def build_residual_model(cfg: PlantConfig, setup: ReplaySetup, *, stride: int = 5, nominal: dict | None = None) -> ResidualModel:
    """Estimate the noise floors and choose the samples of the fit.

    Each floor is the larger of the signal's sensor noise and what a correct model's replay
    leaves (``null_replay_floors``): one constant per signal (reported) and one along the test (the
    weights of the fit, and the yardstick of ``no_mismatch``: ``servo.selection.NOISE_TOLERANCE``).

    Parameters
    ----------
    cfg : PlantConfig
        The nominal replay configuration (overrides applied).
    setup : ReplaySetup
    stride : int
        Use every ``stride``-th sample (5 ms at 1 kHz keeps pressure noise independent).
    nominal : dict, optional
        Unused (kept for callers that already ran the nominal replay).
    """
    signals = compared_signals(setup)
    logged = setup.samples
    sensor = {s: (0.0 if s == "valve_command" else sensor_noise_std(setup.recorded[s][logged], resolution=setup.resolution.get(s, 0.0)))
              for s in signals}
    try:
        null, null_local = null_replay_floors(cfg, setup, sensor)
    except (SimulationError, InputError):
        null, null_local = {}, {}
    step = float(np.median(np.diff(logged))) if logged.size > 1 else 1.0
    index = logged[::max(1, int(round(stride / step)))]  # logged samples only, about ``stride`` periods apart
    floors, local = {}, {}
    for s in signals:
        own = sensor[s] if s != "position" or not setup.closed_loop else 0.0
        f = max(null.get(s, 0.0), own)
        if f <= 0.0:
            f = sensor[s]
        floors[s] = max(f, MIN_FLOOR[s])
        if s in null_local:
            local[s] = np.maximum(np.maximum(null_local[s][index], own), MIN_FLOOR[s])
    return ResidualModel(signals=signals, floors=floors, sensor_noise=sensor, index=index,
                         recorded={s: setup.recorded[s] for s in signals}, local=local or None)


CHECK_SHARE = 0.05  # a stopping replay checks its residual after each segment that adds this share of the fitted samples
STOP_MARGIN = 1.0 + 1e-9  # a partial sum of squares summed in another order than the full one: stop only clearly above


class Bound:
    """Stops a replay once its chi-square over the samples replayed so far exceeds ``limit`` (``run_replay``'s ``stop``).

    The replay is re-synchronised in segments, so after each segment the residuals of every fitted
    sample before its end are final; their sum of squares only grows with the rest. A candidate
    whose value can no longer matter to the search asking for it (``servo.simplex``, the grid scans
    of ``servo.fit``) is known to be worse once that partial sum exceeds the limit, and the rest of
    the recording is not replayed. ``vec`` holds the residuals so far (zeros beyond): its sum of
    squares is the partial chi-square, a lower bound of the full one. A recording's logger (anti-alias
    filter, delays, calibration: ``validation.logger_model``) is applied to the samples replayed so far as
    the whole replay would be (``LoggedPrefix``: the same values).
    """

    def __init__(self, model: ResidualModel, limit: float, full_scale: dict | None = None, logged: LoggedPrefix | None = None):
        self.model, self.limit = model, limit
        self.full_scale = full_scale or {}
        self.logged = logged
        self.vec = np.zeros(model.size)
        self.chi2 = 0.0
        self.done = 0  # fitted samples accounted for (positions in model.index)
        self.every = max(1, int(CHECK_SHARE * model.index.size))
        self.columns = [OUTPUT_COLUMNS.index(s) for s in model.signals]

    def __call__(self, out: np.ndarray, k: int) -> bool:
        """True when the residuals of the samples before ``k`` (final once a segment ends at ``k``) exceed the limit."""
        m = self.model
        # samples before k are final (the next segment starts on sample k); a logged one reads ``lead`` samples on
        j = int(np.searchsorted(m.index, k - (self.logged.lead if self.logged is not None else 0), side="left"))
        if j - self.done < self.every:
            return False
        idx = m.index[self.done:j]
        size = m.index.size
        for i, (s, col) in enumerate(zip(m.signals, self.columns)):
            scale = m.scale(s)
            if not np.isscalar(scale):
                scale = scale[self.done:j]
            sim = out[idx, col] if self.logged is None else self.logged.values(s, out[:, col], k, idx)
            sim = sim if s not in self.full_scale else clip_to_full_scale(sim, self.full_scale[s])
            r = (m.recorded[s][idx] - sim) / scale
            self.vec[i * size + self.done:i * size + j] = r
            self.chi2 += float(np.dot(r, r))
        self.done = j
        return self.chi2 > self.limit * STOP_MARGIN


def evaluate(model: ResidualModel, cfg: PlantConfig, setup: ReplaySetup, limit: float = math.inf) -> tuple[np.ndarray, dict | None, bool]:
    """Run one replay; (normalised residual vector, replay or None when it diverged or stopped, stopped).

    With a finite ``limit`` the replay stops at the first segment where its chi-square exceeds it
    (``Bound``); the vector then holds the residuals so far, zeros beyond.
    """
    bound = None
    if math.isfinite(limit):
        active = setup.logger is not None and setup.logger.active
        # the period run_replay hands the logger, so the filter and the delays are the same arithmetic
        logged = LoggedPrefix(setup.logger, cfg.p("controller.sample_time"), setup.n_samples + 1) if active else None
        bound = Bound(model, limit, setup.full_scale, logged)
    try:
        sim = run_replay(cfg, setup, stop=bound)
    except SimulationError:
        return model.vector(None), None, False
    if sim is None:
        return bound.vec, None, True
    return model.vector(sim), sim, False


def signal_fit(model: ResidualModel, sim: dict | None, mask: np.ndarray | None = None) -> dict:
    """Per-signal agreement of a replay with the recording (all samples, or those in ``mask``).

    Returns
    -------
    dict
        signal -> {rms [SI], rms_normalised [-], nrmse [-] (|r| / |y - mean y|, the validation table's NRMSE),
        fit_percent (100 * (1 - |r| / |y - mean y|), the NRMSE fit of system identification)}.
    """
    out = {}
    for s in model.signals:
        y = model.recorded[s] if mask is None else model.recorded[s][mask]
        if y.size == 0:
            continue
        if sim is None:
            out[s] = {"rms": float("nan"), "rms_normalised": float("nan"), "nrmse": float("nan"), "fit_percent": float("nan")}
            continue
        m = sim[s] if mask is None else sim[s][mask]
        r = y - m
        rms = float(np.sqrt(np.mean(r * r)))
        e = nrmse(y, m)  # the validation table's definition, so text and table quote one number
        e = float("nan") if e is None else e
        out[s] = {"rms": rms, "rms_normalised": rms / model.floors[s], "nrmse": e, "fit_percent": 100.0 * (1.0 - e)}
    return out
