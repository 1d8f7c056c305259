"""Small typed results for tests of their readers (the gate, the terminal table): only what a test names."""

from __future__ import annotations

from compliance.requirements.verdict import Overall, Severity, Status
from compliance.results import (CheckResult, Counts, PlantRecord, RequirementSetRecord, RequirementVerdict, RowTexts,
                                Summary, VerdictRow, WorstCase)


def verdict(rid: str, status: str, margin_pct=None, value=1.0, *, metric="m", limit_text="<= 1", severity="mandatory",
            reasons=(), display=None) -> RequirementVerdict:
    """A requirement's verdict whose worst case has ``margin_pct`` and ``value``; one row per reason given."""
    rows = tuple(VerdictRow(procedure="steps-5", operating_point="mid", run="steps-5@mid", status=Status(status), reason=r)
                 for r in reasons)
    worst = WorstCase(margin_pct=margin_pct, value=value, display=RowTexts(value=display or f"{value}"))
    return RequirementVerdict(id=rid, title=rid, metric=metric, limit_text=limit_text, severity=Severity(severity),
                              status=Status(status), rows=rows, worst=worst)


def result(*entries: RequirementVerdict, digest: str = "d1", status: str = "pass") -> CheckResult:
    """A check result of plant ``p`` against requirement set ``r`` (file digest ``digest``)."""
    return CheckResult(plant=PlantRecord(name="p", digest="x", path="p.toml", parameters=()),
                       requirement_set=RequirementSetRecord(name="r", digest=digest, path="r.toml", requirements=()),
                       summary=Summary(status=Overall(status), counts=Counts()), requirements=tuple(entries))
