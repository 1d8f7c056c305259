"""Does the recording pin the split of a lag, or only its total? A scan along the lumped valley.

A spool or a transducer below the loop's bandwidth shows the loop its total lag (``Effect.lumped``);
its main parameter (spool natural frequency, transducer time constant) and its pure delay trade
along a valley of the fit. After the winner is fitted, its main parameter is moved over
``SPLIT_FACTORS`` of the fitted value while the delay is re-solved to keep the total lag at its
fitted value; the nuisance parameters are profiled coarsely - the total lag at ``TOTAL_FACTORS``
of its fit, a third parameter (the spool's damping) at ``OTHER_FACTORS`` of its fit - and the best
replay of each main value kept. The values whose
replay is as good an explanation as the fit by the verdict's own rule for indistinguishable
explanations - chi-square within ``AMBIGUOUS_RATIO`` of the fit's, and no signal above
``RESIDUAL_LIMIT`` times its floor or, when the fit itself sits near that limit, above the fit's
worst signal by more than the same ratio in chi-square - form the *split interval* (the connected
run of such values around the fit). When it spans more than a factor ``PINNED_SPAN`` the recording pins the total, not the split, and the diagnosis says so with
the interval instead of presenting the fitted split as measured.

Inside an undetermined interval the split is estimated by the segments, not by the pooled
chi-square: every re-synchronised segment of the replay (``validation.replay``) shows the lag in its
transient, but a few segments where a stick-slip event happens or not on a model-form detail
(a slip in the replay that the bench did not make) can hold most of the pooled chi-square and
pull the pooled optimum along the valley. Each valley point is therefore also scored by least
trimmed squares over segments (Rousseeuw 1984): the mean normalised chi-square of its best
``1 - TRIM_SHARE`` of segments. The *estimate* is the point of the interval with the lowest
trimmed score, when that is lower than the pooled fit's by at least ``ESTIMATE_GAIN`` (less is
within the trimmed score's own wrinkles); the diagnosis adopts it as the lag's fitted values (it explains the recording
as well as the pooled fit by the rule above, so the verdict stands). Checked on a
synthetic split the pooled fit misplaces, pulled by the slips of a slow sine, which the segments put
back (tests/diagnosis/test_split.py).

Why this rule and not a statistical interval: the replay's chi-square has wrinkles along the
valley (a stall point or breakaway moves when the lag shifts by a millisecond), measured on the
independent sensor-lag recording at 10-20 % of chi2/N between neighbouring points of one
valley, far above any Gaussian profile threshold (the sandwich standard error of the independent
valve recording's spool frequency is 0.25 % of it); two splits whose chi-squares differ by less
than those wrinkles are not told apart by the recording, which is the same judgement the verdict makes between two explanations.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace as dc_replace

import numpy as np
from scipy.optimize import minimize

from compliance.effects import EFFECTS
from compliance.diagnosis.servo.selection import AMBIGUOUS_RATIO, RESIDUAL_LIMIT

SPLIT_FACTORS = (0.5, 0.67, 0.8, 0.9, 1.12, 1.25, 1.5, 2.0)  # main parameter / fitted value
PINNED_SPAN = 1.25  # an interval wider than this factor (max / min) leaves the split undetermined
OTHER_FACTORS = (0.8, 1.0, 1.25)  # a third parameter (the spool's damping) is tried at these multiples of its fit
TOTAL_FACTORS = (0.96, 1.0, 1.04)  # ... and the total lag at these (independent recordings: fitted totals within 2-5 %)
REFINE = 1.25  # a grid profile within this factor above the limit is refined by a short simplex ...
REFINE_FEV = 12  # ... of this many replays
TRIM_SHARE = 0.2  # least trimmed squares over segments: the worst fifth of the segments is left out (breakdown 20 %)
ESTIMATE_GAIN = 0.05  # the split moves only when the segments clearly prefer it: trimmed chi2 lower by this share


def _delay_param(effect: str) -> str | None:
    eff = EFFECTS[effect]
    return eff.input_delay or eff.output_delay


def _valley_point(effect: str, vals: dict, main: str, delay: str, value: float, total: float) -> dict | None:
    """The parameters with ``main`` at ``value`` and the delay re-solved to keep the lumped total."""
    lumped = EFFECTS[effect].lumped.of
    p = dict(vals)
    p[main] = value
    p[delay] = 0.0
    g0 = float(lumped(p))
    p[delay] = 1e-3
    slope = (float(lumped(p)) - g0) / 1e-3  # the delay enters the total lag linearly
    if slope <= 0.0:
        return None
    p[delay] = (total - g0) / slope
    return p


def _segments(ctx) -> np.ndarray:
    """Segment number of every residual (signal blocks of the fitted samples; one segment without resets)."""
    setup = getattr(ctx, "setup", None)
    index = np.asarray(ctx.model.index)
    if setup is None or len(setup.resets) < 2:
        seg = np.zeros(index.size, dtype=int)
    else:
        seg = np.searchsorted(np.asarray(setup.resets), index, side="right") - 1
    return np.tile(seg, ctx.model.size // max(index.size, 1))


def trimmed_chi2(vec: np.ndarray, segments: np.ndarray) -> float:
    """Least-trimmed-squares score of a residual vector: the chi-square per residual of its best
    ``1 - TRIM_SHARE`` of segments (at least one), each segment's chi-square taken per residual."""
    chi = np.bincount(segments, weights=vec * vec)
    count = np.bincount(segments)
    keep = count > 0
    per = chi[keep] / count[keep]
    order = np.argsort(per)[:max(1, int(math.ceil((1.0 - TRIM_SHARE) * per.size)))]
    return float(chi[keep][order].sum() / count[keep][order].sum())


