"""Writers and readers of results: JSON (versioned schema), JUnit XML, terminal table, Markdown.

Every file is written atomically (a temporary file in the target folder, then ``os.replace``)
so a CI job never reads half a file.
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

from compliance.campaign.basis import verdict_qualifier
from compliance.campaign.coverage import CASES_BASIS, case_coverage_text
from compliance.errors import InputError
from compliance.files.atomic import write_text_atomic
from compliance.files.jsonable import json_text, read_json
from compliance.requirements.verdict import Basis, Severity, Status
from compliance.presentation.values import limit_as_written
from compliance.units.formatting import STATUS_WORD as _STATUS_WORD  # the one status-word table

RESULTS_SCHEMA = "govcheck-results/1"
SITE_SCHEMA = "govcheck-site/1"  # a site's measured verdicts (govcheck accept, compliance.acceptance): same requirements[]


def results_json(results: dict) -> str:
    """Serialise a results dict with the one JSON cleaner (non-finite numbers become null)."""
    # compact: the traces make up most of the file; tools, not people, read it
    return json_text(results, compact=True)


def write_json(results: dict, path) -> None:
    """Write the results JSON atomically."""
    write_text_atomic(path, results_json(results))


def read_results(path) -> dict:
    """Read a results JSON written by ``govcheck check`` (or a site's, by ``govcheck accept``).

    Raises
    ------
    InputError
        Not JSON, or not a govcheck results file of a supported schema.
    """
    p = Path(path)
    data = read_json(p, "results")
    if "schema" not in data:
        raise InputError(f"{p}: schema: missing; expected a govcheck results file ('{RESULTS_SCHEMA}' or '{SITE_SCHEMA}')")
    if data["schema"] not in (RESULTS_SCHEMA, SITE_SCHEMA):
        raise InputError(f"{p}: schema: '{data['schema']}' is not supported (expected '{RESULTS_SCHEMA}' or '{SITE_SCHEMA}')")
    for key in ("requirements", "summary", "plant", "requirement_set"):
        if key not in data:
            raise InputError(f"{p}: {key}: missing from the results file")
    check_numbers(data, str(p))
    return data


def check_numbers(data: dict, where: str) -> None:
    """Refuse text where the report computes with a number, naming the key path.

    ``requirements``, ``runs``, ``timing`` and ``plant`` are checked on ``NUMERIC_KEYS`` (their rows hold free
    text in other keys); the linear analysis and the validation, whose every key ``LINEAR_NUMERIC_KEYS`` names is a
    number wherever govcheck writes it, on those as well.

    Raises
    ------
    InputError
        The results file is damaged or hand-edited.
    """
    for key in ("requirements", "runs", "timing", "plant", "site"):
        _check_numbers(data.get(key), f"{where}: {key}", NUMERIC_KEYS)
    for key in ("linear", "validation"):
        _check_numbers(data.get(key), f"{where}: {key}", NUMERIC_KEYS | LINEAR_NUMERIC_KEYS)


# keys whose values the report computes with: a number, null, or a list of them (text lives in "display" tables)
NUMERIC_KEYS = frozenset({
    "value", "margin", "margin_pct", "wall", "wall_time", "time", "position", "reference", "valve_command",
    "pressure_a", "pressure_b", "supply_pressure", "force", "phase_margin_deg", "gain_margin_db", "time_constant",
    "dead_time", "overshoot", "settling_time", "rise_time", "bandwidth_hz", "natural_frequency_hz", "damping_ratio",
    "gain_crossover_hz", "phase_crossover_hz", "max_error", "rms_error", "steady_error", "peak_speed",
})
# the linear analysis (its map, cross-check and governor parameters) and the validation replay: every key that
# holds numbers, and only numbers, in the results govcheck writes
LINEAR_NUMERIC_KEYS = frozenset({
    "GMAX", "GMIN", "Tg", "Tg_linear", "Tg_nonlinear_samples", "Tg_steps", "UC", "UO", "VELM", "UO_peak", "UC_peak",
    "closed_loop", "closed_loop_discrete", "closed_loop_magnitude_db", "closed_loop_phase_deg", "closed_loop_zeros",
    "dead_time_linear", "dead_time_viscous", "dominant_time_constant", "first_order_time_constant", "frequency_hz",
    "gain_margin_db_continuous", "phase_margin_deg_continuous", "loop_discrete_magnitude_db", "loop_discrete_phase_deg",
    "loop_gain", "loop_magnitude_db", "loop_phase_deg", "natural_frequency_analytic_hz", "plant_minimal",
    "plant_velocity_gain", "pneumatic", "pneumatic_damping_ratio", "pneumatic_stiffness", "positions", "rate_pu_per_s",
    "ratio", "ratio_viscous", "ratio_viscous_no_dead_zone", "state_scales", "stroke_time", "t25", "t75", "t_step",
    "tau_linear", "tau_linear_mean", "tau_nonlinear", "tau_nonlinear_viscous", "time_constant_continuous",
    "unobservable_or_uncontrollable_states", "viscous_damping_ratio_analytic", "x_final", "x_start", "step",
    "fit_percent", "i_end", "i_start", "initial_pressures", "load_force", "max_abs_error", "mean_absolute_error",
    "mean_error", "mean_residual", "nrmse", "peak_abs", "peak_ratio", "rms_residual", "sample_time",
    "sample_time_median", "start", "end", "duration", "velocity_noise", "kp", "ki", "kd",
})
# keys numeric in one table only (a "window" of the validation is a name; the linear map's is its stroke window)
_NUMERIC_IN = {"map": frozenset({"window"})}
# keys that hold a number or one of these words
_NUMBER_OR_WORD = {"load": ("curve", "none", "nominal"), "loads": ("curve", "none", "nominal")}
_TEXT_TABLES = frozenset({"display", "procedure", "operating_point", "settings", "procedures", "operating_points", "units",
                          "notes", "detail", "conventions", "family", "andes", "psse_dyr", "left_out", "sentences",
                          "ieee_pes_tr_2013"})


def _check_numbers(tree, where: str, keys: frozenset, table: str = "") -> None:
    """A damaged results file (text where the report needs a number) is named, not rendered into a crash."""
    if isinstance(tree, dict):
        for k, v in tree.items():
            if k in _TEXT_TABLES:
                continue
            words = _NUMBER_OR_WORD.get(k)
            numeric = k in keys or k in _NUMERIC_IN.get(table, ())
            if (numeric and not _numbers(v)) or (words and not _numbers(v, words)):
                raise InputError(f"{where}.{k}: {str(v)[:60]!r} where a number (or null) belongs; the results file is "
                                 "damaged or hand-edited: regenerate it with govcheck check --json")
            _check_numbers(v, f"{where}.{k}", keys, k)
    elif isinstance(tree, list):
        for i, v in enumerate(tree):
            _check_numbers(v, f"{where}[{i}]", keys, table)


def _numbers(v, words: tuple = ()) -> bool:
    if isinstance(v, list):
        return all(_numbers(x, words) for x in v)
    if isinstance(v, dict):
        return True  # a table of its own: its leaves are checked by name
    return v is None or isinstance(v, (int, float)) or (isinstance(v, str) and v in words)


# --------------------------------------------------------------------------- terminal
_BASIS_WORD = {Basis.MODELLED: "modelled", Basis.BY_CONSTRUCTION: "by constr.", Basis.ASSUMED: "assumed", Basis.NOT_EVALUATED: "-"}


def _status_cell(e: dict) -> str:
    word = _STATUS_WORD.get(e["status"], e["status"])
    if e["status"] == Status.PASS and e.get("basis") == Basis.BY_CONSTRUCTION:
        return word + " (by construction)"
    return word


def _table_row(e: dict) -> tuple:
    w = e.get("worst") or {}
    d = w.get("display") or {}
    margin = "-"
    if d.get("margin_pct"):
        margin = d["margin_pct"]
    elif w.get("margin") is not None:
        margin = d.get("margin", "-")
    band = w.get("band")
    if band and band.get("margin_low_pct") is not None:
        margin += f" [{band['margin_low_pct']:+.0f}..{band['margin_high_pct']:+.0f} %]"
    where = w.get("run") or "-"
    if w.get("which"):
        where += f" ({w['which']})"
    limit = limit_as_written(e, unicode=False)
    cov = e.get("coverage") or {}
    cases = f"{cov['evaluated']}/{cov['rows']}" if cov.get("rows") and e.get("limit") is not None else "-"
    value = "no response" if w.get("non_responding") else d.get("value", "-")
    return (e["id"], e["metric"], limit, value, margin, cases, where, e["severity"],
            _BASIS_WORD.get(e.get("basis"), "-"), _status_cell(e))


def summary_lines(results: dict) -> list[str]:
    """The lines under the table: counts (passes by construction, advisory failures and coverage apart),
    what was not evaluated and why, findings of the requirement set, the assumptions that matter most."""
    s = results["summary"]
    c = s["counts"]
    out = [f"plant {results['plant']['name']} ({results['plant'].get('path')}) against "
           f"{results['requirement_set']['name']} ({results['requirement_set']['path']})"]
    cov = s.get("coverage")
    out.append(
        f"{c['pass']} pass, {c.get('pass_by_construction', 0)} pass by construction (not evidence), "
        f"{c.get('fail_mandatory', c['fail'])} fail (mandatory), {c.get('fail_advisory', 0)} fail (advisory), "
        f"{c.get('uncertain', 0)} uncertain, {c['not_evaluated']} not evaluated, {c['open']} open (no limit set), "
        f"{c['disabled']} disabled" + (f"; {case_coverage_text(cov)}" if cov else ""))
    if cov:
        out.append(f"  ({cov.get('basis') or CASES_BASIS})")
    for e in results["requirements"]:
        if e["status"] == Status.NOT_EVALUATED:
            reasons = sorted({r["reason"] for r in e["rows"] if r.get("reason")})
            out.append(f"  not evaluated {e['id']}: {'; '.join(reasons)[:200]}")
        elif e["status"] == Status.PASS and e.get("basis") == Basis.BY_CONSTRUCTION:
            out.append(f"  by construction {e['id']}: {((e.get('worst') or {}).get('basis_reason') or '')[:200]}")
        elif e["status"] == Status.UNCERTAIN:
            deciding = ", ".join(((e.get("worst") or {}).get("band") or {}).get("deciding") or [])
            out.append(f"  uncertain {e['id']}: its band straddles the limit; decided by {deciding or '-'}")
    findings = results.get("findings") or []
    for f in findings:
        if f.get("mandatory"):
            out.append(f"  requirement set {f['kind']}: {f['text']}")
    others = len(findings) - sum(1 for f in findings if f.get("mandatory"))
    if others:
        out.append(f"  requirement set: {others} more finding(s) involving advisory requirements (results JSON, 'findings')")
    top = s.get("top_assumptions") or (results.get("uncertainty") or {}).get("top_assumptions") or []
    if top:
        out.append("  assumptions that matter most: " + "; ".join(f"{a['parameter']} ({a['why']})" for a in top))
    for n in s.get("notes", []):
        out.append(f"  {n}")
    qualifier = s["qualifier"] if "qualifier" in s else verdict_qualifier(results)
    out.append(f"VERDICT: {s['status'].upper()}" + (f" ({qualifier})" if qualifier else "")
               + (f" (mandatory failures: {', '.join(s['failed_mandatory'])})" if s.get("failed_mandatory") else ""))
    return out


def summary_table(results: dict) -> str:
    """Fixed-width table: one line per requirement with its worst case, cases evaluated and basis, then the verdict."""
    head = ("requirement", "metric", "limit", "worst value", "margin", "cases", "worst case", "severity", "basis", "status")
    rows = [_table_row(e) for e in results["requirements"]]
    widths = [max(len(str(r[i])) for r in rows + [head]) for i in range(len(head))]
    widths[6] = min(widths[6], 62)

    def line(r):
        cells = [str(c) if i != 6 else (str(c) if len(str(c)) <= widths[6] else str(c)[: widths[6] - 1] + "~") for i, c in enumerate(r)]
        return "  ".join(c.ljust(widths[i]) for i, c in enumerate(cells)).rstrip()

    out = [line(head), line(tuple("-" * w for w in widths))] + [line(r) for r in rows]
    return "\n".join(out + [""] + summary_lines(results)) + "\n"


# --------------------------------------------------------------------------- JUnit
def junit_xml(results: dict) -> str:
    """JUnit XML: one testsuite per requirement, one testcase per procedure x operating point.

    fail -> <failure>, not evaluated -> <error> for a mandatory requirement (the check could not
    be made) and <skipped> for an advisory one, open (no limit) -> <skipped>.
    """
    suites = []
    tot = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    for e in results["requirements"]:
        cases = []
        cnt = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
        rows = e["rows"] or [{"run": e["id"], "status": e["status"], "reason": e["status"], "display": {}}]
        for r in rows:
            cnt["tests"] += 1
            d = r.get("display") or {}
            msg = (f"{e['metric']} = {d.get('value', '-')} against {e['limit_text']}"
                   + (f", margin {d['margin_pct']}" if d.get("margin_pct") else "")
                   + (f" ({r['which']})" if r.get("which") else ""))
            body = ""
            st = r.get("status")
            if st == Status.FAIL:
                cnt["failures"] += 1
                body = f"<failure message={quoteattr(msg)} type=\"requirement\">{escape(e['title'])}</failure>"
            elif st in (Status.NOT_EVALUATED, Status.UNCERTAIN):
                band = r.get("band") or {}
                reason = (r.get("reason") or "not evaluated") if st == Status.NOT_EVALUATED else (
                    f"uncertain: band {band.get('low')} .. {band.get('high')} straddles the limit; decided by "
                    + ", ".join(band.get("deciding") or []))
                if e["severity"] == Severity.MANDATORY:
                    cnt["errors"] += 1
                    body = f"<error message={quoteattr(reason)} type=\"{st}\"/>"
                else:
                    cnt["skipped"] += 1
                    body = f"<skipped message={quoteattr(reason)}/>"
            elif st in (Status.OPEN, Status.DISABLED):
                cnt["skipped"] += 1
                body = f"<skipped message={quoteattr(('open: no limit set; measured ' + d.get('value', '-')) if st == Status.OPEN else Status.DISABLED)}/>"
            out = f"<system-out>{escape(msg)}</system-out>"
            cases.append(f'    <testcase classname={quoteattr(e["id"])} name={quoteattr(r.get("run") or e["id"])} time="0">{body}{out}</testcase>')
        for k in tot:
            tot[k] += cnt[k]
        suites.append(
            f'  <testsuite name={quoteattr(e["id"] + " " + e["title"])} tests="{cnt["tests"]}" failures="{cnt["failures"]}" '
            f'errors="{cnt["errors"]}" skipped="{cnt["skipped"]}">\n' + "\n".join(cases) + "\n  </testsuite>"
        )
    name = f"govcheck {results['plant']['name']} vs {results['requirement_set']['name']}"
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<testsuites name={quoteattr(name)} tests="{tot["tests"]}" failures="{tot["failures"]}" errors="{tot["errors"]}" '
        f'skipped="{tot["skipped"]}" time="{results.get("timing", {}).get("wall", 0):.3f}">\n' + "\n".join(suites) + "\n</testsuites>\n"
    )


def write_junit(results: dict, path) -> None:
    """Write the JUnit XML atomically."""
    write_text_atomic(path, junit_xml(results))
