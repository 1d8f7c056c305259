"""What counts as right on a recording with answers (``scoring.benchmark.run_practice``)."""

from __future__ import annotations

from compliance.effects import EFFECTS
from compliance.diagnosis.verdicts.candidate_set import CandidateSet
from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict

# answers given in a unit other than the SI unit of the declared parameter: name -> factor to SI
# (the practice emulator states its pressure-dependent friction per bar; ours is per Pa)
ANSWER_TO_SI = {"kp_fric": 1e-5}


def answer_in_si(name: str, value: float) -> float:
    """A true parameter value of ANSWERS.json in the SI unit of the parameter it names."""
    return value * ANSWER_TO_SI.get(name, 1.0)


def _accepted(d, accept: dict) -> bool:
    """A verdict the answers' ``accept`` lists, or a winner naming only an instrumentation finding."""
    if d.verdict in accept.get("verdicts", ()):
        return True
    names = list(CandidateSet.parse(d.winner).terms)
    if not names or any(w in EFFECTS for w in names):
        return False  # a catalogue effect claimed for a truth that is not plant physics
    return any(any(word in w for word in accept.get("named", ())) for w in names)


def practice_correct(d, truth: list, accept: dict | None = None) -> tuple[bool, bool]:
    """(right verdict and top explanation, ambiguous with the truth among the explanations named).

    A truth of declared effects needs ``missing_physics`` with exactly those effects on top; a truth
    that is not a declared effect (a parameter error such as ``valve_conductance``) needs
    ``parameters_only``; no truth needs ``no_mismatch`` (``parameters_only`` accepted: no physics missing).
    ``accept`` (ANSWERS.json, where the plain rule does not fit: a sensor-only truth) lists the
    verdicts that count as right and the words an instrumentation finding's name may carry.
    """
    if accept:
        return _accepted(d, accept), False
    winner_effects = CandidateSet.parse(d.winner).effects
    declared = [e for e in truth if e in EFFECTS]
    if declared:
        right = d.verdict == DiagnosisVerdict.MISSING_PHYSICS and sorted(winner_effects) == sorted(declared)
        named = {e for k in d.ambiguous for e in CandidateSet.parse(k).terms}
        return right, d.verdict == DiagnosisVerdict.AMBIGUOUS and set(declared) <= named
    if truth:
        return d.verdict == DiagnosisVerdict.PARAMETERS_ONLY, d.verdict == DiagnosisVerdict.AMBIGUOUS and "base" in d.ambiguous
    return d.verdict in (DiagnosisVerdict.NO_MISMATCH, DiagnosisVerdict.PARAMETERS_ONLY), False


def main_parameter(d, truth: list, params: dict) -> dict | None:
    """How the main parameter of the (first) true effect came out, scored two ways kept apart.

    ``params``: answer name -> {"true" [SI], "fitted", "error"} (``scoring.benchmark.run_practice``).
    ``within_25`` is the hit (fitted within 25 % of the truth). A lag whose split the recording does
    not determine (``servo.lag_split.split_scan``: not pinned) is also checked against its split interval:
    ``interval_contains_truth`` says the honest output (the interval) holds the truth - reported
    next to the hit, never counted as one.
    """
    declared = [e for e in truth if e in EFFECTS]
    if not declared:
        return None
    main = EFFECTS[declared[0]].params[0]
    name = next((a for a in main.aliases if a in params), None)
    if name is None:
        return None
    row = params[name]
    err = row["error"]
    out = {"parameter": name, "error": err, "within_25": err is not None and err <= 0.25}
    sp = getattr(d, "split", None)
    if sp and sp["parameter"] == f"{declared[0]}.{main.name}":
        lo, hi = sp["interval"]
        out.update(split_interval=[lo, hi], split_pinned=bool(sp["pinned"]),
                   interval_contains_truth=bool(lo <= row["true"] <= hi))
    return out


def _percent(fraction: float) -> str:
    """A relative error in % with the digits it needs: 0.05 %, 4.1 %, 23 %."""
    v = 100 * fraction
    return f"{v:.2f} %" if v < 1 else f"{v:.1f} %" if v < 10 else f"{v:.0f} %"


