"""Calibrate what seed 000 leaves unstated to the figures it reports (``reproduce plant-a --calibrate``).

Search in the unit cube of the declared plausible ranges (``calibration_table``), objective
``calibration_objective.cost`` over the simulated figures:

1. a scrambled Sobol sample of the cube (plus the starting configuration), each point under
   every combination of the open test conditions, evaluated on a forked process pool;
2. parallel compass searches from the ``STARTS`` best points: all 2n axis moves are polled at once, the
   best improving move is taken, the step halves when none improves (Kolda, Lewis & Torczon
   2003, generating set search: derivative-free and robust to the kinks stick-slip puts in
   settling times);
3. pinning: a local 1-D profile of the objective along each parameter (the others held at the
   optimum); the contiguous values around the optimum whose cost stays within ``PIN_DELTA`` of
   it are what the figures allow. A profile point that beats the optimum restarts the compass
   there with a finer step (``POLISH_ROUNDS``): stick-slip makes the objective rough.

The test conditions are separable blocks of the objective (fig. 9's sequence touches only
fig. 9, the stroke start only the strokes), so each point is scored under every condition set
with its runs shared, and keeps the best. Switching a condition can pay only after several
parameters move together (starting the full strokes from the end stop needs both throttles
opened at once), which an axis-by-axis compass on the best-over-conditions objective never
tries; so after the compass starts, the compass is run again under each other condition set held
fixed, from the optimum (condition-set restarts).

Deterministic: fixed Sobol seed, fixed polling order, ties broken by index.
"""

from __future__ import annotations

import itertools
import math
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from compliance.campaign.executor import warm_up
from compliance.processes import available_cores, dask_session, map_tasks
from compliance.errors import InputError
from compliance.model.config import PlantConfig
from compliance.papers.calibration_objective import best_conditions, cost, rows_of
from compliance.model.parameters import ParamHandle, apply
from compliance.papers.calibration_table import CALIBRATED_SOURCE, CONDITIONS, held_breakaway, unstated_for
from compliance.papers.plant_a import Row, conditions_of

SOBOL_POINTS = 128
COMPASS_START = 0.1  # first step in the unit cube
COMPASS_MIN = 1.0 / 64.0
COMPASS_ITERATIONS = 12
STARTS = 4  # compass searches from the best distinct points of the global sample
PROFILE_OFFSETS = (-0.3, -0.1, -0.03, 0.03, 0.1, 0.3)  # unit-cube offsets of the local profile
POLISH_ROUNDS = 2  # restarts of the compass from a profile point that beat it
PIN_DELTA = 1.0  # one scatter^2: a value that moves one figure by its whole scatter is excluded

_CTX: dict = {}  # the search's state: configuration, parameters, conditions (the executor's context) and Dask client


@dataclass
class ParameterProfile:
    """How well the figures pin one parameter."""

    path: str
    values: list[float]
    costs: list[float]
    allowed: tuple[float, float]  # values with cost <= optimum + PIN_DELTA
    share: float  # width of ``allowed`` as a fraction of the plausible range (in search coordinates)

    best: float = 0.0  # cost at the optimum

    @property
    def verdict(self) -> str:
        """How the figures constrain the parameter (see docs/calibration.md, "pinning").

        ``pinned`` (allowed values < 25 % of the range), ``loosely pinned`` (< 60 %), ``not pinned``;
        ``rough`` when even the nearest profile points (3 % of the range away) cost more than
        ``PIN_DELTA``: stick-slip makes settling times jump, so the minimum is local and the
        allowed interval is not a measure of how well the figures determine the value.
        """
        if self.share == 0.0:
            return "rough: a 3 % move costs > 1 on both sides"
        return "pinned" if self.share < 0.25 else ("loosely pinned" if self.share < 0.6 else "not pinned")

    def deltas(self) -> str:
        """Cost above the optimum at the profile points, compact."""
        return " ".join("0" if c == self.best else f"{c - self.best:+.1f}" for c in self.costs)


@dataclass
class Calibration:
    """Result of a calibration."""

    start: PlantConfig
    best: PlantConfig
    table: tuple[ParamHandle, ...]
    values: dict[str, float]
    conditions: dict[str, str]
    cost_before: float
    cost_after: float
    rows_before: list[Row]
    rows_after: list[Row]
    profiles: list[ParameterProfile] = field(default_factory=list)
    evaluations: int = 0
    workers: int = 1


def _point_cost(ctx: dict, task):
    """Worker: a unit-cube point (or ("cfg", index) into a list of configurations) -> (cost, condition index,
    cost under each condition set); ``ctx`` is the search's state when the task was sent."""
    if isinstance(task, tuple):
        cfg = ctx["cfgs"][task[1]]
    else:
        cfg = _configure(ctx["cfg"], ctx["params"], task)
    try:
        if "score" in ctx:  # another objective of the same search (calibration_reach: one figure alone)
            c = ctx["score"](cfg)
            return c, 0, (c,)
        return best_conditions(cfg, ctx["conds"], ctx.get("targets"))
    except InputError:  # a point the loader's cross-checks refuse is outside the plant
        return math.inf, 0, (math.inf,) * len(ctx["conds"])


