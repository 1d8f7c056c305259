"""Page 1 of the compliance report: what a plant owner signs.

The verdict with the basis it rests on (a simulated model; how many of its parameters are
from the paper, assumed, derived, set by the user or fitted; whether the model was validated
against a recording), every failure in one line with its failing number and what would fix it,
the test cases that could not be evaluated with their reasons, the document control (number,
revision, DRAFT state, the sha256 of every input) and the model assumptions.
"""

from __future__ import annotations

from collections import Counter

from compliance.campaign.coverage import CASES_BASIS, case_coverage, case_coverage_text
from compliance.model.parameters import used_by_model
from compliance.presentation.values import limit_as_written, metric_text
from compliance.requirements.verdict import Overall, Status
from compliance.results.check_result import CheckResult
from compliance.results.remedies import RemedySection
from compliance.results.requirement_set import FileRecord
from compliance.results.rows import WorstCase
from compliance.results.summary import CaseCoverage, Qualifier
from compliance.presentation.numbers import fmt_margin_pct, fmt_si

SOURCE_WORDS = {"paper": "from the paper", "assumed": "assumed", "derived": "derived", "user": "set by the user",
                "fitted": "fitted to a recording"}


def _deciding(result: CheckResult, used) -> list[str]:
    """The assumptions that decide verdicts: named by the verdicts' bands when present, else the usual suspects."""
    named = []
    for e in result.requirements:
        for key in (e.band.deciding if e.band is not None else ()):
            if key not in named:
                named.append(str(key))
    assumed = [p.key for p in used if p.source == "assumed"]
    out = named[:3]
    friction = [k for k in assumed if k.startswith("friction.")]
    if friction and not any(k.startswith("friction.") for k in out):
        out.append("every friction value (" + ", ".join(k.split(".", 1)[1].replace("_", " ") for k in friction) + ")")
    curve = result.plant.load_curve
    ops = result.requirement_set.operating_points.values()
    if curve is not None and curve.assumed and any(o.on_curve for o in ops):
        out.append("the gate load curve over the stroke")
    if "valve.saturation_voltage" in assumed:
        out.append("the valve's full-opening voltage")
    return out


def basis(result: CheckResult) -> dict:
    """What every number of the report comes from: the model, the sources of the parameters it uses, validation."""
    plant = result.plant
    used = [p for p in plant.parameters if used_by_model(p.key, plant.options)]
    counts = Counter(p.source or "assumed" for p in used)
    fitted = sum(len(e.params) for e in plant.effects)
    parts = [f"{n} {SOURCE_WORDS.get(s, s)}" for s, n in counts.most_common()]
    val = result.validation
    if val:
        ok = (val.get("summary") or {}).get("pass")
        validated = (f"validated against a recording: {'PASS' if ok else 'FAIL' if ok is False else 'not decided'} "
                     "(section 6)")
    else:
        validated = "not validated: no recording of this servo was compared with the model"
    bases = Counter(str(e.basis) for e in result.requirements if e.basis)
    return {"model": plant.name, "params": ", ".join(parts), "n_params": sum(counts.values()),
            "n_unused": len(plant.parameters) - len(used), "assumed": counts.get("assumed", 0),
            "effects": [e.name for e in plant.effects], "fitted": fitted, "validated": validated,
            "validation_run": bool(val), "deciding": _deciding(result, used),
            "verdict_bases": [f"{n} {k.replace('_', ' ')}" for k, n in bases.most_common()],
            "provenance": dict(plant.provenance)}


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
    why = None
    if draft:  # in the signer's words: what is missing, not how to add it
        missing = ["the site, the unit and the equipment are not identified"] if needs_identity and not identity else []
        why = "; ".join(missing + ([] if number else ["no document number has been assigned"]))
    return {"number": number, "revision": revision, "draft": draft, "draft_reason": why, "files": files,
            "author": identity.get("author"), "test_date": identity.get("test_date")}


def document_control(result: CheckResult, document: dict | None = None) -> dict:
    """:func:`document_block` of a compliance report: configuration, requirement files, results file, recording.

    ``document`` may also carry ``results`` (``{"path", "digest"}`` of the saved results file).
    """
    document = document or {}
    plant, rs = result.plant, result.requirement_set
    files = [{"what": "Plant configuration", "path": plant.path or plant.name, "digest": plant.digest}]
    for f in rs.files or (FileRecord(path=rs.path, digest=rs.digest),):
        files.append({"what": "Requirement file", "path": f.path, "digest": f.digest})
    res = document.get("results") or {}
    files.append({"what": "Results file", "path": res.get("path") or "not saved (no --json)", "digest": res.get("digest")})
    rec = (result.validation or {}).get("recording") or {}
    if rec:
        files.append({"what": "Recording", "path": rec.get("path"), "digest": rec.get("digest")})
    return document_block(plant.identity, files, document)


