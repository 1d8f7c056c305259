"""Optional report sections: linear analysis and model validation (what exists is shown).

Linear data is the document ``govcheck linear --json`` writes (schema ``govcheck-linear/1``:
``analysis`` or ``analyses``, ``map``, ``crosscheck``, ``governor``), found in a results dict
under ``linear``. Validation data is ``compliance.validation.validate.validate`` output (schema
``govcheck.validation/1``), optionally with a ``diagnosis`` entry (``after`` overlays and the
physics added with its fitted parameters). Missing parts are reported as "not run".
"""

from __future__ import annotations

from compliance.units.formatting import fmt_num, fmt_value, unit_text as pretty_unit
from compliance.report.figures_linear import MAP_QUANTITIES
from compliance.diagnosis.verdicts.verdict import EXPLAINED

SIGNAL_DISPLAY = {  # signal -> (label, unit shown, scale from SI)
    "position": ("position", "mm", 1e3),
    "valve_command": ("valve command", "V", 1.0),
    "pressure_a": ("chamber A pressure", "bar abs", 1e-5),
    "pressure_b": ("chamber B pressure", "bar abs", 1e-5),
    "supply_pressure": ("supply pressure", "bar abs", 1e-5),
}


def _op_label(a: dict) -> str:
    op = a.get("operating_point") or {}
    if a.get("label"):
        return str(a["label"])
    x = op.get("position")
    ld = op.get("load")
    load = "no load" if ld is None else (f"load curve, {(op.get('load_force') or 0) / 1e3:.1f} kN" if isinstance(ld, str)
                                          else f"{ld / 1e3:+.1f} kN")
    return f"{x * 1e3:.0f} mm, {load}" if isinstance(x, (int, float)) else "operating point"


def _op_names(results: dict | None) -> list[tuple[str, float, object]]:
    """The requirement file's operating points as (name, position [m], load: None | N | "curve")."""
    if not results:
        return []
    from compliance.units.amounts import parse_amount

    params = {p.get("key"): p.get("value") for p in results["plant"].get("parameters") or [] if isinstance(p, dict)}
    stroke = params.get("cylinder.stroke") or 0.0
    out = []
    for name, op in (results["requirement_set"].get("operating_points") or {}).items():
        if op.get("initial_position") is None:
            continue
        try:
            x = parse_amount(op["initial_position"], "m", name).resolve(stroke)
        except Exception:  # noqa: BLE001 - a position the report cannot read names no point
            continue
        ld = op.get("load")
        out.append((name, x, params.get("load.nominal_force") if ld == "nominal" else ld))
    return out


def _same_load(a, b) -> bool:
    if a is None or b is None or isinstance(a, str) or isinstance(b, str):
        return a == b
    return abs(float(a) - float(b)) < 1.0


def distinct_points(analyses: list, results: dict | None = None) -> list[tuple[str, dict]]:
    """The analyses at distinct (position, load) points, each labelled with the operating points it stands for."""
    names = _op_names(results)
    out, seen = [], set()
    for a in analyses:
        op = a.get("operating_point") or {}
        x, ld = op.get("position"), op.get("load")
        key = (round(x, 6) if isinstance(x, (int, float)) else None, ld if isinstance(ld, str) or ld is None else round(ld, 1))
        if key in seen:
            continue
        seen.add(key)
        which = [n for n, nx, nl in names if isinstance(x, (int, float)) and abs(nx - x) < 1e-6 and _same_load(nl, ld)]
        label = _op_label(a)
        out.append((label, a, which))
    return out


def _stability(f: dict) -> str:
    """Against the stated margin criterion (MARGIN_CRITERION, our choice): meets / below / unstable / unknown."""
    from compliance.report.acceptance import MARGIN_CRITERION

    if f.get("stable") is False:
        return "unstable"
    pm, gm = f.get("phase_margin_deg"), f.get("gain_margin_db")
    if f.get("stable") is None or pm is None or gm is None:
        return "unknown"
    ok = pm >= MARGIN_CRITERION["phase_margin_deg"] and gm >= MARGIN_CRITERION["gain_margin_db"]
    return "meets" if ok else "below"


