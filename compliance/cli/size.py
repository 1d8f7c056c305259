"""``govcheck size``: propose a gate servo for a duty and a requirement file, check it, hand it to remedies."""

from __future__ import annotations

import sys

from compliance.cli.common import add_allow_conflicts, add_jobs, add_outputs, add_parser, add_quiet, check_args_outputs
from compliance.errors import InputError


def register(subparsers):
    """Add the ``size`` sub-command."""
    p = add_parser(
        subparsers, "size",
        help="size cylinders, valve, throttles and controller from a duty and a requirement file",
        description=(
            "From the duty (stroke, supply pressure, closing force over the stroke, opening/closing times; a "
            "govcheck-duty/1 TOML file) and the requirement file, propose ISO 15552 cylinders (count, bore, rod), "
            "a valve rating (ISO 6358 nominal flow) and the governor settings (set-point rate limiter for the stroke "
            "times, flow-control valves wide open as its backstop, PID gains tuned on the file's own time-constant "
            "test) by the rules of docs/sizing.md; what sizing does not decide comes from the duty's template "
            "configuration. The proposal is checked like `govcheck check`, corrected and, when what fails grows "
            "with the load's share of the cylinders' force, sized again on the next pair of cylinders up; the "
            "requirement it cannot meet is named with the arithmetic. With --remedies it is handed to the remedies "
            "search. Exit 0 when the proposal passes every mandatory requirement, 1 when not, 2 on invalid input."
        ),
        examples=[
            "govcheck size requirements/shpp-400kw.toml --duty models/duties/plant-a.toml --out sized.toml",
            "govcheck size shpp-400kw --duty models/duties/plant-a.toml --out sized.toml --remedies --save-remedy fixed.toml",
        ],
    )
    p.add_argument("requirements", metavar="REQUIREMENTS", help="requirement file: a TOML file or a shipped name")
    p.add_argument("--duty", required=True, metavar="DUTY.toml", help="the duty (schema govcheck-duty/1, docs/sizing.md)")
    p.add_argument("--out", metavar="FILE.toml", help="write the proposed configuration here (when the run has finished; "
                                                     "never over the duty, its template or the requirement file)")
    p.add_argument("--no-check", action="store_true", help="propose only; do not run the campaign (no results: takes no "
                                                          "--json, --remedies or --jobs)")
    p.add_argument("--remedies", action="store_const", const="default", default=None,
                   help="hand the proposal to the remedies search (as `govcheck check --remedies`)")
    from compliance.cli.sweep import add_remedies_options

    add_remedies_options(p)
    add_outputs(p, "json")
    add_allow_conflicts(p)
    add_jobs(p)
    add_quiet(p, "print only the verdict line")
    return p


def _sizing_text(rec: dict, rounds: list) -> str:
    c, v = rec["cylinders"], rec["valve"]
    lines = []
    for r in rounds[:-1]:
        lines.append(f"tried {r['count']} x {r['bore']*1e3:.0f} mm bore (load share {r['load_ratio']:.2f}, {r['valve_rating']:.0f} "
                     f"NL/min): {r['status']}, failing {', '.join(r['failed_mandatory']) or '-'}"
                     + (f"; {r['cannot']}" if r.get("cannot") else "") + " -> the next pair up")
    lines += [f"cylinders: {c['count']} x ISO 15552 {c['bore']*1e3:.0f} mm bore / {c['rod']*1e3:.0f} mm rod ({c['arrangement']}); "
              f"side area {c['area']*1e4:.1f} cm^2 >= {c['area_needed']*1e4:.1f} cm^2 needed; load ratio {c['load_ratio']:.2f}",
              f"valve: {v['rating']:.0f} NL/min ({v['rating_needed']:.0f} NL/min needed for {rec['stroke_speed']*1e3:.1f} mm/s "
              f"at 3x the filling flow); C = {v['conductance']*1e8:.2f} dm^3/(s*bar)"]
    d = rec.get("design") or {}
    for k, why in (d.get("limiter") or {}).items():
        lines.append(f"{k}: {why}")
    for t in d.get("tau") or []:
        rng = ", ".join(f"{k} {v[0]:.3f}-{v[1]:.3f} s" for k, v in (("up", t["up"]), ("down", t["down"])) if v)
        lines.append(f"time constant at K_P {t['kp']:.0f} V/m, K_D {t['kd']:.1f} V*s/m, closing slope {t['slope_negative']:.2f}: {rng}")
    for r in d.get("rounds") or []:
        lines.append(f"check failed {', '.join(r['failing'])}: " + ("; ".join(r["corrections"]) or "no correction applies"))
    st = d.get("stability") or []
    if st:
        pm = min((s["phase_margin_deg"] for s in st if s["phase_margin_deg"] is not None), default=None)
        gm = min((s["gain_margin_db"] for s in st if s["gain_margin_db"] is not None), default=None)
        lines.append(f"linearised loop: least phase margin {pm:.0f} deg, least gain margin {gm:.1f} dB over {len(st)} points "
                     "(criterion 30 deg, 6 dB)" if pm is not None and gm is not None else "linearised loop: no margins")
    if d.get("cannot"):
        lines.append(f"cannot meet: {d['cannot']}")
    return "\n".join(lines) + "\n"


