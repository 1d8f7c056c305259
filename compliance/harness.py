"""A compliance campaign: plant x requirement set -> results dict (sequencing only, no physics).

``run_campaign`` plans the runs (every procedure x operating point some enabled requirement
names, each run once whatever number of requirements use it), runs them on the available
cores, measures the metrics, judges each requirement x procedure x operating point, and
returns the results dict documented in docs/results-schema.md.
"""

from __future__ import annotations

import datetime as _dt
import importlib
import math
import os
import platform
import sys
import time
from dataclasses import dataclass

from . import __version__
from .errors import GovcheckError, InputError
from .metrics import METRICS
from .procedures import Sample, request_key, run as run_procedure
from .requirements import RequirementSet, check_tightening
from .verdicts import (
    DISABLED,
    FAIL,
    NOT_EVALUATED,
    OPEN,
    PASS,
    Verdict,
    evaluate,
    overall_status,
    requirement_status,
    worst_index,
)

RESULTS_SCHEMA = "govcheck-results/1"


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


# --------------------------------------------------------------------------- execution
_CTX: dict = {}  # set before the pool forks: workers read the configuration without pickling it


def _work(i: int):
    cfg, reqset, jobs = _CTX["cfg"], _CTX["reqset"], _CTX["jobs"]
    j = jobs[i]
    return i, run_procedure(cfg, reqset.procedures[j.procedure], reqset.operating_points[j.operating_point], j.requests)


def _warm_up(cfg):
    """Compile (or load from the numba cache) the simulator core once, before workers fork."""
    from .simulate import Scenario, simulate

    simulate(cfg, Scenario(0.01, 0.5 * cfg.p("cylinder.stroke")))


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
        _warm_up(cfg)
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


# --------------------------------------------------------------------------- linear hook
def _linear_value(cfg, metric: str, op):
    """Value of ``metric`` from the linearised model at an operating point, or (None, reason).

    Uses ``compliance.linear`` when it is importable: ``analyse(cfg, position, load,
    flow_control=..., detail=False).metric(name)`` (honours the operating point's circuit), else
    ``linear_metric(cfg, name, position, load)``, else ``evaluate_metric(cfg, name, initial_position=,
    load=, flow_control=)``; otherwise the requirement is reported not evaluated, with the reason.
    """
    try:
        mod = importlib.import_module("compliance.linear")
    except ModuleNotFoundError as exc:
        if exc.name == "compliance.linear":
            return None, "linearised model not available (compliance.linear is not installed yet)"
        raise
    from .procedures import _load

    if op.initial_position is None:
        return None, f"operating point '{op.name}' has no initial_position to linearise about"
    x0 = op.initial_position.resolve(cfg.p("cylinder.stroke"))
    load = _load(cfg, op)
    try:
        if hasattr(mod, "analyse"):
            value = mod.analyse(cfg, x0, load, flow_control=op.flow_control, detail=False).metric(metric)
        elif hasattr(mod, "linear_metric"):
            value = mod.linear_metric(cfg, metric, x0, load)
        elif hasattr(mod, "evaluate_metric"):
            value = mod.evaluate_metric(cfg, metric, initial_position=x0, load=load, flow_control=op.flow_control)
        else:
            return None, "compliance.linear offers no analyse / linear_metric / evaluate_metric"
    except GovcheckError as exc:
        return None, f"linear model: {exc}"
    if value is None or not math.isfinite(float(value)):
        return None, "linear model gave no finite value"
    return float(value), None


# --------------------------------------------------------------------------- verdicts
def fmt(value, metric: str, digits: int = 3) -> str:
    """Display a SI value of ``metric`` in its display unit (``0.0016`` m -> ``'1.60 mm'``)."""
    if value is None:
        return "-"
    info = METRICS[metric]
    v = value * info.display_scale
    if abs(v) < 1e-9:  # numerical zero (a body at rest in stiction), not a measurement
        v = 0.0
    text = f"{v:.0f}" if abs(v) >= 10 ** digits else f"{v:#.{digits}g}".rstrip(".")
    return f"{text} {info.display_unit}"


