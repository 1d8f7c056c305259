"""A verdict row of a site: the measured cases of one recording at one procedure x operating point, judged with their uncertainty.

Each case's figure is judged against the limit (``requirements.verdict.evaluate``) and so are the
two ends of its uncertainty interval: when they disagree the case is UNCERTAIN - the log cannot
tell on which side of the limit the machine lies. The row keeps the worst case (the same order
as ``check``: fails first, then the smallest margin); it FAILS when a case fails beyond its
uncertainty, is UNCERTAIN when none does but one straddles the limit, and is NOT EVALUATED with
the reasons when no case can measure what the requirement asks.
"""

from __future__ import annotations

from compliance.acceptance.measure.uncertainty import Measured
from compliance.presentation.values import metric_text
from compliance.requirements.verdict import Status, Verdict, evaluate, worst_index

__all__ = ["judge_cases", "with_uncertainty"]


def with_uncertainty(m: Measured, comparator: str, limit) -> tuple[Verdict, Status]:
    """The verdict of a measured value and its status with the uncertainty (UNCERTAIN when the interval straddles the limit)."""
    v = evaluate(m.value, comparator, limit, m.reason)
    if v.status not in (Status.PASS, Status.FAIL) or m.u <= 0.0:
        return v, v.status
    ends = {evaluate(m.low, comparator, limit).status, evaluate(m.high, comparator, limit).status, v.status}
    return v, (Status.UNCERTAIN if len(ends) > 1 else v.status)


def _sample(case, m: Measured, metric: str) -> dict:
    return {"label": case.label, "recording": case.recording, "value": m.value, "u": m.u,
            "display": metric_text(m.value, metric, unicode=False), "eligible": m.eligible, "reason": m.reason,
            "budget": dict(m.budget), "detail": {k: v for k, v in case.conditions.items() if not isinstance(v, (list, dict))}}


def _not_evaluated(base: dict, comparator: str, limit, reasons) -> dict:
    text = "; ".join(sorted({r for r in reasons if r})) or "no figure of this metric in the test"
    return {**base, "value": None, "u": None, "comparator": comparator, "limit": None if limit is None else list(limit),
            "margin": None, "margin_pct": None, "status": Status.NOT_EVALUATED, "reason": text, "which": None}


def _open_row(base: dict, req, usable) -> dict:
    pick = (min if req.comparator in (">=", ">") else max)(usable, key=lambda cm: cm[1].value)
    return {**base, "value": pick[1].value, "u": pick[1].u, "comparator": req.comparator, "limit": None, "margin": None,
            "margin_pct": None, "status": Status.OPEN, "reason": None, "which": pick[0].label}


def judge_cases(req, limit, base: dict, pairs: list) -> dict:
    """One verdict row from ``pairs`` of (case, Measured) (see the module docstring).

    Parameters
    ----------
    req : Requirement
    limit : tuple of float or None
        The SI limit (None when open).
    base : dict
        ``procedure``, ``operating_point``, ``run`` (the recording) and the row's departures.
    pairs : list of (Case, Measured)
    """
    samples = [_sample(c, m, req.metric) for c, m in pairs]
    usable = [(c, m) for c, m in pairs if m.eligible and m.value is not None]
    silent = [(c, m) for c, m in pairs if m.eligible and m.value is None]
    if silent and req.limit is not None and req.comparator in ("<=", "<", "within"):
        c, m = silent[0]
        v = Verdict(None, req.comparator, tuple(limit), None, None, Status.FAIL,
                    f"{c.label} did not respond ({m.reason}): the worst case, beyond any upper limit")
        return {**base, **v.as_dict(), "u": None, "which": c.label, "samples": samples, "non_responding": [c.label]}
    if not usable:
        return {**_not_evaluated(base, req.comparator, limit, [m.reason for _, m in pairs]), "samples": samples}
    if req.limit is None:
        return {**_open_row(base, req, usable), "samples": samples}
    judged = [(c, m, *with_uncertainty(m, req.comparator, limit)) for c, m in usable]
    w = worst_index([v for _, _, v, _ in judged])
    c, m, v, _ = judged[w]
    statuses = {s for *_, s in judged}
    status = Status.FAIL if Status.FAIL in statuses else Status.UNCERTAIN if Status.UNCERTAIN in statuses else Status.PASS
    straddling = [cc.label for cc, _, _, s in judged if s == Status.UNCERTAIN]
    reason = None if status != Status.UNCERTAIN else (
        f"the measurement uncertainty straddles the limit: {', '.join(straddling)}")
    return {**base, **v.as_dict(), "status": status, "reason": reason, "u": m.u, "which": c.label, "samples": samples}
