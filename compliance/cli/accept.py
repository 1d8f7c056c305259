"""``govcheck accept``: a site's commissioning recordings judged by a requirement file, beside the model's prediction."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

from compliance.cli.common import (add_allow_conflicts, add_document_options, add_jobs, add_outputs, add_parser, add_quiet,
                                   add_reproducible, check_args_outputs, checked_requirements, document_options,
                                   sidecar_plant)
from compliance.errors import InputError


def register(subparsers):
    """Add the ``accept`` sub-command."""
    p = add_parser(
        subparsers, "accept",
        help="judge a site's commissioning recordings by a requirement file, beside the model's prediction",
        description=(
            "Read a site: a folder of commissioning recordings, one per test, each with its sidecar's [test] table (or "
            "recognised from its trace). Map every test to the requirement file's procedures x operating points, measure "
            "every figure the requirements judge with the simulation's metric code and its measurement uncertainty, "
            "judge each requirement (UNCERTAIN where the uncertainty straddles the limit), say what was not tested, and "
            "set the model's prediction of each test (replayed under its recorded conditions) beside it. --diagnose "
            "explains a disagreement with the joint diagnosis. Exit 0 when every mandatory requirement passes on what "
            "was tested, 1 otherwise, 2 on bad input (nothing written)."
        ),
        examples=[
            "govcheck accept site-p2 --requirements requirements/shpp-400kw.toml --json s.json",
            "govcheck accept site-p2 plant-a -r shpp-400kw --report s.html --pdf s.pdf --junit s.xml",
            "govcheck accept site-p2 -r shpp-400kw --diagnose --json s.json   # explain where the machine and the model differ",
            "govcheck gate s-new.json --baseline s.json                       # CI: gate a re-commissioning",
        ],
        usage="govcheck accept SITE [CONFIG] --requirements REQ [options]",
    )
    p.add_argument("inputs", nargs="+", metavar="SITE [CONFIG]",
                   help="the site folder, and optionally the plant configuration that predicts it (default: the sidecars' plant)")
    p.add_argument("--requirements", "-r", required=True, metavar="REQ", help="requirement file: a TOML file or a shipped name")
    p.add_argument("--column-map", help="column map (TOML path or shipped name) for recordings in a logger's own names and units")
    p.add_argument("--diagnose", action="store_true",
                   help="run the joint diagnosis where the machine and the model disagree and predict those tests again")
    p.add_argument("--no-prediction", action="store_true", help="judge the recordings only (no replay of the tests)")
    add_outputs(p, "json", "junit", "report", "pdf", help={"json": "write the site results (docs/acceptance.md) to FILE.json"})
    add_document_options(p)
    add_allow_conflicts(p)
    add_jobs(p)
    add_quiet(p, "print only the verdict line")
    add_reproducible(p)
    return p


def _site_and_config(inputs: list) -> tuple[Path, str | None]:
    if len(inputs) > 2:
        raise InputError(f"too many inputs {inputs}: give SITE and optionally CONFIG")
    folders = [x for x in inputs if Path(x).is_dir()]
    if not folders:
        raise InputError(f"{inputs[0]}: not a folder; SITE is a folder of recordings (one per test with its NAME.toml sidecar)")
    if len(folders) > 1:
        raise InputError(f"two folders given ({', '.join(folders)}); give one SITE and optionally one CONFIG")
    site = Path(folders[0])
    rest = [x for x in inputs if x != folders[0]]
    return site, rest[0] if rest else None


def _command_line(args, outputs: bool = True) -> str:
    parts = ["govcheck", "accept", *args.inputs, "--requirements", args.requirements]
    for flag in ("json", "junit", "report", "pdf", "jobs"):
        v = getattr(args, flag, None)
        if v is not None and outputs:
            parts += [f"--{flag}", str(v)]
    for flag in ("diagnose", "no_prediction", "reproducible"):
        if getattr(args, flag, False):
            parts.append(f"--{flag.replace('_', '-')}")
    return shlex.join(parts)


def _plant(config: str | None, recordings):
    from compliance.acceptance.site.folder import site_plant
    from compliance.model.config import load_plant

    if config:
        return load_plant(config)
    named, where = site_plant(recordings)
    if not named:
        raise InputError("no CONFIG given and no sidecar of the site names its 'plant'")
    first = next(r for r in recordings if r.path == where)
    return load_plant(sidecar_plant(first.meta, where))


def run(args) -> int:
    """Check inputs and outputs, judge the site, print the table, write the outputs; exit code from the verdict."""
    from compliance.acceptance.run import accept
    from compliance.acceptance.site.folder import read_site
    from compliance.acceptance.site_text import site_table
    from compliance.campaign.results_files import write_json, write_junit
    from compliance.files.reproducible import is_reproducible, make_reproducible
    from compliance.requirements.loading import load_requirements
    from compliance.requirements.verdict import Overall

    check_args_outputs(args)
    if args.diagnose and args.no_prediction:
        raise InputError("--diagnose needs the prediction (it explains where the machine and the model disagree); "
                         "drop --no-prediction")
    if args.jobs is not None and args.no_prediction:  # the recordings are judged in this process
        raise InputError(f"--jobs {args.jobs}: the prediction's replays run in parallel, and --no-prediction runs none; "
                         "drop --jobs")
    site, config = _site_and_config(args.inputs)
    reqset = load_requirements(args.requirements)
    recordings = read_site(site, args.column_map)  # every file read and checked before any replay
    cfg = _plant(config, recordings)
    checked_requirements(reqset, [cfg.p("cylinder.stroke")], args)  # as every command that loads a requirement set
    results = accept(site, reqset, cfg, recordings=recordings, predict=not args.no_prediction, diagnose=args.diagnose,
                     workers=args.jobs, progress=not args.quiet and sys.stderr.isatty(), command_line=_command_line(args))
    if is_reproducible(args.reproducible):
        results = make_reproducible(results, _command_line(args, outputs=False))
    table = site_table(results)
    if args.report or args.pdf:
        from compliance.campaign.results_files import results_json
        from compliance.report.site.document import render_site_report

        doc = document_options(args, args.json, results_json(results) if args.json else None)
        render_site_report(results, html_path=args.report, pdf_path=args.pdf, document=doc)
    if args.quiet:
        print(table.rstrip().splitlines()[-1])
    else:
        sys.stdout.write(table)
    if args.json:
        write_json(results, args.json)
    if args.junit:
        write_junit(results, args.junit)
    return 0 if results["summary"]["status"] == Overall.PASS else 1