def _open_pick(comparator: str, samples: list[Sample]):
    vals = [s for s in samples if s.eligible and s.value is not None]
    if not vals:
        return None
    if comparator in (">=", ">"):
        return min(vals, key=lambda s: s.value)
    return max(vals, key=lambda s: s.value)


def _sample_dict(s: Sample, metric: str) -> dict:
    return {"label": s.label, "value": s.value, "display": fmt(s.value, metric), "eligible": s.eligible,
            "reason": s.reason, "detail": s.detail}


def _row(req, proc: str, op: str, limit, samples, error: str | None) -> dict:
    base = {"procedure": proc, "operating_point": op, "run": f"{proc}@{op}"}
    if error:
        v = Verdict(None, req.comparator, limit or (), None, None, NOT_EVALUATED, error)
        return {**base, **v.as_dict(), "which": None, "samples": []}
    samples = samples or []
    usable = [s for s in samples if s.eligible and s.value is not None]
    if req.limit is None:
        pick = _open_pick(req.comparator, samples)
        return {**base, "value": pick.value if pick else None, "comparator": req.comparator, "limit": None,
                "margin": None, "margin_pct": None, "status": OPEN,
                "reason": None if pick else _why(samples), "which": pick.label if pick else None,
                "samples": [_sample_dict(s, req.metric) for s in samples]}
    if not usable:
        v = Verdict(None, req.comparator, limit, None, None, NOT_EVALUATED, _why(samples))
        return {**base, **v.as_dict(), "which": None, "samples": [_sample_dict(s, req.metric) for s in samples]}
    verdicts = [evaluate(s.value, req.comparator, limit) for s in usable]
    w = worst_index(verdicts)
    return {**base, **verdicts[w].as_dict(), "which": usable[w].label,
            "samples": [_sample_dict(s, req.metric) for s in samples]}


def _why(samples) -> str:
    reasons = sorted({s.reason for s in samples if s.reason})
    return "; ".join(reasons) if reasons else "no sample of this metric in the run"


def _display_row(row: dict, metric: str) -> dict:
    return {
        "value": fmt(row.get("value"), metric),
        "limit": None if not row.get("limit") else " .. ".join(fmt(v, metric) for v in row["limit"]),
        "margin": fmt(row.get("margin"), metric),
        "margin_pct": None if row.get("margin_pct") is None else f"{row['margin_pct']:+.1f} %",
    }


def judge(cfg, reqset: RequirementSet, jobs: list[Job], outcomes) -> tuple[list[dict], list[str]]:
    """Verdict entries per requirement (docs/results-schema.md, ``requirements_results``)."""
    stroke = cfg.p("cylinder.stroke")
    by_key = {j.key: o for j, o in zip(jobs, outcomes)}
    entries, notes = [], []
    for req in reqset.requirements:
        loosen = check_tightening(req, stroke)
        notes.extend(loosen)
        limit = req.resolved_limit(stroke) if req.limit is not None else None
        rows = []
        if not req.enabled:
            status = DISABLED
        elif req.source == "linear":
            for o in req.operating_points:
                val, why = _linear_value(cfg, req.metric, reqset.operating_points[o])
                s = [Sample(val, "linearised model", why)]
                rows.append(_row(req, "linear", o, limit, s, None))
        else:
            key = request_key(req.metric, req.options)
            for p in req.procedures:
                for o in req.operating_points:
                    out = by_key[f"{p}@{o}"]
                    rows.append(_row(req, p, o, limit, out.samples.get(key), out.error))
        for r in rows:
            r["display"] = _display_row(r, req.metric)
        if req.enabled:
            if req.limit is None:
                status = OPEN
            else:
                vs = [Verdict(r["value"], req.comparator, tuple(r["limit"] or ()), r["margin"], r["margin_pct"], r["status"], r["reason"]) for r in rows]
                status = requirement_status(vs)
        worst = None
        if rows and req.limit is not None:
            vs = [Verdict(r["value"], req.comparator, tuple(r["limit"] or ()), r["margin"], r["margin_pct"], r["status"], r["reason"]) for r in rows]
            wi = worst_index(vs)
            worst = None if wi is None else rows[wi]
        elif rows:
            vals = [r for r in rows if r["value"] is not None]
            if vals:
                worst = (min if req.comparator in (">=", ">") else max)(vals, key=lambda r: r["value"])
        entries.append({
            "id": req.id,
            "title": req.title,
            "standard": req.standard,
            "clause": req.clause,
            "metric": req.metric,
            "unit": METRICS[req.metric].si_unit,
            "display_unit": METRICS[req.metric].display_unit,
            "comparator": req.comparator,
            "limit": list(limit) if limit is not None else None,
            "limit_text": req.limit_text,
            "limit_display": None if limit is None else (
                ("within " if req.comparator == "within" else req.comparator + " ") + " .. ".join(fmt(v, req.metric) for v in limit)),
            "severity": req.severity,
            "source": req.source,
            "status": status,
            "worst": None if worst is None else {k: worst[k] for k in ("run", "procedure", "operating_point", "value", "margin", "margin_pct", "status", "which", "display")},
            "rows": rows,
            "note": req.note,
            "loosened": loosen,
        })
    return entries, notes


