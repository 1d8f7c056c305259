"""Joint diagnosis of several recordings of one plant: shared physics, each test's own conditions.

``diagnose_joint(cfg, recordings)`` runs the single-recording engine's stages on each recording
(``servo.diagnose.prepare_recording``: the replay with the recording's own load, start, supply pressure,
controller gains, flow-control valves and loop switch from its sidecar, its noise floors; a closed-loop
test, a full stroke driven by its valve command, a hold whose positioner went to manual: a site's
commissioning tests) and then fits every candidate - the
recalibration of base parameters and each declared effect - with *one* parameter set shared by
all recordings. The objective is the sum of the per-recording chi-squares, each recording's
residuals normalised by its own floors (``JointContext``); the information criteria count every
residual of every recording (BIC_j = chi2_j / c + k_j ln N, N the total). Selection, verdict and
ambiguity are the single recording's (``servo.selection``), on the pooled scores.

Why: two explanations a recording cannot tell apart (``servo.selection.ambiguity_set``) predict different
responses under other conditions; the test ``--suggest-test`` designs (another supply pressure,
another load, another position) is that condition, and diagnosed jointly with the first
recording it settles the question. Friction level against pressure-dependent friction is the
classic case: at one supply pressure the mean chamber pressure barely changes, so a 30 %
higher friction level and a rise of 30 % at that pressure are the same plant; at 70 % of the
supply they are not.

An effect none of whose declared grid points removes ``SCREEN_SHARE`` (2 %) of the nominal
excess chi-square is not refined (reported at its best grid point, marked ``screened``): each
refinement costs one replay per recording per step. The candidate fits run on the shared executor (``processes.map_tasks``; a Dask
scheduler with ``scheduler``). Not done jointly (the single-recording diagnosis does them):
the multi-effect search, the friction-form check, the empirical term and the lag split.
"""

from __future__ import annotations

import math
import time
import tomllib
from dataclasses import dataclass, field

import numpy as np

from compliance.effects import EFFECTS
from compliance.errors import InputError
from compliance.files.jsonable import json_number
from compliance.model.config import PlantConfig, plant_from_dict
from compliance.diagnosis.servo.candidates import base_params, effect_candidate, signature_order
from compliance.diagnosis.servo.fit import FitContext, FitResult, chi2_parts, competing, least_squares_fit, screen_level
from compliance.diagnosis.servo.report_data import SCHEMA
from compliance.diagnosis.servo.selection import AMBIGUOUS_BIC, RESIDUAL_LIMIT, ambiguity_set, honest, score_all, verdict
from compliance.diagnosis.verdicts.verdict import EXPLAINED, DiagnosisVerdict
from compliance.diagnosis.servo.parallel_fits import FitEffect, RecalibrateBase, RefitSet, SecondStart
from compliance.diagnosis.estimation.joint_residuals import JointContext, JointModel



def _joint_context(labels, parts) -> JointContext:
    """The fit context of every recording, built once per worker process (``PerProcess``)."""
    ctxs = [FitContext(plant_from_dict(tomllib.loads(t), "<joint diagnosis>"), setup, model) for t, setup, model in parts]
    return JointContext(ctxs, list(labels))


def _task(context, task) -> FitResult:
    """One joint fit on a worker: a ``RecalibrateBase`` or a ``FitEffect`` (``servo.parallel_fits``)."""
    return task.fit(context.get())


def _prepare_task(context, item):
    """Stages 1-2 of the single-recording engine on one recording (a worker task)."""
    from compliance.diagnosis.servo.stage import prepare_recording

    cfg, stride = context
    frame, meta = item
    return prepare_recording(cfg, frame, meta, stride, 1)


