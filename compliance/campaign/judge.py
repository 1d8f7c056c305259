"""Judging a campaign: every requirement x procedure x operating point becomes a verdict row.

A run offers candidate values (``Sample``) of each metric; the row keeps the worst eligible
one against the limit (``compliance.requirements.verdict``), or, for an open limit (the purchaser's
data-sheet value), the least favourable value with no verdict. A requirement's status
combines its rows by the evaluation rule (:data:`EVALUATION_RULE`): a row whose every value was
excluded by a stated eligibility rule (a ramped, saturated, rate-limited or dead-zone dominated
step) is an *excluded case*, not a gap. Values are also formatted in each metric's display unit.
"""

from __future__ import annotations

from compliance.campaign.basis import limit_assumed, requirement_basis, row_basis
from compliance.campaign.plan import Job
from compliance.requirements.tightening import check_tightening
from compliance.linear.requirement_values import linear_value
from compliance.metrics.catalogue import METRICS
from compliance.presentation.values import metric_text, resolved_limit, row_texts
from compliance.requirements.requirement_set import RequirementSet
from compliance.procedures.outcomes import Sample, request_key
from compliance.requirements.verdict import Basis, Status, Verdict, evaluate, worst_index

__all__ = ["EVALUATION_RULE", "evaluated_status", "explain_fails_under_uncertain", "judge", "judge_row", "sample_dict"]

# docs/requirements.md, "When a requirement is evaluated"
EVALUATION_RULE = ("a requirement is evaluated when every operating point it lists has at least one evaluated case "
                   "(procedure x point row) and every other case is either evaluated or excluded by a stated eligibility "
                   "rule (ramped, saturated, rate limited, dead-zone dominated, not from rest); it fails when any evaluated "
                   "case fails; a case that could not be measured (a failed run, a missing value) leaves it not evaluated")

# keys of the worst row copied into a requirement's entry
_WORST_KEYS = ("run", "procedure", "operating_point", "value", "margin", "margin_pct", "status", "which", "display",
               "basis", "basis_reason", "non_responding")


def sample_dict(s: Sample, metric: str) -> dict:
    """Plain-JSON form of one candidate value, with its display text."""
    return {"label": s.label, "value": s.value, "display": metric_text(s.value, metric, unicode=False), "eligible": s.eligible,
            "reason": s.reason, "detail": s.detail}


def _least_favourable(comparator: str, items, value):
    """The item whose value is worst under ``comparator``: the smallest for >= / >, else the largest."""
    return (min if comparator in (">=", ">") else max)(items, key=value)


def _open_pick(comparator: str, samples: list[Sample]):
    vals = [s for s in samples if s.eligible and s.value is not None]
    if not vals:
        return None
    return _least_favourable(comparator, vals, lambda s: s.value)


def judge_row(req, proc: str, op: str, limit, samples, error: str | None) -> dict:
    """One verdict row of ``req`` at ``proc@op`` from a run's candidate values (the worst eligible one decides)."""
    base = {"procedure": proc, "operating_point": op, "run": f"{proc}@{op}"}
    if error:
        v = Verdict(None, req.comparator, limit or (), None, None, Status.NOT_EVALUATED, error)
        return {**base, **v.as_dict(), "which": None, "samples": []}
    samples = samples or []
    shown = [sample_dict(s, req.metric) for s in samples]
    usable = [s for s in samples if s.eligible and s.value is not None]
    silent = [s for s in samples if s.eligible and s.value is None and (s.detail or {}).get("non_responding")]
    if silent:
        return _non_responding_row(req, base, limit, silent, shown)
    if req.limit is None:
        pick = _open_pick(req.comparator, samples)
        return {**base, "value": pick.value if pick else None, "comparator": req.comparator, "limit": None,
                "margin": None, "margin_pct": None, "status": Status.OPEN,
                "reason": None if pick else _why(samples), "which": pick.label if pick else None,
                "samples": shown}
    if not usable:
        v = Verdict(None, req.comparator, limit, None, None, Status.NOT_EVALUATED, _why(samples))
        row = {**base, **v.as_dict(), "which": None, "samples": shown}
        if samples and all(not s.eligible for s in samples):  # every value excluded by a stated rule: an excluded case
            row["excluded"] = _excluded_text(samples)
        return row
    verdicts = [evaluate(s.value, req.comparator, limit) for s in usable]
    w = worst_index(verdicts)
    row = {**base, **verdicts[w].as_dict(), "which": usable[w].label, "samples": shown}
    flag = (usable[w].detail or {}).get("flag")
    if flag:  # the value was taken by a fallback the reading names (e.g. a stroke with no straight part timed end to end)
        row["flag"] = flag
    excluded = [s for s in samples if not s.eligible]
    if excluded:
        row["excluded"] = _excluded_text(excluded)
    return row


