"""Test procedures as data: step sequences, sinusoid, full stroke, independent adjustment, hold, dead band.

A procedure kind declares its settings (with units and defaults); :func:`run` builds the
scenario(s) for one operating point, simulates them and measures every metric the kind
produces with the ONE metric implementation in :mod:`compliance.metrics`. No physics here.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field

import numpy as np

from . import metrics as M
from .errors import InputError

# signals kept for plots, and the most points per signal (report figures need no more)
TRACE_COLUMNS = ("time", "reference", "position", "valve_command", "pressure_a", "pressure_b")
MAX_TRACE_POINTS = 2000
# a step whose peak speed reaches this fraction of the full-command speed is rate limited
RATE_LIMIT_FRACTION = 0.9


@dataclass(frozen=True)
class Setting:
    """A procedure setting: type (``length``, ``time``, ``frequency``, ``speed``, ``voltage``,
    ``number``, ``count``, ``bool``, ``directions``, ``pattern``), default text (None = required)."""

    type: str
    default: object
    meaning: str


@dataclass(frozen=True)
class Kind:
    """A procedure kind: what it does and the settings it takes."""

    name: str
    meaning: str
    settings: dict


_SI = {"length": "m", "time": "s", "frequency": "Hz", "speed": "m/s", "voltage": "V"}
_CMD = Setting("voltage", "full", "valve command magnitude about the valve centre; 'full' = valve.command_limit")

KINDS: dict[str, Kind] = {
    k.name: k
    for k in (
        Kind("steps", "set-point step sequence in closed loop from the operating point", {
            "size": Setting("length", None, "step size, e.g. '5 %stroke' or '8 mm'"),
            "pattern": Setting("pattern", ["up", "down"], "directions of the successive steps"),
            "lead": Setting("time", "1 s", "hold before the first step"),
            "dwell": Setting("time", "4 s", "time between steps"),
        }),
        Kind("sine", "sinusoidal set-point x0 + A sin(2 pi f t) in closed loop (seed 000: 8 mm at 0.05 Hz)", {
            "amplitude": Setting("length", None, "amplitude A"),
            "frequency": Setting("frequency", None, "frequency f"),
            "cycles": Setting("number", 2, "number of periods simulated"),
            "skip_cycles": Setting("number", 0.5, "periods left out of the tracking errors (start transient)"),
        }),
        Kind("full_stroke", "full command, open loop, from one end to the other through the flow-control valves", {
            "directions": Setting("directions", ["opening", "closing"], "which strokes"),
            "command": _CMD,
            "flow_control": Setting("bool", True, "flow-control valves 2V2/2V3 in the circuit"),
            "timeout": Setting("time", "30 s", "simulated time per stroke"),
        }),
        Kind("independent_adjustment", "change one flow-control valve; the other direction's time must not change", {
            "adjust": Setting("directions", ["opening", "closing"], "which valve(s) to change, one at a time"),
            "factor": Setting("number", 0.5, "factor applied to the adjusted valve's conductance"),
            "command": _CMD,
            "timeout": Setting("time", "30 s", "simulated time per stroke"),
        }),
        Kind("hold", "reach the operating point's position from below, then hold it under its load in closed loop", {
            "duration": Setting("time", "10 s", "simulated time"),
            "settle": Setting("time", "3 s", "start of the measurement window"),
            "approach": Setting("length", "2 %stroke", "start this far below the position (0: start at rest on it); "
                                "larger than the accuracy asked, so the servo must move to hold"),
        }),
        Kind("dead_band", "slow triangular set-point in closed loop; width of the hysteresis loop", {
            "amplitude": Setting("length", "2 %stroke", "triangle amplitude about the operating point"),
            "rate": Setting("speed", "0.5 mm/s", "set-point speed (slow against the servo's time constant)"),
            "lead": Setting("time", "1 s", "hold before the triangle"),
        }),
    )
}


def parse_setting(setting: Setting, value, where: str):
    """Validate one setting value (Amounts for quantities, plain values otherwise)."""
    from .requirements import parse_amount

    t = setting.type
    if t in _SI:
        if t == "voltage" and value == "full":
            return "full"
        a = parse_amount(value, _SI[t], where)
        if a.value < 0:
            raise InputError(f"{where}: must not be negative")
        return a
    if t in ("number", "count"):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise InputError(f"{where}: expected a positive number, got {value!r}")
        return float(value)
    if t == "bool":
        if not isinstance(value, bool):
            raise InputError(f"{where}: expected true or false, got {value!r}")
        return value
    allowed = ("opening", "closing") if t == "directions" else ("up", "down")
    if not isinstance(value, list) or not value or any(v not in allowed for v in value):
        raise InputError(f"{where}: expected a non-empty list of {' / '.join(repr(a) for a in allowed)}, got {value!r}")
    return list(value)


# --------------------------------------------------------------------------- outcomes
@dataclass
class Sample:
    """One candidate value of a metric within a run (one step, one stroke, one window)."""

    value: float | None
    label: str
    reason: str | None = None
    eligible: bool = True  # False: measured but not valid for a verdict (rate limited)
    detail: dict = field(default_factory=dict)


@dataclass
class RunOutcome:
    """Everything one procedure x operating point produced."""

    procedure: str
    operating_point: str
    kind: str
    samples: dict = field(default_factory=dict)  # request key -> list[Sample]
    traces: list = field(default_factory=list)
    marks: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    error: str | None = None
    error_kind: str | None = None  # "InputError" (bad procedure for this plant) or "SimulationError"
    wall_time: float = 0.0

    def add(self, key: str, sample: Sample):
        """Append a candidate value for a metric request."""
        self.samples.setdefault(key, []).append(sample)


def request_key(metric: str, options: dict | None = None) -> str:
    """Key of a metric request: the metric name plus its options as written."""
    if not options:
        return metric
    return metric + "[" + ",".join(f"{k}={v.text if hasattr(v, 'text') else v}" for k, v in sorted(options.items())) + "]"


def downsample(frame, label: str, columns=TRACE_COLUMNS, max_points=MAX_TRACE_POINTS) -> dict:
    """Trace for plots: at most ``max_points`` evenly chosen samples per signal (lists of floats)."""
    n = len(frame)
    idx = np.unique(np.linspace(0, n - 1, min(n, max_points)).round().astype(int)) if n else np.array([], int)
    out = {"label": label, "points": int(idx.size), "samples": int(n)}
    for c in columns:
        if c in frame.columns:
            # 7 significant digits: 0.1 um on a metre, 0.1 Pa on 1 MPa - far below plot resolution
            out[c] = [float(f"{v:.7g}") for v in frame[c].to_numpy()[idx]]
    return out


# --------------------------------------------------------------------------- runner
def run(cfg, procedure, op, requests) -> RunOutcome:
    """Run one procedure at one operating point and measure the requested metrics.

    Parameters
    ----------
    cfg : PlantConfig
    procedure : requirements.Procedure
    op : requirements.OperatingPoint
    requests : list of (metric, options)
        Metrics to measure (with requirement options); every metric the kind produces is
        also measured with default options for the report.

    Returns
    -------
    RunOutcome
        A simulation or input failure is recorded in ``error``, not raised, so one bad run
        does not hide the others.
    """
    from .errors import GovcheckError

    t0 = _time.perf_counter()
    out = RunOutcome(procedure.name, op.name, procedure.kind)
    try:
        _RUNNERS[procedure.kind](cfg, procedure, op, list(requests), out)
    except GovcheckError as exc:
        out.error = str(exc)
        out.error_kind = type(exc).__name__
    out.wall_time = _time.perf_counter() - t0
    return out


def _stroke(cfg) -> float:
    return cfg.p("cylinder.stroke")


def _x0(cfg, op, procedure) -> float:
    if op.initial_position is None:
        raise InputError(f"operating point '{op.name}' has no initial_position, needed by procedure '{procedure.name}'")
    x0 = op.initial_position.resolve(_stroke(cfg))
    if not 0.0 <= x0 <= _stroke(cfg):
        raise InputError(f"operating point '{op.name}': initial position {x0*1e3:.1f} mm is outside the stroke")
    return x0


def _load(cfg, op):
    """Scenario load of an operating point: closing force [N], "curve" or None."""
    if op.load == "nominal":
        return cfg.p("load.nominal_force")
    return op.load


def _full_command(cfg, setting) -> tuple[float, float]:
    """(opening, closing) full command voltages about the valve centre [V]."""
    centre = cfg.p("valve.centre_voltage")
    mag = cfg.p("valve.command_limit") - abs(centre) if setting == "full" else setting.value
    return centre + mag, centre - mag


def _simulate(cfg, duration, x0, *, reference=None, command=None, load=None, flow_control=None):
    from .simulate import Scenario, simulate

    return simulate(cfg, Scenario(duration, x0, reference=reference, command=command, load=load, flow_control=flow_control))


def _opts(options: dict) -> dict:
    """Requirement options -> keyword arguments of metrics.step_response (SI)."""
    kw = {}
    for k, default in M.STEP_OPTION_DEFAULTS.items():
        if k in options:
            kw[k] = options[k].value
    return kw


def _speed_samples(out, requests, tt, x, label, t_from=-np.inf, t_to=np.inf):
    v, vo, vc = M.speed_extremes(tt, x, t_from, t_to)
    for key, val in (("max_speed", v), ("max_opening_speed", vo), ("max_closing_speed", vc)):
        out.add(key, Sample(val, label))


def _saturation_sample(cfg, out, tt, u, label, t_from=-np.inf, t_to=np.inf):
    thr = cfg.p("valve.saturation_voltage")
    centre = cfg.p("valve.centre_voltage")
    out.add("saturation_fraction", Sample(M.saturation_fraction(tt, u - centre, thr, t_from, t_to), label,
                                          detail={"threshold_V": thr}))


# ---- steps
def _step_profile(x0, size, pattern, lead, dwell, stroke, where):
    from .profiles import Profile

    for flip in (1.0, -1.0):
        levels = [x0]
        for d in pattern:
            levels.append(levels[-1] + flip * (size if d == "up" else -size))
        if all(-1e-12 <= v <= stroke + 1e-12 for v in levels):
            times, values = [0.0], [x0]
            for k, lv in enumerate(levels[1:]):
                t = lead + k * dwell
                times += [t, t]
                values += [values[-1], lv]
            used = pattern if flip > 0 else ["down" if d == "up" else "up" for d in pattern]
            return Profile(np.array(times), np.array(values)), used, lead + len(pattern) * dwell
    raise InputError(f"{where}: steps of {size*1e3:.1f} mm in the pattern {pattern} leave the stroke 0..{stroke*1e3:.0f} mm either way")


def _full_command_speeds(cfg, op):
    """Peak speeds at full command from each end under the operating point's load and circuit [m/s]."""
    from .profiles import Profile

    u_open, u_close = _full_command(cfg, "full")
    L = _stroke(cfg)
    res = {}
    for d, x0, u in (("opening", 0.0, u_open), ("closing", L, u_close)):
        df = _simulate(cfg, 3.0, x0, command=Profile.constant(u), load=_load(cfg, op), flow_control=op.flow_control)
        tt, x = M.frame_columns(df, "time", "position")
        _, vo, vc = M.speed_extremes(tt, x)
        res[d] = vo if d == "opening" else vc
    return res


