"""Optional report sections: linear analysis and model validation (what exists is shown).

Linear data is the document ``govcheck linear --json`` writes (schema ``govcheck-linear/1``:
``analysis`` or ``analyses``, ``map``, ``crosscheck``, ``governor``), read from a check's result as
records (``CheckResult.linear_section``). Validation data is ``compliance.validation.validate.validate`` output (schema
``govcheck.validation/1``), optionally with a ``diagnosis`` entry (``after`` overlays and the
physics added with its fitted parameters). Missing parts are reported as "not run".
"""

from __future__ import annotations

from compliance.presentation.quantities import fmt_quantity
from compliance.results.validation import DiagnosisRecord, ValidationRecord
from compliance.presentation.numbers import fmt_num, fmt_value, unit_text as pretty_unit
from compliance.report.figures_linear import MAP_QUANTITIES
from compliance.diagnosis.verdicts.verdict import EXPLAINED

SIGNAL_DISPLAY = {  # signal -> (label, unit shown, scale from SI for the plots)
    "position": ("position", "mm", 1e3),
    "valve_command": ("valve command", "V", 1.0),
    "pressure_a": ("chamber A pressure", "bar abs", 1e-5),
    "pressure_b": ("chamber B pressure", "bar abs", 1e-5),
    "supply_pressure": ("supply pressure", "bar abs", 1e-5),
}


def _load_words(load, force=None) -> str:
    """A linear point's load in words: none, the load curve (with its force there) or a constant force."""
    if load is None:
        return "no load"
    if isinstance(load, str):
        return f"load curve, {fmt_quantity(force or 0.0, 'N', 'kN', 1)}"
    return fmt_quantity(load, "N", "kN", 1, signed=True)


def _signal(name, unit: str = "") -> tuple:
    """(label, unit shown, plot scale from SI) of a recorded signal; an unknown one as named, in ``unit``."""
    return SIGNAL_DISPLAY.get(name, (name, unit, 1.0))


def _op_label(a) -> str:
    if a.label:
        return str(a.label)
    op = a.operating_point
    if not isinstance(op.position, (int, float)):
        return "operating point"
    return f"{fmt_quantity(op.position, 'm', 'mm', 0)}, {_load_words(op.load, op.load_force)}"


def _op_names(result) -> list[tuple[str, float, object]]:
    """The requirement file's operating points as (name, position [m], load: None | N | "curve"), from the result's
    SI operating points (no position is read back from its text)."""
    if result is None:
        return []
    return [(name, op.position, "curve" if op.on_curve else op.load_force)
            for name, op in result.requirement_set.operating_points.items() if op.position is not None]


def _same_load(a, b) -> bool:
    if a is None or b is None or isinstance(a, str) or isinstance(b, str):
        return a == b
    return abs(float(a) - float(b)) < 1.0


def distinct_points(analyses, result=None) -> list[tuple[str, object, list]]:
    """The analyses at distinct (position, load) points, each labelled with the operating points it stands for."""
    names = _op_names(result)
    out, seen = [], set()
    for a in analyses:
        if a.point_key in seen:
            continue
        seen.add(a.point_key)
        x, ld = a.operating_point.position, a.operating_point.load
        which = [n for n, nx, nl in names if isinstance(x, (int, float)) and abs(nx - x) < 1e-6 and _same_load(nl, ld)]
        out.append((_op_label(a), a, which))
    return out


def _stability(f) -> str:
    """Against the stated margin criterion (MARGIN_CRITERION, our choice): meets / below / unstable / unknown."""
    from compliance.report.acceptance import MARGIN_CRITERION

    if f.stable is False:
        return "unstable"
    if f.stable is None or f.phase_margin_deg is None or f.gain_margin_db is None:
        return "unknown"
    ok = f.phase_margin_deg >= MARGIN_CRITERION["phase_margin_deg"] and f.gain_margin_db >= MARGIN_CRITERION["gain_margin_db"]
    return "meets" if ok else "below"


