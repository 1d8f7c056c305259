"""The procedure registry: every kind's runner, and :func:`run` of one procedure at one operating point.

The kinds are declared in :mod:`compliance.procedures.kinds`, the run record in
:mod:`compliance.procedures.outcomes`, the steps every runner shares in
:mod:`compliance.procedures.scenarios`; one module per family holds the runners (``steps``,
``sine``, ``stroke``, ``hold``, ``dead_band``, and plant B's ``path_tracking``).
"""

from __future__ import annotations

import time as _time

from compliance.procedures.dead_band import run_dead_band
from compliance.procedures.hold import run_hold
from compliance.procedures.kinds import KINDS, Kind, Setting, parse_setting
from compliance.procedures.outcomes import MAX_TRACE_POINTS, TRACE_COLUMNS, RunOutcome, Sample, downsample, request_key
from compliance.procedures.scenarios import at_operating_point
from compliance.procedures.sine import run_sine
from compliance.procedures.steps import RATE_LIMIT_FRACTION, run_steps
from compliance.procedures.stroke import run_full_stroke, run_independent_adjustment
from compliance.procedures.path_tracking import RUNNERS as TRACKING_RUNNERS

__all__ = [
    "KINDS",
    "MAX_TRACE_POINTS",
    "RATE_LIMIT_FRACTION",
    "TRACE_COLUMNS",
    "Kind",
    "RunOutcome",
    "Sample",
    "Setting",
    "downsample",
    "parse_setting",
    "request_key",
    "run",
]

# kind -> runner(cfg, procedure, operating_point, requests, outcome)
_RUNNERS = {
    "steps": run_steps,
    "sine": run_sine,
    "full_stroke": run_full_stroke,
    "independent_adjustment": run_independent_adjustment,
    "hold": run_hold,
    "dead_band": run_dead_band,
    **TRACKING_RUNNERS,
}


def run(cfg, procedure, op, requests) -> RunOutcome:
    """Run one procedure at one operating point and measure the requested metrics.

    Parameters
    ----------
    cfg : PlantConfig
    procedure : requirements.Procedure
    op : requirements.OperatingPoint
    requests : list of (metric, options)
        Metrics to measure (with requirement options); every metric the kind produces is
        also measured with default options for the report.

    Returns
    -------
    RunOutcome
        A simulation or input failure is recorded in ``error``, not raised, so one bad run
        does not hide the others.
    """
    from compliance.errors import GovcheckError

    t0 = _time.perf_counter()
    out = RunOutcome(procedure.name, op.name, procedure.kind)
    try:
        _RUNNERS[procedure.kind](at_operating_point(cfg, op), procedure, op, list(requests), out)
    except GovcheckError as exc:
        out.error = str(exc)
        out.error_kind = type(exc).__name__
    out.wall_time = _time.perf_counter() - t0
    return out
