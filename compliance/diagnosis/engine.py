"""The diagnosis of a servo recording: replay, locate, fit every candidate, select, explain.

``diagnose(cfg, frame, meta)`` runs the whole chain on one closed-loop (or open-loop)
recording of the servo and returns a ``Diagnosis`` whose ``to_dict()`` is the JSON of
docs/diagnosis-schema.md. The friction bench has its own chain (``friction_diagnosis``).

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
import os
import time
import tomllib
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace as dc_replace
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from compliance.model.config import PlantConfig, plant_from_dict, plant_to_toml, save_plant
from compliance.effects import EFFECTS
from compliance.errors import InputError, SimulationError
from compliance.diagnosis.candidates import Candidate, apply, base_params, effect_candidate, expand_base, signature_order
from compliance.diagnosis.fit import FitContext, FitResult, fit_candidate, forward_select_base, least_squares_fit
from compliance.diagnosis.replay_fit import ReplaySetup, prepare_replay, replay_config, run_replay
from compliance.diagnosis.residuals import UNITS, build_residual_model, signal_fit, with_fail_level
from compliance.diagnosis.select import NOISE_TOLERANCE, score_all, verdict
from compliance.diagnosis.report_data import SCHEMA, diagnosis_to_dict
from compliance.diagnosis.located import event_rms, locate_mismatch, mask_agreement, where_words

COMBINE_LEVEL = 3.0  # chi2/N of the best single explanation above which effects are refitted with the recalibration
COMBINE_TOP = 1  # how many effects are refitted with the recalibration


@dataclass
class Diagnosis:
    """Result of ``diagnose`` (``to_dict`` gives the documented JSON)."""

    verdict: str
    reason: str
    winner: str | None
    runner_up: str | None
    fits: dict
    scores: dict
    fit_before: dict
    fit_after: dict
    objective_before: dict
    objective_after: dict
    windows: list
    floors: dict
    explanation: str
    cfg: PlantConfig
    fitted_cfg: PlantConfig | None
    recording: str
    seconds: float
    simulations: int
    jobs: int
    notes: list = field(default_factory=list)
    traces: dict = field(default_factory=dict)
    saved_model: str | None = None

    def ranked(self) -> list[str]:
        """Candidate names by BIC, best first (nominal included)."""
        return sorted(self.scores, key=lambda k: self.scores[k].bic)

    def to_dict(self) -> dict:
        """The JSON document of docs/diagnosis-schema.md."""

        return diagnosis_to_dict(self)


# ------------------------------------------------------------------------------- worker side
_WORKER: dict = {}


def _init_worker(toml_text: str, setup: ReplaySetup, model) -> None:
    cfg = plant_from_dict(tomllib.loads(toml_text), "<diagnosis>")
    _WORKER["ctx"] = FitContext(cfg, setup, model)


def _run_task(task):
    """One unit of parallel work: ('base', params) | ('effect', Candidate) | ('combo', Candidate, FitResult)."""
    ctx: FitContext = _WORKER["ctx"]
    kind = task[0]
    if kind == "base":
        penalty = task[2]
        res, log = forward_select_base(ctx, task[1], penalty=penalty)
        res.scan = log
    elif kind == "effect":
        res = fit_candidate(ctx, task[1], None)
    else:  # combination: effect + recalibrated base parameters, from both fits' values
        cand, eff_fit, base_fit = task[1], task[2], task[3]
        params = tuple(eff_fit.params) + tuple(base_fit.params)
        # start exactly at the effect's optimum (base parameters nominal): the combination can only improve on it
        start = list(eff_fit.values) + [fp.nominal for fp in base_fit.params]
        res = least_squares_fit(ctx, cand.name, params, start, simplex_fev=8)
    vec, _ = ctx.residual(res.params, res.values)
    return res, vec


# ------------------------------------------------------------------------------- the chain
def _map(tasks, jobs: int, payload):
    if jobs <= 1 or len(tasks) <= 1:
        _init_worker(*payload)
        return [_run_task(t) for t in tasks]
    import multiprocessing as mp

    try:
        ctx = mp.get_context("fork")
    except ValueError:  # pragma: no cover - platforms without fork
        ctx = mp.get_context()
    with ProcessPoolExecutor(max_workers=min(jobs, len(tasks)), mp_context=ctx, initializer=_init_worker, initargs=payload) as ex:
        return list(ex.map(_run_task, tasks))


def default_jobs() -> int:
    """Worker processes by default: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover
        return max(1, os.cpu_count() or 1)


