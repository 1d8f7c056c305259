"""Full-stroke metrics: stroke times at full command and the independence of the two speed settings.

IEEE 125 / IEC 61362 express the servomotor speed settings as full-stroke times, taken here
from the straight part of the stroke; the flow-control valves must adjust each direction
without changing the other.
"""

from __future__ import annotations

import numpy as np

from compliance.metrics.trace_windows import crossing

__all__ = ["independent_adjustment", "stroke_time"]


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
        t1 = crossing(time, position, lo, 0, +1)
        t2 = None if t1 is None else crossing(time, position, hi, int(np.searchsorted(time, t1)), +1)
    elif direction == "closing":
        t1 = crossing(time, position, hi, 0, -1)
        t2 = None if t1 is None else crossing(time, position, lo, int(np.searchsorted(time, t1)), -1)
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
