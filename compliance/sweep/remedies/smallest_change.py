"""What would make it pass: local sensitivities, the smallest combined change, verified by a campaign.

1. Judge the configuration as it is and, for each adjustable parameter, once more with that
   parameter moved by ``STEP`` (10 %) of its declared range: finite-difference sensitivities
   of every mandatory requirement's margin (in % of its limit) to every parameter, from the
   same simulations the campaign runs.
2. Linearise the margins and solve for the smallest change from the base (Euclidean, in
   normalised units u = (value - low) / (high - low)) that lifts every mandatory margin above
   ``TARGET`` inside the declared box and a trust region (scipy SLSQP).
3. Judge that candidate; if every mandatory requirement passes, verify it with a full
   campaign (``run_campaign``, traces and all); else re-linearise there (up to ``iterations``)
   with a smaller trust region when it did not improve.
   A requirement the linearised margins cannot bring to the target anywhere in the box (it
   hardly moves with any parameter) is set aside for the step, so the search still fixes
   the others; it is named in the result as out of reach.
4. If nothing passes, the closest candidate judged and the requirement that binds it are
   reported: evidence, not a proof, that the declared space holds no pass. Closest =
   ``sweep.candidates.ranking``: fewest failing mandatory requirements, then the smallest sum of
   shortfalls, then the smallest change; the configuration as given is among the judged, so
   the closest never fails more mandatory requirements than it.

Values in ``fixed`` (hardware options of the catalogue) are set on every candidate judged.
"""

from __future__ import annotations

import math

import numpy as np

from compliance.requirements.verdict import Severity, Status
from compliance.sweep.candidates.evaluate import judged
from compliance.sweep.candidates.results import change
from compliance.sweep.candidates.ranking import SETTINGS_COST, candidate_passes, failing_mandatory, rank_key
from compliance.sweep.candidates.runner import run_candidates, shortfall
from compliance.sweep.candidates.sampling import from_normalised, to_normalised
from compliance.presentation.numbers import fmt_margin_pct
from compliance.sweep.remedies.outcome import RemedyStatus

__all__ = ["STEP", "TARGET", "binding", "closeness", "describe_candidate", "find_remedy", "mandatory_margins", "unreachable"]

STEP = 0.1  # finite-difference step, fraction of each declared range
TARGET = 0.02  # margin (fraction of the limit) the linear step aims for, against the model's curvature


def mandatory_margins(row: dict) -> dict:
    """Mandatory requirement id -> margin as a fraction of its limit (judged ones only)."""
    return {rid: r["margin_pct"] / 100.0 for rid, r in row["requirements"].items()
            if r["severity"] == Severity.MANDATORY and r["status"] in (Status.PASS, Status.FAIL) and r["margin_pct"] is not None}


def binding(row: dict) -> tuple[str | None, float | None]:
    """The mandatory requirement with the smallest margin % and that margin."""
    m = mandatory_margins(row)
    if not m:
        return None, None
    rid = min(m, key=m.get)
    return rid, 100.0 * m[rid]


def _sensitivities(adjust, u0, row0, probe_rows, steps):
    m0 = mandatory_margins(row0)
    ids = sorted(m0)
    J = np.zeros((len(ids), len(adjust)))
    for k, (row, du) in enumerate(zip(probe_rows, steps)):
        mk = mandatory_margins(row) if judged(row) else {}
        for r, rid in enumerate(ids):
            if rid in mk and du != 0.0:
                J[r, k] = (mk[rid] - m0[rid]) / du
    return ids, np.array([m0[i] for i in ids]), J


def _probes(adjust, u0):
    us, steps = [], []
    for k in range(len(adjust)):
        du = STEP if u0[k] + STEP <= 1.0 else -STEP
        u = u0.copy()
        u[k] = u0[k] + du
        us.append(u)
        steps.append(du)
    return us, steps


def unreachable(u0, m0, J) -> np.ndarray:
    """Rows whose linearised margin stays below TARGET everywhere in the box [0, 1]."""
    best = m0 + np.sum(np.maximum(J * (0.0 - u0), J * (1.0 - u0)), axis=1)
    return best < TARGET


