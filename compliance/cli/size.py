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
            "a valve rating (ISO 6358 nominal flow), meter-out throttles refined by simulation to the stroke times, "
            "PID gains and dead-zone compensation from the rules of docs/sizing.md; what sizing does not decide "
            "comes from the duty's template configuration. The proposal is then checked like `govcheck check` "
            "and, with --remedies, handed to the remedies search. Exit 0 when the proposal passes every mandatory "
            "requirement, 1 when not, 2 on invalid input."
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


def _sizing_text(rec: dict, tune: dict) -> str:
    c, v, k = rec["cylinders"], rec["valve"], rec["controller"]
    lines = [f"cylinders: {c['count']} x ISO 15552 {c['bore']*1e3:.0f} mm bore / {c['rod']*1e3:.0f} mm rod ({c['arrangement']}); "
             f"side area {c['area']*1e4:.1f} cm^2 >= {c['area_needed']*1e4:.1f} cm^2 needed; load ratio {c['load_ratio']:.2f}",
             f"valve: {v['rating']:.0f} NL/min ({v['rating_needed']:.0f} NL/min needed for {rec['stroke_speed']*1e3:.1f} mm/s "
             f"at 3x the filling flow); C = {v['conductance']*1e8:.2f} dm^3/(s*bar)"]
    for d, t in tune.items():
        lines.append(f"{d} throttle: " + (f"C = {t['conductance']*1e8:.3f} dm^3/(s*bar) -> {t['achieved']:.2f} s "
                                          f"(target {t['target']:.2f} s at {t['operating_point']})" if isinstance(t, dict) else t))
    lines.append(f"PID: K_P = {k['controller.kp']:.0f} V/m (tau {rec['tau_target']:.3f} s, speed gain "
                 f"{k['_speed_gain']*1e3:.1f} mm/s per V), K_I = {k['controller.ki']:.3g} V/(m*s), K_D = {k['controller.kd']:.2f} "
                 f"V*s/m (omega_n {k['_omega']:.0f} rad/s); compensation {k['controller.compensation_dead_zone_positive']:.2f}/"
                 f"{k['controller.compensation_dead_zone_negative']:.2f} V, width {k['controller.compensation_width']:.2f} V")
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
    """Size, check, optionally search remedies, then write; exit code from the proposal's verdict.

    Every input and output is checked first; the proposal (--out) is written only when the run has
    finished, so an interrupted or failed run leaves nothing behind.
    """
    from compliance.cli.common import checked_requirements
    from compliance.cli.sweep import check_remedies_options, remedies_kwargs, save_remedy
    from compliance.files.atomic import write_text_atomic
    from compliance.files.shipped import resolve_shipped
    from compliance.model.config import load_plant
    from compliance.sweep.sizing.duty_file import load_duty
    from compliance.sweep.sizing.size_servo import size_servo, time_constant_target
    from compliance.sweep.sizing.throttle_tuning import tune_throttles

    _refuse_unused(args)
    check_remedies_options(args)
    duty = load_duty(args.duty)
    template_path = resolve_shipped(duty.template, "plant")
    check_args_outputs(args, (args.out, "--out", (".toml",)), (args.save_remedy, "--save-remedy", (".toml",)),
                       inputs={str(template_path): f"the template of {args.duty}", args.duty: "--duty"})
    template = load_plant(duty.template)
    reqset = checked_requirements(args.requirements, [duty.stroke], args)  # before any simulation
    cfg, rec = size_servo(duty, template, time_constant_target(reqset))
    cfg, tune = tune_throttles(cfg, reqset, {"opening": duty.opening_time, "closing": duty.closing_time})
    cfg, text = _sized_configuration(cfg, args.out)
    if not args.quiet:
        sys.stdout.write(_sizing_text(rec, tune))
    if args.no_check:
        if args.out:
            write_text_atomic(args.out, text)
        return 0
    from compliance.campaign.results_files import summary_table
    from compliance.pipeline.chain import Check

    prepared = Check.of(cfg, reqset, uncertainty=None, remedies="default" if args.remedies else None,
                        allow_conflicts=args.allow_conflicts)
    results = prepared.run(jobs=args.jobs, progress=not args.quiet,
                           remedy_options=remedies_kwargs(args) if args.remedies else None)
    results = results.with_(sizing={"duty": duty.path, "record": rec, "throttles": tune})
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
