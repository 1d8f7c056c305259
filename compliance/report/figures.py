"""Report figures of procedure runs: reference and position, error, valve command, pressures.

Each function takes the plain-JSON trace and marks of the results dict (SI units: s, m, V,
Pa abs) and returns an inline SVG fragment (:func:`compliance.report.svg.to_svg`). Titles and
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


def _arr(trace: dict, key: str):
    """Trace column as a float array, or None when absent or all non-finite."""
    v = trace.get(key)
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
    return [m for m in marks if m.get("trace") == label]


def _shade(ax, t0, t1, color, alpha=0.12, label=None):
    ax.axvspan(t0, t1, color=color, alpha=alpha, lw=0, label=label)


@styled
def trace_figure(trace: dict, marks: list, kind: str, prefix: str, *, tolerance=None, valve=None) -> str:
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
        ``saturation_voltage`` and ``dead_zone`` (pair, [V]) to draw on the command panel.
    """
    label = trace.get("label")
    mk = _marks_of(marks, label) if label is not None else []
    t = _arr(trace, "time")
    fig, axes = new_figure("trace", 4, 1, sharex=True, gridspec_kw={"height_ratios": [1.5, 1.0, 1.0, 1.0], "hspace": 0.12})
    ax_x, ax_e, ax_u, ax_p = axes
    if t is None:
        for ax in axes:
            message_axes(ax, "no samples")
        return to_svg(fig, prefix)
    x, r = _arr(trace, "position"), _arr(trace, "reference")
    closed_loop = kind not in OPEN_LOOP_KINDS and r is not None
    t_span = (float(t[0]), float(t[-1]))

    # ---- panel 1: reference and position [mm]
    for m in mk:
        if m["type"] in ("final_window", "tracking_window", "hold_window"):
            for ax in (ax_x, ax_e):
                _shade(ax, m["value"][0], m["value"][1], COLORS["window"], 0.10)
    if closed_loop:
        _plot(ax_x, t, r * MM, color=COLORS["reference"], lw=0.9, ls=(0, (4, 2)), label="set-point")
    if x is not None:
        _plot(ax_x, t, x * MM, color=COLORS["position"], lw=1.1, label="position")
    _position_marks(ax_x, mk)
    ax_x.set_ylabel("position [mm]")
    _legend(ax_x, top=True)

    # ---- panel 2: error with the tolerance band [mm] (closed loop) or speed [mm/s]
    if closed_loop and x is not None:
        e = (r - x) * MM
        if tolerance is not None and math.isfinite(tolerance):
            ax_e.axhspan(-tolerance * MM, tolerance * MM, color=COLORS["band"], alpha=0.12, lw=0,
                         label=f"tolerance \u00b1{tolerance * MM:.3g} mm")
            for s in (-1, 1):
                ax_e.axhline(s * tolerance * MM, color=COLORS["band"], lw=0.6)
        _plot(ax_e, t, e, color=COLORS["error"], lw=0.9, label="error = set-point \u2212 position")
        lim = np.nanpercentile(np.abs(e), 99.5) if np.isfinite(e).any() else 1.0
        top = max(lim, 2.5 * tolerance * MM if tolerance else 0.0, 0.05) * 1.15
        ax_e.set_ylim(-top, top)  # large transients are clipped: the band is what is judged
        ax_e.set_ylabel("error [mm]")
        _legend(ax_e)
    elif x is not None:
        v = np.gradient(x, t) * MM if t.size > 2 else np.zeros_like(x)
        _plot(ax_e, t, v, color=COLORS["error"], lw=0.9, label="speed")
        ax_e.set_ylabel("speed [mm/s]")
        _legend(ax_e)
    else:
        message_axes(ax_e, "position not recorded")

    # ---- panel 3: valve command [V]
    u = _arr(trace, "valve_command")
    if u is not None:
        _plot(ax_u, t, u, color=COLORS["command"], lw=0.9, label="valve command")
        if valve:
            sat = valve.get("saturation_voltage")
            if sat:
                for s in (-1, 1):
                    ax_u.axhline(s * sat, color=COLORS["limit"], lw=0.6, ls=(0, (3, 2)))
                ax_u.plot([], [], color=COLORS["limit"], lw=0.6, ls=(0, (3, 2)), label=f"full opening \u00b1{sat:.3g} V")
            dz = valve.get("dead_zone")
            if dz:
                ax_u.axhspan(-dz[1], dz[0], color="#999999", alpha=0.15, lw=0, label="valve dead zone")
        ax_u.set_ylabel("command [V]")
        _legend(ax_u)
    else:
        message_axes(ax_u, "valve command not recorded")

    # ---- panel 4: chamber pressures [bar abs]
    pa, pb, ps = _arr(trace, "pressure_a"), _arr(trace, "pressure_b"), _arr(trace, "supply_pressure")
    if pa is not None or pb is not None:
        if pa is not None:
            _plot(ax_p, t, pa * BAR, color=COLORS["pressure_a"], lw=0.9, label="chamber A")
        if pb is not None:
            _plot(ax_p, t, pb * BAR, color=COLORS["pressure_b"], lw=0.9, label="chamber B")
        if ps is not None:
            _plot(ax_p, t, ps * BAR, color=COLORS["supply"], lw=0.7, ls=":", label="supply")
        ax_p.set_ylabel("pressure [bar abs]")
        _legend(ax_p)
    else:
        message_axes(ax_p, "chamber pressures not recorded")
    ax_p.set_xlabel("time [s]")
    ax_p.set_xlim(*t_span)
    for ax in axes:
        ax.yaxis.set_label_coords(-0.075, 0.5)  # aligned labels whatever the tick widths
    fig.subplots_adjust(left=0.1, right=0.985, top=0.955, bottom=0.075)
    return to_svg(fig, prefix)


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
        typ, v = m.get("type"), m.get("value")
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
            step_marks = [q for q in mk if q.get("step") == m.get("step")]
            t0 = next((q["value"][0] for q in step_marks if q["type"] == "motion_start"), None)
            t1 = next((q["value"][1] for q in step_marks if q["type"] == "final_window"), None)
            if t0 is not None and t1 is not None:
                ax.fill_between([t0, t1], v[0] * MM, v[1] * MM, color=COLORS["band"], alpha=0.18, lw=0,
                                label=once("settling band"))
        elif typ == "stroke_points":
            for (tp, xp), name in zip(v, ("25 %", "75 %")):
                ax.plot(tp, xp * MM, "o", ms=4, mfc="white", mec=COLORS["mark"], mew=1.2, label=once("25 % / 75 % of stroke"))


@styled
def waveform_figure(series: list, prefix: str, *, ylabel: str, windows=(), xlabel="time [s]") -> str:
    """One panel of overlaid signals with shaded windows (model validation).

    Parameters
    ----------
    series : list of (label, time [s], values, role)
        ``role`` in ``recorded``/``before``/``after`` picks the colour.
    windows : iterable of (t0, t1)
        Time windows to shade (located mismatches) [s].
    """
    fig, ax = new_figure("validation")
    for i, (t0, t1) in enumerate(windows):
        _shade(ax, t0, t1, COLORS["limit"], 0.12, "mismatch window" if i == 0 else None)
    for label, t, y, role in series:
        ax.plot(t, y, color=COLORS.get(role, None), lw=1.2 if role == "recorded" else 1.0,
                ls="-" if role != "before" else (0, (4, 2)), label=label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(loc="best", ncol=2)
    fig.subplots_adjust(left=0.1, right=0.985, top=0.97, bottom=0.12)
    return to_svg(fig, prefix)
