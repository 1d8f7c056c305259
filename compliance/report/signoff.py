"""Page 1 of the compliance report: what a plant owner signs.

The verdict with the basis it rests on (a simulated model; how many of its parameters are
from the paper, assumed, derived, set by the user or fitted; whether the model was validated
against a recording), every failure in one line with its failing number and what would fix it,
the test cases that could not be evaluated with their reasons, the document control (number,
revision, DRAFT state, the sha256 of every input) and the model assumptions.
"""

from __future__ import annotations

from collections import Counter

from compliance.presentation.values import limit_as_written, metric_text
from compliance.units.formatting import fmt_margin_pct, fmt_si

SOURCE_WORDS = {"paper": "from the paper", "assumed": "assumed", "derived": "derived", "user": "set by the user",
                "fitted": "fitted to a recording"}


# parameters read only under one option value (model/assembly.py: the flow law, the friction law and the
# controller type pick their own parameters; the others are not read at all)
_ONLY_WHEN = (
    (("valve.sonic_conductance", "valve.critical_pressure_ratio", "air.reference_density", "air.reference_temperature",
      "flow_control."), "valve.flow_law", ("iso6358",)),
    (("valve.effective_area",), "valve.flow_law", ("sanville",)),
    (("valve.bobrow_coefficient",), "valve.flow_law", ("bobrow",)),
    (("valve.power_law_",), "valve.flow_law", ("power_law",)),
    (("friction.bristle_",), "friction.model", ("lugre",)),
    (("friction.limit_velocity",), "friction.model", ("variable_viscous", "piecewise_stribeck")),
    (("friction.static_force", "friction.coulomb_force", "friction.stribeck_velocity", "friction.viscous_coefficient"),
     "friction.model", ("lugre", "variable_viscous")),
    (("friction.breakaway_force", "friction.low_speed_coefficient", "friction.critical_velocity",
      "friction.high_speed_coefficient"), "friction.model", ("piecewise_stribeck",)),
    (("controller.closed_loop_", "controller.acceleration_observer", "controller.friction_observer",
      "controller.velocity_filter"), "controller.type", ("state_feedback",)),
    (("controller.kp", "controller.ki", "controller.kd", "controller.filter_cutoff", "controller.compensation_"),
     "controller.type", ("pid",)),
)


def used_by_model(key: str, options: dict) -> bool:
    """Whether the selected model (its flow law, friction law, controller) reads parameter ``key``."""
    for prefixes, option, values in _ONLY_WHEN:
        if any(key == p or (p.endswith(("_", ".")) and key.startswith(p)) for p in prefixes):
            return str(options.get(option, "")) in values
    return True


def _deciding(results: dict, used: list[dict]) -> list[str]:
    """The assumptions that decide verdicts: named by the verdicts' bands when present, else the usual suspects."""
    named = []
    for e in results["requirements"]:
        for key in ((e.get("band") or {}).get("deciding") or []):
            if key not in named:
                named.append(str(key))
    assumed = [p["key"] for p in used if p.get("source") == "assumed"]
    out = []
    if named:
        out += [k for k in named][:3]
    friction = [k for k in assumed if k.startswith("friction.")]
    if friction and not any(k.startswith("friction.") for k in out):
        out.append("every friction value (" + ", ".join(k.split(".", 1)[1].replace("_", " ") for k in friction) + ")")
    curve = results["plant"].get("load_curve") or {}
    ops = results["requirement_set"].get("operating_points") or {}
    if curve and curve.get("source", "assumed") == "assumed" and any(o.get("load") == "curve" for o in ops.values()):
        out.append("the gate load curve over the stroke")
    for k in ("valve.saturation_voltage",):
        if k in assumed:
            out.append("the valve's full-opening voltage")
    return out


def basis(results: dict) -> dict:
    """What every number of the report comes from: the model, the sources of the parameters it uses, validation."""
    plant = results["plant"]
    options = plant.get("options") or {}
    params = [p for p in plant.get("parameters") or [] if isinstance(p, dict)]
    used = [p for p in params if used_by_model(str(p.get("key")), options)]
    counts = Counter(str(p.get("source") or "assumed") for p in used)
    fitted = sum(len(e.get("params") or []) for e in plant.get("effects") or [])
    parts = [f"{n} {SOURCE_WORDS.get(s, s)}" for s, n in counts.most_common()]
    val = results.get("validation")
    if val:
        ok = (val.get("summary") or {}).get("pass")
        validated = (f"validated against a recording: {'PASS' if ok else 'FAIL' if ok is False else 'not decided'} "
                     "(section 6)")
    else:
        validated = "not validated: no recording of this servo was compared with the model"
    bases = Counter(str(e.get("basis")) for e in results["requirements"] if e.get("basis"))
    return {"model": plant["name"], "params": ", ".join(parts), "n_params": sum(counts.values()),
            "n_unused": len(params) - len(used), "assumed": counts.get("assumed", 0),
            "effects": [e.get("name") for e in plant.get("effects") or []], "fitted": fitted, "validated": validated,
            "validation_run": bool(val), "deciding": _deciding(results, used),
            "verdict_bases": [f"{n} {k.replace('_', ' ')}" for k, n in bases.most_common()],
            "provenance": dict(plant.get("provenance") or {})}


