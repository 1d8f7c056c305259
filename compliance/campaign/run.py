"""A compliance campaign: plant x requirement set -> results dict (sequencing only, no physics).

The campaign's steps, each public so ``compliance.check`` composes them: the requirement set is
vetted once (``requirements.vetting.vet``: loosening and conflicts), :func:`execute_runs` plans
every procedure x operating point some enabled requirement names (each run once, whatever number
of requirements use it) and runs them on the one executor, ``campaign.judge`` judges each
requirement x procedure x operating point, ``campaign.uncertainty`` bands the verdicts, and
:func:`assemble` makes the results dict documented in docs/results-schema.md.
:func:`run_campaign` runs them in that order for a caller that wants the dict (sweeps, the gate).
"""

from __future__ import annotations

import datetime as _dt
import importlib
import platform
import time
from dataclasses import dataclass

from compliance.model.force_limit import check_load_force
from compliance.simulation.scenario import scenario_load
from compliance.files.display import display_path
from compliance.model.identity import identity_dict
from compliance.version import __version__
from compliance.campaign.plan import Job, plan
from compliance.campaign.executor import execute
from compliance.processes import available_cores
from compliance.campaign.judge import EVALUATION_RULE, explain_fails_under_uncertain, judge, sample_dict
from compliance.errors import InputError
from compliance.requirements.requirement_set import RequirementSet
from compliance.requirements.vetting import Vetting, vet
from compliance.results.keys import RequestKey
from compliance.campaign.basis import verdict_qualifier
from compliance.campaign.coverage import case_coverage, unjudged
from compliance.campaign.uncertainty import local_bands, ranged_parameters
from compliance.results.check_result import RESULTS_SCHEMA
from compliance.requirements.verdict import Basis, Severity, Status, overall_status

__all__ = [
    "RESULTS_SCHEMA",
    "CampaignRuns",
    "Job",
    "assemble",
    "available_cores",
    "check_loads",
    "execute",
    "execute_runs",
    "judge",
    "plan",
    "plant_section",
    "run_campaign",
    "run_records",
    "summary_section",
    "versions_section",
]


# --------------------------------------------------------------------------- results
def versions_section() -> dict:
    """Versions of govcheck, Python and the numerical packages (a results file's ``versions``)."""
    out = {"govcheck": __version__, "python": platform.python_version()}
    for mod in ("numpy", "scipy", "pandas", "numba", "control", "pint", "pydantic"):
        try:
            out[mod] = importlib.import_module(mod).__version__
        except Exception:  # a missing optional package is reported as absent, not fatal
            out[mod] = None
    return out


def _by_construction(e: dict) -> bool:
    return e["status"] == Status.PASS and e.get("basis") == Basis.BY_CONSTRUCTION


def summary_counts(entries: list[dict]) -> dict:
    """Requirement counts by status, with passes by construction and advisory failures counted apart."""
    counts = {s: sum(1 for e in entries if e["status"] == s) for s in Status}  # in declared order
    counts["pass_by_construction"] = sum(1 for e in entries if _by_construction(e))
    counts[Status.PASS] -= counts["pass_by_construction"]  # a pass by construction is not evidence: never counted as a pass
    counts["fail_mandatory"] = sum(1 for e in entries if e["status"] == Status.FAIL and e["severity"] == Severity.MANDATORY)
    counts["fail_advisory"] = counts[Status.FAIL] - counts["fail_mandatory"]
    return counts