def _non_responding_row(req, base: dict, limit, silent, shown) -> dict:
    """A step that never responded is the worst case: beyond any upper limit (a fail), the value shown as none."""
    s = silent[0]
    why = f"{s.label} did not respond ({s.reason}): the worst case"
    labels = [x.label for x in silent]
    if req.limit is None or req.comparator not in ("<=", "<", "within"):
        return {**base, "value": None, "comparator": req.comparator, "limit": None if req.limit is None else list(limit),
                "margin": None, "margin_pct": None, "status": Status.OPEN if req.limit is None else Status.NOT_EVALUATED,
                "reason": why, "which": s.label, "samples": shown, "non_responding": labels}
    v = Verdict(None, req.comparator, tuple(limit), None, None, Status.FAIL, why + ", beyond any upper limit")
    return {**base, **v.as_dict(), "which": s.label, "samples": shown, "non_responding": labels}


def _excluded_text(samples) -> str:
    """"<label>: <rule's reason>" of every excluded value, joined."""
    return "; ".join(f"{s.label}: {s.reason}" for s in samples if not s.eligible)


def evaluated_status(req, rows: list[dict], verdicts) -> Status:
    """Status of a requirement with a limit from its rows by :data:`EVALUATION_RULE`."""
    st = [v.status for v in verdicts]
    if Status.FAIL in st:
        return Status.FAIL
    evaluated = [r for r, v in zip(rows, verdicts) if v.status == Status.PASS]
    gaps = [r for r, v in zip(rows, verdicts) if v.status == Status.NOT_EVALUATED and not r.get("excluded")]
    listed = [r for r in rows if not r.get("extended")]
    covered = {r["operating_point"] for r in evaluated if not r.get("extended")}
    if not rows or gaps or any(o not in covered for o in {r["operating_point"] for r in listed}):
        return Status.NOT_EVALUATED
    return Status.PASS


def _why(samples) -> str:
    reasons = sorted({s.reason for s in samples if s.reason})
    return "; ".join(reasons) if reasons else "no sample of this metric in the run"


def _row_verdict(req, r: dict) -> Verdict:
    return Verdict(r["value"], req.comparator, tuple(r["limit"] or ()), r["margin"], r["margin_pct"], r["status"], r["reason"])


def _rows(cfg, reqset: RequirementSet, req, limit, by_key: dict) -> list[dict]:
    """Verdict rows of an enabled requirement: one per operating point (linear) or per run."""
    rows = []
    if req.source == "linear":
        for o in req.operating_points:
            val, why = linear_value(cfg, req.metric, reqset.operating_points[o])
            s = [Sample(val, "linearised model", why)]
            rows.append(judge_row(req, "linear", o, limit, s, None))
    else:
        key = request_key(req.metric, req.options)
        for p in req.procedures:
            for o in req.operating_points:
                out = by_key[f"{p}@{o}"]
                rows.append(judge_row(req, p, o, limit, out.samples.get(key), out.error))
        rows.extend(_extended_rows(req, limit, by_key, key))
    for r in rows:
        r["basis"], r["basis_reason"] = row_basis(cfg, reqset, req, r)
    return rows


def _extended_rows(req, limit, by_key: dict, key: str) -> list[dict]:
    """Rows at operating points the requirement does not list where another requirement's run computed its
    metric with one of its procedures: a computed figure is judged by every limit that applies there.

    A point the requirement names in ``not_applicable`` is left out (the coverage gives its reason), as is a
    run without an eligible value (the coverage gives the samples' reasons).
    """
    rows = []
    for run_key, out in by_key.items():
        p, o = run_key.split("@", 1)
        if p not in req.procedures or o in req.operating_points or o in req.not_applicable or out.error:
            continue
        samples = out.samples.get(key) or []
        if not any(s.eligible and s.value is not None for s in samples):
            continue
        row = judge_row(req, p, o, limit, samples, None)
        row["extended"] = (f"{req.metric} was computed at {o} (a run another requirement asked for); {req.id} applies "
                           f"wherever its metric is computed unless its file says why not (not_applicable)")
        rows.append(row)
    return rows


