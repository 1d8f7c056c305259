"""``govcheck report``: re-render the HTML / PDF report from saved results, without simulating."""

from __future__ import annotations

from pathlib import Path

from compliance.cli.common import (add_document_options, add_jobs, add_parser, add_scheduler, check_args_outputs,
                                   check_scheduler, document_options)
from compliance.errors import InputError
from compliance.files.jsonable import read_json


def register(subparsers):
    """Add the ``report`` sub-command."""
    p = add_parser(
        subparsers, "report",
        help="render the HTML/PDF report from a saved results JSON (no simulation)",
        description=(
            "Render the compliance report of a results file written by 'govcheck check --json' (or the "
            "validation report of a file written by 'govcheck validate --json') as one self-contained HTML "
            "file and/or an A4 PDF. Nothing is simulated. Without --report and --pdf the HTML is written next "
            "to the results with the suffix .html. Exit 0 when written, 2 on invalid input."
        ),
        examples=[
            "govcheck report reports/plant-a.json --report reports/plant-a.html --pdf reports/plant-a.pdf",
            "govcheck report r.json --linear lin.json --validation val.json --report full.html",
        ],
    )
    p.add_argument("results", metavar="RESULTS.json", help="results JSON (schema govcheck-results/1 or govcheck.validation/1)")
    p.add_argument("--report", "--html", dest="report", metavar="FILE.html", help="write the HTML report here")
    p.add_argument("--pdf", metavar="FILE.pdf", help="write the PDF report here")
    p.add_argument("--linear", metavar="LINEAR.json", action="append",
                   help="add the linear analysis written by 'govcheck linear --map --crosscheck --governor --json'; "
                        "repeat for more critical points (their Bode diagrams and poles are overlaid; map, "
                        "cross-check and governor parameters are taken from the first file that has them)")
    p.add_argument("--validation", metavar="VALIDATION.json",
                   help="add a model validation written by 'govcheck validate --json'")
    add_document_options(p)
    add_jobs(p, "processes drawing figures")
    add_scheduler(p, "the figures")
    p.add_argument("--appendix", choices=("none", "summary", "full"), default="summary",
                   help="compliance report appendix: none, summary (configuration, requirement file, versions; default) "
                        "or full (+ every run with its figures)")
    return p


def merge_linear(docs) -> dict:
    """Several ``govcheck linear --json`` documents -> one ``linear`` entry with every analysis."""
    out: dict = {"schema": "govcheck-linear/1", "analyses": []}
    for path, lin in docs:
        if lin.get("schema") != "govcheck-linear/1":
            raise InputError(f"{path}: key 'schema' is {lin.get('schema')!r}; expected 'govcheck-linear/1' "
                             "(written by govcheck linear --json)")
        if lin.get("analysis"):
            out["analyses"].append(lin["analysis"])
        for key in ("map", "crosscheck", "governor"):
            if lin.get(key) and key not in out:
                out[key] = lin[key]
    return out


def run(args) -> int:
    """Render the report(s); print where they were written."""
    from compliance.report.render import VALIDATION_SCHEMA, check_validation, render_report, render_validation_report
    from compliance.results.check_result import CheckResult

    html = args.report
    if not html and not args.pdf:
        html = str(Path(args.results).with_suffix(".html"))
    check_args_outputs(args, (None if args.report else html, "--report (default, beside the results)", (".html",)))
    scheduler = check_scheduler(args)
    data = read_json(args.results, "results")
    if data.get("schema") == VALIDATION_SCHEMA:
        if args.linear or args.validation:
            raise InputError(f"{args.results}: a validation results file takes no --linear / --validation")
        check_validation(data, str(args.results))
        if not html:
            raise InputError("a validation report needs --report (the PDF is made from it)")
        render_validation_report(data, html, args.pdf, workers=args.jobs, scheduler=scheduler)
    else:
        result = CheckResult.from_dict(data, str(args.results))
        if args.linear:
            result = result.with_(linear=merge_linear([(p, read_json(p, "linear analysis")) for p in args.linear]))
        if args.validation:
            val = read_json(args.validation, "validation")
            check_validation(val, str(args.validation))
            result = result.with_(validation=val)
        render_report(result, html, args.pdf, workers=args.jobs, appendix=args.appendix,
                      document=document_options(args, args.results), scheduler=scheduler)
    written = [p for p in (html, args.pdf) if p]
    print("report: " + ", ".join(written))
    return 0
