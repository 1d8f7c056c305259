"""``govcheck gate``: fail CI when a candidate configuration regresses against a baseline."""

from __future__ import annotations

import sys
from pathlib import Path

from compliance.errors import InputError


def register(subparsers):
    """Add the ``gate`` sub-command."""
    p = subparsers.add_parser(
        "gate",
        help="compare a candidate with a baseline and fail on regressions",
        description=(
            "Compare requirement by requirement: fail (exit 1) when a pass turns into a fail (or stops being "
            "evaluated), a requirement disappears, a new one fails, or a worst-case margin shrinks by more than "
            "--max-margin-loss percentage points. Baseline and candidate are results JSON files or plant "
            "configurations (which are checked first)."
        ),
    )
    p.add_argument("--baseline", required=True, help="baseline: results JSON from 'govcheck check --json' or a plant configuration")
    p.add_argument("--candidate", required=True, help="candidate: a plant configuration or a results JSON")
    p.add_argument("--requirements", "-r", default=None,
                   help="requirement file (default: the one recorded in a baseline results JSON)")
    p.add_argument("--max-margin-loss", type=float, default=None, metavar="PP",
                   help="largest allowed loss of a worst-case margin, in percentage points (default: not checked)")
    p.add_argument("--markdown", metavar="OUT.md", help="write a Markdown summary for a pull-request comment")
    p.add_argument("--json", metavar="OUT.json", help="write the gate result as JSON")
    p.add_argument("--jobs", "-j", type=int, default=None, help="worker processes (default: available cores)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar; print only the gate line")
    return p


def _is_results(path: str) -> bool:
    return path.endswith(".json")


def _requirements_for(args, baseline_results):
    """Requirement file to run configurations against."""
    from compliance.requirements.loading import load_requirements

    if args.requirements:
        return load_requirements(args.requirements)
    if baseline_results is None:
        raise InputError("--requirements is needed when the baseline is a plant configuration")
    rs = baseline_results["requirement_set"]
    path = rs.get("path")
    if path and Path(path).is_file():
        return load_requirements(path)
    if rs.get("name"):
        try:
            return load_requirements(rs["name"])
        except InputError:
            pass
    raise InputError(f"{args.baseline}: requirement_set.path: '{path}' is not readable here; give --requirements")


def run(args) -> int:
    """Obtain both results, compare, print, write; exit 1 when the gate trips."""
    from compliance.model.config import load_plant
    from compliance.campaign.regression_gate import compare, gate_markdown, gate_table
    from compliance.campaign.run import run_campaign
    from compliance.campaign.results_files import read_results, results_json
    from compliance.files.atomic import write_text_atomic

    if args.max_margin_loss is not None and not args.max_margin_loss >= 0:
        raise InputError(f"--max-margin-loss {args.max_margin_loss}: expected a number of percentage points >= 0")
    if args.jobs is not None and args.jobs < 1:
        raise InputError(f"--jobs {args.jobs}: expected a positive number of processes")
    for path, flag in ((args.markdown, "--markdown"), (args.json, "--json")):
        if path and str(Path(path).parent) and not Path(path).parent.is_dir():
            raise InputError(f"{flag} {path}: folder '{Path(path).parent}' does not exist")
    base = read_results(args.baseline) if _is_results(args.baseline) else None
    cand = read_results(args.candidate) if _is_results(args.candidate) else None
    reqset = None
    if base is None or cand is None:
        reqset = _requirements_for(args, base)
        if base is not None and reqset.digest != base["requirement_set"].get("digest"):
            print(f"govcheck gate: note: {reqset.path} changed since the baseline was made "
                  f"(digest {str(base['requirement_set'].get('digest'))[:12]} -> {reqset.digest[:12]})", file=sys.stderr)
    for name, which in (("baseline", base), ("candidate", cand)):
        if which is None:
            source = getattr(args, name)
            results = run_campaign(load_plant(source), reqset, workers=args.jobs, progress=not args.quiet,
                                   command_line=f"govcheck gate ({name} {source})")
            if name == "baseline":
                base = results
            else:
                cand = results
    result = compare(base, cand, args.max_margin_loss)
    table = gate_table(result)
    if args.quiet:
        print(table.rstrip().splitlines()[-1])
    else:
        sys.stdout.write(table)
    if args.markdown:
        write_text_atomic(args.markdown, gate_markdown(result))
    if args.json:
        write_text_atomic(args.json, results_json(result))
    return 0 if result["status"] == "pass" else 1
