"""A sweep from its file to its outputs: candidates, judging, table, summary, best candidate's results.

``run_sweep`` writes into one folder: ``results.parquet`` and ``results.csv`` (one row per
candidate), ``summary.json`` and ``summary.md`` (counts, executor statistics, the Pareto front
of the two tightest requirements, the best candidate) and ``best-results.json.gz`` (the best
candidate's full campaign, schema ``govcheck-results/1``, which ``govcheck report`` renders).
``run_yield_file`` does the same for a tolerance-yield run: ``yield.json``, ``yield.md``, the unit
table (``results.parquet``/``.csv``, one row per unit) and ``results.json`` (the nominal
candidate's full campaign with the yield under ``tolerance_yield``).
"""

from __future__ import annotations

import time

from compliance.processes import raise_if_stopping
from compliance.files.atomic import write_json_atomic, write_text_atomic
from compliance.requirements.verdict import Overall
from compliance.results.check_result import CheckResult
from compliance.sweep.candidates.evaluate import make_context
from compliance.sweep.remedies.smallest_change import find_remedy
from compliance.sweep.candidates.results import best_index, pareto_front, table, tightest, write_table
from compliance.sweep.candidates.sampling import grid, latin_hypercube
from compliance.sweep.summary_text import summary_markdown, yield_markdown
from compliance.sweep.tolerance.yield_mc import nominal_values, run_yield

__all__ = ["SUMMARY_SCHEMA", "load_inputs", "run_sweep", "run_yield_file", "verify_settings"]

SUMMARY_SCHEMA = "govcheck-sweep-summary/1"


def load_inputs(spec):
    """Base configuration and requirement set named by a sweep file."""
    from compliance.model.config import load_plant
    from compliance.requirements.loading import load_requirements

    return load_plant(spec.base), load_requirements(spec.requirements)


def verify_settings(cfg, reqset, paths, values, *, command_line=None, workers=None) -> CheckResult:
    """The full campaign (traces, linear requirements and all) of ``cfg`` with ``values`` applied."""
    from compliance.campaign.run import run_campaign
    from compliance.model.parameters import apply

    # a search judges candidates against the set its caller vetted (a conflict it allowed stays allowed)
    return CheckResult.of(run_campaign(apply(cfg, [paths[p] for p in values], values.values()), reqset, workers=workers,
                                       progress=False, command_line=command_line, allow_conflicts=True))


MAX_GRID = 100_000  # a grid beyond this is a typo in `steps`, not a plan (use latin_hypercube)


def _candidates(spec):
    if spec.method == "grid":
        import math

        from compliance.errors import InputError

        n = math.prod(len(a.values) if a.values is not None else a.steps for a in spec.adjust)
        if n > MAX_GRID:
            raise InputError(f"{spec.path}: search.method: a grid of {n} candidates is over {MAX_GRID}; "
                             "use fewer steps or method = \"latin_hypercube\"")
        return grid(spec.adjust)
    return latin_hypercube(spec.adjust, spec.samples, spec.seed)


def _pareto(df, rows):
    pair = tightest(df, rows)
    if len(pair) < 2:
        return {"requirements": pair, "candidates": []}
    front = pareto_front(df, *pair)
    cols = ["candidate", "status", "shortfall", "change"] + [f"{r}.margin_pct" for r in pair]
    return {"requirements": pair, "candidates": df[df["candidate"].isin(front)][cols].to_dict("records")}


