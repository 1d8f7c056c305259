"""Page 1 of the compliance report: what a plant owner signs.

The verdict with the basis it rests on (a simulated model; how many of its parameters are
from the paper, assumed, derived, set by the user or fitted; whether the model was validated
against a recording), every failure in one line with its failing number and what would fix it,
the test cases that could not be evaluated with their reasons, the document control (number,
revision, DRAFT state, the sha256 of every input) and the model assumptions; beyond the verdict word
(the terminal summary says the same):

- every mandatory requirement that failed, is uncertain or was not evaluated, with its number
  against its limit, where, its band, the parameters that decide an uncertain one, and whether
  the measurements contradict the figure it rests on;
- the model's evidence (``CheckResult.model_evidence``): validated or not, and the verdicts that
  rest on figures the measurements contradict;
- the loop's stability margins against govcheck's criterion (``CheckResult.stability``);
- the requirement set's own findings (``CheckResult.findings``: narrowing, rate splits, tensions).

Only the typed result is read; nothing here computes a verdict.
"""

from __future__ import annotations

from collections import Counter

from compliance.campaign.coverage import CASES_BASIS, case_coverage, case_coverage_text
from compliance.model.parameters import used_by_model
from compliance.presentation.values import limit_as_written, metric_text, verdict_texts
from compliance.requirements.verdict import Overall, Severity, Status
from compliance.results.check_result import CheckResult
from compliance.results.remedies import RemedySection
from compliance.results.requirement_set import FileRecord
from compliance.results.rows import WorstCase
from compliance.results.summary import CaseCoverage, Qualifier
from compliance.results.validation import ValidationRecord
from compliance.presentation.numbers import fmt_si, status_word

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
    ev = result.model_evidence
    if ev is not None and ev.sources:
        validated = f"{ev.status} against the measurements the plant file names (section 6)"
    elif val:
        ok = (val.get("summary") or {}).get("pass")
        validated = (f"validated against a recording: {'PASS' if ok else 'FAIL' if ok is False else 'not decided'} "
                     "(section 6)")
    else:
        validated = "not validated: no recording of this servo was compared with the model"
    bases = Counter(str(e.basis) for e in result.requirements if e.basis and e.limit is not None)  # open ones: no verdict
    return {"model": plant.name, "params": ", ".join(parts), "n_params": sum(counts.values()),
            "n_unused": len(plant.parameters) - len(used), "assumed": counts.get("assumed", 0),
            "effects": [e.name for e in plant.effects], "fitted": fitted, "validated": validated,
            "validation_run": bool(val) or (ev is not None and ev.status in ("validated", "contradicted")),
            "deciding": _deciding(result, used),
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
    files.append({"what": "Results file", "path": res.get("path") or "not saved (this run wrote no results file)", "digest": res.get("digest")})
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


remedy_lines = _remedy_lines  # page 1's lines on what is not met read the same remedies


def failures(result: CheckResult) -> list[dict]:
    """One line per failed requirement: the failing number against its limit, where, and the remedy if computed."""
    remedies = _remedy_lines(result.remedies)
    out = []
    for e in result.failed():
        w = e.worst or WorstCase()
        texts = verdict_texts(e)
        out.append({"id": e.id, "title": e.title, "severity": e.severity, "value": texts["value"],
                    "limit": limit_as_written(e), "margin_pct": texts["margin_pct"],
                    "where": f"{w.procedure} at {w.operating_point}" if w.procedure else None,
                    "remedy": remedies.get(e.id), "anchor": "req-" + e.id})
    return out


def not_evaluated(result: CheckResult) -> dict:
    """Judged test cases not evaluated, counted by reason, on the basis of the terminal and JSON summaries
    (:func:`compliance.campaign.coverage.case_coverage`)."""
    cov = result.summary.coverage or CaseCoverage(**case_coverage([e.as_dict() for e in result.requirements]))
    reasons, excluded = Counter(), Counter()  # an excluded case (a stated eligibility rule) is not a gap
    for e in result.requirements:
        if e.limit is None:
            continue
        for r in e.rows:
            if r.status == Status.NOT_EVALUATED:
                (excluded if r.excluded else reasons)[(e.id, str(r.reason or "no value").split(":")[0].split(";")[0].strip())] += 1
    items = [{"requirement": rid, "reason": why, "count": n} for (rid, why), n in reasons.most_common()]
    out = [{"requirement": rid, "reason": why, "count": n} for (rid, why), n in excluded.most_common()]
    return {"cases": cov.rows, "count": cov.not_evaluated, "evaluated": cov.evaluated, "basis": cov.basis or CASES_BASIS,
            "excluded": cov.excluded or 0, "excluded_reasons": out,
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


# --------------------------------------------------------------------------- beyond the verdict word
_OPEN_OR_OFF = (Status.OPEN, Status.DISABLED)
_NOT_MET = (Status.FAIL, Status.UNCERTAIN, Status.NOT_EVALUATED)


def _band_text(band, metric: str) -> str | None:
    if band is None or band.low is None:
        return None
    lo, hi = metric_text(band.low, metric), metric_text(band.high, metric)
    return f"band {lo.rsplit(' ', 1)[0]}\u2013{hi}" if lo.rsplit(" ", 1)[-1] == hi.rsplit(" ", 1)[-1] else f"band {lo}\u2013{hi}"


def mandatory_not_met(result: CheckResult, remedies: dict | None = None) -> list[dict]:
    """One line per mandatory requirement that failed, is uncertain or was not evaluated (worst first by status)."""
    ev = result.model_evidence
    contradicted = {c.requirement: c for c in ev.contradicted} if ev is not None else {}
    out = []
    for e in result.requirements:
        if e.severity != Severity.MANDATORY or e.status not in _NOT_MET:
            continue
        w = e.worst or WorstCase()
        texts = verdict_texts(e)
        band = w.band or e.band
        reason = None
        if e.status == Status.NOT_EVALUATED:
            reason = "; ".join(sorted({str(r).split(":")[0] for r in e.not_evaluated_reasons()}))[:160] or "no value"
        c = contradicted[e.id] if e.id in contradicted else None
        out.append({
            "id": e.id, "title": e.title, "status": e.status, "word": status_word(e.status),
            "value": "no response" if w.non_responding else texts["value"],
            "limit": limit_as_written(e), "margin_pct": texts["margin_pct"],
            "where": f"{w.procedure} at {w.operating_point}" if w.procedure else None,
            "band": _band_text(band, e.metric), "deciding": list(band.deciding) if band is not None else [],
            "reason": reason, "anchor": "req-" + e.id,
            "contradicted": None if c is None else f"contradicted by measurement ({c.lean}): {c.example or c.text}",
            "remedy": remedies[e.id] if remedies and e.id in remedies else None,
        })
    order = {Status.FAIL: 0, Status.UNCERTAIN: 1, Status.NOT_EVALUATED: 2}
    return _merged(sorted(out, key=lambda r: order[r["status"]]))


_SAME = ("status", "value", "limit", "where", "band", "deciding", "reason", "contradicted", "remedy")


def _merged(lines: list[dict]) -> list[dict]:
    """Requirements judged on the same figure against the same limit (IEC and IEEE closing times) share one line."""
    out: list[dict] = []
    for line in lines:
        twin = next((o for o in out if all(o[k] == line[k] for k in _SAME)), None)
        if twin is None:
            out.append(dict(line, ids=[line["id"]]))
        else:
            twin["ids"].append(line["id"])
    return out


def advisory_failures(result: CheckResult) -> list[dict]:
    """Advisory requirements that failed: id, value and limit (they do not decide the verdict)."""
    return [{"id": e.id, "value": verdict_texts(e)["value"], "limit": limit_as_written(e), "anchor": "req-" + e.id}
            for e in result.failed() if e.severity != Severity.MANDATORY]


def evidence_block(result: CheckResult) -> dict:
    """The model's evidence in page-1 words: status word, summary, the judged verdicts resting on contradicted figures."""
    ev = result.model_evidence
    if ev is None:
        if result.validation:  # a recording validation added by `govcheck report --validation`
            ok = ValidationRecord.from_dict(result.validation, "results.validation").passed
            return {"status": "validated" if ok else "contradicted", "word": "VALIDATED" if ok else "CONTRADICTED",
                    "summary": f"compared with a recording: {'every window within its limits' if ok else 'windows outside their limits'} "
                               "(section 6)", "verdicts": []}
        return {"status": "not validated", "word": "NOT VALIDATED",
                "summary": "no measurement of this servo was compared with the model", "verdicts": []}
    contradicted = {c.requirement: c for c in ev.contradicted}
    verdicts = []
    for e in result.requirements:
        if e.id not in contradicted or e.status in _OPEN_OR_OFF:
            continue
        c = contradicted[e.id]
        verdicts.append({"id": c.requirement, "severity": c.severity, "status": e.status,
                         "word": status_word(e.status), "lean": c.lean, "text": c.text})
    verdicts.sort(key=lambda v: (v["severity"] != Severity.MANDATORY, v["status"] == Status.PASS))
    summary = ev.summary.removeprefix(f"{ev.status}: ")  # the word is printed before it
    if ev.status == "contradicted":
        summary = (f"{ev.contradict} of {ev.compared} independent measured figures disagree with the model: "
                   + "; ".join(ev.examples[:2]))
    return {"status": ev.status, "word": ev.word if ev.status in ("validated", "contradicted") else "NOT VALIDATED",
            "summary": summary, "verdicts": verdicts, "sources": [s.label for s in ev.sources]}


def _ids(ids: list[str]) -> str:
    return ", ".join(dict.fromkeys(ids))


def _of(ids: list[str], v_max: float) -> str:
    """``IEEE125-NOFASTER's 32.0 mm/s`` or, for several limits alike, ``the 32.0 mm/s of A, B``."""
    ids = list(dict.fromkeys(ids))
    speed = f"{v_max * 1e3:.1f} mm/s"
    return f"{ids[0]}'s {speed}" if len(ids) == 1 else f"the {speed} of {', '.join(ids)}"


def finding_groups(findings) -> list[dict]:
    """Findings that say the same thing of several requirements, grouped: ``{line, text, mandatory, kind, count,
    explain}`` each, ``line`` in a few words with the figures (every requirement the group involves), ``text`` the
    first finding's full explanation, shown (``explain``) for the first group of each kind whose line does not
    already say it; a group is mandatory when one of its findings is (``findings``: the result's ``Finding``
    records, their arithmetic's SI figures read by ``Finding.figure``)."""
    groups: dict = {}
    for f in findings:
        t_min, step, v_max = f.figure("t_min"), f.figure("step"), f.figure("v_max")
        if f.kind == "narrowing" and t_min is not None and v_max is not None:
            key = ("narrowing figures", round(t_min, 6), f.figure("t_max"), round(v_max, 6))
        elif f.kind == "rate_split" and step is not None and v_max is not None:
            key = ("rate_split figures", f.requirements[0], round(step, 6), round(v_max, 6))
        else:
            key = (f.kind, f.text)
        groups.setdefault(key, []).append(f)
    out = []
    for key, fs in groups.items():
        f = fs[0]
        partners = [g.requirements[1] for g in fs if len(g.requirements) > 1]
        if key[0] == "narrowing figures":
            t_max = f.figure("t_max")
            hi = "" if t_max is None else f"\u2013{t_max:.3g} s"
            line = (f"narrowing: {_ids([g.requirements[0] for g in fs])} with {_ids(partners)} "
                    f"(\u2264 {f.figure('v_max') * 1e3:.1f} mm/s) admit only strokes of {f.figure('t_min'):.3g}"
                    f"{hi or ' s or longer'}")
        elif key[0] == "rate_split figures":
            line = (f"rate split: {f.requirements[0]} (\u2264 {f.figure('tau_max'):.3g} s on {f.figure('step') * 1e3:.1f} mm "
                    f"steps) needs {f.figure('mean_speed') * 1e3:.1f} mm/s, above {_of(partners, f.figure('v_max'))} "
                    "(met only with the speed-limiting devices not acting)")
        else:
            line = f"{f.kind.replace('_', ' ')}: {f.text}"
        out.append({"line": line, "text": f.text, "mandatory": any(g.mandatory for g in fs), "kind": f.kind,
                    "count": len(fs), "advisory": sorted({r for g in fs if not g.mandatory for r in g.requirements}
                                                         - {r for g in fs if g.mandatory for r in g.requirements})})
    out.sort(key=lambda g: not g["mandatory"])
    seen = set()
    for g in out:  # the arithmetic once per kind of finding: the next groups of that kind repeat it with other ids
        g["explain"] = g["kind"] not in seen and g["line"] != f"{g['kind'].replace('_', ' ')}: {g['text']}"
        seen.add(g["kind"])
    return out


def findings_lines(result: CheckResult) -> dict:
    """The requirement set's findings on page 1: one line per group of mandatory findings, and how many involve
    advisory requirements."""
    mandatory = [f for f in result.findings if f.mandatory]
    return {"lines": [g["line"] for g in finding_groups(mandatory)], "advisory": len(result.findings) - len(mandatory),
            "total": len(result.findings)}