def _least_change(ubase, u0, m0, J, radius):
    """min ||u - ubase||^2 s.t. m0 + J (u - u0) >= TARGET (reachable rows), 0 <= u <= 1, |u - u0| <= radius."""
    from scipy.optimize import minimize

    keep = ~unreachable(u0, m0, J)
    m0, J = m0[keep], J[keep]
    lo = np.maximum(0.0, u0 - radius)
    hi = np.minimum(1.0, u0 + radius)
    cons = [{"type": "ineq", "fun": lambda u: m0 + J @ (u - u0) - TARGET, "jac": lambda u: J}] if len(m0) else []
    res = minimize(lambda u: float(np.sum((u - ubase) ** 2)), np.clip(u0, lo, hi), jac=lambda u: 2 * (u - ubase),
                   bounds=list(zip(lo, hi)), constraints=cons, method="SLSQP", options={"maxiter": 200})
    if res.success or not len(m0):
        return res.x
    # not reachable inside the trust region: go as far as it allows toward the worst reachable margin
    g = J[int(np.argmin(m0))]
    return np.clip(u0 + radius * np.sign(g), lo, hi)


def closeness(row: dict, values: dict, adjust, start: dict, cost: float = 0.0) -> tuple:
    """Ranking key of a candidate (smaller is closer to passing; ``sweep.candidates.ranking.rank_key``)."""
    return rank_key(row, cost + SETTINGS_COST * change(adjust, start, values))


def _sensitivity_table(adjust, ids, m0, J, failed):
    out = []
    for r, rid in enumerate(ids):
        if rid not in failed:
            continue
        by = [{"path": a.param.path, "unit": a.param.unit, "step": STEP * a.span,
               "delta_margin_pct": float(100.0 * J[r, k] * STEP)} for k, a in enumerate(adjust)]
        by.sort(key=lambda d: -abs(d["delta_margin_pct"]))
        out.append({"requirement": rid, "margin_pct": float(100.0 * m0[r]), "by_parameter": by})
    return out


def describe_candidate(adjust, base, values, row) -> dict:
    """A judged candidate as the remedies section reports it: values, changes from ``base``, binding, failing."""
    rid, marg = binding(row)
    return {
        "values": {k: float(v) for k, v in values.items()},
        "changes": [{"path": a.param.path, "unit": a.param.unit, "from": float(base[a.param.path]),
                     "to": float(values[a.param.path])} for a in adjust
                    if abs(values[a.param.path] - base[a.param.path]) > 1e-6 * a.span],  # unchanged to round-off
        "change": change(adjust, base, values),
        "status": row["status"],
        "shortfall_pct": 100.0 * shortfall(row) if math.isfinite(shortfall(row)) else None,
        "binding": rid,
        "binding_margin_pct": marg,
        "binding_where": row["requirements"][rid].get("where") if rid else None,
        "failed_mandatory": failing_mandatory(row),
        "by_construction": sorted(r for r in failing_mandatory(row) if row["requirements"].get(r, {}).get("status") == Status.PASS),
        "total_shortfall": rank_key(row, 0.0)[1],
    }


def _clamped_base(adjust, base):
    return {a.param.path: float(min(max(base[a.param.path], a.low), a.high)) for a in adjust}