def judge(cfg, reqset: RequirementSet, jobs: list[Job], outcomes, loosened: dict | None = None) -> tuple[list[dict], list[str]]:
    """Verdict entries per requirement (docs/results-schema.md, ``requirements_results``).

    ``loosened``: requirement id -> loosening notes of the vetted set (``requirements.vetting.vet``);
    without it (a sweep judging candidates) each requirement's history is checked here.
    """
    stroke = cfg.p("cylinder.stroke")
    by_key = {j.key: o for j, o in zip(jobs, outcomes)}
    entries, notes = [], []
    for req in reqset.requirements:
        loosen = list(loosened[req.id]) if loosened is not None else check_tightening(req, stroke)
        notes.extend(loosen)
        limit = req.resolved_limit(stroke) if req.limit is not None else None
        rows = _rows(cfg, reqset, req, limit, by_key) if req.enabled else []
        for r in rows:
            r["display"] = row_texts(r, req.metric, unicode=False)
        verdicts = [_row_verdict(req, r) for r in rows] if req.limit is not None else []
        if not req.enabled:
            status = Status.DISABLED
        elif req.limit is None:
            status = Status.OPEN
        else:
            status = evaluated_status(req, rows, verdicts)
        worst = None
        if rows and req.limit is not None:
            wi = worst_index(verdicts)
            worst = None if wi is None else rows[wi]
        elif rows:
            vals = [r for r in rows if r["value"] is not None]
            silent = [r for r in rows if r.get("non_responding")]
            if silent:  # an open limit still shows its worst case: a step that never responded
                worst = silent[0]
            elif vals:
                worst = _least_favourable(req.comparator, vals, lambda r: r["value"])
        entries.append({
            "id": req.id,
            "title": req.title,
            "standard": req.standard,
            "clause": req.clause,
            "metric": req.metric,
            "request_key": request_key(req.metric, req.options),
            "unit": METRICS[req.metric].si_unit,
            "display_unit": METRICS[req.metric].display_unit,
            "comparator": req.comparator,
            "limit": list(limit) if limit is not None else None,
            "limit_text": req.limit_text,
            "limit_display": None if limit is None else resolved_limit(req.comparator, limit, req.metric),
            "severity": req.severity,
            "source": req.source,
            "status": status,
            "worst": None if worst is None else {k: worst.get(k) for k in _WORST_KEYS},
            "rows": rows,
            "basis": requirement_basis(rows) if req.enabled and req.limit is not None else Basis.NOT_EVALUATED,
            "coverage": {"rows": len(rows), "evaluated": sum(1 for r in rows if r.get("status") in (Status.PASS, Status.FAIL)),
                         "excluded": sum(1 for r in rows if r.get("status") == Status.NOT_EVALUATED and r.get("excluded")),
                         "extended": sum(1 for r in rows if r.get("extended"))},
            "reading": req.reading,
            "alternative": req.alternative,
            "own_choice": req.own_choice,
            "limit_assumed": limit_assumed(req),
            "note": req.note,
            "loosened": loosen,
        })
    return entries, notes


def _band_text(band: dict, metric: str) -> str:
    from compliance.presentation.values import metric_text

    return f"[{metric_text(band['low'], metric, unicode=False)} .. {metric_text(band['high'], metric, unicode=False)}]"


def explain_fails_under_uncertain(entries: list[dict]) -> None:
    """Give every FAIL row of an UNCERTAIN requirement the sentence that explains it (``status_note``).

    A requirement is UNCERTAIN when a band straddles its limit; a row may still fail at the plant file's
    values. Unbanded, its note says so and which band made the requirement uncertain; failing across its
    own whole band, it is a certain failure and the requirement is FAIL (entries are updated in place).
    """
    for e in entries:
        if e.get("status") != Status.UNCERTAIN:
            continue
        w = e.get("worst") or {}
        certain = []
        for r in e["rows"]:
            if r.get("status") != Status.FAIL or r.get("status_note"):
                continue
            band = r.get("band")
            if band is None:
                deciding = e.get("band")
                where = f"its deciding row {w.get('run')} ({w.get('which')})"
                r["status_note"] = (
                    f"fails at the plant file's values; this row was not banded itself: {e['id']} is UNCERTAIN because "
                    f"{where} has a band {_band_text(deciding, e['metric']) if deciding else ''} that straddles the limit "
                    "over the declared parameter ranges")
            else:
                r["status_note"] = (f"fails at the plant file's values and over its whole band {_band_text(band, e['metric'])}: "
                                    "a failure whatever the declared ranges")
                certain.append(r)
        if certain:
            e["status"] = Status.FAIL
            e["status_note"] = f"{len(certain)} row(s) fail over their whole band: a failure, not an uncertainty"
