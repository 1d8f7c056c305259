"""Parallel fits of one diagnosis: worker processes that each hold the recording's fit context.

The recording's replay set-up and residual model are sent once per worker (initializer); each
task is a small frozen record of what to fit (``RecalibrateBase``, ``FitEffect``, ``FitWithBase``,
``ExtendSet``) or to screen (``ScreenAddition``), run by ``_run_task``. Processes are forked where the platform
allows it (no re-import of the compiled core).
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass

from compliance.model.config import plant_from_dict
from compliance.diagnosis.servo.candidates import Candidate
from compliance.model.parameters import ParamHandle
from compliance.diagnosis.servo.fit import FitContext, FitResult, fit_candidate, least_squares_fit
from compliance.diagnosis.servo.recalibration import forward_select_base
from compliance.diagnosis.servo.effect_sets import SET_SIMPLEX_FEV, extend_fit, screen_addition
from compliance.diagnosis.evidence.replay_fit import ReplaySetup

_WORKER: dict = {}


@dataclass(frozen=True)
class RecalibrateBase:
    """Greedy forward selection of the base parameters ``params`` (``penalty`` per added parameter)."""

    params: tuple[ParamHandle, ...]
    penalty: float

    def fit(self, ctx: FitContext) -> FitResult:
        res, log = forward_select_base(ctx, self.params, penalty=self.penalty)
        res.scan = log
        return res


@dataclass(frozen=True)
class FitEffect:
    """One candidate on the nominal plant; not refined when no grid point gets below ``screen`` (a chi-square)."""

    candidate: Candidate
    screen: float | None = None

    def fit(self, ctx: FitContext) -> FitResult:
        return fit_candidate(ctx, self.candidate, None, screen=self.screen)


@dataclass(frozen=True)
class FitWithBase:
    """An effect refitted together with the recalibrated base parameters, from both fits' values."""

    candidate: Candidate
    effect_fit: FitResult
    base_fit: FitResult

    def fit(self, ctx: FitContext) -> FitResult:
        params = tuple(self.effect_fit.params) + tuple(self.base_fit.params)
        # start exactly at the effect's optimum (base parameters nominal): the combination can only improve on it
        start = list(self.effect_fit.values) + [fp.nominal for fp in self.base_fit.params]
        return least_squares_fit(ctx, self.candidate.name, params, start, simplex_fev=8)


@dataclass(frozen=True)
class ExtendSet:
    """The effect set ``current`` refitted with ``single``'s effect added, from ``start`` (None: the best start)."""

    current: FitResult
    single: FitResult
    start: list[float] | None = None

    def fit(self, ctx: FitContext) -> FitResult:
        return extend_fit(ctx, self.current, self.single, self.start)


@dataclass(frozen=True)
class RefitSet:
    """The set ``name`` refitted from a start near its optimum (``effect_sets.prune``)."""

    name: str
    params: tuple[ParamHandle, ...]
    start: list[float]

    def fit(self, ctx: FitContext) -> FitResult:
        return least_squares_fit(ctx, self.name, self.params, self.start, simplex_fev=SET_SIMPLEX_FEV)


@dataclass(frozen=True)
class ScreenAddition:
    """``single``'s effect switched on in the set ``current``, unfitted (``effect_sets.screen_addition``)."""

    current: FitResult
    single: FitResult


def _init_worker(toml_text: str, setup: ReplaySetup, model) -> None:
    cfg = plant_from_dict(tomllib.loads(toml_text), "<diagnosis>")
    _WORKER["ctx"] = FitContext(cfg, setup, model)


def _run_task(task):
    """One unit of parallel work: a fit -> (FitResult, residual vector); a screen -> ((effect, chi-square,
    start, replays) of ``effect_sets.screen_addition``, None): no fit, no residual."""
    ctx: FitContext = _WORKER["ctx"]
    if isinstance(task, ScreenAddition):
        return screen_addition(ctx, task.current, task.single), None
    res = task.fit(ctx)
    sims = ctx.sims
    vec, _ = ctx.residual(res.params, res.values)  # the fit's own last replay, remembered (FitContext.memo)
    res.sims += ctx.sims - sims
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
