"""Out-of-sample proof of a seal's friction law: fit on the other pressures, predict the one left out.

For a seal with runs at three or more pressures, each run in turn is held out: the law is
refitted (from the all-runs optimum) on the other runs and predicts the held-out run sample by
sample. Per run the table gives

- ``in_sample_rms``: the RMS error of the law fitted with every run, on this run [N];
- ``held_out_rms``: the RMS error of the law fitted without this run, on this run [N];
- ``held_out_offset``: the mean of that error: the run's own force zero relative to the
  bias the other runs give (a bench finding, not physics: a sensor zero that moves
  between runs), and ``held_out_rms_without_offset`` with it removed;
- ``in_sample_offset``: the run's own mean error under the all-runs law: its run-to-run
  offset (a bench finding), and ``in_sample_rms_without_offset``;
- ``noise_floor``: the force sensor's noise [N];
- ``refit``: the pressure parameters of the law refitted without this run (``REFIT_KEYS``, value
  and standard error): with three pressures left a three-parameter pressure shape is determined
  with none to spare, and folds that disagree by many standard errors say the shape is not the
  seal's whole story (``refit_all_runs`` gives the all-runs values);
- ``ratio`` (held-out / in-sample) and ``ratio_without_offset`` (both with the run's own
  offset removed: the friction law's prediction alone).

``median_ratio`` (median over the runs of held-out / in-sample, each run's force offset
included) is the proof asked for: a law that only describes the runs it saw degrades far more out
of sample. ``ratio_without_offset`` is reported beside it, never in its place: the offset is what
the bias law fitted on the other runs fails to predict of the held-out run's force zero.
A declared bench effect (``fit.BENCH_EFFECTS``) is kept only when it *earns its parameters on
held-out runs* (``earns``): it lowers the held-out error of at least ``EARN_FOLDS`` of the runs and
the median held-out error by ``EARN_GAIN`` (and the BIC over all runs). A ratio can rise when an
effect is kept: the effect lowers the in-sample error more than the held-out error.
The folds run on the shared executor (``processes.map_tasks``).
"""

from __future__ import annotations

import numpy as np

from compliance.files.jsonable import json_number
from compliance.diagnosis.friction_bench.fit import LawFit, fit_law, predict, start_from
from compliance.diagnosis.friction_bench.position import POSITION_FRICTION
from compliance.diagnosis.friction_bench.pressure_shape import NONLINEAR_PRESSURE, PRESSURE_FORCE
from compliance.diagnosis.friction_bench.running_in import FRICTION_DRIFT
from compliance.presentation.numbers import fmt_si
from compliance.diagnosis.verdicts.candidate_set import CandidateSet

MIN_RUNS = 3  # fit on at least two pressures, predict a third
RATIO_TARGET = 1.5  # median held-out error within this multiple of the in-sample error (our target)
EARN_GAIN = 0.05  # an added effect must lower the median held-out error by 5 % ... (our choice)
EARN_FOLDS = 0.75  # ... and the held-out error of at least 3 runs in 4 (our choice)
MIN_PRESSURE_STEP = 0.3e5  # Pa; runs closer in pressure count as one pressure
REFIT_KEYS = ("pressure_coefficient", "pressure_exponent", "bias_per_pressure", "bias_per_pressure_squared")
BENCH_MEANINGS = {e.name: e.meaning for e in (NONLINEAR_PRESSURE, PRESSURE_FORCE, POSITION_FRICTION, FRICTION_DRIFT)}


def _fold(context, item) -> tuple[np.ndarray, dict]:
    """Held-out residual [N] of run ``i`` under the law refitted on the other runs, and that refit's pressure parameters."""
    runs, name, start = context
    i = item
    fit = fit_law([r for j, r in enumerate(runs) if j != i], name, start)
    r = runs[i]
    return (r.friction - predict(r, fit))[r.valid], _pressure_parameters(fit)


def _pressure_parameters(fit: LawFit) -> dict:
    """The pressure shape a fit found: ``REFIT_KEYS`` it has, each ``{value, stderr}`` (SI)."""
    return {k: {"value": json_number(fit.params[k]), "stderr": json_number(fit.stderr.get(k))} for k in REFIT_KEYS if k in fit.params}


def held_out_fits(runs, full: LawFit, *, jobs: int | None = None, scheduler: str | None = None) -> list | None:
    """Per run, (its residual [N], the refit's pressure parameters) under the law ``full.name`` refitted without it.

    None with fewer than ``MIN_RUNS`` runs.
    """
    if len(runs) < MIN_RUNS:
        return None
    from compliance.processes import map_tasks

    res, stats = map_tasks(_fold, (runs, full.name, start_from(full.params)), list(range(len(runs))), workers=jobs,
                           scheduler=scheduler, progress=False, label="held-out fits", retries=0)
    if stats.failed:
        raise RuntimeError(f"held-out fit failed: {stats.errors[0][1]}")
    return res


