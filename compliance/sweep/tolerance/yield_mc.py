"""Tolerance yield: Monte Carlo over the uncertain parameters of one candidate, seeded.

Each manufactured unit is the candidate with its uncertain parameters drawn around their
nominal values (``candidates.sampling.draw_units``, one ``default_rng(seed)`` in the parent). Each unit
is judged by the full campaign. Reported: the fraction of units passing each requirement and
all mandatory ones, with Wilson score intervals (Wilson 1927, the usual interval for a binomial
proportion that stays inside [0, 1] near 0 or 1); Spearman rank correlations of each
uncertain parameter with each margin (which tolerances drive the failures); histograms of the
margins. Draws that make no physical plant (e.g. static friction below Coulomb) are counted
as invalid and left out of the fractions.
"""

from __future__ import annotations

import math

import numpy as np

from compliance.sweep.candidates.ranking import candidate_passes
from compliance.sweep.candidates.runner import run_candidates, shortfall
from compliance.sweep.candidates.sampling import draw_units

__all__ = ["lower_bound", "nominal_values", "run_yield", "wilson"]

HIST_BINS = 20


def wilson(k: int, n: int, confidence: float) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion k/n at ``confidence``."""
    from scipy.stats import norm

    if n == 0:
        return 0.0, 1.0
    z = float(norm.ppf(0.5 + confidence / 2.0))
    p = k / n
    den = 1.0 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, mid - half), min(1.0, mid + half)


def lower_bound(k: int, n: int, confidence: float) -> float:
    """One-sided exact (Clopper-Pearson) lower confidence bound of a pass fraction k/n.

    ``lower_bound(59, 59, 0.95)`` = 0.9505: 59 passing units of 59 show >= 95 % yield at 95 %
    confidence (the success-run rule); the two-sided Wilson interval of :func:`wilson` is the
    table's, this is the acceptance statement's.
    """
    from scipy.stats import beta

    if n == 0 or k == 0:
        return 0.0
    return float(beta.ppf(1.0 - confidence, k, n - k + 1))


def nominal_values(cfg, paths: dict) -> dict:
    """SI value of each path in ``cfg`` (an effect that is off gives its declared default)."""
    from compliance.effects import EFFECTS

    out = {}
    for path, pp in paths.items():
        if pp.effect:
            out[path] = float(cfg.effects.get(pp.effect, EFFECTS[pp.effect].defaults()).get(pp.name,
                                                                                             EFFECTS[pp.effect].param(pp.name).default))
        else:
            out[path] = float(cfg.params[path])
    return out


def _drivers(units, rows, uncertain, ids):
    from scipy.stats import spearmanr

    out = []
    short = np.array([-shortfall(r) if math.isfinite(shortfall(r)) else np.nan for r in rows])
    for u in uncertain:
        x = np.array([d[u.param.path] for d in units])
        entry = {"path": u.param.path, "worst_margin": None, "by_requirement": {}}
        for rid in ids + ["__worst__"]:
            y = short if rid == "__worst__" else np.array(
                [r["requirements"].get(rid, {}).get("margin_pct") or np.nan for r in rows], float)
            ok = np.isfinite(y)
            if ok.sum() < 3 or np.ptp(x[ok]) == 0 or np.ptp(y[ok]) == 0:
                rho = None
            else:
                rho = float(spearmanr(x[ok], y[ok]).statistic)
            if rid == "__worst__":
                entry["worst_margin"] = rho
            else:
                entry["by_requirement"][rid] = rho
        out.append(entry)
    out.sort(key=lambda e: -abs(e["worst_margin"] or 0.0))
    return out


def _requirement_yield(rows, rid, confidence):
    sts = [r["requirements"][rid]["status"] for r in rows if rid in r["requirements"]]
    judged = [s for s in sts if s in ("pass", "fail", "not_evaluated")]
    k = sum(1 for s in judged if s == "pass")
    lo, hi = wilson(k, len(judged), confidence)
    m = np.array([r["requirements"][rid]["margin_pct"] for r in rows
                  if rid in r["requirements"] and r["requirements"][rid]["margin_pct"] is not None], float)
    hist = None
    if m.size:
        counts, edges = np.histogram(m, bins=HIST_BINS)
        hist = {"counts": counts.tolist(), "edges": edges.tolist()}
    return {"requirement": rid, "severity": rows[0]["requirements"][rid]["severity"], "units": len(judged), "pass": k,
            "fraction": k / len(judged) if judged else None, "ci": [lo, hi], "margin_pct_histogram": hist,
            "margin_pct_median": float(np.median(m)) if m.size else None}


def run_yield(ctx, cfg, candidate: dict, uncertain, *, units: int, seed: int, confidence: float, run_kw=None):
    """Monte Carlo tolerance yield of ``candidate`` (settings dict over ``cfg``).

    Returns
    -------
    tuple
        (yield dict, unit settings list, rows, RunStats)
    """
    nominal = nominal_values(cfg, {u.param.path: u.param for u in uncertain})
    nominal.update({k: v for k, v in candidate.items() if k in nominal})
    draws = draw_units(uncertain, nominal, units, seed)
    settings = [{**candidate, **d} for d in draws]
    rows, stats = run_candidates(ctx, settings, **{"label": "yield", **(run_kw or {})})
    valid = [r for r in rows if r["status"] not in ("invalid", "failed")]
    vunits = [d for d, r in zip(draws, rows) if r["status"] not in ("invalid", "failed")]
    ids = sorted({rid for r in valid for rid, e in r["requirements"].items() if e["status"] not in ("open", "disabled")})
    k_all = sum(1 for r in valid if candidate_passes(r))
    lo, hi = wilson(k_all, len(valid), confidence)
    out = {
        "candidate": {k: float(v) for k, v in candidate.items()},
        "units": units, "seed": seed, "confidence": confidence,
        "valid": len(valid), "invalid": sum(1 for r in rows if r["status"] == "invalid"),
        "failed_tasks": sum(1 for r in rows if r["status"] == "failed"),
        "uncertain": [{"path": u.param.path, "unit": u.param.unit, "distribution": u.distribution,
                       "spread": u.spread, "relative": u.relative, "nominal": nominal[u.param.path]} for u in uncertain],
        "all_mandatory": {"pass": k_all, "fraction": k_all / len(valid) if valid else None, "ci": [lo, hi],
                          "lower_bound": lower_bound(k_all, len(valid), confidence)},
        "requirements": [_requirement_yield(valid, rid, confidence) for rid in ids] if valid else [],
        "drivers": _drivers(vunits, valid, uncertain, ids) if valid else [],
    }
    return out, draws, rows, stats
