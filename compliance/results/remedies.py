"""What would make it pass, as page 1 of the report reads it: the ``remedies`` section of a check.

The section is written as the remedies search made it (``CheckResult.remedies``, docs/results-schema.md
"remedies"); these records read the parts a reader is told about first: the verified change, what is
out of reach, and which setting helps most (changes in SI, margins in % of each limit).
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.results.record import FrozenDict, Record, key, optional, records, tuple_of

__all__ = ["Change", "ParameterEffect", "RemedyCandidate", "RemedySection", "Sensitivity"]


@dataclass(frozen=True, kw_only=True)
class Change(Record):
    """One setting changed: its path, unit and the values before and after [SI]."""

    path: str = ""
    unit: str = ""
    start: float | None = key("from", default=None)
    end: float | None = key("to", default=None)
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class RemedyCandidate(Record):
    """A candidate configuration: its changes and, for the remedy, the full campaign that verified it."""

    changes: tuple[Change, ...] = key(default=(), read=records(Change))
    verified: FrozenDict = key(factory=FrozenDict)  # {status, failed_mandatory}
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class ParameterEffect(Record):
    """How a failed requirement's margin moves when one setting moves by ``step`` [percentage points]."""

    path: str = ""
    unit: str = ""
    step: float | None = None
    delta_margin_pct: float | None = None
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class Sensitivity(Record):
    """A failed mandatory requirement's margin and what each setting does to it, largest first."""

    requirement: str = ""
    margin_pct: float | None = None
    by_parameter: tuple[ParameterEffect, ...] = key(default=(), read=records(ParameterEffect))
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def most_helpful(self) -> ParameterEffect | None:
        """The first setting whose move grows the margin."""
        return next((b for b in self.by_parameter if (b.delta_margin_pct or 0) > 0), None)


@dataclass(frozen=True, kw_only=True)
class RemedySection(Record):
    """The remedies search: found, already passes or none found, and what it learned on the way."""

    status: str | None = None
    failed: tuple[str, ...] = key(default=(), read=tuple_of(str))
    out_of_reach: tuple[str, ...] = key(default=(), read=tuple_of(str))
    remedy: RemedyCandidate | None = key(default=None, read=optional(RemedyCandidate))
    sensitivities: tuple[Sensitivity, ...] = key(default=(), read=records(Sensitivity))
    extra: FrozenDict = key(factory=FrozenDict)