def _configure(cfg: PlantConfig, params, u) -> PlantConfig:
    return apply(cfg, *held_breakaway(cfg, params, [fp.from_unit(x) for fp, x in zip(params, u)]), source=CALIBRATED_SOURCE)


def _map(tasks: list, workers: int) -> list[tuple[float, int, tuple[float, ...]]]:
    """Score tasks on the one executor: ``workers`` local processes, or the Dask client of :func:`search_session`."""
    ctx = {k: v for k, v in _CTX.items() if k != "client"}
    client = _CTX.get("client")
    if workers <= 1 or len(tasks) < 4:  # a few points: fork and scatter cost more than they save
        workers, client = 1, None
    results, stats = map_tasks(_point_cost, ctx, list(tasks), workers=workers, client=client, progress=False,
                               label="calibration points", retries=0)
    stats.raise_if_failed()
    return results


@contextmanager
def search_session(scheduler: str | None):
    """Every search inside runs on one Dask client for ``scheduler`` (``local:N`` or ``tcp://host:port``); None: local."""
    if scheduler is None or _CTX.get("client") is not None:
        yield
        return
    with dask_session(scheduler) as client:
        _CTX["client"] = client
        try:
            yield
        finally:
            _CTX.pop("client", None)


def map_configs(cfgs: list[PlantConfig], conds: list[dict], workers: int) -> list[tuple[float, int, tuple]]:
    """(cost, condition index, cost per set) of each configuration, on the same pool as the search."""
    _CTX.update(cfgs=cfgs, conds=conds, targets=None)
    return _map([("cfg", i) for i in range(len(cfgs))], workers)


def _condition_sets(fixed: dict | None = None) -> list[dict]:
    names = [c.name for c in CONDITIONS]
    choices = [c.choices if not fixed or c.name not in fixed else (fixed[c.name],) for c in CONDITIONS]
    return [dict(zip(names, combo)) for combo in itertools.product(*choices)]


def _compass(u0: np.ndarray, best: tuple[float, int], workers: int, iterations: int = COMPASS_ITERATIONS,
             start: float = COMPASS_START, good_enough: float = -math.inf):
    """Parallel compass search in the unit cube from ``u0`` (its (cost, condition) ``best``).

    Stops early once the cost is at most ``good_enough``.
    """
    u, step, n_eval = u0.copy(), start, 0
    for _ in range(iterations):
        if step < COMPASS_MIN or best[0] <= good_enough:
            break
        trials = []
        for i in range(u.size):
            for s in (+1.0, -1.0):
                t = u.copy()
                t[i] = min(max(t[i] + s * step, 0.0), 1.0)
                if t[i] != u[i]:
                    trials.append(t)
        results = _map(trials, workers)
        n_eval += len(trials)
        k = min(range(len(results)), key=lambda j: results[j][0]) if results else -1
        if k >= 0 and results[k][0] < best[0] - 1e-9:
            u, best = trials[k], results[k]
        else:
            step *= 0.5
    return u, best, n_eval


def _condition_restarts(u_best: np.ndarray, best: tuple, workers: int, iterations: int):
    """The compass again from the optimum under each other condition set, held fixed.

    Under a fixed set the moves that make that set pay (both throttles opening for a stroke
    from the end stop) improve one axis at a time, so the compass follows them; restarting from
    the best sample point of each set instead missed that basin (docs/calibration.md).
    Returns the best (point, (cost, condition index)) and the evaluations spent.
    """
    conds, n_eval = _CTX["conds"], 0
    u_start, best_j = u_best, best[1]
    for j, cond in enumerate(conds):
        if j == best_j:
            continue
        _CTX["conds"] = [cond]  # the forked workers read it
        try:
            r0 = _point_cost(_CTX, u_start)
            u, b, n = _compass(np.asarray(u_start), r0, workers, iterations)
        finally:
            _CTX["conds"] = conds
        n_eval += n + 1
        if b[0] < best[0] - 1e-9:
            u_best, best = u, (b[0], j)
    return u_best, best, n_eval


