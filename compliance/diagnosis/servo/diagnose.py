"""The diagnosis of a servo recording: replay, locate, fit every candidate, select, explain.

``diagnose(cfg, frame, meta)`` runs the whole chain on one closed-loop (or open-loop)
recording of the servo and returns a ``Diagnosis`` whose ``to_dict()`` is the JSON of
docs/diagnosis-schema.md. The friction bench has its own chain (``friction_bench.diagnose``).

Stages:
1. nominal replay (re-synchronised segments, matched noise) and noise floors;
2. located windows of the nominal residual and their regimes (compliance.validation.locate);
3. in parallel: the recalibration of base parameters (greedy forward selection) and one fit
   per effect (coarse grid, then bounded least squares), likely effects first;
4. if the best single explanation leaves a clear excess and the recalibration found
   something, the best effects are refitted together with the recalibrated parameters;
5. scores (BIC/AIC on normalised residuals), verdict, windows agreement, explanation;
6. full closed-loop replays of the nominal and of the winner for the before/after figures.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace as dc_replace

import numpy as np

from compliance.model.config import PlantConfig
from compliance.model.parameters import apply
from compliance.effects import EFFECTS
from compliance.errors import InputError, SimulationError
from compliance.diagnosis.servo.candidates import Candidate, base_params, effect_candidate, signature_order
from compliance.diagnosis.servo.fit import SINGLE_SCREEN_SHARE, FitContext, FitResult, replays_bound, screen_level
from compliance.diagnosis.servo.fitted_model import fitted_plant, save_fitted
from compliance.diagnosis.servo.effect_sets import CANDIDATES_PER_ROUND, MAX_EFFECTS, adds_enough, contributions, full_name, prune
from compliance.diagnosis.evidence.discriminating_test import design_test
from compliance.diagnosis.evidence.empirical_force import empirical_term
from compliance.diagnosis.servo.instrument_candidates import PREFIX, instrument_candidates, instrument_verdict, instrumented
from compliance.diagnosis.verdicts.candidate_set import is_instrument
from compliance.diagnosis.servo.lag_split import adopted_fit, split_scan
from compliance.diagnosis.servo.friction_form import OPTION as FORM_OPTION, form_after_effects, friction_form_check
from compliance.validation.replay import ReplaySetup, run_replay
from compliance.diagnosis.evidence.residuals import UNITS, null_recording, own_floor_objective, signal_fit
from compliance.diagnosis.servo.selection import (AMBIGUOUS_BIC, EXPLAINED_ENOUGH, NOISE_TOLERANCE, RESIDUAL_LIMIT, ambiguity_set, honest,
                                         score_all, signals_left, verdict)
from compliance.diagnosis.servo.report_data import SCHEMA, Diagnosis
from compliance.diagnosis.evidence.locate_misfit import event_rms, mask_agreement, where_words
from compliance.diagnosis.servo.parallel_fits import (ExtendSet, FitEffect, FitWithBase, RecalibrateBase, RefitSet, ScreenAddition,
                                                     ValleyPoint)
from compliance.diagnosis.verdicts.candidate_set import BASE, CandidateSet
from compliance.diagnosis.verdicts.verdict import EXPLAINED, INCOMPLETE, DiagnosisVerdict
from compliance.diagnosis.servo.stage import Stage, check_effects, first_fits, prepare_recording, record
from compliance.processes import available_cores, dask_session

COMBINE_LEVEL = 3.0  # chi2/N of the best single explanation above which effects are refitted with the recalibration
COMBINE_TOP = 1  # how many effects are refitted with the recalibration


def _based_search(cfg: PlantConfig, frame, meta: dict, stride: int, jobs: int, names, recalibrate: bool, client=None):
    """Stages 1-5 on the friction law's form that fits (servo/friction_form.py): the other form is the base from the start
    when it beats the nominal, or after an incomplete verdict when effects refitted under it beat the declared form."""
    st = prepare_recording(cfg, frame, meta, stride, jobs, client=client)
    form = friction_form_check(st.rc, st.setup, st.model, st.fits["nominal"])
    if form and form["adopted"]:  # the other friction law is the base of the whole search
        cfg = cfg.replace(options={FORM_OPTION: form["adopted"]})
        st = prepare_recording(cfg, frame, meta, stride, jobs, st.sims, client)
        st.rebased = True
    _fit_singles(st, names, recalibrate)
    dec = _decide(st)
    if form and not form["adopted"] and dec["verdict"] in INCOMPLETE:
        form = form_after_effects(form, st.rc, st.setup, st.model, st.fits, jobs, client)
        if form["adopted"]:  # ... and the whole search runs again on it
            cfg = cfg.replace(options={FORM_OPTION: form["adopted"]})
            st = prepare_recording(cfg, frame, meta, stride, jobs, st.sims, client)
            st.rebased = True
            _fit_singles(st, names, recalibrate)
            dec = _decide(st)
    st.sims += form["replays"] if form else 0
    return cfg, st, form, dec


def _run(st: Stage, tasks) -> None:
    tasks = list(tasks)
    record(st, tasks, st.run_fits(tasks))


def _fit_singles(st: Stage, names, recalibrate: bool) -> None:
    """Stages 3-4: the recalibration, one fit per effect, and the best effect with the recalibration."""
    n = st.model.size
    chi2 = st.fits["nominal"].chi2
    excess = {s: v * v - 1.0 for s, v in st.nominal_rms.items()}
    tasks = []
    # within the floor the verdict is no_mismatch whatever the fits: every candidate is shown at its best grid point
    within = max(_objective(st, "nominal").values(), default=0.0) <= NOISE_TOLERANCE
    bparams = base_params(st.rc) if recalibrate and not within else ()
    if bparams:
        tasks.append(RecalibrateBase(bparams, 2.0 * math.log(n) * max(1.0, chi2 / n)))
    screen = -math.inf if within else screen_level(chi2, n, SINGLE_SCREEN_SHARE)
    fits = [FitEffect(effect_candidate(e), screen) for e in signature_order(names, excess)]
    fits += [FitEffect(c, -math.inf if within else None) for c in instrument_candidates(st.model.signals, st.setup.closed_loop)]
    first_fits(st, tasks + sorted(fits, key=lambda t: -replays_bound(t.candidate)))  # the longest fits first
    base_fit = st.fits.get("base")
    singles = [f for f in st.fits.values() if f.name != "nominal"]
    best = min(singles, key=lambda f: f.chi2, default=None)
    if base_fit is not None and base_fit.k > 0 and best is not None and best.chi2 / n > COMBINE_LEVEL:
        top = sorted((f for f in singles if f.name in EFFECTS), key=lambda f: f.chi2)[:COMBINE_TOP]
        _run(st, [FitWithBase(Candidate(CandidateSet.parse(f.name).plus(BASE).name), f, base_fit) for f in top])


def _search_sets(st: Stage, winner: str) -> list[dict]:
    """Stage 5: greedy forward selection of further effects on what the winner leaves (servo/effect_sets.py)."""
    n = st.model.size
    log = []
    current = st.fits[winner]
    while len(CandidateSet.parse(current.name).effects) < MAX_EFFECTS:
        if not signals_left(_objective(st, current.name)):
            break
        have = set(CandidateSet.parse(current.name).effects)
        singles = [f for f in st.fits.values() if f.name in EFFECTS and f.name not in have]
        screened = [r for r, _ in st.run_fits([ScreenAddition(current, f) for f in singles])]
        screen = {name: (chi, start) for name, chi, start, _ in screened}
        st.sims += sum(r[3] for r in screened)
        level = screen_level(current.chi2, n)  # an addition whose screen removes too little is not refitted
        order = sorted((f for f in singles if screen[f.name][0] <= level), key=lambda f: screen[f.name][0])
        tasks = [ExtendSet(current, f, screen[f.name][1]) for f in order[:CANDIDATES_PER_ROUND]]
        if not tasks:
            break
        _run(st, tasks)
        c = max(1.0, min(f.chi2 / max(n - f.k, 1) for f in st.fits.values() if math.isfinite(f.chi2)))
        tried = sorted((_extended(st, t.current, t.single) for t in tasks), key=lambda f: f.chi2)
        best = tried[0]
        times = np.tile(st.setup.time[st.model.index], len(st.model.signals))  # residuals are signal blocks
        vecs = (st.vecs[current.name], st.vecs[best.name], times) if current.name in st.vecs else None
        ok, why = adds_enough(best, current, n, math.log(n), c, vecs)
        log.append({"round": len(have) + 1, "tried": [f.name for f in tried], "best": best.name, "kept": ok, "why": why})
        if not ok:
            break
        current = best
    return log


def _extended(st: Stage, current: FitResult, single: FitResult) -> FitResult:
    return st.fits[full_name(CandidateSet.parse(current.name).effects + CandidateSet.parse(single.name).effects, current.params)]


def _objective(st: Stage, name: str) -> dict:
    """Signal -> normalised RMS of the re-synchronised replay of candidate ``name``."""
    m = st.model.index.size
    return {s: math.sqrt(st.fits[name].chi2_signal[s] / m) for s in st.model.signals}


def _decide(st: Stage) -> dict:
    """Verdict, winner, ambiguity set, each effect's own contribution (stage 5-6)."""
    n = st.model.size
    scores = score_all(st.fits, n)
    effect_like = [k for k in st.fits if k not in ("nominal", "base") and not is_instrument(k)]
    # "within the floor" on the objective every other verdict is judged on (time-resolved floors,
    # select.NOISE_TOLERANCE), not on the constant floor the JSON reports
    verdict_name, winner, reason = verdict(scores, n, _objective(st, "nominal"), effect_like)
    search = []
    if winner is not None and winner != "base" and verdict_name != DiagnosisVerdict.NO_MISMATCH:
        search = _search_sets(st, winner)
        kept = [r for r in search if r["kept"]]
        winner, pruned = prune(st.fits, kept[-1]["best"] if kept else winner, n, lambda sets: _run(st, [RefitSet(*s) for s in sets]))
        search += pruned
        scores = score_all(st.fits, n)  # the sets tried are candidates too
        if kept:
            explained = scores[winner].explained
            reason = f"{' and '.join(CandidateSet.parse(winner).effects)} together explain {100*explained:.0f} % of the excess residual"
            verdict_name = DiagnosisVerdict.MISSING_PHYSICS if explained >= EXPLAINED_ENOUGH else DiagnosisVerdict.UNEXPLAINED
    verdict_name, winner, reason = instrument_verdict(scores, n, (verdict_name, winner, reason),
                                                      [k for k in st.fits if k.startswith(PREFIX)])
    after = _own_floors(st, winner, verdict_name)
    verdict_name, reason = honest(verdict_name, winner, reason, after)
    objectives = {k: _objective(st, k) for k in st.fits if k != "nominal"}
    plant_scores = {k: v for k, v in scores.items() if not is_instrument(k)}  # instruments were settled by beats()
    settled = (DiagnosisVerdict.NO_MISMATCH, DiagnosisVerdict.INSTRUMENTATION)
    ambiguous = ambiguity_set(plant_scores, winner, objectives) if verdict_name not in settled else []
    if ambiguous and verdict_name in EXPLAINED:
        verdict_name = DiagnosisVerdict.AMBIGUOUS
        reason = (f"{' and '.join(ambiguous)} explain the recording equally well (every signal within "
                  f"{RESIDUAL_LIMIT:g} x its floor, or BIC within {AMBIGUOUS_BIC:g}); another test tells them apart")
    return {"scores": scores, "verdict": verdict_name, "winner": winner, "reason": reason, "search": search,
            "ambiguous": ambiguous, "after": after, "left": signals_left(after if winner else _objective(st, "nominal"))}