def find_remedy(ctx, adjust, base: dict, *, verify, iterations: int = 4, seeds=(), run_kw=None, fixed=None,
                cost: float = 0.0, report_base=None) -> dict:
    """Sensitivities and the smallest verified change that passes every mandatory requirement.

    Parameters
    ----------
    ctx : compliance.sweep.candidates.evaluate.Context
    adjust : tuple of Adjustable
    base : dict
        path -> SI value of the configuration as it is (clamped into the declared box).
    verify : callable
        settings dict -> results dict of a full campaign of the changed configuration.
    iterations : int
        Re-linearisations after the first step.
    seeds : list of (settings, row)
        Candidates already judged (a sweep's samples): the search may start from the closest.
    run_kw : dict
        Passed to :func:`~compliance.sweep.candidates.runner.run_candidates` (scheduler, workers, progress, client).
    fixed : dict
        path -> SI value set on every candidate (hardware options); ``verify`` receives them too.
    cost : float
        Cost of the fixed hardware (ranking).
    report_base : dict
        Values the reported changes are measured from (default: ``base``; a later stage gives the configuration's).

    Returns
    -------
    dict
        The ``remedies`` section of the results (docs/results-schema.md).
    """
    run_kw = dict(run_kw or {})
    run_kw.setdefault("label", "remedies")
    run_kw["fixed"] = dict(fixed or {})
    start = _clamped_base(adjust, base)
    ubase = to_normalised(adjust, start)
    (row0,), _ = _judge(ctx, [start], **run_kw)
    judged = [(start, row0)] + list(seeds)
    space = [{"path": a.param.path, "unit": a.param.unit, "low": a.low, "high": a.high, "base": float(base[a.param.path])}
             for a in adjust]
    out = {"status": RemedyStatus.ALREADY_PASSES, "space": space, "failed": [], "sensitivities": [], "out_of_reach": [],
           "remedy": None, "closest": None, "evaluated": 1 + len(seeds), "note": ""}
    if candidate_passes(row0):
        out["note"] = "every mandatory requirement passes as configured: nothing to change"
        out["closest"] = describe_candidate(adjust, start, start, row0)
        return out
    out["failed"] = failing_mandatory(row0)

    def key(t):
        return closeness(t[1], t[0], adjust, start, cost)

    u0 = ubase
    ids, m0, J = _linearise(ctx, adjust, u0, row0, run_kw, judged, out)
    out["sensitivities"] = _sensitivity_table(adjust, ids, m0, J, set(out["failed"]))
    out["out_of_reach"] = [rid for rid, bad in zip(ids, unreachable(u0, m0, J)) if bad]
    cur, cur_row = min([(start, row0)] + list(seeds), key=key)
    radius = 0.5
    for it in range(iterations + 1):
        if it or cur is not start:  # at the base the probes are the sensitivities above
            u0 = to_normalised(adjust, cur)
            ids, m0, J = _linearise(ctx, adjust, u0, cur_row, run_kw, judged, out)
        u_new = _least_change(ubase, u0, m0, J, radius) if ids else u0
        cand = from_normalised(adjust, u_new)
        (row,), _ = _judge(ctx, [cand], **run_kw)
        out["evaluated"] += 1
        judged.append((cand, row))
        if candidate_passes(row):
            results = verify({**cand, **run_kw["fixed"]})
            remedy = describe_candidate(adjust, start, cand, row)
            remedy["verified"] = {"status": results.summary.status, "failed_mandatory": list(results.summary.failed_mandatory)}
            if results.passed:
                out.update(status=RemedyStatus.FOUND, remedy=remedy,
                           note=f"verified by a full campaign of the changed configuration ({len(results.runs)} runs)")
                return out
        if key((cand, row)) < key((cur, cur_row)):
            cur, cur_row = cand, row
        else:
            radius *= 0.5
    return _none_found(out, adjust, start, min(judged, key=key))


def _linearise(ctx, adjust, u0, row, run_kw, judged, out):
    """Judge the probes around ``u0``; finite-difference margins (ids, m0, J). Appends to ``judged``."""
    us, steps = _probes(adjust, u0)
    settings = [from_normalised(adjust, u) for u in us]
    probe_rows, _ = _judge(ctx, settings, **run_kw)
    out["evaluated"] += len(us)
    judged += list(zip(settings, probe_rows))
    return _sensitivities(adjust, u0, row, probe_rows, steps)


def _judge(ctx, settings, *, fixed, **run_kw):
    """Judge settings with the fixed (hardware) values set on each -> (rows, RunStats)."""
    return run_candidates(ctx, [{**s, **fixed} for s in settings], **run_kw)


def _none_found(out, adjust, start, closest):
    out.update(status=RemedyStatus.NONE_FOUND, closest=describe_candidate(adjust, start, *closest))
    rid = out["closest"]["binding"]
    reach = (f" Out of reach of every declared parameter by the local sensitivities: {', '.join(out['out_of_reach'])}."
             if out["out_of_reach"] else "")
    out["note"] = (f"no candidate of the {out['evaluated']} judged in the declared space passes every mandatory requirement; "
                   f"the closest is stopped by {rid} (margin {fmt_margin_pct(out['closest']['binding_margin_pct'])}).{reach} "
                   "This is the evidence of a search, not a proof that no pass exists.")
    return out
