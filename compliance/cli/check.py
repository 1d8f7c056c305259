"""``govcheck check``: does a candidate configuration meet a requirement file? With evidence."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

from compliance.errors import InputError


def register(subparsers):
    """Add the ``check`` sub-command."""
    p = subparsers.add_parser(
        "check",
        help="check a plant configuration against a requirement file",
        description=(
            "Run the procedures a requirement file names at its operating points, measure the metrics, "
            "judge every requirement (value, limit, margin) and print a summary. "
            "Exit 0 when every mandatory requirement passes, 1 when one fails or could not be evaluated, "
            "2 on invalid input."
        ),
    )
    p.add_argument("plant", help="plant configuration: a TOML file or a reference name (plant-a)")
    p.add_argument("--requirements", "-r", required=True,
                   help="requirement file: a TOML file or a reference name (iec61362, ieee125, iec60308, shpp-400kw)")
    p.add_argument("--json", metavar="OUT.json", help="write the results JSON (docs/results-schema.md)")
    p.add_argument("--junit", metavar="OUT.xml", help="write JUnit XML for CI")
    p.add_argument("--report", metavar="OUT.html", help="write the HTML report")
    p.add_argument("--pdf", metavar="OUT.pdf", help="write the PDF report")
    p.add_argument("--appendix", choices=("none", "summary", "full"), default="summary",
                   help="report appendix: none, summary (configuration, requirement file, versions; default) or full (+ every run)")
    p.add_argument("--linear", action="store_true",
                   help="add the linear analysis to the results and report: every operating point, the stroke x load map, "
                        "the linear/nonlinear cross-check and the HYGOV parameters (adds ~20-40 s)")
    p.add_argument("--jobs", "-j", type=int, default=None, help="worker processes (default: available cores)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar; print only the verdict line")
    return p


def _check_out(path: str | None, flag: str):
    if path is None:
        return
    folder = Path(path).parent
    if str(folder) and not folder.is_dir():
        raise InputError(f"{flag} {path}: folder '{folder}' does not exist")


def renderer(args):
    """The report renderer when --report/--pdf is asked for (imported lazily)."""
    if not (args.report or args.pdf):
        return None
    from compliance.report.render import render_report

    return render_report


def command_line(args, name: str = "check") -> str:
    """The command as given (reconstructed from the parsed arguments)."""
    parts = ["govcheck", name, args.plant, "--requirements", args.requirements]
    for flag in ("json", "junit", "report", "pdf", "jobs"):
        v = getattr(args, flag, None)
        if v is not None:
            parts += [f"--{flag}", str(v)]
    if getattr(args, "linear", False):
        parts.append("--linear")
    if getattr(args, "quiet", False):
        parts.append("--quiet")
    return shlex.join(parts)


def run(args) -> int:
    """Run the campaign, print the table, write the outputs; exit code from the verdict."""
    from compliance.model.config import load_plant
    from compliance.campaign.run import run_campaign
    from compliance.requirements.loading import load_requirements
    from compliance.campaign.results_files import summary_table, write_json, write_junit

    if args.jobs is not None and args.jobs < 1:
        raise InputError(f"--jobs {args.jobs}: expected a positive number of processes")
    for path, flag in ((args.json, "--json"), (args.junit, "--junit"), (args.report, "--report"), (args.pdf, "--pdf")):
        _check_out(path, flag)
    render = renderer(args)
    cfg = load_plant(args.plant)
    reqset = load_requirements(args.requirements)
    results = run_campaign(cfg, reqset, workers=args.jobs, progress=not args.quiet, command_line=command_line(args))
    if args.linear:
        from compliance.linear.operating_points import linear_for_campaign

        results["linear"] = linear_for_campaign(cfg, reqset)
    table = summary_table(results)
    if args.quiet:
        print(table.rstrip().splitlines()[-1])
    else:
        sys.stdout.write(table)
    if args.json:
        write_json(results, args.json)
    if args.junit:
        write_junit(results, args.junit)
    if render is not None:
        render(results, html_path=args.report, pdf_path=args.pdf, appendix=getattr(args, "appendix", "summary"))
    return 0 if results["summary"]["status"] == "pass" else 1
