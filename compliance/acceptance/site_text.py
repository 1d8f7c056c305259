"""The site verdict as a terminal reads it: one line per requirement, measured beside predicted, then what it rests on."""

from __future__ import annotations

from compliance.presentation.values import limit_as_written, metric_text
from compliance.requirements.verdict import Status
from compliance.presentation.numbers import STATUS_WORD

__all__ = ["site_table", "site_lines"]


def _measured(e: dict) -> str:
    w = e.get("worst") or {}
    if w.get("non_responding"):
        return "no response"
    if w.get("value") is None:
        return "-"
    u = w.get("u")
    return metric_text(w["value"], e["metric"], unicode=False) + ("" if not u else f" +/- {metric_text(u, e['metric'], 2, unicode=False)}")


def _predicted(e: dict) -> str:
    p = e.get("prediction")
    if not p or p.get("value") is None:
        return "-"
    m = e["metric"]
    return f"{metric_text(p['value'], m, unicode=False)} [{metric_text(p['low'], m, 2, unicode=False)}..{metric_text(p['high'], m, 2, unicode=False)}]"


def _status(e: dict) -> str:
    word = STATUS_WORD.get(e["status"], e["status"])
    cov = e.get("coverage") or {}
    if e["status"] in (Status.PASS, Status.FAIL, Status.UNCERTAIN) and not cov.get("complete", True):
        word += f" ({len(cov['tested'])}/{cov['asked']} tested)"
    return word


def _row(e: dict) -> tuple:
    w = e.get("worst") or {}
    p = e.get("prediction")
    model = "-" if not p else (STATUS_WORD.get(p["status"], p["status"]) + ("" if p["agree"] else " *"))
    where = (w.get("run") or "-") + (f" ({w['which']})" if w.get("which") else "")
    return (e["id"], limit_as_written(e, unicode=False), _measured(e), _predicted(e), model, where, e["severity"], _status(e))


def site_lines(results: dict) -> list:
    """The lines under the table: what was not tested, departures, disagreements, the diagnosis, the verdict."""
    s = results["summary"]
    c = s["counts"]
    site = results["site"]
    out = [f"site {site['name']} ({len(site['recordings'])} recordings) against {results['requirement_set']['name']}, "
           f"predicted by {results['plant']['name']}",
           f"{c['pass']} pass, {c.get('fail_mandatory', 0)} fail (mandatory), {c.get('fail_advisory', 0)} fail (advisory), "
           f"{c.get('uncertain', 0)} uncertain, {c['not_evaluated']} not evaluated, {c['open']} open (no limit set)",
           "  (measured: each value +/- its expanded measurement uncertainty (k = 2); model: the prediction's verdict, "
           "* where a test disagrees beyond the band and the uncertainty)"]
    for r in site["recordings"]:
        if r.get("problem"):
            out.append(f"  not judged {r['name']}: {r['problem']}")
        elif r["test"]["source"] != "sidecar":
            out.append(f"  recognised {r['name']}: {r['test']['kind']} ({r['test']['source']})")
    for e in results["requirements"]:
        cov = e.get("coverage") or {}
        if e["status"] == Status.NOT_EVALUATED:
            reasons = sorted({r["reason"] for r in e["rows"] if r.get("reason")}) or [e.get("reason") or "-"]
            out.append(f"  not evaluated {e['id']}: {'; '.join(reasons)[:220]}")
        elif e["status"] != Status.OPEN and cov.get("not_tested") and e["status"] != Status.DISABLED:
            out.append(f"  not tested for {e['id']}: {', '.join(cov['not_tested'][:6])}" + (" ..." if len(cov["not_tested"]) > 6 else ""))
    agree = s.get("agreement") or {}
    if agree.get("tests"):
        out.append(f"  the model disagrees on {', '.join(agree['tests'])} ({', '.join(agree['disagree'])})")
    if agree.get("verdicts_differ"):
        out.append(f"  the model's verdict differs on {', '.join(agree['verdicts_differ'])}")
    d = results.get("diagnosis")
    if d:
        out.append("  diagnosis: " + d.get("text", ""))
    for n in s.get("notes", []):
        out.append(f"  {n}")
    out.append(f"VERDICT: {s['status'].upper()}" + (f" (mandatory failures: {', '.join(s['failed_mandatory'])})"
                                                    if s.get("failed_mandatory") else ""))
    return out


def site_table(results: dict) -> str:
    """Fixed-width table of a site's verdicts (see the module docstring)."""
    head = ("requirement", "limit", "measured", "predicted [band]", "model", "worst test", "severity", "status")
    rows = [_row(e) for e in results["requirements"]]
    widths = [max(len(str(r[i])) for r in rows + [head]) for i in range(len(head))]
    widths[5] = min(widths[5], 56)

    def line(r):
        cells = [str(c) if i != 5 or len(str(c)) <= widths[5] else str(c)[: widths[5] - 1] + "~" for i, c in enumerate(r)]
        return "  ".join(c.ljust(widths[i]) for i, c in enumerate(cells)).rstrip()

    return "\n".join([line(head), line(tuple("-" * w for w in widths))] + [line(r) for r in rows] + [""] + site_lines(results)) + "\n"