def _run_steps(cfg, proc, op, requests, out):
    s = proc.settings
    L = _stroke(cfg)
    x0 = _x0(cfg, op, proc)
    size = s["size"].resolve(L)
    ref, used, duration = _step_profile(x0, size, s["pattern"], s["lead"].value, s["dwell"].value, L,
                                        f"procedure '{proc.name}' at '{op.name}'")
    if used != s["pattern"]:
        out.notes.append(f"pattern reversed to {used} to stay inside the stroke from {x0*1e3:.1f} mm")
    df = _simulate(cfg, duration, x0, reference=ref, load=_load(cfg, op), flow_control=op.flow_control)
    label = f"{proc.name}@{op.name}"
    out.traces.append(downsample(df, label))
    tt, x, r, u = M.frame_columns(df, "time", "position", "reference", "valve_command")
    events = M.find_steps(tt, r, min_size=min(5e-5, 0.5 * size))
    wants_tau = any(m == "time_constant" for m, _ in requests)
    vmax = _full_command_speeds(cfg, op) if wants_tau else None
    if vmax:
        out.notes.append(
            "rate limit check: full-command peak speeds under this load and circuit "
            f"{vmax['opening']*1e3:.0f} mm/s opening, {vmax['closing']*1e3:.0f} mm/s closing"
        )
    wanted = {m: (m, {}) for m, info in M.METRICS.items() if "steps" in info.kinds}
    wanted.update({request_key(m, o): (m, o) for m, o in requests if "steps" in M.METRICS[m].kinds})
    sat_v = cfg.p("valve.saturation_voltage")
    centre = cfg.p("valve.centre_voltage")
    per_opts: dict = {}
    for key, (metric, opts) in wanted.items():
        okey = request_key("", opts)
        if okey not in per_opts:
            per_opts[okey] = [M.step_response(tt, x, ev, valve_command=u - centre, command_saturation=sat_v, **_opts(opts))
                              for ev in events]
        for k, (ev, sm) in enumerate(zip(events, per_opts[okey])):
            direction = "up" if ev.size > 0 else "down"
            lab = f"step {k+1} {direction} {abs(ev.size)*1e3:.2f} mm at {ev.t_step:.2f} s"
            detail = {"t_step": ev.t_step, "size": ev.size, "x_start": sm.x_start, "x_final": sm.x_final}
            if metric in ("max_speed", "max_opening_speed", "max_closing_speed", "saturation_fraction"):
                continue
            val = getattr(sm, metric)
            reason = sm.reasons.get(metric)
            eligible = True
            if metric == "time_constant" and val is not None:
                if sm.rate_limited:
                    eligible = False
                elif vmax is not None:
                    lim = vmax["opening" if ev.size > 0 else "closing"]
                    if lim > 0 and sm.max_speed >= RATE_LIMIT_FRACTION * lim:
                        eligible = False
                        reason = (f"rate limited: peak speed {sm.max_speed*1e3:.0f} mm/s >= "
                                  f"{RATE_LIMIT_FRACTION:.0%} of the full-command speed {lim*1e3:.0f} mm/s")
                detail["peak_speed"] = sm.max_speed
            out.add(key, Sample(val, lab, reason, eligible, detail))
    # marks for plots (default options)
    for k, (ev, sm) in enumerate(zip(events, per_opts[request_key("", {})])):
        for name, v in sm.marks.items():
            out.marks.append({"trace": label, "step": k + 1, "type": name, "value": v})
    _speed_samples(out, requests, tt, x, label)
    _saturation_sample(cfg, out, tt, u, label)


