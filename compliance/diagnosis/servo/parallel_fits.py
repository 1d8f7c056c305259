"""Parallel fits of one diagnosis on the one executor: each worker holds the recording's fit context.

The recording's replay set-up and residual model are the executor's context, built into a
``FitContext`` once per worker process (:class:`~compliance.processes.PerProcess`); each task is a
small frozen record of what to fit (``RecalibrateBase``, ``FitEffect``, ``FitWithBase``, ``ExtendSet``,
``RefitSet``, ``SecondStart``), to screen (``ScreenAddition``) or a point of a lag's valley to replay (``ValleyPoint``), run by
``_run_task``.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass

from compliance.model.config import plant_from_dict
from compliance.diagnosis.servo.candidates import Candidate
from compliance.model.parameters import ParamHandle
from compliance.diagnosis.servo.fit import FitContext, FitResult, fit_candidate, least_squares_fit, second_start
from compliance.diagnosis.servo.recalibration import forward_select_base
from compliance.diagnosis.servo.effect_sets import SET_SIMPLEX_FEV, extend_fit, screen_addition
from compliance.diagnosis.servo.lag_split import valley_point
from compliance.validation.replay import ReplaySetup
from compliance.processes import PerProcess, map_tasks


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
    """One candidate on the nominal plant; not refined when no grid point gets below ``screen`` (a chi-square).
    Its second local fit, if any, is left to a ``SecondStart`` task (``second_from``)."""

    candidate: Candidate
    screen: float | None = None

    def fit(self, ctx: FitContext) -> FitResult:
        return fit_candidate(ctx, self.candidate, None, screen=self.screen, second=False)


@dataclass(frozen=True)
class SecondStart:
    """The second local fit of a candidate that still competes (``fit.second_start``)."""

    first: FitResult

    def fit(self, ctx: FitContext) -> FitResult:
        # as in a fresh worker: its replays (and their count) never depend on what this process fitted before
        # (a speculative second start may follow its own candidate's first fit in the same worker)
        ctx.memo.clear()
        return second_start(ctx, self.first)


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

    def run(self, ctx: FitContext) -> tuple:
        return screen_addition(ctx, self.current, self.single)


@dataclass(frozen=True)
class ValleyPoint:
    """A point of the lag-split scan: ``effect``'s main parameter at ``value`` [SI] in ``fit``
    (``lag_split.valley_point``: the best profiled replay there and the replays it ran)."""

    fit: FitResult
    effect: str
    value: float
    limit: float

    def run(self, ctx: FitContext) -> tuple:
        return valley_point(ctx, self.fit, self.effect, self.value, self.limit)


def _fit_context(toml_text: str, setup: ReplaySetup, model) -> FitContext:
    return FitContext(plant_from_dict(tomllib.loads(toml_text), "<diagnosis>"), setup, model)


def _run_task(context: PerProcess, task):
    """One unit of parallel work: a fit -> (FitResult, residual vector); a task that is not a fit (a screen,
    a valley point) -> (what its ``run`` returns, None): no fit, no residual."""
    ctx: FitContext = context.get()
    if hasattr(task, "run"):
        return task.run(ctx), None
    res = task.fit(ctx)
    sims = ctx.sims
    vec, _ = ctx.residual(res.params, res.values)  # the fit's own last replay, remembered (FitContext.memo)
    res.sims += ctx.sims - sims
    return res, vec


def fit_context(payload) -> PerProcess:
    """The workers' fit context of ``payload`` (plant TOML text, replay set-up, residual model), built once per process."""
    return PerProcess(_fit_context, *payload)


def run_fits(tasks, jobs: int, payload, scheduler: str | None = None, client=None, follow=None, wanted=None) -> list:
    """(result, residual vector) of every fit task, in task order, on ``jobs`` processes (or Dask: the
    ``scheduler`` address, or the run's Dask ``client`` from ``processes.dask_session``).

    ``payload`` is (plant TOML text, replay set-up, residual model), or its ``fit_context``; a task that
    raises raises here. ``follow``, ``wanted``: follow-up tasks as in ``processes.map_tasks`` (their
    results after the tasks', None where dropped).
    """
    context = payload if isinstance(payload, PerProcess) else fit_context(payload)
    results, stats = map_tasks(_run_task, context, list(tasks), workers=jobs, scheduler=scheduler, client=client,
                               progress=False, label="fits", retries=0, follow=follow, wanted=wanted)
    stats.raise_if_failed()
    return results


__all__ = ["ExtendSet", "FitEffect", "FitWithBase", "RecalibrateBase", "RefitSet", "ScreenAddition", "SecondStart", "ValleyPoint",
           "fit_context", "run_fits"]
