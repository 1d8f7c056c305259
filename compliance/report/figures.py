"""Report figures of procedure runs: reference and position, error, valve command, pressures.

Each function takes a run's trace and marks as the check's result holds them
(``compliance.results.runs.Trace`` and ``Mark``; SI units: s, m, V, Pa abs) and returns an inline SVG fragment (:func:`compliance.report.svg.to_svg`). Titles and
captions are written by the HTML template (escaped), not inside the figures; the only text a
figure draws is axis labels, legends and short mark labels of our own.
"""

from __future__ import annotations

import math

import numpy as np

from compliance.report.svg import COLORS, message_axes, new_figure, styled, to_svg

MM = 1e3  # [m] -> [mm] for display
BAR = 1e-5  # [Pa] -> [bar] for display
OPEN_LOOP_KINDS = ("full_stroke", "independent_adjustment")


def _arr(trace, key: str):
    """Trace signal as a float array, or None when absent or all non-finite."""
    v = trace.signal(key)
    if v is None:
        return None
    a = np.asarray([np.nan if x is None else x for x in v], dtype=float)
    return a if a.size and np.isfinite(a).any() else None


def decimate(t, y, buckets=250):
    """Min/max decimation of one signal for plotting: at most ``3 * buckets`` points.

    Each bucket keeps its first, smallest and largest sample, so peaks, steps and the noise
    envelope survive; a 170 mm wide plot resolves ~0.2 mm, far coarser than 250 buckets.

    Parameters
    ----------
    t, y : array
        Time [s] and signal (any unit); non-finite values are kept where they fall.

    Returns
    -------
    (t, y) arrays, in time order.
    """
    n = t.size
    if n <= 3 * buckets:
        return t, y
    k = -(-n // buckets)  # samples per bucket (ceil)
    pad = k * buckets - n
    yy = np.where(np.isfinite(y), y, np.nan)
    yp = np.concatenate([yy, np.full(pad, np.nan)]).reshape(buckets, k)
    base = np.arange(buckets) * k
    with np.errstate(all="ignore"):
        filled = np.where(np.isnan(yp), np.nanmean(yp) if np.isfinite(yp).any() else 0.0, yp)
    idx = np.concatenate([base, base + np.argmax(filled, axis=1), base + np.argmin(filled, axis=1), [n - 1]])
    idx = np.unique(idx[idx < n])
    return t[idx], y[idx]


def _plot(ax, t, y, **kw):
    """``ax.plot`` of a decimated signal."""
    td, yd = decimate(t, y)
    return ax.plot(td, yd, **kw)


def _marks_of(marks, label):
    return [m for m in marks if m.trace == label]


def _shade(ax, t0, t1, color, alpha=0.12, label=None):
    ax.axvspan(t0, t1, color=color, alpha=alpha, lw=0, label=label)


@styled
def trace_figure(trace: dict, marks: list, kind: str, prefix: str, *, tolerance=None, valve=None, speed_limit=None,
                 compact: bool = False, tau_window=None) -> str:
    """Four stacked panels of one run, with the metrics measured on it marked.

    Parameters
    ----------
    trace : dict
        ``time`` [s], ``position``/``reference`` [m], ``valve_command`` [V],
        ``pressure_a``/``pressure_b`` [Pa abs] lists (any but time may be missing).
    marks : list of dict
        Marks of this run (``type`` and ``value`` as written by ``compliance.procedures.registry``):
        ``tau_632`` [t, x], ``settled`` [t, x], ``band`` [lo, hi], ``final_window`` [t0, t1],
        ``motion_start`` [t, x], ``tracking_window``/``hold_window`` [t0, t1],
        ``stroke_points`` [[t, x], [t, x]].
    kind : str
        Procedure kind; full-stroke kinds are open loop (no set-point: the second panel shows
        the speed instead of the error).
    prefix : str
        SVG id prefix, unique in the document.
    tolerance : float, optional
        Position tolerance to draw as the error band [m] (the positioning requirement).
    valve : dict, optional
        ``saturation_voltage``, ``centre_voltage`` (the valve null) and ``dead_zone`` (pair, [V])
        to draw on the command panel, around the null.
    speed_limit : float, optional
        Speed limit [m/s] of a speed requirement: the second panel then shows the speed with
        the limit drawn (whatever the procedure).
    compact : bool or "short"
        Three panels (no chamber pressures) in a shorter figure: the worst case on a requirement
        page ("short": shorter still, for a page shared by several requirements).
    tau_window : (float, float), optional
        Time-constant limits [s]: each step's window of allowed 63.2 % instants (from the end of
        its dead time) is shaded on the position panel, beside the 63.2 % point measured.
    """
    mk = _marks_of(marks, trace.label)
    t = _arr(trace, "time")
    if compact:
        fig, axes = new_figure("trace_short" if compact == "short" else "trace_compact", 3, 1, sharex=True, gridspec_kw={"height_ratios": [1.5, 1.0, 1.0], "hspace": 0.12})
        (ax_x, ax_e, ax_u), ax_p = axes, None
    else:
        fig, axes = new_figure("trace", 4, 1, sharex=True, gridspec_kw={"height_ratios": [1.5, 1.0, 1.0, 1.0], "hspace": 0.12})
        ax_x, ax_e, ax_u, ax_p = axes
    if t is None:
        for ax in axes:
            message_axes(ax, "no samples")
        return to_svg(fig, prefix)
    x, r = _arr(trace, "position"), _arr(trace, "reference")
    closed_loop = kind not in OPEN_LOOP_KINDS and r is not None and speed_limit is None
    t_span = (float(t[0]), float(t[-1]))

    _position_panel(ax_x, ax_e, t, x, r, mk, closed_loop)
    if tau_window is not None:
        _tau_window(ax_x, mk, tau_window)
    _error_or_speed_panel(ax_e, t, x, r, closed_loop, tolerance, speed_limit)
    _command_panel(ax_u, t, _arr(trace, "valve_command"), valve)
    last = ax_u if ax_p is None else ax_p
    if ax_p is not None:
        _pressure_panel(ax_p, t, trace)
    last.set_xlabel("time [s]")
    last.set_xlim(*t_span)
    for ax in axes:
        if compact:  # short panels: the unit on a second line, so stacked labels never run into each other
            ax.set_ylabel(ax.get_ylabel().replace(" [", "\n["), linespacing=1.0)
        ax.yaxis.set_label_coords(-0.075, 0.5)  # aligned labels whatever the tick widths
    fig.subplots_adjust(left=0.1, right=0.985, top=0.94 if compact else 0.955, bottom=0.1 if compact else 0.075)
    return to_svg(fig, prefix)


def _position_panel(ax_x, ax_e, t, x, r, mk, closed_loop):
    """Panel 1: set-point and position [mm], the judged windows shaded on panels 1 and 2."""
    for m in mk:
        if m.type in ("final_window", "tracking_window", "hold_window"):
            for ax in (ax_x, ax_e):
                _shade(ax, m.value[0], m.value[1], COLORS["window"], 0.10)
    if closed_loop:
        _plot(ax_x, t, r * MM, color=COLORS["reference"], lw=0.9, ls=(0, (4, 2)), label="set-point")
    if x is not None:
        _plot(ax_x, t, x * MM, color=COLORS["position"], lw=1.1, label="position")
    _position_marks(ax_x, mk)
    ax_x.set_ylabel("position [mm]")
    _legend(ax_x, top=True)


def _error_or_speed_panel(ax_e, t, x, r, closed_loop, tolerance, speed_limit):
    """Panel 2: error with the tolerance band [mm] (closed loop), else the speed [mm/s] with its limit."""
    if closed_loop and x is not None:
        e = (r - x) * MM
        if tolerance is not None and math.isfinite(tolerance):
            ax_e.axhspan(-tolerance * MM, tolerance * MM, color=COLORS["band"], alpha=0.12, lw=0,
                         label=f"tolerance \u00b1{tolerance * MM:.3g} mm")
            for s in (-1, 1):
                ax_e.axhline(s * tolerance * MM, color=COLORS["band"], lw=0.6)
        _plot(ax_e, t, e, color=COLORS["error"], lw=0.9, label="error = set-point \u2212 position")
        lim = np.nanpercentile(np.abs(e), 99.5) if np.isfinite(e).any() else 1.0
        # scaled to the band when one is judged (step transients run off the panel: the settled error is what counts)
        top = (2.5 * tolerance * MM) if tolerance else max(lim, 0.05) * 1.15
        ax_e.set_ylim(-top, top)
        ax_e.set_ylabel("error [mm]")
        _legend(ax_e)
    elif x is not None:
        v = np.gradient(x, t) * MM if t.size > 2 else np.zeros_like(x)
        _plot(ax_e, t, v, color=COLORS["error"], lw=0.9, label="speed")
        if speed_limit is not None and math.isfinite(speed_limit):
            for sgn in (-1, 1):
                ax_e.axhline(sgn * speed_limit * MM, color=COLORS["limit"], lw=0.9, ls=(0, (4, 2)))
            ax_e.plot([], [], color=COLORS["limit"], lw=0.9, ls=(0, (4, 2)), label=f"limit \u00b1{speed_limit * MM:.3g} mm/s")
        ax_e.set_ylabel("speed [mm/s]")
        _legend(ax_e)
    else:
        message_axes(ax_e, "position not recorded")


def _tau_window(ax, mk, window) -> None:
    """Shade, per step, where its 63.2 % instant must fall: [motion start + lo, motion start + hi]."""
    lo, hi = window
    first = True
    for m in mk:
        if m.type != "motion_start" or m.value is None:
            continue
        t0 = m.value[0]
        ax.axvspan(t0 + lo, t0 + hi, color=COLORS["band"], alpha=0.16, lw=0,
                   label=f"\u03c4 limit {lo:g}\u2013{hi:g} s after motion start" if first else None)
        first = False
    if not first:
        _legend(ax, top=True)


def _command_panel(ax_u, t, u, valve):
    """Panel 3: valve command [V] with the full-opening lines, the null and the dead zone about it."""
    if u is None:
        message_axes(ax_u, "valve command not recorded")
        return
    _plot(ax_u, t, u, color=COLORS["command"], lw=0.9, label="valve command")
    if valve:
        c0 = valve.get("centre_voltage") or 0.0  # the valve null: 0 V for a +/-10 V valve, 5 V for a 0-10 V one
        sat = valve.get("saturation_voltage")
        if sat:
            for s in (-1, 1):
                ax_u.axhline(c0 + s * sat, color=COLORS["limit"], lw=0.6, ls=(0, (3, 2)))
            where = f"{c0:.3g} \u00b1 {sat:.3g} V" if c0 else f"\u00b1{sat:.3g} V"
            ax_u.plot([], [], color=COLORS["limit"], lw=0.6, ls=(0, (3, 2)), label=f"full opening {where}")
        if c0:
            ax_u.axhline(c0, color="#999999", lw=0.6, ls=(0, (1, 1)), zorder=0.5, label=f"valve null {c0:.3g} V")
        dz = valve.get("dead_zone")
        if dz:
            ax_u.axhspan(c0 - dz[1], c0 + dz[0], color="#999999", alpha=0.15, lw=0, label="valve dead zone")
    ax_u.set_ylabel("command [V]")
    _legend(ax_u)


def _pressure_panel(ax_p, t, trace):
    """Panel 4: chamber pressures and supply [bar abs]."""
    pa, pb, ps = _arr(trace, "pressure_a"), _arr(trace, "pressure_b"), _arr(trace, "supply_pressure")
    if pa is None and pb is None:
        message_axes(ax_p, "chamber pressures not recorded")
        return
    if pa is not None:
        _plot(ax_p, t, pa * BAR, color=COLORS["pressure_a"], lw=0.9, label="chamber A")
    if pb is not None:
        _plot(ax_p, t, pb * BAR, color=COLORS["pressure_b"], lw=0.9, label="chamber B")
    if ps is not None:
        _plot(ax_p, t, ps * BAR, color=COLORS["supply"], lw=0.7, ls=":", label="supply")
    ax_p.set_ylabel("pressure [bar abs]")
    _legend(ax_p)


def _legend(ax, top=False):
    """Small legend: above the axes in one row (top panel), else inside at the upper right."""
    if top:
        ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=7, borderaxespad=0.2, handlelength=1.8,
                  columnspacing=1.2)
    else:
        ax.legend(loc="best", ncol=3, frameon=True, framealpha=0.85, edgecolor="none", handlelength=1.8,
                  columnspacing=1.2, borderpad=0.3)


