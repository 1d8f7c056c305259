"""``govcheck sweep``: candidate sweeps, the optimise (remedies) search and tolerance yield; the remedies options.

The options that shape ``--remedies`` of ``govcheck check`` and ``govcheck size`` (catalogue, yield units,
scheduler, resumable state, saved remedy) live here too: the same search, the same executor.
"""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

from compliance.cli.common import add_allow_conflicts, add_jobs, add_parser, add_quiet, add_scheduler, check_scheduler
from compliance.errors import InputError
from compliance.sweep.remedies.outcome import RemedyStatus


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
    add_allow_conflicts(p)
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


def _check_requirement_set(spec, args) -> None:
    """The sweep's requirement set is checked like every other command's (before any candidate runs)."""
    from compliance.cli.common import checked_requirements
    from compliance.model.config import load_plant

    checked_requirements(spec.requirements, [load_plant(spec.base).p("cylinder.stroke")], args)


def _command_line(args) -> str:
    parts = ["govcheck", "sweep", args.sweep]
    for flag in ("out", "scheduler", "jobs", "samples"):
        v = getattr(args, flag)
        if v is not None:
            parts += [f"--{flag}", str(v)]
    return shlex.join(parts)


def _write_section(path, title: str, **section) -> None:
    """The remedies / yield report section as its own page beside the run's files (read without a whole report)."""
    from compliance.files.atomic import write_text_atomic
    from compliance.report.render import section_page

    write_text_atomic(path, section_page(title, **section))


def run(args) -> int:
    """Run the sweep (or yield run), print the summary, exit 0 / 1 / 2."""
    from dataclasses import replace

    from compliance.sweep.run import run_sweep, run_yield_file
    from compliance.requirements.verdict import Overall
    from compliance.sweep.candidates.spec import load_sweep

    for flag in ("jobs", "samples", "units"):
        v = getattr(args, flag)
        if v is not None and v < 1:
            raise InputError(f"--{flag} {v}: expected a positive number")
    check_scheduler(args)  # a bad address is exit 2 before any work
    spec = load_sweep(args.sweep)
    if args.units is not None and not args.yield_of:
        raise InputError(f"--units {args.units}: the Monte Carlo units of --yield; without --yield no yield is run")
    if args.samples is not None and spec.method == "grid":
        raise InputError(f"--samples {args.samples}: overrides the latin-hypercube sample count, and {spec.path} searches a "
                         "grid (method = \"grid\"), whose size its steps set")
    _check_requirement_set(spec, args)
    if args.samples:
        spec = replace(spec, samples=args.samples)
    out = _out_dir(args, spec)
    kw = {"scheduler": args.scheduler, "workers": args.jobs, "progress": not args.quiet}
    if args.yield_of:
        from compliance.sweep.summary_text import yield_markdown

        cand = _yield_candidate(args.yield_of, out, spec)
        y = run_yield_file(spec, out / f"yield-{args.yield_of}", cand, args.yield_of, units=args.units, **kw)
        _write_section(out / f"yield-{args.yield_of}" / "yield.html", f"{spec.title}: tolerance yield of '{args.yield_of}'",
                       tolerance_yield=y)
        text = yield_markdown(y)
        print(text.splitlines()[3] if args.quiet else text)
        return 0
    from compliance.sweep.summary_text import summary_markdown

    s = run_sweep(spec, out, command_line=_command_line(args), **kw)
    if s["remedies"] is not None:
        _write_section(out / "summary.html", f"{spec.title}: what would make it pass", remedies=s["remedies"])
    text = summary_markdown(s)
    print(text.splitlines()[3] if args.quiet else text)
    return 0 if s["best"] and s["best"]["verified_status"] == Overall.PASS else 1


