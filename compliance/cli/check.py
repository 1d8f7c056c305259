"""``govcheck check``: does a candidate configuration meet a requirement file? With evidence."""

from __future__ import annotations

import shlex
import sys

from compliance.cli.common import (add_allow_conflicts, add_document_options, add_jobs, add_outputs, add_parser,
                                   add_plant_argument, add_quiet, add_reproducible, check_args_outputs, document_options,
                                   plant_source)


def register(subparsers):
    """Add the ``check`` sub-command."""
    from compliance.files.shipped import shipped_names

    names = shipped_names("requirements")
    p = add_parser(
        subparsers, "check",
        help="check a plant configuration against a requirement file",
        description=(
            "Run the procedures a requirement file names at its operating points, measure the metrics, "
            "judge every requirement (value, limit, margin) and print a summary. "
            "Exit 0 when every mandatory requirement passes, 1 when one fails or could not be evaluated, "
            "2 on invalid input (every output path is checked before anything runs).\n\n"
            "shipped requirement files (-r NAME): " + ", ".join(names)
        ),
        examples=[
            "govcheck check models/plant-a.toml -r shpp-400kw",
            "govcheck check plant-a -r iec61362 --json r.json --junit r.xml --report r.html --pdf r.pdf",
            "govcheck check models/plant-a.toml -r requirements/shpp-400kw.toml --linear -q --reproducible --json r.json",
            "govcheck check plant-a -r shpp-400kw --uncertainty 32 --json r.json   # Monte Carlo bands over the declared ranges",
        ],
    )
    add_plant_argument(p)
    p.add_argument("--requirements", "-r", required=True, metavar="REQ",
                   help="requirement file: a TOML file or a shipped name (" + ", ".join(names) + ")")
    add_outputs(p, "json", "junit", "report", "pdf")
    p.add_argument("--appendix", choices=("none", "summary", "full"), default=None,
                   help="with --report/--pdf: report appendix: none, summary (configuration, requirement file, versions; "
                        "default) or full (+ every run)")
    p.add_argument("--linear", action="store_true",
                   help="add the linear analysis to the results and report: every operating point, the stroke x load map, "
                        "the linear/nonlinear cross-check and the HYGOV parameters (adds ~20-40 s)")
    p.add_argument("--remedies", nargs="?", const="default", metavar="SWEEP.toml",
                   help="what would make it pass: sensitivities and the smallest verified change over the on-site settings "
                        "(or the adjustable space of a sweep file); added to the results as 'remedies'")
    p.add_argument("--uncertainty", type=int, default=None, metavar="N",
                   help="bands from a Latin-hypercube Monte Carlo of N plants over the plant file's declared ranges "
                        "(instead of the local sensitivities); 0 = point values only")
    add_allow_conflicts(p)
    from compliance.cli.sweep import add_remedies_options

    add_remedies_options(p)
    add_document_options(p)
    add_jobs(p)
    add_quiet(p, "no progress bar; print only the verdict line")
    add_reproducible(p)
    return p


def command_line(args, name: str = "check", outputs: bool = True) -> str:
    """The command as given (reconstructed from the parsed arguments); without output paths if not ``outputs``."""
    parts = ["govcheck", name, plant_source(args), "--requirements", args.requirements]
    for flag in ("json", "junit", "report", "pdf", "jobs"):
        v = getattr(args, flag, None)
        if v is not None and outputs:
            parts += [f"--{flag}", str(v)]
    if getattr(args, "uncertainty", None) is not None:
        parts += ["--uncertainty", str(args.uncertainty)]
    for flag in ("linear", "quiet", "reproducible", "allow_conflicts"):
        if getattr(args, flag, False):
            parts.append(f"--{flag.replace('_', '-')}")
    return shlex.join(parts)


def _check_first(args) -> None:
    """Outputs, options and SOURCE_DATE_EPOCH checked before any work (exit 2)."""
    from compliance.cli.sweep import check_remedies_options
    from compliance.files.reproducible import fixed_created, is_reproducible
    from compliance.pipeline.chain import check_uncertainty

    check_uncertainty(args.uncertainty)
    if args.appendix is not None and not (args.report or args.pdf):
        from compliance.errors import InputError

        raise InputError(f"--appendix {args.appendix}: shapes the report, and no report is asked for; add --report "
                         "FILE.html or --pdf FILE.pdf")
    args.appendix = args.appendix or "summary"
    check_args_outputs(args, (getattr(args, "save_remedy", None), "--save-remedy", (".toml",)))
    check_remedies_options(args)
    if is_reproducible(args.reproducible):
        fixed_created()  # a malformed SOURCE_DATE_EPOCH is refused before the work


def _print(result, args) -> None:
    from compliance.campaign.results_files import summary_table

    table = summary_table(result)
    if args.quiet:
        print(table.rstrip().splitlines()[-1])
        return
    sys.stdout.write(table)
    if result.remedies is not None:
        from compliance.sweep.summary_text import remedies_markdown

        sys.stdout.write("\n" + remedies_markdown(result.remedies))


def run(args) -> int:
    """Parse, call ``compliance.check``, print and write; exit 0 when every mandatory requirement passes, else 1."""
    from compliance.cli.common import plant_from_args
    from compliance.cli.progress import progress
    from compliance.cli.sweep import remedies_kwargs, save_remedy
    from compliance.files.reproducible import is_reproducible
    from compliance.pipeline.chain import Check

    _check_first(args)
    cfg = plant_from_args(args)
    uncertainty = "local" if args.uncertainty is None else args.uncertainty
    prepared = Check.of(cfg, args.requirements, linear=args.linear, remedies=args.remedies, uncertainty=uncertainty,
                        allow_conflicts=args.allow_conflicts)  # every input checked before any work
    render = args.report or args.pdf
    stages = ["campaign"] + ["linear analysis"] * bool(args.linear) + ["report"] * bool(render)
    # the campaign reports its runs itself on a terminal; in a CI log these stage lines (and a heartbeat) show progress
    with progress(len(stages), "check", quiet=args.quiet or sys.stderr.isatty(), unit="stage", first="campaign") as bar:
        def on_stage(name):
            if name in stages:
                bar.update(1)
                if stages.index(name) + 1 < len(stages):
                    bar.set_postfix_str(stages[stages.index(name) + 1], refresh=False)

        result = prepared.run(jobs=args.jobs, progress=not args.quiet, command_line=command_line(args),
                              remedy_options=remedies_kwargs(args) if args.remedies else None, on_stage=on_stage)
        if is_reproducible(args.reproducible):
            result = result.made_reproducible(command_line(args, outputs=False))
        if render:
            from compliance.report.render import render_report

            doc = document_options(args, args.json, result.json_text() if args.json else None)
            render_report(result, html_path=args.report, pdf_path=args.pdf, appendix=args.appendix, document=doc)
            on_stage("report")
    _print(result, args)
    if args.remedies:
        save_remedy(args, cfg, result.remedies)
    write_outputs(result, args)
    return 0 if result.passed else 1


def write_outputs(result, args) -> None:
    """The results JSON (``--json``) and JUnit XML (``--junit``)."""
    from compliance.campaign.results_files import write_junit

    if args.json:
        result.to_json(args.json)
    if args.junit:
        write_junit(result, args.junit)