# ---- sine
def _run_sine(cfg, proc, op, requests, out):
    from .profiles import sine

    s = proc.settings
    L = _stroke(cfg)
    x0 = _x0(cfg, op, proc)
    amp = s["amplitude"].resolve(L)
    f = s["frequency"].value
    if x0 - amp < 0 or x0 + amp > L:
        raise InputError(f"procedure '{proc.name}' at '{op.name}': {x0*1e3:.1f} +/- {amp*1e3:.1f} mm leaves the stroke")
    duration = s["cycles"] / f
    df = _simulate(cfg, duration, x0, reference=sine(amp, f, x0, duration=duration), load=_load(cfg, op), flow_control=op.flow_control)
    label = f"{proc.name}@{op.name}"
    out.traces.append(downsample(df, label))
    tt, x, r, u = M.frame_columns(df, "time", "position", "reference", "valve_command")
    t_from = s["skip_cycles"] / f
    rms, mx = M.tracking_errors(tt, x, r, t_from)
    lab = f"after {t_from:.1f} s"
    out.add("tracking_rms_error", Sample(rms, lab))
    out.add("tracking_max_error", Sample(mx, lab))
    out.marks.append({"trace": label, "type": "tracking_window", "value": [t_from, float(tt[-1])]})
    _speed_samples(out, requests, tt, x, label)
    _saturation_sample(cfg, out, tt, u, label)