def _map_minimum(omap: dict | None, name: str):
    """Smallest value of a map quantity and where (position [m], load label)."""
    vals = ((omap or {}).get("values") or {}).get(name)
    if not vals:
        return None
    best = None
    loads = omap.get("loads") or [None] * len(vals)
    for i, row in enumerate(vals):
        for j, v in enumerate(row):
            if isinstance(v, (int, float)) and (best is None or v < best[0]):
                best = (v, omap["positions"][j], loads[i])
    return best


def _crosscheck_summary(rows: list[dict]) -> str:
    """One sentence on the linear vs nonlinear cross-check (the table itself goes to the appendix)."""
    done = [r for r in rows if "skipped" not in r]
    ratios = [r["ratio"] for r in done if r.get("ratio") is not None]
    stalled = sum(1 for r in done if r.get("tau_linear") is not None and r.get("tau_nonlinear") is None)
    return (f"{len(done)} small steps were simulated with the nonlinear model at the critical points" + (
        f": where the servo completes the step its time constant is {fmt_num(min(ratios), 3)} to {fmt_num(max(ratios), 3)}"
        " times the linear one (friction and the valve dead zone, which the linear model leaves out)" if ratios else "")
        + (f"; {stalled} steps stall inside the valve dead zone and reach no 63.2 % point" if stalled else "") + ".")


def linear_section(linear: dict | None, start: int, results: dict | None = None) -> tuple[dict | None, list[dict]]:
    """Context of the linear-analysis section and its figure specs (ids from ``start``)."""
    if not linear:
        return None, []
    from compliance.report.acceptance import MARGIN_CRITERION

    specs = []

    def add(kind, **kw):
        fid = f"fig-{start + len(specs)}"
        specs.append({"id": fid, "kind": kind, **kw})
        return fid

    analyses = list(linear.get("analyses") or ([linear["analysis"]] if linear.get("analysis") else []))
    points_named = distinct_points(analyses, results)
    labelled = [(f"P{k + 1} {label}", a) for k, (label, a, _) in enumerate(points_named)]  # keys as in the table
    maps = []
    omap = linear.get("map")
    if omap:
        for name in ("time_constant", "gain_margin_db", "phase_margin_deg"):
            if (omap.get("values") or {}).get(name):
                maps.append({"id": add("map", omap=omap, name=name), "title": MAP_QUANTITIES[name][0],
                             "unit": MAP_QUANTITIES[name][1]})
    points = []
    for k, (label, a, which) in enumerate(points_named):
        f = a.get("figures") or {}
        points.append({"key": f"P{k + 1}", "label": label, "names": which, "time_constant": _ms(f.get("time_constant")),
                       "gain_margin": fmt_num(f.get("gain_margin_db"), 3), "phase_margin": fmt_num(f.get("phase_margin_deg"), 3),
                       "bandwidth": fmt_num(f.get("bandwidth_hz"), 3), "damping": fmt_num(f.get("damping_ratio"), 3),
                       "natural_frequency": fmt_num(f.get("natural_frequency_hz"), 3),
                       "stable": f.get("stable"), "stability": _stability(f)})
    minima = []
    for name, unit in (("phase_margin_deg", "°"), ("gain_margin_db", " dB")):
        m = _map_minimum(omap, name)
        if m is not None:
            where = f"{m[1] * 1e3:.0f} mm, " + ("no load" if m[2] is None else "load curve" if isinstance(m[2], str)
                                                 else f"{m[2] / 1e3:+.1f} kN")
            minima.append(f"{MAP_QUANTITIES[name][0]} {fmt_num(m[0], 3)}{unit} at {where}")
    criterion = {"pm": MARGIN_CRITERION["phase_margin_deg"], "gm": MARGIN_CRITERION["gain_margin_db"], "minima": minima,
                 "below": sum(1 for p in points if p["stability"] != "meets")}
    bode = add("bode", analyses=labelled) if any(a.get("bode") for _, a in labelled) else None
    poles = add("poles", analyses=labelled) if any((a.get("poles") or {}).get("closed_loop") for _, a in labelled) else None
    cross = []
    for r in linear.get("crosscheck") or []:
        if "skipped" in r:
            cross.append({"position": _mm(r.get("position")), "load": _load(r.get("load")), "skipped": r["skipped"]})
            continue
        cross.append({"position": _mm(r.get("position")), "load": _load(r.get("load"), r.get("load_force")),
                      "step": f"{r['step'] * 100:+.0f} %" if r.get("step") is not None else "\u2013",
                      "tau_linear": _ms(r.get("tau_linear")), "tau_nonlinear": _ms(r.get("tau_nonlinear"), "stalled"),
                      "ratio": fmt_num(r.get("ratio"), 3), "steady_error": _mm(r.get("steady_error"), 2),
                      "why": r.get("why") or "agrees within 20 %"})
    gov = None
    summary = _crosscheck_summary(linear.get("crosscheck") or [])
    g = linear.get("governor")
    if g:
        units = g.get("units") or {}
        params = dict(g.get("parameters") or {})
        params.update({k: v for k, v in (g.get("rate_limits") or {}).items()})
        rows = [{"name": k, "value": fmt_num(v, 4), "unit": units.get(k, "")} for k, v in params.items()]
        if g.get("Tg_linear") is not None:
            rows.append({"name": "Tg (linear)", "value": fmt_num(g["Tg_linear"], 4), "unit": "s"})
        stroke = next((p.get("value") for p in ((results or {}).get("plant") or {}).get("parameters") or []
                       if isinstance(p, dict) and p.get("key") == "cylinder.stroke"), None)
        per_unit = f" (1 pu = the full stroke, {stroke * 1e3:.0f} mm)" if isinstance(stroke, (int, float)) else ""
        intro = (f"{g.get('model', 'HYGOV')} is the hydro turbine-governor model of power-system simulation tools (IEEE PES "
                 "TR 2013, hydro turbine-governor models): Tg is its gate-servomotor time constant, VELM the gate velocity "
                 "limit, GMAX and GMIN the gate limits, UO and UC the opening and closing rate limits. Gate positions are "
                 f"per unit (pu) of the stroke and rates in pu/s, per unit of stroke per second{per_unit}.")
        gov = {"model": g.get("model", "HYGOV"), "rows": rows,
               "basis": [intro] + governor_basis(g.get("basis") or {}, (results or {}).get("plant", {}).get("load_curve"))}
    notes = list((omap or {}).get("notes") or [])
    ctx = {"maps": maps, "points": points, "bode": bode, "poles": poles, "crosscheck": cross, "crosscheck_summary": summary, "governor": gov,
           "notes": notes, "window": (omap or {}).get("window"), "criterion": criterion}
    return ctx, specs


