"""Running a campaign's jobs: a forked process pool over the available cores, with a progress bar.

The simulator core is compiled (or loaded from the numba cache) once before the workers
fork; workers read the configuration and the jobs from module state set before the fork,
so nothing large is pickled. One core, one job or no ``fork`` start method: the jobs run
serially in this process.
"""

from __future__ import annotations

import os
import sys

from compliance.campaign.plan import Job
from compliance.procedures.registry import run as run_procedure
from compliance.requirements.requirement_set import RequirementSet

__all__ = ["available_cores", "execute", "warm_up"]

_CTX: dict = {}  # set before the pool forks: workers read the configuration without pickling it


def _work(i: int):
    cfg, reqset, jobs = _CTX["cfg"], _CTX["reqset"], _CTX["jobs"]
    j = jobs[i]
    return i, run_procedure(cfg, reqset.procedures[j.procedure], reqset.operating_points[j.operating_point], j.requests)


def warm_up(cfg):
    """Compile (or load from the numba cache) the simulator core once, before workers fork."""
    from compliance.simulation import Scenario, simulate

    simulate(cfg, Scenario(0.01, 0.5 * cfg.p("cylinder.stroke")))
    if cfg.options["controller.type"] != "pid":
        from compliance.simulation.state_feedback_loop import warm_up as warm_up_state_feedback

        warm_up_state_feedback(cfg)


class _Progress:
    """A one-line progress bar on stderr (hidden when stderr is not a terminal or when quiet)."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.done = total, 0
        self.enabled = enabled and total > 0 and sys.stderr.isatty()

    def step(self, label: str):
        self.done += 1
        if self.enabled:
            n = 30
            k = int(n * self.done / self.total)
            sys.stderr.write(f"\r[{'#' * k}{'.' * (n - k)}] {self.done}/{self.total} {label[:50]:<50}")
            sys.stderr.flush()

    def close(self):
        if self.enabled:
            sys.stderr.write("\r" + " " * 100 + "\r")
            sys.stderr.flush()


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def execute(cfg, reqset: RequirementSet, jobs: list[Job], *, workers: int | None = None, progress: bool = True):
    """Run the jobs, in parallel when there are several cores and several jobs.

    Returns
    -------
    tuple
        (outcomes in job order, number of workers used)
    """
    import multiprocessing as mp

    n = len(jobs)
    workers = max(1, min(workers or available_cores(), n)) if n else 1
    if n:
        warm_up(cfg)
    bar = _Progress(n, progress)
    outcomes = [None] * n
    _CTX.update(cfg=cfg, reqset=reqset, jobs=jobs)
    try:
        if workers == 1 or "fork" not in mp.get_all_start_methods():
            workers = 1
            for i in range(n):
                outcomes[i] = _work(i)[1]
                bar.step(jobs[i].key)
        else:
            from concurrent.futures import ProcessPoolExecutor, as_completed

            with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("fork")) as pool:
                futures = [pool.submit(_work, i) for i in range(n)]
                for fut in as_completed(futures):
                    i, out = fut.result()
                    outcomes[i] = out
                    bar.step(jobs[i].key)
    finally:
        bar.close()
        _CTX.clear()
    return outcomes, workers
