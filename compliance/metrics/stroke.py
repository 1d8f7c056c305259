"""Full-stroke metrics: stroke times at full command and the independence of the two speed settings.

IEEE 125 / IEC 61362 express the servomotor speed settings as full-stroke times, taken here
from the straight part of the stroke; the flow-control valves must adjust each direction
without changing the other.
"""

from __future__ import annotations

import numpy as np

from compliance.metrics.trace_windows import crossing

__all__ = ["START_FRACTION", "independent_adjustment", "stroke_timing", "stroke_time"]


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


# travel that marks the start of motion and the entry into the end cushion (govcheck's choice; ASME PTC 29-2005
# (R2020) asks for the servomotor timing and the cushioning time without fixing these fractions)
START_FRACTION = 0.01
CUSHION_FRACTION = 0.90
END_FRACTION = 0.99


def stroke_timing(time, position, stroke, direction, full_stroke_time):
    """The timing figures of one full stroke beside its 25-75 % time [s].

    Parameters
    ----------
    time, position : array [s], [m]
        The stroke, command given at ``time[0]``, starting at the end the stroke leaves.
    stroke : float
        Servomotor stroke [m].
    direction : {"opening", "closing"}
    full_stroke_time : float or None
        The 25-75 % extrapolated time (:func:`stroke_time`) [s].

    Returns
    -------
    dict
        ``start_delay`` (command to 1 % of the stroke travelled), ``time_to_end`` (command to
        99 %: the end stop), ``cushion_time`` (90 % to 99 % of travel: the cushioning at the
        end stop) and ``cushion_at_rate`` (the time the same 9 % takes at the straight-part rate,
        0.09 x full-stroke time; a cushion makes ``cushion_time`` longer); None where not reached.
    """
    t = np.asarray(time, float)
    x = np.asarray(position, float)
    travel = (x - x[0]) if direction == "opening" else (x[0] - x)

    def at(frac):
        return crossing(t, travel, frac * stroke, 0, +1)

    t_start, t_cushion, t_end = at(START_FRACTION), at(CUSHION_FRACTION), at(END_FRACTION)
    rel = (lambda v: None if v is None else v - float(t[0]))
    return {
        "start_delay": rel(t_start),
        "time_to_end": rel(t_end),
        "cushion_time": None if t_cushion is None or t_end is None else t_end - t_cushion,
        "cushion_at_rate": None if full_stroke_time is None else (END_FRACTION - CUSHION_FRACTION) * full_stroke_time,
    }


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