def _curve_force(curve, x):
    """Closing force of the load curve at position ``x`` [m] -> N (None without a curve)."""
    import numpy as np

    if not curve or not isinstance(x, (int, float)):
        return None
    return float(np.interp(x, curve["position"], curve["force"]))


def governor_basis(b: dict, curve: dict | None = None) -> list[str]:
    """Where the HYGOV figures come from, in sentences (never a raw dict)."""
    if b.get("sentences"):  # the governor export writes its own (compliance.linear.governor_formats)
        return [str(s) for s in b["sentences"]]
    out = []
    pt = b.get("Tg_point") or {}
    samples = [v for v in b.get("Tg_nonlinear_samples") or [] if isinstance(v, (int, float))]
    if samples:
        ld = pt.get("load")
        if ld == "curve":
            f = _curve_force(curve, pt.get("position"))
            load = "on the load curve" + (f" ({f / 1e3:.1f} kN there)" if f is not None else "")
        else:
            load = "" if ld is None else ", " + _load(ld) + " load"
        where = _mm(pt.get("position")) + (" " + load if ld == "curve" else load)
        out.append(f"Tg is the mean time constant of {len(samples)} nonlinear steps of "
                   + " and ".join(f"{100 * s:+.0f} %" for s in b.get("Tg_steps") or []) + f" of stroke at {where}: "
                   + ", ".join(fmt_value(v, "s", 3) for v in samples) + ".")
    runs = b.get("stroke_runs") or {}
    if runs:
        o, c = runs.get("opening") or {}, runs.get("closing") or {}
        load = runs.get("load")
        out.append("UO and UC come from closed-loop strokes end to end (reference step, 25\u201375 % of stroke extrapolated)"
                   + (f" at a {fmt_value(load / 1e3, 'kN', 3)} closing load" if isinstance(load, (int, float)) else "")
                   + f": opening {fmt_value(o.get('stroke_time'), 's', 3)}, closing {fmt_value(c.get('stroke_time'), 's', 3)}. "
                   "They differ slightly from the opening and closing times of section 4, which are judged on open-loop "
                   "full strokes at the governor set-up load.")
    return out


