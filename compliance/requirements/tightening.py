"""Inherited requirements may only be tightened: the check across a file's ``extends`` chain.

Each file's limit must accept a subset of what the file before it accepted; lowering the
severity or disabling a requirement is a loosening too. A file that means it says
``allow_loosen = true``, and the loosening is reported.
"""

from __future__ import annotations

import math

from compliance.errors import InputError
from compliance.requirements.requirement_set import Requirement, format_limit
from compliance.requirements.verdict import Severity

__all__ = ["check_tightening"]


def _interval(comparator: str, limits: tuple[float, ...]) -> tuple[float, float]:
    if comparator in ("<=", "<"):
        return (-math.inf, limits[0])
    if comparator in (">=", ">"):
        return (limits[0], math.inf)
    return (limits[0], limits[1])


def check_tightening(req: Requirement, stroke: float) -> list[str]:
    """Check that every override tightened the requirement; return notes on allowed loosening.

    Each file's limit must accept a subset of what the file before it accepted, severity may
    not drop from mandatory to advisory and a requirement may not be disabled, unless that
    file says ``allow_loosen = true``.

    Raises
    ------
    InputError
        When a file loosens a requirement without ``allow_loosen = true``.
    """
    notes = []
    for prev, cur in zip(req.history, req.history[1:]):
        problems = []
        if prev.limit is not None and cur.limit is None:
            problems.append("re-opens a limit that was set")
        elif prev.limit is not None and cur.limit is not None:
            a = _interval(prev.comparator, tuple(x.resolve(stroke) for x in prev.limit))
            b = _interval(cur.comparator, tuple(x.resolve(stroke) for x in cur.limit))
            tol = 1e-9 * max(1.0, *(abs(v) for v in (*a, *b) if math.isfinite(v)))
            if b[0] < a[0] - tol or b[1] > a[1] + tol:
                problems.append(f"widens the limit from {format_limit(prev.comparator, prev.limit, 'open')} "
                                f"to {format_limit(cur.comparator, cur.limit, 'open')}")
        if prev.severity == Severity.MANDATORY and cur.severity == Severity.ADVISORY:
            problems.append("lowers the severity from mandatory to advisory")
        if prev.enabled and not cur.enabled:
            problems.append("disables it")
        if problems:
            msg = f"{cur.file}: requirements.{req.id}: {'; '.join(problems)} (set by {prev.file})"
            if not cur.allow_loosen:
                raise InputError(msg + "; a file may only tighten an inherited requirement unless it says allow_loosen = true")
            notes.append("LOOSENED: " + msg)
    return notes
