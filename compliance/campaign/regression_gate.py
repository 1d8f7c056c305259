"""Regression gate: compare a candidate's results with a baseline's, requirement by requirement.

The gate trips when
- a requirement that passed in the baseline does not pass in the candidate (fail, or no
  longer evaluated: a check that silently stops running must not look like a pass),
- a mandatory requirement that was evaluated in the baseline (pass or fail) cannot be
  evaluated in the candidate (a change that makes a failing requirement unmeasurable must not
  turn a known failure into silence), unless the user allows it explicitly for that id
  (``allow_not_evaluated``); the reason it could not be evaluated is in the row,
- a requirement present in the baseline is missing from the candidate,
- a requirement new in the candidate fails,
- a requirement uncertain in the baseline (its band straddles the limit, so it may pass) fails in the
  candidate,
- a requirement's worst-case margin shrinks by more than ``max_margin_loss`` percentage
  points (margins in % of the binding limit, docs/metrics.md), when the user sets it.
A requirement already failing in the baseline is reported, not counted as a regression.
"""

from __future__ import annotations

from compliance.requirements.verdict import Overall, Severity, Status
from compliance.results.check_result import CheckResult
from compliance.results.entries import RequirementVerdict
from compliance.presentation.numbers import STATUS_WORD as _STATUS_WORD


def _worst(entry: RequirementVerdict | None):
    """(margin %, value, value as displayed) of a requirement's worst case."""
    w = entry.worst if entry is not None else None
    if w is None:
        return None, None, "-"
    return w.margin_pct, w.value, w.display.value if w.display is not None else "-"


def not_evaluated_reason(entry: RequirementVerdict | None) -> str | None:
    """Why a requirement could not be evaluated (the distinct reasons of its rows), or None."""
    if entry is None or entry.status != Status.NOT_EVALUATED:
        return None
    return "; ".join(entry.not_evaluated_reasons() or ([entry.reason] if entry.reason else [])) or "no reason recorded"


def _status_reasons(rid: str, b, c, why: str | None, allowed: bool):
    """Why a status change trips the gate (list), and the note of an explicitly allowed one (or None)."""
    bs = b.status if b else "absent"
    cs = c.status if c else "absent"
    if b is not None and c is None:
        return ["requirement removed in the candidate"], None
    if b is None and cs == Status.FAIL:
        return ["new requirement fails"], None
    if cs == Status.NOT_EVALUATED and (bs == Status.PASS or (bs == Status.FAIL and c.severity == Severity.MANDATORY)):
        if allowed:
            return [], f"{bs} -> not_evaluated allowed explicitly (--allow-not-evaluated {rid}): {why}"
        return [f"{bs} -> not_evaluated: could not be evaluated: {why}"], None
    if bs == Status.PASS and cs != Status.PASS:
        return [f"{bs} -> {cs}"], None
    if bs == Status.UNCERTAIN and cs == Status.FAIL:  # the baseline could pass; the candidate fails outright
        return [f"{bs} -> {cs}: the baseline's band reached the limit, the candidate fails it"], None
    return [], None


def _subject(result) -> dict:
    """What a result judged: a plant configuration, or a site's recordings (``govcheck accept``)."""
    site = getattr(result, "site", None)
    if site is not None:
        return {"plant": f"site {site['name']}", "digest": site.get("digest"), "path": site.get("path"),
                "verdict": result.summary.status}
    p = result.plant
    return {"plant": p.name, "digest": p.digest, "path": p.path, "verdict": result.summary.status}


def compare(baseline, candidate, max_margin_loss: float | None = None,
            allow_not_evaluated: tuple[str, ...] | list[str] = ()) -> dict:
    """Compare two check results.

    Parameters
    ----------
    baseline, candidate : CheckResult or SiteResult
        Results of ``govcheck check`` (``compliance.check``, or a results file read with ``read_results``) or of
        ``govcheck accept`` (schema govcheck-site/1: a re-commissioning gated against the last one).
    max_margin_loss : float, optional
        Largest allowed loss of worst-case margin [percentage points]; None: not checked.
    allow_not_evaluated : sequence of str
        Requirement ids allowed to become not evaluated (the row says so; the gate does not trip).

    Returns
    -------
    dict
        ``{"status": "pass"|"fail", "tripped": [...ids], "rows": [...], "notes": [...], ...}`` (schema ``govcheck-gate/1``)
    """
    base, cand = baseline.verdicts, candidate.verdicts
    rows, tripped, notes = [], [], []
    allowed = set(allow_not_evaluated)
    unknown = sorted(allowed - set(base) - set(cand))
    if unknown:
        notes.append(f"--allow-not-evaluated names requirements not in either result: {', '.join(unknown)}")
    bset, cset = baseline.requirement_set, candidate.requirement_set
    if bset.digest != cset.digest:
        notes.append(f"requirement files differ: baseline {bset.name} ({str(bset.digest)[:12]}), "
                     f"candidate {cset.name} ({str(cset.digest)[:12]})")
    for rid in list(base) + [k for k in cand if k not in base]:
        b, c = base.get(rid), cand.get(rid)
        bm, bv, bd = _worst(b)
        cm, cv, cd = _worst(c)
        delta = None if bm is None or cm is None else cm - bm
        why = not_evaluated_reason(c)
        reasons, allowed_note = _status_reasons(rid, b, c, why, rid in allowed)
        if max_margin_loss is not None and delta is not None and -delta > max_margin_loss:
            reasons.append(f"margin lost {-delta:.1f} pp > {max_margin_loss:g} pp allowed")
        if reasons:
            tripped.append(rid)
        ref = c or b
        bs, cs = (b.status if b else "absent"), (c.status if c else "absent")
        rows.append({
            "id": rid, "title": ref.title, "metric": ref.metric, "limit_text": ref.limit_text, "severity": ref.severity,
            "baseline": {"status": bs, "value": bv, "display": bd, "margin_pct": bm},
            "candidate": {"status": cs, "value": cv, "display": cd, "margin_pct": cm},
            "margin_change_pp": delta, "tripped": bool(reasons), "reasons": reasons, "not_evaluated_reason": why,
            "allowed": allowed_note, "preexisting_failure": bs == Status.FAIL and cs == Status.FAIL,
        })
    return {
        "schema": "govcheck-gate/1",
        "subject": "site" if getattr(candidate, "site", None) is not None else "plant",
        "status": Overall.FAIL if tripped else Overall.PASS,
        "tripped": tripped,
        "max_margin_loss": max_margin_loss,
        "allow_not_evaluated": sorted(allowed),
        "baseline": _subject(baseline),
        "candidate": _subject(candidate),
        "requirements": {"name": cset.name, "path": cset.path, "digest": cset.digest},
        "rows": rows,
        "notes": notes,
    }


