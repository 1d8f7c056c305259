"""Declared bench effect: seal friction that drifts during a run (``friction_drift``).

An elastomer seal's friction is not fixed over a run of strokes: running friction heats the seal,
the warmed elastomer swells and presses harder, and its friction rises (Apple Rubber, Seal Design
Guide, "Effects of friction"); the lubricant film is also redistributed by each stroke. The
friction level therefore drifts with the time the seal has been sliding. Both Stribeck levels are
scaled by one factor linear in the time from the middle of each run:

    F_C,S(t) = F_C,S * (1 + r (t - t_m)),   t_m = the run's mid time,

with one relative rate r [1/s] shared by every run of a seal: a drift the other runs predict. A
drift of one run alone is named in ``structure_left`` instead. The linear form and the run's mid
time as reference are our choices.
"""

from __future__ import annotations

import numpy as np

from compliance.effects.param import Param
from compliance.diagnosis.friction_bench.position import BenchEffect, MIN_FACTOR

FRICTION_DRIFT = BenchEffect(
    name="friction_drift",
    meaning="the seal's friction level drifts during each run (running-in: the contact warms, the lubricant film moves)",
    params=(Param("drift_rate", "1/s", "relative change of both friction levels per second of the run, r", 0.0, (-0.02, 0.02)),),
    equations="F_C,S(t) = F_C,S (1 + r (t - t_m))",
    source="friction heating swells the seal and raises its friction (Apple Rubber, Seal Design Guide); linear form: our choice",
)


def drift_factor(time, params: dict) -> np.ndarray | float:
    """1 + r (t - t_m) of one run (t_m its mid time); 1.0 without ``drift_rate``; never below ``MIN_FACTOR``."""
    if "drift_rate" not in params or time is None:
        return 1.0
    t = np.asarray(time, dtype=float)
    return np.maximum(1.0 + params["drift_rate"] * (t - 0.5 * (t[0] + t[-1])), MIN_FACTOR)


__all__ = ["FRICTION_DRIFT", "drift_factor"]
