"""Judging candidates in a worker: one campaign per candidate, verdicts only, many per task.

A task is a batch of candidates (index, settings). The worker holds the base configuration,
the requirement set and the planned runs (sent once), applies each candidate's settings,
runs every planned procedure x operating point in turn without plot traces, and judges the
requirements with the campaign's own :func:`~compliance.campaign.judge.judge`. What comes back
is small: per requirement the worst value, margin, margin % and status, and the basis the judge
gives it (a pass by construction is no pass: ``sweep.candidates.ranking``, as the campaign's own verdict).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from compliance.campaign.judge import judge
from compliance.campaign.plan import plan
from compliance.errors import GovcheckError
from compliance.procedures.outcomes import traces_off
from compliance.procedures.registry import run as run_procedure
from compliance.requirements.verdict import DISABLED, FAIL, NOT_EVALUATED, OPEN, PASS, overall_status
from compliance.sweep.candidates.parameter_paths import apply_values

__all__ = ["Context", "INVALID", "evaluate_batch", "evaluate_one", "make_context", "sweep_requirements"]

INVALID = "invalid"  # the settings make no physical plant (e.g. static below Coulomb friction)


@dataclass(frozen=True)
class Context:
    """What every worker needs once: base configuration, requirement set, planned runs, paths."""

    cfg: object
    reqset: object
    jobs: tuple
    paths: dict


def sweep_requirements(reqset, linear: bool):
    """The requirement set a sweep judges: linear-model requirements switched off unless asked.

    The linear analysis costs ~0.3 s per operating point and candidate, more than the whole
    nonlinear campaign's simulations of a candidate; sweeps judge nonlinear results unless the
    sweep file says ``linear = true``.
    """
    if linear:
        return reqset
    reqs = tuple(replace(r, enabled=False) if r.source == "linear" else r for r in reqset.requirements)
    return replace(reqset, requirements=reqs)


def make_context(cfg, reqset, paths: dict, linear: bool = False) -> Context:
    """The context of a sweep (the requirement set as judged, its planned runs)."""
    rs = sweep_requirements(reqset, linear)
    return Context(cfg, rs, tuple(plan(rs)), dict(paths))


def evaluate_one(ctx: Context, values: dict) -> dict:
    """Judge one candidate: ``{"status", "error", "requirements": {id: {...}}}``."""
    try:
        cfg = apply_values(ctx.cfg, ctx.paths, values)
        with traces_off():
            outcomes = [run_procedure(cfg, ctx.reqset.procedures[j.procedure],
                                      ctx.reqset.operating_points[j.operating_point], j.requests) for j in ctx.jobs]
        bad = next((o for o in outcomes if o.error and o.error_kind == "InputError"), None)
        if bad is not None:
            return {"status": INVALID, "error": f"run {bad.procedure}@{bad.operating_point}: {bad.error}", "requirements": {}}
        entries, _ = judge(cfg, ctx.reqset, list(ctx.jobs), outcomes)
    except GovcheckError as exc:  # settings outside physics: this candidate is invalid, the sweep goes on
        return {"status": INVALID, "error": str(exc), "requirements": {}}
    reqs = {}
    for e in entries:
        w = e["worst"] or {}
        reqs[e["id"]] = {"severity": e["severity"], "status": e["status"], "value": w.get("value"),
                         "margin": w.get("margin"), "margin_pct": w.get("margin_pct"), "where": w.get("run"),
                     "basis": e.get("basis")}
    judged = [(e["severity"], e["status"], e.get("basis")) for e in entries if e["status"] not in (OPEN, DISABLED)]
    return {"status": overall_status(judged), "error": None, "requirements": reqs}


def evaluate_batch(ctx: Context, batch: list) -> list:
    """Worker task: ``[(index, settings), ...]`` -> ``[(index, row), ...]``."""
    return [(i, evaluate_one(ctx, values)) for i, values in batch]


STATUSES = (PASS, FAIL, NOT_EVALUATED, OPEN, DISABLED, INVALID)
