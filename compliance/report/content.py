"""A check's result (``compliance.results.CheckResult``) -> what the compliance report shows.

A results dict is read into the typed result at this edge (bad input -> ``InputError`` naming the
key); the rest reads the result: numbers formatted with units, runs grouped by procedure, the
figures to draw listed. No rendering here: the figures are produced by
:mod:`compliance.report.figures` from the specs built below, the text by the jinja2 templates.
"""

from __future__ import annotations

import hashlib

from compliance.presentation.values import band_pct_text, limit_as_written, metric_text, row_texts, verdict_texts
from compliance.report.requirement_pages import TOLERANCE_METRICS, reader_text
from compliance.requirements.verdict import Basis, Overall, Status
from compliance.results.check_result import CheckResult
from compliance.presentation.numbers import fmt_num, unit_text

SOURCES = ("paper", "assumed", "derived", "user")


def as_result(results, where: str = "results") -> CheckResult:
    """The typed result to report on: a ``CheckResult`` as it is, a results dict read (and checked) at this edge.

    Raises
    ------
    InputError
        Wrong schema version, or a missing / mistyped key (named with its path).
    """
    return results if isinstance(results, CheckResult) else CheckResult.from_dict(results, where)


# --------------------------------------------------------------------------- formatting
# the one formatter and status-word table live in compliance/presentation/numbers.py

def setting_text(v) -> str:
    """A procedure setting as a reader reads it: units typeset, yes/no, lists joined."""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, str):
        return unit_text(v)
    if isinstance(v, (list, tuple)):
        return ", ".join(setting_text(x) for x in v)
    if isinstance(v, (int, float)):
        return fmt_num(v)
    return str(v)


def readable_settings(settings: dict) -> list[tuple[str, str]]:
    """A settings or conditions mapping as (name in words, value in words): no Python literals, units typeset."""
    out = []
    for k, v in sorted(settings.items()):
        if isinstance(v, dict):
            text = "; ".join(f"{str(a).replace('_', ' ')} {setting_text(b)}" for a, b in sorted(v.items()) if b is not None)
        else:
            text = setting_text(v) if v is not None else "\u2013"
        out.append((str(k).replace("_", " "), text or "\u2013"))
    return out


def status_class(status: str | None) -> str:
    """CSS class of a status badge."""
    return {Status.PASS: "pass", Status.FAIL: "fail", Overall.INCOMPLETE: "warn", Status.NOT_EVALUATED: "warn",
            Status.UNCERTAIN: "warn"}.get(status or "", "neutral")


# --------------------------------------------------------------------------- sections
_NO_TEXTS = {"value": "\u2013", "limit": None, "margin": "\u2013", "margin_pct": None}  # a requirement without a worst case


def summary_rows(result: CheckResult) -> list[dict]:
    """One row per requirement: worst value, limit, margin, status, where the worst case was."""
    out = []
    run_ids = {r.id for r in result.runs}
    for e in result.requirements:
        w = e.worst
        d = verdict_texts(e) if w is not None else _NO_TEXTS
        reason = "; ".join(e.not_evaluated_reasons()) or "not evaluated" if e.status == Status.NOT_EVALUATED else None
        where = (w.run or f"{w.procedure}@{w.operating_point}") if w is not None else None
        out.append({
            "id": e.id, "title": e.title, "metric": e.metric, "severity": e.severity, "source": e.source,
            "standard": e.standard, "clause": e.clause, "limit_text": e.limit_text, "limit": limit_as_written(e),
            "value": d["value"], "margin": d["margin"] if w is not None and w.margin is not None else "\u2013",
            "margin_pct": d["margin_pct"], "status": e.status, "where": where, "which": w and w.which,
            "procedure": w and w.procedure, "operating_point": w and w.operating_point, "reason": reason,
            "anchor": "run-" + _slug(where) if where in run_ids else None, "note": e.note, "loosened": list(e.loosened),
            # how the verdict is known and how sure it is (campaign.basis, campaign.uncertainty)
            "basis": BASIS_WORDS.get(e.basis, str(e.basis).replace("_", " ")) if e.basis else None,
            "basis_key": e.basis, "basis_reason": w and w.basis_reason,
            "band": band_text(e.band, e.metric), "band_pct": e.band, "coverage": e.coverage,
            "band_margins": band_pct_text(e.band, w.margin_pct if w is not None else None, unicode=True),
        })
    return out


# how a verdict is known
BASIS_WORDS = {Basis.MODELLED: "modelled", Basis.BY_CONSTRUCTION: "by construction", Basis.NOT_EVALUATED: "not evaluated",
               Basis.ASSUMED: "assumed"}


def band_text(band, metric: str) -> str | None:
    """A verdict's value band under the declared parameter uncertainty (SI) as text."""
    if band is None or band.low is None or band.high is None:
        return None
    return f"band {metric_text(band.low, metric)} to {metric_text(band.high, metric)}"


