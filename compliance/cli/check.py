"""``govcheck check``: does a candidate configuration meet a requirement file? With evidence."""

from __future__ import annotations

import shlex
import sys

from compliance.cli.common import (add_allow_conflicts, add_document_options, add_jobs, add_outputs, add_parser, add_plant_argument, add_quiet,
                                   add_reproducible, document_options,
                                   check_args_outputs, plant_source)


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


def renderer(args):
    """The report renderer when --report/--pdf is asked for (imported lazily)."""
    if not (args.report or args.pdf):
        return None
    from compliance.report.render import render_report

    return render_report


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


def finish_results(results: dict, args, name: str = "check") -> dict:
    """Results as written: reproducible (fixed ``created``, no timings) with --reproducible / SOURCE_DATE_EPOCH."""
    from compliance.files.reproducible import is_reproducible, make_reproducible

    if not is_reproducible(getattr(args, "reproducible", False)):
        return results
    return make_reproducible(results, command_line(args, name, outputs=False))


def monte_carlo(cfg, reqset, results: dict, args) -> None:
    """Replace the verdicts' bands by a Monte Carlo of ``args.uncertainty`` plants and re-summarise."""
    from compliance.campaign.basis import verdict_qualifier
    from compliance.campaign.run import summary_section
    from compliance.sweep.tolerance.uncertainty_mc import monte_carlo_bands

    results["uncertainty"] = monte_carlo_bands(cfg, reqset, results, args.uncertainty, workers=args.jobs,
                                               progress=not args.quiet)
    results["summary"] = summary_section(results["requirements"], results["summary"]["notes"], results["uncertainty"])
    results["summary"]["qualifier"] = verdict_qualifier(results)


def check_uncertainty_option(args, cfg=None) -> None:
    """``--uncertainty N``: at least 2 plants (or 0), and, given the plant, a plant file that declares ranges."""
    from compliance.errors import InputError

    if args.uncertainty is not None and (args.uncertainty == 1 or args.uncertainty < 0):
        raise InputError(f"--uncertainty {args.uncertainty}: expected at least 2 plants (or 0 for point values)")
    if args.uncertainty and cfg is not None:
        from compliance.campaign.uncertainty import ranged_parameters

        if not ranged_parameters(cfg):
            raise InputError(f"{cfg.path or cfg.name}: --uncertainty {args.uncertainty}: the plant file gives no parameter "
                             "a range (range = [low, high] with range_note, docs/requirements.md 'Uncertainty')")


def run(args) -> int:
    """Check outputs and inputs, run the campaign, print the table, write the outputs; exit code from the verdict."""
    from compliance.campaign.results_files import summary_table, write_json, write_junit
    from compliance.campaign.run import run_campaign
    from compliance.cli.common import plant_from_args
    from compliance.cli.progress import progress
    from compliance.files.reproducible import fixed_created, is_reproducible
    from compliance.cli.common import checked_requirements
    from compliance.requirements.verdict import Overall

    check_uncertainty_option(args)
    if args.appendix is not None and not (args.report or args.pdf):
        from compliance.errors import InputError

        raise InputError(f"--appendix {args.appendix}: shapes the report, and no report is asked for; add --report "
                         "FILE.html or --pdf FILE.pdf")
    args.appendix = args.appendix or "summary"
    from compliance.cli.sweep import check_remedies_options

    check_args_outputs(args, (getattr(args, "save_remedy", None), "--save-remedy", (".toml",)))
    check_remedies_options(args)
    if is_reproducible(args.reproducible):
        fixed_created()  # a malformed SOURCE_DATE_EPOCH is refused before the work
    render = renderer(args)
    if args.remedies and args.remedies != "default":  # a bad sweep file is exit 2 before any simulation
        from compliance.sweep.candidates.spec import load_sweep

        load_sweep(args.remedies)
    cfg = plant_from_args(args)
    reqset = checked_requirements(args.requirements, [cfg.p("cylinder.stroke")], args)  # before any simulation
    check_uncertainty_option(args, cfg)
    stages = 1 + bool(args.linear) + (render is not None)
    # the campaign reports its runs itself on a terminal; in a CI log these stage lines (and a heartbeat) show progress
    with progress(stages, "check", quiet=args.quiet or sys.stderr.isatty(), unit="stage", first="campaign") as bar:
        results = run_campaign(cfg, reqset, workers=args.jobs, progress=not args.quiet, command_line=command_line(args),
                               uncertainty="local" if args.uncertainty is None else None)
        if args.uncertainty:
            monte_carlo(cfg, reqset, results, args)
        bar.update(1)
        if args.linear:
            from compliance.linear.operating_points import linear_for_campaign

            bar.set_postfix_str("linear analysis", refresh=False)
            results["linear"] = linear_for_campaign(cfg, reqset)
            bar.update(1)
        if args.remedies:
            from compliance.sweep.check_remedies import remedies_for_check

            from compliance.cli.sweep import remedies_kwargs

            results["remedies"] = remedies_for_check(cfg, reqset, args.remedies, workers=args.jobs, progress=not args.quiet,
                                                     **remedies_kwargs(args))
        results = finish_results(results, args)
        table = summary_table(results)
        if render is not None:
            bar.set_postfix_str("report", refresh=False)
            from compliance.campaign.results_files import results_json

            doc = document_options(args, args.json, results_json(results) if args.json else None)
            render(results, html_path=args.report, pdf_path=args.pdf, appendix=args.appendix, document=doc)
            bar.update(1)
    if args.quiet:
        print(table.rstrip().splitlines()[-1])
    else:
        sys.stdout.write(table)
        if args.remedies:
            from compliance.sweep.summary_text import remedies_markdown

            sys.stdout.write("\n" + remedies_markdown(results["remedies"]))
    if args.remedies:
        from compliance.cli.sweep import save_remedy

        save_remedy(args, cfg, results["remedies"])
    if args.json:
        write_json(results, args.json)
    if args.junit:
        write_junit(results, args.junit)
    return 0 if results["summary"]["status"] == Overall.PASS else 1
