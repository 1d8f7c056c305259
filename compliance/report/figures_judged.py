"""Figures drawn for one judged metric: both full strokes of a stroke-time page, the dead-band loop.

The general run figure (``figures.trace_figure``) plots signals against time; these two plot
what the requirement judges: the opening and the closing stroke side by side with their 25 % and
75 % points, and the position against the set-point of the dead-band run (the hysteresis loop)
with the width the limit allows.
"""

from __future__ import annotations

import numpy as np

from compliance.report.figures import MM, _arr, _legend, decimate
from compliance.report.svg import COLORS, message_axes, new_figure, styled, to_svg


@styled
def stroke_pair_figure(traces: list, marks: list, prefix: str) -> str:
    """Position and speed of an opening and a closing stroke, each from its own start, 25/75 % points marked.

    Parameters
    ----------
    traces : list of dict
        Two stroke traces (``label`` ending in ``opening`` / ``closing``; ``time`` [s], ``position`` [m]).
    marks : list of dict
        The run's marks; ``stroke_points`` of each trace ([[t25, x25], [t75, x75]]) are drawn.
    """
    fig, (ax_x, ax_v) = new_figure("trace_compact", 2, 1, sharex=True, gridspec_kw={"height_ratios": [1.4, 1.0], "hspace": 0.12})
    colours = {"opening": COLORS["position"], "closing": COLORS["error"]}
    drawn = 0
    for tr in traces:
        t, x = _arr(tr, "time"), _arr(tr, "position")
        if t is None or x is None:
            continue
        direction = tr.direction
        c = colours.get(direction, COLORS["reference"])
        ax_x.plot(*decimate(t - t[0], x * MM), color=c, lw=1.1, label=f"{direction} stroke")
        v = np.gradient(x, t) * MM if t.size > 2 else np.zeros_like(x)
        ax_v.plot(*decimate(t - t[0], v), color=c, lw=0.9)
        for m in marks:
            if m.trace == tr.label and m.type == "stroke_points":
                for tp, xp in m.value:
                    ax_x.plot(tp - t[0], xp * MM, "o", ms=4, mfc="white", mec=COLORS["mark"], mew=1.2)
        drawn += 1
    if not drawn:
        message_axes(ax_x, "no stroke recorded")
        message_axes(ax_v, "")
        return to_svg(fig, prefix)
    ax_x.plot([], [], "o", ms=4, mfc="white", mec=COLORS["mark"], mew=1.2, label="25 % / 75 % of stroke")
    ax_x.set_ylabel("position\n[mm]", linespacing=1.0)
    ax_v.set_ylabel("speed\n[mm/s]", linespacing=1.0)
    ax_v.set_xlabel("time from the start of each stroke [s]")
    _legend(ax_x, top=True)
    for ax in (ax_x, ax_v):
        ax.yaxis.set_label_coords(-0.075, 0.5)
    fig.subplots_adjust(left=0.1, right=0.985, top=0.92, bottom=0.13)
    return to_svg(fig, prefix)


@styled
def dead_band_figure(trace: dict, prefix: str, limit: float | None = None) -> str:
    """Position against set-point of a dead-band run (the hysteresis loop), with the width the limit allows.

    Parameters
    ----------
    trace : dict
        ``reference`` and ``position`` [m].
    limit : float, optional
        Largest loop width allowed [m]: drawn as two lines ``position = set-point -/+ limit/2``
        about the loop's centre line (a loop between them is no wider than the limit).
    """
    fig, ax = new_figure("map")
    r, x = _arr(trace, "reference"), _arr(trace, "position")
    if r is None or x is None:
        message_axes(ax, "set-point or position not recorded")
        return to_svg(fig, prefix)
    ok = np.isfinite(r) & np.isfinite(x)
    r, x = r[ok] * MM, x[ok] * MM
    ax.plot(*decimate(r, x), color=COLORS["position"], lw=0.9, label="position against set-point")
    if limit is not None and np.isfinite(limit):
        offset = float(np.median(x - r))  # the loop's centre line: position = set-point + offset
        lo, hi = float(np.min(r)), float(np.max(r))
        for sgn in (-1, 1):
            ax.plot([lo, hi], [lo + offset + sgn * limit * MM / 2, hi + offset + sgn * limit * MM / 2],
                    color=COLORS["limit"], lw=0.8, ls=(0, (4, 2)),
                    label=f"limit: loop width {limit * MM:.3g} mm" if sgn < 0 else None)
    ax.set_xlabel("set-point [mm]")
    ax.set_ylabel("position [mm]")
    _legend(ax, top=True)
    fig.subplots_adjust(left=0.1, right=0.985, top=0.88, bottom=0.15)
    return to_svg(fig, prefix)