# ---- full stroke
def _stroke_runs(cfg, op, command, flow_control, timeout, label, out, directions=("opening", "closing")):
    from .profiles import Profile

    L = _stroke(cfg)
    u_open, u_close = _full_command(cfg, command)
    times = {}
    for d in directions:
        x0, u = (0.0, u_open) if d == "opening" else (L, u_close)
        # simulate 8 s, then double up to the timeout until the stroke passes 75 % (25 %) and ends
        dur = min(8.0, timeout)
        while True:
            df = _simulate(cfg, dur, x0, command=Profile.constant(u), load=_load(cfg, op), flow_control=flow_control)
            tt, x = M.frame_columns(df, "time", "position")
            T, t1, t2, why = M.stroke_time(tt, x, L, d)
            done = abs(x[-1] - (L - x0)) <= 0.01 * L
            if (T is not None and done) or dur >= timeout:
                break
            dur = min(2.0 * dur, timeout)
        times[d] = (T, why, df, t1, t2)
        if label:
            tl = f"{label} {d}"
            out.traces.append(downsample(df, tl))
            if t1 is not None and t2 is not None:
                out.marks.append({"trace": tl, "type": "stroke_points", "value": [[t1, x[np.searchsorted(tt, t1)]], [t2, x[np.searchsorted(tt, t2)]]]})
    return times


