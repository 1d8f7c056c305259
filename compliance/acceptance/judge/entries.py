"""A site's verdict per requirement: its rows, its status, its coverage of the file's procedures x operating points.

Every case measured at the site is offered to every requirement: it becomes a row where it stands
for one of the requirement's procedures at one of its operating points (``judge.mapping``), or an
*extended* row where it ran one of its procedures at another point of the file - or at a point the
file does not name - and gave an eligible figure (as ``check`` judges a computed figure wherever a
limit applies). A requirement FAILS when a row fails beyond its uncertainty, is UNCERTAIN when a
row straddles its limit, NOT EVALUATED when a row could not measure what it asks or nothing it asks
was tested, and PASSES otherwise; the coverage lists what it asks that the site did not test, so a
pass on part of the cases is never silent.
"""

from __future__ import annotations

from compliance.acceptance.judge.mapping import circuit_text, point_match, procedure_match
from compliance.acceptance.judge.readings import measured_key, row_value
from compliance.acceptance.judge.rows import judge_cases
from compliance.metrics.catalogue import METRICS
from compliance.presentation.values import resolved_limit, row_texts
from compliance.requirements.verdict import Basis, Status, Verdict, worst_index

__all__ = ["judge_requirement", "requirement_status"]


def requirement_status(rows: list, limit) -> Status:
    """A requirement's status from its rows (see the module docstring)."""
    if limit is None:
        return Status.OPEN
    st = {r["status"] for r in rows}
    if not rows:
        return Status.NOT_EVALUATED
    for s in (Status.FAIL, Status.UNCERTAIN, Status.NOT_EVALUATED):
        if s in st:
            return s
    return Status.PASS


def _site_point(case) -> str:
    c = case.conditions
    pos = "" if c.get("position") is None else f"{c['position'] * 1e3:.0f} mm, "
    load = c.get("load")
    load = "load curve" if load == "curve" else f"{(load or 0.0) / 1e3:.1f} kN"
    return f"as tested ({pos}{load}, {circuit_text(c.get('flow_control'))})"


def _place(req, reqset, proc, case, cfg):
    """(operating point name, departures, extended) of a case that runs ``proc``; None when it should not count here."""
    best = None
    for o in req.operating_points:
        ok, same_circuit, dep = point_match(reqset.operating_points[o], case, cfg)
        if ok and (best is None or (same_circuit and not best[2])):
            best = (o, dep, same_circuit)
    if best is not None:
        return best[0], best[1], False
    for o, op in reqset.operating_points.items():
        if o in req.not_applicable:
            continue
        ok, same_circuit, dep = point_match(op, case, cfg)
        if ok and same_circuit:
            return o, dep, True
    return _site_point(case), [], True


def _groups(req, reqset, cases: list, cfg) -> dict:
    """(procedure, point, recording) -> (departures, extended, [cases])."""
    listed = [reqset.procedures[p] for p in req.procedures]
    out: dict = {}
    for case in cases:
        for proc in listed:
            ok, dep = procedure_match(proc, case, cfg, listed)
            if not ok:
                continue
            o, pdep, extended = _place(req, reqset, proc, case, cfg)
            key = (proc.name, o, case.recording)
            entry = out.setdefault(key, [set(), extended, []])
            entry[0].update(dep + pdep)
            entry[2].append(case)
            break
    return out


def _rows(req, reqset, cases: list, cfg, limit) -> list:
    rows = []
    key = measured_key(req)
    for (p, o, rec), (dep, extended, group) in _groups(req, reqset, cases, cfg).items():
        pairs = [(c, m) for c in group if (m := row_value(req, reqset.procedures[p], c, key)) is not None]
        if not pairs:
            continue  # the test does not produce this figure (an opening stroke for a closing time)
        if extended and not any(m.eligible and m.value is not None for _, m in pairs):
            continue  # a point the requirement does not name: judged only where the figure is measured
        base = {"procedure": p, "operating_point": o, "run": rec, "departures": sorted(dep), "basis": Basis.MEASURED}
        row = judge_cases(req, limit, base, pairs)
        if extended:
            row["extended"] = (f"{req.metric} was measured by {rec} at {o}, a point {req.id} does not list; it applies "
                               "wherever its metric is measured")
        row["display"] = row_texts(row, req.metric, unicode=False)
        rows.append(row)
    return rows


