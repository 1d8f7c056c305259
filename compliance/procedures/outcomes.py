"""What a procedure run produces: candidate metric values (samples), plot traces, marks and notes.

A run keeps every candidate value of a metric (one per step, stroke or window) with a label
and, when it has none, the reason; the harness judges them. Traces are downsampled for
plots so the results stay small.
"""

from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field

import numpy as np

__all__ = ["MAX_TRACE_POINTS", "TRACE_COLUMNS", "RunOutcome", "Sample", "downsample", "request_key", "traces_off"]

# False inside ``traces_off()``: sweeps judge thousands of candidates and plot none of them, and
# formatting the plot traces costs about a quarter of a campaign's CPU (measured, docs/performance.md)
_KEEP_TRACES: ContextVar[bool] = ContextVar("keep_traces", default=True)

# signals kept for plots, and the most points per signal (report figures need no more)
TRACE_COLUMNS = ("time", "reference", "position", "valve_command", "pressure_a", "pressure_b")
MAX_TRACE_POINTS = 2000


@dataclass
class Sample:
    """One candidate value of a metric within a run (one step, one stroke, one window)."""

    value: float | None
    label: str
    reason: str | None = None
    eligible: bool = True  # False: measured but not valid for a verdict (rate limited)
    detail: dict = field(default_factory=dict)


@dataclass
class RunOutcome:
    """Everything one procedure x operating point produced."""

    procedure: str
    operating_point: str
    kind: str
    samples: dict = field(default_factory=dict)  # request key -> list[Sample]
    traces: list = field(default_factory=list)
    marks: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    error: str | None = None
    error_kind: str | None = None  # "InputError" (bad procedure for this plant) or "SimulationError"
    wall_time: float = 0.0

    def add(self, key: str, sample: Sample):
        """Append a candidate value for a metric request."""
        self.samples.setdefault(key, []).append(sample)


def request_key(metric: str, options: dict | None = None) -> str:
    """Key of a metric request: the metric name plus its options as written."""
    if not options:
        return metric
    return metric + "[" + ",".join(f"{k}={v.text if hasattr(v, 'text') else v}" for k, v in sorted(options.items())) + "]"


def downsample(frame, label: str, columns=TRACE_COLUMNS, max_points=MAX_TRACE_POINTS) -> dict:
    """Trace for plots: at most ``max_points`` evenly chosen samples per signal (lists of floats).

    Inside :func:`traces_off` the trace keeps its label and length but no signals.
    """
    n = len(frame)
    if not _KEEP_TRACES.get():
        return {"label": label, "points": 0, "samples": int(n)}
    idx = np.unique(np.linspace(0, n - 1, min(n, max_points)).round().astype(int)) if n else np.array([], int)
    out = {"label": label, "points": int(idx.size), "samples": int(n)}
    for c in columns:
        if c in frame.columns:
            # 7 significant digits: 0.1 um on a metre, 0.1 Pa on 1 MPa - far below plot resolution
            out[c] = [float(f"{v:.7g}") for v in frame[c].to_numpy()[idx]]
    return out


@contextmanager
def traces_off():
    """Within this block, :func:`downsample` keeps no signals (sweeps: verdicts only, no plots)."""
    token = _KEEP_TRACES.set(False)
    try:
        yield
    finally:
        _KEEP_TRACES.reset(token)
