"""Uncertainty bands on the verdicts: the plant file's declared ranges propagated by local sensitivities.

Every parameter a plant file gives a plausible ``range`` (``compliance.model.assumptions``) is moved,
one at a time, to each end of its range, and the run behind each requirement's deciding (worst) row
is repeated on the campaign executor and judged again. The changes of the row's value are that
parameter's two swings (no linearity assumed between the ends; a response that turns back inside
the range is the one case the ends miss). The band is the interval sum of the swings (each
parameter anywhere in its range, the worst combination):

    low  = v0 + sum_k min(0, d_k+, d_k-)        high = v0 + sum_k max(0, d_k+, d_k-)

A verdict whose band straddles its limit is ``uncertain``; the parameters that decide it are the
largest swings towards the limit, in order, until they cover the margin. ``govcheck check
--uncertainty N`` replaces the local band by a Latin-hypercube Monte Carlo over the same ranges
(``compliance.sweep.tolerance.uncertainty_mc``). docs/requirements.md, "Uncertainty".
"""

from __future__ import annotations

from compliance.processes import map_tasks
from compliance.campaign.judge import judge_row
from compliance.procedures.outcomes import traces_off
from compliance.procedures.registry import run as run_procedure
from compliance.requirements.verdict import Basis, Status, evaluate

__all__ = ["apply_band", "local_bands", "ranged_parameters", "top_assumptions"]


def ranged_parameters(cfg) -> list[tuple[str, dict]]:
    """(dotted key, range) of every parameter the plant file gives a range, in file order."""
    return [(k, a["range"]) for k, a in cfg.assumptions.items() if a.get("range")]


def _perturbed_run(ctx, item):
    """Worker: one run with one parameter moved -> (samples by request key, error)."""
    cfg, reqset, jobs = ctx
    key, value, j = item
    moved = cfg.replace(params={key: value}, sources={key: cfg.sources.get(key, "user")})
    job = jobs[j]
    with traces_off():
        out = run_procedure(moved, reqset.procedures[job.procedure], reqset.operating_points[job.operating_point], job.requests)
    return out.samples, out.error


# a verdict farther than this from its limit (margin in % of the limit) gets no local band: the declared
# ranges move plant A's figures by tens of per cent at most, so it cannot reach the limit (govcheck's choice;
# the Monte Carlo of --uncertainty N bands every verdict)
FAR_MARGIN_PCT = 100.0


def _targets(entries, far: float | None = None) -> list[dict]:
    """Requirements whose deciding row is a modelled (or assumed) simulated value with a verdict
    (and, with ``far``, a margin within ``far`` per cent of the limit)."""
    out = [e for e in entries if e["source"] == "simulation" and e["status"] in (Status.PASS, Status.FAIL) and e.get("worst")
           and e["worst"].get("basis") in (Basis.MODELLED, Basis.ASSUMED) and e["worst"].get("value") is not None]
    if far is None:
        return out
    return [e for e in out if e["worst"].get("margin_pct") is None or abs(e["worst"]["margin_pct"]) <= far]


def _deciding(swings: dict, margin: float, toward_limit_sign: float) -> list[str]:
    """Parameters whose swings towards the limit, largest first, cover ``margin``."""
    order = sorted(((max(max(0.0, toward_limit_sign * d) for d in s), k) for k, s in swings.items()), reverse=True)
    out, covered = [], 0.0
    for amount, k in order:
        if amount <= 0.0:
            break
        out.append(k)
        covered += amount
        if covered >= abs(margin):
            break
    return out


