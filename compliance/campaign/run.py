"""A compliance campaign: plant x requirement set -> results dict (sequencing only, no physics).

``run_campaign`` plans the runs (every procedure x operating point some enabled requirement
names, each run once whatever number of requirements use it), runs them on the available
cores, measures the metrics, judges each requirement x procedure x operating point, and
returns the results dict documented in docs/results-schema.md.

The steps live beside this module: ``campaign_plan`` (the runs), ``campaign_pool`` (process
pool and progress bar), ``campaign_verdicts`` (rows and statuses) and ``linear_requirements``
(``source = "linear"``); this module assembles the results.
"""

from __future__ import annotations

import datetime as _dt
import importlib
import platform
import time

from compliance.model.force_limit import check_load_force
from compliance.simulation.scenario import scenario_load
from compliance.files.display import display_path
from compliance.model.identity import identity_dict
from compliance import __version__
from compliance.campaign.plan import Job, plan
from compliance.campaign.executor import execute
from compliance.processes import available_cores
from compliance.campaign.judge import judge, sample_dict
from compliance.errors import InputError
from compliance.requirements.consistency import consistency_findings
from compliance.requirements.tightening import check_tightening
from compliance.requirements.requirement_set import RequirementSet
from compliance.campaign.basis import verdict_qualifier
from compliance.campaign.coverage import case_coverage, unjudged
from compliance.campaign.uncertainty import local_bands, ranged_parameters
from compliance.requirements.verdict import Basis, Severity, Status, overall_status

__all__ = [
    "RESULTS_SCHEMA",
    "Job",
    "available_cores",
    "execute",
    "judge",
    "plan",
    "plant_section",
    "run_campaign",
    "summary_section",
    "versions_section",
]

RESULTS_SCHEMA = "govcheck-results/1"

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


def run_campaign(cfg, reqset: RequirementSet, *, workers: int | None = None, progress: bool = True,
                 command_line: str | None = None, uncertainty: str | None = None) -> dict:
    """Check a plant against a requirement set.

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

    Returns
    -------
    dict
        The results (schema ``govcheck-results/1``, docs/results-schema.md).

    Raises
    ------
    InputError
        A requirement file loosens an inherited limit without ``allow_loosen``, or a
        procedure cannot run on this plant (e.g. steps leaving the stroke).
    """
    t0 = time.perf_counter()
    stroke = cfg.p("cylinder.stroke")
    for req in reqset.requirements:  # fail fast on loosening, before any simulation
        check_tightening(req, stroke)
    for op in reqset.operating_points.values():  # a load no cylinder of this plant can hold is a typo, not a test
        check_load_force(cfg, scenario_load(cfg, op), f"{reqset.path}: operating_points.{op.name}.load = {op.load_text!r}")
    jobs = plan(reqset)
    outcomes, used = execute(cfg, reqset, jobs, workers=workers, progress=progress)
    for j, o in zip(jobs, outcomes):
        if o.error and o.error_kind == "InputError":
            raise InputError(f"{reqset.path}: run {j.key}: {o.error}")
    entries, notes = judge(cfg, reqset, jobs, outcomes)
    bands = None
    if uncertainty == "local" and ranged_parameters(cfg):
        bands = local_bands(cfg, reqset, jobs, entries, workers=workers, progress=progress)
    runs = []
    for j, o in zip(jobs, outcomes):
        proc = reqset.procedures[j.procedure]
        runs.append({
            "id": j.key,
            "procedure": j.procedure,
            "operating_point": j.operating_point,
            "kind": proc.kind,
            "title": proc.title,
            "error": o.error,
            "notes": o.notes,
            "metrics": {k: [sample_dict(s, k.split("[")[0]) for s in v] for k, v in o.samples.items()},
            "traces": o.traces,
            "marks": o.marks,
            "wall_time": o.wall_time,
        })
    results = {
        "schema": RESULTS_SCHEMA,
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command_line": command_line,
        "versions": versions_section(),
        "plant": plant_section(cfg),
        "requirement_set": reqset.as_dict(),
        "summary": summary_section(entries, notes, bands),
        "coverage": {"unjudged": unjudged(reqset, jobs, outcomes, entries)},
        "findings": consistency_findings(reqset, stroke),
        "uncertainty": bands,
        "requirements": entries,
        "runs": runs,
        "timing": {"wall": time.perf_counter() - t0, "runs": len(jobs), "workers": used,
                   "run_wall_sum": sum(o.wall_time for o in outcomes)},
    }
    results["summary"]["qualifier"] = verdict_qualifier(results)
    return results
