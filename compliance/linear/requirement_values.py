"""Requirements with ``source = "linear"``: their value from the linearised model, when it is there.

``compliance.linear.analysis`` is looked up at call time (so a stand-in in ``sys.modules`` is used);
while it is missing, or offers none of the entry points below, the requirement is reported
*not evaluated* with the reason, never guessed.
"""

from __future__ import annotations

import importlib
import math

from compliance.errors import GovcheckError
from compliance.simulation.scenario import scenario_load

__all__ = ["linear_value"]


def linear_value(cfg, metric: str, op):
    """Value of ``metric`` from the linearised model at an operating point, or (None, reason).

    Uses ``compliance.linear.analysis`` when it is importable: ``analyse(cfg, position, load,
    flow_control=..., detail=False).metric(name)`` (honours the operating point's circuit), else
    ``linear_metric(cfg, name, position, load)``, else ``evaluate_metric(cfg, name, initial_position=,
    load=, flow_control=)``; otherwise the requirement is reported not evaluated, with the reason.
    """
    try:
        mod = importlib.import_module("compliance.linear.analysis")
    except ModuleNotFoundError as exc:
        if exc.name == "compliance.linear.analysis":
            return None, "linearised model not available (compliance.linear.analysis is not installed yet)"
        raise
    if op.initial_position is None:
        return None, f"operating point '{op.name}' has no initial_position to linearise about"
    x0 = op.initial_position.resolve(cfg.p("cylinder.stroke"))
    load = scenario_load(cfg, op)
    try:
        if hasattr(mod, "analyse"):
            value = mod.analyse(cfg, x0, load, flow_control=op.flow_control, detail=False).metric(metric)
        elif hasattr(mod, "linear_metric"):
            value = mod.linear_metric(cfg, metric, x0, load)
        elif hasattr(mod, "evaluate_metric"):
            value = mod.evaluate_metric(cfg, metric, initial_position=x0, load=load, flow_control=op.flow_control)
        else:
            return None, "compliance.linear.analysis offers no analyse / linear_metric / evaluate_metric"
    except GovcheckError as exc:
        return None, f"linear model: {exc}"
    if value is None or not math.isfinite(float(value)):
        return None, "linear model gave no finite value"
    return float(value), None