def apply_band(e: dict, low: float, high: float, swings: dict, method: str) -> None:
    """Put a band on requirement entry ``e`` (worst row and entry) and make it UNCERTAIN if it straddles the limit."""
    w = e["worst"]
    lim = tuple(w.get("limit") or e["limit"])
    ends = [evaluate(v, e["comparator"], lim) for v in (low, high)]
    straddles = len({v.status for v in ends} | {w["status"]}) > 1
    # which way is the limit from the value: a failing value needs the margin to grow, a passing one to shrink
    v0 = w["value"]
    sign = 1.0
    if e["comparator"] in ("<=", "<"):
        sign = 1.0 if w["status"] == Status.PASS else -1.0
    elif e["comparator"] in (">=", ">"):
        sign = -1.0 if w["status"] == Status.PASS else 1.0
    else:
        mid = 0.5 * (lim[0] + lim[1])
        sign = (1.0 if v0 >= mid else -1.0) * (1.0 if w["status"] == Status.PASS else -1.0)
    band = {"low": low, "high": high, "method": method,
            "margin_low_pct": min(x.margin_pct for x in ends) if all(x.margin_pct is not None for x in ends) else None,
            "margin_high_pct": max(x.margin_pct for x in ends) if all(x.margin_pct is not None for x in ends) else None,
            "deciding": _deciding(swings, w["margin"] or 0.0, sign) if straddles else [],
            "swings": {k: list(s) for k, s in swings.items()}}
    w["band"] = band
    e["band"] = band
    for r in e["rows"]:
        if r["run"] == w["run"] and r.get("which") == w.get("which"):
            r["band"] = band
            if straddles:
                r["status"] = Status.UNCERTAIN
    if straddles:
        w["status"] = Status.UNCERTAIN
        e["status"] = Status.UNCERTAIN


def local_bands(cfg, reqset, jobs, entries, *, workers=None, progress=False) -> dict:
    """Local-sensitivity bands on every modelled verdict (see the module docstring); entries are updated in place.

    Parameters
    ----------
    cfg : PlantConfig
    reqset : RequirementSet
    jobs : list of Job
        The campaign's planned runs.
    entries : list of dict
        The judge's requirement entries.
    workers : int, optional
        Local pool size.

    Returns
    -------
    dict
        ``{"method": "local", "parameters": [...], "runs": N, "top_assumptions": [...]}``.
    """
    ranged = ranged_parameters(cfg)
    targets = _targets(entries, FAR_MARGIN_PCT)
    index = {j.key: i for i, j in enumerate(jobs)}
    need = sorted({index[e["worst"]["run"]] for e in targets})
    items = [(k, rng[end], j) for k, rng in ranged for end in ("low", "high") for j in need]
    results, _ = map_tasks(_perturbed_run, (cfg, reqset, list(jobs)), items, workers=workers, progress=progress,
                           label="uncertainty") if items else ([], None)
    got = {(k, v, j): r for (k, v, j), r in zip(items, results)}
    by_id = {r.id: r for r in reqset.requirements}
    for e in targets:
        req, w = by_id[e["id"]], e["worst"]
        j = index[w["run"]]
        swings = {}
        for k, rng in ranged:
            ends = []
            for v in (rng["high"], rng["low"]):
                res = got.get((k, v, j))
                row = judge_row(req, w["procedure"], w["operating_point"], tuple(w.get("limit") or e["limit"]),
                                res[0].get(e["request_key"]), res[1]) if res else {"value": None}
                ends.append(None if row["value"] is None else row["value"] - w["value"])
            if None not in ends:
                swings[k] = tuple(ends)  # (change at the top of the range, change at the bottom)
        low = w["value"] + sum(min(0.0, *s) for s in swings.values())
        high = w["value"] + sum(max(0.0, *s) for s in swings.values())
        apply_band(e, low, high, swings, "local")
    return {"method": "local", "parameters": [{"parameter": k, **rng} for k, rng in ranged], "runs": len(items),
            "far_margin_pct": FAR_MARGIN_PCT,
            "top_assumptions": top_assumptions(entries, cfg)}


def top_assumptions(entries, cfg, n: int = 3) -> list[dict]:
    """The ``n`` ranged parameters that matter most: the largest swing relative to a verdict's margin."""
    score: dict[str, tuple[float, str]] = {}
    for e in entries:
        band = e.get("band")
        w = e.get("worst") or {}
        if not band or w.get("margin") is None:
            continue
        m = max(abs(w["margin"]), 1e-12)
        for k, s in band["swings"].items():
            r = max(abs(d) for d in s) / m
            if r > score.get(k, (0.0, ""))[0]:
                score[k] = (r, f"moves {e['id']} by up to {max(abs(d) for d in s) / m:.0%} of its margin")
    top = sorted(score.items(), key=lambda kv: -kv[1][0])[:n]
    return [{"parameter": k, "score": r, "why": why, "range": (cfg.assumptions.get(k) or {}).get("range")} for k, (r, why) in top]
