"""Results dict (docs/results-schema.md) -> what the compliance report shows.

Checks the keys the report needs (bad input -> ``InputError`` naming the key), formats numbers
with units, groups runs by procedure and lists the figures to draw. No rendering here: the
figures are produced by :mod:`compliance.report.figures` from the specs built below, the
text by the jinja2 templates.
"""

from __future__ import annotations

import hashlib
import shlex

from compliance.errors import InputError
from compliance.presentation.values import limit_as_written, metric_text, row_texts
from compliance.report.requirement_pages import TOLERANCE_METRICS, reader_text
from compliance.requirements.verdict import Basis, Overall, Status
from compliance.units.formatting import fmt_num, unit_text

RESULTS_SCHEMA = "govcheck-results/1"
SOURCES = ("paper", "assumed", "derived", "user")

_REQUIRED = {
    "plant": ("name", "digest", "parameters"),
    "requirement_set": ("name", "path", "digest", "requirements"),
    "summary": ("status", "counts"),
}
_REQ_KEYS = ("id", "title", "metric", "status", "severity", "limit_text", "rows")
_RUN_KEYS = ("id", "procedure", "operating_point", "kind", "traces")


def _need(obj, key, where, typ=None):
    if not isinstance(obj, dict) or key not in obj:
        raise InputError(f"{where}: key '{key}' is missing (expected a govcheck results file, schema '{RESULTS_SCHEMA}')")
    v = obj[key]
    if typ is not None and not isinstance(v, typ):
        raise InputError(f"{where}: key '{key}' should be a {typ.__name__ if isinstance(typ, type) else 'list'}, "
                         f"got {type(v).__name__}")
    return v


def check_results(results, where: str = "results") -> None:
    """Check a results dict has everything the report needs.

    Raises
    ------
    InputError
        Wrong schema version, or a missing / mistyped key (named with its path).
    """
    if not isinstance(results, dict):
        raise InputError(f"{where}: expected a JSON object (a govcheck results file), got {type(results).__name__}")
    schema = _need(results, "schema", where)
    if schema != RESULTS_SCHEMA:
        raise InputError(f"{where}: key 'schema' is '{schema}'; this govcheck reads '{RESULTS_SCHEMA}' "
                         "(re-run 'govcheck check' to regenerate the results)")
    for section, keys in _REQUIRED.items():
        sec = _need(results, section, where, dict)
        for k in keys:
            _need(sec, k, f"{where}: {section}")
    reqs = _need(results, "requirements", where, list)
    for i, e in enumerate(reqs):
        for k in _REQ_KEYS:
            _need(e, k, f"{where}: requirements[{i}]")
    runs = results.get("runs") or []
    if not isinstance(runs, list):
        raise InputError(f"{where}: key 'runs' should be a list, got {type(runs).__name__}")
    for i, r in enumerate(runs):
        for k in _RUN_KEYS:
            _need(r, k, f"{where}: runs[{i}]")
    from compliance.campaign.results_files import check_numbers

    check_numbers(results, where)