def _run_evidence(result: CheckResult, run_id: str) -> list[dict]:
    """Requirement rows judged on one run, with every sample measured for them."""
    rows = []
    for e in result.requirements:
        for r in e.rows:
            if r.run != run_id:
                continue
            d = row_texts(r.as_dict(), e.metric)
            samples = [{"label": s.label, "value": s.display or metric_text(s.value, e.metric),
                        "excluded": not s.eligible or s.value is None, "reason": s.reason} for s in r.samples]
            rows.append({"id": e.id, "metric": e.metric, "value": d["value"], "which": r.which,
                         "limit": d["limit"] or ("open" if e.limit is None else e.limit_text),
                         "margin": d["margin"] if r.margin is not None else "\u2013", "margin_pct": d["margin_pct"],
                         "status": r.status, "reason": r.reason, "samples": samples})
    return rows


def _tolerance(result: CheckResult, run_id: str):
    """Smallest position tolerance [m] a requirement applies to this run (the error band), or None."""
    tol = [max(r.limit) for e in result.requirements if e.metric in TOLERANCE_METRICS
           for r in e.rows if r.run == run_id and r.limit]
    return min(tol) if tol else None


def valve_marks(result: CheckResult) -> dict:
    """Valve full-opening voltage, dead zone, centre and command limit [V] for the command panels (from the plant)."""
    v = result.plant.value
    out = {}
    if v("valve.saturation_voltage"):
        out["saturation_voltage"] = v("valve.saturation_voltage")
    if v("valve.dead_zone_positive") or v("valve.dead_zone_negative"):
        out["dead_zone"] = [v("valve.dead_zone_positive") or 0.0, v("valve.dead_zone_negative") or 0.0]
    for name in ("centre_voltage", "command_limit"):
        if v(f"valve.{name}"):
            out[name] = v(f"valve.{name}")
    return out


def _run_item(result: CheckResult, run, start: int, specs: list) -> dict:
    """A run of the appendix: its operating point, notes, evidence and figures (their specs appended to ``specs``)."""
    figs = []
    tol = _tolerance(result, run.id)
    for tr in run.traces:
        fid = f"fig-{start + len(specs)}"
        specs.append({"id": fid, "kind": "trace", "trace": tr, "marks": run.marks, "run_kind": run.kind, "tolerance": tol})
        figs.append({"id": fid, "label": tr.label or run.id, "points": tr.points, "samples": tr.samples})
    op = result.requirement_set.operating_points.get(run.operating_point)
    return {"id": run.id, "anchor": "run-" + _slug(run.id), "operating_point": run.operating_point,
            "op_title": op and op.title, "initial_position": op and op.initial_position,
            "load": op and (op.load_text if op.load_text is not None else op.load), "flow_control": op and op.flow_control,
            "error": run.error, "notes": list(run.notes), "evidence": _run_evidence(result, run.id), "figures": figs,
            "tolerance": tol, "wall_time": run.wall_time}


def procedure_sections(result: CheckResult, start: int = 1) -> tuple[list[dict], list[dict]]:
    """Runs grouped by procedure (in the requirement set's order) and the figure specs.

    Returns
    -------
    (sections, figure_specs)
        ``figure_specs`` items: ``{"id", "kind": "trace", "trace", "marks", "run_kind",
        "tolerance"}``; a section's runs refer to their figures by ``id``.
    """
    procs, ops = result.requirement_set.procedures, list(result.requirement_set.operating_points)
    order = list(procs) + sorted({r.procedure for r in result.runs} - set(procs))
    specs, sections = [], []
    for pname in order:
        pruns = sorted((r for r in result.runs if r.procedure == pname),
                       key=lambda r: ops.index(r.operating_point) if r.operating_point in ops else len(ops))
        if not pruns:
            continue
        p = procs.get(pname)
        items = [_run_item(result, run, start, specs) for run in pruns]
        sections.append({"name": pname, "anchor": "proc-" + _slug(pname), "title": (p and p.title) or pname,
                         "kind": (p and p.kind) or pruns[0].kind, "settings": p.settings if p else {},
                         "note": p and p.note, "runs": items})
    return sections, specs


def _slug(text: str) -> str:
    """An id-safe slug of a user string (ids must not carry markup or spaces)."""
    text = str(text)
    out = "".join(c if (c.isascii() and c.isalnum()) or c in "-_" else "-" for c in text)
    if out == text and out:
        return out
    return (out.strip("-") or "x")[:60] + "-" + hashlib.sha1(text.encode("utf-8")).hexdigest()[:8]


def parameter_rows(result: CheckResult) -> list[dict]:
    """Appendix table: every parameter the selected model uses, with value, unit, meaning and source."""
    from compliance.model.parameters import used_by_model

    rows = []
    for p in sorted(result.plant.parameters, key=lambda q: q.key):
        if not used_by_model(p.key, result.plant.options):
            continue  # a law or controller not selected: not part of this model
        src = p.source or "\u2013"
        rows.append({"key": p.key, "value": fmt_num(p.value, 6), "unit": unit_text(p.unit) or "\u2013",
                     "meaning": reader_text(p.meaning), "source": src, "source_class": src if src in SOURCES else "other"})
    return rows


def command_text(result: CheckResult) -> str:
    """The exact command line that produced the results."""
    return result.command_line or "not recorded"
