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
    """Judged test cases evaluated, excluded and not evaluated, on the one basis :data:`CASES_BASIS`.

    Parameters
    ----------
    entries : list of dict
        Requirement entries of the results (each with ``limit`` and ``rows``).

    Returns
    -------
    dict
        ``{"rows", "evaluated", "excluded", "not_evaluated", "basis"}``: a case is evaluated when its
        verdict row is PASS, FAIL or UNCERTAIN (a value was judged against the limit), excluded when an
        eligibility rule the requirement states excluded every value of it (``judge.EVALUATION_RULE``:
        not a gap), not evaluated otherwise (a failed run, a missing value).
    """
    rows = [r for e in entries if e.get("limit") is not None for r in e["rows"]]
    evaluated = sum(1 for r in rows if r.get("status") in (Status.PASS, Status.FAIL, Status.UNCERTAIN))
    excluded = sum(1 for r in rows if r.get("status") == Status.NOT_EVALUATED and r.get("excluded"))
    return {"rows": len(rows), "evaluated": evaluated, "excluded": excluded,
            "not_evaluated": len(rows) - evaluated - excluded, "basis": CASES_BASIS}


def case_coverage_text(cov: dict) -> str:
    """``"91 of 115 judged test cases evaluated, 24 excluded by an eligibility rule, 0 not evaluated"``."""
    n, ex = cov["rows"], cov.get("excluded") or 0
    ne = cov.get("not_evaluated", n - cov["evaluated"] - ex)
    return (f"{cov['evaluated']} of {n} judged test cases evaluated, "
            + (f"{ex} excluded by an eligibility rule, " if ex else "") + f"{ne} not evaluated")


def _judged_pairs(entries) -> tuple[set[tuple[str, str]], dict]:
    """(run id, request key) of every row that judged a value against a limit, and the reasons of the rows
    that did not (open limit, every value excluded, no value) by the same pair."""
    judged, other = set(), {}
    for e in entries:
        for r in e["rows"]:
            pair = (r["run"], e["request_key"])
            if r.get("status") in (Status.PASS, Status.FAIL, Status.UNCERTAIN):
                judged.add(pair)
            elif r.get("status") == Status.OPEN:
                other.setdefault(pair, []).append(f"{e['id']} has no limit (open: the purchaser's data sheet); its value is reported")
            elif r.get("excluded"):
                other.setdefault(pair, []).append(f"{e['id']}: every value excluded by its eligibility rule ({r['excluded']})")
            else:
                other.setdefault(pair, []).append(f"{e['id']}: {r.get('reason') or 'no value'}")
    return judged, other


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
    """Every (run, metric request) with a computed value that no verdict row judged against a limit, with the reason
    (no row, or rows that are open, excluded or not evaluated: their own reasons).

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
    judged, other = _judged_pairs(entries)
    out = []
    for job, o in zip(jobs, outcomes):
        for key, samples in o.samples.items():
            n = sum(1 for s in samples if s.value is not None)
            if n == 0 or (job.key, key) in judged:
                continue
            why = "; ".join(dict.fromkeys(other[(job.key, key)])) if (job.key, key) in other else \
                _why_not(reqset, job.key, key, samples, o.error)
            out.append({"run": job.key, "metric": key, "values": n, "reason": why})
    return out