def _own_floors(st: Stage, winner: str | None, verdict_name: str) -> dict | None:
    """What the winner leaves, x floor; a complete verdict's leftovers are judged against its own null floors too,
    unless the base is already another friction form (one relaxation of the yardstick at a time: on the pairs
    benchmark, floors from a substitute friction law plus its winner's own passed wrong pairs as complete)."""
    after = _objective(st, winner) if winner else None
    if verdict_name in EXPLAINED and signals_left(after) and winner in st.vecs \
            and not st.rebased:
        w = st.fits[winner]
        try:
            own = own_floor_objective(st.model, apply(st.rc, w.params, w.values), st.setup, st.vecs[winner])
        except (SimulationError, InputError):
            return after
        st.sims += 4  # two null draws, each a recording and its replay
        after = {s: min(v, own.get(s, v)) for s, v in after.items()}
    return after


def _suggest(st: Stage, ambiguous: list) -> dict | None:
    """The discriminating test between the two best explanations of an ambiguous recording."""
    if len(ambiguous) < 2:
        return None
    a, b = st.fits[ambiguous[0]], st.fits[ambiguous[1]]
    load = st.setup.load if not isinstance(st.setup.load, str) else 0.0
    return design_test(apply(st.rc, a.params, a.values), apply(st.rc, b.params, b.values), st.model.floors,
                       x0=st.setup.initial_position, load=float(load), names=(a.name, b.name))


