"""Performance metrics of position traces: ONE implementation for simulated and recorded runs.

Every function takes plain arrays (``time`` [s], ``position`` [m], ``reference`` [m],
``valve_command`` [V]) so the same code measures a simulation DataFrame and a bench recording
(use :func:`frame_columns` to pull the canonical columns out of a DataFrame). The definitions
are written out in ``docs/metrics.md``; python-control's ``step_info`` conventions are matched
for rise time (10-90 % of the actual change), settling time (last exit from a band about the
final value) and overshoot (per cent of the actual change).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError

# fraction of the commanded step that defines the time constant (1 - 1/e, first-order response)
TAU_FRACTION = 1.0 - math.exp(-1.0)
# default motion threshold for the dead time, fraction of the commanded step
DETECT_FRACTION = 0.01


@dataclass(frozen=True)
class MetricInfo:
    """Declaration of one metric: SI unit, display unit, which procedure kinds produce it."""

    name: str
    si_unit: str  # "" = dimensionless fraction
    display_unit: str
    display_scale: float  # display value = SI value * display_scale
    kinds: tuple[str, ...]
    meaning: str
    options: tuple[str, ...] = ()


_SETTLE_OPTS = ("settling_band", "settling_band_abs", "final_window")

METRICS: dict[str, MetricInfo] = {
    m.name: m
    for m in (
        MetricInfo("dead_time", "s", "s", 1.0, ("steps",), "command step to first detectable motion", ("detect",)),
        MetricInfo(
            "time_constant", "s", "s", 1.0, ("steps",),
            "end of dead time to 63.2 % of the commanded step, steps out of the rate limit only", ("detect",),
        ),
        MetricInfo("rise_time", "s", "s", 1.0, ("steps",), "10 % to 90 % of the actual change", ("final_window",)),
        MetricInfo("settling_time", "s", "s", 1.0, ("steps",), "step to last exit from the settling band", _SETTLE_OPTS),
        MetricInfo("overshoot", "", "%", 100.0, ("steps",), "peak beyond the final value, per cent of the change", ("final_window",)),
        MetricInfo(
            "steady_state_error", "m", "mm", 1e3, ("steps", "hold"),
            "|reference - mean position| over the final window", ("final_window",),
        ),
        MetricInfo(
            "max_positioning_error", "m", "mm", 1e3, ("steps", "hold"),
            "max |reference - position| over the final (settled) windows", ("final_window",),
        ),
        MetricInfo("tracking_rms_error", "m", "mm", 1e3, ("sine",), "RMS of reference - position after the skip"),
        MetricInfo("tracking_max_error", "m", "mm", 1e3, ("sine",), "max |reference - position| after the skip"),
        MetricInfo("dead_band", "m", "mm", 1e3, ("dead_band",), "width of the position/reference hysteresis loop"),
        MetricInfo("opening_time", "s", "s", 1.0, ("full_stroke",), "2 x time from 25 % to 75 % of stroke, opening"),
        MetricInfo("closing_time", "s", "s", 1.0, ("full_stroke",), "2 x time from 75 % to 25 % of stroke, closing"),
        MetricInfo(
            "max_speed", "m/s", "mm/s", 1e3, ("steps", "sine", "full_stroke", "hold", "dead_band"),
            "max |dx/dt| over a centred 20 ms difference",
        ),
        MetricInfo(
            "max_opening_speed", "m/s", "mm/s", 1e3, ("steps", "sine", "full_stroke", "hold", "dead_band"),
            "max dx/dt (opening direction)",
        ),
        MetricInfo(
            "max_closing_speed", "m/s", "mm/s", 1e3, ("steps", "sine", "full_stroke", "hold", "dead_band"),
            "max -dx/dt (closing direction)",
        ),
        MetricInfo("limit_cycle_amplitude", "m", "mm", 1e3, ("hold",), "half peak-to-peak of the detrended position"),
        MetricInfo("drift", "m", "mm", 1e3, ("hold",), "|slope of a line fit| x window length"),
        MetricInfo(
            "saturation_fraction", "", "%", 100.0, ("steps", "sine", "hold", "dead_band"),
            "fraction of time |valve command| >= the valve's full-opening voltage",
        ),
        MetricInfo(
            "cross_adjustment_change", "", "%", 100.0, ("independent_adjustment",),
            "relative change of the other direction's full-stroke time when one flow-control valve is changed",
        ),
        MetricInfo(
            "adjusted_time_change", "", "%", 100.0, ("independent_adjustment",),
            "relative change of the adjusted direction's full-stroke time (shows the adjustment acts)",
        ),
    )
}

# options of the step metrics with defaults: name -> (SI unit, default text, meaning)
STEP_OPTION_DEFAULTS = {
    "settling_band": ("", "2 %", "half-width of the settling band, fraction of the actual change (step_info)"),
    "settling_band_abs": ("m", "0 mm", "lower bound on the band half-width (sensor resolution)"),
    "detect": ("m", "0 mm", "motion threshold for the dead time; 0 = max(1 % of the step, 5 x pre-step noise)"),
    "final_window": ("s", "0.5 s", "window before the next step over which the settled position is taken"),
}


def frame_columns(frame, *names, where="trace"):
    """Return the named columns of a DataFrame as float arrays.

    Parameters
    ----------
    frame : pandas.DataFrame
        A trace with canonical columns (``time`` [s], ``position`` [m], ...).
    names : str
        Column names.
    where : str
        Name of the trace (file) for the error message.

    Raises
    ------
    InputError
        If a column is missing.
    """
    out = []
    for n in names:
        if n not in frame.columns:
            raise InputError(f"{where}: column '{n}' is needed for this metric but is missing")
        out.append(np.asarray(frame[n].to_numpy(), dtype=float))
    return out


# --------------------------------------------------------------------------- helpers
def _crossing(time, signal, level, start, direction):
    """First time at or after index ``start`` where ``signal`` crosses ``level`` going ``direction`` (+1/-1).

    Linear interpolation between the two samples around the crossing [s]; None if never.
    """
    s = direction * (signal[start:] - level)
    idx = np.nonzero(s >= 0.0)[0]
    if idx.size == 0:
        return None
    i = start + int(idx[0])
    if i == start or i == 0:
        return float(time[i])
    s0 = direction * (signal[i - 1] - level)
    s1 = direction * (signal[i] - level)
    frac = 0.0 if s1 == s0 else -s0 / (s1 - s0)
    return float(time[i - 1] + frac * (time[i] - time[i - 1]))


def _window(time, t_from, t_to):
    """Index slice of samples with t_from <= t < t_to."""
    i0 = int(np.searchsorted(time, t_from, side="left"))
    i1 = int(np.searchsorted(time, t_to, side="left"))
    return slice(i0, max(i0, i1))


def speed(time, position, window=0.02):
    """Velocity from a centred difference over ``window`` [m/s].

    Parameters
    ----------
    time : array [s]
    position : array [m]
    window : float
        Span of the centred difference [s]; 20 ms suppresses sample-level noise while keeping
        the ~0.1 s dynamics of a gate servo.
    """
    time = np.asarray(time, float)
    position = np.asarray(position, float)
    n = time.size
    if n < 3:
        return np.zeros(n)
    dt = float(np.median(np.diff(time)))
    k = max(1, int(round(window / 2.0 / dt))) if dt > 0 else 1
    lo = np.clip(np.arange(n) - k, 0, n - 1)
    hi = np.clip(np.arange(n) + k, 0, n - 1)
    span = time[hi] - time[lo]
    span[span <= 0] = np.inf
    return (position[hi] - position[lo]) / span


def speed_extremes(time, position, t_from=-np.inf, t_to=np.inf, window=0.02):
    """Maximum speeds in a window: (max |v|, max opening v, max closing -v) [m/s]."""
    v = speed(time, position, window)
    sl = _window(np.asarray(time, float), t_from, t_to)
    seg = v[sl]
    if seg.size == 0:
        return 0.0, 0.0, 0.0
    return float(np.max(np.abs(seg))), float(max(0.0, np.max(seg))), float(max(0.0, -np.min(seg)))


def saturation_fraction(time, valve_command, threshold, t_from=-np.inf, t_to=np.inf):
    """Fraction of time the valve command is at or beyond ``threshold`` in magnitude [-].

    Parameters
    ----------
    time : array [s]
    valve_command : array [V]
    threshold : float
        Command magnitude at which the valve is fully open [V].
    """
    time = np.asarray(time, float)
    u = np.asarray(valve_command, float)
    sl = _window(time, t_from, t_to)
    t = time[sl]
    if t.size < 2:
        return 0.0
    dt = np.diff(t)
    sat = (np.abs(u[sl][:-1]) >= threshold * (1.0 - 1e-9)).astype(float)
    return float(np.sum(sat * dt) / np.sum(dt))


# --------------------------------------------------------------------------- steps
@dataclass(frozen=True)
class StepEvent:
    """A set-point step found in a reference trace."""

    t_step: float  # [s]
    t_end: float  # next step or end of trace [s]
    r_before: float  # [m]
    r_after: float  # [m]

    @property
    def size(self) -> float:
        """Signed step size [m]."""
        return self.r_after - self.r_before


def find_steps(time, reference, min_size=5e-5, merge=0.005):
    """Find the steps of a piecewise-constant reference.

    Parameters
    ----------
    time : array [s]
    reference : array [m]
    min_size : float
        Smallest jump between consecutive samples counted as a step [m]; 50 um is far above
        the per-sample change of any sinusoid or ramp the procedures use (8 mm at 0.05 Hz moves
        2.5 um per 1 ms sample).
    merge : float
        Jumps closer than this are one step spread over a few samples [s].
    """
    time = np.asarray(time, float)
    reference = np.asarray(reference, float)
    d = np.diff(reference)
    idx = np.nonzero(np.abs(d) > min_size)[0]
    groups = []
    for i in idx:
        if groups and time[i] - time[groups[-1][1]] <= merge:
            groups[-1][1] = i + 1
        else:
            groups.append([i, i + 1])
    # a step is dated by the first sample holding the new value (or the start of a spread step)
    starts = [float(time[i0 + 1]) if i1 == i0 + 1 else float(time[i0]) for i0, i1 in groups]
    events = []
    for g, (i0, i1) in enumerate(groups):
        t_end = starts[g + 1] if g + 1 < len(groups) else float(time[-1]) + (float(time[-1] - time[-2]) if time.size > 1 else 0.0)
        events.append(StepEvent(starts[g], t_end, float(reference[i0]), float(reference[i1])))
    return events


@dataclass(frozen=True)
class StepMetrics:
    """Metrics of one step response; ``None`` values come with a reason in ``reasons``."""

    event: StepEvent
    x_start: float  # position before the step [m]
    x_final: float  # settled position (mean over the final window) [m]
    dead_time: float | None  # [s]
    time_constant: float | None  # [s]
    rise_time: float | None  # [s]
    settling_time: float | None  # [s]
    overshoot: float | None  # fraction of the actual change [-]
    steady_state_error: float  # [m]
    max_positioning_error: float  # [m]
    max_speed: float  # [m/s]
    rate_limited: bool
    reasons: dict = field(default_factory=dict)
    marks: dict = field(default_factory=dict)


def step_response(
    time,
    position,
    event: StepEvent,
    *,
    valve_command=None,
    command_saturation=None,
    settling_band=0.02,
    settling_band_abs=0.0,
    detect=0.0,
    final_window=0.5,
    pre_window=0.05,
):
    """Measure one step response.

    Parameters
    ----------
    time, position : array [s], [m]
    event : StepEvent
        The step (from :func:`find_steps`); the response is analysed on [t_step, t_end).
    valve_command : array [V], optional
        With ``command_saturation`` [V]: a step whose command reaches the valve's full-opening
        voltage before the 63.2 % point is *rate limited*; its time constant is measured but
        flagged, since it then reflects flow saturation, not the linear time constant.
    settling_band : float
        Half-width of the settling band as a fraction of the actual change (step_info: 0.02).
    settling_band_abs : float
        Lower bound on the band half-width [m].
    detect : float
        Motion threshold for the dead time [m]; 0 = max(1 % of |step|, 5 x the standard
        deviation of the position over ``pre_window`` before the step). For a first-order
        lag the time constant then reads low by tau*ln(1/0.99) = 1 % (docs/metrics.md).
    final_window : float
        Settled position = mean over the last ``final_window`` before ``t_end`` [s].
    pre_window : float
        Window before the step over which the starting position is averaged [s].
    """
    time = np.asarray(time, float)
    position = np.asarray(position, float)
    reasons: dict = {}
    marks: dict = {}
    i_step = int(np.searchsorted(time, event.t_step, side="left"))
    i_end = int(np.searchsorted(time, event.t_end, side="left"))
    pre = _window(time, event.t_step - pre_window, event.t_step)
    if pre.stop > pre.start:
        x0 = float(np.mean(position[pre]))
        noise = float(np.std(position[pre]))
    else:
        x0 = float(position[max(0, i_step - 1)])
        noise = 0.0
    dr = event.size
    sgn = 1.0 if dr >= 0 else -1.0
    fw = _window(time, max(event.t_step, event.t_end - final_window), event.t_end)
    if fw.stop <= fw.start:
        fw = slice(max(i_step, i_end - 1), max(i_step + 1, i_end))
    xf = float(np.mean(position[fw]))
    sse = abs(event.r_after - xf)
    mpe = float(np.max(np.abs(event.r_after - position[fw])))
    marks["final_window"] = [float(time[fw.start]), float(time[fw.stop - 1])]
    marks["x_final"] = xf

    tt = time[i_step:i_end]
    xx = position[i_step:i_end]
    vmax = speed_extremes(time, position, event.t_step, event.t_end)[0]

    # dead time: first detectable motion in the commanded direction
    thr = detect if detect > 0 else max(DETECT_FRACTION * abs(dr), 5.0 * noise)
    t_move = _crossing(tt, sgn * (xx - x0), thr, 0, +1) if tt.size else None
    dead_time = None if t_move is None else t_move - event.t_step
    if t_move is None:
        reasons["dead_time"] = f"no motion beyond {thr * 1e3:.3g} mm after the step"
    else:
        marks["motion_start"] = [t_move, x0 + sgn * thr]

    # time constant: end of dead time to 63.2 % of the COMMANDED step
    target = x0 + TAU_FRACTION * dr
    t63 = _crossing(tt, xx, target, 0, int(sgn)) if tt.size else None
    rate_limited = False
    tau = None
    if t63 is None:
        reached = (np.max(sgn * (xx - x0)) / abs(dr)) if tt.size and dr != 0 else 0.0
        reasons["time_constant"] = (
            f"stalled: reached {100 * reached:.0f} % of the commanded step, never 63.2 % "
            f"(steady error inside the valve dead zone)"
        )
    elif t_move is None:
        reasons["time_constant"] = reasons["dead_time"]
    else:
        tau = t63 - t_move
        marks["tau_632"] = [t63, target]
        if valve_command is not None and command_saturation is not None:
            u = np.asarray(valve_command, float)[i_step : int(np.searchsorted(time, t63, side="right"))]
            if u.size and np.max(np.abs(u)) >= command_saturation * (1.0 - 1e-9):
                rate_limited = True
                reasons["time_constant"] = (
                    f"rate limited: valve command reached {np.max(np.abs(u)):.2f} V >= full opening "
                    f"{command_saturation:.2f} V before 63.2 %"
                )

    # step_info-style metrics on the actual change
    change = xf - x0
    rise = settle = over = None
    if abs(change) <= max(thr, 1e-12):
        for k in ("rise_time", "settling_time", "overshoot"):
            reasons[k] = "no net motion"
    else:
        s = 1.0 if change > 0 else -1.0
        t10 = _crossing(tt, xx, x0 + 0.1 * change, 0, int(s))
        t90 = _crossing(tt, xx, x0 + 0.9 * change, 0, int(s))
        if t10 is not None and t90 is not None:
            rise = t90 - t10
        else:
            reasons["rise_time"] = "did not pass 10 % and 90 % of the change"
        band = max(settling_band * abs(change), settling_band_abs)
        outside = np.nonzero(np.abs(xx - xf) >= band)[0]
        if outside.size == 0:
            settle = 0.0
        elif outside[-1] + 1 < tt.size:
            settle = float(tt[outside[-1] + 1] - event.t_step)
        else:
            reasons["settling_time"] = "not settled before the next step"
        if settle is not None:
            marks["settled"] = [event.t_step + settle, xf]
        marks["band"] = [xf - band, xf + band]
        peak = float(np.max(s * (xx - x0)))
        over = max(0.0, (peak - abs(change)) / abs(change))
    return StepMetrics(
        event, x0, xf, dead_time, tau, rise, settle, over, sse, mpe, vmax, rate_limited, reasons, marks
    )


# --------------------------------------------------------------------------- full stroke
def stroke_time(time, position, stroke, direction, lower=0.25, upper=0.75):
    """Full-stroke time from the straight part of a full-command trace [s].

    The time between ``lower`` and ``upper`` fractions of the stroke, extrapolated to the
    whole stroke: T = (t_upper - t_lower) / (upper - lower). This excludes the acceleration at
    the start and any end cushion (IEEE 125 expresses the speed settings as full-stroke times).

    Parameters
    ----------
    time, position : array [s], [m]
    stroke : float
        Servomotor stroke [m], position 0 = closed.
    direction : {"opening", "closing"}

    Returns
    -------
    tuple
        (time [s] or None, t_first [s], t_second [s], reason or None)
    """
    time = np.asarray(time, float)
    position = np.asarray(position, float)
    lo, hi = lower * stroke, upper * stroke
    if direction == "opening":
        t1 = _crossing(time, position, lo, 0, +1)
        t2 = None if t1 is None else _crossing(time, position, hi, int(np.searchsorted(time, t1)), +1)
    elif direction == "closing":
        t1 = _crossing(time, position, hi, 0, -1)
        t2 = None if t1 is None else _crossing(time, position, lo, int(np.searchsorted(time, t1)), -1)
    else:
        raise ValueError(direction)
    if t1 is None or t2 is None:
        reached = (np.max(position) if direction == "opening" else np.min(position)) / stroke
        return None, t1, t2, f"{direction}: did not pass {100*lower:.0f} % and {100*upper:.0f} % of stroke (reached {100*reached:.0f} %)"
    return (t2 - t1) / (upper - lower), t1, t2, None


def independent_adjustment(base, modified, adjusted):
    """Cross-effect of adjusting one flow-control valve.

    Parameters
    ----------
    base, modified : dict
        ``{"opening": T_open, "closing": T_close}`` full-stroke times [s] before and after.
    adjusted : {"opening", "closing"}
        Which valve was changed.

    Returns
    -------
    tuple
        (cross change, adjusted change), relative changes [-] of the other direction's time
        and of the adjusted direction's time.
    """
    other = "closing" if adjusted == "opening" else "opening"
    cross = abs(modified[other] - base[other]) / base[other]
    own = abs(modified[adjusted] - base[adjusted]) / base[adjusted]
    return cross, own


# --------------------------------------------------------------------------- sinusoid, hold
def tracking_errors(time, position, reference, t_from=-np.inf, t_to=np.inf):
    """RMS and maximum of reference - position over a window [m] (time-weighted RMS)."""
    time = np.asarray(time, float)
    sl = _window(time, t_from, t_to)
    e = np.asarray(reference, float)[sl] - np.asarray(position, float)[sl]
    if e.size == 0:
        raise InputError("tracking window holds no samples")
    return float(np.sqrt(np.mean(e * e))), float(np.max(np.abs(e)))


@dataclass(frozen=True)
class HoldMetrics:
    """Holding a position under load, over a window [m]."""

    steady_state_error: float
    max_positioning_error: float
    drift: float
    limit_cycle_amplitude: float


def hold(time, position, reference, t_from, t_to):
    """Metrics of a hold window: mean and max error, drift (line fit), limit-cycle amplitude.

    drift = |slope of the least-squares line| x window length [m];
    limit-cycle amplitude = half the peak-to-peak of position minus that line [m].
    """
    time = np.asarray(time, float)
    sl = _window(time, t_from, t_to)
    t = time[sl]
    x = np.asarray(position, float)[sl]
    r = np.asarray(reference, float)[sl]
    if t.size < 3:
        raise InputError("hold window holds fewer than 3 samples")
    e = r - x
    slope, icpt = np.polyfit(t - t[0], x, 1)
    resid = x - (icpt + slope * (t - t[0]))
    return HoldMetrics(
        float(abs(np.mean(e))),
        float(np.max(np.abs(e))),
        float(abs(slope) * (t[-1] - t[0])),
        float(0.5 * (np.max(resid) - np.min(resid))),
    )


# --------------------------------------------------------------------------- dead band
@dataclass(frozen=True)
class DeadBandMetrics:
    """Hysteresis loop of position against a slow triangular reference."""

    width: float  # median loop width [m]
    width_max: float  # [m]
    levels: int  # number of position levels compared


def dead_band(time, position, reference, levels=41, central=0.6):
    """Width of the position/reference hysteresis loop under a slow triangular reference [m].

    For position levels y in the central ``central`` fraction of the range both branches
    cover, r_up(y) is the reference when the position first reaches y while the reference
    rises and r_down(y) the reference when it first comes back down to y while the reference
    falls; the loop width is median over y of r_up(y) - r_down(y). For a pure backlash of
    width w (position = reference -/+ w/2) this is exactly w, the total band of command change
    without position change (IEC 60308 servomotor dead band).
    """
    time = np.asarray(time, float)
    x = np.asarray(position, float)
    r = np.asarray(reference, float)
    dr = np.diff(r)
    rising = np.concatenate([dr > 0, [False]])
    falling = np.concatenate([dr < 0, [False]])
    if not rising.any() or not falling.any():
        raise InputError("dead-band trace needs a reference that both rises and falls")
    lo = max(np.min(x[rising]), np.min(x[falling]))
    hi = min(np.max(x[rising]), np.max(x[falling]))
    if hi <= lo:
        raise InputError("dead-band trace: the rising and falling branches do not overlap in position")
    mid, half = 0.5 * (lo + hi), 0.5 * central * (hi - lo)
    widths = []
    # branch segments: contiguous runs of rising / falling reference
    def runs(mask):
        edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
        return list(zip(edges[0::2], edges[1::2]))

    up_runs, down_runs = runs(rising), runs(falling)
    # use branches that start from a reversal (an up run after a down run and vice versa), so
    # the first leg from rest does not count as a loop branch
    up_rev = [(a, b) for a, b in up_runs if a > down_runs[0][0]] or up_runs
    down_rev = [(a, b) for a, b in down_runs if a > up_runs[0][0]] or down_runs
    for y in np.linspace(mid - half, mid + half, levels):
        r_up = r_down = None
        for a, b in up_rev:
            k = np.nonzero(x[a:b] >= y)[0]
            if k.size and x[a] < y:
                r_up = r[a + k[0]]
                break
        for a, b in down_rev:
            k = np.nonzero(x[a:b] <= y)[0]
            if k.size and x[a] > y:
                r_down = r[a + k[0]]
                break
        if r_up is not None and r_down is not None:
            widths.append(r_up - r_down)
    if not widths:
        raise InputError("dead-band trace: no position level is crossed on both branches")
    w = np.asarray(widths)
    return DeadBandMetrics(float(np.median(w)), float(np.max(w)), int(w.size))