def _crosscheck_summary(rows) -> str:
    """One sentence on the linear vs nonlinear cross-check (the table itself goes to the appendix)."""
    done = [r for r in rows if r.skipped is None]
    ratios = [r.ratio for r in done if r.ratio is not None]
    stalled = sum(1 for r in done if r.tau_linear is not None and r.tau_nonlinear is None)
    return (f"{len(done)} small steps were simulated with the nonlinear model at the critical points" + (
        f": where the servo completes the step its time constant is {fmt_num(min(ratios), 3)} to {fmt_num(max(ratios), 3)}"
        " times the linear one (friction and the valve dead zone, which the linear model leaves out)" if ratios else "")
        + (f"; {stalled} steps stall inside the valve dead zone and reach no 63.2 % point" if stalled else "") + ".")


def _point_row(k: int, label: str, a, which) -> dict:
    f = a.figures
    return {"key": f"P{k + 1}", "label": label, "names": which, "time_constant": _ms(f.time_constant),
            "gain_margin": fmt_num(f.gain_margin_db, 3), "phase_margin": fmt_num(f.phase_margin_deg, 3),
            "bandwidth": fmt_num(f.bandwidth_hz, 3), "damping": fmt_num(f.damping_ratio, 3),
            "natural_frequency": fmt_num(f.natural_frequency_hz, 3), "stable": f.stable, "stability": _stability(f)}


def _cross_row(r) -> dict:
    if r.skipped is not None:
        return {"position": _mm(r.position), "load": _load(r.load), "skipped": r.skipped}
    return {"position": _mm(r.position), "load": _load(r.load, r.load_force),
            "step": fmt_quantity(r.step, "", "%", 0, signed=True) if r.step is not None else "\u2013",
            "tau_linear": _ms(r.tau_linear), "tau_nonlinear": _ms(r.tau_nonlinear, "stalled"), "ratio": fmt_num(r.ratio, 3),
            "steady_error": _mm(r.steady_error, 2), "why": r.why or "agrees within 20 %"}


def _governor(g, result) -> dict:
    """The HYGOV table and where its figures come from."""
    rows = [{"name": k, "value": fmt_num(v, 4), "unit": g.units.get(k, "")}
            for k, v in {**g.parameters, **g.rate_limits}.items()]
    if g.Tg_linear is not None:
        rows.append({"name": "Tg (linear)", "value": fmt_num(g.Tg_linear, 4), "unit": "s"})
    stroke = result.plant.stroke if result is not None else None
    per_unit = f" (1 pu = the full stroke, {fmt_quantity(stroke, 'm', 'mm', 0)})" if isinstance(stroke, (int, float)) else ""
    intro = (f"{g.model} is the hydro turbine-governor model of power-system simulation tools (IEEE PES "
             "TR 2013, hydro turbine-governor models): Tg is its gate-servomotor time constant, VELM the gate velocity "
             "limit, GMAX and GMIN the gate limits, UO and UC the opening and closing rate limits. Gate positions are "
             f"per unit (pu) of the stroke and rates in pu/s, per unit of stroke per second{per_unit}.")
    curve = result.plant.load_curve if result is not None else None
    return {"model": g.model, "rows": rows, "basis": [intro] + governor_basis(g.basis, curve)}


def linear_section(linear, start: int, result=None) -> tuple[dict | None, list[dict]]:
    """Context of the linear-analysis section (a :class:`~compliance.results.linear.LinearSection`) and its
    figure specs (ids from ``start``)."""
    if linear is None:
        return None, []
    from compliance.report.acceptance import MARGIN_CRITERION

    specs = []

    def add(kind, **kw):
        fid = f"fig-{start + len(specs)}"
        specs.append({"id": fid, "kind": kind, **kw})
        return fid

    points_named = distinct_points(linear.all_analyses, result)
    labelled = [(f"P{k + 1} {label}", a) for k, (label, a, _) in enumerate(points_named)]  # keys as in the table
    omap = linear.map
    maps = [{"id": add("map", omap=omap, name=name), "title": MAP_QUANTITIES[name][0], "unit": MAP_QUANTITIES[name][1]}
            for name in ("time_constant", "gain_margin_db", "phase_margin_deg") if omap is not None and omap.values.get(name)]
    points = [_point_row(k, label, a, which) for k, (label, a, which) in enumerate(points_named)]
    minima = []
    for name, unit in (("phase_margin_deg", "°"), ("gain_margin_db", " dB")):
        m = omap.minimum(name) if omap is not None else None
        if m is not None:
            where = f"{fmt_quantity(m[1], 'm', 'mm', 0)}, " + ("no load" if m[2] is None else "load curve"
                                                                 if isinstance(m[2], str) else _load(m[2]))
            minima.append(f"{MAP_QUANTITIES[name][0]} {fmt_num(m[0], 3)}{unit} at {where}")
    criterion = {"pm": MARGIN_CRITERION["phase_margin_deg"], "gm": MARGIN_CRITERION["gain_margin_db"], "minima": minima,
                 "below": sum(1 for p in points if p["stability"] != "meets")}
    bode = add("bode", analyses=labelled) if any(a.bode.frequency_hz for _, a in labelled) else None
    poles = add("poles", analyses=labelled) if any(a.poles.closed_loop for _, a in labelled) else None
    ctx = {"maps": maps, "points": points, "bode": bode, "poles": poles,
           "crosscheck": [_cross_row(r) for r in linear.crosscheck], "crosscheck_summary": _crosscheck_summary(linear.crosscheck),
           "governor": _governor(linear.governor, result) if linear.governor is not None else None,
           "notes": list(omap.notes) if omap is not None else [], "window": omap.window if omap is not None else None,
           "criterion": criterion}
    return ctx, specs