def _window_rows(st: Stage, seg_win) -> list:
    model = st.model
    before_rows = event_rms(st.events, model.recorded, st.nominal_sim, model.floors, model.signals)
    after_rows = event_rms(st.events, model.recorded, seg_win, model.floors, model.signals)
    return [{"index": i, "start": e["start"], "end": e["end"], "duration": e["duration"], "signals": dict(e["signals"]),
             "regimes": list(e["dominant"]), "before": b, "after": a}
            for i, (e, b, a) in enumerate(zip(st.events, before_rows, after_rows))]


def _empirical(st: Stage, dec: dict) -> dict | None:
    """Stage 7: outside the library, the missing force the recording implies (evidence/empirical_force.py)."""
    if dec["verdict"] not in INCOMPLETE:
        return None
    w = dec["winner"]
    cfg = apply(st.rc, st.fits[w].params, st.fits[w].values) if w else st.rc
    try:
        null = null_recording(cfg, st.setup, st.model.sensor_noise)
        return empirical_term(cfg, st.setup, null)
    except (SimulationError, InputError) as exc:
        return {"label": "empirical suggestion, not a declared effect", "words": f"not estimated: {exc}", "terms": []}


def diagnose(cfg: PlantConfig, frame, meta: dict, *, effects=None, jobs: int | None = None, stride: int = 5,
             recalibrate: bool = True, suggest_test: bool = False, scheduler: str | None = None) -> Diagnosis:
    """Diagnose one recording of the servo against a plant configuration.

    Parameters
    ----------
    cfg : PlantConfig
        The nominal plant (effects already switched on in it stay on and are not candidates).
    frame : pandas.DataFrame
        Canonical recording (``compliance.recordings.reader.read_recording``).
    meta : dict
        Its metadata.
    effects : iterable of str, optional
        Candidate effects (default: every declared effect not already on).
    jobs : int, optional
        Worker processes (default: the available cores).
    stride : int
        Residual subsampling (every ``stride``-th sample).
    recalibrate : bool
        Also consider recalibrating base parameters.
    suggest_test : bool
        Design a discriminating test between the winner and the runner-up even when the
        recording tells them apart (an ambiguous recording always gets one).
    scheduler : str, optional
        Dask scheduler (``local:N`` or ``tcp://host:port``) for every fit of the diagnosis, one session
        for the whole run; None: the local pool of ``jobs`` processes.

    Returns
    -------
    Diagnosis

    Raises
    ------
    InputError
        Unknown effect names, a recording the replay cannot use.
    """
    t0 = time.perf_counter()
    jobs = available_cores() if jobs is None else max(1, int(jobs))
    names = check_effects(cfg, effects)
    with dask_session(scheduler) as client:
        cfg, st, form, dec = _based_search(cfg, frame, meta, stride, jobs, names, recalibrate, client)
        return _conclude(cfg, meta, st, form, dec, t0, suggest_test)