def summary_section(entries: list[dict], notes: list[str], uncertainty: dict | None = None) -> dict:
    """The results' ``summary``: overall verdict, counts, lists of ids by outcome, coverage, the assumptions that matter most."""
    judged = [(e["severity"], e["status"], e.get("basis")) for e in entries if e["status"] not in (Status.OPEN, Status.DISABLED)]
    return {
        "status": overall_status(judged),
        "counts": summary_counts(entries),
        "failed": [e["id"] for e in entries if e["status"] == Status.FAIL],
        "failed_mandatory": [e["id"] for e in entries if e["status"] == Status.FAIL and e["severity"] == Severity.MANDATORY],
        "not_evaluated": [e["id"] for e in entries if e["status"] == Status.NOT_EVALUATED],
        "open": [e["id"] for e in entries if e["status"] == Status.OPEN],
        "passed_by_construction": [e["id"] for e in entries if _by_construction(e)],
        "uncertain": [e["id"] for e in entries if e["status"] == Status.UNCERTAIN],
        "coverage": case_coverage(entries),
        "top_assumptions": (uncertainty or {}).get("top_assumptions") or [],
        "notes": notes,
        **({"commissioned": uncertainty["commissioning"]["text"]} if (uncertainty or {}).get("commissioning") else {}),
    }


def plant_section(cfg) -> dict:
    """Plant identity and the full parameter table with units, meanings and sources."""
    from compliance.model.parameters import BASE_BY_KEY

    params = []
    for key, value in cfg.params.items():
        spec = BASE_BY_KEY.get(key)
        params.append({"key": key, "value": float(value), "unit": spec.unit if spec else "",
                       "meaning": spec.meaning if spec else "", "source": cfg.sources.get(key, "")})
    effects = []
    from compliance.effects import EFFECTS

    for name, values in cfg.effects.items():
        eff = EFFECTS.get(name)
        effects.append({
            "name": name,
            "meaning": eff.meaning if eff else "",
            "params": [{"name": k, "value": float(v), "unit": eff.param(k).unit if eff else "",
                        "meaning": eff.param(k).meaning if eff else ""} for k, v in values.items()],
        })
    curve = None
    if cfg.load_curve is not None:
        curve = {"position": [float(v) for v in cfg.load_curve[0]], "force": [float(v) for v in cfg.load_curve[1]],
                 "source": cfg.sources.get("load.curve", "user")}
    return {
        "name": cfg.name,
        "description": cfg.description,
        "path": display_path(cfg.path),
        "digest": cfg.digest,
        "parameters": params,
        "options": dict(cfg.options),
        "effects": effects,
        "load_curve": curve,
        "provenance": dict(cfg.provenance),
        "identity": identity_dict(cfg.identity),
    }


@dataclass(frozen=True)
class CampaignRuns:
    """The campaign's runs (planned jobs in order) and what each produced."""

    jobs: tuple
    outcomes: tuple
    workers: int  # workers actually used
    started: float  # time.perf_counter() when the campaign began (for the results' timing)

    @property
    def by_key(self) -> dict:
        """``procedure@operating_point`` -> outcome."""
        return {j.key: o for j, o in zip(self.jobs, self.outcomes)}


def check_loads(cfg, reqset: RequirementSet) -> None:
    """A load no cylinder of this plant can hold is a typo, not a test (``InputError`` naming the point)."""
    for op in reqset.operating_points.values():
        check_load_force(cfg, scenario_load(cfg, op), f"{reqset.path}: operating_points.{op.name}.load = {op.load_text!r}")


def execute_runs(cfg, reqset: RequirementSet, *, workers: int | None = None, progress: bool = True,
                 scheduler: str | None = None) -> CampaignRuns:
    """Plan the runs a requirement set needs and execute them (the campaign step).

    Raises
    ------
    InputError
        A load beyond the plant's cylinders, or a procedure that cannot run on this plant
        (e.g. steps leaving the stroke).
    """
    t0 = time.perf_counter()
    check_loads(cfg, reqset)
    jobs = plan(reqset)
    outcomes, used = execute(cfg, reqset, jobs, workers=workers, progress=progress, scheduler=scheduler)
    for j, o in zip(jobs, outcomes):
        if o.error and o.error_kind == "InputError":
            raise InputError(f"{reqset.path}: run {j.key}: {o.error}")
    return CampaignRuns(tuple(jobs), tuple(outcomes), used, t0)


