"""A requirement's verdict: the requirement as judged, its status, its worst case and every row.

``limit`` is the limit resolved to SI for this plant (two values for ``within``, None when open);
``limit_text`` is as the file writes it and ``limit_display`` the resolved limit in the display unit.
docs/results-schema.md, ``requirements[]``.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.requirements.verdict import Basis, Severity, Status
from compliance.results.keys import RequestKey
from compliance.results.record import FrozenDict, Record, enum_of, key, records, tuple_of
from compliance.results.rows import Band, VerdictRow, WorstCase

__all__ = ["EntryCoverage", "RequirementVerdict"]


def _request_key(v, where):
    return RequestKey.parse(v)


@dataclass(frozen=True, kw_only=True)
class EntryCoverage(Record):
    """A requirement's cases: rows, rows evaluated (pass or fail), excluded by an eligibility rule, extended."""

    rows: int = key(default=0)
    evaluated: int = key(default=0)
    excluded: int | None = key(omit_none=True, default=None)
    extended: int = key(default=0)
    extra: FrozenDict = key(factory=FrozenDict)  # a site's cases asked, tested, not tested, complete


@dataclass(frozen=True, kw_only=True)
class RequirementVerdict(Record):
    """One requirement of the set, judged (docs/results-schema.md, ``requirements[]``)."""

    id: str = key()
    title: str = key()
    standard: str | None = key(default=None)
    clause: str | None = key(default=None)
    metric: str = key()
    request_key: RequestKey = key(default=None, read=_request_key)
    unit: str = key(default="")
    display_unit: str = key(default="")
    comparator: str = key(default="<=")
    limit: tuple[float, ...] | None = key(default=None)
    limit_text: str = key()
    limit_display: str | None = key(default=None)
    severity: Severity = key(read=enum_of(Severity))
    source: str = key(default="simulation")
    status: Status = key(read=enum_of(Status))
    worst: WorstCase | None = key(default=None, read=WorstCase.from_dict)
    rows: tuple[VerdictRow, ...] = key(read=records(VerdictRow))
    basis: Basis | None = key(default=None, read=enum_of(Basis))
    coverage: EntryCoverage | None = key(default=None, read=EntryCoverage.from_dict)
    reading: str | None = key(default=None)
    alternative: str | None = key(default=None)
    own_choice: str | None = key(default=None)
    limit_assumed: bool = key(default=False)
    note: str | None = key(default=None)
    loosened: tuple[str, ...] = key(default=(), read=tuple_of(str))
    band: Band | None = key(omit_none=True, default=None, read=Band.from_dict)
    status_note: str | None = key(omit_none=True, default=None)
    reason: str | None = key(omit_none=True, default=None)  # why a site could not judge it at all
    extra: FrozenDict = key(factory=FrozenDict)  # keys a site's measured verdict adds (measured_metric, prediction)

    def __post_init__(self):
        if self.request_key is None:  # a results file of an older govcheck: the metric with the default options
            object.__setattr__(self, "request_key", RequestKey(self.metric))

    @property
    def judged_rows(self) -> tuple[VerdictRow, ...]:
        """The rows whose value was judged against the limit."""
        return tuple(r for r in self.rows if r.judged)

    @property
    def open(self) -> bool:
        """No limit set (a purchaser's data-sheet value nobody filled in)."""
        return self.limit is None

    def not_evaluated_reasons(self) -> list[str]:
        """The distinct reasons of its rows, sorted."""
        return sorted({r.reason for r in self.rows if r.reason})
