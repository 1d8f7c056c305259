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
- the model's evidence (``model_evidence``): validated or not, and the verdicts that rest on
  figures the measurements contradict;
- the loop's stability margins against govcheck's criterion (``stability``);
- the requirement set's own findings (``findings``: narrowing, rate splits, tensions).

Only the results dict is read; nothing here computes a verdict.
"""

from __future__ import annotations

from collections import Counter

from compliance.campaign.coverage import case_coverage, case_coverage_text
from compliance.campaign.basis import verdict_qualifier
from compliance.model.parameters import used_by_model
from compliance.presentation.values import limit_as_written, metric_text, row_texts
from compliance.requirements.verdict import Overall, Severity, Status
from compliance.units.formatting import fmt_si, status_word

SOURCE_WORDS = {"paper": "from the paper", "assumed": "assumed", "derived": "derived", "user": "set by the user",
                "fitted": "fitted to a recording"}


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
    ev = results.get("model_evidence") or {}
    if ev.get("sources"):
        validated = f"{ev['status']} against the measurements the plant file names (section 6)"
    elif val:
        ok = (val.get("summary") or {}).get("pass")
        validated = (f"validated against a recording: {'PASS' if ok else 'FAIL' if ok is False else 'not decided'} "
                     "(section 6)")
    else:
        validated = "not validated: no recording of this servo was compared with the model"
    bases = Counter(str(e.get("basis")) for e in results["requirements"] if e.get("basis"))
    return {"model": plant["name"], "params": ", ".join(parts), "n_params": sum(counts.values()),
            "n_unused": len(params) - len(used), "assumed": counts.get("assumed", 0),
            "effects": [e.get("name") for e in plant.get("effects") or []], "fitted": fitted, "validated": validated,
            "validation_run": bool(val) or ev.get("status") in ("validated", "contradicted"), "deciding": _deciding(results, used),
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
    why = None
    if draft:  # in the signer's words: what is missing, not how to add it
        missing = ["the site, the unit and the equipment are not identified"] if needs_identity and not identity else []
        why = "; ".join(missing + ([] if number else ["no document number has been assigned"]))
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
                                     f"({best['delta_margin_pct']:+.1f} points per {fmt_si(best['step'], best['unit'])})".replace("-", "\u2212"))
    return out


remedy_lines = _remedy_lines  # page 1's lines (report.page_one) read the same remedies


def failures(results: dict) -> list[dict]:
    """One line per failed requirement: the failing number against its limit, where, and the remedy if computed."""
    remedies = _remedy_lines(results.get("remedies"))
    out = []
    for e in results["requirements"]:
        if e["status"] != Status.FAIL:
            continue
        w = e.get("worst") or {}
        out.append({"id": e["id"], "title": e["title"], "severity": e["severity"], "value": row_texts(w, e["metric"])["value"],
                    "limit": limit_as_written(e), "margin_pct": row_texts(w, e["metric"])["margin_pct"],
                    "where": f"{w.get('procedure')} at {w.get('operating_point')}" if w.get("procedure") else None,
                    "remedy": remedies.get(e["id"]), "anchor": "req-" + e["id"]})
    return out


def not_evaluated(results: dict) -> dict:
    """Judged test cases not evaluated, counted by reason, on the basis of the terminal and JSON summaries
    (:func:`compliance.campaign.coverage.case_coverage`)."""
    cov = case_coverage(results["requirements"])
    reasons = Counter()
    for e in results["requirements"]:
        if e.get("limit") is None:
            continue
        for r in e["rows"]:
            if r.get("status") == Status.NOT_EVALUATED:
                reasons[(e["id"], str(r.get("reason") or "no value").split(":")[0].split(";")[0].strip())] += 1
    items = [{"requirement": rid, "reason": why, "count": n} for (rid, why), n in reasons.most_common()]
    return {"cases": cov["rows"], "count": cov["not_evaluated"], "evaluated": cov["evaluated"], "basis": cov["basis"],
            "text": case_coverage_text(cov), "reasons": items,
            "requirements": (results["summary"].get("counts") or {}).get(Status.NOT_EVALUATED, 0)}


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


def qualified_verdict(results: dict) -> dict:
    """Page 1's verdict: the word, its qualifier (``campaign.basis.verdict_qualifier``) and why, in the owner's words.

    A PASS against assumed limits or on a mostly assumed model is not a plain (green) PASS: its
    class is ``warn`` and the qualifier is printed under the word.
    """
    status = results["summary"]["status"]
    summary = results["summary"]
    qualifier = (summary["qualifier"] if "qualifier" in summary else verdict_qualifier(results)) if status == Overall.PASS else None
    if not qualifier:
        return {"status": status, "qualifier": None, "css": None, "why": None}
    b = basis(results)
    why = []
    if "assumed targets" in qualifier:
        ids = [e["id"] for e in results["requirements"] if e.get("limit_assumed") and e["status"] == Status.PASS]
        why.append(f"the limits of {', '.join(ids)} are assumed design targets of the requirement file, not figures of a "
                   "standard or of the plant owner")
    if "assumed model" in qualifier:
        why.append(f"{b['assumed']} of the {b['n_params']} parameters the model uses are assumed")
    return {"status": status, "qualifier": qualifier, "css": "warn",
            "why": "; ".join(why) + ": the PASS says the model meets these targets, not that the built system meets "
                                    "a specification"}


# --------------------------------------------------------------------------- beyond the verdict word
_OPEN_OR_OFF = (Status.OPEN, Status.DISABLED)
_NOT_MET = (Status.FAIL, Status.UNCERTAIN, Status.NOT_EVALUATED)
# the consequence of a contradicted figure in two words (model_evidence.contradicted[].consequence)
_LEANS = (("pessimistic", "the model errs towards the limit"), ("optimistic", "the model errs away from the limit"))


def _contradicted(results: dict) -> dict:
    return {c["requirement"]: c for c in (results.get("model_evidence") or {}).get("contradicted") or []}


def _lean(c: dict) -> str:
    """What a contradicted figure means for the verdict, in one word: the model errs towards the limit
    (pessimistic), away from it (optimistic), or both ways."""
    for word, _ in _LEANS:
        if word in c.get("consequence", ""):
            return word
    return "either way"


def _band_text(band, metric: str) -> str | None:
    if not isinstance(band, dict) or band.get("low") is None:
        return None
    lo, hi = metric_text(band["low"], metric), metric_text(band["high"], metric)
    return f"band {lo.rsplit(' ', 1)[0]}\u2013{hi}" if lo.rsplit(" ", 1)[-1] == hi.rsplit(" ", 1)[-1] else f"band {lo}\u2013{hi}"


def mandatory_not_met(results: dict, remedies: dict | None = None) -> list[dict]:
    """One line per mandatory requirement that failed, is uncertain or was not evaluated (worst first by status)."""
    contradicted = _contradicted(results)
    out = []
    for e in results["requirements"]:
        if e["severity"] != Severity.MANDATORY or e["status"] not in _NOT_MET:
            continue
        w = e.get("worst") or {}
        texts = row_texts(w, e["metric"]) if w else {}
        band = w.get("band") or e.get("band") or {}
        reason = None
        if e["status"] == Status.NOT_EVALUATED:
            reasons = sorted({str(r.get("reason")).split(":")[0] for r in e["rows"] if r.get("reason")})
            reason = "; ".join(reasons)[:160] or "no value"
        c = contradicted.get(e["id"])
        out.append({
            "id": e["id"], "title": e["title"], "status": e["status"], "word": status_word(e["status"]),
            "value": "no response" if w.get("non_responding") else texts.get("value") or "\u2013",
            "limit": limit_as_written(e), "margin_pct": texts.get("margin_pct"),
            "where": f"{w['procedure']} at {w['operating_point']}" if w.get("procedure") else None,
            "band": _band_text(band, e["metric"]), "deciding": list(band.get("deciding") or []),
            "reason": reason, "anchor": "req-" + e["id"],
            "contradicted": None if c is None else f"contradicted by measurement ({_lean(c)}): {c.get('example') or c['text']}",
            "remedy": (remedies or {}).get(e["id"]),
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


def advisory_failures(results: dict) -> list[dict]:
    """Advisory requirements that failed: id, value and limit (they do not decide the verdict)."""
    out = []
    for e in results["requirements"]:
        if e["severity"] == Severity.MANDATORY or e["status"] != Status.FAIL:
            continue
        w = e.get("worst") or {}
        out.append({"id": e["id"], "value": row_texts(w, e["metric"])["value"] if w else "\u2013",
                    "limit": limit_as_written(e), "anchor": "req-" + e["id"]})
    return out


def evidence_block(results: dict) -> dict:
    """The model's evidence in page-1 words: status word, summary, the judged verdicts resting on contradicted figures."""
    ev = results.get("model_evidence")
    if not ev:
        val = results.get("validation")
        if val:  # a recording validation added by `govcheck report --validation`
            ok = (val.get("summary") or {}).get("pass")
            return {"status": "validated" if ok else "contradicted", "word": "VALIDATED" if ok else "CONTRADICTED",
                    "summary": f"compared with a recording: {'every window within its limits' if ok else 'windows outside their limits'} "
                               "(section 6)", "verdicts": []}
        return {"status": "not validated", "word": "NOT VALIDATED",
                "summary": "no measurement of this servo was compared with the model", "verdicts": []}
    by_id = {e["id"]: e for e in results["requirements"]}
    verdicts = []
    for c in ev.get("contradicted") or []:
        e = by_id.get(c["requirement"])
        if e is None or e["status"] in _OPEN_OR_OFF:
            continue
        verdicts.append({"id": c["requirement"], "severity": c["severity"], "status": e["status"],
                         "word": status_word(e["status"]), "lean": _lean(c), "text": c["text"]})
    verdicts.sort(key=lambda v: (v["severity"] != Severity.MANDATORY, v["status"] == Status.PASS))
    word = {"validated": "VALIDATED", "contradicted": "CONTRADICTED"}.get(ev["status"], "NOT VALIDATED")
    summary = ev["summary"].removeprefix(f"{ev['status']}: ")  # the word is printed before it
    if ev["status"] == "contradicted":
        summary = (f"{ev['contradict']} of {ev['compared']} independent measured figures disagree with the model: "
                   + "; ".join((ev.get("examples") or [])[:2]))
    return {"status": ev["status"], "word": word, "summary": summary, "verdicts": verdicts,
            "sources": [s.get("title") or s.get("path") for s in ev.get("sources") or []]}


