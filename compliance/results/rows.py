"""A verdict row: one requirement judged at one procedure x operating point, with every candidate value.

All numbers are SI (``value``, ``limit``, ``margin``; ``margin_pct`` in % of the binding limit);
``display`` holds the texts the one formatter (``compliance.presentation.values``) made of them
when the row was judged. A row's ``band`` is its value's range over the plant file's declared
parameter ranges (``compliance.campaign.uncertainty``). docs/results-schema.md, ``requirements[]``.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.requirements.verdict import Basis, Status
from compliance.results.record import FrozenDict, Record, enum_of, key, records, tuple_of

__all__ = ["Band", "RowTexts", "SampleRecord", "VerdictRow", "WorstCase"]


@dataclass(frozen=True, kw_only=True)
class SampleRecord(Record):
    """One candidate value of a metric in a run (a step, a stroke, a window) and whether it may decide a verdict."""

    label: str = key()
    value: float | None = key()
    display: str | None = key(default=None)
    eligible: bool = key(default=True)
    reason: str | None = key(default=None)
    detail: FrozenDict = key(factory=FrozenDict)
    extra: FrozenDict = key(factory=FrozenDict)  # keys a site's measured value adds (recording, u, budget)


@dataclass(frozen=True, kw_only=True)
class RowTexts(Record):
    """A row's value, limit, margin and margin in per cent as the terminal and the JSON print them."""

    value: str = key(default="-")
    limit: str | None = key(default=None)
    margin: str = key(default="-")
    margin_pct: str | None = key(default=None)


@dataclass(frozen=True, kw_only=True)
class Band(Record):
    """A value's range over the declared parameter ranges [SI], the margins at its ends [%] and what decides it."""

    low: float | None = key()
    high: float | None = key()
    method: str = key(default="local")
    margin_low_pct: float | None = key(default=None)
    margin_high_pct: float | None = key(default=None)
    straddles: bool | None = key(omit_none=True, default=None)
    deciding: tuple[str, ...] = key(default=(), read=tuple_of(str))
    swings: FrozenDict = key(factory=FrozenDict)  # parameter -> (change at the top of its range, at the bottom) [SI]
    unmeasured: tuple[str, ...] | None = key(omit_none=True, default=None, read=tuple_of(str))


_status = enum_of(Status)
_basis = enum_of(Basis)


@dataclass(frozen=True, kw_only=True)
class VerdictRow(Record):
    """One requirement at one ``procedure@operating_point`` (``procedure = "linear"`` for the linearised model)."""

    procedure: str = key()
    operating_point: str = key()
    run: str = key()
    value: float | None = key(default=None)
    comparator: str = key(default="<=")
    limit: tuple[float, ...] | None = key(default=None)
    margin: float | None = key(default=None)
    margin_pct: float | None = key(default=None)
    status: Status = key(read=_status)
    reason: str | None = key(default=None)
    which: str | None = key(default=None)  # the candidate that decided ("step 2 down 8.00 mm at 5.00 s")
    samples: tuple[SampleRecord, ...] = key(default=(), read=records(SampleRecord))
    non_responding: tuple[str, ...] | None = key(omit_none=True, default=None, read=tuple_of(str))
    flag: str | None = key(omit_none=True, default=None)
    excluded: str | None = key(omit_none=True, default=None)
    extended: str | None = key(omit_none=True, default=None)  # why it is judged at a point it does not list
    basis: Basis | None = key(default=None, read=_basis)
    basis_reason: str | None = key(default=None)
    display: RowTexts = key(factory=RowTexts, read=RowTexts.from_dict)
    band: Band | None = key(omit_none=True, default=None, read=Band.from_dict)
    status_note: str | None = key(omit_none=True, default=None)
    extra: FrozenDict = key(factory=FrozenDict)  # keys a site's measured row adds (departures, u)

    @property
    def judged(self) -> bool:
        """Whether a value was judged against a limit (pass, fail or uncertain)."""
        return self.status in (Status.PASS, Status.FAIL, Status.UNCERTAIN)


@dataclass(frozen=True, kw_only=True)
class WorstCase(Record):
    """The row that decides a requirement, as the requirement's summary line quotes it."""

    run: str | None = key(default=None)
    procedure: str | None = key(default=None)
    operating_point: str | None = key(default=None)
    value: float | None = key(default=None)
    margin: float | None = key(default=None)
    margin_pct: float | None = key(default=None)
    status: Status | None = key(default=None, read=_status)
    which: str | None = key(default=None)
    display: RowTexts | None = key(default=None, read=RowTexts.from_dict)
    basis: Basis | None = key(default=None, read=_basis)
    basis_reason: str | None = key(default=None)
    non_responding: tuple[str, ...] | None = key(default=None, read=tuple_of(str))
    band: Band | None = key(omit_none=True, default=None, read=Band.from_dict)
    extra: FrozenDict = key(factory=FrozenDict)
