"""Page 1 of the compliance report: what a plant owner signs.

The verdict with the basis it rests on (a simulated model; how many of its parameters are
from the paper, assumed, derived, set by the user or fitted; whether the model was validated
against a recording), every failure in one line with its failing number and what would fix it,
the test cases that could not be evaluated with their reasons, the document identity and the
deviations list (every FAIL and OPEN item with an owner to fill in), and the assumptions and
what was not tested, in one place.
"""

from __future__ import annotations

from collections import Counter

from compliance.report.requirement_pages import limit_text, metric_text
from compliance.units.formatting import STATUS_WORD, fmt_margin_pct

SOURCE_WORDS = {"paper": "from the paper", "assumed": "assumed", "derived": "derived", "user": "set by the user",
                "fitted": "fitted to a recording"}


def basis(results: dict) -> dict:
    """What every number of the report comes from: the model, its parameter sources, validation."""
    plant = results["plant"]
    counts = Counter(str(p.get("source") or "assumed") for p in plant.get("parameters") or [])
    fitted = sum(len(e.get("params") or []) for e in plant.get("effects") or [])
    parts = [f"{n} {SOURCE_WORDS.get(s, s)}" for s, n in counts.most_common()]
    val = results.get("validation")
    if val:
        ok = (val.get("summary") or {}).get("pass")
        rec = (val.get("recording") or {}).get("path") or "a recording"
        validated = f"validated against {rec}: {'PASS' if ok else 'FAIL' if ok is False else 'not decided'} (section 4)"
    else:
        validated = "not validated: no recording of this servo was compared with the model (run govcheck validate)"
    return {"model": plant["name"], "path": plant.get("path"), "params": ", ".join(parts), "n_params": sum(counts.values()),
            "assumed": counts.get("assumed", 0), "effects": [e.get("name") for e in plant.get("effects") or []],
            "fitted": fitted, "validated": validated, "validation_run": bool(val),
            "provenance": dict(plant.get("provenance") or {})}


def _remedy_lines(rem) -> dict:
    """Requirement id -> one line on what would fix it, from a ``remedies`` section (docs/results-schema.md)."""
    if not isinstance(rem, dict):
        return {}
    out = {}
    fix = rem.get("remedy")
    if fix:
        changes = ", ".join(f"{c['path']} {c['from']:.4g} -> {c['to']:.4g} {c['unit']}" for c in fix.get("changes", []))
        for rid in rem.get("failed", []):
            out[rid] = f"passes with {changes} (verified by a full campaign: {fix.get('verified', {}).get('status', 'not run')})"
        return out
    for rid in rem.get("out_of_reach", []):
        out[rid] = "out of reach of every adjustable setting searched; needs a hardware or design change"
    for s in rem.get("sensitivities", []):
        best = next((b for b in s.get("by_parameter", []) if b.get("delta_margin_pct", 0) > 0), None)
        if s["requirement"] not in out and best:
            out[s["requirement"]] = (f"no passing setting found; {best['path']} helps most "
                                     f"({best['delta_margin_pct']:+.1f} points per {best['step']:.3g} {best['unit']})")
    return out


def failures(results: dict) -> list[dict]:
    """One line per failed requirement: the failing number against its limit, where, and the remedy if computed."""
    remedies = _remedy_lines(results.get("remedies"))
    out = []
    for e in results["requirements"]:
        if e["status"] != "fail":
            continue
        w = e.get("worst") or {}
        out.append({"id": e["id"], "title": e["title"], "severity": e["severity"], "value": metric_text(w.get("value"), e["metric"]),
                    "limit": limit_text(e), "margin_pct": fmt_margin_pct(w.get("margin_pct")),
                    "where": f"{w.get('procedure')} at {w.get('operating_point')}" if w.get("procedure") else None,
                    "remedy": remedies.get(e["id"]), "anchor": "req-" + e["id"]})
    return out


def not_evaluated(results: dict) -> dict:
    """Test cases (requirement x procedure x operating point) not evaluated, counted by reason."""
    total, reasons = 0, Counter()
    for e in results["requirements"]:
        for r in e["rows"]:
            total += 1
            if r.get("status") == "not_evaluated":
                reasons[(e["id"], str(r.get("reason") or "no value").split(":")[0].split(";")[0].strip())] += 1
    items = [{"requirement": rid, "reason": why, "count": n} for (rid, why), n in reasons.most_common()]
    return {"cases": total, "count": sum(reasons.values()), "reasons": items,
            "requirements": (results["summary"].get("counts") or {}).get("not_evaluated", 0)}


def deviations(results: dict) -> list[dict]:
    """Every FAIL, NOT EVALUATED and OPEN requirement, with what it needs and an owner field."""
    out = []
    for e in results["requirements"]:
        if e["status"] not in ("fail", "open", "not_evaluated"):
            continue
        w = e.get("worst") or {}
        if e["status"] == "open":
            need = f"purchaser to set the limit (value found: {metric_text(w.get('value'), e['metric'])})"
        elif e["status"] == "fail":
            need = f"{metric_text(w.get('value'), e['metric'])} against {limit_text(e)}"
        else:
            need = "evidence missing (see its page)"
        out.append({"id": e["id"], "title": e["title"], "status": e["status"], "word": STATUS_WORD.get(e["status"]),
                    "severity": e["severity"], "need": need, "owner": (e.get("owner") or "")})
    return out


def assumptions(results: dict) -> list[str]:
    """Assumptions the verdict rests on and what was not tested, gathered in one place."""
    b = basis(results)
    out = [f"Every value in this report is computed by simulating the model '{b['model']}'; no hardware was tested.",
           f"{b['assumed']} of the {b['n_params']} model parameters are assumed (physically consistent choices not given "
           "by the paper or the user; appendix A lists them)."]
    if not b["validation_run"]:
        out.append("The model has not been validated against a recording of this servo; friction, valve and leakage "
                   "parameters may differ on the real unit.")
    for e in results["requirement_set"].get("requirements") or []:
        note = str(e.get("note") or "")
        if "assum" in note.lower() or "reads it as" in note.lower() or "reading" in note.lower():
            out.append(f"{e['id']}: {note}")
    rs_ops = results["requirement_set"].get("operating_points") or {}
    out.append(f"Only the {len(rs_ops)} operating points of the requirement file were simulated; other loads, supply "
               "pressures and temperatures were not.")
    return out
