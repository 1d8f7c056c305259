"""``govcheck gate``: fail CI when a candidate configuration regresses against a baseline."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from compliance.cli.common import (add_allow_conflicts, add_jobs, add_outputs, add_parser, add_quiet, add_reproducible,
                                   check_args_outputs)
from compliance.errors import InputError, did_you_mean


def register(subparsers):
    """Add the ``gate`` sub-command."""
    p = add_parser(
        subparsers, "gate",
        help="compare a candidate with a baseline and fail on regressions",
        description=(
            "Compare requirement by requirement: fail (exit 1) when a pass turns into a fail (or stops being "
            "evaluated), a mandatory requirement evaluated in the baseline (pass or fail) can no longer be "
            "evaluated (unless --allow-not-evaluated ID), a requirement disappears, a new one fails, or a "
            "worst-case margin shrinks by more than --max-margin-loss percentage points. Baseline and candidate "
            "are results JSON files or plant configurations (which are checked first)."
        ),
        examples=[
            "govcheck gate models/candidate.toml --baseline reports/plant-a.json --markdown pr-comment.md",
            "govcheck gate new.json --baseline old.json --max-margin-loss 5 --json gate.json",
            "govcheck gate models/candidate.toml --baseline models/plant-a.toml -r shpp-400kw --allow-not-evaluated IEC61362-TC",
        ],
    )
    p.add_argument("candidate_pos", metavar="CANDIDATE", nargs="?",
                   help="candidate: a plant configuration (TOML or reference name) or a results JSON")
    p.add_argument("--candidate", help=argparse.SUPPRESS)
    p.add_argument("--baseline", required=True, metavar="BASELINE",
                   help="baseline: results JSON from 'govcheck check --json' or a plant configuration")
    p.add_argument("--requirements", "-r", default=None, metavar="REQ",
                   help="requirement file (default: the one recorded in a baseline results JSON)")
    p.add_argument("--max-margin-loss", type=float, default=None, metavar="PP",
                   help="largest allowed loss of a worst-case margin, in percentage points (default: not checked)")
    p.add_argument("--allow-not-evaluated", action="append", default=[], metavar="ID",
                   help="allow requirement ID to become not evaluated without tripping the gate (repeatable; "
                        "the PR comment still says why it could not be evaluated)")
    p.add_argument("--markdown", metavar="FILE.md", help="write a Markdown summary for a pull-request comment")
    add_outputs(p, "json", help={"json": "write the gate result as JSON to FILE.json"})
    add_allow_conflicts(p)
    add_jobs(p)
    add_quiet(p, "no progress bar; print only the gate line")
    add_reproducible(p)
    return p


def _is_results(path: str) -> bool:
    return path.endswith((".json", ".json.gz"))  # .json.gz: a sweep's best candidate is stored compressed


def _requirements_for(args, baseline_results):
    """Requirement file to run configurations against."""
    from compliance.requirements.loading import load_requirements

    if args.requirements:
        return load_requirements(args.requirements)
    if baseline_results is None:
        raise InputError("--requirements is needed when the baseline is a plant configuration")
    rs = baseline_results.requirement_set
    path = rs.path
    if path and Path(path).is_file():
        return load_requirements(path)
    if rs.name:
        try:
            return load_requirements(rs.name)
        except InputError:
            pass
    raise InputError(f"{args.baseline}: requirement_set.path: '{path}' is not readable here; give --requirements")


def _check_allowed_ids(allowed, reqset, *results) -> None:
    """Every ``--allow-not-evaluated`` ID names a requirement of the comparison (a typo would allow nothing)."""
    known = {r.id for r in reqset.requirements} if reqset is not None else set()
    for res in results:
        if res is not None:
            known |= {e.id for e in res.requirements}
    for rid in allowed:
        if rid not in known:
            raise InputError(f"--allow-not-evaluated {rid}: no requirement with this ID in the comparison"
                             f"{did_you_mean(rid, known)} (IDs: {', '.join(sorted(known)) or 'none'})")


def _candidate(args) -> str:
    pos, old = args.candidate_pos, args.candidate
    if pos and old and pos != old:
        raise InputError(f"two candidates given: '{pos}' and --candidate '{old}'; give one (positional CANDIDATE)")
    if not (pos or old):
        raise InputError("no candidate given: pass CANDIDATE (a plant configuration or a results JSON)")
    return pos or old


def run(args) -> int:
    """Obtain both results, compare, print, write; exit 1 when the gate trips."""
    from compliance.campaign.regression_gate import compare, gate_markdown, gate_table
    from compliance.campaign.results_files import read_results
    from compliance.pipeline.chain import Check
    from compliance.files.atomic import write_json_atomic, write_text_atomic
    from compliance.files.reproducible import is_reproducible, make_reproducible
    from compliance.model.config import load_plant
    from compliance.requirements.verdict import Overall

    candidate = _candidate(args)
    if args.max_margin_loss is not None and not args.max_margin_loss >= 0:
        raise InputError(f"--max-margin-loss {args.max_margin_loss}: expected a number of percentage points >= 0")
    check_args_outputs(args, (args.markdown, "--markdown", (".md", ".markdown")))
    if _is_results(args.baseline) and _is_results(candidate):  # nothing is run: the options of a run do nothing
        for flag, value in (("--allow-conflicts", args.allow_conflicts or None), ("--requirements", args.requirements),
                            ("--jobs", args.jobs)):
            if value is not None:
                raise InputError(f"{flag}: both sides are results files, so nothing is run or judged here; drop {flag}")
    base = read_results(args.baseline) if _is_results(args.baseline) else None
    cand = read_results(candidate) if _is_results(candidate) else None
    sources = {"baseline": args.baseline, "candidate": candidate}
    configs = {name: load_plant(src) for name, src in sources.items() if not _is_results(src)}
    reqset = None
    if configs:
        reqset = _requirements_for(args, base)
        if base is not None and reqset.digest != base.requirement_set.digest:
            print(f"govcheck gate: note: {reqset.path} changed since the baseline was made "
                  f"(digest {str(base.requirement_set.digest)[:12]} -> {reqset.digest[:12]})", file=sys.stderr)
    _check_allowed_ids(args.allow_not_evaluated, reqset, base, cand)
    # every side's inputs vetted (conflicts at each plant's stroke) before either is simulated
    prepared = {name: Check.of(cfg, reqset, uncertainty=None, allow_conflicts=args.allow_conflicts)
                for name, cfg in configs.items()}
    for name, ready in prepared.items():
        results = ready.run(jobs=args.jobs, progress=not args.quiet, command_line=f"govcheck gate ({name} {sources[name]})")
        base, cand = (results, cand) if name == "baseline" else (base, results)
    result = compare(base, cand, args.max_margin_loss, allow_not_evaluated=args.allow_not_evaluated)
    table = gate_table(result)
    if args.quiet:
        print(table.rstrip().splitlines()[-1])
    else:
        sys.stdout.write(table)
    if is_reproducible(args.reproducible):
        result = make_reproducible(result)
    if args.markdown:
        write_text_atomic(args.markdown, gate_markdown(result))
    if args.json:
        write_json_atomic(args.json, result)
    return 0 if result["status"] == Overall.PASS else 1