# --------------------------------------------------------------------------- formatting
# the one formatter and status-word table live in compliance/units/formatting.py

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
def summary_rows(results: dict) -> list[dict]:
    """One row per requirement: worst value, limit, margin, status, where the worst case was."""
    out = []
    run_ids = {r.get("id") for r in results.get("runs") or []}
    for e in results["requirements"]:
        w = e.get("worst") or {}
        d = row_texts(w, e["metric"]) if w else {}
        reason = None
        if e["status"] == Status.NOT_EVALUATED:
            reason = "; ".join(sorted({r.get("reason") for r in e["rows"] if r.get("reason")})) or "not evaluated"
        where = None
        if w:
            where = w.get("run") or f"{w.get('procedure')}@{w.get('operating_point')}"
        out.append({
            "id": e["id"], "title": e["title"], "metric": e["metric"], "severity": e["severity"],
            "source": e.get("source", "simulation"), "standard": e.get("standard"), "clause": e.get("clause"),
            "limit_text": e["limit_text"],
            "limit": limit_as_written(e),
            "value": d.get("value", "\u2013"), "margin": d.get("margin", "\u2013") if w.get("margin") is not None else "\u2013",
            "margin_pct": d.get("margin_pct"), "status": e["status"], "where": where, "which": w.get("which"),
            "procedure": w.get("procedure"), "operating_point": w.get("operating_point"), "reason": reason,
            "anchor": "run-" + _slug(where) if where in run_ids else None,
            "note": e.get("note"), "loosened": e.get("loosened") or [],
            # how the verdict is known and how sure it is (campaign.basis, campaign.uncertainty)
            "basis": BASIS_WORDS.get(str(e.get("basis")), str(e.get("basis")).replace("_", " ")) if e.get("basis") else None,
            "basis_key": e.get("basis"), "basis_reason": w.get("basis_reason"),
            "band": band_text(e.get("band"), e["metric"]), "band_pct": e.get("band"),
            "coverage": e.get("coverage"),
        })
    return out


# how a verdict is known (the verdict work's ``basis`` key; absent in older results)
BASIS_WORDS = {Basis.MODELLED: "modelled", Basis.BY_CONSTRUCTION: "by construction", Basis.NOT_EVALUATED: "not evaluated",
               Basis.ASSUMED: "assumed"}


def band_text(band, metric: str) -> str | None:
    """A verdict's value band under the declared parameter uncertainty (``{"low", "high"}``, SI) as text."""
    if not isinstance(band, dict) or band.get("low") is None or band.get("high") is None:
        return None
    lo, hi = metric_text(band["low"], metric), metric_text(band["high"], metric)
    return f"band {lo} to {hi}"


def _run_evidence(results: dict, run_id: str) -> list[dict]:
    """Requirement rows judged on one run, with every sample measured for them."""
    rows = []
    for e in results["requirements"]:
        for r in e["rows"]:
            if r.get("run") != run_id:
                continue
            d = row_texts(r, e["metric"])
            samples = []
            for s in r.get("samples") or []:
                samples.append({"label": s.get("label"), "value": s.get("display") or metric_text(s.get("value"), e["metric"]),
                                "excluded": not s.get("eligible", True) or s.get("value") is None, "reason": s.get("reason")})
            rows.append({"id": e["id"], "metric": e["metric"], "value": d.get("value"), "which": r.get("which"),
                         "limit": d.get("limit") or ("open" if e.get("limit") is None else e["limit_text"]), "margin": d.get("margin") if r.get("margin") is not None else "\u2013",
                         "margin_pct": d.get("margin_pct"), "status": r.get("status"), "reason": r.get("reason"),
                         "samples": samples})
    return rows


def _tolerance(results: dict, run_id: str):
    """Smallest position tolerance [m] a requirement applies to this run (the error band), or None."""
    tol = []
    for e in results["requirements"]:
        if e["metric"] not in TOLERANCE_METRICS:
            continue
        for r in e["rows"]:
            lim = r.get("limit")
            if r.get("run") == run_id and lim:
                tol.append(max(lim))
    return min(tol) if tol else None


def _params_by_key(results: dict) -> dict:
    return {p.get("key"): p.get("value") for p in results["plant"]["parameters"] if isinstance(p, dict)}


def valve_marks(results: dict) -> dict:
    """Valve full-opening voltage and dead zone [V] for the command panels (from the plant)."""
    p = _params_by_key(results)
    out = {}
    if p.get("valve.saturation_voltage"):
        out["saturation_voltage"] = p["valve.saturation_voltage"]
    if p.get("valve.dead_zone_positive") or p.get("valve.dead_zone_negative"):
        out["dead_zone"] = [p.get("valve.dead_zone_positive") or 0.0, p.get("valve.dead_zone_negative") or 0.0]
    if p.get("valve.centre_voltage"):
        out["centre_voltage"] = p["valve.centre_voltage"]
    if p.get("valve.command_limit"):
        out["command_limit"] = p["valve.command_limit"]
    return out