def _replay_point(ctx, fit, values, segments) -> tuple | None:
    """(chi2 per residual, largest normalised RMS of a signal, trimmed chi2 per residual, values) at ``values``."""
    vec, sim = ctx.residual(fit.params, values)
    if sim is None:
        return None
    parts = {s: float(np.dot(r, r)) for s, r in ctx.model.split(vec).items()}
    m = ctx.model.index.size
    return (sum(parts.values()) / ctx.model.size, max(math.sqrt(c / m) for c in parts.values()),
            trimmed_chi2(vec, segments), list(values))


def _best_on_valley(ctx, fit, effect, idx, vals, main, delay, value, total, limit, segments) -> tuple | None:
    """The best replay with ``main`` at ``value``, the nuisance parameters profiled (delay re-solved).

    A coarse grid (total lag x ``TOTAL_FACTORS``, a third parameter x ``OTHER_FACTORS``); where the
    decision hinges on it - the grid's best within ``REFINE`` times the ``limit`` above it - a short
    simplex from the grid's best refines the profile (a coarse grid only bounds it from above).
    """
    others = [q for q in idx if q not in (main, delay)]
    fd = fit.params[idx[delay]]

    def at(factors):
        trial = dict(vals)
        for q, f in zip(others, factors[1:]):
            fp = fit.params[idx[q]]
            trial[q] = min(max(vals[q] * f, fp.low), fp.high)
        p = _valley_point(effect, trial, main, delay, value, total * factors[0])
        if p is None or not fd.low <= p[delay] <= fd.high:
            return None
        values = list(fit.values)
        for q in idx:
            values[idx[q]] = p[q]
        return _replay_point(ctx, fit, values, segments)

    grid = [(f, at(f)) for f in itertools.product(TOTAL_FACTORS, *([OTHER_FACTORS] * len(others)))]
    grid = [(f, g) for f, g in grid if g is not None]
    if not grid:
        return None
    f0, best = min(grid, key=lambda fg: fg[1][0])
    if limit < best[0] <= REFINE * limit:
        seen = {}

        def cost(logf):
            got = at(tuple(np.exp(logf)))
            seen[tuple(logf)] = got
            return math.inf if got is None else got[0]

        x0 = np.log(np.asarray(f0, dtype=float))
        steps = np.diag([0.02] + [0.12] * len(others))  # half the grid's spacing in log factor
        minimize(cost, x0, method="Nelder-Mead", options={"maxfev": REFINE_FEV, "initial_simplex": np.vstack([x0, x0 + steps])})
        best = min((g for g in seen.values() if g is not None), key=lambda g: g[0], default=best)
    return best


def _connected(points: list, fitted: float, ok) -> list[float]:
    """[low, high] of the run of values around ``fitted`` that ``ok`` accepts (points sorted by value)."""
    values = [p[0] for p in points]
    k = values.index(fitted)
    lo = hi = k
    while lo > 0 and ok(points[lo - 1]):
        lo -= 1
    while hi < len(values) - 1 and ok(points[hi + 1]):
        hi += 1
    return [values[lo], values[hi]]


def _valley(fit, effect: str):
    """(parameter index by name, fitted values by name, main, delay, lumped total) of ``effect`` in ``fit``,
    or None when the effect declares no lumped combination with a delay."""
    decl = EFFECTS.get(effect)
    delay = _delay_param(effect) if decl is not None else None
    if decl is None or decl.lumped is None or delay is None:
        return None
    idx = {fp.name: i for i, fp in enumerate(fit.params) if fp.kind == "effect" and fp.effect == effect}
    if len(idx) != len(decl.params):
        return None
    vals = {q: fit.values[i] for q, i in idx.items()}
    return idx, vals, decl.params[0].name, delay, float(decl.lumped.of(vals))


def valley_point(ctx, fit, effect: str, value: float, limit: float) -> tuple[tuple | None, int]:
    """One point of the scan (``split_scan``): the best replay with the main parameter of ``effect`` at
    ``value`` [SI] and the nuisance parameters profiled, or None outside the bounds; and the replays it ran.

    ``limit``: chi-square per residual deciding whether the coarse profile is refined."""
    idx, vals, main, delay, total = _valley(fit, effect)
    fm = fit.params[idx[main]]
    sims = ctx.sims
    got = (_best_on_valley(ctx, fit, effect, idx, vals, main, delay, value, total, limit, _segments(ctx))
           if fm.low <= value <= fm.high else None)
    return got, ctx.sims - sims