def practice_table(rep: dict, timings: bool = True) -> str:
    """The scored practice recordings as a Markdown table (``scoring.benchmark.run_practice``'s result).

    ``timings=False`` leaves out the wall-time column (``--reproducible``: the same text on every run).
    """
    head = "| recording | truth | verdict | winner | right | largest residual after (x floor) | main parameter error |"
    lines = [head + (" s |" if timings else ""), "|---" * (8 if timings else 7) + "|"]
    for r in rep["recordings"]:
        after = r.get("objective_after") or r.get("objective_before") or {}
        worst = max(after.items(), key=lambda kv: kv[1], default=None)
        main = r.get("main") or {}
        err = f"{_percent(main['error'])} ({main['parameter']})" if main.get("error") is not None else "-"
        lines.append(f"| {r['name']} | {r['truth']} | {r['verdict']} | {r['winner'] or '-'} | "
                     f"{'yes' if r['correct'] else 'no'} | {f'{worst[1]:.2f} ({worst[0]})' if worst else '-'} | {err} |"
                     + (f" {r['seconds']:.0f} |" if timings else ""))
    lines.append(f"\n{rep['correct']}/{len(rep['recordings'])} right.")
    return "\n".join(lines)


def practice_markdown(rep: dict, timings: bool = True) -> str:
    """``diagnose-benchmark --practice DIR --markdown FILE``: the practice table and the parameter recovery."""
    amb = sum(bool(r.get("ambiguous_with_truth")) for r in rep["recordings"])
    lines = [practice_table(rep, timings)]
    if amb:
        lines.append(f"{amb} more called ambiguous with the truth among the explanations named (not counted as right).")
    lines.append(f"Main parameter within 25 % of the truth: {rep['main_within_25']} of {rep['main_scored']}.")
    return "\n".join(lines) + "\n"


def _pct(x) -> str:
    return "n/a" if x is None else f"{100 * x:.0f} %"


def benchmark_markdown(report: dict, timings: bool = True) -> str:
    """``diagnose-benchmark --markdown FILE`` on generated cases: the figures, per effect, the confusion matrix.

    ``report`` is ``scoring.benchmark.run_benchmark``'s result; ``timings=False`` leaves out the times.
    """
    s = report["summary"]
    mr, mo, me = s["median_reduction"], s.get("median_reduction_objective"), s["median_main_error"]
    rows = [("top-1 correct effect (effect cases)", _pct(s["top1_accuracy"])),
            ("null cases called `no_mismatch`", _pct(s["null_accuracy"])),
            ("miscalibrations called `parameters_only`", _pct(s["miscalibration_accuracy"])),
            ("called `ambiguous` with the truth named (not counted as hits)", str(s.get("ambiguous_with_truth", 0))),
            ("median residual after/before, full closed-loop replay", "n/a" if mr is None else f"{mr:.3f}"),
            ("median residual after/before, re-synchronised replay", "n/a" if mo is None else f"{mo:.3f}"),
            ("median main-parameter error (correct cases)", "n/a" if me is None else f"{100 * me:.1f} %"),
            ("main parameter within 25 % (correct cases)", _pct(s["within_25_percent"])),
            ("cases", str(s["n_cases"]))]
    if timings:
        rows.append(("time per case, median / max", f"{s['median_seconds']:.0f} s / {s['max_seconds']:.0f} s"))
    lines = ["| figure | value |", "|---|---|"] + [f"| {a} | {b} |" for a, b in rows]
    if s.get("not_visible"):
        lines.append("\nNot scored (no concealed draw visible above the noise): "
                     + ", ".join(f"{h['truth']} (seed {h['seed']}, diagnosed {h['predicted']})" for h in s["not_visible"]) + ".")
    lines += ["", "| effect | cases | correct | median main-parameter error |", "|---|---|---|---|"]
    for name, e in s.get("per_effect", {}).items():
        err = "-" if e["median_main_error"] is None else f"{100 * e['median_main_error']:.1f} %"
        lines.append(f"| {name} | {e['cases']} | {e['correct']} | {err} |")
    conf = s["confusion"]
    cols = [c for c in s["labels"] if any(c in row for row in conf.values())]
    lines += ["", "Confusion matrix (rows: truth, columns: diagnosis):", "",
              "| truth | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
    lines += [f"| {t} | " + " | ".join(str(row.get(c, "")) for c in cols) + " |" for t, row in conf.items() if row]
    return "\n".join(lines) + "\n"


__all__ = ["answer_in_si", "benchmark_markdown", "main_parameter", "practice_correct", "practice_markdown", "practice_table"]