def _run_full_stroke(cfg, proc, op, requests, out):
    s = proc.settings
    label = f"{proc.name}@{op.name}"
    times = _stroke_runs(cfg, op, s["command"], s["flow_control"], s["timeout"].value, label, out, s["directions"])
    for d, (T, why, df, t1, t2) in times.items():
        tt, x = M.frame_columns(df, "time", "position")
        L = _stroke(cfg)
        # informative: time from the command to within 1 % of the other end (includes the cushion)
        end = np.nonzero(x >= 0.99 * L)[0] if d == "opening" else np.nonzero(x <= 0.01 * L)[0]
        detail = {"t25_75": [t1, t2], "time_to_end": float(tt[end[0]]) if end.size else None}
        out.add(f"{d}_time", Sample(T, f"{d} at full command", why, detail=detail))
        v, vo, vc = M.speed_extremes(tt, x)
        out.add("max_speed", Sample(v, d))
        out.add("max_opening_speed" if d == "opening" else "max_closing_speed", Sample(vo if d == "opening" else vc, d))
    out.notes.append("flow-control valves " + ("installed" if s["flow_control"] else "removed") + f"; load {op.load_text}")


# ---- independent adjustment
_VALVE_KEY = {"opening": "flow_control.opening_conductance", "closing": "flow_control.closing_conductance"}


def _run_independent(cfg, proc, op, requests, out):
    s = proc.settings
    timeout = s["timeout"].value
    base = _stroke_runs(cfg, op, s["command"], True, timeout, f"{proc.name}@{op.name} base", out)
    base_t = {d: v[0] for d, v in base.items()}
    for d, v in base.items():
        if v[0] is None:
            raise InputError(f"procedure '{proc.name}' at '{op.name}': base {v[1]}")
    for adj in s["adjust"]:
        key = _VALVE_KEY[adj]
        c0 = cfg.p(key)
        other = "closing" if adj == "opening" else "opening"
        if c0 <= 0.0:
            reason = f"{key} = 0 (no throttle in the circuit): there is nothing to adjust"
            out.add("cross_adjustment_change", Sample(None, f"adjust {adj}", reason))
            out.add("adjusted_time_change", Sample(None, f"adjust {adj}", reason))
            continue
        mod_cfg = cfg.replace(params={key: c0 * s["factor"]})
        mod = _stroke_runs(mod_cfg, op, s["command"], True, timeout, f"{proc.name}@{op.name} {adj} x{s['factor']:g}", out)
        mod_t = {d: v[0] for d, v in mod.items()}
        if any(v is None for v in mod_t.values()):
            why = "; ".join(v[1] for v in mod.values() if v[0] is None)
            out.add("cross_adjustment_change", Sample(None, f"adjust {adj}", why))
            out.add("adjusted_time_change", Sample(None, f"adjust {adj}", why))
            continue
        cross, own = M.independent_adjustment(base_t, mod_t, adj)
        detail = {"base": base_t, "modified": mod_t, "factor": s["factor"], "parameter": key}
        out.add("cross_adjustment_change", Sample(cross, f"{other} time when {adj} valve x{s['factor']:g}", detail=detail))
        out.add("adjusted_time_change", Sample(own, f"{adj} time when {adj} valve x{s['factor']:g}", detail=detail))
        out.notes.append(
            f"{key} x{s['factor']:g}: opening {base_t['opening']:.2f} -> {mod_t['opening']:.2f} s, "
            f"closing {base_t['closing']:.2f} -> {mod_t['closing']:.2f} s"
        )