def _position_marks(ax, mk) -> None:
    """Draw the measured points on the position panel (one legend entry per type)."""
    seen = set()

    def once(name):
        if name in seen:
            return None
        seen.add(name)
        return name

    for m in mk:
        typ, v = m.type, m.value
        if v is None:
            continue
        if typ == "tau_632":
            ax.plot(v[0], v[1] * MM, "o", ms=4, mfc="white", mec=COLORS["mark"], mew=1.2, label=once("63.2 % point"))
        elif typ == "settled":
            ax.axvline(v[0], color=COLORS["band"], lw=0.7, ls=(0, (2, 2)))
            ax.plot(v[0], v[1] * MM, "D", ms=3.5, color=COLORS["band"], label=once("settling instant"))
        elif typ == "motion_start":
            ax.plot(v[0], v[1] * MM, "^", ms=3.5, color=COLORS["error"], label=once("motion start"))
        elif typ == "band":
            step_marks = [q for q in mk if q.step == m.step]
            t0 = next((q.value[0] for q in step_marks if q.type == "motion_start"), None)
            t1 = next((q.value[1] for q in step_marks if q.type == "final_window"), None)
            if t0 is not None and t1 is not None:
                ax.fill_between([t0, t1], v[0] * MM, v[1] * MM, color=COLORS["band"], alpha=0.18, lw=0,
                                label=once("settling band"))
        elif typ == "stroke_points":
            for (tp, xp), name in zip(v, ("25 %", "75 %")):
                ax.plot(tp, xp * MM, "o", ms=4, mfc="white", mec=COLORS["mark"], mew=1.2, label=once("25 % / 75 % of stroke"))