def _curve_force(curve, x):
    """Closing force of the load curve at position ``x`` [m] -> N (None without a curve)."""
    import numpy as np

    if curve is None or not isinstance(x, (int, float)):
        return None
    return float(np.interp(x, curve.position, curve.force))


def governor_basis(b, curve=None) -> list[str]:
    """Where the HYGOV figures come from (a :class:`~compliance.results.linear.GovernorBasis`), in sentences."""
    if b.sentences:  # the governor export writes its own (compliance.linear.governor_formats)
        return list(b.sentences)
    out = []
    pt = b.Tg_point
    samples = [v for v in b.Tg_nonlinear_samples if isinstance(v, (int, float))]
    if samples:
        if pt.load == "curve":
            f = _curve_force(curve, pt.position)
            load = "on the load curve" + (f" ({fmt_quantity(f, 'N', 'kN', 1)} there)" if f is not None else "")
        else:
            load = "" if pt.load is None else ", " + _load(pt.load) + " load"
        where = _mm(pt.position) + (" " + load if pt.load == "curve" else load)
        out.append(f"Tg is the mean time constant of {len(samples)} nonlinear steps of "
                   + " and ".join(fmt_quantity(s, "", "%", 0, signed=True) for s in b.Tg_steps)
                   + f" of stroke at {where}: " + ", ".join(fmt_value(v, "s", 3) for v in samples) + ".")
    if b.stroke_runs:
        load = b.stroke_runs.get("load")
        out.append("UO and UC come from closed-loop strokes end to end (reference step, 25\u201375 % of stroke extrapolated)"
                   + (f" at a {fmt_quantity(load, 'N', 'kN', digits=3)} closing load" if isinstance(load, (int, float)) else "")
                   + f": opening {fmt_value(b.stroke_time('opening'), 's', 3)}, closing {fmt_value(b.stroke_time('closing'), 's', 3)}. "
                   "They differ slightly from the opening and closing times of section 4, which are judged on open-loop "
                   "full strokes at the governor set-up load.")
    return out


def _ms(v, none="\u2013"):
    return none if v is None else fmt_quantity(v, "s", "ms", 0)


def _mm(v, digits=0):
    return "\u2013" if v is None else fmt_quantity(v, "m", "mm", digits)


def _load(ld, force=None):
    if ld is None:
        return "none"
    if isinstance(ld, str):
        return ld + (f" ({fmt_quantity(force, 'N', 'kN', 1)})" if isinstance(force, (int, float)) else "")
    return fmt_quantity(ld, "N", "kN", 1, signed=True)


# --------------------------------------------------------------------------- validation
def _mode_figures(mode, after, start: int, specs: list) -> list[dict]:
    """One overlay figure per signal of a replay (with the replay after the diagnosis, when there is one)."""
    figs = []
    for sig, ov in mode.overlays.items():
        label, unit, scale = _signal(sig, ov.unit)
        series = [("recorded", ov.time, ov.recorded, "recorded"),
                  ("simulated" + (" (before)" if after else ""), ov.time, ov.simulated, "before")]
        aov = after.overlays.get(sig) if after else None
        if aov:
            series.append(("simulated (after)", aov.time, aov.simulated, "after"))
        fid = f"fig-{start + len(specs)}"
        specs.append({"id": fid, "kind": "waveform", "series": series, "scale": scale, "ylabel": f"{label} [{unit}]",
                      "windows": _shaded(mode.located_windows, sig, ov.time), "smooth": sig == "valve_command"})
        figs.append({"id": fid, "signal": label, "role": ov.role, "shaded": bool(specs[-1]["windows"])})
    return figs


