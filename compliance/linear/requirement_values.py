"""Requirements with ``source = "linear"``: their value from the linearised model.

A metric the linear model cannot give at an operating point (no initial position, no finite
value, an input the linearisation refuses) is reported *not evaluated* with the reason, never guessed.
"""

from __future__ import annotations

import math

from compliance.errors import GovcheckError
from compliance.linear.analysis import analyse
from compliance.simulation.scenario import scenario_load

__all__ = ["linear_value"]


def linear_value(cfg, metric: str, op):
    """Value of ``metric`` from the linearised model at an operating point, or (None, reason)."""
    if op.initial_position is None:
        return None, f"operating point '{op.name}' has no initial_position to linearise about"
    x0 = op.initial_position.resolve(cfg.p("cylinder.stroke"))
    load = scenario_load(cfg, op)
    try:
        value = analyse(cfg, x0, load, flow_control=op.flow_control, detail=False).metric(metric)
    except GovcheckError as exc:
        return None, f"linear model: {exc}"
    if value is None or not math.isfinite(float(value)):
        return None, "linear model gave no finite value"
    return float(value), None
