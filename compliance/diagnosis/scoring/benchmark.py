"""The diagnosis benchmark: generated concealed cases, null cases and miscalibrations, scored.

``run_benchmark`` generates the cases (``scoring.concealed_cases``), diagnoses each against the nominal
plant and scores:

- top-1 accuracy on effect cases (the winning explanation names the true effect);
- null accuracy (null cases called ``no_mismatch``);
- miscalibration accuracy (``parameters_only`` with the miscalibrated parameter refitted);
- the confusion matrix (rows: truth; columns: what the diagnosis said);
- the residual reduction of each correct case on the signal the effect shows in most
  (before/after RMS of the full closed-loop replay; "halved" when <= 0.5);
- the parameter recovery error of each correct case: |fitted - true| / |true| of the
  effect's main (first declared) parameter.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from compliance.model.config import PlantConfig
from compliance.effects import EFFECTS
from compliance.diagnosis.servo.candidates import FRICTION_LEVEL
from compliance.diagnosis.scoring.concealed_cases import MISCALIBRATIONS, Case, effect_case, miscalibration_case, null_case
from compliance.diagnosis.scoring.practice_score import practice_correct
from compliance.diagnosis.verdicts.candidate_set import CandidateSet
from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict


@dataclass
class CaseResult:
    """Outcome of one benchmark case (plain data, JSON-ready)."""

    kind: str
    truth: str
    predicted: str
    verdict: str
    correct: bool
    seed: int
    operating_point: dict
    true_params: dict
    fitted_params: dict = field(default_factory=dict)
    main_error: float | None = None
    reduction: float | None = None  # after/before RMS of the full closed-loop replay on reduction_signal
    reduction_signal: str | None = None
    reduction_objective: float | None = None  # the same on the re-synchronised replay the fits minimise
    effective_error: float | None = None  # the effect's declared lumped combination (e.g. total lag): relative error
    seconds: float = 0.0
    simulations: int = 0
    visibility: dict = field(default_factory=dict)
    runner_up: str | None = None
    visible: bool = True
    ambiguous_with_truth: bool = False  # called ambiguous with the truth among the explanations named (not a hit)


def predicted_label(diag) -> str:
    """What a diagnosis said, as a confusion-matrix column label."""
    if diag.verdict == DiagnosisVerdict.MISSING_PHYSICS:
        return CandidateSet.parse(diag.winner).first
    if diag.verdict == DiagnosisVerdict.PARAMETERS_ONLY:
        return DiagnosisVerdict.PARAMETERS_ONLY
    if diag.verdict == DiagnosisVerdict.NO_MISMATCH:
        return "none"
    if diag.verdict == DiagnosisVerdict.AMBIGUOUS:
        return DiagnosisVerdict.AMBIGUOUS  # its own column: not a hit, not "unexplained" either
    if diag.verdict == DiagnosisVerdict.INSTRUMENTATION:
        return DiagnosisVerdict.INSTRUMENTATION  # a logger or transducer finding: never a plant effect
    return DiagnosisVerdict.UNEXPLAINED


def _main_error(case: Case, diag) -> tuple[dict, float | None]:
    if diag.winner is None or diag.winner not in diag.fits:
        return {}, None
    fit = diag.fits[diag.winner]
    fitted = {fp.key: v for fp, v in zip(fit.params, fit.values)}
    if case.kind == "effect":
        main = EFFECTS[case.truth].params[0].name
        key = f"{case.truth}.{main}"
        if key in fitted and case.params.get(main):
            return fitted, abs(fitted[key] - case.params[main]) / abs(case.params[main])
    if case.kind == "miscalibration":
        key = case.truth
        if key in fitted:
            return fitted, abs(fitted[key] - case.params[key]) / abs(case.params[key])
    return fitted, None


def effective_error(truth: str, true_params: dict, fitted: dict) -> float | None:
    """Relative error of the identifiable combination of a valley-prone effect (None for others)."""
    lumped = EFFECTS[truth].lumped if truth in EFFECTS else None
    if lumped is None:
        return None
    f = lumped.of
    got = {k.split(".", 1)[1]: v for k, v in fitted.items() if k.startswith(truth + ".")}
    try:
        t, g = f(true_params), f(got)
    except KeyError:
        return None
    return abs(g - t) / abs(t)


def _reduction(case: Case, diag) -> tuple[float | None, str | None, float | None]:
    """After/before RMS on the signal the effect shows in most (among its declared signals)."""
    if diag.fit_after is None:
        return None, None, None
    signals = EFFECTS[case.truth].signals if case.kind == "effect" else tuple(diag.fit_before)
    cand = [s for s in signals if s in diag.fit_before]
    if not cand:
        return None, None, None
    s = max(cand, key=lambda k: diag.objective_before[k])
    b, a = diag.fit_before[s]["rms"], diag.fit_after[s]["rms"]
    ob, oa = diag.objective_before[s], (diag.objective_after or {}).get(s)
    return (a / b if b > 0 else None), s, (oa / ob if oa is not None and ob > 0 else None)


def score_case(case: Case, diag) -> CaseResult:
    """Score one diagnosis against its case's truth."""
    label = predicted_label(diag)
    if case.kind == "effect":
        correct = label == case.truth
    elif case.kind == "null":
        correct = diag.verdict == DiagnosisVerdict.NO_MISMATCH
    else:
        fit = diag.fits.get(diag.winner) if diag.winner else None
        keys = {fp.key for fp in fit.params} if fit is not None else set()
        correct = diag.verdict == DiagnosisVerdict.PARAMETERS_ONLY and (case.truth in keys or (case.truth == FRICTION_LEVEL and FRICTION_LEVEL in keys))
    fitted, err = _main_error(case, diag)
    _, amb = practice_correct(diag, [case.truth] if case.kind != "null" else [])
    red, sig, red_obj = _reduction(case, diag) if correct and case.kind != "null" else (None, None, None)
    return CaseResult(
        kind=case.kind, truth=case.truth, predicted=label, verdict=diag.verdict, correct=bool(correct),
        seed=int(case.operating_point.get("seed", 0)), operating_point=dict(case.operating_point),
        true_params={k: float(v) for k, v in case.params.items()}, fitted_params={k: float(v) for k, v in fitted.items()},
        main_error=err, reduction=red, reduction_signal=sig, reduction_objective=red_obj,
        effective_error=effective_error(case.truth, case.params, fitted) if correct and case.kind == "effect" else None,
        seconds=diag.seconds, simulations=diag.simulations,
        visibility=dict(case.visibility), runner_up=diag.runner_up, visible=case.visible, ambiguous_with_truth=bool(amb),
    )