def _mode_context(name: str, mode, after, start: int, specs: list) -> dict:
    """A replay mode of the validation section: figures, fits (before and after), windowed errors, located misses."""
    figs = _mode_figures(mode, after, start, specs)
    fits = [{"signal": _signal(s)[0], "fit": fmt_num(f.fit_percent, 3), "nrmse": fmt_num(f.nrmse, 3),
             "rms": _sig(f.rms_error, s), "max": _sig(f.max_abs_error, s),
             "fit_after": fmt_num(after.fits[s].fit_percent if s in after.fits else None, 3) if after else None}
            for s, f in mode.fits.items()]
    located = [{"signal": _signal(w.signal)[0], "start": fmt_num(w.start, 4), "end": fmt_num(w.end, 4),
                "peak_ratio": fmt_num(w.peak_ratio, 3), "regimes": ", ".join(regime_text(r) for r in w.dominant)}
               for w in mode.located_windows]
    return {"name": name, "pass": mode.passed, "figures": figs, "fits": fits, "rows": _window_table(mode.window_metrics),
            "located": located, "has_after": bool(after)}


def _added_physics(diag) -> list[dict]:
    return [{"name": eff.name, "meaning": eff.meaning or "",
             "params": [{"name": p.name, "value": fmt_num(p.value, 4), "unit": pretty_unit(p.unit),
                         "bounds": " .. ".join(fmt_num(b, 3) for b in p.bounds or ())} for p in eff.params]}
            for eff in (diag.physics_added if diag is not None else ())]


def validation_section(val, start: int) -> tuple[dict | None, list[dict]]:
    """Context of the model-validation section and its figure specs (ids from ``start``).

    ``val``: a :class:`~compliance.results.validation.ValidationRecord` (a validation document is read into one here).
    """
    if not val:
        return None, []
    if isinstance(val, dict):
        val = ValidationRecord.from_dict(val, "validation")
    specs = []
    diag = val.diagnosis
    after_modes = diag.after.modes if diag is not None and diag.after is not None else {}
    modes = [_mode_context(name, m, after_modes.get(name), start, specs) for name, m in val.modes.items()]
    first = modes[0]["fits"] if modes else []
    pos = next((f for f in first if f["signal"] == "position"), {})
    ctx = {"fit_before": pos.get("fit") if pos.get("fit") not in (None, "\u2013") else None,
           "fit_after": pos.get("fit_after") if pos.get("fit_after") not in (None, "\u2013") else None,
           "finding": diagnosis_finding(diag) if diag is not None else None, "recording": val.recording,
           "plant": val.plant, "conditions": val.conditions, "modes": modes, "added": _added_physics(diag),
           "diagnosis": diag is not None, "explanation": diag.explanation if diag is not None else None,
           "warnings": list(val.warnings), "pass": val.passed}
    return ctx, specs


_REGIME_TEXT = {"a_choked": "choked flow into chamber A", "a_subsonic": "subsonic flow into chamber A",
                "b_choked": "choked flow into chamber B", "b_subsonic": "subsonic flow into chamber B",
                "valve_dead_band": "valve in its dead band", "valve_saturated": "valve fully open",
                "command_at_limit": "command at its limit", "region_closed": "near the closed end",
                "region_low": "low stroke", "region_mid": "mid stroke", "region_high": "high stroke"}


def regime_text(name) -> str:
    """A regime of compliance.validation.regimes in words (``b_choked`` -> ``choked flow into chamber B``)."""
    return _REGIME_TEXT.get(str(name), str(name).replace("_", " "))


VERDICT_TEXT = {"missing_physics": "MISSING PHYSICS FOUND", "parameters_only": "PARAMETERS ONLY",
                "no_mismatch": "NO MISMATCH", "unexplained": "UNEXPLAINED"}