def _remedy_lines(rem) -> dict:
    """Requirement id -> one line on what would fix it, from a ``remedies`` section (docs/results-schema.md)."""
    if not rem:
        return {}
    rem = RemedySection.from_dict(rem, "results.remedies")
    if rem.remedy is not None:
        changes = ", ".join(f"{c.path} from {fmt_si(c.start, c.unit)} to {fmt_si(c.end, c.unit)}" for c in rem.remedy.changes)
        verified = rem.remedy.verified.get("status", "not run")
        return {rid: f"passes with {changes} (verified by a full campaign: {verified})" for rid in rem.failed}
    out = {rid: "out of reach of every adjustable setting searched; needs a hardware or design change" for rid in rem.out_of_reach}
    for s in rem.sensitivities:
        best = s.most_helpful
        if s.requirement not in out and best:
            out[s.requirement] = (f"no passing setting found; {best.path} helps most "
                                  f"({best.delta_margin_pct:+.1f} points per {fmt_si(best.step, best.unit)})".replace("-", "\u2212"))
    return out


def failures(result: CheckResult) -> list[dict]:
    """One line per failed requirement: the failing number against its limit, where, and the remedy if computed."""
    remedies = _remedy_lines(result.remedies)
    out = []
    for e in result.failed():
        w = e.worst or WorstCase()
        out.append({"id": e.id, "title": e.title, "severity": e.severity, "value": metric_text(w.value, e.metric),
                    "limit": limit_as_written(e), "margin_pct": fmt_margin_pct(w.margin_pct),
                    "where": f"{w.procedure} at {w.operating_point}" if w.procedure else None,
                    "remedy": remedies.get(e.id), "anchor": "req-" + e.id})
    return out


def not_evaluated(result: CheckResult) -> dict:
    """Judged test cases not evaluated, counted by reason, on the basis of the terminal and JSON summaries
    (:func:`compliance.campaign.coverage.case_coverage`)."""
    cov = result.summary.coverage or CaseCoverage(**case_coverage([e.as_dict() for e in result.requirements]))
    reasons = Counter()
    for e in result.requirements:
        if e.limit is None:
            continue
        for r in e.rows:
            if r.status == Status.NOT_EVALUATED:
                reasons[(e.id, str(r.reason or "no value").split(":")[0].split(";")[0].strip())] += 1
    items = [{"requirement": rid, "reason": why, "count": n} for (rid, why), n in reasons.most_common()]
    return {"cases": cov.rows, "count": cov.not_evaluated, "evaluated": cov.evaluated, "basis": cov.basis or CASES_BASIS,
            "text": case_coverage_text(cov.as_dict()), "reasons": items, "requirements": result.summary.counts.not_evaluated}


def assumptions(result: CheckResult) -> list[str]:
    """The model assumptions the verdicts rest on (the readings of the requirements are departures, acceptance.py)."""
    b = basis(result)
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


def qualified_verdict(result: CheckResult) -> dict:
    """Page 1's verdict: the word, its qualifiers (``campaign.basis.verdict_qualifier``) and why, in the owner's words.

    A PASS against assumed limits or on a mostly assumed model is not a plain (green) PASS: its
    class is ``warn`` and the qualifier is printed under the word.
    """
    status = result.summary.status
    qualifiers = result.summary.qualifiers if status == Overall.PASS else ()
    if not qualifiers:
        return {"status": status, "qualifier": None, "css": None, "why": None}
    b = basis(result)
    why = []
    if Qualifier.ASSUMED_TARGETS in qualifiers:
        ids = [e.id for e in result.requirements if e.limit_assumed and e.status == Status.PASS]
        why.append(f"the limits of {', '.join(ids)} are assumed design targets of the requirement file, not figures of a "
                   "standard or of the plant owner")
    if Qualifier.ASSUMED_MODEL in qualifiers:
        why.append(f"{b['assumed']} of the {b['n_params']} parameters the model uses are assumed")
    return {"status": status, "qualifier": ", ".join(qualifiers), "css": "warn",
            "why": "; ".join(why) + ": the PASS says the model meets these targets, not that the built system meets "
                                    "a specification"}