# --------------------------------------------------------------------------- the remedies options of check and size
def add_remedies_options(p) -> None:
    """Add the options that shape ``--remedies``."""
    p.add_argument("--save-remedy", metavar="FILE.toml",
                   help="with --remedies: write the verified remedy as a configuration file that govcheck check accepts "
                        "(written only when a remedy is found)")
    p.add_argument("--catalogue", metavar="FILE.toml", default=None,
                   help="with --remedies: hardware catalogue of orderable options (default: the shipped "
                        "models/hardware-catalogue.toml; 'none' for settings only)")
    p.add_argument("--yield-units", type=int, default=None, metavar="N",
                   help="with --remedies: Monte Carlo units of the remedy's tolerance yield (default 59: 59/59 passing shows "
                        ">= 95 %% at 95 %% confidence; 0 skips it)")
    add_scheduler(p, "the --remedies search (needs --remedies)")
    p.add_argument("--remedies-state", metavar="DIR",
                   help="with --remedies: keep every judged candidate in DIR so an interrupted search resumes there "
                        "(DIR is made if missing; its parent folder must exist)")


def check_remedies_options(args) -> None:
    """Refuse inconsistent or bad remedies options before any work (exit 2).

    Every option that shapes ``--remedies`` does nothing without it and is refused, not ignored.
    """
    used = [f for f in ("save_remedy", "catalogue", "yield_units", "scheduler", "remedies_state")
            if getattr(args, f, None) is not None]
    if used and not args.remedies:
        raise InputError(f"--{used[0].replace('_', '-')} needs --remedies (without it no remedy is searched, so the "
                         "option would do nothing)")
    if args.yield_units is not None and args.yield_units < 0:
        raise InputError(f"--yield-units {args.yield_units}: expected 0 or a positive number of units")
    check_scheduler(args)
    if args.remedies_state is not None:
        _check_state_folder(args.remedies_state)
    if args.remedies and args.catalogue not in (None, "default", "none"):
        from compliance.sweep.sizing.hardware_catalogue import load_catalogue

        load_catalogue(args.catalogue)  # a bad catalogue is exit 2 before any simulation


def _check_state_folder(text: str) -> None:
    """``--remedies-state DIR``: a folder (made if missing) in a folder that exists and is writable."""
    import os

    state = Path(text)
    if not text.strip():
        raise InputError("--remedies-state: empty path; expected a folder name")
    if state.exists() and not state.is_dir():
        raise InputError(f"--remedies-state {text}: is a file; expected a folder for the judged candidates")
    parent = state.parent if str(state.parent) else Path(".")
    if not state.exists() and not parent.is_dir():
        raise InputError(f"--remedies-state {text}: folder '{parent}' does not exist (govcheck makes only the state "
                         "folder itself, never its parents)")
    where = state if state.exists() else parent
    if not os.access(where, os.W_OK | os.X_OK):
        raise InputError(f"--remedies-state {text}: folder '{where}' is not writable")


def remedies_kwargs(args) -> dict:
    """Keyword arguments of ``remedies_for_check`` from the options."""
    from compliance.sweep.candidates.candidate_store import CandidateStore
    from compliance.sweep.check_remedies import YIELD_UNITS

    catalogue = "default" if args.catalogue is None else (None if args.catalogue == "none" else args.catalogue)
    return {"catalogue": catalogue, "scheduler": args.scheduler,
            "yield_units": YIELD_UNITS if args.yield_units is None else args.yield_units,
            "store": CandidateStore(args.remedies_state) if args.remedies_state else None}


def save_remedy(args, cfg, rem) -> None:
    """Write the remedy configuration (``--save-remedy``) when one was found; say so either way."""
    if not args.save_remedy:
        return
    if rem.get("status") != RemedyStatus.FOUND:
        print(f"--save-remedy {args.save_remedy}: nothing written (no verified remedy in the declared space)", file=sys.stderr)
        return
    from compliance.model.config import save_plant
    from compliance.model.parameters import param_handle
    from compliance.sweep.remedies.finish import remedy_configuration, remedy_values

    paths = {p: param_handle(p, "remedy") for p in remedy_values(rem)}
    save_plant(remedy_configuration(cfg, rem, paths), args.save_remedy, overwrite=True)
    if not args.quiet:
        print(f"remedy written to {args.save_remedy} (govcheck check {args.save_remedy} -r {args.requirements})")