def split_scan(ctx, fit, effect: str, vec: np.ndarray | None = None, along=None) -> dict | None:
    """Scan the lumped valley of ``effect`` in the fitted candidate ``fit`` (``servo.fit.FitContext`` ``ctx``);
    ``vec``: the fit's own residual vector when the caller has it (else it is replayed once); ``along``:
    runs ``valley_point`` for a list of main-parameter values and limit (the caller's workers; default here).

    Returns
    -------
    dict or None
        ``parameter`` (key of the main parameter), ``fitted``, ``points`` [(value, chi2/N, largest
        normalised RMS, trimmed chi2/N)], ``interval`` [low, high] of the values indistinguishable from
        the fit, ``bracket`` (the nearest values tried outside it, None at the scan's end), ``pinned``
        (interval narrower than ``PINNED_SPAN``), ``lumped`` (total held), ``estimate`` (the interval's
        point with the lowest trimmed chi2: ``value``, ``values`` of all the fit's parameters, ``trimmed``
        and the fit's ``trimmed_fit``; None when it is the fit itself or the split is pinned), ``replays``
        (the scan's own) - or None when the effect declares no lumped combination with a delay.
    """
    valley = _valley(fit, effect)
    if valley is None:
        return None
    idx, vals, main, delay, total = valley
    sims0 = ctx.sims
    m = ctx.model.index.size
    segments = _segments(ctx)
    fit_worst = max(math.sqrt(c / m) for c in fit.chi2_signal.values())
    if vec is not None:
        own_trimmed = trimmed_chi2(vec, segments)
    else:
        own = _replay_point(ctx, fit, list(fit.values), segments)
        own_trimmed = own[2] if own else math.inf
    points = [(vals[main], fit.chi2 / ctx.model.size, fit_worst, own_trimmed, list(fit.values))]
    limit = AMBIGUOUS_RATIO * fit.chi2 / ctx.model.size
    values = [vals[main] * f for f in SPLIT_FACTORS]
    replays = ctx.sims - sims0  # the fit's own, when replayed here; each point counts its own below
    scanned = (along or (lambda vs, lim: [valley_point(ctx, fit, effect, v, lim) for v in vs]))(values, limit)
    replays += sum(n for _, n in scanned)
    points += [(value, *got) for value, (got, _) in zip(values, scanned) if got is not None]
    points.sort(key=lambda p: p[0])
    # as good as the fit: chi-square within the ratio, no signal beyond the limit or (when the fit itself
    # sits near it) beyond the fit's own worst signal by the same ratio
    worst_ok = max(RESIDUAL_LIMIT, fit_worst * math.sqrt(AMBIGUOUS_RATIO))
    interval = _connected(points, vals[main], lambda p: p[1] <= limit and p[2] <= worst_ok)
    values = [p[0] for p in points]
    lo, hi = values.index(interval[0]), values.index(interval[1])
    # the scan's resolution: the nearest values tried outside the interval (None: the scan's end)
    bracket = [values[lo - 1] if lo > 0 else None, values[hi + 1] if hi < len(values) - 1 else None]
    pinned = interval[1] / interval[0] < PINNED_SPAN
    # the estimate never leaves a signal above both the residual limit and the fit's own worst (verdicts stand)
    best = min((p for p in points[lo:hi + 1] if p[2] <= max(RESIDUAL_LIMIT, fit_worst)), key=lambda p: p[3])
    own_trimmed = points[values.index(vals[main])][3]
    estimate = None if pinned or best[3] > (1.0 - ESTIMATE_GAIN) * own_trimmed else {
        "value": best[0], "values": best[4], "trimmed": best[3], "trimmed_fit": own_trimmed}
    return {"parameter": f"{effect}.{main}", "fitted": vals[main], "lumped": total, "delay": f"{effect}.{delay}",
            "points": [list(p[:4]) for p in points], "interval": interval, "bracket": bracket,
            "pinned": pinned, "scanned": [points[0][0], points[-1][0]], "estimate": estimate, "replays": replays}


def adopted_fit(ctx, fit, estimate: dict):
    """The fit moved to the scan's ``estimate`` along its valley: (FitResult, residual vector), or None
    when that replay fails. Values, chi-square and its signal parts are the estimate's; standard
    errors and covariance stay the pooled fit's (the total they pin is unchanged)."""
    vec, sim = ctx.residual(fit.params, estimate["values"])
    if sim is None:
        return None
    parts = {s: float(np.dot(r, r)) for s, r in ctx.model.split(vec).items()}
    moved = dc_replace(fit, values=list(estimate["values"]), chi2=sum(parts.values()), chi2_signal=parts,
                       sims=fit.sims + 1, message=fit.message + "; split moved to the segments' estimate (servo/lag_split.py)")
    return moved, vec


__all__ = ["adopted_fit", "split_scan", "valley_point", "trimmed_chi2", "SPLIT_FACTORS", "PINNED_SPAN", "TRIM_SHARE", "ESTIMATE_GAIN"]
