"""A recorded dead-band staircase: the dead band of each leg and of the servo, with its uncertainty.

The legs and the figure are ``metrics.staircase``'s, read on the conditioned position with a
motion threshold of half a stair (the stair it moved on is then resolved), never below ``K``
conditioned-noise standard deviations. The uncertainty is any other stair the threshold crossing
could fall on within its noise band. The staircase's own resolution (one stair) is the figure's definition, not a
measurement error: it is stated beside the figure (``conditions["stair"]``).
"""

from __future__ import annotations

import math

import numpy as np

from compliance.acceptance.measure.case import Case
from compliance.acceptance.measure.uncertainty import K, combine, crossing_with_interval, missing
from compliance.metrics.staircase import staircase_dead_band, staircase_legs
from compliance.metrics.trace_windows import time_window

__all__ = ["measure_staircase"]


def _stair(cond, settings: dict) -> float | None:
    if settings.get("stair"):
        return float(settings["stair"])
    ref = cond.column("reference")
    if ref is None:
        return None
    d = np.abs(np.diff(ref))
    d = d[d > 1e-7]
    return float(np.median(d)) if d.size else None


def _leg_band(cond, leg, threshold: float, stair: float):
    value, moved = staircase_dead_band(cond.time, cond.position, leg, threshold)
    if value is None:
        return None, 0.0, None
    pre = time_window(cond.time, leg.times[0] - 0.05, leg.times[0])
    x0 = float(np.mean(cond.raw[pre])) if pre.stop > pre.start else float(cond.position[0])
    u = math.hypot(cond.u_position, cond.sigma / math.sqrt(max(1, pre.stop - pre.start)))
    t, span = crossing_with_interval(cond.time, leg.direction * (cond.position - x0), threshold, u,
                                     int(np.searchsorted(cond.time, leg.times[0])), +1)
    times = np.asarray(leg.times)
    k_lo = int(np.searchsorted(times, (t or moved) - span, side="right")) - 1
    k_hi = int(np.searchsorted(times, (t or moved) + span, side="right")) - 1
    stairs_apart = max(0, k_hi - k_lo)
    return value, stairs_apart * stair, moved


def measure_staircase(name: str, cond, run, cfg) -> list[Case]:
    """One case for a recorded dead-band staircase (see the module docstring)."""
    stair = _stair(cond, run.settings)
    base = {"position": run.position, "load": run.load, "flow_control": run.flow_control}
    ref = cond.column("reference")
    if stair is None or ref is None:
        return [Case(name, "dead_band", "dead-band staircase", base,
                     {"dead_band": missing("no reference logged: the stairs are not in the log")})]
    legs = [lg for lg in staircase_legs(cond.time, ref, stair) if len(lg.times) >= 2]
    threshold = max(0.5 * stair, K * cond.u_position)
    per_leg, moved, worst = [], {}, None
    for lg in legs:
        value, u_stairs, t_moved = _leg_band(cond, lg, threshold, stair)
        word = "up" if lg.direction > 0 else "down"
        if value is None:
            per_leg.append(missing(f"leg {word} from {lg.times[0]:.1f} s: the position never moved {threshold * 1e3:.2f} mm "
                                   f"over its {len(lg.times)} stairs ({len(lg.times) * stair * 1e3:.2f} mm)"))
            continue
        m = combine(value, {"threshold crossing": u_stairs})
        per_leg.append(m)
        moved[word] = t_moved
        if worst is None or m.value > worst.value:
            worst = m
    if not legs:
        value = missing(f"no run of stairs of {stair * 1e3:.3g} mm in the reference")
    elif any(m.value is None for m in per_leg):
        value = next(m for m in per_leg if m.value is None)  # wider than a leg: no figure, the reason
    else:
        value = worst
    conditions = {**base, "stair": stair, "legs": len(legs), "threshold": threshold,
                  "legs_values": [m.value for m in per_leg]}
    return [Case(name, "dead_band", f"dead-band staircase of {stair * 1e3:.2g} mm stairs", conditions,
                 {"dead_band": value}, (), {"moved": moved})]
