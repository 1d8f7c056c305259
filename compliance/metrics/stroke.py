"""Full-stroke metrics: stroke times by a named timing, the stroke's timing points, independent adjustment.

IEEE Std 125-2007 (5.2.6) and IEC 61362:2024 express the servomotor speed settings as full-stroke
times; ASME PTC 29-2005 (R2020) times the stroke at full rate and the end cushion apart, and IEC
60308:2024 extrapolates the straight (full-rate) part of the recorded stroke to the whole stroke.
:func:`stroke_figures` measures every figure of one recorded or simulated stroke; :func:`timed`
picks the one a requirement's ``timing`` names (``full_rate``, ``end_to_end``, ``extrapolated``).
A stroke with no straight part has no full-rate time: it is flagged and gets its end-to-end time.
"""

from __future__ import annotations

import numpy as np

from compliance.metrics.trace_windows import crossing

__all__ = ["START_FRACTION", "STRAIGHT_TOLERANCE", "TIMINGS", "independent_adjustment", "stroke_figures", "stroke_timing",
           "stroke_time", "timed"]


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


def stroke_timing(time, position, stroke, direction, full_stroke_time, t_command=None):
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
    t_command : float, optional
        When the stroke was commanded [s]; default ``time[0]``.

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
    t0 = float(t[0]) if t_command is None else float(t_command)
    rel = (lambda v: None if v is None else v - t0)
    return {
        "start_delay": rel(t_start),
        "time_to_end": rel(t_end),
        "cushion_time": None if t_cushion is None or t_end is None else t_end - t_cushion,
        "cushion_at_rate": None if full_stroke_time is None else (END_FRACTION - CUSHION_FRACTION) * full_stroke_time,
    }


# the straight (full-rate) part: the mean speeds over 25-50 % and 50-75 % of the travel agree within this fraction
# of their mean (govcheck's choice: a stroke at its full rate keeps its speed to a few per cent; a pneumatic
# meter-out stroke decelerating from its start-up surge differs by 40-90 %)
STRAIGHT_TOLERANCE = 0.20
TIMINGS = ("full_rate", "end_to_end", "extrapolated")


def stroke_figures(time, position, stroke, direction, t_command=None) -> dict:
    """Every timing figure of one full stroke [s, m/s], for simulated and recorded traces alike.

    Parameters
    ----------
    time, position : array [s], [m]
        The stroke, starting at the end it leaves (position 0 = closed).
    stroke : float
        Servomotor stroke [m].
    direction : {"opening", "closing"}
    t_command : float, optional
        When the stroke was commanded [s]; default ``time[0]``.

    Returns
    -------
    dict
        ``extrapolated`` (25-75 % extrapolated, :func:`stroke_time`), ``t25_75``; ``quarter_speeds``
        (mean speeds over 25-50 % and 50-75 % of the travel [m/s]) and ``straight`` (they agree within
        :data:`STRAIGHT_TOLERANCE` of their mean); ``full_rate`` (the extrapolated time when the stroke
        is straight, else None); ``end_to_end`` (command to 99 % of the travel: the start delay included)
        and the :func:`stroke_timing` figures; ``reason`` when the stroke did not pass 25-75 %.
    """
    t = np.asarray(time, float)
    x = np.asarray(position, float)
    T, t1, t2, why = stroke_time(t, x, stroke, direction)
    t0 = float(t[0]) if t_command is None else float(t_command)
    tim = stroke_timing(t, x, stroke, direction, T, t_command=t0)
    travel = (x - x[0]) if direction == "opening" else (x[0] - x)
    cr = [crossing(t, travel, f * stroke, 0, +1) for f in (0.25, 0.50, 0.75)]
    quarters = None
    straight = None
    if None not in cr and cr[1] > cr[0] and cr[2] > cr[1]:
        quarters = (0.25 * stroke / (cr[1] - cr[0]), 0.25 * stroke / (cr[2] - cr[1]))
        mean = 0.5 * (quarters[0] + quarters[1])
        straight = abs(quarters[0] - quarters[1]) <= STRAIGHT_TOLERANCE * mean
    return {"extrapolated": T, "t25_75": [t1, t2], "reason": why, "quarter_speeds": quarters, "straight": straight,
            "full_rate": T if straight else None, "end_to_end": tim.get("time_to_end"), **tim}


def timed(fig: dict, timing: str) -> tuple[float | None, str | None, str]:
    """The stroke time a requirement's ``timing`` names, from :func:`stroke_figures`.

    Returns
    -------
    tuple
        (time [s] or None, reason or flag, timing used). ``full_rate`` on a stroke with no straight
        part gives the end-to-end time, flagged in the reason; a time that cannot be measured is None
        with the reason.
    """
    if timing not in TIMINGS:
        raise ValueError(timing)
    if timing == "extrapolated":
        return fig["extrapolated"], fig["reason"], "extrapolated"
    end = fig.get("end_to_end")
    no_end = "did not reach 99 % of the stroke (the end stop) within the run"
    if timing == "end_to_end":
        return end, None if end is not None else no_end, "end_to_end"
    if fig["extrapolated"] is None:
        return None, fig["reason"], "full_rate"
    if fig["straight"]:
        return fig["full_rate"], None, "full_rate"
    v1, v2 = fig["quarter_speeds"] or (float("nan"), float("nan"))
    flag = (f"no straight part: {v1 * 1e3:.1f} mm/s over 25-50 % of the travel, {v2 * 1e3:.1f} mm/s over 50-75 % "
            f"(more than {STRAIGHT_TOLERANCE:.0%} apart), so there is no full rate to time; timed end to end "
            "(command to 99 % of the travel, start delay included)")
    return end, flag if end is not None else flag + "; " + no_end, "end_to_end"


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
