"""Servomotor dead band: width of the position/reference hysteresis loop (IEC 60308).

Measured under a slow triangular set-point, so the loop shows the band of command change
without position change rather than the servo's dynamics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from compliance.errors import InputError
from compliance.metrics.trace_windows import true_runs

__all__ = ["DeadBandMetrics", "dead_band"]


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
    up_runs, down_runs = true_runs(rising), true_runs(falling)
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
