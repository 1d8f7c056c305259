"""Report figures of the linear analysis: operating maps, Bode diagrams, pole maps.

Inputs are the records of a linear analysis (``compliance.results.linear``: an analysis, the
operating map), read from the documents ``compliance.linear.analysis`` and ``compliance.linear.maps``
write, in SI units (s, Hz, dB, deg, m, N).
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap

from compliance.presentation.quantities import fmt_quantity, to_display
from compliance.report.svg import COLORS, message_axes, new_figure, plain, styled, to_svg

# one colour per critical point (Okabe-Ito and two more): eight distinct points in plant A
PALETTE = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#999933", "#882255"]

MAP_QUANTITIES = {  # name -> (label, unit, display scale, requirement-window key or None)
    "time_constant": ("time constant", "ms", 1e3, "window"),
    "gain_margin_db": ("gain margin", "dB", 1.0, None),
    "phase_margin_deg": ("phase margin", "deg", 1.0, None),
    "bandwidth_hz": ("bandwidth", "Hz", 1.0, None),
    "damping_ratio": ("least damping ratio", "\u2013", 1.0, None),
}


def _load_labels(loads):
    return ["none" if ld is None else ld if isinstance(ld, str) else fmt_quantity(ld, "N", "kN", 1, signed=True)
            for ld in loads]


@styled
def map_figure(omap, name: str, prefix: str) -> str:
    """Heat map of one linear figure over stroke x load, the requirement window outlined.

    Parameters
    ----------
    omap : OperatingMapRecord
        ``positions`` [m], ``loads`` (N / "curve" / None), ``values[name][i][j]`` at load i,
        position j (None: no trim), ``window`` [s] for the time constant.
    name : str
        Key of ``MAP_QUANTITIES``.
    """
    fig, ax = new_figure("map")
    if draw_map(fig, ax, omap, name):
        fig.subplots_adjust(left=0.12, right=0.93, top=0.9, bottom=0.15)
    return to_svg(fig, prefix)


def draw_map(fig, ax, omap, name: str) -> bool:
    """Draw the map of quantity ``name`` on ``ax`` (see :func:`map_figure`); False when the map lacks it."""
    label, unit, scale, wkey = MAP_QUANTITIES[name]
    vals = omap.values.get(name)
    pos = np.asarray(omap.positions, float)
    if not vals or pos.size == 0:
        message_axes(ax, f"{label}: not in the results")
        return False
    z = np.array([[np.nan if v is None else v * scale for v in row] for row in vals], float)
    cmap = ListedColormap(["#f7fbff", "#deebf7", "#c6dbef", "#9ecae1", "#6baed6", "#4292c6", "#2171b5", "#08519c"])
    cmap.set_bad("#e0e0e0")
    # pcolormesh, not imshow: cells stay vector rectangles (imshow would embed a raster image)
    im = ax.pcolormesh(np.arange(pos.size + 1) - 0.5, np.arange(len(vals) + 1) - 0.5, np.ma.masked_invalid(z),
                       cmap=cmap, shading="flat", edgecolors="white", linewidth=0.6)
    ax.set_xlim(-0.5, pos.size - 0.5)
    ax.set_ylim(-0.5, len(vals) - 0.5)
    ax.set_xticks(range(pos.size), [fmt_quantity(x, "m", "mm", 0).split()[0] for x in pos])
    ax.set_yticks(range(len(vals)), [plain(x) for x in _load_labels(omap.loads or [None] * len(vals))])
    ax.set_xlabel("position [mm]")
    ax.set_ylabel("closing load")
    ax.grid(False)
    cb = fig.colorbar(im, ax=ax, pad=0.015, fraction=0.04)
    cb.set_label(f"{label} [{unit}]")
    cb.outline.set_linewidth(0.4)
    win = omap.window if wkey else None
    for i in range(z.shape[0]):
        for j in range(z.shape[1]):
            v = z[i, j]
            if not np.isfinite(v):
                ax.text(j, i, "no trim", ha="center", va="center", fontsize=5.5, color="#666666")
                continue
            outside = win is not None and not (win[0] * scale <= v <= win[1] * scale)
            dark = im.norm(v) > 0.6
            ax.text(j, i, f"{v:.0f}" if abs(v) >= 10 else f"{v:.2g}", ha="center", va="center", fontsize=6,
                    color="white" if dark else "#1f2a33", fontweight="bold" if outside else "normal")
            if outside:  # cells outside the requirement window: red outline
                ax.add_patch(_cell(j, i, COLORS["limit"]))
    if win is not None:
        ax.plot([], [], "s", mfc="none", mec=COLORS["limit"], label=f"outside {win[0] * scale:g}\u2013{win[1] * scale:g} {unit}")
        ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=2, borderaxespad=0.2)
    return True


def _cell(j, i, color):
    from matplotlib.patches import Rectangle

    return Rectangle((j - 0.46, i - 0.46), 0.92, 0.92, fill=False, ec=color, lw=1.0)


@styled
def bode_figure(analyses: list, prefix: str) -> str:
    """Bode magnitude and phase of the sampled loop L at each critical point.

    Parameters
    ----------
    analyses : list of (label, LinearAnalysisRecord)
        Each with its ``bode`` arrays (frequency [Hz], loop magnitude [dB] and phase [deg], sampled where given).
    """
    fig, (am, ap) = new_figure("bode", 2, 1, sharex=True, gridspec_kw={"hspace": 0.1})
    if draw_bode(am, ap, analyses):
        fig.subplots_adjust(left=0.1, right=0.985, top=0.9, bottom=0.12)
    return to_svg(fig, prefix)


def draw_bode(am, ap, analyses: list) -> int:
    """Draw the loop's Bode magnitude on ``am`` and phase on ``ap`` per analysis (see :func:`bode_figure`); the count drawn."""
    shown = 0
    for k, (label, a) in enumerate(analyses):
        f, mag, ph = a.bode.frequency_hz, a.bode.loop_magnitude, a.bode.loop_phase
        if not f or not mag:
            continue
        c = PALETTE[k % len(PALETTE)]
        am.semilogx(f, mag, color=c, label=plain(label))
        if ph:
            ap.semilogx(f, ph, color=c)
        figs = a.figures
        if figs.gain_crossover_hz and figs.phase_margin_deg is not None:
            ap.plot(figs.gain_crossover_hz, figs.phase_margin_deg - 180.0, "o", ms=3.5, mfc="white", mec=c)
        shown += 1
    if not shown:
        message_axes(am, "no Bode data in the results")
        message_axes(ap, "")
        return 0
    am.axhline(0.0, color="#333333", lw=0.6)
    ap.axhline(-180.0, color="#333333", lw=0.6)
    am.set_ylabel("|L| [dB]")
    ap.set_ylabel("phase [deg]")
    ap.set_xlabel("frequency [Hz]")
    am.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=4, borderaxespad=0.2)
    return shown