def run_sweep(spec, out_dir, *, scheduler=None, workers=None, progress=True, client=None, command_line=None) -> dict:
    """Run a sweep file and write its outputs into ``out_dir``; returns the summary dict."""
    from pathlib import Path

    t0 = time.perf_counter()
    out = Path(out_dir)  # created only when every result is in hand: a failed or interrupted sweep leaves no folder
    cfg, reqset = load_inputs(spec)
    ctx = make_context(cfg, reqset, spec.paths, spec.linear)
    base = nominal_values(cfg, spec.paths)
    from compliance.processes import dask_session
    from compliance.sweep.candidates.runner import run_candidates

    cands = _candidates(spec)
    remedies = None
    with dask_session(scheduler, client) as session:
        run_kw = {"scheduler": scheduler, "workers": workers, "progress": progress, "client": session}
        rows, stats = run_candidates(ctx, cands, **run_kw)
        if spec.method == "optimise":
            remedies = find_remedy(ctx, spec.adjust, base, iterations=spec.iterations, seeds=list(zip(cands, rows)),
                                   verify=lambda v: verify_settings(cfg, reqset, spec.paths, v, workers=workers),
                                   run_kw=run_kw)
    ids = [r.id for r in ctx.reqset.requirements]
    df = table(cands, rows, ids, spec.adjust, base)
    best = best_index(df)
    best_info, res = None, None
    if best is not None:
        values = cands[best]
        res = verify_settings(cfg, reqset, spec.paths, values, command_line=command_line, workers=workers)
        res = res.with_(sweep={"name": spec.name, "file": spec.path, "candidate": best, "values": values}, remedies=remedies)
        best_info = {"candidate": best, "values": values, "status": df.loc[best, "status"],
                     "shortfall": float(df.loc[best, "shortfall"]), "change": float(df.loc[best, "change"]),
                     "verified_status": res.summary.status, "failed_mandatory": list(res.summary.failed_mandatory),
                     "results_file": str(out / "best-results.json.gz")}
    raise_if_stopping()
    out.mkdir(parents=True, exist_ok=True)
    files = write_table(df, out)
    if res is not None:
        res.to_json(out / "best-results.json.gz")
    counts = df["status"].value_counts().to_dict()
    summary = {
        "schema": SUMMARY_SCHEMA, "name": spec.name, "title": spec.title, "sweep_file": spec.path,
        "base": spec.base, "requirements": spec.requirements, "method": spec.method, "seed": spec.seed,
        "candidates": len(cands), "counts": {k: int(v) for k, v in counts.items()},
        "passing": int(counts.get(Overall.PASS, 0)),
        "executor": stats.as_dict() if stats else None,
        "parameters": [{"path": a.param.path, "unit": a.param.unit, "low": a.low, "high": a.high,
                        "base": base[a.param.path]} for a in spec.adjust],
        "pareto": _pareto(df, rows), "best": best_info, "remedies": remedies,
        "files": files, "wall": time.perf_counter() - t0, "command_line": command_line,
    }
    write_json_atomic(out / "summary.json", summary)
    write_text_atomic(out / "summary.md", summary_markdown(summary))
    return summary


def run_yield_file(spec, out_dir, candidate: dict, label: str, *, scheduler=None, workers=None, progress=True,
                   client=None, units=None) -> dict:
    """Tolerance yield of ``candidate`` (settings over the base); writes ``yield.json``, ``yield.md`` and the unit table."""
    from pathlib import Path

    from compliance.errors import InputError

    if not spec.uncertain:
        raise InputError(f"{spec.path}: uncertain: no uncertain parameter declared; a yield run needs at least one")
    out = Path(out_dir)  # created at the end, with every result in hand
    cfg, reqset = load_inputs(spec)
    ctx = make_context(cfg, reqset, spec.paths, spec.linear)
    from compliance.processes import dask_session

    with dask_session(scheduler, client) as session:
        run_kw = {"scheduler": scheduler, "workers": workers, "progress": progress, "client": session}
        y, draws, rows, stats = run_yield(ctx, cfg, candidate, spec.uncertain, units=units or spec.yield_units,
                                          seed=spec.yield_seed, confidence=spec.confidence, run_kw=run_kw)
    y.update(name=spec.name, label=label, executor=stats.as_dict() if stats else None)
    df = table(draws, rows, [r.id for r in ctx.reqset.requirements])
    res = verify_settings(cfg, reqset, spec.paths, candidate, workers=workers)
    raise_if_stopping()
    out.mkdir(parents=True, exist_ok=True)
    buf_files = write_table(df, out)
    y["files"] = {"units": buf_files, "results": str(out / "results.json")}
    res.with_(tolerance_yield=y).to_json(out / "results.json")  # the nominal candidate's campaign: govcheck report renders it
    write_json_atomic(out / "yield.json", y)
    write_text_atomic(out / "yield.md", yield_markdown(y))
    return y