def procedure_sections(results: dict, start: int = 1) -> tuple[list[dict], list[dict]]:
    """Runs grouped by procedure (in the requirement set's order) and the figure specs.

    Returns
    -------
    (sections, figure_specs)
        ``figure_specs`` items: ``{"id", "kind": "trace", "trace", "marks", "run_kind",
        "tolerance"}``; a section's runs refer to their figures by ``id``.
    """
    rs = results["requirement_set"]
    procs = rs.get("procedures") or {}
    ops = rs.get("operating_points") or {}
    runs = results.get("runs") or []
    order = list(procs) + sorted({r["procedure"] for r in runs} - set(procs))
    specs, sections = [], []
    for pname in order:
        pruns = [r for r in runs if r["procedure"] == pname]
        if not pruns:
            continue
        p = procs.get(pname) or {}
        op_order = list(ops)
        pruns.sort(key=lambda r: op_order.index(r["operating_point"]) if r["operating_point"] in op_order else len(op_order))
        items = []
        for run in pruns:
            figs = []
            tol = _tolerance(results, run["id"])
            for j, tr in enumerate(run.get("traces") or []):
                fid = f"fig-{start + len(specs)}"
                specs.append({"id": fid, "kind": "trace", "trace": tr, "marks": run.get("marks") or [],
                              "run_kind": run["kind"], "tolerance": tol})
                figs.append({"id": fid, "label": tr.get("label") or run["id"], "points": tr.get("points"),
                             "samples": tr.get("samples")})
            op = ops.get(run["operating_point"]) or {}
            items.append({"id": run["id"], "anchor": "run-" + _slug(run["id"]), "operating_point": run["operating_point"],
                          "op_title": op.get("title"), "initial_position": op.get("initial_position"),
                          "load": op.get("load_text") if op.get("load_text") is not None else op.get("load"),
                          "flow_control": op.get("flow_control"), "error": run.get("error"), "notes": run.get("notes") or [],
                          "evidence": _run_evidence(results, run["id"]), "figures": figs, "tolerance": tol,
                          "wall_time": run.get("wall_time")})
        settings = p.get("settings") or {}
        sections.append({"name": pname, "anchor": "proc-" + _slug(pname), "title": p.get("title") or pname,
                         "kind": p.get("kind") or pruns[0]["kind"], "settings": settings, "note": p.get("note"),
                         "runs": items})
    return sections, specs


def _slug(text: str) -> str:
    """An id-safe slug of a user string (ids must not carry markup or spaces)."""
    text = str(text)
    out = "".join(c if (c.isascii() and c.isalnum()) or c in "-_" else "-" for c in text)
    if out == text and out:
        return out
    return (out.strip("-") or "x")[:60] + "-" + hashlib.sha1(text.encode("utf-8")).hexdigest()[:8]


def parameter_rows(results: dict) -> list[dict]:
    """Appendix table: every parameter the selected model uses, with value, unit, meaning and source."""
    from compliance.report.signoff import used_by_model

    rows = []
    options = results["plant"].get("options") or {}
    for p in sorted(results["plant"]["parameters"], key=lambda q: str(q.get("key"))):
        if not used_by_model(str(p.get("key")), options):
            continue  # a law or controller not selected: not part of this model
        src = p.get("source") or "\u2013"
        rows.append({"key": p.get("key"), "value": fmt_num(p.get("value"), 6), "unit": unit_text(p.get("unit", "")) or "\u2013",
                     "meaning": reader_text(p.get("meaning")), "source": src, "source_class": src if src in SOURCES else "other"})
    return rows


def command_text(results: dict) -> str:
    """The exact command line that produced the results."""
    c = results.get("command_line") or results.get("command")
    if isinstance(c, list):
        return shlex.join(str(x) for x in c)
    return str(c) if c else "not recorded"
