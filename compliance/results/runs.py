"""What a check simulated and what no row judged: runs, their traces and values; unjudged values; findings.

docs/results-schema.md, ``runs[]``, ``coverage`` and ``findings``.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.results.keys import RequestKey
from compliance.results.record import FrozenDict, Record, key, records, tuple_of
from compliance.results.rows import SampleRecord

__all__ = ["Finding", "Mark", "RunRecord", "Timing", "Trace", "Unjudged"]


def _metrics(v, where) -> FrozenDict:
    """``{"metric[opts]": [sample, ...]}`` -> ``{RequestKey: (SampleRecord, ...)}``."""
    read = records(SampleRecord)
    return FrozenDict({RequestKey.parse(k): read(s, f"{where}.{k}") for k, s in v.items()})


def _metrics_json(v) -> dict:
    return {str(k): [s.as_dict() for s in samples] for k, samples in v.items()}


@dataclass(frozen=True, kw_only=True)
class Trace(Record):
    """One simulation's signals for plots: at most 2000 evenly chosen samples per signal (SI: s, m, V, Pa abs)."""

    label: str = ""
    kind: str | None = key(omit_none=True, default=None)  # "path3d": plant B's path in space (per-axis signals)
    points: int = 0  # samples kept per signal
    samples: int = 0  # samples simulated
    extra: FrozenDict = key(factory=FrozenDict)  # the signals by name: time, reference, position, valve_command, ...

    def signal(self, name: str) -> tuple | None:
        """The samples of signal ``name`` (None when the trace does not carry it)."""
        return self.extra.get(name)

    @property
    def direction(self) -> str:
        """The last word of the label (``opening`` / ``closing`` for a stroke)."""
        return self.label.rsplit(" ", 1)[-1]


@dataclass(frozen=True, kw_only=True)
class Mark(Record):
    """A point, band or window drawn on a trace (``value`` SI; ``[t, x]`` pairs are time [s] and position [m])."""

    trace: str | None = None  # the label of the trace it belongs to
    step: int | None = key(omit_none=True, default=None)  # which step of a sequence (1-based)
    type: str = ""
    value: object = None
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class RunRecord(Record):
    """One procedure at one operating point: every metric value it produced, its traces and plot marks."""

    id: str  # procedure@operating_point
    procedure: str
    operating_point: str
    kind: str
    title: str = ""
    error: str | None = None  # why the run failed (its rows are not evaluated)
    notes: tuple[str, ...] = key(default=(), read=tuple_of(str))
    metrics: FrozenDict = key(factory=FrozenDict, read=_metrics, write=_metrics_json)
    traces: tuple[Trace, ...] = key(read=records(Trace))
    marks: tuple[Mark, ...] = key(default=(), read=records(Mark))
    wall_time: float | None = key(omit_none=True, default=None)  # [s]; absent in a reproducible file

    def samples(self, request: RequestKey | str) -> tuple[SampleRecord, ...]:
        """The values of one metric request (a key or a metric name without options)."""
        k = request if isinstance(request, RequestKey) else RequestKey.parse(request)
        return self.metrics.get(k, ())


@dataclass(frozen=True, kw_only=True)
class Unjudged(Record):
    """A run's computed metric value that no row judged against a limit, and why."""

    run: str
    metric: RequestKey = key(read=lambda v, where: RequestKey.parse(v))
    values: int = 0
    reason: str = ""


@dataclass(frozen=True, kw_only=True)
class Finding(Record):
    """Two limits of the set that conflict, pull against each other or narrow each other (with the SI figures)."""

    kind: str  # conflict | tension | narrowing | rate_split
    requirements: tuple[str, ...] = key(default=(), read=tuple_of(str))
    procedure: str | None = None
    text: str = ""
    mandatory: bool = False
    extra: FrozenDict = key(factory=FrozenDict)  # the arithmetic's figures (step, tau_max, v_max, mean_speed...)

    @property
    def figures(self) -> FrozenDict:
        """The SI figures of the finding's arithmetic."""
        return self.extra

    def figure(self, name: str) -> float | None:
        """One SI figure of the arithmetic (``t_min``, ``t_max``, ``v_max``, ``step``, ``tau_max``, ``mean_speed``),
        None when this kind of finding has none."""
        return self.extra.get(name)


@dataclass(frozen=True, kw_only=True)
class Timing(Record):
    """Wall time of the check [s], runs, workers and the summed CPU work of the runs [s]."""

    wall: float = 0.0
    runs: int = 0
    workers: int = 1
    run_wall_sum: float = 0.0
