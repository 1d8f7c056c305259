"""Words of a seal-friction diagnosis: the paragraph per seal and the console summary."""

from __future__ import annotations

import math

import numpy as np

from compliance.diagnosis.friction_bench.fit import PRESSURE_EFFECT
from compliance.diagnosis.friction_bench.position import POSITION_FRICTION
from compliance.diagnosis.friction_bench.pressure_shape import NONLINEAR_PRESSURE, PRESSURE_FORCE
from compliance.diagnosis.friction_bench.running_in import FRICTION_DRIFT
from compliance.diagnosis.friction_bench.laws import core_equivalent
from compliance.presentation.numbers import fmt_si
from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict


def explain_friction(d) -> str:
    """One paragraph for a plant engineer about a ``friction_bench.diagnose.SealDiagnosis``."""
    base = d.fits["baseline"]
    rb = base.rms_per_run()
    runs = d.runs
    lo, hi = int(np.argmin([r.pressure for r in runs])), int(np.argmax([r.pressure for r in runs]))
    bp = base.params
    text = (f"Seal {d.seal}: a pressure-independent Stribeck law (F_C {fmt_si(bp['coulomb'], 'N')}, F_S {fmt_si(bp['static'], 'N')}, "
            f"b {fmt_si(bp['viscous'], 'N*s/m')}) leaves an RMS friction error of {fmt_si(np.mean(rb), 'N')} over the {len(runs)} runs "
            f"({math.sqrt(base.chi2 / base.n):.0f} times the force noise of {fmt_si(d.noise_floor, 'N')}).")
    loc = d.located
    trend = loc.get("pressure_trend")
    if trend:
        text += (f" Where it fails: in steady sliding the seal rubs {fmt_si(abs(trend['slope']), 'N/Pa')} of pressure "
                 f"{'harder' if trend['slope'] > 0 else 'less'} than the law says as the pressure rises "
                 f"({'+' if trend['span'] >= 0 else ''}{fmt_si(trend['span'], 'N')} across the pressures)")
    else:
        text += " Where it fails:"
    if loc.get("reversal_excess"):
        text += (f"{';' if trend else ''} after each reversal the residual is {loc['reversal_excess']:.1f} times its sliding level "
                 f"- the friction builds up over the first millimetres of travel instead of jumping.")
    else:
        text += "."
    if d.verdict == DiagnosisVerdict.NO_MISMATCH:
        return text + " The law already fits within the force noise: nothing is missing."
    if d.winner is None:
        tested = "pressure-dependent friction, pre-sliding hysteresis" if PRESSURE_EFFECT in d.fits else (
            "pre-sliding hysteresis; pressure dependence needs runs at two or more pressures")
        return text + f" None of the candidate physics ({tested}) removes enough of it: unexplained."
    w = d.fits[d.winner]
    p = w.params
    parts = []
    if "pressure_exponent" in p:
        parts.append(f"seal friction that rises with the chamber pressure along a power law (k_p p_r (p_g/p_r)^n, "
                     f"k_p = {fmt_si(p['pressure_coefficient'], 'N/Pa')}, n = {p['pressure_exponent']:.2f}, p_r = "
                     f"{fmt_si(p['reference_pressure'], 'Pa')} gauge, on F_C and F_S; the bench effect \u201c{NONLINEAR_PRESSURE.meaning}\u201d, "
                     f"kept because it predicts held-out runs better{core_equivalent(p)}, a straight line that meets the power law "
                     "at zero and at p_r only)")
    elif "pressure_coefficient" in p:
        parts.append(f"seal friction that rises with the chamber pressure (k_p = {fmt_si(p['pressure_coefficient'], 'N/Pa')} "
                     f"on F_C and F_S{core_equivalent(p)})")
    if "bristle_stiffness" in p:
        pm = float(np.mean([r.pressure for r in runs]))
        fc = p["coulomb"] + p.get("pressure_coefficient", 0.0) * pm
        parts.append(f"pre-sliding hysteresis at reversals (LuGre bristles, \u03c3\u2080 = {fmt_si(p['bristle_stiffness'], 'N/m')}: "
                     f"the friction builds up over a pre-sliding distance F_C/\u03c3\u2080 of about "
                     f"{fmt_si(fc / p['bristle_stiffness'], 'm')} at {fmt_si(pm, 'Pa')} gauge)")
    if "position_gradient" in p:
        parts.append(f"friction that changes along the stroke (levels \u00d7 (1 + a (x \u2212 x_r) + c (x \u2212 x_r)\u00b2), "
                     f"a = {fmt_si(p['position_gradient'], '1/m')}, c = {fmt_si(p['position_curvature'], '1/m^2')}, "
                     f"x_r = {fmt_si(p['reference_position'], 'm')}; the bench effect \u201c{POSITION_FRICTION.meaning}\u201d, "
                     "kept because it predicts held-out runs better)")
    if "drift_rate" in p:
        parts.append(f"friction that drifts during each run (both levels \u00d7 (1 + r (t \u2212 t_m)), r = "
                     f"{100 * p['drift_rate']:.3f} %/s from the run's mid time; the bench effect \u201c{FRICTION_DRIFT.meaning}\u201d, "
                     "kept because it predicts held-out runs better)")
    if "bias_per_pressure_squared" in p:
        span = max(r.pressure for r in runs) - min(r.pressure for r in runs)
        # c2 p^2 trades off against c1 p: its size is how far it bends the bias from a straight line, c2 span^2 / 4
        parts.append(f"a direction-independent force curved in the pressure (c2 p_g\u00b2, c2 = "
                     f"{fmt_si(p['bias_per_pressure_squared'], 'N/Pa^2')}: up to {fmt_si(abs(p['bias_per_pressure_squared']) * span ** 2 / 4, 'N')} "
                     f"off a straight line across the pressures; the bench effect \u201c{PRESSURE_FORCE.meaning}\u201d, kept because it "
                     "predicts the held-out runs' force offsets)")
    ra = w.rms_per_run()
    text += (f" The missing physics: {' and '.join(parts)}. Adding it cuts the RMS friction error from {fmt_si(np.mean(rb), 'N')} "
             f"to {fmt_si(np.mean(ra), 'N')} ({fmt_si(rb[lo], 'N')} \u2192 {fmt_si(ra[lo], 'N')} at {fmt_si(runs[lo].pressure, 'Pa')} gauge, "
             f"{fmt_si(rb[hi], 'N')} \u2192 {fmt_si(ra[hi], 'N')} at {fmt_si(runs[hi].pressure, 'Pa')} gauge).")
    if d.verdict == DiagnosisVerdict.UNEXPLAINED:
        text += " It still leaves most of the error: the rest is physics outside these candidates (e.g. position-dependent friction)."
    return text


