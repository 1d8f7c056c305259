"""``govcheck reproduce plant-a``: the paper's tests beside the simulated figures."""

from __future__ import annotations


from compliance.model.config import load_plant
from compliance.errors import InputError


def register(sub):
    p = sub.add_parser("reproduce", help="run the seed paper's tests and compare with its measured figures",
                       description="Run every test of the reference sheet's table 'Results the model must be compared with' "
                                   "and print simulated settling time and steady error beside the paper's, with the metric "
                                   "definitions; flagged rows name the assumed parameter that drives the difference.")
    p.add_argument("plant", help="reference plant name or configuration file (only plant-a has a paper table)")
    p.add_argument("--no-explain", action="store_true", help="skip the sensitivity runs that name the driving parameter")
    p.add_argument("--json", help="also write the comparison as JSON")
    p.add_argument("--calibrate", nargs="?", const="models/plant-a-calibrated.toml", metavar="OUT.toml",
                   help="fit the parameters the paper leaves unstated to its figures, print before/after and save "
                        "the calibrated configuration (default models/plant-a-calibrated.toml; docs/calibration.md)")
    return p


def run(args) -> int:
    from compliance.papers.plant_a import compare, format_table

    cfg = load_plant(args.plant)
    if cfg.options["cylinder.arrangement"] != "tandem":
        raise InputError(f"{args.plant}: the paper comparison exists for the tandem gate servo (plant A) only")
    if args.calibrate:
        from compliance.papers.calibration_run import run_calibration

        return run_calibration(cfg, args.calibrate, json_path=args.json)
    comp = compare(cfg, explain=not args.no_explain)
    print(format_table(comp))
    if args.json:
        from compliance.files.atomic import write_json_atomic

        write_json_atomic(args.json, {"plant": cfg.name, "stall_error_m": comp.stall_error, "notes": comp.notes,
                                      "rows": [r.__dict__ for r in comp.rows]})
    return 0