def run_records(runs: CampaignRuns, reqset: RequirementSet) -> list[dict]:
    """The results' ``runs``: every run's values (by request key), traces, marks and notes."""
    out = []
    for j, o in zip(runs.jobs, runs.outcomes):
        proc = reqset.procedures[j.procedure]
        out.append({
            "id": j.key,
            "procedure": j.procedure,
            "operating_point": j.operating_point,
            "kind": proc.kind,
            "title": proc.title,
            "error": o.error,
            "notes": o.notes,
            "metrics": {k: [sample_dict(s, RequestKey.parse(k).metric) for s in v] for k, v in o.samples.items()},
            "traces": o.traces,
            "marks": o.marks,
            "wall_time": o.wall_time,
        })
    return out


def assemble(cfg, reqset: RequirementSet, runs: CampaignRuns, entries: list[dict], notes: list[str], vetting: Vetting,
             bands: dict | None, command_line: str | None = None) -> dict:
    """The results dict of a judged campaign (schema ``govcheck-results/1``, docs/results-schema.md).

    After the bands: a failing row under an UNCERTAIN requirement gets the sentence that explains it
    (``judge.explain_fails_under_uncertain``)."""
    explain_fails_under_uncertain(entries)
    results = {
        "schema": RESULTS_SCHEMA,
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command_line": command_line,
        "versions": versions_section(),
        "plant": plant_section(cfg),
        "requirement_set": reqset.as_dict(),
        "summary": summary_section(entries, notes, bands),
        "coverage": {"unjudged": unjudged(reqset, runs.jobs, runs.outcomes, entries), "evaluation_rule": EVALUATION_RULE},
        "findings": list(vetting.findings),
        "uncertainty": bands,
        "requirements": entries,
        "runs": run_records(runs, reqset),
        "timing": {"wall": time.perf_counter() - runs.started, "runs": len(runs.jobs), "workers": runs.workers,
                   "run_wall_sum": sum(o.wall_time for o in runs.outcomes)},
    }
    results["summary"]["qualifier"] = verdict_qualifier(results)
    return results


def run_campaign(cfg, reqset: RequirementSet, *, workers: int | None = None, progress: bool = True,
                 command_line: str | None = None, uncertainty: str | None = None, allow_conflicts: bool = False,
                 scheduler: str | None = None) -> dict:
    """Check a plant against a requirement set: vet, run, judge, band (``compliance.check`` adds the rest).

    Parameters
    ----------
    cfg : PlantConfig
    reqset : RequirementSet
    workers : int, optional
        Processes to use (default: the available cores; 1 = serial).
    progress : bool
        Show a progress bar on stderr when it is a terminal.
    command_line : str, optional
        Recorded in the results.
    uncertainty : {"local", None}
        Bands on the verdicts from the plant file's declared ranges by local sensitivities
        (``compliance.campaign.uncertainty``); None (default): point values only.
    allow_conflicts : bool
        Judge a set whose mandatory limits conflict (else ``InputError`` before any simulation).
    scheduler : str, optional
        Run on Dask (``local:N`` or ``tcp://host:port``) instead of the local process pool.

    Returns
    -------
    dict
        The results (schema ``govcheck-results/1``, docs/results-schema.md).

    Raises
    ------
    InputError
        A requirement file loosens an inherited limit without ``allow_loosen``, two mandatory limits
        conflict, or a procedure cannot run on this plant (e.g. steps leaving the stroke).
    """
    vetting = vet(reqset, cfg.p("cylinder.stroke"), allow_conflicts)  # fail fast, before any simulation
    runs = execute_runs(cfg, reqset, workers=workers, progress=progress, scheduler=scheduler)
    entries, notes = judge(cfg, reqset, list(runs.jobs), list(runs.outcomes), vetting.loosened)
    bands = None
    if uncertainty == "local" and ranged_parameters(cfg):
        bands = local_bands(cfg, reqset, list(runs.jobs), entries, workers=workers, progress=progress)
    return assemble(cfg, reqset, runs, entries, notes, vetting, bands, command_line)
