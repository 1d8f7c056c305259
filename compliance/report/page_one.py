"""What page 1 of the compliance report (and the terminal summary) says beyond the verdict word.

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

from compliance.presentation.values import limit_as_written, metric_text, row_texts
from compliance.requirements.verdict import Severity, Status
from compliance.units.formatting import status_word

__all__ = ["evidence_block", "findings_lines", "mandatory_not_met", "stability_line"]

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
            "contradicted": None if c is None else f"contradicted by measurement ({_lean(c)})",
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
    summary = ev["summary"]
    if ev["status"] == "contradicted":
        summary = (f"{ev['contradict']} of {ev['compared']} independent measured figures disagree with the model: "
                   + "; ".join((ev.get("examples") or [])[:3]))
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


def findings_lines(results: dict) -> dict:
    """The requirement set's findings: one line per group of mandatory findings, and how many involve advisory ones."""
    findings = results.get("findings") or []
    mandatory = [f for f in findings if f.get("mandatory")]
    groups: dict = {}
    for f in mandatory:
        if f["kind"] == "narrowing" and f.get("t_min") is not None:
            key = ("narrowing figures", f["requirements"][1], round(f["t_min"], 6), f.get("t_max"))
        elif f["kind"] == "rate_split" and f.get("step") is not None:
            key = ("rate_split figures", tuple(f["requirements"]), round(f["step"], 6))
        else:
            key = (f["kind"], f["text"])
        groups.setdefault(key, []).append(f)
    lines = []
    for key, fs in groups.items():
        f = fs[0]
        if key[0] == "narrowing figures":
            hi = "" if f.get("t_max") is None else f"\u2013{f['t_max']:.3g} s"
            lines.append(f"narrowing: {_ids([g['requirements'][0] for g in fs])} with {f['requirements'][1]} "
                         f"(\u2264 {f['v_max'] * 1e3:.1f} mm/s) admit only strokes of {f['t_min']:.3g}{hi or ' s or longer'}")
        elif key[0] == "rate_split figures":
            lines.append(f"rate split: {f['requirements'][0]} (\u2264 {f['tau_max']:.3g} s on {f['step'] * 1e3:.1f} mm steps) needs "
                         f"{f['mean_speed'] * 1e3:.1f} mm/s, above {f['requirements'][1]}'s {f['v_max'] * 1e3:.1f} mm/s "
                         "(met only with the speed-limiting devices not acting)")
        else:
            lines.append(f"{f['kind'].replace('_', ' ')}: {f['text']}")
    return {"lines": lines, "advisory": len(findings) - len(mandatory), "total": len(findings)}


def _figure_cells(f: dict) -> dict:
    if f["agreement"] is None:
        word, css = "no measured figure", "neutral"
    elif f["by_construction"]:
        word, css = "by construction (derived to give it)", "neutral"
    elif not f["independent"]:
        word, css = f"{f['agreement']} (fitted to it)", "neutral"
    else:
        word, css = f["agreement"], "pass" if f["agreement"] == "agrees" else "fail"
    shown = f.get("display") or {}
    return {"test": f["test"], "metric": f["metric"], "modelled": shown.get("modelled", "\u2013"),
            "measured": shown.get("measured", "\u2013"), "agreement": word, "css": css}


def evidence_sections(results: dict) -> tuple[list[dict], list[dict]]:
    """Section 6's tables: each source of the model evidence with its figures, and the verdicts on contradicted figures."""
    ev = results.get("model_evidence") or {}
    out = []
    for s in ev.get("sources") or []:
        if s["kind"] == "paper":
            out.append({"kind": "paper", "title": "Measured figures of the plant paper", "command": s["command"],
                        "independence": s["independence"].capitalize(), "rows": [_figure_cells(f) for f in s["figures"]]})
        else:
            modes = "; ".join(f"{m.replace('_', ' ')}: {'every window within its limits' if d['pass'] else str(len(d['failed_windows'])) + ' of ' + str(d['windows']) + ' windows outside their limits'}"
                              for m, d in s["modes"].items())
            out.append({"kind": "recording", "title": f"Recording {s['path']}", "command": s["command"],
                        "independence": "A recording of the servo, replayed with the model", "summary": modes})
    return out, list(ev.get("contradicted") or [])
