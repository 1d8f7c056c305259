"""One paragraph a plant engineer understands: where the model missed, why, what was fitted, what it gained."""

from __future__ import annotations

from compliance.effects import EFFECTS
from compliance.diagnosis.servo.candidates import FRICTION_LEVEL
from compliance.diagnosis.servo.friction_form import form_words
from compliance.diagnosis.servo.instrument_candidates import PREFIX, finding_words
from compliance.diagnosis.verdicts.candidate_set import is_instrument
from compliance.presentation.numbers import fmt_dbic, fmt_num, fmt_si
from compliance.diagnosis.verdicts.candidate_set import CandidateSet
from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict

# how each effect reads in words, with its main fitted value ({v} is filled in): ``Effect.explanation``
PHYSICS = {name: eff.explanation for name, eff in EFFECTS.items()}
SIGNAL_WORDS = {"position": "position", "pressure_a": "side-A pressure", "pressure_b": "side-B pressure",
                "valve_command": "valve command", "supply_pressure": "supply pressure"}
ALMOST_AS_WELL = 1.5  # a runner-up within this chi-square ratio of the winner is named as an alternative
REGIME_WORDS = {"step": "after the set-point steps", "hold": "while the position holds", "tracking": "during the sinusoidal tracking",
                "open_loop": "over the run"}


def effect_words(key: str | None) -> str:
    """An effect (or ``a+b`` set) in the words of its declaration: ``heat_transfer`` -> "chambers exchange heat with the walls"."""
    if not key:
        return "none"
    if key == "base":
        return "recalibrating the base parameters"
    # the declaration's meaning up to its colon (the rest is the mechanism, which the signature already gives)
    return " together with ".join(EFFECTS[k].meaning.split(":")[0].strip() if k in EFFECTS else k.replace("_", " ")
                                  for k in CandidateSet.parse(key).terms)


def _param_words(fp) -> str:
    """A fitted parameter in words: ``valve_dynamics.natural_frequency`` -> "natural frequency", base keys in full."""
    return (fp.name if fp.kind == "effect" else fp.key.replace(".", " ")).replace("_", " ")


def _pm(value, err, unit) -> str:
    """Value with its statistical standard error (which does not cover model-structure error), SI prefixes."""
    if err is None or not (err == err) or err <= 0 or err > 10 * abs(value):
        return fmt_si(value, unit)
    return f"{fmt_si(value, unit)} (standard error {fmt_si(err, unit)})"


def _signal_change(d, signals) -> str:
    """'cuts the side-A pressure residual from 8.7 kPa to 0.4 kPa' for the signal that gained most."""
    if not d.fit_after:
        return ""
    best = None
    for s in signals:
        if s not in d.fit_before or s not in d.fit_after:
            continue
        b = d.fit_before[s]["rms_normalised"]
        a = d.fit_after[s]["rms_normalised"]
        if best is None or (b - a) > best[0]:
            best = (b - a, s)
    if best is None:
        return ""
    s = best[1]
    b, a = d.fit_before[s], d.fit_after[s]
    unit = {"position": "m", "valve_command": "V"}.get(s, "Pa")
    txt = f"the {SIGNAL_WORDS[s]} residual falls from {fmt_si(b['rms'], unit)} to {fmt_si(a['rms'], unit)} RMS"
    if b.get("fit_percent") == b.get("fit_percent") and a.get("fit_percent") == a.get("fit_percent"):
        # the fit of the validation table (100 (1 - NRMSE)), formatted as its Fit columns
        txt += f" (fit {fmt_num(b['fit_percent'], 3)} % \u2192 {fmt_num(a['fit_percent'], 3)} %)"
    return txt


def _where(d) -> str:
    regs = [REGIME_WORDS.get(r, r) for r in getattr(d, "located_regimes", [])]
    if not regs:
        return "across the recording"
    return ", ".join(regs[:-1]) + (" and " if len(regs) > 1 else "") + regs[-1]


def _worst(d, objective: bool = False) -> tuple[str, float]:
    """Signal with the largest normalised residual of the nominal replay (full closed loop, or the
    re-synchronised one the verdict is taken on)."""
    if objective:
        s = max(d.objective_before, key=lambda k: d.objective_before[k])
        return s, d.objective_before[s]
    s = max(d.fit_before, key=lambda k: d.fit_before[k]["rms_normalised"])
    return s, d.fit_before[s]["rms_normalised"]


def _base_changes(d, fit) -> str:
    parts = []
    for fp, v, e in zip(fit.params, fit.values, fit.stderr):
        if fp.kind != "base":
            continue
        if fp.key == FRICTION_LEVEL:
            fs = d.cfg.p("friction.static_force")
            fc = d.cfg.p("friction.coulomb_force")
            parts.append(f"friction levels scaled by {v:.3g} (static {fs:.0f} -> {fs*v:.0f} N, Coulomb {fc:.0f} -> {fc*v:.0f} N)")
        else:
            parts.append(f"{_param_words(fp)} refitted from {fmt_si(fp.nominal, fp.unit)} to {_pm(v, e, fp.unit)}")
    return "; ".join(parts)


