"""Campaign planning: the procedure x operating point runs a requirement set needs, each run once.

Every enabled simulation requirement names procedures and operating points; a run is
planned once however many requirements use it, with the metric requests (metric + options)
of all of them. Runs are ordered longest first for a better load balance on few cores.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.requirements.requirement_set import RequirementSet
from compliance.procedures.outcomes import request_key

__all__ = ["Job", "plan"]


@dataclass(frozen=True)
class Job:
    """One procedure at one operating point with the metric requests that need it."""

    procedure: str
    operating_point: str
    requests: tuple  # ((metric, options), ...)

    @property
    def key(self) -> str:
        """``procedure@operating_point``."""
        return f"{self.procedure}@{self.operating_point}"


_COST = {"steps": 10.0, "sine": 40.0, "full_stroke": 30.0, "independent_adjustment": 120.0, "hold": 10.0, "dead_band": 40.0}


def plan(reqset: RequirementSet) -> list[Job]:
    """The runs a requirement set needs, longest first (better load balance on few cores)."""
    wanted: dict[tuple[str, str], dict] = {}
    for r in reqset.requirements:
        if not r.enabled or r.source != "simulation":
            continue
        for p in r.procedures:
            for o in r.operating_points:
                wanted.setdefault((p, o), {})[request_key(r.metric, r.options)] = (r.metric, r.options)
    jobs = [Job(p, o, tuple(v.values())) for (p, o), v in wanted.items()]
    jobs.sort(key=lambda j: -_COST.get(reqset.procedures[j.procedure].kind, 10.0))
    return jobs
