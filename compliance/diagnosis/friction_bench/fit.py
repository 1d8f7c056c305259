"""Friction laws fitted to seal-bench runs: bounded least squares on every sample, normalised residuals.

Each law (``LAWS``) is fitted to all runs of one seal at once. The residual of a sample is
(measured - bias - friction) / force noise floor, over the samples whose velocity estimate
is not smeared across a reversal (``Run.valid``). The nonlinear parameters (Stribeck
velocity, bristle stiffness) are scanned coarsely first; standard errors come from the
Jacobian with the reduced chi-square and the residuals' lag-1 autocorrelation folded in.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from compliance.diagnosis.friction_bench.laws import bias_force, friction_force
from compliance.diagnosis.friction_bench.position import POSITION_FRICTION, reference_position
from compliance.diagnosis.friction_bench.pressure_shape import NONLINEAR_PRESSURE, PRESSURE_FORCE, reference_pressure
from compliance.diagnosis.friction_bench.running_in import FRICTION_DRIFT
from compliance.diagnosis.friction_bench.runs import Run
from compliance.diagnosis.verdicts.candidate_set import CandidateSet


MAX_NFEV = 100  # least-squares evaluations per candidate law (besides the Jacobian's); the real runs stop on ftol well before
PRESSURE_EFFECT = "pressure_dependent_friction"
PRESLIDING = "presliding_hysteresis"
POSITION_EFFECT = POSITION_FRICTION.name
BENCH_EFFECTS = (NONLINEAR_PRESSURE, PRESSURE_FORCE, POSITION_FRICTION, FRICTION_DRIFT)  # declared, each kept only if it earns its place held out
LAWS = {  # candidate -> (pressure dependent, pre-sliding)
    "baseline": (False, False),
    PRESSURE_EFFECT: (True, False),
    PRESLIDING: (False, True),
    CandidateSet.of((PRESSURE_EFFECT, PRESLIDING)).name: (True, True),
}


@dataclass
class LawFit:
    """A friction law fitted to all runs of a seal."""

    name: str
    params: dict
    stderr: dict
    chi2: float
    k: int
    n: int
    residuals: list  # per run, [N]
    seconds: float = 0.0
    sims: int = 0

    def rms_per_run(self) -> list[float]:
        """RMS residual of each run [N]."""
        return [float(np.sqrt(np.mean(r * r))) for r in self.residuals]


_SPEC = {  # name -> (low, high, log); FIT_BOUNDS below is the public name (the report flags values at a bound)
    "bias": (-100.0, 100.0, False),
    "bias_per_pressure": (-2e-4, 2e-4, False),
    "coulomb": (0.0, 1000.0, False),
    "excess": (0.0, 1000.0, False),
    "stribeck_velocity": (1e-4, 0.05, True),
    "viscous": (0.0, 1e4, False),
    "pressure_coefficient": (0.0, 1e-3, False),
    "bristle_stiffness": (1e2, 1e8, True),
    **{q.name: (q.bounds[0], q.bounds[1], q.log_scale) for e in BENCH_EFFECTS for q in e.params},
}


# fit coordinate = value / scale for parameters many decades below 1 in SI (a well-conditioned Jacobian)
_SCALE = {"bias_per_pressure_squared": 1e-12}


def _coord(name: str, value: float) -> float:
    """A parameter's value [SI] in the fit's coordinates (log10, or divided by its ``_SCALE``)."""
    return math.log10(value) if _SPEC[name][2] else value / _SCALE.get(name, 1.0)


def law_flags(name: str) -> tuple[bool, bool, bool]:
    """(pressure dependent, pre-sliding, position dependent) of a law named by its effects joined by ``+``."""
    parts = set(CandidateSet.parse(name).terms)
    return PRESSURE_EFFECT in parts, PRESLIDING in parts, POSITION_EFFECT in parts


FIT_BOUNDS = _SPEC


def _names(name: str) -> list[str]:
    """The fitted parameters of the law ``name`` (in the fit's order)."""
    parts = set(CandidateSet.parse(name).terms)
    names = ["bias", "bias_per_pressure", "coulomb", "excess", "stribeck_velocity", "viscous"]
    if PRESSURE_EFFECT in parts or NONLINEAR_PRESSURE.name in parts:
        names.append("pressure_coefficient")
    if PRESLIDING in parts:
        names.append("bristle_stiffness")
    names += [q.name for e in BENCH_EFFECTS if e.name in parts for q in e.params]
    return names


def _fixed(runs: list[Run], name: str) -> dict:
    """Reference values of the law ``name`` taken from the runs, not fitted (x_r, p_r)."""
    parts = set(CandidateSet.parse(name).terms)
    fixed = {"reference_position": reference_position(runs)} if POSITION_EFFECT in parts else {}
    if NONLINEAR_PRESSURE.name in parts:
        fixed["reference_pressure"] = reference_pressure(runs)
    return fixed


def _to_params(names, x, fixed: dict | None = None) -> dict:
    p = dict(fixed or {})
    for n, v in zip(names, x):
        lo, hi, log = _SPEC[n]
        p[n] = 10.0 ** v if log else float(v) * _SCALE.get(n, 1.0)
    p["static"] = p["coulomb"] + p.pop("excess")
    return p


def _residuals(runs: list[Run], params: dict, presliding: bool) -> list[np.ndarray]:
    return [(r.friction - _force(r, params, presliding))[r.valid] for r in runs]


def _force(run: Run, params: dict, presliding: bool) -> np.ndarray:
    return bias_force(run.pressure_gauge, params) + friction_force(run.velocity, run.pressure_gauge, run.time, params,
                                                                   presliding=presliding, position=run.position)


def predict(run: Run, fit: LawFit) -> np.ndarray:
    """The law's force (bias + friction) at every sample of a run [N] (a run it was not fitted on, too)."""
    return _force(run, fit.params, law_flags(fit.name)[1])


def _start(runs: list[Run]) -> dict:
    """Starting values from the steady-sliding medians of each direction."""
    pos, neg = [], []
    for r in runs:
        m = r.sliding
        pos.append(r.friction[m & (r.velocity > 0)])
        neg.append(r.friction[m & (r.velocity < 0)])
    fp = float(np.median(np.concatenate(pos))) if any(a.size for a in pos) else 1.0
    fn = float(np.median(np.concatenate(neg))) if any(a.size for a in neg) else -1.0
    return {"bias": 0.5 * (fp + fn), "bias_per_pressure": 0.0, "coulomb": max(0.5 * (fp - fn), 0.1), "excess": 0.1 * max(0.5 * (fp - fn), 0.1),
            "stribeck_velocity": math.log10(2e-3), "viscous": 0.0, "pressure_coefficient": 0.0, "bristle_stiffness": 4.0,
            **{q.name: _coord(q.name, q.default) for e in BENCH_EFFECTS for q in e.params}}


def fit_law(runs: list[Run], name: str, start: dict | None = None) -> LawFit:
    """Fit one candidate law (``LAWS[name]``) to all runs by bounded least squares."""
    t0 = time.perf_counter()
    presliding = law_flags(name)[1]
    names = _names(name)
    fixed = _fixed(runs, name)
    floors = [r.floor for r in runs]
    s0 = dict(_start(runs))
    if start:
        s0.update(start)
    lo = np.array([_coord(n, _SPEC[n][0]) for n in names])
    hi = np.array([_coord(n, _SPEC[n][1]) for n in names])
    count = [0]

    def fun(x):
        count[0] += 1
        p = _to_params(names, x, fixed)
        return np.concatenate([res / fl for res, fl in zip(_residuals(runs, p, presliding), floors)])

    margin = np.minimum(1e-9, 1e-6 * (hi - lo))  # inside the bounds, also for a range far below 1e-9 (c2 in N/Pa^2)
    x_start = np.clip(np.array([s0[n] for n in names], dtype=float), lo + margin, hi - margin)

    def cost(x):
        r0 = fun(x)
        return float(r0 @ r0)

    # coarse scans of the nonlinear parameters (v_s, then sigma0) before least squares: the map's
    # Stribeck dip and the bristles' pre-sliding trade off, and a poor start finds the wrong one
    scans = [("stribeck_velocity", [-3.0, -2.5, -2.0, -1.5])]
    if presliding and "bristle_stiffness" not in (start or {}):
        scans.append(("bristle_stiffness", [3.0, 3.5, 4.0, 4.5, 5.0, 5.5, 6.0, 7.0]))
    if "pressure_exponent" in names and "pressure_exponent" not in (start or {}):  # k_p p_r fixed: n bends the rise about p_r
        scans.append(("pressure_exponent", [math.log10(e) for e in (0.5, 0.75, 1.5, 2.0, 3.0, 4.0)]))
    for pname, grid in scans:
        j = names.index(pname)
        trials = []
        for e in [x_start[j]] + grid:
            x = x_start.copy()
            x[j] = e
            trials.append((cost(x), e))
        x_start[j] = min(trials)[1]
    best = least_squares(fun, x_start, bounds=(lo, hi), x_scale="jac", method="trf", max_nfev=MAX_NFEV, ftol=1e-5)
    r = best.fun
    chi2 = float(r @ r)
    n = r.size
    k = len(names)
    params = _to_params(names, best.x, fixed)
    stderr = _param_stderr(names, best, chi2, n)
    return LawFit(name, params, stderr, chi2, k, n, _residuals(runs, params, presliding), time.perf_counter() - t0, count[0])


def _param_stderr(names, res, chi2, n) -> dict:
    k = len(names)
    # residuals of a bench run are serially correlated: inflate by the AR(1) factor (1+rho)/(1-rho)
    r = res.fun
    rho = float(np.dot(r[1:], r[:-1]) / np.dot(r, r)) if r.size > 2 and np.dot(r, r) > 0 else 0.0
    rho = min(max(rho, 0.0), 0.99)
    s2 = max(1.0, chi2 / max(n - k, 1)) * (1 + rho) / (1 - rho)
    try:
        # columns scaled to unit norm first: k_p and c1 (N/Pa) span ten decades against the rest, and an unscaled
        # pseudo-inverse would cut the small directions and report standard errors far too small
        d = np.linalg.norm(res.jac, axis=0)
        d[d == 0] = 1.0
        js = res.jac / d
        cov = np.linalg.pinv(js.T @ js) / np.outer(d, d) * s2
        su = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:
        su = np.full(k, np.inf)
    x = _to_params(names, res.x)
    out = {}
    for nme, s, xv in zip(names, su, res.x):
        if _SPEC[nme][2]:
            out[nme] = float(10.0 ** xv * math.log(10.0) * s)
        else:
            out["static" if nme == "excess" else nme] = float(s) * _SCALE.get(nme, 1.0)
    out.setdefault("static", float("nan"))
    return {k2: out.get(k2, float("nan")) for k2 in x}


def law_scores(fits: dict, n: int) -> dict:
    """BIC scores of the fitted laws (``servo.selection.score_all``; the baseline in the role of the nominal)."""
    from compliance.diagnosis.servo.fit import FitResult
    from compliance.diagnosis.servo.selection import score_all

    scores = score_all({"nominal" if k == "baseline" else k: FitResult(f.name, tuple(range(f.k)), [], [], f.chi2, {}, f.n)
                        for k, f in fits.items()}, n)
    if "nominal" in scores:
        scores["baseline"] = scores.pop("nominal")
    return scores


def start_from(params: dict) -> dict:
    """Starting values (in the fit's own coordinates) at a fitted law's parameters: a refit starts where it ended."""
    out = {k: v for k, v in params.items() if k in _SPEC}
    out["excess"] = max(params["static"] - params["coulomb"], 0.0)
    return {k: _coord(k, v) for k, v in out.items()}