NEXT_STEP = {
    "missing_physics": "Add the effect with the fitted parameters to the configuration (govcheck diagnose --save-model), "
                       "then re-run govcheck check on the fitted model.",
    "parameters_only": "Recalibrate the named parameters (govcheck diagnose --save-model) and re-run govcheck check.",
    "no_mismatch": "None: the model reproduces the recording within its noise floor.",
    "unexplained": "No declared effect explains the mismatch: record a test that separates the candidates "
                   "(e.g. slow ramps at several supply pressures for friction and leakage, steps of several sizes for "
                   "valve dynamics) and diagnose again.",
}


def diagnosis_finding(diag) -> dict:
    """The finding of a diagnosis for the top of its report: verdict, effect, parameters with uncertainty, next step."""
    from compliance.report.fit_bounds import effect_bound
    from compliance.presentation.numbers import fmt_si

    if isinstance(diag, dict):
        diag = DiagnosisRecord.from_dict(diag, "diagnosis")
    verdict, winner = diag.verdict, diag.ranked_winner
    params = [{"name": p.name, "text": fmt_si(p.value, p.unit or "", p.stderr), "meaning": p.meaning or "",
               "bound": effect_bound(p.name, p.value, p.unit)} for p in (winner.parameters if winner else ())]
    runner = diag.effects_ranked[1] if len(diag.effects_ranked) > 1 else None
    step = NEXT_STEP.get(verdict, "")
    if runner is not None and runner.delta_bic is not None and winner is not None and verdict in NEXT_STEP:
        gap = (runner.delta_bic or 0.0) - (winner.delta_bic or 0.0)
        if 0 <= gap < 10:  # BIC difference under 10: the data do not decide between the two
            step = (f"Ambiguous between {winner.name} and {runner.name} (BIC differs by {gap:.1f}, under 10): "
                    "run a test that separates them before changing the model. " + step)
    return {"verdict": verdict, "word": VERDICT_TEXT.get(verdict, str(verdict or "\u2013").upper()),
            "effect": winner.name if verdict in EXPLAINED and winner else None,
            "params": params if verdict in EXPLAINED else [], "explanation": diag.explanation, "next": step}


def _shaded(windows, sig: str, time) -> list:
    """The located mismatch windows worth shading on a plot: the three strongest, none longer than 40 % of the record."""
    span = (max(time) - min(time)) if time else None
    ws = [w for w in windows if w.signal == sig and w.start is not None and w.end is not None]
    if span:
        ws = [w for w in ws if (w.end - w.start) <= 0.4 * span]
    ws.sort(key=lambda w: -(w.peak_ratio or 0.0))
    return [(w.start, w.end) for w in ws[:3]]


def _window_table(metrics) -> dict:
    """Windowed errors pivoted: one row per window, one cell per signal (max / mean |error| [pu])."""
    signals, rows, index = [], [], {}
    for r in metrics:
        if r.signal not in signals:
            signals.append(r.signal)
        key = (r.window, r.kind, r.start)
        if key not in index:
            index[key] = {"window": r.window, "kind": r.kind, "cells": {}, "pass": True}
            rows.append(index[key])
        row = index[key]
        row["cells"][r.signal] = {"text": f"{_pct(r.max_error)} / {_pct(r.mean_absolute_error)}", "pass": r.passed,
                                  "failed": ", ".join(r.failed)}
        row["pass"] = row["pass"] and bool(r.passed)
    for row in rows:
        row["cells"] = [row["cells"].get(sig) for sig in signals]
    limits = {}
    for r in metrics:
        limits.setdefault((r.signal, r.kind), r.limits)
    lim_rows = [{"signal": _signal(sg)[0], "kind": k,
                 "text": ", ".join(f"{name.replace('_', ' ')} {_pct(v)} %" for name, v in lim.items() if v is not None)}
                for (sg, k), lim in limits.items()]
    return {"signals": [_signal(sg)[0] for sg in signals], "rows": rows, "limits": lim_rows}


def _pct(v) -> str:
    """A per-unit error as per cent of its base, two decimals (``0.00056`` -> ``0.06``)."""
    return "\u2013" if v is None else f"{100.0 * v:.2f}"


def _sig(v, signal):
    """An error of a signal in its display unit; an error of an absolute pressure is a difference (bar, not bar abs)."""
    if v is None:
        return "\u2013"
    label, unit, scale = _signal(signal)
    return f"{fmt_num(v * scale, 3)} {unit.replace(' abs', '')}"