def _refuse_unused(args) -> None:
    """With --no-check nothing is checked, so an option that shapes the check would do nothing: refused."""
    if not args.no_check:
        return
    for flag, value in (("--json", args.json), ("--remedies", args.remedies), ("--jobs", args.jobs),
                        ("--save-remedy", args.save_remedy), ("--catalogue", args.catalogue),
                        ("--yield-units", args.yield_units), ("--scheduler", args.scheduler),
                        ("--remedies-state", args.remedies_state)):
        if value is not None:
            raise InputError(f"{flag} does nothing with --no-check (the proposal is not checked, so there are no results); "
                             f"drop {flag} or --no-check")


def _sized_configuration(cfg, out: str | None):
    """The proposal as it will be written (rendered to TOML and read back: what is checked is what is saved)."""
    import hashlib
    import tomllib

    from compliance.model.config import plant_from_dict, plant_to_toml

    text = plant_to_toml(cfg)
    return plant_from_dict(tomllib.loads(text), out or "<sized configuration>", hashlib.sha256(text.encode()).hexdigest()), text


def run(args) -> int:
    """Size, set the governor, check (stepping the cylinders up when needed), optionally search remedies, then write.

    Every input and output is checked first; the proposal (--out) is written only when the run has
    finished, so an interrupted or failed run leaves nothing behind.
    """
    from compliance.cli.common import checked_requirements
    from compliance.cli.sweep import check_remedies_options, remedies_kwargs, save_remedy
    from compliance.files.atomic import write_text_atomic
    from compliance.files.shipped import resolve_shipped
    from compliance.model.config import load_plant
    from compliance.sweep.sizing.duty_file import load_duty
    from compliance.sweep.sizing.size_servo import size_and_check, size_servo, time_constant_target

    _refuse_unused(args)
    check_remedies_options(args)
    duty = load_duty(args.duty)
    template_path = resolve_shipped(duty.template, "plant")
    check_args_outputs(args, (args.out, "--out", (".toml",)), (args.save_remedy, "--save-remedy", (".toml",)),
                       inputs={str(template_path): f"the template of {args.duty}", args.duty: "--duty"})
    template = load_plant(duty.template)
    reqset = checked_requirements(args.requirements, [duty.stroke], args)  # before any simulation
    if args.no_check:
        from compliance.sweep.sizing.governor_design import design_governor

        cfg, rec = size_servo(duty, template, time_constant_target(reqset))
        cfg, rec["design"] = design_governor(cfg, reqset, tune=False)
        if not args.quiet:
            sys.stdout.write(_sizing_text(rec, [{}]))
        if args.out:
            write_text_atomic(args.out, _sized_configuration(cfg, args.out)[1])
        return 0
    from compliance.campaign.results_files import summary_table
    from compliance.pipeline.chain import Check, remedy_search
    from compliance.results.check_result import CheckResult

    cfg, rec, results, rounds = size_and_check(duty, template, reqset, workers=args.jobs, progress=not args.quiet)
    if not args.quiet:
        sys.stdout.write(_sizing_text(rec, rounds))
    cfg, text = _sized_configuration(cfg, args.out)  # what is judged is what --out will hold, written at the end
    from compliance.campaign.uncertainty import ranged_parameters

    if ranged_parameters(cfg):  # judged as `govcheck check` will judge the written file: with the bands of its declared ranges
        prepared = Check.of(cfg, reqset, uncertainty="local", allow_conflicts=args.allow_conflicts)
        results = prepared.run(jobs=args.jobs, progress=not args.quiet)
    else:
        results = CheckResult.of(results)
    results = results.with_(sizing={"duty": duty.path, "record": rec, "rounds": rounds})
    if args.remedies:
        results = results.with_(remedies=remedy_search(cfg, reqset, "default", jobs=args.jobs, progress=not args.quiet,
                                                       **remedies_kwargs(args)))
    table = summary_table(results)
    sys.stdout.write(table.rstrip().splitlines()[-1] + "\n" if args.quiet else table)
    if args.remedies and not args.quiet:
        from compliance.sweep.summary_text import remedies_markdown

        sys.stdout.write("\n" + remedies_markdown(results.remedies))
    if args.out:
        write_text_atomic(args.out, text)
    if args.remedies:
        save_remedy(args, cfg, results.remedies)
    if args.json:
        results.to_json(args.json)
    return 0 if results.passed else 1