def diagnose(cfg: PlantConfig, frame, meta: dict, *, effects=None, jobs: int | None = None, stride: int = 5,
             recalibrate: bool = True) -> Diagnosis:
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

    Returns
    -------
    Diagnosis

    Raises
    ------
    InputError
        Unknown effect names, a recording the replay cannot use.
    """
    t0 = time.perf_counter()
    jobs = default_jobs() if jobs is None else max(1, int(jobs))
    names = [e for e in EFFECTS if e not in cfg.effects] if effects is None else list(effects)
    for e in names:
        if e not in EFFECTS:
            from compliance.model.config import _suggest

            raise InputError(f"--effects: '{e}' is not a declared effect{_suggest(e, EFFECTS)} (known: {', '.join(EFFECTS)})")
    setup = prepare_replay(cfg, frame, meta)
    rc = replay_config(cfg, setup)
    nominal_sim = run_replay(rc, setup)
    model = build_residual_model(rc, setup, stride=stride, nominal=nominal_sim)
    model = with_fail_level(model, model.vector(nominal_sim))
    n = model.size
    events, event_mask, _ = locate_mismatch(rc, setup, model.signals, nominal_sim)
    nominal_fit = signal_fit(model, nominal_sim)
    nominal_rms = {s: v["rms_normalised"] for s, v in nominal_fit.items()}
    excess = {s: v * v - 1.0 for s, v in nominal_rms.items()}
    order = signature_order(names, excess)
    sims = 2
    fits: dict[str, FitResult] = {}
    vecs: dict[str, np.ndarray] = {}
    nvec = model.vector(nominal_sim)
    from compliance.diagnosis.fit import chi2_parts

    chi2, parts = chi2_parts(model, nvec)
    fits["nominal"] = FitResult("nominal", (), [], [], chi2, parts, n, 0, 0.0, "nominal model")
    payload = (plant_to_toml(rc), setup, model)
    tasks = []
    bparams = base_params(rc) if recalibrate else ()
    if bparams:
        tasks.append(("base", bparams, 2.0 * math.log(n) * max(1.0, chi2 / n)))
    tasks += [("effect", effect_candidate(e)) for e in order]
    for res, v in _map(tasks, jobs, payload):
        fits[res.name] = res
        vecs[res.name] = v
        sims += res.sims + 1
    # stage 4: effects together with the recalibration when neither explains it alone
    base_fit = fits.get("base")
    singles = [f for f in fits.values() if f.name != "nominal"]
    best = min(singles, key=lambda f: f.chi2, default=None)
    if (base_fit is not None and base_fit.k > 0 and best is not None and best.chi2 / n > COMBINE_LEVEL):
        top = sorted((f for f in singles if f.name in EFFECTS), key=lambda f: f.chi2)[:COMBINE_TOP]
        ctasks = [("combo", Candidate(f"{f.name}+base"), f, base_fit) for f in top]
        for res, v in _map(ctasks, jobs, payload):
            fits[res.name] = res
            vecs[res.name] = v
            sims += res.sims + 1
    scores = score_all(fits, n)
    effect_like = [k for k in fits if k not in ("nominal", "base")]
    verdict_name, winner, reason = verdict(scores, n, nominal_rms, effect_like)
    agreement = {k: mask_agreement(model, nvec, vecs[k], event_mask) for k in fits if k in vecs}
    ranked = sorted((k for k in fits if k != "nominal"), key=lambda k: (scores[k].bic, -agreement.get(k, 0.0)))
    if winner is None:
        runner = ranked[0] if ranked else None
    else:
        runner = next((k for k in ranked if k != winner and k.split("+")[0] != winner.split("+")[0]), None)
    # stage 6: full closed-loop replays for the figures a test engineer reproduces
    full = dc_replace(setup, resets=np.array([0]))
    full_nom = run_replay(rc, full)
    fitted_cfg = None
    full_win = None
    notes = list(setup.notes)
    if winner is not None and verdict_name in ("missing_physics", "parameters_only"):
        wf = fits[winner]
        full_win = _safe_replay(apply(rc, wf.params, wf.values), full, notes, "full closed-loop replay of the winner")
        fitted_cfg = _fitted_plant(cfg, wf, meta)
    sims += 2 if full_win is not None else 1
    fit_before = signal_fit(model, full_nom)
    fit_after = signal_fit(model, full_win) if full_win is not None else None
    seg_win = None
    if winner is not None:
        seg_win = _safe_replay(apply(rc, fits[winner].params, fits[winner].values), setup, notes, "replay of the winner")
        sims += 1
    before_rows = event_rms(events, model.recorded, nominal_sim, model.floors, model.signals)
    after_rows = event_rms(events, model.recorded, seg_win, model.floors, model.signals)
    windows_out = []
    for i, (e, b, a) in enumerate(zip(events, before_rows, after_rows)):
        windows_out.append({
            "index": i, "start": e["start"], "end": e["end"], "duration": e["duration"],
            "signals": dict(e["signals"]), "regimes": list(e["dominant"]),
            "before": b, "after": a,
        })
    objective_before = {s: math.sqrt(fits["nominal"].chi2_signal[s] / model.index.size) for s in model.signals}
    objective_after = ({s: math.sqrt(fits[winner].chi2_signal[s] / model.index.size) for s in model.signals}
                       if winner else None)
    diag = Diagnosis(
        verdict=verdict_name, reason=reason, winner=winner, runner_up=runner, fits=fits, scores=scores,
        fit_before=fit_before, fit_after=fit_after, objective_before=objective_before, objective_after=objective_after,
        windows=windows_out, floors=dict(model.floors), explanation="", cfg=cfg, fitted_cfg=fitted_cfg,
        recording=setup.source, seconds=0.0, simulations=sims, jobs=jobs, notes=notes,
        traces={"time": setup.time, "recorded": model.recorded, "before": full_nom, "after": full_win,
                "objective_before": nominal_sim, "objective_after": seg_win},
    )
    diag.agreement = agreement  # type: ignore[attr-defined]
    diag.located_regimes = where_words(events)  # type: ignore[attr-defined]
    from compliance.diagnosis.explain import explain

    diag.explanation = explain(diag)
    diag.seconds = time.perf_counter() - t0
    return diag


def _safe_replay(cfg: PlantConfig, setup: ReplaySetup, notes: list, what: str):
    """A replay for the figures; a candidate that diverges there is noted, not fatal."""
    try:
        return run_replay(cfg, setup)
    except SimulationError as exc:
        notes.append(f"{what} failed: {exc}")
        return None


def _fitted_plant(cfg: PlantConfig, fit: FitResult, meta: dict) -> PlantConfig:
    """The plant (not the test's controller overrides) with the winner's values, with provenance."""
    params = expand_base(cfg, fit.params, fit.values)
    effects: dict[str, dict] = {}
    for fp, v in zip(fit.params, fit.values):
        if fp.kind == "effect":
            effects.setdefault(fp.effect, {})[fp.name] = v
    prov = dict(cfg.provenance)
    prov.update({
        "fitted_by": "govcheck diagnose",
        "parent": str(cfg.path or cfg.name),
        "parent_digest": cfg.digest or "(in-memory configuration)",
        "recording": str(meta.get("source_path", "<recording>")),
        "date": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "explanation": fit.name,
    })
    return cfg.replace(params=params or None, effects=effects or None, provenance=prov,
                       sources={k: "derived" for k in params}, name=f"{cfg.name}-fitted")


def save_fitted(diag: Diagnosis, path) -> Path:
    """Write the fitted configuration (never overwrites; ``save_plant`` refuses)."""
    if diag.fitted_cfg is None:
        raise InputError(f"{path}: nothing to save: the verdict is '{diag.verdict}' (no fitted model)")
    out = save_plant(diag.fitted_cfg, path)
    diag.saved_model = str(out)
    return out


__all__ = ["Diagnosis", "diagnose", "save_fitted", "default_jobs", "SCHEMA", "UNITS", "NOISE_TOLERANCE"]
