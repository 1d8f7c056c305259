"""One measured test case: a step of a series, a stroke, a hold, a staircase, a sinusoid, with its figures.

A recording holds one test; a step series holds one case per step. A case carries the
conditions it ran under (what maps it to a requirement file's procedures and operating points),
its figures as :class:`~compliance.acceptance.measure.uncertainty.Measured` values keyed by the
metric names of ``compliance.metrics.catalogue``, the departures of the test as run from the
standard procedure, and the marks a report draws.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from compliance.acceptance.measure.uncertainty import Measured, missing

__all__ = ["Case"]


@dataclass(frozen=True)
class Case:
    """A measured test case.

    Attributes
    ----------
    recording : str
        The recording's name (file name without its suffixes).
    kind : str
        Procedure kind it measures (``steps``, ``full_stroke``, ``hold``, ``dead_band``, ``sine``).
    label : str
        What it is, as a row names it (``"step 5 of 8 up 3.20 mm at 7.00 s (outward)"``).
    conditions : dict
        ``position`` [m] (operating position; None for a stroke), ``load`` [N] or ``"curve"`` or None,
        ``flow_control`` (True: valves as commissioned, False: open, None: not said), and per kind:
        ``size`` [m] and ``direction`` (``up``/``down``) and ``role`` (``outward``/``return``) of a step,
        ``direction`` (``opening``/``closing``) of a stroke.
    values : dict
        Metric name -> Measured.
    departures : tuple of str
        How the test as run differs from the standard procedure (said in the report).
    marks : dict
        Times and levels a plot marks (SI).
    problem : str or None
        Why the recording cannot be judged as run (every figure is then missing for this reason).
    """

    recording: str
    kind: str
    label: str
    conditions: dict
    values: dict = field(default_factory=dict)
    departures: tuple = ()
    marks: dict = field(default_factory=dict)
    problem: str | None = None

    def value(self, metric: str) -> Measured:
        """The figure of ``metric``, or a missing one saying why this test does not give it."""
        if self.problem:
            return missing(self.problem)
        return self.values.get(metric) or missing(f"{self.label}: this test does not give {metric}")

    def as_dict(self) -> dict:
        """Plain-JSON form."""
        return {"recording": self.recording, "kind": self.kind, "label": self.label, "conditions": dict(self.conditions),
                "values": {k: v.as_dict() for k, v in self.values.items()}, "departures": list(self.departures),
                "marks": dict(self.marks), "problem": self.problem}
