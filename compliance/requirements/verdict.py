"""Verdicts: a measured value against a limit -> value, limit, margin, pass/fail.

Conventions (docs/metrics.md, "Verdicts"):
- margin is positive inside the limit and negative outside, in the metric's SI unit;
  for ``within`` it is the distance to the nearer edge;
- margin % = margin / |binding limit| x 100 (the binding limit is the nearer edge for
  ``within``); None when the binding limit is 0;
- a value equal to the limit within a relative 1e-9 (unit conversion round-off, e.g. 1.6 mm
  against 1 % of a 0.160 m stroke) counts as exactly at the limit: ``<=``/``>=``/``within``
  pass, ``<``/``>`` fail.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from enum import StrEnum

COMPARATORS = ("<=", "<", ">=", ">", "within")
EQUAL_REL_TOL = 1e-9  # round-off of unit conversions; far below any measurement resolution



class Status(StrEnum):
    """Status of one requirement row or requirement, spelt as in the results JSON."""

    PASS = "pass"
    FAIL = "fail"
    NOT_EVALUATED = "not_evaluated"  # no value (the reason says why)
    OPEN = "open"  # no limit set (a purchaser's data-sheet value nobody filled in)
    DISABLED = "disabled"
    UNCERTAIN = "uncertain"  # the value's uncertainty band straddles the limit (compliance.campaign.uncertainty)


class Overall(StrEnum):
    """Verdict of a whole run (results ``summary.status``, a regression gate's ``status``)."""

    PASS = "pass"
    FAIL = "fail"
    INCOMPLETE = "incomplete"  # nothing mandatory fails, but something mandatory is not evidence


class Basis(StrEnum):
    """How a verdict's value is known (compliance.campaign.basis)."""

    MODELLED = "modelled"  # the model predicts it from the plant's parameters
    BY_CONSTRUCTION = "by_construction"  # a parameter was derived to give this figure: not evidence
    ASSUMED = "assumed"  # it rests on an assumed input (e.g. the load curve) more than on the servo
    MEASURED = "measured"  # taken from a recording of the machine (compliance.acceptance)
    NOT_EVALUATED = "not_evaluated"  # no value


class Severity(StrEnum):
    """Whether a requirement decides the run's verdict (a requirement file's ``severity``)."""

    MANDATORY = "mandatory"  # a failure fails the run
    ADVISORY = "advisory"  # reported beside the verdict, never deciding it


@dataclass(frozen=True)
class Verdict:
    """A value judged against a limit (all SI)."""

    value: float | None
    comparator: str
    limit: tuple[float, ...]
    margin: float | None
    margin_pct: float | None
    status: Status
    reason: str | None = None

    def as_dict(self) -> dict:
        """Plain-JSON form."""
        return {**asdict(self), "limit": list(self.limit)}


def _equal(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=EQUAL_REL_TOL, abs_tol=0.0) or a == b


def evaluate(value: float | None, comparator: str, limit, reason: str | None = None) -> Verdict:
    """Judge ``value`` against ``limit``.

    Parameters
    ----------
    value : float or None
        Measured value in SI; None = could not be measured (``reason`` says why).
    comparator : {"<=", "<", ">=", ">", "within"}
    limit : float or tuple of float
        SI limit; a (low, high) pair for ``within``.
    reason : str, optional
        Why the value is missing.

    Returns
    -------
    Verdict
    """
    if comparator not in COMPARATORS:
        raise ValueError(f"unknown comparator {comparator!r}")
    lim = tuple(float(v) for v in (limit if isinstance(limit, (tuple, list)) else (limit,)))
    if comparator == "within":
        if len(lim) != 2 or lim[0] > lim[1]:
            raise ValueError("'within' needs (low, high) with low <= high")
    elif len(lim) != 1:
        raise ValueError(f"comparator {comparator!r} takes one limit")
    if value is None or not math.isfinite(value):
        return Verdict(None, comparator, lim, None, None, Status.NOT_EVALUATED, reason or "no value")
    v = float(value)
    if comparator in ("<=", "<"):
        binding = lim[0]
        at = _equal(v, binding)
        margin = 0.0 if at else binding - v
        ok = (margin >= 0.0) if comparator == "<=" else (margin > 0.0 and not at)
    elif comparator in (">=", ">"):
        binding = lim[0]
        at = _equal(v, binding)
        margin = 0.0 if at else v - binding
        ok = (margin >= 0.0) if comparator == ">=" else (margin > 0.0 and not at)
    else:
        lo, hi = lim
        m_lo = 0.0 if _equal(v, lo) else v - lo
        m_hi = 0.0 if _equal(v, hi) else hi - v
        margin, binding = (m_lo, lo) if m_lo <= m_hi else (m_hi, hi)
        ok = margin >= 0.0
    pct = None if binding == 0.0 else 100.0 * margin / abs(binding)
    return Verdict(v, comparator, lim, margin, pct, Status.PASS if ok else Status.FAIL, None)


def _badness(v: Verdict) -> tuple:
    """Sort key: fails first, then the smallest margin (in % when known)."""
    m = v.margin_pct if v.margin_pct is not None else v.margin
    if m is None:  # a fail without a margin is a step that never responded: the worst of all
        m = -math.inf if v.status == Status.FAIL else math.inf
    return (0 if v.status == Status.FAIL else 1, m)


def worst_index(verdicts) -> int | None:
    """Index of the worst evaluated verdict (a fail with the most negative margin, else the
    smallest margin); None if none was evaluated."""
    ev = [(i, v) for i, v in enumerate(verdicts) if v.status in (Status.PASS, Status.FAIL)]
    if not ev:
        return None
    return min(ev, key=lambda iv: _badness(iv[1]))[0]


def requirement_status(verdicts) -> Status:
    """Status of one requirement from its rows: fail if any row fails; pass if every row was
    evaluated and passed; not_evaluated if any row could not be evaluated and none failed."""
    st = [v.status for v in verdicts]
    if not st:
        return Status.NOT_EVALUATED
    if Status.FAIL in st:
        return Status.FAIL
    if Status.NOT_EVALUATED in st:
        return Status.NOT_EVALUATED
    return Status.PASS


def overall_status(items) -> Overall:
    """Overall verdict from (severity, status) or (severity, status, basis) tuples.

    ``fail`` if a mandatory requirement fails; ``incomplete`` if none fails but a mandatory
    requirement could not be evaluated, is UNCERTAIN (its band straddles the limit), or passes
    only by construction (the configuration was tuned to give the figure, or the model lacks the
    physics that could make it fail: not evidence); ``pass`` otherwise. Advisory requirements and
    requirements whose limit is still open (a purchaser's data-sheet value nobody set) are
    reported but do not decide the verdict.
    """
    mand = [(it[1], it[2] if len(it) > 2 else None) for it in items if it[0] == Severity.MANDATORY]
    st = [s for s, _ in mand]
    if Status.FAIL in st:
        return Overall.FAIL
    if (Status.NOT_EVALUATED in st or Status.UNCERTAIN in st
            or any(s == Status.PASS and b == Basis.BY_CONSTRUCTION for s, b in mand)):
        return Overall.INCOMPLETE
    return Overall.PASS