def _ms(v, none="\u2013"):
    return none if v is None else f"{v * 1e3:.0f} ms"


def _mm(v, digits=0):
    return "\u2013" if v is None else f"{v * 1e3:.{digits}f} mm"


def _load(ld, force=None):
    if ld is None:
        return "none"
    if isinstance(ld, str):
        return ld + (f" ({force / 1e3:.1f} kN)" if isinstance(force, (int, float)) else "")
    return f"{ld / 1e3:+.1f} kN"


# --------------------------------------------------------------------------- validation
def validation_section(val: dict | None, start: int) -> tuple[dict | None, list[dict]]:
    """Context of the model-validation section and its figure specs (ids from ``start``)."""
    if not val:
        return None, []
    specs = []
    modes = []
    diag = val.get("diagnosis") or {}
    after_modes = (diag.get("after") or {}).get("modes") or {}
    for mode, m in (val.get("modes") or {}).items():
        windows = m.get("located_windows") or []
        after = after_modes.get(mode) or {}
        figs = []
        for sig, ov in (m.get("overlays") or {}).items():
            label, unit, scale = SIGNAL_DISPLAY.get(sig, (sig, ov.get("unit", ""), 1.0))
            series = [("recorded", ov.get("time"), ov.get("recorded"), "recorded"),
                      ("simulated" + (" (before)" if after else ""), ov.get("time"), ov.get("simulated"), "before")]
            aov = (after.get("overlays") or {}).get(sig)
            if aov:
                series.append(("simulated (after)", aov.get("time"), aov.get("simulated"), "after"))
            fid = f"fig-{start + len(specs)}"
            specs.append({"id": fid, "kind": "waveform", "series": series, "scale": scale, "ylabel": f"{label} [{unit}]",
                          "windows": _shaded(windows, sig, ov.get("time")), "smooth": sig == "valve_command"})
            figs.append({"id": fid, "signal": label, "role": ov.get("role"), "shaded": bool(specs[-1]["windows"])})
        fits = [{"signal": SIGNAL_DISPLAY.get(s, (s,))[0], "fit": fmt_num(f.get("fit_percent"), 3),
                 "nrmse": fmt_num(f.get("nrmse"), 3), "rms": _sig(f.get("rms_error"), s), "max": _sig(f.get("max_abs_error"), s),
                 "fit_after": fmt_num(((after.get("fits") or {}).get(s) or {}).get("fit_percent"), 3) if after else None}
                for s, f in (m.get("fits") or {}).items()]
        rows = _window_table(m.get("window_metrics") or [])
        located = [{"signal": SIGNAL_DISPLAY.get(w.get("signal"), (w.get("signal"),))[0], "start": fmt_num(w.get("start"), 4),
                    "end": fmt_num(w.get("end"), 4), "peak_ratio": fmt_num(w.get("peak_ratio"), 3),
                    "regimes": ", ".join(regime_text(r) for r in w.get("dominant") or [])} for w in windows]
        modes.append({"name": mode, "pass": m.get("pass"), "figures": figs, "fits": fits, "rows": rows, "located": located,
                      "has_after": bool(after)})
    added = []
    for eff in diag.get("added") or diag.get("effects") or []:
        added.append({"name": eff.get("name"), "meaning": eff.get("meaning") or "",
                      "params": [{"name": p.get("name"), "value": fmt_num(p.get("value"), 4), "unit": pretty_unit(p.get("unit", "")),
                                  "bounds": " .. ".join(fmt_num(b, 3) for b in (p.get("bounds") or []))}
                                 for p in eff.get("params") or []]})
    rec = val.get("recording") or {}
    first = modes[0] if modes else {}
    pos = next((f for f in first.get("fits") or [] if f["signal"] == "position"), {})
    ctx = {"fit_before": pos.get("fit") if pos.get("fit") not in (None, "\u2013") else None,
           "fit_after": pos.get("fit_after") if pos.get("fit_after") not in (None, "\u2013") else None,
           "finding": diagnosis_finding(diag) if diag else None, "recording": rec, "plant": val.get("plant") or {}, "conditions": val.get("conditions") or {},
           "modes": modes, "added": added, "diagnosis": bool(diag), "explanation": diag.get("explanation"),
           "warnings": val.get("warnings") or [], "pass": (val.get("summary") or {}).get("pass")}
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


