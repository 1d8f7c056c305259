"""Parallel fits of one diagnosis on the one executor: each worker holds the recording's fit context.

The recording's replay set-up and residual model are the executor's context, built into a
``FitContext`` once per worker process (:class:`~compliance.processes.PerProcess`); each task
then names a candidate to fit (``_run_task``).
"""

from __future__ import annotations

import tomllib

from compliance.model.config import plant_from_dict
from compliance.diagnosis.servo.fit import FitContext, fit_candidate, least_squares_fit
from compliance.diagnosis.servo.recalibration import forward_select_base
from compliance.diagnosis.servo.effect_sets import extend_fit, screen_addition
from compliance.diagnosis.evidence.replay_fit import ReplaySetup
from compliance.processes import PerProcess, map_tasks


def _fit_context(toml_text: str, setup: ReplaySetup, model) -> FitContext:
    return FitContext(plant_from_dict(tomllib.loads(toml_text), "<diagnosis>"), setup, model)


def _run_task(context: PerProcess, task):
    """One unit of parallel work: ('base', params) | ('effect', Candidate) | ('combo', Candidate, FitResult)
    | ('extend', FitResult of a set, FitResult of a single effect, start values or None)
    | ('screen', FitResult of a set, FitResult of a single effect)."""
    ctx: FitContext = context.get()
    kind = task[0]
    if kind == "screen":  # (effect, chi-square, start, replays) of multi.screen_addition; no fit, no residual
        return screen_addition(ctx, task[1], task[2]), None
    if kind == "extend":
        res = extend_fit(ctx, *task[1:])
    elif kind == "base":
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


def run_fits(tasks, jobs: int, payload, scheduler: str | None = None) -> list:
    """(result, residual vector) of every fit task, in task order, on ``jobs`` processes (or Dask).

    ``payload`` is (plant TOML text, replay set-up, residual model); a task that raises raises here.
    """
    results, stats = map_tasks(_run_task, PerProcess(_fit_context, *payload), list(tasks), workers=jobs,
                               scheduler=scheduler, progress=False, label="fits", retries=0)
    stats.raise_if_failed()
    return results


__all__ = ["run_fits"]