def _conclude(cfg: PlantConfig, meta: dict, st: Stage, form, dec: dict, t0: float, suggest_test: bool) -> Diagnosis:
    """Stages 6-7 after the search: the lag split, the figures' full replays, contributions, the suggested test."""
    winner, verdict_name = dec["winner"], dec["verdict"]
    split = _split(st, winner, verdict_name, dec)
    agreement = {k: mask_agreement(st.model, st.nvec, st.vecs[k], st.event_mask) for k in st.fits if k in st.vecs}
    ranked = sorted((k for k in st.fits if k != "nominal"), key=lambda k: (dec["scores"][k].bic, -agreement.get(k, 0.0)))
    runner = (ranked[0] if ranked else None) if winner is None else next(
        (k for k in ranked if k != winner and not CandidateSet.parse(k).same_physics(CandidateSet.parse(winner))), None)
    # full closed-loop replays for the figures a test engineer reproduces
    full = dc_replace(st.setup, resets=np.array([0]))
    full_nom = run_replay(st.rc, full)
    notes = list(st.setup.notes)
    fitted_cfg = full_win = seg_win = None
    if winner is not None:
        w = st.fits[winner]
        wcfg = apply(st.rc, w.params, w.values)
        if verdict_name in (*EXPLAINED, DiagnosisVerdict.PARTIALLY_EXPLAINED, DiagnosisVerdict.AMBIGUOUS,
                            DiagnosisVerdict.INSTRUMENTATION):
            full_win = _safe_replay(wcfg, instrumented(full, w.params, w.values), notes, "full closed-loop replay of the winner")
            fitted_cfg = None if is_instrument(winner) else fitted_plant(cfg, w, meta)
        seg_win = _safe_replay(wcfg, instrumented(st.setup, w.params, w.values), notes, "replay of the winner")
    st.sims += 1 + (full_win is not None) + (seg_win is not None)
    contrib = _contributions(st, winner)  # its replays count in st.sims
    pair = dec["ambiguous"] or ([winner, runner] if suggest_test and winner and runner else [])
    suggested, empirical = _suggest(st, pair), _empirical(st, dec)
    return Diagnosis(
        verdict=verdict_name, reason=dec["reason"], winner=winner, runner_up=runner, fits=st.fits, scores=dec["scores"],
        fit_before=signal_fit(st.model, full_nom), fit_after=signal_fit(st.model, full_win) if full_win is not None else None,
        objective_before=_objective(st, "nominal"), objective_after=dec["after"] if winner else None,
        windows=_window_rows(st, seg_win), floors=dict(st.model.floors), cfg=cfg, fitted_cfg=fitted_cfg,
        recording=st.setup.source, seconds=time.perf_counter() - t0,
        simulations=st.sims + (split["replays"] if split else 0), jobs=st.jobs, notes=notes,
        traces={"time": st.setup.time, "recorded": st.model.recorded, "before": full_nom, "after": full_win,
                "objective_before": st.nominal_sim, "objective_after": seg_win},
        agreement=agreement, located_regimes=where_words(st.events), ambiguous=dec["ambiguous"], signals_left=dec["left"],
        search=dec["search"], contributions=contrib, suggested_test=suggested, empirical=empirical, split=split,
        friction_form=form,
    )