def _library(d) -> str:
    """What was tried: the whole effect library or the --effects subset, and the recalibration."""
    tried = [k for k in d.fits if k in EFFECTS]
    what = (f"the {len(EFFECTS)} declared effects" if len(tried) == len(EFFECTS)
            else f"the {len(tried)} effects tried ({'; '.join(effect_words(k) for k in tried)})")
    return what + (" and the recalibrated base parameters" if "base" in d.fits else "")


def _left(d) -> str:
    """'the side-B pressure (3.1 times its floor) and the valve command (2.4 times)' for the signals left."""
    items = sorted(d.signals_left.items(), key=lambda kv: -kv[1])
    return " and ".join(f"the {SIGNAL_WORDS.get(s, s)} ({v:.1f} times its floor)" for s, v in items)


def _empirical(d) -> str:
    e = d.empirical
    if not e or not e.get("words"):
        return ""
    return f" Empirical suggestion (not a declared effect): {e['words']}"


def _contribution_words(d) -> str:
    if len(d.contributions) < 2:
        return ""
    parts = [f"{effect_words(e)} {100*c['share_of_excess']:.0f} %" for e, c in d.contributions.items()]
    return (" Each effect's own contribution (share of the nominal excess lost when it alone is switched off): "
            + ", ".join(parts) + ".")


def _ambiguity_words(d) -> str:
    if len(d.ambiguous) < 2:
        return ""
    alts = "; ".join(effect_words(a) for a in d.ambiguous[1:])
    text = f" This recording cannot tell it from {alts} (information criteria within the ambiguity margin)."
    t = d.suggested_test
    if t and t.get("recommended"):
        r = t["recommended"]
        text += (f" Suggested test: {r['test']}; the two explanations' predictions differ there by {r['difference']:.1f} "
                 f"times the noise floor on the {SIGNAL_WORDS.get(r['signal'], r['signal'])}"
                 + ("." if t.get("separates") else ", which may still not separate them."))
    return text


def _split_words(d, fp) -> str:
    """What the scan along the lumped valley says about the split (``servo.lag_split.split_scan``)."""
    sp = getattr(d, "split", None)
    if not sp or sp["parameter"] != fp.key:
        return ""
    lo, hi = (fmt_si(v, fp.unit) for v in sp["interval"])
    if sp["pinned"]:
        out = [fmt_si(v, fp.unit) for v in sp.get("bracket", []) if v is not None]
        return (f" Along that valley the recording pins {_param_words(fp)} near {lo if lo == hi else f'{lo} - {hi}'}"
                + (f" (the scan's {' and '.join(out)} fit worse)." if out else "."))
    text = (f" Along that valley every {_param_words(fp)} from {lo} to {hi} explains the recording as well as the "
            f"pooled fit (total lag within 4 % of its fit): the pooled fit does not determine the split, only the total.")
    est = sp.get("estimate")
    if est:
        text += (f" The re-synchronised segments agree best at {fmt_si(est['value'], fp.unit)} (least trimmed squares: "
                 f"the worst fifth of the segments, where a stick-slip event can decide, left out; trimmed chi2/N "
                 f"{est['trimmed']:.2f} against {est['trimmed_fit']:.2f}), the value given above.")
    return text


def explain_with_table(d, before: dict, after: dict) -> str:
    """The paragraph with its before/after residuals and fits taken from the validation tables the report prints.

    ``before`` / ``after``: signal -> ``fit_metrics.signal_fit`` rows (``rms_error``, ``nrmse``, ``fit_percent``)
    of the model as configured and of the fitted model, so the text and the table quote one number.
    """
    import dataclasses

    def rows(fits, own):
        return {k: {**v, **({"rms": fits[k]["rms_error"], "nrmse": fits[k]["nrmse"], "fit_percent": fits[k]["fit_percent"]}
                            if k in fits and fits[k].get("fit_percent") is not None else {})} for k, v in (own or {}).items()}

    return explain(dataclasses.replace(d, fit_before=rows(before, d.fit_before), fit_after=rows(after, d.fit_after)))


def explain(d) -> str:
    """The paragraph for ``servo.diagnose.Diagnosis`` ``d``."""
    text = _explain_core(d)
    if d.winner and not is_instrument(d.winner) and PREFIX in d.winner:
        text += f" Check your instrumentation too: {finding_words(d.fits[d.winner])}."
    if d.verdict == DiagnosisVerdict.PARTIALLY_EXPLAINED:
        text += f" It does not explain everything: what is left sits on {_left(d)}."
    return text + form_words(getattr(d, "friction_form", None)) + _contribution_words(d) + _ambiguity_words(d) + _empirical(d)


