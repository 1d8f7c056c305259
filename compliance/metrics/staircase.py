"""Servomotor dead band from a set-point staircase: how far the set-point moves after a reversal before the servo does.

The IEC 60308 dead-band test as commissioning engineers run it: the set-point climbs in small
equal stairs, then comes down in the same stairs. On each leg (a run of stairs in one direction,
started after a reversal) the dead band is the set-point change from the leg's starting level to
the level in force when the position has first moved ``threshold`` in the leg's direction from
where it stood when the leg began; its resolution is one stair. The servomotor's dead band is the
larger of the legs. A leg on which the position never moved that far gives no value (the band is
wider than the leg).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from compliance.metrics.trace_windows import crossing, time_window

__all__ = ["StaircaseLeg", "staircase_legs", "staircase_dead_band"]


@dataclass(frozen=True)
class StaircaseLeg:
    """One leg of a staircase: its stairs' times [s], the set-point levels after each [m], its direction (+1 up, -1 down)."""

    times: tuple
    levels: tuple
    start_level: float
    direction: int


def staircase_legs(time, reference, stair: float, tolerance: float = 0.2) -> list[StaircaseLeg]:
    """The legs of a staircase reference: runs of consecutive set-point changes of one ``stair`` [m] in one direction.

    A change of another size (an approach step) is not a stair and ends a leg.
    """
    t = np.asarray(time, float)
    r = np.asarray(reference, float)
    d = np.diff(r)
    jumps = np.nonzero(np.abs(d) > 0.5 * stair)[0]
    legs, cur = [], None
    for i in jumps:
        size = d[i]
        if abs(abs(size) - stair) > tolerance * stair:
            cur = None
            continue
        sgn = 1 if size > 0 else -1
        if cur is None or cur["dir"] != sgn:
            cur = {"dir": sgn, "times": [], "levels": [], "start": float(r[i])}
            legs.append(cur)
        cur["times"].append(float(t[i + 1]))
        cur["levels"].append(float(r[i + 1]))
    return [StaircaseLeg(tuple(g["times"]), tuple(g["levels"]), g["start"], g["dir"]) for g in legs]


def staircase_dead_band(time, position, leg: StaircaseLeg, threshold: float, pre_window: float = 0.05):
    """Dead band of one leg [m] and the time the position first moved ``threshold`` [s] (None, None if it never did).

    Parameters
    ----------
    time, position : array [s], [m]
    leg : StaircaseLeg
    threshold : float
        Motion that counts as the servo having moved [m] (half a stair resolves the stair it moved on).
    pre_window : float
        The position where the leg began is the mean over this span before its first stair [s].
    """
    t = np.asarray(time, float)
    x = np.asarray(position, float)
    pre = time_window(t, leg.times[0] - pre_window, leg.times[0])
    x0 = float(np.mean(x[pre])) if pre.stop > pre.start else float(np.interp(leg.times[0], t, x))
    i0 = int(np.searchsorted(t, leg.times[0]))
    end = leg.times[-1] + (leg.times[-1] - leg.times[-2] if len(leg.times) > 1 else 0.0)
    moved = crossing(t, leg.direction * (x - x0), threshold, i0, +1)
    if moved is None or moved > end:
        return None, None
    k = int(np.searchsorted(np.asarray(leg.times), moved, side="right")) - 1
    return abs(leg.levels[k] - leg.start_level), moved