def document_block(identity: dict, files: list[dict], document: dict | None = None, *, needs_identity: bool = True) -> dict:
    """Document number, revision, DRAFT state and the cited inputs of any govcheck report.

    ``document``: ``number`` / ``revision`` from the command line (they win over the
    ``[identity]`` table). Without an identity (when the report is about a configured unit,
    ``needs_identity``) or without a document number the report is a DRAFT.
    """
    document = document or {}
    identity = identity or {}
    number = document.get("number") or identity.get("document_number")
    revision = document.get("revision") or identity.get("revision")
    draft = (needs_identity and not identity) or not number
    why = ("no [identity] table in the configuration" if needs_identity and not identity else "no document number "
           "(--document-number)") if draft else None
    return {"number": number, "revision": revision, "draft": draft, "draft_reason": why, "files": files,
            "author": identity.get("author"), "test_date": identity.get("test_date")}


def document_control(results: dict, document: dict | None = None) -> dict:
    """:func:`document_block` of a compliance report: configuration, requirement files, results file, recording.

    ``document`` may also carry ``results`` (``{"path", "digest"}`` of the saved results file).
    """
    document = document or {}
    plant, rs = results["plant"], results["requirement_set"]
    files = [{"what": "Plant configuration", "path": plant.get("path") or plant["name"], "digest": plant.get("digest")}]
    for f in rs.get("files") or [{"path": rs.get("path"), "digest": rs.get("digest")}]:
        files.append({"what": "Requirement file", "path": f.get("path"), "digest": f.get("digest")})
    res = document.get("results") or {}
    files.append({"what": "Results file", "path": res.get("path") or "not saved (no --json)", "digest": res.get("digest")})
    rec = (results.get("validation") or {}).get("recording") or {}
    if rec:
        files.append({"what": "Recording", "path": rec.get("path"), "digest": rec.get("digest")})
    return document_block(plant.get("identity") or {}, files, document)


def _remedy_lines(rem) -> dict:
    """Requirement id -> one line on what would fix it, from a ``remedies`` section (docs/results-schema.md)."""
    if not isinstance(rem, dict):
        return {}
    out = {}
    fix = rem.get("remedy")
    if fix:
        changes = ", ".join(f"{c['path']} from {fmt_si(c['from'], c['unit'])} to {fmt_si(c['to'], c['unit'])}"
                            for c in fix.get("changes", []))
        for rid in rem.get("failed", []):
            out[rid] = f"passes with {changes} (verified by a full campaign: {fix.get('verified', {}).get('status', 'not run')})"
        return out
    for rid in rem.get("out_of_reach", []):
        out[rid] = "out of reach of every adjustable setting searched; needs a hardware or design change"
    for s in rem.get("sensitivities", []):
        best = next((b for b in s.get("by_parameter", []) if b.get("delta_margin_pct", 0) > 0), None)
        if s["requirement"] not in out and best:
            out[s["requirement"]] = (f"no passing setting found; {best['path']} helps most "
                                     f"({best['delta_margin_pct']:+.1f} points per {fmt_si(best['step'], best['unit'])})")
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
                    "limit": limit_as_written(e), "margin_pct": fmt_margin_pct(w.get("margin_pct")),
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


def assumptions(results: dict) -> list[str]:
    """The model assumptions the verdicts rest on (the readings of the requirements are departures, acceptance.py)."""
    b = basis(results)
    out = [f"Every value in this report is computed by simulating the model '{b['model']}'; no hardware was tested.",
           f"{b['assumed']} of the {b['n_params']} parameters the model uses are assumed (physically consistent choices "
           "not given by the paper or the user; appendix A lists them)"
           + (f"; {b['n_unused']} further parameters of laws not selected are not used and not counted." if b["n_unused"] else ".")]
    if b["deciding"]:
        out.append("The assumptions that decide the verdicts: " + "; ".join(b["deciding"]) + ".")
    if not b["validation_run"]:
        out.append("The model has not been validated against a recording of this servo; friction, valve and leakage "
                   "parameters may differ on the real unit.")
    return out