def _cell(side: dict) -> str:
    word = _STATUS_WORD.get(side["status"], side["status"].upper())
    m = "" if side["margin_pct"] is None else f" ({side['margin_pct']:+.1f} %)"
    return f"{word} {side['display']}{m}" if side["display"] not in (None, "-") else word


def _gate_cell(row: dict, tripped_word: str) -> str:
    """The gate column: why it tripped, an explicit allowance, or ok; with the not-evaluated reason."""
    if row["tripped"]:
        return f"{tripped_word}: " + "; ".join(row["reasons"])
    if row.get("allowed"):
        return f"allowed: {row['allowed']}"
    cs = row["candidate"]["status"]
    text = ("still failing" if row["preexisting_failure"] else
            "no regression (candidate fails; not passing in the baseline either)" if cs == Status.FAIL else
            "no regression (candidate uncertain)" if cs == Status.UNCERTAIN else "ok")
    if row.get("not_evaluated_reason"):
        text += f" (not evaluated: {row['not_evaluated_reason']})"
    return text


def gate_table(result: dict) -> str:
    """Side-by-side terminal table of a gate result."""
    head = ("requirement", "limit", "baseline", "candidate", "margin change", "gate")
    rows = []
    for r in result["rows"]:
        d = "-" if r["margin_change_pp"] is None else f"{r['margin_change_pp']:+.1f} pp"
        rows.append((r["id"], r["limit_text"], _cell(r["baseline"]), _cell(r["candidate"]), d, _gate_cell(r, "TRIPPED")))
    widths = [max(len(str(x[i])) for x in rows + [head]) for i in range(len(head))]
    line = lambda x: "  ".join(str(c).ljust(widths[i]) for i, c in enumerate(x)).rstrip()  # noqa: E731
    out = [line(head), line(tuple("-" * w for w in widths))] + [line(x) for x in rows]
    out += [""] + [f"note: {n}" for n in result["notes"]]
    out.append(f"GATE: {result['status'].upper()}" + (f" ({len(result['tripped'])} regression(s): {', '.join(result['tripped'])})" if result["tripped"] else ""))
    return "\n".join(out) + "\n"


def gate_markdown(result: dict) -> str:
    """Markdown summary fit for a pull-request comment."""
    ok = result["status"] == Overall.PASS
    b, c = result["baseline"], result["candidate"]
    lines = [
        f"### govcheck gate: {'passed' if ok else 'FAILED'}"
        + ("" if ok else f" - {len(result['tripped'])} regression(s)"),
        "",
        f"- baseline: `{b['plant']}` (`{str(b['digest'])[:12]}`), verdict **{b['verdict']}**",
        f"- candidate: `{c['plant']}` (`{str(c['digest'])[:12]}`), verdict **{c['verdict']}**",
        f"- requirements: `{result['requirements']['name']}` (`{str(result['requirements']['digest'])[:12]}`)",
        "- margin-loss threshold: " + ("not set" if result["max_margin_loss"] is None else f"{result['max_margin_loss']:g} percentage points"),
        "",
        "| requirement | limit | baseline | candidate | margin change | gate |",
        "|---|---|---|---|---|---|",
    ]
    for r in result["rows"]:
        d = "-" if r["margin_change_pp"] is None else f"{r['margin_change_pp']:+.1f} pp"
        g = _gate_cell(r, "**tripped**").replace("|", "\\|")
        lines.append(f"| `{r['id']}` {r['title']} | {r['limit_text']} | {_cell(r['baseline'])} | {_cell(r['candidate'])} | {d} | {g} |")
    for n in result["notes"]:
        lines += ["", f"> note: {n}"]
    return "\n".join(lines).replace("|  |", "| - |") + "\n"
