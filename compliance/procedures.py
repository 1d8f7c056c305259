"""Test procedures as data: step sequences, sinusoid, full stroke, independent adjustment, hold, dead band.

A procedure kind declares its settings (with units and defaults); :func:`run` builds the
scenario(s) for one operating point, simulates them and measures every metric the kind
produces with the ONE metric implementation in :mod:`compliance.metrics`. No physics here.

This module dispatches a run to its kind's runner (``_RUNNERS``; plant B's tracking kinds
register theirs here). The declarations are in ``procedure_kinds``, the run record in
``run_outcomes``, the shared scenario steps in ``procedure_scenarios`` and one runner per
family in ``step_procedure``, ``sine_procedure``, ``stroke_procedures``, ``hold_procedure``
and ``dead_band_procedure``.
"""

from __future__ import annotations

import time as _time

from .dead_band_procedure import run_dead_band
from .hold_procedure import run_hold
from .procedure_kinds import KINDS, Kind, Setting, parse_setting
from .procedure_scenarios import scenario_load
from .run_outcomes import MAX_TRACE_POINTS, TRACE_COLUMNS, RunOutcome, Sample, downsample, request_key
from .sine_procedure import run_sine
from .step_procedure import RATE_LIMIT_FRACTION, run_steps
from .stroke_procedures import run_full_stroke, run_independent_adjustment

# unused here: importable from this module before it was split, so kept for callers
from . import metrics as M  # noqa: F401
from .errors import InputError  # noqa: F401

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

_load = scenario_load  # the old private name, still imported by callers outside this module

# kind -> runner(cfg, procedure, operating_point, requests, outcome); extended by compliance.tracking
_RUNNERS = {
    "steps": run_steps,
    "sine": run_sine,
    "full_stroke": run_full_stroke,
    "independent_adjustment": run_independent_adjustment,
    "hold": run_hold,
    "dead_band": run_dead_band,
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
    from .errors import GovcheckError

    t0 = _time.perf_counter()
    out = RunOutcome(procedure.name, op.name, procedure.kind)
    try:
        _RUNNERS[procedure.kind](cfg, procedure, op, list(requests), out)
    except GovcheckError as exc:
        out.error = str(exc)
        out.error_kind = type(exc).__name__
    out.wall_time = _time.perf_counter() - t0
    return out