def _explain_core(d) -> str:
    worst_sig, worst = _worst(d, objective=d.verdict == DiagnosisVerdict.NO_MISMATCH)
    if d.verdict == DiagnosisVerdict.NO_MISMATCH:
        return (f"Nothing is wrong: the nominal model reproduces the recording to within the sensor noise on every "
                f"measured signal (the largest residual is {worst:.2f} times its noise floor, on the {SIGNAL_WORDS[worst_sig]}). "
                f"No physics is missing and no parameter needs refitting.")
    if d.verdict == DiagnosisVerdict.UNEXPLAINED or d.winner is None:
        best = d.winner or d.runner_up
        share = d.scores[best].explained * 100 if best in d.scores else 0.0
        return (f"The model misses the recording {_where(d)} (the {SIGNAL_WORDS[worst_sig]} residual is {worst:.1f} times its "
                f"noise floor), and nothing in the library explains it: the best candidate ({effect_words(best)}) removes only "
                f"{share:.0f} % of the excess. The physics behind it is outside {_library(d)}; look at the located windows.")
    fit = d.fits[d.winner]
    change = _signal_change(d, list(d.fit_before))
    if is_instrument(d.winner):
        return (f"Check your instrumentation: the plant is not shown to be wrong. The model misses the recording {_where(d)} "
                f"(the {SIGNAL_WORDS[worst_sig]} residual is {worst:.1f} times its noise floor) the way an instrument does: "
                f"{finding_words(fit)}. No plant-physics explanation beats it." + (f" With it, {change}." if change else ""))
    if d.verdict == DiagnosisVerdict.PARAMETERS_ONLY or d.winner == "base":
        return (f"No physics is missing. The model misses the recording {_where(d)} (the {SIGNAL_WORDS[worst_sig]} residual is "
                f"{worst:.1f} times its noise floor) because base parameters are off: {_base_changes(d, fit)}. "
                f"With them {change}." if change else f"No physics is missing: {_base_changes(d, fit)}.")
    if len(CandidateSet.parse(d.winner).effects) > 1:
        return _explain_set(d, fit, worst_sig, worst, change)
    effect = CandidateSet.parse(d.winner).first
    eff = EFFECTS[effect]
    main = next(i for i, fp in enumerate(fit.params) if fp.kind == "effect")
    fp = fit.params[main]
    phys = PHYSICS.get(effect, eff.meaning + " ({v})").format(v=_pm(fit.values[main], fit.stderr[main], fp.unit))
    others = [f"{_param_words(q)} {_pm(v, e, q.unit)}" for q, v, e in zip(fit.params, fit.values, fit.stderr) if q.kind == "effect" and q is not fp]
    text = (f"The model misses the recording {_where(d)} (the {SIGNAL_WORDS[worst_sig]} residual is {worst:.1f} times its noise "
            f"floor) in the pattern of one declared effect, {effect_words(effect)}: {eff.signature}. The explanation: {phys}")
    if others:
        text += "; also fitted: " + ", ".join(others)
    text += "."
    lumped = fit.lumped(effect)
    if lumped is not None and eff.lumped is not None:
        text += (f" The test pins down their combination best: {eff.lumped.meaning} = "
                 f"{_pm(lumped[0], lumped[1], eff.lumped.unit)}; how it splits between the parameters is less certain"
                 f" than their own errors suggest (they trade along a valley of the fit).")
        text += _split_words(d, fp)
    base = _base_changes(d, fit)
    if base:
        text += f" Together with it, {base}."
    if change:
        text += f" Adding it, {change}."
    if d.runner_up and d.runner_up in d.scores:
        ru, w = d.scores[d.runner_up], d.scores[d.winner]
        if ru.chi2 < ALMOST_AS_WELL * w.chi2:
            alt = effect_words(d.runner_up)
            text += (f" Caution: {alt} explains the recording almost as well (residual {ru.chi2 / w.chi2:.2f} times the "
                     f"winner's); a test at another operating point (supply pressure, load) tells them apart.")
        else:
            text += f" The runner-up ({effect_words(d.runner_up)}) fits worse by {fmt_dbic(ru.bic - w.bic)} in BIC."
    return text


def _explain_set(d, fit, worst_sig, worst, change) -> str:
    """Several effects together (the multi-effect search)."""
    effects = CandidateSet.parse(d.winner).effects
    parts = []
    for e in effects:
        vals = [f"{_param_words(q)} {_pm(v, err, q.unit)}" for q, v, err in zip(fit.params, fit.values, fit.stderr) if q.effect == e]
        parts.append(f"{effect_words(e)} ({', '.join(vals)})")
    text = (f"The model misses the recording {_where(d)} (the {SIGNAL_WORDS[worst_sig]} residual is {worst:.1f} times its noise "
            f"floor), and no single effect explains it; {len(effects)} effects together do: " + "; ".join(parts) + ".")
    base = _base_changes(d, fit)
    if base:
        text += f" Together with them, {base}."
    if change:
        text += f" Adding them, {change}."
    return text
