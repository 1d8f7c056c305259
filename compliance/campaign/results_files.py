"""What a check's result reads as outside the report: the terminal table and summary lines, JUnit XML.

The result itself writes and reads its JSON (``CheckResult.to_json``/``from_json``, schema
``govcheck-results/1``). Every file is written atomically (a temporary file in the target folder,
then ``os.replace``) so a CI job never reads half a file.
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

from compliance.campaign.coverage import CASES_BASIS, case_coverage_text
from compliance.files.atomic import write_text_atomic
from compliance.files.jsonable import json_text, read_json
from compliance.requirements.verdict import Basis, Severity, Status
from compliance.presentation.values import band_pct_text, limit_as_written
from compliance.results.check_result import CheckResult
from compliance.results.rows import RowTexts, VerdictRow, WorstCase
from compliance.results.site_result import SITE_SCHEMA, typed_results
from compliance.presentation.numbers import STATUS_WORD as _STATUS_WORD  # the one status-word table

__all__ = ["SITE_SCHEMA", "junit_xml", "read_results", "results_json", "summary_lines", "summary_table", "write_json",
           "write_junit"]


def results_json(results: dict) -> str:
    """Serialise a results dict (a site's, ``govcheck accept``) with the one JSON cleaner (non-finite numbers become null)."""
    return json_text(results, compact=True)  # compact: the traces make up most of the file; tools, not people, read it


def write_json(results: dict, path) -> None:
    """Write a results dict's JSON atomically (a check's result writes itself: ``CheckResult.to_json``)."""
    write_text_atomic(path, results_json(results))


def read_results(path):
    """Read a results JSON written by ``govcheck check`` (a ``CheckResult``) or by ``govcheck accept`` (a ``SiteResult``).

    Raises
    ------
    InputError
        Not JSON, not a govcheck results file of a supported schema, or a damaged one (the key named).
    """
    return typed_results(read_json(Path(path), "results"), str(path))


# --------------------------------------------------------------------------- terminal
_BASIS_WORD = {Basis.MODELLED: "modelled", Basis.BY_CONSTRUCTION: "by constr.", Basis.ASSUMED: "assumed", Basis.NOT_EVALUATED: "-"}


def _status_cell(e) -> str:
    word = _STATUS_WORD.get(e.status, e.status)
    if e.status == Status.PASS and e.basis == Basis.BY_CONSTRUCTION:
        return word + " (by construction)"
    return word


def _table_row(e) -> tuple:
    """One requirement's line: its worst case's value and margin (with the band's margins), cases, basis, status."""
    w = e.worst or WorstCase()
    d = w.display or RowTexts()
    margin = "-"
    if d.margin_pct:
        margin = d.margin_pct
    elif w.margin is not None:
        margin = d.margin
    band = band_pct_text(w.band, w.margin_pct)
    if band:
        margin += f" {band}"
    where = (w.run or "-") + (f" ({w.which})" if w.which else "")
    cov = e.coverage
    cases = f"{cov.evaluated}/{cov.rows}" if cov is not None and cov.rows and e.limit is not None else "-"
    value = "no response" if w.non_responding else d.value
    return (e.id, e.metric, limit_as_written(e, unicode=False), value, margin, cases, where, e.severity,
            _BASIS_WORD.get(e.basis, "-"), _status_cell(e))


def _requirement_lines(result: CheckResult) -> list[str]:
    """Why a requirement is not evaluated, passes only by construction, or is uncertain."""
    out = []
    for e in result.requirements:
        if e.status == Status.NOT_EVALUATED:
            out.append(f"  not evaluated {e.id}: {'; '.join(e.not_evaluated_reasons())[:200]}")
        elif e.status == Status.PASS and e.basis == Basis.BY_CONSTRUCTION:
            out.append(f"  by construction {e.id}: {((e.worst and e.worst.basis_reason) or '')[:200]}")
        elif e.status == Status.UNCERTAIN:
            band = e.worst.band if e.worst is not None else None
            deciding = ", ".join(band.deciding if band is not None else ())
            out.append(f"  uncertain {e.id}: its band straddles the limit; decided by {deciding or '-'}")
    return out


def summary_lines(result: CheckResult) -> list[str]:
    """The lines under the table: counts (passes by construction, advisory failures and coverage apart),
    what was not evaluated and why, findings of the requirement set, the assumptions that matter most."""
    s, c = result.summary, result.summary.counts
    out = [f"plant {result.plant.name} ({result.plant.path}) against "
           f"{result.requirement_set.name} ({result.requirement_set.path})"]
    remedy_yield = result.plant.provenance.get("remedy_yield")
    if remedy_yield:  # a configuration written by --save-remedy: the yield its search showed
        out.append(f"  remedy: {remedy_yield}")
    cov = s.coverage
    out.append(
        f"{c.passed} pass, {c.pass_by_construction} pass by construction (not evidence), "
        f"{c.fail_mandatory} fail (mandatory), {c.fail_advisory} fail (advisory), "
        f"{c.uncertain} uncertain, {c.not_evaluated} not evaluated, {c.open} open (no limit set), "
        f"{c.disabled} disabled" + (f"; {case_coverage_text(cov.as_dict())}" if cov else ""))
    if cov:
        out.append(f"  ({cov.basis or CASES_BASIS})")
    out += _requirement_lines(result)
    mandatory = [f for f in result.findings if f.mandatory]
    out += [f"  requirement set {f.kind}: {f.text}" for f in mandatory]
    others = len(result.findings) - len(mandatory)
    if others:
        out.append(f"  requirement set: {others} more finding(s) involving advisory requirements (results JSON, 'findings')")
    out += evidence_lines(result)
    if s.commissioned:
        out.append("  " + s.commissioned)
    if s.top_assumptions:
        out.append("  assumptions that matter most: " + "; ".join(f"{a.parameter} ({a.why})" for a in s.top_assumptions))
    out += [f"  {n}" for n in s.notes]
    qualifier = ", ".join(s.qualifiers)
    pending = [f"{w} {', '.join(ids)}" for w, ids in (("uncertain:", _mandatory(result, Status.UNCERTAIN)),
                                                       ("not evaluated:", _mandatory(result, Status.NOT_EVALUATED))) if ids]
    out.append(f"VERDICT: {s.status.upper()}" + (f" ({qualifier})" if qualifier else "")
               + (f" (mandatory failures: {', '.join(s.failed_mandatory)})" if s.failed_mandatory else "")
               + (f" (mandatory {'; '.join(pending)})" if pending else ""))
    return out


def _mandatory(result, status) -> list[str]:
    return [e.id for e in result.requirements if e.severity == Severity.MANDATORY and e.status == status]


def evidence_lines(result) -> list[str]:
    """The model's evidence and the loop's stability margins under the table (``model_evidence``, ``stability``)."""
    out = []
    ev = getattr(result, "model_evidence", None)  # a site's result carries none
    if ev is not None:
        out.append(f"  model evidence: {ev.summary}")
        judged = {e.id: e for e in result.requirements if e.status not in (Status.OPEN, Status.DISABLED)}
        rest = [f"{c.requirement} ({c.severity}, {_STATUS_WORD.get(judged[c.requirement].status, '')}: "
                f"{c.consequence.split(':')[0]})" for c in ev.contradicted if c.requirement in judged]
        if rest:
            out.append("  verdicts resting on figures the measurements contradict: " + "; ".join(rest))
    st = getattr(result, "stability", None)
    if st is not None:
        out.append(f"  stability of the linearised loop: {st.summary}")
    return out


def summary_table(result: CheckResult) -> str:
    """Fixed-width table: one line per requirement with its worst case, cases evaluated and basis, then the verdict."""
    head = ("requirement", "metric", "limit", "worst value", "margin", "cases", "worst case", "severity", "basis", "status")
    rows = [_table_row(e) for e in result.requirements]
    widths = [max(len(str(r[i])) for r in rows + [head]) for i in range(len(head))]
    widths[6] = min(widths[6], 62)

    def line(r):
        cells = [str(c) if i != 6 or len(str(c)) <= widths[6] else str(c)[: widths[6] - 1] + "~" for i, c in enumerate(r)]
        return "  ".join(c.ljust(widths[i]) for i, c in enumerate(cells)).rstrip()

    out = [line(head), line(tuple("-" * w for w in widths))] + [line(r) for r in rows]
    return "\n".join(out + [""] + summary_lines(result)) + "\n"


# --------------------------------------------------------------------------- JUnit
def _case(e, r) -> tuple[str, str]:
    """(kind of the JUnit outcome: "", failure, error, skipped; its XML body) of one verdict row."""
    d = r.display
    msg = (f"{e.metric} = {d.value} against {e.limit_text}" + (f", margin {d.margin_pct}" if d.margin_pct else "")
           + (f" ({r.which})" if r.which else ""))
    st = r.status
    body, kind = "", ""
    if st == Status.FAIL:
        kind, body = "failures", f"<failure message={quoteattr(msg)} type=\"requirement\">{escape(e.title)}</failure>"
    elif st in (Status.NOT_EVALUATED, Status.UNCERTAIN):
        band = r.band
        reason = (r.reason or "not evaluated") if st == Status.NOT_EVALUATED else (
            f"uncertain: band {band.low if band else None} .. {band.high if band else None} straddles the limit; decided by "
            + ", ".join(band.deciding if band else ()))
        if e.severity == Severity.MANDATORY:
            kind, body = "errors", f"<error message={quoteattr(reason)} type=\"{st}\"/>"
        else:
            kind, body = "skipped", f"<skipped message={quoteattr(reason)}/>"
    elif st in (Status.OPEN, Status.DISABLED):
        text = ("open: no limit set; measured " + d.value) if st == Status.OPEN else Status.DISABLED
        kind, body = "skipped", f"<skipped message={quoteattr(text)}/>"
    return kind, body + f"<system-out>{escape(msg)}</system-out>"


def junit_xml(result) -> str:
    """JUnit XML: one testsuite per requirement, one testcase per procedure x operating point.

    fail -> <failure>, not evaluated -> <error> for a mandatory requirement (the check could not
    be made) and <skipped> for an advisory one, open (no limit) -> <skipped>. ``result``: a ``CheckResult``,
    a ``SiteResult``, or a site's results dict (read at this edge).
    """
    result = typed_results(result) if isinstance(result, dict) else result
    suites = []
    tot = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    for e in result.requirements:
        cases = []
        cnt = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
        rows = e.rows or (VerdictRow(procedure="", operating_point="", run=e.id, status=e.status, reason=e.status),)
        for r in rows:
            cnt["tests"] += 1
            kind, body = _case(e, r)
            if kind:
                cnt[kind] += 1
            cases.append(f'    <testcase classname={quoteattr(e.id)} name={quoteattr(r.run or e.id)} time="0">{body}</testcase>')
        for k in tot:
            tot[k] += cnt[k]
        suites.append(
            f'  <testsuite name={quoteattr(e.id + " " + e.title)} tests="{cnt["tests"]}" failures="{cnt["failures"]}" '
            f'errors="{cnt["errors"]}" skipped="{cnt["skipped"]}">\n' + "\n".join(cases) + "\n  </testsuite>"
        )
    name = f"govcheck {result.plant.name} vs {result.requirement_set.name}"
    wall = result.wall
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<testsuites name={quoteattr(name)} tests="{tot["tests"]}" failures="{tot["failures"]}" errors="{tot["errors"]}" '
        f'skipped="{tot["skipped"]}" time="{wall:.3f}">\n' + "\n".join(suites) + "\n</testsuites>\n"
    )


def write_junit(result, path) -> None:
    """Write the JUnit XML atomically."""
    write_text_atomic(path, junit_xml(result))