def stability_line(results: dict) -> dict | None:
    """The loop's margins against govcheck's criterion, or None when not analysed in these results."""
    st = results.get("stability")
    if not st:
        return None
    below = [p for p in st.get("points") or [] if p.get("meets") is False]
    return {"summary": st.get("summary"), "below": len(below), "points": len(st.get("points") or []),
            "criterion": st.get("criterion") or {}}


def _ids(ids: list[str]) -> str:
    return ", ".join(dict.fromkeys(ids))


def finding_groups(findings: list[dict]) -> list[dict]:
    """Findings that say the same thing of several requirements, grouped: ``{line, text, mandatory, kind}`` each,
    ``line`` in a few words with the figures, ``text`` the first finding's full explanation."""
    groups: dict = {}
    for f in findings:
        if f["kind"] == "narrowing" and f.get("t_min") is not None:
            key = ("narrowing figures", f["requirements"][1], round(f["t_min"], 6), f.get("t_max"))
        elif f["kind"] == "rate_split" and f.get("step") is not None:
            key = ("rate_split figures", tuple(f["requirements"]), round(f["step"], 6))
        else:
            key = (f["kind"], f["text"])
        groups.setdefault(key, []).append(f)
    out = []
    for key, fs in groups.items():
        f = fs[0]
        if key[0] == "narrowing figures":
            hi = "" if f.get("t_max") is None else f"\u2013{f['t_max']:.3g} s"
            line = (f"narrowing: {_ids([g['requirements'][0] for g in fs])} with {f['requirements'][1]} "
                    f"(\u2264 {f['v_max'] * 1e3:.1f} mm/s) admit only strokes of {f['t_min']:.3g}{hi or ' s or longer'}")
        elif key[0] == "rate_split figures":
            line = (f"rate split: {f['requirements'][0]} (\u2264 {f['tau_max']:.3g} s on {f['step'] * 1e3:.1f} mm steps) needs "
                    f"{f['mean_speed'] * 1e3:.1f} mm/s, above {f['requirements'][1]}'s {f['v_max'] * 1e3:.1f} mm/s "
                    "(met only with the speed-limiting devices not acting)")
        else:
            line = f"{f['kind'].replace('_', ' ')}: {f['text']}"
        out.append({"line": line, "text": f["text"], "mandatory": bool(f.get("mandatory")), "kind": f["kind"],
                    "count": len(fs)})
    return sorted(out, key=lambda g: not g["mandatory"])


def findings_lines(results: dict) -> dict:
    """The requirement set's findings on page 1: one line per group of mandatory findings, and how many involve
    advisory requirements."""
    findings = results.get("findings") or []
    mandatory = [f for f in findings if f.get("mandatory")]
    return {"lines": [g["line"] for g in finding_groups(mandatory)], "advisory": len(findings) - len(mandatory),
            "total": len(findings)}