@dataclass
class JointDiagnosis:
    """Outcome of a joint diagnosis (``to_dict``: docs/diagnosis-schema.md, ``kind = "joint"``)."""

    verdict: str
    reason: str
    winner: str | None
    ambiguous: list
    fits: dict
    scores: dict
    objectives: dict  # candidate -> block label -> normalised RMS
    recordings: list  # per recording: label, source, conditions, residuals
    n: int
    seconds: float = 0.0
    simulations: int = 0
    workers: int = 1
    backend: str = "local"
    notes: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-ready (SI units)."""
        ranked = sorted((k for k in self.fits if k != "nominal"), key=lambda k: self.scores[k].bic)
        effects = []
        for rank, name in enumerate(ranked, 1):
            f, s = self.fits[name], self.scores[name]
            effects.append({
                "rank": rank, "name": name, "k": f.k, "chi2": json_number(s.chi2), "chi2_per_residual": json_number(s.chi2 / self.n),
                "bic": json_number(s.bic), "delta_bic": json_number(s.delta_bic), "explained_fraction": json_number(s.explained),
                "parameters": [{"name": fp.key, "kind": fp.kind, "value": json_number(v), "stderr": json_number(e), "unit": fp.unit}
                               for fp, v, e in zip(f.params, f.values, f.stderr)],
                "per_recording": _per_recording(self.objectives[name], self.recordings),
                "screened": f.message.startswith("screened"),
            })
        return {"schema": SCHEMA, "kind": "joint", "verdict": self.verdict, "reason": self.reason, "winner": self.winner,
                "ambiguous": self.ambiguous, "n_residuals": self.n, "recordings": self.recordings, "effects": effects,
                "before": _per_recording(self.objectives["nominal"], self.recordings),
                "after": _per_recording(self.objectives[self.winner], self.recordings) if self.winner else None,
                "notes": self.notes, "timing": {"seconds": self.seconds, "simulations": self.simulations,
                                                "workers": self.workers, "backend": self.backend}}


def _per_recording(objective: dict, recordings: list) -> dict:
    """Recording label -> signal -> normalised RMS (residual over its own floor)."""
    out = {}
    for rec in recordings:
        pre = rec["label"] + ":"
        out[rec["label"]] = {k[len(pre):]: json_number(v) for k, v in objective.items() if k.startswith(pre)}
    return out


def _objective(fit: FitResult, model: JointModel) -> dict:
    sizes = dict(zip(model.signals, model.block_sizes))
    return {lab: math.sqrt(fit.chi2_signal[lab] / sizes[lab]) for lab in model.signals}


def _conditions(stage) -> dict:
    st, rc = stage.setup, stage.rc
    load = st.load if isinstance(st.load, str) else float(st.load)
    return {"supply_pressure": rc.p("air.supply_pressure"), "load_force": load, "initial_position": st.initial_position,
            "kp": rc.p("controller.kp"), "ki": rc.p("controller.ki"), "kd": rc.p("controller.kd"),
            "sample_time": rc.p("controller.sample_time"), "duration": float(st.time[-1])}


def _stages(cfg: PlantConfig, recordings, stride: int, jobs, scheduler) -> tuple[list, list]:
    """Stages 1-2 of the single-recording engine on each recording, in parallel; labels R1, R2, ... in order."""
    from compliance.campaign.executor import warm_up
    from compliance.processes import map_tasks

    warm_up(cfg)  # the compiled core loaded once, before the workers fork
    stages, stats = map_tasks(_prepare_task, (cfg, stride), list(recordings), workers=jobs, scheduler=scheduler,
                              progress=False, label="replays", retries=0)
    if stats.failed:  # bad input (InputError) is raised by the executor itself; this is a bug
        raise RuntimeError(f"replay of recording {stats.errors[0][0] + 1} failed: {stats.errors[0][1]}")
    return stages, [f"R{i}" for i in range(1, len(stages) + 1)]


def _throttled(cfg: PlantConfig, setup) -> bool:
    return cfg.flow_control_installed if setup.flow_control is None else bool(setup.flow_control)


def _commissioned(cfg: PlantConfig, stages, labels, recordings, stride: int, jobs, scheduler):
    """The site's flow-control throttles fitted on the full strokes that ran with them, and the stages on them.

    A site's needles 2V2/2V3 sit where its commissioning engineer left them (``servo.candidates.THROTTLES``),
    and a full stroke's open-loop replay integrates a few per cent of throttle error into millimetres: left
    at the plant file's values they would hold most of every stroke's residual and each candidate would be
    judged on them. They are test conditions, like the supply pressure: fitted first (one shared pair,
    priors on the file's values), and every candidate is then fitted on top.

    Returns
    -------
    (PlantConfig, list, FitResult or None)
        The configuration with the fitted throttles (unchanged when no full stroke ran with them or
        the fit does not improve on the file's values), its stages, the fit.
    """
    from compliance.model.config import plant_to_toml
    from compliance.model.parameters import apply

    # the tests the throttles are commissioned by: full strokes at full command, driven by it (IEC 60308 stroke times);
    # elsewhere (a hold at null, small steps) they barely act, and fitted there they would wander to their bounds
    chosen = [i for i, st in enumerate(stages) if _throttled(cfg, st.setup) and not st.setup.closed_loop]
    params = base_params(cfg, keys=(), throttles=True)
    if not chosen or not params:
        return cfg, stages, None
    ctx = _joint_context([labels[i] for i in chosen], [(plant_to_toml(stages[i].rc), stages[i].setup, stages[i].model)
                                                       for i in chosen])
    fit = least_squares_fit(ctx, "flow_control", params, [fp.nominal for fp in params])
    fit.sims = ctx.sims
    if not fit.chi2 < sum(stages[i].fits["nominal"].chi2 for i in chosen):
        return cfg, stages, fit
    cfg = apply(cfg, params, fit.values)
    stages, _ = _stages(cfg, recordings, stride, jobs, scheduler)
    return cfg, stages, fit


def _with_settings(fits: dict, settings, stages, labels, jobs, scheduler) -> None:
    """Each effect that still competes refitted together with the site's throttles (in place, when that fits better):
    the throttles were fitted on the nominal plant, and an effect that changes a stroke moves them too. The refits
    run on the workers, one task each."""
    from compliance.model.config import plant_to_toml
    from compliance.processes import PerProcess, map_tasks

    if settings is None or not settings.params:
        return
    rivals = competing([f for k, f in fits.items() if k in EFFECTS])
    tasks = [RefitSet(f.name, tuple(f.params) + tuple(settings.params), list(f.values) + list(settings.values)) for f in rivals]
    if not tasks:
        return
    payload = PerProcess(_joint_context, tuple(labels), [(plant_to_toml(s.rc), s.setup, s.model) for s in stages])
    results, stats = map_tasks(_task, payload, tasks, workers=jobs, scheduler=scheduler, progress=False,
                               label="joint fits", retries=1)
    if stats.failed:
        raise RuntimeError(f"joint fit failed: {stats.errors[0][1]}")
    for f, res in zip(rivals, results):
        res.sims += f.sims
        if res.chi2 < f.chi2:
            fits[f.name] = res


def _fit_all(stages, labels, names, recalibrate, jobs, scheduler) -> tuple[dict, object]:
    """Stage 3, joint: the recalibration and one fit per effect, each with one parameter set for every recording."""
    from compliance.model.config import plant_to_toml
    from compliance.processes import PerProcess, map_tasks

    n = sum(s.model.size for s in stages)
    chi2_nom = sum(s.fits["nominal"].chi2 for s in stages)
    excess = {}
    for s in stages:  # each signal's worst excess over the recordings orders the effects (likely ones first)
        for sig, v in s.nominal_rms.items():
            excess[sig] = max(excess.get(sig, -1.0), v * v - 1.0)
    tasks = []
    keys = recalibrate if isinstance(recalibrate, (tuple, list)) else None
    bparams = (base_params(stages[0].rc, keys) if keys else base_params(stages[0].rc)) if recalibrate else ()
    if bparams:
        tasks.append(RecalibrateBase(bparams, 2.0 * math.log(n) * max(1.0, chi2_nom / n)))
    screen = screen_level(chi2_nom, n)  # an effect none of whose grid points removes SCREEN_SHARE of the excess: not refined
    tasks += [FitEffect(effect_candidate(e), screen) for e in signature_order(names, excess)]
    payload = PerProcess(_joint_context, tuple(labels), [(plant_to_toml(s.rc), s.setup, s.model) for s in stages])
    results, stats = map_tasks(_task, payload, tasks, workers=jobs, scheduler=scheduler, progress=False,
                               label="joint fits", retries=1)
    if stats.failed:
        raise RuntimeError(f"joint fit failed: {stats.errors[0][1]}")
    fits = {res.name: res for res in results}
    # a second local fit only where it can still matter (servo.fit.competing)
    second = [SecondStart(f) for f in competing(list(fits.values())) if f.second_from]
    if second:
        more, stats2 = map_tasks(_task, payload, second, workers=jobs, scheduler=scheduler, progress=False,
                                 label="joint fits", retries=1)
        if stats2.failed:
            raise RuntimeError(f"joint fit failed: {stats2.errors[0][1]}")
        fits.update({res.name: res for res in more})
    return fits, stats


def diagnose_joint(cfg: PlantConfig, recordings, *, effects=None, jobs: int | None = None, scheduler: str | None = None,
                   stride: int = 5, recalibrate: bool | tuple = True) -> JointDiagnosis:
    """Diagnose several recordings of one plant together (see the module docstring).

    Parameters
    ----------
    cfg : PlantConfig
        The nominal plant; each recording's sidecar sets its own load, start, supply pressure and gains.
    recordings : sequence of (DataFrame, metadata)
        ``read_recording`` output, one or more (one gives the single-recording selection on the same objective).
    effects : iterable of str, optional
        Candidate effects (default: every declared effect not already on).
    jobs : int, optional
        Local worker processes (default: the available cores).
    scheduler : str, optional
        Dask scheduler (``local:N`` or ``tcp://host:port``) for the candidate fits.
    stride : int
        Residual subsampling.
    recalibrate : bool or tuple of str
        Also fit the recalibration of base parameters (a tuple: only these keys, e.g. ``("friction.level",)``).

    Raises
    ------
    InputError
        No recording, an unknown effect, a recording the replay cannot use.
    """
    from compliance.diagnosis.servo.stage import check_effects

    t0 = time.perf_counter()
    if not recordings:
        raise InputError("a joint diagnosis needs at least one recording")
    names = check_effects(cfg, effects)
    stages, labels = _stages(cfg, recordings, stride, jobs, scheduler)
    cfg, stages, settings = _commissioned(cfg, stages, labels, recordings, stride, jobs, scheduler)
    fits, stats = _fit_all(stages, labels, names, recalibrate, jobs, scheduler)
    _with_settings(fits, settings, stages, labels, jobs, scheduler)
    model = JointModel([s.model for s in stages], labels)
    n = model.size
    nvec = np.concatenate([s.nvec for s in stages])
    chi2, parts = chi2_parts(model, nvec)
    fits["nominal"] = FitResult("nominal", (), [], [], chi2, parts, n, 0, 0.0, "nominal model")
    scores = score_all(fits, n)
    objectives = {k: _objective(f, model) for k, f in fits.items()}
    effect_like = [k for k in fits if k not in ("nominal", "base")]
    verdict_name, winner, reason = verdict(scores, n, objectives["nominal"], effect_like)
    verdict_name, reason = honest(verdict_name, winner, reason, objectives.get(winner) if winner else None)
    ambiguous = ambiguity_set(scores, winner, objectives) if verdict_name != DiagnosisVerdict.NO_MISMATCH else []
    if ambiguous and verdict_name in EXPLAINED:
        verdict_name = DiagnosisVerdict.AMBIGUOUS
        reason = (f"{' and '.join(ambiguous)} explain the {len(stages)} recording(s) equally well (every signal within "
                  f"{RESIDUAL_LIMIT:g} x its floor, or BIC within {AMBIGUOUS_BIC:g}); another test tells them apart")
    recs = [{"label": lab, "source": s.setup.source, "conditions": {k: json_number(v) if not isinstance(v, str) else v
                                                                    for k, v in _conditions(s).items()},
             "n_residuals": s.model.size, "floors": {k: json_number(v) for k, v in s.model.floors.items()}}
            for lab, s in zip(labels, stages)]
    sims = sum(s.sims for s in stages) + sum(f.sims for k, f in fits.items() if k != "nominal")
    notes = [f"{lab}: {note}" for lab, s in zip(labels, stages) for note in s.setup.notes]
    if settings is not None:
        sims += settings.sims
        notes.insert(0, "the flow-control throttles as commissioned on site, fitted first on the full strokes that ran with them: "
                     + ", ".join(f"{fp.key} = {v:.4g} {fp.unit}" for fp, v in zip(settings.params, settings.values)))
    return JointDiagnosis(verdict_name, reason, winner, ambiguous, fits, scores, objectives, recs, n,
                          time.perf_counter() - t0, sims, stats.workers, stats.backend, notes)


def format_joint(d: dict, quiet: bool = False) -> str:
    """Console summary of a joint diagnosis."""
    lines = [f"verdict: {d['verdict']}" + (f" ({d['winner']})" if d.get("winner") else "") + f" - {d['reason']}"]
    if quiet:
        return "\n".join(lines)
    lines.append("")
    for r in d["recordings"]:
        c = r["conditions"]
        load = c["load_force"] if isinstance(c["load_force"], str) else f"{c['load_force']/1e3:.2f} kN"
        lines.append(f"{r['label']}: {r['source']}  supply {c['supply_pressure']/1e5:.2f} bar abs, load {load}, "
                     f"start {c['initial_position']*1e3:.1f} mm, Kp {c['kp']:g}, {c['duration']:.1f} s")
    lines.append("")
    lines.append(f"{'candidate':34s} {'k':>2s} {'chi2/N':>9s} {'dBIC':>10s} {'explained':>9s}  parameters")
    for e in d["effects"][:8]:
        params = ", ".join(f"{p['name'].split('.')[-1]}={p['value']:.4g} {p['unit']}".rstrip() for p in e["parameters"])
        lines.append(f"{e['name']:34s} {e['k']:2d} {e['chi2_per_residual']:9.3f} {e['delta_bic']:10.1f} "
                     f"{100*(e['explained_fraction'] or 0):8.0f}%  {params}")
    lines.append("")
    lines.append("normalised RMS per recording and signal (residual / its own floor), before -> after:")
    for lab, sig in d["before"].items():
        after = (d.get("after") or {}).get(lab, {})
        lines.append(f"  {lab}: " + ", ".join(f"{s} {v:.2f}" + (f" -> {after[s]:.2f}" if s in after else "") for s, v in sig.items()))
    t = d["timing"]
    lines.append(f"\n{d['n_residuals']} residuals; {t['simulations']} simulations in {t['seconds']:.1f} s on "
                 f"{t['workers']} worker(s) ({t['backend']})")
    return "\n".join(lines)


__all__ = ["JointDiagnosis", "diagnose_joint", "format_joint"]