def _profiles(params, u_best: np.ndarray, c_best: float, workers: int):
    """Local profiles around ``u_best``; also the best profile point if it beats the optimum (or None)."""
    tasks = []
    for i in range(len(params)):
        for d in PROFILE_OFFSETS:
            t = u_best.copy()
            t[i] = min(max(t[i] + d, 0.0), 1.0)
            tasks.append(t)
    results = _map(tasks, workers)
    j = min(range(len(results)), key=lambda m: results[m][0])
    better = (tasks[j], results[j]) if results[j][0] < c_best - 1e-9 else None
    out = []
    n = len(PROFILE_OFFSETS)
    for i, fp in enumerate(params):
        us = [float(tasks[i * n + j][i]) for j in range(n)] + [float(u_best[i])]
        cs = [results[i * n + j][0] for j in range(n)] + [c_best]
        order = sorted(range(len(us)), key=lambda j: us[j])
        us, cs = [us[j] for j in order], [cs[j] for j in order]
        # the contiguous run of values around the optimum whose cost stays within PIN_DELTA
        k = us.index(float(u_best[i]))
        lo = hi = k
        while lo > 0 and cs[lo - 1] <= c_best + PIN_DELTA:
            lo -= 1
        while hi < len(us) - 1 and cs[hi + 1] <= c_best + PIN_DELTA:
            hi += 1
        out.append(ParameterProfile(fp.path, [fp.from_unit(x) for x in us], cs,
                           (fp.from_unit(us[lo]), fp.from_unit(us[hi])), us[hi] - us[lo], c_best))
    return out, better


def calibrate(cfg: PlantConfig, *, workers: int | None = None, sobol_points: int = SOBOL_POINTS,
              table: tuple[ParamHandle, ...] | None = None, conditions: dict | None = None,
              profiles: bool = True, targets: dict | None = None,
              compass_iterations: int = COMPASS_ITERATIONS, seeds: tuple[PlantConfig, ...] = (),
              starts: int = STARTS, restarts: bool = True, scheduler: str | None = None) -> Calibration:
    """Fit the unstated parameters and test conditions of ``cfg`` to the paper's figures.

    Parameters
    ----------
    cfg : PlantConfig
        Starting configuration (plant A, or a variant with effects switched on).
    workers : int, optional
        Processes (default: the cores available).
    sobol_points : int
        Size of the global sample (a power of two).
    table : tuple of ParamHandle, optional
        What may move (default ``unstated_for(cfg)``).
    conditions : dict, optional
        Test conditions to hold fixed (others are chosen by the fit).
    profiles : bool
        Compute the 1-D profiles that say how well each parameter is pinned.
    targets : dict, optional
        (test, metric) -> figure to calibrate to instead of the paper's (``rows_of``).
    compass_iterations : int
        Iterations of the local search.
    seeds : tuple of PlantConfig
        Further starting points for the global sample (e.g. an earlier stage's optimum).
    starts : int
        Compass searches from that many best points of the sample.
    restarts : bool
        Condition-set restarts: the compass again from the optimum under each other set of test conditions.
    scheduler : str, optional
        Evaluate the points on Dask (:func:`search_session`) instead of ``workers`` local processes.
    """
    with search_session(scheduler):
        return _calibrate(cfg, workers, sobol_points, table, conditions, profiles, targets, compass_iterations, seeds,
                          starts, restarts)


def _calibrate(cfg, workers, sobol_points, table, conditions, profiles, targets, compass_iterations, seeds, starts,
               restarts) -> Calibration:
    workers = max(1, workers or available_cores())
    table = table if table is not None else unstated_for(cfg)
    params = list(table)
    warm_up(cfg)
    conds = _condition_sets(conditions)
    _CTX.update(cfg=cfg, params=params, conds=conds, targets=targets)
    start_cond = dict(conditions_of(cfg), **(conditions or {}))
    rows_before = rows_of(cfg, start_cond, targets=targets)
    u0 = np.array([fp.to_unit(fp.value_in(cfg)) for fp in params])
    from scipy.stats import qmc

    extra = [np.array([fp.to_unit(fp.value_in(s)) for fp in params]) for s in (seeds or ())]
    sample = [u0] + extra + list(qmc.Sobol(len(params), scramble=True, seed=17).random(sobol_points))
    results = _map(sample, workers)
    n_eval = len(sample)
    u_best, best = None, (math.inf, 0)
    for k in sorted(range(len(results)), key=lambda j: results[j][0])[:starts]:  # the landscape has several basins
        u, b, n = _compass(np.asarray(sample[k]), results[k], workers, compass_iterations)
        n_eval += n
        if b[0] < best[0]:
            u_best, best = u, b
    if restarts and len(conds) > 1:
        u_best, best, n = _condition_restarts(u_best, best, workers, compass_iterations)
        n_eval += n
    prof = []
    for _ in range(POLISH_ROUNDS + 1 if profiles else 0):
        prof, better = _profiles(params, u_best, best[0], workers)
        n_eval += len(params) * len(PROFILE_OFFSETS)
        if better is None:
            break
        # a profile point beat the optimum (a rough objective fools the compass): restart there, finer
        u_best, best, n = _compass(better[0], better[1], workers, compass_iterations, start=COMPASS_START / 4)
        n_eval += n
    cal = _configure(cfg, params, u_best)
    cond = conds[best[1]]
    rows_after = rows_of(cal, cond, targets=targets)
    values = {fp.path: fp.value_in(cal) for fp in params}
    return Calibration(cfg, cal, tuple(table), values, cond, cost(rows_before), cost(rows_after), rows_before,
                       rows_after, prof, n_eval, workers)
