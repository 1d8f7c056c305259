"""A campaign's runs on the one executor (:func:`compliance.processes.map_tasks`).

The campaign's jobs (procedure x operating point) are one ``map_tasks`` call whose context is
the configuration and the requirement set; :func:`warm_up` compiles the simulator core once
before the workers fork, so no worker compiles it again.
"""

from __future__ import annotations

from compliance.campaign.plan import Job
from compliance.processes import map_tasks
from compliance.procedures.registry import run as run_procedure
from compliance.requirements.requirement_set import RequirementSet

__all__ = ["execute", "warm_up"]


# --------------------------------------------------------------------------- campaigns
def warm_up(cfg):
    """Compile (or load from the numba cache) the plant kind's loops once, before workers fork."""
    from compliance.plants import kind_of

    kind_of(cfg).warm_up(cfg)


def _campaign_run(context, job: Job):
    cfg, reqset = context
    return run_procedure(cfg, reqset.procedures[job.procedure], reqset.operating_points[job.operating_point], job.requests)


def execute(cfg, reqset: RequirementSet, jobs: list[Job], *, workers: int | None = None, progress: bool = True,
            scheduler: str | None = None):
    """Run a campaign's jobs, in parallel when there are several cores and several jobs.

    Returns
    -------
    tuple
        (outcomes in job order, number of workers used)
    """
    if jobs:
        warm_up(cfg)
    outcomes, stats = map_tasks(_campaign_run, (cfg, reqset), list(jobs), scheduler=scheduler, workers=workers,
                                progress=progress, label="runs", retries=1)
    if stats.failed:  # a run that crashed twice (not a simulation error: those are recorded) is a bug
        i, why = stats.errors[0]
        raise RuntimeError(f"run {jobs[i].key} failed: {why}")
    return outcomes, stats.workers
