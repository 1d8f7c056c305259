"""Out-of-sample proof of a seal's friction law: fit on the other pressures, predict the one left out.

For a seal with runs at three or more pressures, each run in turn is held out: the law is
refitted (from the all-runs optimum) on the other runs and predicts the held-out run sample by
sample. Per run the table gives

- ``in_sample_rms``: the RMS error of the law fitted with every run, on this run [N];
- ``held_out_rms``: the RMS error of the law fitted without this run, on this run [N];
- ``held_out_offset``: the mean of that error: the run's own force zero relative to the
  bias line the other runs give (a bench finding, not physics: a sensor zero that moves
  between runs), and ``held_out_rms_without_offset`` with it removed;
- ``in_sample_offset``: the run's own mean error under the all-runs law: its run-to-run
  offset (a bench finding), and ``in_sample_rms_without_offset``;
- ``noise_floor``: the force sensor's noise [N];
- ``ratio`` (held-out / in-sample) and ``ratio_without_offset`` (both with the run's own
  offset removed: the friction law's prediction alone).

``median_ratio`` (median over the runs of held-out / in-sample) is the proof asked for: a law
that only describes the runs it saw degrades far more out of sample. An added effect is kept
only when it *earns its parameters on held-out runs* (``earns``): it lowers the held-out error
of at least ``EARN_FOLDS`` of the runs and the median held-out error by ``EARN_GAIN``.
The folds run on the shared executor (``processes.map_tasks``).
"""

from __future__ import annotations

import numpy as np

from compliance.files.jsonable import json_number
from compliance.diagnosis.friction_bench.fit import LawFit, fit_law, predict, start_from
from compliance.diagnosis.friction_bench.position import POSITION_FRICTION
from compliance.units.formatting import fmt_si
from compliance.diagnosis.verdicts.candidate_set import CandidateSet

MIN_RUNS = 3  # fit on at least two pressures, predict a third
RATIO_TARGET = 1.5  # median held-out error within this multiple of the in-sample error (our target)
EARN_GAIN = 0.05  # an added effect must lower the median held-out error by 5 % ... (our choice)
EARN_FOLDS = 0.75  # ... and the held-out error of at least 3 runs in 4 (our choice)


def _fold(context, item) -> np.ndarray:
    """Held-out residual [N] of run ``i`` under the law refitted on the other runs."""
    runs, name, start = context
    i = item
    fit = fit_law([r for j, r in enumerate(runs) if j != i], name, start)
    r = runs[i]
    return (r.friction - predict(r, fit))[r.valid]


def held_out_residuals(runs, full: LawFit, *, jobs: int | None = None, scheduler: str | None = None) -> list | None:
    """Each run's residual [N] under the law ``full.name`` refitted without it (None: fewer than ``MIN_RUNS`` runs)."""
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
    for r, ins, h in zip(runs, full.residuals, held):
        off, ioff = float(np.mean(h)), float(np.mean(ins))
        rows.append({"run": r.name, "pressure_gauge": json_number(r.pressure),
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
            "unit": "N"}


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
            f"differ from the others' bias line by up to {fmt_si(max(abs(r['held_out_offset']) for r in rows), 'N')} "
            f"(a bench finding: the sensor zero moves between runs of {seal}, not friction physics); without each "
            f"run's own offset the median ratio is {table['median_ratio_without_offset']:.2f}.")




def prove_out_of_sample(runs, fits: dict, law: str, try_position: bool, *, jobs: int | None = None) -> dict:
    """The held-out table of ``law`` and, when ``try_position``, whether ``position_dependent_friction`` earns its place.

    Returns
    -------
    dict
        ``holdout`` (table of the law finally kept, or None with fewer than ``MIN_RUNS`` runs),
        ``position`` (the added effect's held-out comparison, its fitted shape and table, or None)
        and ``law`` (the law kept; its LawFit is added to ``fits`` when it is the new one).
    """
    from compliance.diagnosis.friction_bench.fit import POSITION_EFFECT

    held = held_out_residuals(runs, fits[law], jobs=jobs)
    if held is None:
        return {"holdout": None, "position": None, "law": law}
    table = holdout_table(runs, fits[law], held)
    position = None
    if try_position and POSITION_EFFECT not in CandidateSet.parse(law).terms:
        name = CandidateSet.parse(law).plus(POSITION_EFFECT).name if law != "baseline" else POSITION_EFFECT
        fits[name] = fit_law(runs, name, start_from(fits[law].params))
        other = holdout_table(runs, fits[name], held_out_residuals(runs, fits[name], jobs=jobs))
        position = {"candidate": name, **earns(other, table), "holdout": other}
        position["parameters"] = {q: fits[name].params[q] for q in ("position_gradient", "position_curvature", "reference_position")}
        if position["earned"]:
            table, law = other, name
        else:  # not a candidate of the ranking: its held-out comparison is reported under ``position``
            fits.pop(name)
    return {"holdout": table, "position": position, "law": law}


def position_words(position: dict | None) -> str:
    """One sentence on whether ``position_dependent_friction`` earned its parameters on held-out runs."""
    if not position:
        return ""
    verdict = "kept" if position["earned"] else "not kept"
    return (f" {POSITION_FRICTION.meaning[0].upper() + POSITION_FRICTION.meaning[1:]} , a declared bench effect: median "
            f"held-out error {fmt_si(position['median_held_out_rms_without'], 'N')} without it, "
            f"{fmt_si(position['median_held_out_rms_with'], 'N')} with it, lower in {position['runs_improved']} of "
            f"{position['runs']} held-out runs: {verdict} (rule: {position['rule']}).")


__all__ = ["holdout_table", "held_out_residuals", "earns", "holdout_words", "prove_out_of_sample", "position_words", "MIN_RUNS", "RATIO_TARGET"]