def _coverage(req, rows: list) -> dict:
    asked = [(p, o) for p in req.procedures for o in req.operating_points]
    tested = {(r["procedure"], r["operating_point"]) for r in rows if not r.get("extended")}
    missing = [f"{p}@{o}" for p, o in asked if (p, o) not in tested]
    evaluated = sum(1 for r in rows if r["status"] in (Status.PASS, Status.FAIL, Status.UNCERTAIN))
    return {"rows": len(rows), "evaluated": evaluated, "extended": sum(1 for r in rows if r.get("extended")),
            "asked": len(asked), "tested": sorted(f"{p}@{o}" for p, o in tested), "not_tested": missing,
            "complete": not missing}


def _worst(rows: list, limit, comparator: str):
    judged = [r for r in rows if r["status"] in (Status.PASS, Status.FAIL, Status.UNCERTAIN, Status.OPEN)
              and r.get("value") is not None]
    silent = [r for r in rows if r.get("non_responding")]
    if silent:
        return silent[0]
    if not judged:
        return None
    if limit is None:  # an open limit still shows its least favourable value
        return (min if comparator in (">=", ">") else max)(judged, key=lambda r: r["value"])
    order = [Verdict(r["value"], r["comparator"], tuple(limit), r["margin"], r["margin_pct"],
                     Status.FAIL if r["status"] == Status.FAIL else Status.PASS) for r in judged]
    return judged[worst_index(order)]


def judge_requirement(req, reqset, cases: list, cfg) -> dict:
    """The site entry of one requirement (``requirements[]`` of the site JSON, docs/acceptance.md)."""
    stroke = cfg.p("cylinder.stroke")
    limit = req.resolved_limit(stroke) if req.limit is not None else None
    base = {"id": req.id, "title": req.title, "standard": req.standard, "clause": req.clause, "metric": req.metric,
            "measured_metric": measured_key(req), "unit": METRICS[req.metric].si_unit,
            "display_unit": METRICS[req.metric].display_unit, "comparator": req.comparator,
            "limit": None if limit is None else list(limit), "limit_text": req.limit_text,
            "limit_display": None if limit is None else resolved_limit(req.comparator, limit, req.metric),
            "severity": req.severity, "source": req.source, "reading": req.reading, "alternative": req.alternative,
            "own_choice": req.own_choice, "note": req.note, "basis": Basis.MEASURED}
    if not req.enabled:
        return {**base, "status": Status.DISABLED, "rows": [], "worst": None, "coverage": _coverage(req, []), "reason": "disabled"}
    if req.source == "linear":
        why = "a property of the linearised model; a site measures the machine, not its linearisation"
        return {**base, "status": Status.NOT_EVALUATED, "rows": [], "worst": None, "coverage": _coverage(req, []),
                "reason": why, "basis": Basis.NOT_EVALUATED}
    rows = _rows(req, reqset, cases, cfg, limit)
    coverage = _coverage(req, rows)
    status = requirement_status(rows, limit)
    reason = None
    if not rows:
        reason = f"none of its {coverage['asked']} cases was tested at this site ({', '.join(coverage['not_tested'][:4])}" \
                 + (", ..." if len(coverage["not_tested"]) > 4 else "") + ")"
    worst = _worst(rows, limit, req.comparator)
    return {**base, "status": status, "reason": reason, "rows": rows, "coverage": coverage,
            "worst": None if worst is None else {k: worst.get(k) for k in (
                "run", "procedure", "operating_point", "value", "u", "margin", "margin_pct", "status", "which", "display",
                "non_responding")},
            "basis": Basis.MEASURED if status in (Status.PASS, Status.FAIL, Status.UNCERTAIN, Status.OPEN) else Basis.NOT_EVALUATED}
