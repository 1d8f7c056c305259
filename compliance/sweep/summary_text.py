"""Plain-text (Markdown) summaries of a sweep, a remedies search and a yield run, for people and CI logs."""

from __future__ import annotations

from pathlib import Path

from compliance.presentation.numbers import fmt_margin_pct, fmt_num, si_prefix, unit_text
from compliance.sweep.remedies.outcome import RemedyStatus

__all__ = ["remedies_markdown", "summary_markdown", "yield_markdown"]


def _g(v, unit: str = "") -> str:
    """A parameter value with its unit: SI prefix, 4 significant digits without padding zeros, typeset unit
    (``8e+05 Pa`` -> ``800 kPa``, ``9.271e-09 m^3/(s*Pa)`` -> ``9.271×10⁻⁹ m³/(s·Pa)``)."""
    if v is None:
        return "-"
    scale, shown = si_prefix(float(v), unit or "")
    return f"{fmt_num(float(v) * scale, 4)} {unit_text(shown)}".strip()


def _pct(v) -> str:
    return "-" if v is None else f"{v:+.1f} %".replace("-", "\u2212")


def _margin(v) -> str:
    """A margin in per cent of its limit, capped as in the report (beyond ±100 % it says far beyond/inside)."""
    return fmt_margin_pct(v) or "-"


def remedies_markdown(rem: dict) -> str:
    """The remedies section: status, sensitivities of each failed requirement, the change or the closest candidate."""
    lines = ["## What would make it pass", "", rem.get("note", ""), ""]
    for s in rem.get("sensitivities", []):
        lines.append(f"- **{s['requirement']}** (margin {_margin(s['margin_pct'])}) moves with, per 10 % of each range:")
        for b in s["by_parameter"][:4]:
            lines.append(f"  - {b['path']} +{_g(b['step'], b['unit'])}: {_pct(b['delta_margin_pct'])} points")
    pick = rem.get("remedy") or rem.get("closest")
    if rem.get("status") == RemedyStatus.ALREADY_PASSES:  # the note says it; no "closest" to show
        pick = None
    if pick:
        title = "Smallest verified change" if rem.get("remedy") else "Closest candidate (does not pass)"
        if not pick["changes"]:  # the configuration as given ranks first: no table of nothing
            lines += ["", f"**{title}**: the configuration as given (no candidate judged ranks before it); binding "
                          f"{pick['binding']} {_margin(pick['binding_margin_pct'])}."]
        else:
            lines += ["", f"**{title}** (normalised change {pick['change']:.3f}; binding {pick['binding']} "
                          f"{_margin(pick['binding_margin_pct'])}):", ""]
            lines += ["| parameter | from | to |", "|---|---|---|"]
            lines += [f"| {c['path']} | {_g(c['from'], c['unit'])} | {_g(c['to'], c['unit'])} |" for c in pick["changes"]]
        if pick.get("hardware"):
            lines.append("\nHardware: " + "; ".join(f"{h['title']} (cost {h['cost']:g})" for h in pick["hardware"]))
        if pick.get("failed_mandatory"):
            lines.append(f"\nStill failing: {', '.join(pick['failed_mandatory'])}")
    lines += _yield_lines(rem.get("tolerance_yield"))
    if rem.get("hardware_tried"):
        lines += ["", "Hardware options judged alone at the best settings:", ""]
        lines += [f"- {h['title']} (cost {h['cost']:g}): {h['status']}"
                  + (f", failing {', '.join(h['failed_mandatory'])}" if h["failed_mandatory"] else "") for h in rem["hardware_tried"]]
    if rem.get("not_modelled"):
        lines += ["", "Not in the search (the model cannot represent them): "
                  + "; ".join(f"{n['title']} ({n['reason']})" for n in rem["not_modelled"])]
    return "\n".join(lines) + "\n"


def _yield_lines(y) -> list[str]:
    if not y:
        return []
    verdict = "meets" if y["meets"] else "does not show"
    return ["", f"**Tolerance yield**: {y['pass']} of {y['valid']} units pass every mandatory requirement "
                f"({100 * (y['fraction'] or 0):.1f} %; one-sided {int(100 * y['confidence'])} % lower bound "
                f"{100 * y['lower_bound']:.1f} %): {verdict} >= {100 * y['target']:.0f} % of units at "
                f"{100 * y['confidence']:.0f} % confidence."
                + (" Weakest: " + ", ".join(f"{r['requirement']} {100 * r['fraction']:.0f} %" for r in y["worst_requirements"])
                   if not y["meets"] else "")]


