"""Running many candidates on the one executor: batches of candidates per task, results in order.

A campaign of plant A is ~50 runs of 1-20 s simulated each; sending one candidate per task
would be fine for Dask's overhead (~1 ms) but batching a few candidates per task keeps the
per-task cost (pickling the rows, scheduling, progress) negligible and still leaves several
tasks per worker for balance (``batch_size``).
"""

from __future__ import annotations

import math

from compliance.campaign.executor import warm_up
from compliance.processes import map_tasks
from compliance.requirements.verdict import Severity, Status
from compliance.sweep.candidates.evaluate import Context, Unjudged, evaluate_batch, judged

__all__ = ["batch_size", "run_candidates", "shortfall", "total_shortfall"]


def batch_size(n: int, workers: int) -> int:
    """Candidates per task: about 4 tasks per worker, at most 16 candidates per task."""
    return max(1, min(16, math.ceil(n / (4 * max(1, workers)))))


def run_candidates(ctx: Context, candidates: list[dict], *, scheduler=None, workers=None, progress=True,
                   label="candidates", client=None, store=None):
    """Judge every candidate (settings dicts) -> (rows in candidate order, RunStats).

    A candidate whose task failed every retry gets a row with status ``failed`` so that the
    table still has one row per candidate and the summary counts it. With a ``store``
    (:class:`~compliance.sweep.candidates.candidate_store.CandidateStore`) candidates judged before are
    not judged again and the new ones are kept.
    """
    if store is not None:
        rows = [store.get(ctx, c) for c in candidates]
        todo = [i for i, r in enumerate(rows) if r is None]
        new, stats = run_candidates(ctx, [candidates[i] for i in todo], scheduler=scheduler, workers=workers,
                                    progress=progress, label=label, client=client)
        store.add(ctx, [(candidates[i], r) for i, r in zip(todo, new)])
        for i, r in zip(todo, new):
            rows[i] = r
        return rows, stats
    from compliance.processes import available_cores

    if not candidates:
        return [], None
    warm_up(ctx.cfg)  # compile (or load) the core once before a local pool forks
    w = workers or available_cores()
    if scheduler and scheduler.startswith("local:"):
        w = int(scheduler.split(":", 1)[1])
    b = batch_size(len(candidates), w)
    batches = [list(enumerate(candidates))[k:k + b] for k in range(0, len(candidates), b)]
    out, stats = map_tasks(evaluate_batch, ctx, batches, scheduler=scheduler, workers=workers, progress=progress,
                           label=label, client=client)
    rows: list = [None] * len(candidates)
    for batch, res in zip(batches, out):
        if res is None:  # every attempt of this task failed
            for i, _ in batch:
                rows[i] = {"status": Unjudged.FAILED, "error": "task failed on every attempt", "requirements": {}}
            continue
        for i, row in res:
            rows[i] = row
    return rows, stats


def shortfall(row: dict) -> float:
    """How far the worst mandatory requirement is from passing, in fractions of its limit (0 = passes).

    A requirement not evaluated, or an invalid candidate, counts as infinitely short.
    """
    if not judged(row):
        return math.inf
    worst = 0.0
    for r in row["requirements"].values():
        if r["severity"] != Severity.MANDATORY or r["status"] in (Status.OPEN, Status.DISABLED):
            continue
        if r["status"] == Status.NOT_EVALUATED or r["margin_pct"] is None:
            if r["status"] != Status.PASS:
                return math.inf
            continue
        worst = max(worst, -r["margin_pct"] / 100.0)
    return worst


def total_shortfall(row: dict) -> float:
    """Sum of the mandatory margins short of passing, in fractions of their limits (0 = passes)."""
    if not math.isfinite(shortfall(row)):
        return math.inf
    return sum(max(0.0, -r["margin_pct"] / 100.0) for r in row["requirements"].values()
               if r["severity"] == Severity.MANDATORY and r["status"] in (Status.PASS, Status.FAIL) and r["margin_pct"] is not None)
