"""Bounded least-squares fits of candidate explanations to a recording's replay residuals.

One fit: a coarse scan of the candidate's starting grid (cheap, finds the basin), a
Nelder-Mead simplex (Nelder & Mead 1965) from the best grid point with steps of 5 % of each
parameter's range, then ``scipy.optimize.least_squares`` (trust-region reflective, bounds)
to polish and to give the Jacobian. All of it runs in the unit cube of
``model.parameters.ParamHandle`` on the stacked residuals of every measured signal divided by its
noise floor, plus prior residuals holding recalibrated base parameters near their
data-sheet values.

Why the simplex: even re-synchronised, a closed loop with a dead zone and stiction leaves
fine-grained roughness on the residual surface (a stall point moves by one quantum), on
which forward-difference Gauss-Newton steps stall at the first wrinkle (on the practice
valve-dynamics recording least squares alone stops at chi2/N = 14.5, the simplex reaches 4.1).
The simplex' 5 % steps see the bowl, not the wrinkles.

Standard errors come from the final Jacobian J and the residuals r themselves: the
heteroscedasticity-and-autocorrelation-consistent sandwich of Newey & West (1987),
cov = (J^T J)^-1 S (J^T J)^-1 with S = sum over lags |l| <= L of (1 - |l|/(L+1)) sum_t g_t g_(t-l)^T,
g_t = J_t r_t, L = ``HAC_SECONDS`` of residuals. A replay's misfit is not white noise: one
breakaway the replay makes and the bench did not leaves a burst correlated over a second, and
such bursts carry far less information than as many independent samples. S is never taken
below J^T J (the floors' own noise level).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from compliance.model.config import PlantConfig
from compliance.model.parameters import ParamHandle, apply
from compliance.effects import EFFECTS
from compliance.errors import InputError
from compliance.diagnosis.servo.candidates import Candidate
from compliance.diagnosis.servo.instrument_candidates import instrumented
from compliance.validation.replay import ReplaySetup
from compliance.diagnosis.evidence.residuals import ResidualModel, evaluate
from compliance.diagnosis.estimation.simplex import simplex_search
from compliance.diagnosis.estimation.standard_errors import fit_errors

DIFF_STEP = 0.01  # forward-difference step, 1 % of each parameter's (log) range
MAX_NFEV = 6  # least-squares polishing evaluations (besides the Jacobian's)
SIMPLEX_FEV = 16  # simplex evaluations per fitted parameter
SECOND_START = 2.0  # a second local fit starts from a grid point within this chi-square ratio of the best ...
COMPETE = 2.0  # ... of a candidate whose first fit is within this ratio of the best candidate's (the others have lost)
MEMO = 16  # replays a fit context remembers (each its residuals and simulated signals: ~2 MB for 30 s at 1 kHz)
HAC_SECONDS = 1.0  # s; Newey-West bandwidth: residual correlation of about one stick-slip episode
# share of the nominal excess chi-square an effect's best grid point must remove to be refined (our choice: a candidate
# must remove select.MIN_GAIN = 25 % to matter; the refinement of one that starts at 2 % costs as many replays as a real one)
SCREEN_SHARE = 0.02
# ... of a single effect on one recording (servo.diagnose): refinement raised an effect's share of the nominal excess by
# at most +0.13 (0.09 -> 0.22, 0.07 -> 0.20) on the twelve practice recordings of sets 1 and 3, so one whose grid removes
# less than 10 % does not reach select.MIN_GAIN = 25 % (it stays a candidate at its best grid point)
SINGLE_SCREEN_SHARE = 0.10


def screen_level(chi2_nominal: float, n: int, share: float = SCREEN_SHARE) -> float:
    """Chi-square a candidate's best grid point must reach to be refined (``fit_candidate``'s ``screen``): it must
    remove ``share`` of the excess chi-square over the ``n`` residuals."""
    return chi2_nominal - share * max(chi2_nominal - n, 0.0)


@dataclass
class FitContext:
    """What every fit of one recording shares.

    Attributes
    ----------
    cfg : PlantConfig
        Parent configuration (recording overrides applied).
    setup : ReplaySetup
    model : ResidualModel
    """

    cfg: PlantConfig
    setup: ReplaySetup
    model: ResidualModel
    sims: int = 0
    memo: dict = field(default_factory=dict, repr=False)  # (keys, values) -> (residuals, replay): the latest MEMO
    stopped: bool = False  # the last ``residual`` stopped its replay early
    stopped_sims: int = 0  # replays stopped early (counted in ``sims`` too)

    def residual(self, params, values, limit: float = math.inf) -> tuple[np.ndarray, dict | None]:
        """Normalised data residuals of a parameter set, and the replay (None if it failed or stopped).

        Instrumentation parameters (``servo.instrument_candidates``) act on the logger model and on the
        states the re-synchronisations read (the plant's, not the instrument's). A parameter set
        replayed moments ago (a fit's best grid point where its simplex starts, the fitted values
        the caller replays again) is not replayed twice: values equal to 10 significant digits
        (a round trip through the fit's unit cube) give the same replay.

        ``limit``: the caller only needs to know whether the chi-square exceeds it; the replay may
        stop at the first segment where it does (``evidence.residuals.Bound``), and ``stopped`` says
        so (the residuals after that segment are then zero).
        """
        key = (tuple(fp.key for fp in params), tuple(float(f"{v:.10g}") for v in values))
        self.stopped = False
        if key in self.memo:
            return self.memo[key]
        setup = instrumented(self.setup, params, values)
        self.sims += 1
        try:
            cfg = apply(self.cfg, params, values)
        except InputError:
            return self.model.vector(None), None
        vec, sim, self.stopped = evaluate(self.model, cfg, setup, limit)
        if self.stopped:
            self.stopped_sims += 1
            return vec, None
        out = self.memo[key] = (vec, sim)
        while len(self.memo) > MEMO:
            self.memo.pop(next(iter(self.memo)))
        return out


@dataclass
class FitResult:
    """Outcome of fitting one candidate.

    Attributes
    ----------
    name : str
        Effect name, ``base`` (recalibration alone) or ``nominal``.
    params : tuple of ParamHandle
    values, stderr : list of float
        Fitted values and standard errors [SI].
    chi2 : float
        Sum of squared normalised data residuals (priors excluded).
    chi2_signal : dict
        Signal -> its part of chi2.
    n : int
        Number of residuals.
    sims : int
        Replays run.
    seconds : float
    message : str
    """

    name: str
    params: tuple = ()
    values: list = field(default_factory=list)
    stderr: list = field(default_factory=list)
    chi2: float = math.inf
    chi2_signal: dict = field(default_factory=dict)
    n: int = 0
    sims: int = 0
    seconds: float = 0.0
    message: str = ""
    scan: list = field(default_factory=list)
    cov: np.ndarray | None = None  # covariance of the fitted values [SI], from the final Jacobian
    second_from: list | None = None  # start of a second local fit not run yet (``fit_candidate``'s ``second``)

    @property
    def k(self) -> int:
        """Number of fitted parameters."""
        return len(self.params)

    def lumped(self, effect: str) -> tuple[float, float] | None:
        """(value, standard error) of ``effect``'s declared lumped combination, or None.

        The error propagates the full covariance (delta method): parameters that trade along a
        valley are strongly anti-correlated, so their sum is much sharper than either.
        """
        decl = EFFECTS.get(effect)
        if decl is None or decl.lumped is None:
            return None
        idx = [i for i, fp in enumerate(self.params) if fp.kind == "effect" and fp.effect == effect]
        vals = {self.params[i].name: self.values[i] for i in idx}
        if len(vals) != len(decl.params):
            return None
        f0 = float(decl.lumped.of(vals))
        if self.cov is None or not np.all(np.isfinite(self.cov)):
            return f0, float("nan")
        grad = np.zeros(len(self.params))
        for i in idx:
            h = 1e-6 * max(abs(self.values[i]), 1e-9)
            bumped = dict(vals)
            bumped[self.params[i].name] += h
            grad[i] = (float(decl.lumped.of(bumped)) - f0) / h
        return f0, float(math.sqrt(max(float(grad @ self.cov @ grad), 0.0)))

    def value(self, key: str) -> float:
        """Fitted value of parameter ``key``."""
        for fp, v in zip(self.params, self.values):
            if fp.key == key:
                return v
        raise KeyError(key)


def chi2_parts(model: ResidualModel, vec: np.ndarray) -> tuple[float, dict]:
    """Total chi-square and its split per signal."""
    parts = {s: float(np.dot(r, r)) for s, r in model.split(vec).items()}
    return float(sum(parts.values())), parts


def _objective(ctx: FitContext, params, cache: dict):
    """``fun(u, limit)``: the residual vector (data, then priors) at the unit-cube point ``u``; with a finite ``limit``
    on its sum of squares the replay may stop once it exceeds it (``FitContext.residual``)."""
    prior_idx = [i for i, fp in enumerate(params) if fp.prior]

    def fun(u, limit=math.inf):
        key = tuple(np.round(u, 12))
        hit = cache.get(key)
        if hit is not None and (hit[1] or float(np.dot(hit[0], hit[0])) > limit):
            return hit[0]
        values = [fp.from_unit(x) for fp, x in zip(params, u)]
        prior = [params[i].prior_residual(values[i]) for i in prior_idx]
        vec, _ = ctx.residual(params, values, limit - sum(p * p for p in prior))
        if prior_idx:
            vec = np.concatenate([vec, prior])
        cache[key] = (vec, not ctx.stopped)
        return vec

    return fun


def _nelder_mead(fun, u0: np.ndarray, maxfev: int, step: float = 0.05) -> np.ndarray:
    """Simplex search of sum(fun(u)^2) in the unit cube (points outside are clipped and penalised; ``servo.simplex``)."""
    k = u0.size

    def f(u, limit=math.inf):
        uc = np.clip(u, 0.0, 1.0)
        pen = 1.0 + 10.0 * float(np.sum((u - uc) ** 2))
        out = float(np.dot(r := fun(uc, limit / pen), r))
        return out * pen

    simplex = [u0]
    for i in range(k):
        v = u0.copy()
        v[i] = u0[i] + step if u0[i] + step <= 1.0 else u0[i] - step
        simplex.append(v)
    f0 = f(u0)
    # stop when the simplex spans < 0.2 % of the range and its values differ by < 0.1 % (the roughness level)
    return np.clip(simplex_search(f, np.array(simplex), maxfev, xatol=2e-3, fatol=1e-3 * f0), 0.0, 1.0)


def least_squares_fit(ctx: FitContext, name: str, params: tuple[ParamHandle, ...], start: list[float], *,
                      max_nfev: int = MAX_NFEV, diff_step: float = DIFF_STEP, simplex_fev: int = SIMPLEX_FEV) -> FitResult:
    """Fit ``params`` from ``start`` (SI values): simplex search, then bounded least squares.

    Returns
    -------
    FitResult
        With standard errors from the Jacobian at the solution.
    """
    t0 = time.perf_counter()
    sims0 = ctx.sims
    n = ctx.model.size
    if not params:
        vec, _ = ctx.residual((), [])
        chi2, parts = chi2_parts(ctx.model, vec)
        return FitResult(name, (), [], [], chi2, parts, n, ctx.sims - sims0, time.perf_counter() - t0, "nothing to fit")
    cache: dict = {}
    fun = _objective(ctx, params, cache)
    u0 = np.array([min(max(fp.to_unit(v), 1e-6), 1.0 - 1e-6) for fp, v in zip(params, start)])
    if simplex_fev > 0:
        u0 = np.clip(_nelder_mead(fun, u0, maxfev=simplex_fev * len(params) + 10), 1e-6, 1.0 - 1e-6)
    res = least_squares(fun, u0, bounds=(np.zeros(len(params)), np.ones(len(params))), method="trf",
                        diff_step=diff_step, max_nfev=max_nfev, xtol=1e-4, ftol=1e-4, x_scale=1.0)
    u = res.x
    if float(np.dot(fun(u0), fun(u0))) < float(np.dot(fun(u), fun(u))):
        u = u0  # never return worse than the simplex found
    values = [fp.from_unit(x) for fp, x in zip(params, u)]
    vec = fun(u)[:n]
    chi2, parts = chi2_parts(ctx.model, vec)
    t_res = ctx.setup.time[ctx.model.index]
    dt_res = float(np.median(np.diff(t_res))) if t_res.size > 1 else 1.0
    stderr, cov = fit_errors(params, values, res.jac, n, ctx.model, vec, max(1, int(round(HAC_SECONDS / dt_res))))
    out = FitResult(name, tuple(params), values, stderr, chi2, parts, n, ctx.sims - sims0,
                    time.perf_counter() - t0, str(res.message))
    out.cov = cov
    return out


def scan_points(ctx: FitContext, params, points: list[list[float]], keep: float | None = None,
                runner_up: bool = False) -> list[float]:
    """Chi-square (data + prior) at each point of a scan (SI values per point).

    ``keep``: only points within ``keep`` times the best so far matter to the caller (the argmin: 1;
    a second start within ``SECOND_START`` of the best: that ratio); a replay stops once its point
    is known to be beyond, and its value is then a lower bound above that level.

    ``runner_up``: besides the argmin the caller needs only the best point of another main-parameter
    value (``points[i][0]``; ``fit_candidate``'s second start), so a point also stops once beyond the
    second-lowest of the main values' best points so far: it can then be neither.
    """
    out = []
    best = math.inf
    by_main: dict = {}  # main-parameter value -> its best point's chi-square so far
    for values in points:
        prior = sum(fp.prior_residual(v) ** 2 for fp, v in zip(params, values))
        level = keep * best if keep is not None and math.isfinite(best) else math.inf
        if runner_up and len(by_main) >= 2:
            level = min(level, sorted(by_main.values())[1])
        vec, _ = ctx.residual(params, values, level - prior)
        out.append(float(np.dot(vec, vec)) + prior)
        best = min(best, out[-1])
        by_main[values[0]] = min(by_main.get(values[0], math.inf), out[-1])
    return out


def replays_bound(cand: Candidate) -> int:
    """Replays a full fit of ``cand`` takes at most: its grid, the simplex, the polish and its Jacobian, twice
    with a second start (``fit_candidate``). The pool gets the longest fits first (a long fit started last
    leaves the other workers idle)."""
    k = len(cand.params)
    return len(cand.grid or ({},)) + (SIMPLEX_FEV * k + 10 + MAX_NFEV + k) * (2 if k > 1 else 1)


def fit_candidate(ctx: FitContext, cand: Candidate, base_fit: FitResult | None, *, max_nfev: int = MAX_NFEV,
                  screen: float | None = None, second: bool = True) -> FitResult:
    """Fit one effect on top of the recalibrated base, co-fitting the recalibrated base parameters.

    The effect's grid is scanned with the base parameters at their recalibrated values; the
    local fit starts from the best grid point. Effects with several parameters often trade
    them along a valley (a spool delay against a slower spool, a sensor delay against its lag),
    so a second local fit starts from the best grid point with another main-parameter value
    when it is within ``SECOND_START`` of the best, and the better result is kept.

    ``screen`` (a chi-square): when no grid point gets below it, the candidate is not refined and
    its result is the best grid point (``message`` says so; no standard errors).

    ``second``: False leaves the second local fit to the caller (``second_start``), who runs it only
    for a candidate that still competes once every first fit is known; the result's
    ``second_from`` holds its start.
    """
    t0 = time.perf_counter()
    sims0 = ctx.sims
    bparams = tuple(base_fit.params) if base_fit is not None else ()
    bvalues = list(base_fit.values) if base_fit is not None else []
    eparams = cand.params
    defaults = [fp.nominal for fp in eparams]
    grid = cand.grid or ({},)
    points = []
    for g in grid:
        points.append([g.get(fp.name, d) for fp, d in zip(eparams, defaults)] + bvalues)
    all_params = tuple(eparams) + bparams
    # a second start (several parameters) needs the best point of another main value within SECOND_START of the best
    chis = scan_points(ctx, all_params, points, keep=SECOND_START if len(eparams) > 1 else 1.0, runner_up=len(eparams) > 1)
    best = int(np.argmin(chis))
    if screen is not None and chis[best] > screen:
        vec, _ = ctx.residual(all_params, points[best])
        chi2, parts = chi2_parts(ctx.model, vec)
        return FitResult(cand.name, tuple(all_params), list(points[best]), [math.nan] * len(all_params), chi2, parts,
                         ctx.model.size, ctx.sims - sims0, time.perf_counter() - t0,
                         "screened: no point of its grid removes enough to be refined",
                         [(dict(zip([fp.key for fp in all_params], p)), c) for p, c in zip(points, chis)])
    res = least_squares_fit(ctx, cand.name, all_params, points[best], max_nfev=max_nfev)
    if len(eparams) > 1:
        others = [i for i in np.argsort(chis) if points[i][0] != points[best][0]]
        if others and chis[others[0]] <= SECOND_START * chis[best]:
            if second:
                alt = least_squares_fit(ctx, cand.name, all_params, points[others[0]], max_nfev=max_nfev)
                if alt.chi2 < res.chi2:
                    res = alt
            else:
                res.second_from = list(points[others[0]])
    res.sims = ctx.sims - sims0
    res.seconds = time.perf_counter() - t0
    res.scan = [(dict(zip([fp.key for fp in all_params], p)), c) for p, c in zip(points, chis)]
    return res


def second_start(ctx: FitContext, first: FitResult, *, max_nfev: int = MAX_NFEV) -> FitResult:
    """``first`` or the second local fit from ``first.second_from``, whichever fits better (``fit_candidate``)."""
    t0 = time.perf_counter()
    alt = least_squares_fit(ctx, first.name, first.params, first.second_from, max_nfev=max_nfev)
    best = alt if alt.chi2 < first.chi2 else first
    out = dataclasses.replace(best, sims=first.sims + alt.sims, seconds=first.seconds + time.perf_counter() - t0,
                              second_from=None, scan=first.scan)
    out.cov = best.cov
    return out


def competing(fits, factor: float = COMPETE) -> list:
    """The fits that still compete: a chi-square within ``factor`` of the best one."""
    finite = [f.chi2 for f in fits if math.isfinite(f.chi2)]
    best = min(finite, default=math.inf)
    return [f for f in fits if f.chi2 <= factor * best]


__all__ = ["FitContext", "FitResult", "competing", "fit_candidate", "second_start", "replays_bound", "screen_level", "SINGLE_SCREEN_SHARE", "least_squares_fit", "scan_points", "chi2_parts"]
