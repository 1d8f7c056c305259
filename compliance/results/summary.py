"""A check's summary: the overall verdict, the counts behind it and what a PASS rests on.

docs/results-schema.md, ``summary``; the qualifier words are ``compliance.campaign.basis``'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from compliance.requirements.verdict import Overall
from compliance.results.record import FrozenDict, Record, enum_of, key, records, tuple_of

__all__ = ["CaseCoverage", "Counts", "Qualifier", "Summary", "TopAssumption"]


class Qualifier(StrEnum):
    """What an overall PASS rests on when it is not the plant's evidence against a real limit."""

    ASSUMED_TARGETS = "against assumed targets"  # a passing mandatory requirement's limit is an assumed target
    ASSUMED_MODEL = "on a mostly assumed model"  # more than half of the parameters the model uses are assumed


def _qualifiers(v, where) -> tuple[Qualifier, ...]:
    """``"against assumed targets, on a mostly assumed model"`` -> both members (the JSON joins them)."""
    if v is None:
        return ()
    read = enum_of(Qualifier)
    return tuple(read(part, where) for part in str(v).split(", ") if part)


def _qualifier_text(v) -> str | None:
    return ", ".join(q.value for q in v) or None


@dataclass(frozen=True, kw_only=True)
class Counts(Record):
    """Requirements per status; a pass by construction and advisory failures counted apart."""

    passed: int = key("pass", default=0)  # modelled evidence only
    fail: int = key(default=0)
    not_evaluated: int = key(default=0)
    open: int = key(default=0)
    disabled: int = key(default=0)
    uncertain: int = key(default=0)
    pass_by_construction: int = key(default=0)
    fail_mandatory: int = key(default=0)
    fail_advisory: int = key(default=0)


@dataclass(frozen=True, kw_only=True)
class CaseCoverage(Record):
    """Judged test cases evaluated, excluded by an eligibility rule and not evaluated, on the one basis
    (``compliance.campaign.coverage.CASES_BASIS``)."""

    rows: int = key(default=0)
    evaluated: int = key(default=0)
    excluded: int | None = key(omit_none=True, default=None)  # every value excluded by a stated eligibility rule
    not_evaluated: int = key(default=0)
    basis: str = key(default="")


@dataclass(frozen=True, kw_only=True)
class TopAssumption(Record):
    """A ranged parameter that matters most: its largest swing relative to a verdict's margin."""

    parameter: str = key()
    score: float = key(default=0.0)
    why: str = key(default="")
    range: FrozenDict | None = key(default=None)


@dataclass(frozen=True, kw_only=True)
class Summary(Record):
    """The overall verdict, the counts, the ids by outcome, coverage and the assumptions that matter most."""

    status: Overall = key(read=enum_of(Overall))
    counts: Counts = key(read=Counts.from_dict)
    failed: tuple[str, ...] = key(default=(), read=tuple_of(str))
    failed_mandatory: tuple[str, ...] = key(default=(), read=tuple_of(str))
    not_evaluated: tuple[str, ...] = key(default=(), read=tuple_of(str))
    open: tuple[str, ...] = key(default=(), read=tuple_of(str))
    passed_by_construction: tuple[str, ...] = key(default=(), read=tuple_of(str))
    uncertain: tuple[str, ...] = key(default=(), read=tuple_of(str))
    coverage: CaseCoverage | None = key(default=None, read=CaseCoverage.from_dict)
    top_assumptions: tuple[TopAssumption, ...] = key(default=(), read=records(TopAssumption))
    notes: tuple[str, ...] = key(default=(), read=tuple_of(str))
    # the bands were judged on plants commissioned as on site (campaign.uncertainty, [commissioning]): what that means
    commissioned: str | None = key(omit_none=True, default=None)
    qualifiers: tuple[Qualifier, ...] = key("qualifier", default=(), read=_qualifiers, write=_qualifier_text)
    extra: FrozenDict = key(factory=FrozenDict)  # a site's partial requirements and agreement with the model