# ---- hold
def _run_hold(cfg, proc, op, requests, out):
    s = proc.settings
    x0 = _x0(cfg, op, proc)
    dur, settle = s["duration"].value, s["settle"].value
    if settle >= dur:
        raise InputError(f"procedure '{proc.name}': settle ({settle:g} s) must be shorter than duration ({dur:g} s)")
    from .profiles import Profile

    start = max(0.0, x0 - s["approach"].resolve(_stroke(cfg)))
    df = _simulate(cfg, dur, start, reference=Profile.constant(x0), load=_load(cfg, op), flow_control=op.flow_control)
    label = f"{proc.name}@{op.name}"
    if start != x0:
        out.notes.append(f"approached from {start*1e3:.1f} mm to {x0*1e3:.1f} mm")
    out.traces.append(downsample(df, label))
    tt, x, r, u = M.frame_columns(df, "time", "position", "reference", "valve_command")
    h = M.hold(tt, x, r, settle, dur + 1.0)
    lab = f"window {settle:g}-{dur:g} s"
    for k in ("steady_state_error", "max_positioning_error", "drift", "limit_cycle_amplitude"):
        out.add(k, Sample(getattr(h, k), lab))
    out.marks.append({"trace": label, "type": "hold_window", "value": [settle, dur]})
    _speed_samples(out, requests, tt, x, label, settle)
    _saturation_sample(cfg, out, tt, u, label, settle)


# ---- dead band
def _run_dead_band(cfg, proc, op, requests, out):
    from .profiles import Profile

    s = proc.settings
    L = _stroke(cfg)
    x0 = _x0(cfg, op, proc)
    a = s["amplitude"].resolve(L)
    rate = s["rate"].value
    lead = s["lead"].value
    if x0 - a < 0 or x0 + a > L:
        raise InputError(f"procedure '{proc.name}' at '{op.name}': {x0*1e3:.1f} +/- {a*1e3:.1f} mm leaves the stroke")
    if rate <= 0:
        raise InputError(f"procedure '{proc.name}': rate must be > 0")
    leg = a / rate
    # x0 -> x0+a -> x0-a -> x0+a -> x0 : the middle two legs give both branches from a reversal
    times = np.array([0.0, lead, lead + leg, lead + 3 * leg, lead + 5 * leg, lead + 6 * leg])
    values = np.array([x0, x0, x0 + a, x0 - a, x0 + a, x0])
    df = _simulate(cfg, times[-1] + 1.0, x0, reference=Profile(times, values), load=_load(cfg, op), flow_control=op.flow_control)
    label = f"{proc.name}@{op.name}"
    out.traces.append(downsample(df, label))
    tt, x, r, u = M.frame_columns(df, "time", "position", "reference", "valve_command")
    db = M.dead_band(tt, x, r)
    out.add("dead_band", Sample(db.width, f"median over {db.levels} levels", detail={"max": db.width_max}))
    _speed_samples(out, requests, tt, x, label)
    _saturation_sample(cfg, out, tt, u, label)


_RUNNERS = {
    "steps": _run_steps,
    "sine": _run_sine,
    "full_stroke": _run_full_stroke,
    "independent_adjustment": _run_independent,
    "hold": _run_hold,
    "dead_band": _run_dead_band,
}
