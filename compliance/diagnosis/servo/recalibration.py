"""Recalibration of base parameters: greedy forward selection with 1-D scans and refits.

"No physics is missing, parameter X is off": each round scans every recalibratable base
parameter (``servo.candidates.base_scan_values``), refines the most promising in 1-D, and adds the
best one when it pays for itself (the information criterion's price of a parameter) and
removes a material share (``JOIN_GAIN``) of what is left above the noise floor; then all chosen
parameters are refitted together (``servo.fit.least_squares_fit``, with their priors).
"""

from __future__ import annotations

import math
import time

import numpy as np

from compliance.model.parameters import ParamHandle
from compliance.diagnosis.servo.candidates import base_scan_values
from compliance.diagnosis.servo.fit import MAX_NFEV, SIMPLEX_FEV, FitContext, FitResult, least_squares_fit, scan_points

REFINE_TOP = 3  # base parameters refined in 1-D per forward-selection round
REFINE_SPAN = 0.15  # half-width of that refinement in the unit cube
REFINE_EVALS = 8
# share of the gain a parameter needs to join (JOIN_GAIN, the penalty) its coarse scan must already show to be refined:
# on the practice recordings a refinement added at most a few per cent of a round's chi-square, while a round
# that joins nothing (every second round there) spent 24 of its ~50 replays refining
REFINE_SHARE = 0.25
JOIN_GAIN = 0.25  # share of the excess chi-square a base parameter must remove to join the recalibration
AT_FLOOR = 1.2  # chi2/N at which the recalibration stops: the fit is at the noise floor


def forward_select_base(ctx: FitContext, params: tuple[ParamHandle, ...], *, penalty: float, max_params: int = 2,
                        max_nfev: int = MAX_NFEV) -> tuple[FitResult, list[dict]]:
    """Greedy recalibration: add the base parameter whose 1-D scan helps most, refit, repeat.

    A parameter joins only when it lowers chi-square by more than ``penalty`` (the information
    criterion's price of one parameter). Only the ``REFINE_TOP`` parameters whose scans reach lowest
    matter to a round, so a scan replay stops once its point is beyond the ``REFINE_TOP``-th best
    parameter so far (``_scan``); a parameter whose every point stopped keeps a lower bound above
    that level, and the round chooses as it would with full replays.

    Returns
    -------
    (FitResult, list of dict)
        The recalibration (possibly with no parameters) and the log of each round.
    """
    t0 = time.perf_counter()
    sims0 = ctx.sims
    chosen: list[ParamHandle] = []
    values: list[float] = []
    current = least_squares_fit(ctx, "base", (), [])
    log = []
    while len(chosen) < max_params:
        trials = []
        for fp in params:
            if fp in chosen:
                continue
            for v in base_scan_values(fp, fp.nominal):
                trials.append((fp, tuple(chosen) + (fp,), values + [v]))
        if not trials:
            break
        best_by_param = _scan(ctx, trials)
        cur_total = current.chi2 + sum(f.prior_residual(v) ** 2 for f, v in zip(current.params, current.values))
        n = ctx.model.size
        need = max(penalty, JOIN_GAIN * (cur_total - n))  # what a parameter must remove to join (below)
        # refine the most promising parameters in 1-D before choosing: a coarse scan point can
        # miss a 25 % miscalibration and hand the round to a parameter that only mimics it; a parameter
        # whose scan removes less than REFINE_SHARE of what joining needs is left at its scan (and none is refined
        # when the recalibration is at the floor already: nothing joins then)
        for key in sorted(best_by_param, key=lambda k: best_by_param[k][0])[:REFINE_TOP]:
            c, v, fp = best_by_param[key]
            if cur_total - c < REFINE_SHARE * need or cur_total <= AT_FLOOR * n:
                continue
            c2, v2 = _refine_1d(ctx, tuple(chosen), values, fp, v)
            if c2 < c:
                best_by_param[key] = (c2, v2, fp)
        key, (c, v, fp) = min(best_by_param.items(), key=lambda kv: kv[1][0])
        log.append({"round": len(chosen) + 1, "best": key, "scan_chi2": c, "current_chi2": cur_total,
                    "by_parameter": {k: b[0] for k, b in best_by_param.items()}})
        # a parameter joins when it pays for itself (information criterion) and matters: it removes a
        # material share of what is left above the noise floor (nothing joins a fit already at the floor)
        if cur_total - c <= need or cur_total <= AT_FLOOR * n:
            break
        chosen.append(fp)
        res = least_squares_fit(ctx, "base", tuple(chosen), values + [v], max_nfev=max_nfev, simplex_fev=SIMPLEX_FEV // 2)
        if res.chi2 >= current.chi2 - penalty:
            chosen.pop()
            break
        current = res
        values = list(res.values)
    current.sims = ctx.sims - sims0
    current.seconds = time.perf_counter() - t0
    return current, log


def _refine_1d(ctx: FitContext, chosen: tuple, values: list, fp: ParamHandle, start: float) -> tuple[float, float]:
    """Bounded 1-D minimisation of chi-square (+ prior) over ``fp`` around ``start``, others held."""
    from scipy.optimize import minimize_scalar

    params = chosen + (fp,)
    u0 = fp.to_unit(start)
    lo, hi = max(0.0, u0 - REFINE_SPAN), min(1.0, u0 + REFINE_SPAN)

    def f(u):
        return scan_points(ctx, params, [values + [fp.from_unit(u)]])[0]

    res = minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"maxiter": REFINE_EVALS, "xatol": 2e-3})
    return float(res.fun), fp.from_unit(res.x)


def _scan(ctx: FitContext, trials: list) -> dict[str, tuple[float, float, ParamHandle]]:
    """Parameter key -> (its scan's lowest chi-square + prior, that value, the parameter) over ``trials``
    ((parameter, parameters, values) each), each replay stopped once beyond the ``REFINE_TOP``-th best parameter."""
    best: dict[str, tuple[float, float, ParamHandle]] = {}
    for fp, tp, tv in trials:
        ranked = sorted(b[0] for b in best.values())
        limit = ranked[REFINE_TOP - 1] if len(ranked) >= REFINE_TOP else math.inf
        prior = sum(f.prior_residual(v) ** 2 for f, v in zip(tp, tv))
        vec, _ = ctx.residual(tp, list(tv), limit - prior)
        c = float(np.dot(vec, vec)) + prior
        if fp.key not in best or c < best[fp.key][0]:
            best[fp.key] = (c, tv[-1], fp)
    return best


__all__ = ["forward_select_base", "JOIN_GAIN", "AT_FLOOR"]
