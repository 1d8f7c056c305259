"""Coverage of a campaign: every metric value a run computed is judged, or the results say why not.

The judge turns requirement x run into verdict rows; this module walks every run's metric values
the other way round and lists each (run, metric) that no row judged, with the reason: no
requirement limits that metric, the requirement judges it on other procedures or with other
options, the file says the limit does not apply at that operating point, or no value of the run
is eligible (each sample's own reason). docs/results-schema.md, ``coverage``.
"""

from __future__ import annotations

from compliance.procedures.outcomes import request_key
from compliance.results.keys import RequestKey
from compliance.requirements.verdict import Status

__all__ = ["CASES_BASIS", "case_coverage", "case_coverage_text", "unjudged"]

# the one basis of every count of test cases (terminal summary, results JSON, report page 1)
CASES_BASIS = ("a judged test case is one requirement \u00d7 procedure \u00d7 operating point of a requirement with a limit; "
               "open requirements (no limit) are not counted")


def case_coverage(entries: list[dict]) -> dict:
    """Judged test cases evaluated and not evaluated, on the one basis :data:`CASES_BASIS`.

    Parameters
    ----------
    entries : list of dict
        Requirement entries of the results (each with ``limit`` and ``rows``).

    Returns
    -------
    dict
        ``{"rows", "evaluated", "not_evaluated", "basis"}``: a case is evaluated when its verdict
        row is PASS, FAIL or UNCERTAIN (a value was judged against the limit).
    """
    rows = [r for e in entries if e.get("limit") is not None for r in e["rows"]]
    evaluated = sum(1 for r in rows if r.get("status") in (Status.PASS, Status.FAIL, Status.UNCERTAIN))
    return {"rows": len(rows), "evaluated": evaluated, "not_evaluated": len(rows) - evaluated, "basis": CASES_BASIS}


def case_coverage_text(cov: dict) -> str:
    """``"87 of 111 judged test cases evaluated, 24 not evaluated"`` from :func:`case_coverage`."""
    n = cov["rows"]
    ne = cov.get("not_evaluated", n - cov["evaluated"])
    return f"{cov['evaluated']} of {n} judged test cases evaluated, {ne} not evaluated"


def _judged_pairs(entries) -> set[tuple[str, str]]:
    """(run id, request key) of every verdict row."""
    out = set()
    for e in entries:
        for r in e["rows"]:
            out.add((r["run"], e["request_key"]))
    return out


def _why_not(reqset, run_id: str, key: str, samples, error) -> str:
    """Why no requirement judged metric request ``key`` of run ``run_id``."""
    metric = RequestKey.parse(key).metric
    proc, op = run_id.split("@", 1)
    on_metric = [r for r in reqset.requirements if r.metric == metric]
    if not on_metric:
        return f"no requirement of {reqset.name} limits {metric}; reported for information"
    reasons = []
    for r in on_metric:
        if not r.enabled:
            reasons.append(f"{r.id} is disabled")
        elif r.source != "simulation":
            reasons.append(f"{r.id} judges the linearised model, not this run")
        elif proc not in r.procedures:
            reasons.append(f"{r.id} judges {metric} on {', '.join(r.procedures)} only")
        elif op in r.not_applicable:
            reasons.append(f"{r.id} does not apply at {op}: {r.not_applicable[op]}")
        elif request_key(r.metric, r.options) != key:
            reasons.append(f"{r.id} judges {request_key(r.metric, r.options)}; this value uses the default options "
                           "and is kept for the report")
        elif error:
            reasons.append(f"{r.id}: the run failed: {error}")
        else:
            why = sorted({s.reason for s in samples if s.reason}) or ["no value"]
            reasons.append(f"{r.id}: no eligible value here ({'; '.join(why)})")
    return "; ".join(dict.fromkeys(reasons))


def unjudged(reqset, jobs, outcomes, entries) -> list[dict]:
    """Every (run, metric request) with a computed value that no verdict row judged, with the reason.

    Parameters
    ----------
    reqset : RequirementSet
    jobs, outcomes : list
        The campaign's runs and what they produced (same order).
    entries : list of dict
        The judge's requirement entries (each with ``request_key`` and ``rows``).

    Returns
    -------
    list of dict
        ``{"run", "metric", "values", "reason"}``; ``values`` counts the computed values.
    """
    judged = _judged_pairs(entries)
    out = []
    for job, o in zip(jobs, outcomes):
        for key, samples in o.samples.items():
            n = sum(1 for s in samples if s.value is not None)
            if n == 0 or (job.key, key) in judged:
                continue
            out.append({"run": job.key, "metric": key, "values": n, "reason": _why_not(reqset, job.key, key, samples, o.error)})
    return out