def holdout_table(runs, full: LawFit, held: list) -> dict:
    """The out-of-sample table of one law (see the module docstring); JSON-ready."""
    rows = []
    for r, ins, (h, refit) in zip(runs, full.residuals, held):
        off, ioff = float(np.mean(h)), float(np.mean(ins))
        rows.append({"run": r.name, "pressure_gauge": json_number(r.pressure), "refit": refit,
                     "in_sample_rms": json_number(float(np.sqrt(np.mean(ins * ins)))),
                     "in_sample_offset": json_number(ioff),
                     "in_sample_rms_without_offset": json_number(float(np.sqrt(np.mean((ins - ioff) ** 2)))),
                     "held_out_rms": json_number(float(np.sqrt(np.mean(h * h)))),
                     "held_out_offset": json_number(off),
                     "held_out_rms_without_offset": json_number(float(np.sqrt(np.mean((h - off) ** 2)))),
                     "noise_floor": json_number(r.floor)})
    for row in rows:
        row["ratio"] = json_number(row["held_out_rms"] / max(row["in_sample_rms"], 1e-12))
        row["held_out_in_noise"] = json_number(row["held_out_rms"] / max(row["noise_floor"], 1e-12))
        row["ratio_without_offset"] = json_number(row["held_out_rms_without_offset"] / max(row["in_sample_rms_without_offset"], 1e-12))
    ratio = float(np.median([row["ratio"] for row in rows]))
    return {"law": full.name, "runs": rows, "median_ratio": ratio, "ratio_target": RATIO_TARGET,
            "within_target": bool(ratio <= RATIO_TARGET),
            "median_ratio_without_offset": float(np.median([row["ratio_without_offset"] for row in rows])),
            "median_held_out_rms": float(np.median([row["held_out_rms"] for row in rows])),
            "median_in_sample_rms": float(np.median([row["in_sample_rms"] for row in rows])),
            "refit_all_runs": _pressure_parameters(full), "unit": "N"}


def pooled_holdout(tables: list) -> dict | None:
    """The held-out proof over every run of every seal (None without a held-out table).

    ``median_ratio`` is the median over all runs of held-out / in-sample RMS, each run's force
    offset included (the figure judged against ``RATIO_TARGET``); ``median_ratio_without_offset``
    removes each run's own mean error in both (the friction law's prediction alone).
    """
    rows = [row for t in tables if t for row in t["runs"]]
    if not rows:
        return None
    ratio = float(np.median([r["ratio"] for r in rows]))
    return {"runs": len(rows), "median_ratio": ratio, "ratio_target": RATIO_TARGET, "within_target": bool(ratio <= RATIO_TARGET),
            "median_ratio_without_offset": float(np.median([r["ratio_without_offset"] for r in rows]))}


def earns(with_effect: dict, without: dict) -> dict:
    """Does an added effect earn its parameters on held-out runs? Both tables over the same runs."""
    a = np.array([row["held_out_rms"] for row in with_effect["runs"]])
    b = np.array([row["held_out_rms"] for row in without["runs"]])
    folds = int(np.sum(a < b))
    gain = 1.0 - float(np.median(a)) / max(float(np.median(b)), 1e-12)
    ok = folds >= EARN_FOLDS * a.size and gain >= EARN_GAIN
    return {"earned": bool(ok), "runs_improved": folds, "runs": int(a.size), "median_gain": gain,
            "median_held_out_rms_with": float(np.median(a)), "median_held_out_rms_without": float(np.median(b)),
            "rule": f"held-out error lower in >= {EARN_FOLDS:.0%} of the runs and its median lower by >= {EARN_GAIN:.0%}"}


def holdout_words(table: dict, seal: str) -> str:
    """One sentence for the explanation."""
    rows = table["runs"]
    worst = max(rows, key=lambda r: r["ratio"])
    return (f" Out of sample (each pressure predicted by the law fitted on the others): median held-out error "
            f"{fmt_si(table['median_held_out_rms'], 'N')} against {fmt_si(table['median_in_sample_rms'], 'N')} in sample "
            f"(median ratio {table['median_ratio']:.2f}, target \u2264 {table['ratio_target']:g}; worst "
            f"{worst['ratio']:.2f} at {fmt_si(worst['pressure_gauge'], 'Pa')} gauge); the held-out runs' own force zeros "
            f"differ from the bias the others give by up to {fmt_si(max(abs(r['held_out_offset']) for r in rows), 'N')} "
            f"(a bench finding: the sensor zero moves between runs of {seal}, not friction physics); without each "
            f"run's own offset the median ratio is {table['median_ratio_without_offset']:.2f}.")




