"""What counts as right on a recording with answers (``scoring.benchmark.run_practice``)."""

from __future__ import annotations

from compliance.effects import EFFECTS

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
    names = [w for w in (d.winner or "").split("+") if w]
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
    winner_effects = [e for e in (d.winner or "").split("+") if e in EFFECTS]
    declared = [e for e in truth if e in EFFECTS]
    if declared:
        right = d.verdict == "missing_physics" and sorted(winner_effects) == sorted(declared)
        named = {e for k in d.ambiguous for e in k.split("+")}
        return right, d.verdict == "ambiguous" and set(declared) <= named
    if truth:
        return d.verdict == "parameters_only", d.verdict == "ambiguous" and "base" in d.ambiguous
    return d.verdict in ("no_mismatch", "parameters_only"), False


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


def practice_table(rep: dict) -> str:
    """The scored practice recordings as a Markdown table (``scoring.benchmark.run_practice``'s result)."""
    lines = ["| recording | truth | verdict | winner | right | largest residual after (x floor) | main parameter error | s |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rep["recordings"]:
        after = r.get("objective_after") or r.get("objective_before") or {}
        worst = max(after.items(), key=lambda kv: kv[1], default=None)
        main = r.get("main") or {}
        err = f"{100 * main['error']:.0f} % ({main['parameter']})" if main.get("error") is not None else "-"
        lines.append(f"| {r['name']} | {r['truth']} | {r['verdict']} | {r['winner'] or '-'} | "
                     f"{'yes' if r['correct'] else 'no'} | {f'{worst[1]:.2f} ({worst[0]})' if worst else '-'} | {err} | "
                     f"{r['seconds']:.0f} |")
    lines.append(f"\n{rep['correct']}/{len(rep['recordings'])} right.")
    return "\n".join(lines)


__all__ = ["answer_in_si", "main_parameter", "practice_correct", "practice_table"]