def _split(st: Stage, winner: str | None, verdict_name: str, dec: dict) -> dict | None:
    """Does the recording pin the split of the winner's lag, or its total only (``servo.lag_split.split_scan``)?
    An undetermined split moves to the segments' estimate (the winner's fit, scores and what is left follow)."""
    lag = next((e for e in CandidateSet.parse(winner).effects if EFFECTS[e].lumped is not None), None)
    if lag is None or verdict_name == DiagnosisVerdict.UNEXPLAINED:
        return None
    ctx = FitContext(st.rc, st.setup, st.model)
    fit = st.fits[winner]

    def along(values, limit):  # the scan's points are independent: one task each on the workers
        return [r for r, _ in st.run_fits([ValleyPoint(fit, lag, v, limit) for v in values])]

    sp = split_scan(ctx, fit, lag, st.vecs.get(winner), along)
    moved = adopted_fit(ctx, fit, sp["estimate"]) if sp and sp["estimate"] else None
    if moved is not None:
        st.fits[winner], st.vecs[winner] = moved
        after = _own_floors(st, winner, verdict_name)
        dec.update(scores=score_all(st.fits, st.model.size), after=after, left=signals_left(after))
    return sp and {**sp, "replays": sp["replays"] + (moved is not None)}


def _contributions(st: Stage, winner: str | None) -> dict:
    """Effect -> its own share of the nominal excess in the winning set (switched off alone)."""
    if winner is None or not CandidateSet.parse(winner).effects:
        return {}
    ctx = FitContext(st.rc, st.setup, st.model)
    raw = contributions(ctx, st.fits[winner])
    st.sims += ctx.sims
    excess = max(st.fits["nominal"].chi2 - st.model.size, 1e-12)
    return {e: {"chi2_increase_when_removed": v, "share_of_excess": v / excess} for e, v in raw.items()}


def _safe_replay(cfg: PlantConfig, setup: ReplaySetup, notes: list, what: str):
    """A replay for the figures; a candidate that diverges there is noted, not fatal."""
    try:
        return run_replay(cfg, setup)
    except SimulationError as exc:
        notes.append(f"{what} failed: {exc}")
        return None


__all__ = ["Diagnosis", "diagnose", "save_fitted", "SCHEMA", "UNITS", "NOISE_TOLERANCE"]
