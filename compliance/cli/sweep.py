"""``govcheck sweep``: candidate sweeps, the optimise (remedies) search and tolerance yield."""

from __future__ import annotations

import shlex
from pathlib import Path

from compliance.cli.common import add_jobs, add_parser, add_quiet, add_scheduler, check_scheduler
from compliance.errors import InputError


def register(subparsers):
    """Add the ``sweep`` sub-command."""
    p = add_parser(
        subparsers, "sweep",
        help="judge many candidate configurations (grid, latin hypercube, optimise) or the tolerance yield of one",
        description=(
            "Run the campaign of a requirement file for every candidate of a sweep file (docs/scaling.md) and "
            "write a results table (Parquet + CSV), a summary (passing count, Pareto front of the two tightest "
            "requirements, best candidate) and the best candidate's full results (for 'govcheck report'). "
            "With --yield, run the tolerance Monte Carlo of one candidate instead. Exit 0 when a candidate passes "
            "(or the yield run finished), 1 when none passes, 2 on invalid input."
        ),
        examples=[
            "govcheck sweep models/sweeps/plant-a-remedies.toml",
            "govcheck sweep models/sweeps/plant-a-remedies.toml --scheduler local:2",
            "govcheck sweep models/sweeps/plant-a-remedies.toml --yield best --units 2000",
        ],
    )
    p.add_argument("sweep", help="sweep file (TOML, schema govcheck-sweep/1)")
    p.add_argument("--out", metavar="DIR", help="output folder (default: reports/sweeps/NAME)")
    add_scheduler(p, "the candidates")
    add_jobs(p, "local worker processes")
    p.add_argument("--samples", type=int, default=None, help="override the sweep file's latin-hypercube sample count")
    p.add_argument("--yield", dest="yield_of", metavar="CANDIDATE",
                   help="tolerance yield of CANDIDATE: 'base', 'best' or a candidate number of an earlier sweep "
                        "in the same output folder")
    p.add_argument("--units", type=int, default=None, help="override the number of Monte Carlo units of --yield")
    add_quiet(p, "no progress; print only the result line")
    return p


def _out_dir(args, spec) -> Path:
    """The output folder, checked before any work; it is created (with its parents) only when the sweep has finished."""
    import os

    out = Path(args.out) if args.out else Path("reports") / "sweeps" / spec.name
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: is a file; expected a folder for the sweep's outputs")
    existing = next(p for p in (out, *out.parents) if p.exists())  # the folder that will hold the new ones
    if not os.access(existing, os.W_OK | os.X_OK):
        raise InputError(f"--out {out}: folder '{existing}' is not writable")
    return out


def _yield_candidate(which: str, out: Path, spec) -> dict:
    """Settings of the candidate named on --yield."""
    if which == "base":
        return {}
    import pandas as pd

    table = next((t for t in (out / "results.parquet", out / "results.csv") if t.exists()), None)
    if table is None:
        raise InputError(f"--yield {which}: no sweep results in {out} (run 'govcheck sweep {spec.path}' first, "
                         "or use --yield base)")
    df = pd.read_parquet(table) if table.suffix == ".parquet" else pd.read_csv(table)
    if which == "best":
        import json

        best = json.loads((out / "summary.json").read_text(encoding="utf-8")).get("best")
        if not best:
            raise InputError(f"--yield best: the sweep in {out} has no best candidate")
        idx = best["candidate"]
    else:
        try:
            idx = int(which)
        except ValueError:
            raise InputError(f"--yield {which}: expected 'base', 'best' or a candidate number") from None
        if idx not in set(df["candidate"]):
            raise InputError(f"--yield {which}: no candidate {idx} in {table} (0 .. {len(df) - 1})")
    row = df[df["candidate"] == idx].iloc[0]
    return {a.param.path: float(row[a.param.path]) for a in spec.adjust}


def _command_line(args) -> str:
    parts = ["govcheck", "sweep", args.sweep]
    for flag in ("out", "scheduler", "jobs", "samples"):
        v = getattr(args, flag)
        if v is not None:
            parts += [f"--{flag}", str(v)]
    return shlex.join(parts)


def run(args) -> int:
    """Run the sweep (or yield run), print the summary, exit 0 / 1 / 2."""
    from dataclasses import replace

    from compliance.sweep.run import run_sweep, run_yield_file
    from compliance.sweep.spec import load_sweep

    for flag in ("jobs", "samples", "units"):
        v = getattr(args, flag)
        if v is not None and v < 1:
            raise InputError(f"--{flag} {v}: expected a positive number")
    check_scheduler(args)  # a bad address is exit 2 before any work
    spec = load_sweep(args.sweep)
    if args.samples:
        spec = replace(spec, samples=args.samples)
    out = _out_dir(args, spec)
    kw = {"scheduler": args.scheduler, "workers": args.jobs, "progress": not args.quiet}
    if args.yield_of:
        from compliance.sweep.summary_text import yield_markdown

        cand = _yield_candidate(args.yield_of, out, spec)
        y = run_yield_file(spec, out / f"yield-{args.yield_of}", cand, args.yield_of, units=args.units, **kw)
        text = yield_markdown(y)
        print(text.splitlines()[3] if args.quiet else text)
        return 0
    from compliance.sweep.summary_text import summary_markdown

    s = run_sweep(spec, out, command_line=_command_line(args), **kw)
    text = summary_markdown(s)
    print(text.splitlines()[3] if args.quiet else text)
    return 0 if s["best"] and s["best"]["verified_status"] == "pass" else 1