def diagnosis_finding(diag: dict) -> dict:
    """The finding of a diagnosis for the top of its report: verdict, effect, parameters with uncertainty, next step."""
    verdict = diag.get("verdict")
    ranked = diag.get("effects_ranked") or []
    winner = ranked[0] if ranked else None
    for e in ranked:
        if e.get("name") == diag.get("winner"):
            winner = e
    params = []
    from compliance.report.fit_bounds import effect_bound
    from compliance.units.formatting import fmt_si

    for p in (winner or {}).get("parameters") or []:
        params.append({"name": p.get("name"), "text": fmt_si(p.get("value"), p.get("unit") or "", p.get("stderr")),
                       "meaning": p.get("meaning") or "", "bound": effect_bound(p)})
    runner = ranked[1] if len(ranked) > 1 else None
    step = NEXT_STEP.get(verdict, "")
    if runner is not None and runner.get("delta_bic") is not None and winner is not None and verdict in NEXT_STEP:
        gap = (runner.get("delta_bic") or 0.0) - (winner.get("delta_bic") or 0.0)
        if 0 <= gap < 10:  # BIC difference under 10: the data do not decide between the two
            step = (f"Ambiguous between {winner.get('name')} and {runner.get('name')} (BIC differs by {gap:.1f}, under 10): "
                    "run a test that separates them before changing the model. " + step)
    return {"verdict": verdict, "word": VERDICT_TEXT.get(verdict, str(verdict or "\u2013").upper()),
            "effect": (winner or {}).get("name") if verdict in EXPLAINED else None,
            "params": params if verdict in EXPLAINED else [],
            "explanation": diag.get("explanation"), "next": step}


def _shaded(windows: list, sig: str, time) -> list:
    """The located mismatch windows worth shading on a plot: the three strongest, none longer than 40 % of the record."""
    span = (max(time) - min(time)) if time else None
    ws = [w for w in windows if w.get("signal") == sig and w.get("start") is not None and w.get("end") is not None]
    if span:
        ws = [w for w in ws if (w["end"] - w["start"]) <= 0.4 * span]
    ws.sort(key=lambda w: -(w.get("peak_ratio") or 0.0))
    return [(w["start"], w["end"]) for w in ws[:3]]


def _window_table(metrics: list) -> dict:
    """Windowed errors pivoted: one row per window, one cell per signal (max / mean |error| [pu])."""
    signals, rows, index = [], [], {}
    for r in metrics:
        sig = r.get("signal")
        if sig not in signals:
            signals.append(sig)
        key = (r.get("window"), r.get("kind"), r.get("start"))
        if key not in index:
            index[key] = {"window": r.get("window"), "kind": r.get("kind"), "cells": {}, "pass": True}
            rows.append(index[key])
        row = index[key]
        row["cells"][sig] = {"text": f"{_pct(r.get('max_error'))} / {_pct(r.get('mean_absolute_error'))}",
                             "pass": r.get("pass"), "failed": ", ".join(r.get("failed") or [])}
        row["pass"] = row["pass"] and bool(r.get("pass"))
    for row in rows:
        row["cells"] = [row["cells"].get(sig) for sig in signals]
    limits = {}
    for r in metrics:
        limits.setdefault((r.get("signal"), r.get("kind")), r.get("limits") or {})
    lim_rows = [{"signal": SIGNAL_DISPLAY.get(sg, (sg,))[0], "kind": k,
                 "text": ", ".join(f"{name.replace('_', ' ')} {_pct(v)} %" for name, v in lim.items() if v is not None)}
                for (sg, k), lim in limits.items()]
    return {"signals": [SIGNAL_DISPLAY.get(sg, (sg,))[0] for sg in signals], "rows": rows, "limits": lim_rows}


def _pct(v) -> str:
    """A per-unit error as per cent of its base, two decimals (``0.00056`` -> ``0.06``)."""
    return "\u2013" if v is None else f"{100.0 * v:.2f}"


def _sig(v, signal):
    """An error of a signal in its display unit; an error of an absolute pressure is a difference (bar, not bar abs)."""
    if v is None:
        return "\u2013"
    label, unit, scale = SIGNAL_DISPLAY.get(signal, (signal, "", 1.0))
    return f"{fmt_num(v * scale, 3)} {unit.replace(' abs', '')}"
