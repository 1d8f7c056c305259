"""The requirement set as evaluated (after ``extends``): operating points, procedures, requirements as written.

The file's texts are kept as written (``initial_position = "50 %stroke"``); an operating point
also carries its position and constant load in SI, resolved against the plant when the result is
made or read, so no reader parses a position back out of its text. docs/results-schema.md,
``requirement_set``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from compliance.requirements.verdict import Severity
from compliance.results.record import FrozenDict, Record, derived, key, records, tuple_of

__all__ = ["FileRecord", "OperatingPointRecord", "ProcedureRecord", "RequirementSetRecord", "RequirementSpec"]


@dataclass(frozen=True, kw_only=True)
class OperatingPointRecord(Record):
    """Where a test is run: start position and load as written, and resolved to SI."""

    name: str
    title: str = ""
    initial_position: str | None = None  # as written ("50 %stroke", "80 mm")
    load: float | str | None = None  # N, "curve", "nominal" or None (no load)
    load_text: str | None = None
    flow_control: bool | None = None  # throttles in (True) / out (False) / as configured (None)
    setpoint_limiter: bool | None = None  # False: the step is injected downstream of the set-point rate limiter
    note: str = ""
    position: float | None = derived()  # [m] the initial position resolved against the plant's stroke
    load_force: float | None = derived()  # [N] a constant load (nominal resolved); None for none or the curve

    @property
    def on_curve(self) -> bool:
        """Whether the load follows the plant's load curve over the stroke."""
        return self.load == "curve"

    def resolved(self, stroke: float | None, nominal_force: float | None) -> "OperatingPointRecord":
        """This point with its SI position and load (the one parser of positions, ``units.amounts``)."""
        from compliance.units.amounts import parse_position

        x = None
        if self.initial_position is not None and stroke is not None:
            x = parse_position(self.initial_position, stroke, f"operating_points.{self.name}.initial_position")
        constant = self.load if isinstance(self.load, (int, float)) else None
        force = nominal_force if self.load == "nominal" else constant
        return replace(self, position=x, load_force=force)


@dataclass(frozen=True, kw_only=True)
class ProcedureRecord(Record):
    """A test procedure: its kind and settings as written."""

    name: str
    kind: str
    title: str = ""
    settings: FrozenDict = key(factory=FrozenDict)
    note: str = ""


@dataclass(frozen=True, kw_only=True)
class RequirementSpec(Record):
    """A requirement as its files write it, with the history of the files that set its limit."""

    id: str
    title: str = ""
    standard: str | None = None
    clause: str | None = None
    metric: str
    metric_meaning: str = ""
    unit: str = ""
    display_unit: str = ""
    comparator: str = "<="
    limit_text: str = ""
    limit: tuple[str, ...] | None = None  # as written; None = open
    procedures: tuple[str, ...] = key(default=(), read=tuple_of(str))
    operating_points: tuple[str, ...] = key(default=(), read=tuple_of(str))
    severity: str = Severity.MANDATORY.value
    source: str = "simulation"
    options: FrozenDict = key(factory=FrozenDict)
    note: str | None = None
    enabled: bool = True
    defined_in: str | None = None
    reading: str | None = None
    alternative: str | None = None
    own_choice: str | None = None
    not_applicable: FrozenDict = key(factory=FrozenDict)
    history: tuple = ()
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class FileRecord(Record):
    """A file read, with the sha256 of its bytes."""

    path: str | None = None
    digest: str | None = None


def _points(v, where) -> FrozenDict:
    return FrozenDict({k: OperatingPointRecord.from_dict(p, f"{where}.{k}") for k, p in v.items()})


def _procedures(v, where) -> FrozenDict:
    return FrozenDict({k: ProcedureRecord.from_dict(p, f"{where}.{k}") for k, p in v.items()})


def _records_map(v) -> dict:
    return {k: r.as_dict() for k, r in v.items()}


@dataclass(frozen=True, kw_only=True)
class RequirementSetRecord(Record):
    """The requirement set as evaluated."""

    name: str
    title: str | None = None
    path: str | None = None
    digest: str | None = None
    files: tuple[FileRecord, ...] = key(default=(), read=records(FileRecord))
    operating_points: FrozenDict = key(factory=FrozenDict, read=_points, write=_records_map)
    procedures: FrozenDict = key(factory=FrozenDict, read=_procedures, write=_records_map)
    requirements: tuple[RequirementSpec, ...] = key(read=records(RequirementSpec))

    def resolved(self, stroke: float | None, nominal_force: float | None) -> "RequirementSetRecord":
        """The set with every operating point's SI position and load."""
        pts = FrozenDict({k: p.resolved(stroke, nominal_force) for k, p in self.operating_points.items()})
        return replace(self, operating_points=pts)