def summary_markdown(s: dict) -> str:
    """The sweep summary as Markdown."""
    ex = s.get("executor") or {}
    lines = [f"# Sweep {s['name']}: {s['title']}", "",
             f"- method {s['method']} (random-number start {s['seed']}); "
             f"{s['candidates']} candidates drawn from the declared ranges",
             f"- **{s['passing']} of the {s['candidates']} drawn candidates pass** every mandatory requirement; by status: "
             + ", ".join(f"{k} {v}" for k, v in sorted(s["counts"].items()))]
    judged = (s.get("remedies") or {}).get("evaluated")
    if judged:
        found = 1 if (s["remedies"].get("remedy")) else 0
        # a different count from the drawn candidates above: the search starts from them and adds its own steps
        lines.append(f"- the remedy search, started from these {s['candidates']}, judged {judged} candidate settings in all "
                     "(its own search steps and verification runs counted); "
                     + ("a verified change passes" if found else "none passes"))
    lines += [f"- executor: {ex.get('backend')} \u00d7 {ex.get('workers')} workers; {ex.get('done')} tasks done, "
              f"{ex.get('failed')} failed, {ex.get('retried')} retried; wall time {fmt_num(s['wall'], 3)} s", ""]
    par = s["pareto"]
    if len(par["requirements"]) == 2:
        a, b = par["requirements"]
        lines += [f"## Pareto front of the two tightest requirements: {a} x {b}", "",
                  f"| candidate | status | {a} margin | {b} margin | change |", "|---|---|---|---|---|"]
        lines += [f"| {c['candidate']} | {c['status']} | {_margin(c[a + '.margin_pct'])} | {_margin(c[b + '.margin_pct'])} | "
                  f"{c['change']:.3f} |" for c in par["candidates"]]
        lines.append("")
    b = s.get("best")
    if b:
        lines += [f"## Best candidate: #{b['candidate']} ({b['status']}; full campaign: {b['verified_status']})", "",
                  "| parameter | value | base |", "|---|---|---|"]
        for p in s["parameters"]:
            lines.append(f"| {p['path']} | {_g(b['values'][p['path']], p['unit'])} | {_g(p['base'], p['unit'])} |")
        if b["failed_mandatory"]:
            lines.append(f"\nStill failing: {', '.join(b['failed_mandatory'])}")
        lines.append(f"\nFull results: {Path(b['results_file']).name}, written next to this summary "
                     "(`govcheck report` renders it)\n")
    if s.get("remedies"):
        lines.append(remedies_markdown(s["remedies"]))
    return "\n".join(lines) + "\n"


def yield_markdown(y: dict) -> str:
    """The yield summary as Markdown."""
    a = y["all_mandatory"]
    conf = int(round(100 * y["confidence"]))
    lines = [f"# Tolerance yield of {y['name']} candidate '{y['label']}'", "",
             f"- {y['units']} units (random-number start {y['seed']}); {y['valid']} valid, {y['invalid']} invalid draws, "
             f"{y['failed_tasks']} lost",
             f"- **all mandatory requirements: {a['pass']} / {y['valid']} = {100 * (a['fraction'] or 0):.1f} %** "
             f"({conf} % CI {100 * a['ci'][0]:.1f} - {100 * a['ci'][1]:.1f} %)", "",
             "| requirement | severity | pass | yield | CI | median margin |", "|---|---|---|---|---|---|"]
    for r in y["requirements"]:
        f = "-" if r["fraction"] is None else f"{100 * r['fraction']:.1f} %"
        lines.append(f"| {r['requirement']} | {r['severity']} | {r['pass']}/{r['units']} | {f} | "
                     f"{100 * r['ci'][0]:.1f} - {100 * r['ci'][1]:.1f} % | {_pct(r['margin_pct_median'])} |")
    lines += ["", "Drivers (Spearman rank correlation with the worst mandatory margin):", ""]
    lines += [f"- {d['path']}: {fmt_num(d['worst_margin'], 3)}" for d in y["drivers"]]
    return "\n".join(lines) + "\n"