@styled
def waveform_figure(series: list, prefix: str, *, ylabel: str, windows=(), xlabel="time [s]", smooth: bool = False) -> str:
    """One panel of overlaid signals with shaded windows (model validation).

    Parameters
    ----------
    series : list of (label, time [s], values, role)
        ``role`` in ``recorded``/``before``/``after`` picks the colour. The recording is drawn
        last and on top (a fitted "after" line that matches it must not hide it).
    windows : iterable of (t0, t1)
        Time windows to shade (located mismatches) [s].
    smooth : bool
        Noisy signal (valve command): each series is drawn as a 50 ms moving mean over a faint raw
        trace, so the command stays readable instead of a band of noise.
    """
    fig, ax = new_figure("validation")
    for i, (t0, t1) in enumerate(windows):
        _shade(ax, t0, t1, COLORS["limit"], 0.10, "mismatch window" if i == 0 else None)
    order = sorted(series, key=lambda s: s[3] == "recorded")  # the recording last: on top
    for label, t, y, role in order:
        t, y = np.asarray(t, float), np.asarray(y, float)
        style = {"recorded": dict(color="#111111", lw=1.3, zorder=4),
                 "before": dict(color=COLORS.get("before"), lw=1.0, ls=(0, (4, 2)), zorder=2),
                 "after": dict(color=COLORS.get("after"), lw=1.1, alpha=0.8, zorder=3)}.get(role, dict(lw=1.0))
        if smooth and t.size > 10:
            dt = np.median(np.diff(t)) if t.size > 1 else 0.0
            k = max(1, int(round(0.05 / dt))) if dt > 0 else 1
            if k > 1:
                ax.plot(*decimate(t, y), color=style.get("color"), lw=0.4, alpha=0.25, zorder=1)
                y = np.convolve(np.where(np.isfinite(y), y, 0.0), np.ones(k) / k, mode="same")
                label = f"{label} (50 ms mean)"
        ax.plot(*decimate(t, y), label=label, **style)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(loc="best", ncol=2)
    fig.subplots_adjust(left=0.1, right=0.985, top=0.97, bottom=0.12)
    return to_svg(fig, prefix)