# --------------------------------------------------------------------------- results
def _versions() -> dict:
    out = {"govcheck": __version__, "python": platform.python_version()}
    for mod in ("numpy", "scipy", "pandas", "numba", "control", "pint", "pydantic"):
        try:
            out[mod] = importlib.import_module(mod).__version__
        except Exception:  # a missing optional package is reported as absent, not fatal
            out[mod] = None
    return out


def plant_section(cfg) -> dict:
    """Plant identity and the full parameter table with units, meanings and sources."""
    from .parameters import BASE_BY_KEY

    params = []
    for key, value in cfg.params.items():
        spec = BASE_BY_KEY.get(key)
        params.append({"key": key, "value": float(value), "unit": spec.unit if spec else "",
                       "meaning": spec.meaning if spec else "", "source": cfg.sources.get(key, "")})
    effects = []
    try:
        from .effects import EFFECTS
    except ImportError:  # pragma: no cover - effects registry always ships with the core
        EFFECTS = {}
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
        curve = {"position": [float(v) for v in cfg.load_curve[0]], "force": [float(v) for v in cfg.load_curve[1]]}
    return {
        "name": cfg.name,
        "description": cfg.description,
        "path": cfg.path,
        "digest": cfg.digest,
        "parameters": params,
        "options": dict(cfg.options),
        "effects": effects,
        "load_curve": curve,
        "provenance": dict(cfg.provenance),
    }


def run_campaign(cfg, reqset: RequirementSet, *, workers: int | None = None, progress: bool = True,
                 command_line: str | None = None) -> dict:
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
    jobs = plan(reqset)
    outcomes, used = execute(cfg, reqset, jobs, workers=workers, progress=progress)
    for j, o in zip(jobs, outcomes):
        if o.error and o.error_kind == "InputError":
            raise InputError(f"{reqset.path}: run {j.key}: {o.error}")
    entries, notes = judge(cfg, reqset, jobs, outcomes)
    judged = [(e["severity"], e["status"]) for e in entries if e["status"] not in (OPEN, DISABLED)]
    overall = overall_status(judged)
    counts = {s: sum(1 for e in entries if e["status"] == s) for s in (PASS, FAIL, NOT_EVALUATED, OPEN, DISABLED)}
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
            "metrics": {k: [_sample_dict(s, k.split("[")[0]) for s in v] for k, v in o.samples.items()},
            "traces": o.traces,
            "marks": o.marks,
            "wall_time": o.wall_time,
        })
    return {
        "schema": RESULTS_SCHEMA,
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "command_line": command_line,
        "versions": _versions(),
        "plant": plant_section(cfg),
        "requirement_set": reqset.as_dict(),
        "summary": {
            "status": overall,
            "counts": counts,
            "failed": [e["id"] for e in entries if e["status"] == FAIL],
            "failed_mandatory": [e["id"] for e in entries if e["status"] == FAIL and e["severity"] == "mandatory"],
            "not_evaluated": [e["id"] for e in entries if e["status"] == NOT_EVALUATED],
            "open": [e["id"] for e in entries if e["status"] == OPEN],
            "notes": notes,
        },
        "requirements": entries,
        "runs": runs,
        "timing": {"wall": time.perf_counter() - t0, "runs": len(jobs), "workers": used,
                   "run_wall_sum": sum(o.wall_time for o in outcomes)},
    }