def case_plan(effects, cases: int, seed: int, *, null: bool = True, miscalibrations: bool = True) -> list[tuple]:
    """The list of (kind, truth, seed) to generate (deterministic for a seed)."""
    plan = []
    k = 0
    for e in effects:
        for _ in range(cases):
            plan.append(("effect", e, seed + k))
            k += 1
    if null:
        for _ in range(cases):
            plan.append(("null", "none", seed + k))
            k += 1
    if miscalibrations:
        for i, key in enumerate(MISCALIBRATIONS):
            for _ in range(max(1, cases // 2)):
                plan.append(("miscalibration", key, seed + k))
                k += 1
    return plan


def make_case(cfg: PlantConfig, kind: str, truth: str, seed: int) -> Case:
    """Generate one planned case."""
    if kind == "effect":
        return effect_case(cfg, truth, seed)
    if kind == "null":
        return null_case(cfg, seed)
    return miscalibration_case(cfg, truth, seed)


def _bench_context(cfg_text: str, library, diag_jobs: int) -> dict:
    """What every case of a worker shares: the plant (built once per worker process), the library, the fit processes."""
    import tomllib

    from compliance.model.config import plant_from_dict

    return {"cfg": plant_from_dict(tomllib.loads(cfg_text), "<benchmark plant>"), "library": library, "jobs": diag_jobs}


def _run_one(context, item) -> CaseResult:
    from compliance.diagnosis.servo.diagnose import diagnose

    from compliance.errors import GovcheckError

    kind, truth, seed = item
    bench = context.get()
    cfg = bench["cfg"]
    try:
        case = make_case(cfg, kind, truth, seed)
        diag = diagnose(cfg, case.frame, case.meta, effects=bench["library"], jobs=bench["jobs"])
    except GovcheckError as exc:  # a case that cannot be generated or diagnosed counts as a failure, with its reason
        return CaseResult(kind=kind, truth=truth, predicted="error", verdict=f"error: {exc}", correct=False, seed=seed,
                          operating_point={}, true_params={})
    return score_case(case, diag)


def run_benchmark(cfg: PlantConfig, *, effects=None, cases: int = 3, seed: int = 1, library=None, jobs: int = 1,
                  null: bool = True, miscalibrations: bool = True, progress=None, scheduler: str | None = None) -> dict:
    """Generate and diagnose the benchmark cases; return per-case rows and the summary.

    Parameters
    ----------
    cfg : PlantConfig
        Nominal plant (cases are generated from it, and diagnosed against it).
    effects : iterable of str, optional
        Effects to generate cases of (default: all declared).
    cases : int
        Cases per effect (and null cases; miscalibration cases: cases // 2 per parameter, at least 1).
    seed : int
    library : iterable of str, optional
        Candidate effects the diagnosis may choose from (default: all).
    jobs : int
        Cases diagnosed in parallel (each diagnosis runs serially).
    scheduler : str, optional
        Dask scheduler for the cases (``local:N`` or ``tcp://host:port``; ``processes.map_tasks``).
    null, miscalibrations : bool
        Include null / miscalibration cases.
    progress : callable, optional
        Called with each CaseResult as it completes.
    """
    from compliance.model.config import plant_to_toml
    from compliance.processes import PerProcess, map_tasks

    effects = list(EFFECTS) if effects is None else list(effects)
    plan = case_plan(effects, cases, seed, null=null, miscalibrations=miscalibrations)
    t0 = time.perf_counter()
    payload = (plant_to_toml(cfg), None if library is None else list(library), 1)
    results, stats = map_tasks(_run_one, PerProcess(_bench_context, *payload), plan, workers=jobs, scheduler=scheduler,
                               progress=False, label="cases", retries=0,
                               on_result=(lambda i, r: progress(r)) if progress else None)
    stats.raise_if_failed()
    return {"cases": [r.__dict__ for r in results], "summary": summarise(results, effects), "seconds": time.perf_counter() - t0,
            "seed": seed, "cases_per_effect": cases}


def summarise(results: list[CaseResult], effects) -> dict:
    """Accuracies, confusion matrix, improvement and recovery statistics."""
    # a case whose truth could not be made visible while concealed tests nothing: it is listed, not scored
    hidden = [r for r in results if not r.visible and r.kind != "null"]
    eff = [r for r in results if r.kind == "effect" and r.visible]
    nul = [r for r in results if r.kind == "null"]
    mis = [r for r in results if r.kind == "miscalibration" and r.visible]
    labels = list(effects) + ["none", DiagnosisVerdict.PARAMETERS_ONLY, DiagnosisVerdict.AMBIGUOUS, DiagnosisVerdict.UNEXPLAINED,
                              "error"]
    truths = list(effects) + (["none"] if nul else []) + sorted({r.truth for r in mis})
    confusion = {t: {} for t in truths}
    for r in results:
        if not r.visible and r.kind != "null":
            continue
        row = confusion.setdefault(r.truth, {})
        row[r.predicted] = row.get(r.predicted, 0) + 1
    red = [r.reduction for r in eff if r.correct and r.reduction is not None]
    red_obj = [r.reduction_objective for r in eff if r.correct and r.reduction_objective is not None]
    err = [r.main_error for r in eff if r.correct and r.main_error is not None]
    per_effect = {}
    for e in effects:
        rs = [r for r in eff if r.truth == e]
        if rs:
            errs = [r.main_error for r in rs if r.correct and r.main_error is not None]
            eff_errs = [r.effective_error for r in rs if r.effective_error is not None]
            per_effect[e] = {"cases": len(rs), "correct": sum(r.correct for r in rs),
                             "median_main_error": float(np.median(errs)) if errs else None,
                             "median_effective_error": float(np.median(eff_errs)) if eff_errs else None}

    def frac(rs):
        return sum(r.correct for r in rs) / len(rs) if rs else None

    return {
        "top1_accuracy": frac(eff),
        "null_accuracy": frac(nul),
        "miscalibration_accuracy": frac(mis),
        "confusion": confusion,
        "labels": labels,
        "median_reduction": float(np.median(red)) if red else None,
        "halved_fraction": (sum(x <= 0.5 for x in red) / len(red)) if red else None,
        "median_reduction_objective": float(np.median(red_obj)) if red_obj else None,
        "halved_fraction_objective": (sum(x <= 0.5 for x in red_obj) / len(red_obj)) if red_obj else None,
        "median_main_error": float(np.median(err)) if err else None,
        "within_25_percent": (sum(x <= 0.25 for x in err) / len(err)) if err else None,
        "per_effect": per_effect,
        "median_seconds": float(np.median([r.seconds for r in results])) if results else None,
        "max_seconds": float(max((r.seconds for r in results), default=0.0)),
        "n_cases": len(results),
        "ambiguous_with_truth": sum(r.ambiguous_with_truth for r in eff + mis),
        "not_visible": [{"kind": r.kind, "truth": r.truth, "seed": r.seed, "predicted": r.predicted} for r in hidden],
    }


def format_summary(report: dict) -> str:
    """Human-readable benchmark summary with the confusion matrix."""
    s = report["summary"]
    conf = s["confusion"]
    cols = [c for c in s["labels"] if any(c in row for row in conf.values())]
    short = {c: c[:10] for c in cols}
    lines = ["confusion matrix (rows: truth, columns: diagnosis)"]
    lines.append(f"{'':28s}" + "".join(f"{short[c]:>11s}" for c in cols))
    for t, row in conf.items():
        if not row:
            continue
        lines.append(f"{t[:28]:28s}" + "".join(f"{row.get(c, 0) or '.':>11}" for c in cols))

    def pct(x):
        return "n/a" if x is None else f"{100*x:.0f} %"

    lines.append("")
    lines.append(f"top-1 accuracy (effect cases):      {pct(s['top1_accuracy'])}")
    lines.append(f"null cases called no_mismatch:      {pct(s['null_accuracy'])}")
    lines.append(f"miscalibrations called parameters:  {pct(s['miscalibration_accuracy'])}")
    if s.get("ambiguous_with_truth"):
        lines.append(f"not hits, called ambiguous with the truth among the explanations named: {s['ambiguous_with_truth']}")
    mr = s["median_reduction"]
    mo = s.get("median_reduction_objective")
    lines.append(f"median residual after/before:       {'n/a' if mr is None else f'{mr:.3f}'} full closed-loop replay "
                 f"(halved in {pct(s['halved_fraction'])} of correct cases); {'n/a' if mo is None else f'{mo:.3f}'} "
                 f"re-synchronised replay (halved in {pct(s.get('halved_fraction_objective'))})")
    me = s["median_main_error"]
    lines.append(f"median main-parameter error:        {'n/a' if me is None else f'{100*me:.1f} %'} (within 25 % in {pct(s['within_25_percent'])})")
    lines.append(f"time per case: median {s['median_seconds']:.1f} s, max {s['max_seconds']:.1f} s; {s['n_cases']} cases in {report['seconds']:.0f} s")
    if s.get("not_visible"):
        lines.append(f"not scored ({len(s['not_visible'])}): no concealed draw was visible above the noise: "
                     + ", ".join(f"{h['truth']} (seed {h['seed']}, said {h['predicted']})" for h in s["not_visible"]))
    return "\n".join(lines)


# ------------------------------------------------------------------------ recordings with answers
# parameter names an ANSWERS.json may use -> fitted keys (the practice emulator's names: ``Param.aliases``)
ANSWER_ALIASES = {alias: f"{name}.{p.name}" for name, eff in EFFECTS.items() for p in eff.params for alias in p.aliases}


def _practice_row(context, item) -> dict:
    """Diagnose one practice recording and score it against its answer."""
    from compliance.diagnosis.scoring.practice_score import answer_in_si, main_parameter, practice_correct
    from compliance.diagnosis.servo.diagnose import diagnose
    from compliance.recordings.reader import read_recording

    cfg, library, jobs = context
    name, ans, path = item
    frame, meta = read_recording(path)
    d = diagnose(cfg, frame, meta, effects=library, jobs=jobs)
    truth = list(ans.get("effects") or [])
    correct, ambiguous_ok = practice_correct(d, truth, ans.get("accept"))
    fitted = {}
    if d.winner:
        fit = d.fits[d.winner]
        fitted = {fp.key: v for fp, v in zip(fit.params, fit.values)}
    params = {}
    for alias, value in (ans.get("parameters") or {}).items():
        key = ANSWER_ALIASES.get(alias, alias)
        got = fitted.get(key)
        value = answer_in_si(alias, value)
        params[alias] = {"true": value, "fitted": got, "error": None if got is None else abs(got - value) / abs(value)}
    return {"name": name, "truth": ", ".join(truth) or "none", "verdict": d.verdict, "winner": d.winner,
            "correct": bool(correct), "ambiguous_with_truth": ambiguous_ok, "ambiguity": list(d.ambiguous),
            "signals_left": dict(d.signals_left), "parameters": params, "seconds": d.seconds,
            "simulations": d.simulations, "explanation": d.explanation, "fit_before": d.fit_before, "fit_after": d.fit_after, "main": main_parameter(d, truth, params),
            # the verdict's own yardstick (re-synchronised replay, x floor), every fitted value, the lag scan
            "objective_before": d.objective_before, "objective_after": d.objective_after, "fitted": fitted,
            "split": d.split}


def run_practice(directory, cfg: PlantConfig, *, library=None, jobs: int = 1, progress=None,
                 scheduler: str | None = None) -> dict:
    """Diagnose every recording of a directory and score it against the directory's ANSWERS.json.

    ANSWERS.json maps a recording name (file name without ``.csv``/``.csv.gz``) to
    ``{"effects": [...], "parameters": {name: value}}``; an empty effect list means "no effect"
    (the right verdict is ``no_mismatch``; ``parameters_only`` is also accepted as "no missing physics").
    Locally the recordings are diagnosed one after the other, each on ``jobs`` processes; with a Dask
    ``scheduler`` the recordings run side by side, each diagnosis in one process.
    """
    import json
    from pathlib import Path

    from compliance.errors import InputError
    from compliance.processes import map_tasks

    folder = Path(directory)
    answers_path = folder / "ANSWERS.json"
    if not answers_path.is_file():
        raise InputError(f"{folder}: no ANSWERS.json to score against")
    try:
        answers = json.loads(answers_path.read_text())
    except json.JSONDecodeError as exc:
        raise InputError(f"{answers_path}: not valid JSON ({exc})") from None
    items = []
    for name, ans in sorted(answers.items()):
        files = [p for p in (folder / f"{name}.csv.gz", folder / f"{name}.csv") if p.is_file()]
        if not files:
            raise InputError(f"{answers_path}: '{name}' has no {name}.csv(.gz) beside it")
        items.append((name, ans, files[0]))
    rows, stats = map_tasks(_practice_row, (cfg, library, jobs if scheduler is None else 1), items, workers=1,
                            scheduler=scheduler, progress=False, label="recordings", retries=0,
                            on_result=(lambda i, row: progress(row)) if progress is not None else None)
    stats.raise_if_failed()
    mains = [r["main"] for r in rows if r["main"]]
    return {"recordings": rows, "correct": sum(r["correct"] for r in rows), "main_scored": len(mains),
            "main_within_25": sum(m["within_25"] for m in mains),
            "main_split_open_interval_contains_truth": sum(not m["within_25"] and m.get("split_pinned") is False
                                                           and m.get("interval_contains_truth", False) for m in mains)}