def format_friction(d: dict, quiet: bool = False) -> str:
    """Console summary of a friction diagnosis."""
    lines = []
    for s in d["seals"]:
        lines.append(f"seal {s['seal']}: verdict {s['verdict']}" + (f" ({s['winner']})" if s["winner"] else ""))
        if quiet:
            continue
        lines.append("  " + s["explanation"])
        lines.append(f"  {'candidate':50s} {'k':>2s} {'chi2/N':>9s} {'dBIC':>9s}")
        for e in s["effects"]:
            lines.append(f"  {e['name']:50s} {e['k']:2d} {e['chi2_per_residual']:9.2f} {e['delta_bic']:9.1f}")
        lines.append(f"  {'run':28s} {'p [bar g]':>9s} {'RMS before [N]':>15s} {'RMS after [N]':>14s}")
        for run, b in s["fit_before"].items():
            a = (s["fit_after"] or {}).get(run)
            lines.append(f"  {run:28s} {b['pressure_gauge']/1e5:9.2f} {b['rms']:15.3f} {a['rms'] if a else float('nan'):14.3f}")
        if s.get("holdout"):
            h = s["holdout"]
            lines.append(f"  out of sample ({h['law']}): each pressure predicted by the law fitted on the others")
            lines.append(f"  {'run':28s} {'p [bar g]':>9s} {'in-sample [N]':>14s} {'held-out [N]':>13s} {'ratio':>6s} "
                         f"{'offset [N]':>11s} {'noise [N]':>10s}")
            for r in h["runs"]:
                lines.append(f"  {r['run']:28s} {r['pressure_gauge']/1e5:9.2f} {r['in_sample_rms']:14.3f} {r['held_out_rms']:13.3f} "
                             f"{r['ratio']:6.2f} {r['held_out_offset']:+11.2f} {r['noise_floor']:10.3f}")
            lines.append(f"  median held-out / in-sample: {h['median_ratio']:.2f} (target <= {h['ratio_target']:g}); "
                         f"without each run's own offset: {h['median_ratio_without_offset']:.2f}")
            lines += _refit_lines(h)
            for t in s.get("bench_effects") or []:
                lines.append(f"  bench effect {t['effect']}: {'kept' if t['kept'] else 'not kept'} (held-out error lower in "
                             f"{t['runs_improved']} of {t['runs']} runs, median {100 * t['median_gain']:+.1f} %, dBIC {t['delta_bic']:.0f})")
    pooled = d.get("holdout_pooled")
    if pooled and len(d["seals"]) > 1:
        lines.append(f"all seals, {pooled['runs']} runs: median held-out / in-sample {pooled['median_ratio']:.2f} "
                     f"(target <= {pooled['ratio_target']:g}); without each run's own offset: {pooled['median_ratio_without_offset']:.2f}")
    lines.append(f"{d['timing']['seconds']:.1f} s")
    return "\n".join(lines)


_REFIT_WORDS = {"pressure_exponent": ("pressure exponent n", ""), "bias_per_pressure_squared": ("c2", "N/Pa^2")}


def _refit_lines(h: dict) -> list[str]:
    """Per pressure-shape parameter, its value refitted without each run and with all runs (console)."""
    from compliance.presentation.numbers import fmt_si

    out = []
    for key, (label, unit) in _REFIT_WORDS.items():
        every = h.get("refit_all_runs", {}).get(key)
        if not every:
            continue
        folds = ", ".join(fmt_si(r["refit"][key]["value"], unit, r["refit"][key]["stderr"]) for r in h["runs"])
        out.append(f"  {label} refitted without each run: {folds}; all runs: {fmt_si(every['value'], unit, every['stderr'])}")
    return out