@styled
def pole_figure(analyses: list, prefix: str) -> str:
    """Closed-loop poles (continuous) at each critical point, with the 0.25 s time-constant line."""
    fig, ax = new_figure("map")
    if draw_poles(ax, analyses):
        fig.subplots_adjust(left=0.1, right=0.985, top=0.8, bottom=0.16)
    return to_svg(fig, prefix)


def draw_poles(ax, analyses: list) -> int:
    """Draw the closed-loop poles per analysis on ``ax`` (see :func:`pole_figure`); the count drawn."""
    shown = 0
    for k, (label, a) in enumerate(analyses):
        poles = a.poles.closed_loop
        if not poles:
            continue
        p = np.asarray(poles, float).reshape(-1, 2)
        ax.plot(p[:, 0], p[:, 1], "x", ms=5, mew=1.2, color=PALETTE[k % len(PALETTE)], label=plain(label))
        shown += 1
    if not shown:
        message_axes(ax, "no pole data in the results")
        return 0
    ax.set_xscale("symlog", linthresh=10.0)
    ax.set_yscale("symlog", linthresh=10.0)
    for tau, ls in ((0.25, (0, (4, 2))), (0.10, ":")):
        ax.axvline(-1.0 / tau, color=COLORS["limit"], lw=0.7, ls=ls, label=f"\u03c4 = {tau:g} s")
    ax.axvline(0.0, color="#333333", lw=0.6)
    ax.set_xlabel("real part [1/s] (symmetric log)")
    ax.set_ylabel("imaginary part [rad/s]")
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3, borderaxespad=0.2)
    return shown


def _draw_step(ax, step) -> None:
    """The predicted step of the linear loop (sampled and continuous) [mm against s]."""
    if step is None or not step.time:
        message_axes(ax, "no predicted step in the analysis")
        return
    ax.plot(step.time, to_display(np.asarray(step.position, float), "m", "mm"), color=COLORS["position"], label="sampled loop")
    if step.time_continuous:
        ax.plot(step.time_continuous, to_display(np.asarray(step.position_continuous, float), "m", "mm"), color=COLORS["reference"],
                ls=(0, (4, 2)), label="continuous")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("position [mm]")
    ax.set_title(f"predicted {fmt_quantity(abs(step.size), 'm', 'mm', 0)} step")
    ax.legend(loc="lower right")


@styled
def analysis_page(analysis, label: str, omap=None, fmt: str = "png") -> bytes:
    """One linear analysis on one page in the report's figures (``govcheck linear --plot``): the loop's Bode
    diagram, the closed-loop poles, the predicted step and, with a map, the time-constant map; bytes of ``fmt``
    (png, svg or pdf, without a date so the same analysis gives the same file)."""
    import io

    from matplotlib.figure import Figure

    from compliance.report.svg import HEIGHTS_IN, WIDTH_IN

    rows = 3 if omap else 2
    fig = Figure(figsize=(WIDTH_IN, HEIGHTS_IN["bode"] + HEIGHTS_IN["map"] * (rows - 1)))
    grid = fig.add_gridspec(rows + 1, 2, height_ratios=[1.0, 1.0] + [1.6] * (rows - 1), hspace=0.55, wspace=0.3)
    am, ap = fig.add_subplot(grid[0, :]), None
    ap = fig.add_subplot(grid[1, :], sharex=am)
    draw_bode(am, ap, [(label, analysis)])
    draw_poles(fig.add_subplot(grid[2, 0]), [(label, analysis)])
    _draw_step(fig.add_subplot(grid[2, 1]), analysis.step)
    if omap:
        draw_map(fig, fig.add_subplot(grid[3, :]), omap, "time_constant")
    buf = io.BytesIO()
    meta = {"svg": {"Date": None}, "pdf": {"CreationDate": None}}.get(fmt, {})
    fig.savefig(buf, format=fmt, metadata=meta, bbox_inches="tight", pad_inches=0.05)
    return buf.getvalue()
