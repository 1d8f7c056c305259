"""Parallel fits of one diagnosis: worker processes that each hold the recording's fit context.

The recording's replay set-up and residual model are sent once per worker (initializer); each
task then names a candidate to fit (``_run_task``). Processes are forked where the platform
allows it (no re-import of the compiled core).
"""

from __future__ import annotations

import os
import tomllib

from compliance.model.config import plant_from_dict
from compliance.diagnosis.servo.fit import FitContext, fit_candidate, least_squares_fit
from compliance.diagnosis.servo.recalibration import forward_select_base
from compliance.diagnosis.servo.effect_sets import extend_fit, screen_addition
from compliance.diagnosis.evidence.replay_fit import ReplaySetup

_WORKER: dict = {}


def _init_worker(toml_text: str, setup: ReplaySetup, model) -> None:
    cfg = plant_from_dict(tomllib.loads(toml_text), "<diagnosis>")
    _WORKER["ctx"] = FitContext(cfg, setup, model)


def _run_task(task):
    """One unit of parallel work: ('base', params) | ('effect', Candidate) | ('combo', Candidate, FitResult)
    | ('extend', FitResult of a set, FitResult of a single effect, start values or None)
    | ('screen', FitResult of a set, FitResult of a single effect)."""
    ctx: FitContext = _WORKER["ctx"]
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


def map_tasks(tasks, jobs: int, payload):
    if jobs <= 1 or len(tasks) <= 1:
        _init_worker(*payload)
        return [_run_task(t) for t in tasks]
    import multiprocessing as mp

    try:
        ctx = mp.get_context("fork")
    except ValueError:  # pragma: no cover - platforms without fork
        ctx = mp.get_context()
    from compliance.processes import worker_pool

    with worker_pool(min(jobs, len(tasks)), ctx, initializer=_init_worker, initargs=payload) as ex:
        return list(ex.map(_run_task, tasks))


def default_jobs() -> int:
    """Worker processes by default: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover
        return max(1, os.cpu_count() or 1)


__all__ = ["map_tasks", "default_jobs"]