def _applies(effect, law: str, runs) -> bool:
    """Can ``effect`` be added to ``law`` and be refitted in every fold?

    The pressure shapes add a third pressure parameter (n to F_C0 and k_p; c2 to c0 and c1): a fold
    refits the law on the other runs, so it needs three distinct pressures among them.
    """
    from compliance.diagnosis.friction_bench.fit import PRESSURE_EFFECT

    terms = CandidateSet.parse(law).terms
    if effect.name in terms:
        return False
    pressures = np.unique(np.round([r.pressure / MIN_PRESSURE_STEP for r in runs]))
    if effect is NONLINEAR_PRESSURE:
        return PRESSURE_EFFECT in terms and pressures.size >= MIN_RUNS + 1
    if effect is PRESSURE_FORCE:
        return pressures.size >= MIN_RUNS + 1
    return True


def prove_out_of_sample(runs, fits: dict, law: str, try_effects: bool, *, jobs: int | None = None) -> dict:
    """The held-out table of ``law`` and, when ``try_effects``, which declared bench effects earn their place.

    The bench effects (``fit.BENCH_EFFECTS``: nonlinear_pressure_friction, pressure_force_curvature,
    friction_along_stroke, friction_drift, in that order) are tried one after another on the law kept so far;
    one is kept when it earns its parameters on held-out runs (``earns``) *and* lowers the BIC by
    ``selection.SIGNIFICANCE`` over all runs.

    Returns
    -------
    dict
        ``holdout`` (table of the law finally kept, or None with fewer than ``MIN_RUNS`` runs),
        ``effects`` (per effect tried: its held-out comparison, ``delta_bic``, ``kept``, fitted
        parameters and table), ``position`` (the position effect's entry, or None) and ``law`` (the
        law kept; its LawFit is in ``fits``, the effects not kept are removed from it).
    """
    from compliance.diagnosis.friction_bench.fit import BENCH_EFFECTS, law_scores
    from compliance.diagnosis.servo.selection import SIGNIFICANCE

    held = held_out_fits(runs, fits[law], jobs=jobs)
    if held is None:
        return {"holdout": None, "effects": [], "position": None, "law": law}
    table = holdout_table(runs, fits[law], held)
    tried = []
    for effect in (BENCH_EFFECTS if try_effects else ()):
        if not _applies(effect, law, runs):
            continue
        name = CandidateSet.parse(law).plus(effect.name).name if law != "baseline" else effect.name
        fits[name] = fit_law(runs, name, start_from(fits[law].params))
        other = holdout_table(runs, fits[name], held_out_fits(runs, fits[name], jobs=jobs))
        scores = law_scores(fits, fits[law].n)
        trial = {"effect": effect.name, "candidate": name, **earns(other, table), "holdout": other,
                 "delta_bic": json_number(scores[law].bic - scores[name].bic),
                 "parameters": {q.name: fits[name].params[q.name] for q in effect.params}}
        if effect is POSITION_FRICTION:
            trial["parameters"]["reference_position"] = fits[name].params["reference_position"]
        if effect is NONLINEAR_PRESSURE:
            trial["parameters"]["reference_pressure"] = fits[name].params["reference_pressure"]
        trial["kept"] = bool(trial["earned"] and scores[law].bic - scores[name].bic >= SIGNIFICANCE)
        if trial["kept"]:
            table, law = other, name
        else:  # not a candidate of the ranking: its held-out comparison is reported under ``effects``
            fits.pop(name)
        tried.append(trial)
    position = next((t for t in tried if t["effect"] == POSITION_FRICTION.name), None)
    return {"holdout": table, "effects": tried, "position": position, "law": law}


def effect_words(tried: list) -> str:
    """One sentence per declared bench effect tried: did it earn its parameters on held-out runs?"""
    out = ""
    for t in tried:
        meaning = BENCH_MEANINGS[t["effect"]]
        verdict = "kept" if t["kept"] else ("not kept (BIC)" if t["earned"] else "not kept")
        out += (f" {meaning[0].upper() + meaning[1:]}, a declared bench effect: median held-out error "
                f"{fmt_si(t['median_held_out_rms_without'], 'N')} without it, {fmt_si(t['median_held_out_rms_with'], 'N')} "
                f"with it, lower in {t['runs_improved']} of {t['runs']} held-out runs: {verdict} (rule: {t['rule']}).")
    return out


__all__ = ["holdout_table", "held_out_fits", "earns", "holdout_words", "prove_out_of_sample", "effect_words", "MIN_RUNS", "RATIO_TARGET"]
