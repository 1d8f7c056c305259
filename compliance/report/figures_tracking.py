"""Figures of path tracking: a report figure for ``path3d`` traces and the docs/plant-b.md figures.

:func:`path_figure` follows the report's conventions (``compliance.report.svg``: fixed width,
Okabe-Ito palette, inline SVG): left the path in the xy plane (reference path and measured tool
point, 1:1), right the per-axis errors and the 3-D path deviation against time.
"""

from __future__ import annotations

import numpy as np

MM = 1e3  # [m] -> [mm]
_AXIS_COLORS = {"x": "#0072B2", "y": "#E69F00", "z": "#009E73"}


def _arr(trace, key):
    v = trace.signal(key)
    return None if v is None else np.asarray(v, float)


def draw_path(ax_xy, ax_err, trace, *, label="measured", color="#0072B2", errors=True) -> None:
    """Draw one ``path3d`` trace (a ``compliance.results.runs.Trace``) on an xy axes (1:1) and an error-against-time axes."""
    px, py = _arr(trace, "path_x"), _arr(trace, "path_y")
    if px is not None:
        ax_xy.plot(px * MM, py * MM, color="#555555", lw=0.8, label="reference path")
    ax_xy.plot(_arr(trace, "position_x") * MM, _arr(trace, "position_y") * MM, color=color, lw=0.9, label=label)
    ax_xy.set_aspect("equal", adjustable="datalim")
    ax_xy.set_xlabel("x [mm]")
    ax_xy.set_ylabel("y [mm]")
    t = _arr(trace, "time")
    if errors:
        for a in ("x", "y", "z"):
            e = _arr(trace, f"error_{a}")
            if e is not None and np.any(e != 0):
                ax_err.plot(t, e * MM, color=_AXIS_COLORS[a], lw=0.8, label=f"error {a}")
    ax_err.plot(t, _arr(trace, "path_deviation") * MM, color="#D55E00" if errors else color, lw=1.0,
                label="path deviation" if errors else label)
    ax_err.set_xlabel("time [s]")
    ax_err.set_ylabel("error [mm]")


def path_figure(trace: dict, prefix: str) -> str:
    """Inline SVG of a ``path3d`` trace for the HTML/PDF report.

    Parameters
    ----------
    trace : Trace
        A trace with ``kind == "path3d"`` (``tracking_procedures._path_trace``): time [s],
        reference/position/error per axis, path_x/y/z, path_deviation [m].
    prefix : str
        Unique id prefix of the SVG fragment.
    """
    from compliance.report.svg import new_figure, styled, to_svg

    @styled
    def build():
        fig, (ax_xy, ax_err) = new_figure("map", 1, 2, gridspec_kw={"width_ratios": [1, 1.6]})
        draw_path(ax_xy, ax_err, trace)
        ax_xy.legend(loc="upper left", fontsize=6)
        ax_err.legend(loc="upper right", ncol=2, fontsize=6)
        fig.tight_layout()
        return to_svg(fig, prefix)

    return build()
