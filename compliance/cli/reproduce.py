"""``govcheck reproduce plant-a``: the paper's tests beside the simulated figures."""

from __future__ import annotations

from compliance.cli.common import (add_jobs, add_outputs, add_parser, add_plant_argument, add_scheduler,
                                   check_args_outputs, check_scheduler, plant_from_args)
from compliance.errors import InputError


def register(sub):
    """Add the ``reproduce`` sub-command."""
    p = add_parser(
        sub, "reproduce",
        help="run the seed paper's tests and compare with its measured figures",
        description="Run every test of the reference plant's table of measured results (docs/reference-plant.md) "
                    "and print simulated settling time and steady error beside the paper's, with the metric "
                    "definitions; flagged rows name the assumed parameter that drives the difference.",
        examples=[
            "govcheck reproduce plant-a",
            "govcheck reproduce models/plant-a.toml --no-explain --json paper.json",
        ],
    )
    add_plant_argument(p, help="reference plant name or configuration file (only the tandem plant A has a paper table)")
    p.add_argument("--no-explain", action="store_true", help="skip the sensitivity runs that name the driving parameter")
    add_outputs(p, "json", help={"json": "also write the comparison as JSON to FILE.json"})
    p.add_argument("--calibrate", nargs="?", const="models/plant-a-calibrated.toml", metavar="OUT.toml",
                   help="fit the parameters the paper leaves unstated to its figures, print before/after and save "
                        "the calibrated configuration (default models/plant-a-calibrated.toml; docs/calibration.md)")
    add_scheduler(p, "the --calibrate search")
    add_jobs(p, "local worker processes of the --calibrate search")
    return p


def run(args) -> int:
    """Compare with the paper; print the table, write the JSON."""
    from compliance.papers.plant_a import compare, format_table

    check_args_outputs(args, (args.calibrate, "--calibrate", (".toml",)))
    scheduler = check_scheduler(args)
    if scheduler is not None and not args.calibrate:
        raise InputError(f"--scheduler {scheduler}: only the --calibrate search runs in parallel; add --calibrate")
    if args.jobs is not None and not args.calibrate:
        raise InputError(f"--jobs {args.jobs}: only the --calibrate search runs in parallel; add --calibrate")
    cfg = plant_from_args(args)
    if cfg.options["cylinder.arrangement"] != "tandem":
        from compliance.files.display import display_path

        raise InputError(f"{display_path(cfg.path) or cfg.name}: the paper comparison exists for the tandem gate servo (plant A) only")
    if args.calibrate:
        from compliance.papers.calibration_run import run_calibration

        return run_calibration(cfg, args.calibrate, json_path=args.json, scheduler=scheduler, workers=args.jobs)
    comp = compare(cfg, explain=not args.no_explain)
    print(format_table(comp))
    if args.json:
        from compliance.files.atomic import write_json_atomic

        write_json_atomic(args.json, {"plant": cfg.name, "stall_error_m": comp.stall_error, "notes": comp.notes,
                                      "rows": [r.__dict__ for r in comp.rows]})
    return 0
