"""``govcheck linear``: linearised analysis of a plant at an operating point, maps, cross-check, HYGOV."""

from __future__ import annotations

import argparse

from compliance.cli.common import add_outputs, add_parser, add_plant_argument, add_quiet, add_reproducible, check_args_outputs
from compliance.errors import InputError
from compliance.presentation.quantities import fmt_quantity

_PLOT_SUFFIXES = (".png", ".svg", ".pdf")


def register(subparsers):
    """Add the ``linear`` sub-command."""
    p = add_parser(
        subparsers, "linear",
        help="linearise the plant: time constant, margins, bandwidth, maps, HYGOV parameters",
        description=(
            "Trim the nonlinear plant at rest at a position and load, linearise it (numerical Jacobians of the "
            "simulator's own right-hand side), close the loop with the configured PID and report the pneumatic "
            "natural frequency, time constant, bandwidth and gain/phase margins. Options add operating maps over "
            "stroke x load, a cross-check against nonlinear step responses and HYGOV-style governor parameters. "
            "Quantities accept units ('136 mm', '11.4 kN', '85 %' of stroke); bare numbers are SI. "
            "For python-control objects in your own scripts see compliance.linear.nlsys (docs/python-control.md)."
        ),
        examples=[
            "govcheck linear models/plant-a.toml --at '136 mm' --load '11.4 kN'",
            "govcheck linear plant-a --map --crosscheck --governor --json lin.json --plot lin.png",
            "govcheck linear plant-a --at '85 %' --load curve --governor-json hygov.json",
        ],
    )
    add_plant_argument(p)
    p.add_argument("--at", default=None, help="operating position, e.g. '136 mm', 0.136 or '85 %%' (default: mid stroke; "
                   "with --governor the nominal point, where the load curve reaches the nominal force)")
    p.add_argument("--load", default=None, help="closing load, e.g. '11.4 kN', 11400, 'curve' or 'none' (default: none; "
                   "with --governor the load curve)")
    p.add_argument("--gain", choices=("mean", "opening", "closing"), default="mean",
                   help="valve slope of the linear model: mean of both directions (default) or one direction")
    p.add_argument("--flow-control", action=argparse.BooleanOptionalAction, default=None,
                   help="force the meter-out flow-control valves in or out (default: as configured; with --governor in)")
    p.add_argument("--map", action="store_true", help="operating map of time constant and margins over stroke x load")
    p.add_argument("--crosscheck", action="store_true", help="compare with nonlinear 1 %% and 5 %% steps at the paper's operating points")
    p.add_argument("--governor", action="store_true",
                   help="equivalent gate-servo parameters for HYGOV / HYGOV4 (Tg, VELM, UO/UC, GMAX/GMIN), ANDES table, PSS/E record")
    p.add_argument("--rating", metavar="MVA", help="with --governor: the unit's rating Tn, the machine base of the ANDES and "
                   "PSS/E numbers (default: the system base)")
    p.add_argument("--system-base", metavar="MVA", help="with --governor: the study's system base Sb (default 100 MVA)")
    p.add_argument("--dispatch", metavar="MW", help="with --governor: the unit's power at the operating point, as the "
                   "study dispatches it (sets At so the gate starts there; default: rating x operating gate)")
    p.add_argument("--stroke-load", default=None,
                   help="with --governor: load during the governor's large moves: a force, 'curve' or 'none' "
                        "(default: the load curve)")
    add_outputs(p, "json", help={"json": "write everything as JSON to FILE.json"})
    p.add_argument("--governor-json", metavar="FILE.json", help="write only the HYGOV parameters as JSON (implies --governor)")
    p.add_argument("--plot", metavar="FILE.png", help="write the report's figures of the analysis: Bode, closed-loop poles, the "
                   "predicted step and, with --map, the time-constant map (.png, .svg or .pdf)")
    add_quiet(p, "print only the headline figures")
    add_reproducible(p)
    return p


def _point(cfg, args, governor: bool):
    """(position [m], load, flow_control) of the analysis; with --governor the governor's own point and circuit."""
    from compliance.linear.governor_model import nominal_point
    from compliance.units.amounts import parse_load, parse_position

    x_n, load_n = nominal_point(cfg) if governor else (None, None)
    L = cfg.p("cylinder.stroke")
    x = parse_position(args.at, L, f"--at {args.at!r}", require_unit=False) if args.at is not None else (x_n if governor else 0.5 * L)
    load = parse_load(args.load, f"--load {args.load!r}", require_unit=False) if args.load is not None else (load_n if governor else None)
    flow_control = args.flow_control if args.flow_control is not None else (True if governor else None)
    return x, load, flow_control


def _study(args, governor: bool) -> dict:
    """--rating / --system-base / --dispatch [MVA, MVA, MW], checked before any work; each needs --governor."""
    from compliance.units import parse_quantity

    out = {}
    for flag, key, unit in (("--rating", "rating_mva", "MVA"), ("--system-base", "system_mva", "MVA"),
                            ("--dispatch", "dispatch_mw", "MW")):
        text = getattr(args, flag.lstrip("-").replace("-", "_"))
        if text is None:
            continue
        if not governor:
            raise InputError(f"{flag} {text}: a basis of the governor export; it needs --governor (or --governor-json)")
        try:
            float(text)
        except ValueError:
            value = parse_quantity(text, "W", f"{flag} {text!r}") / 1e6  # VA and W share pint's dimension
        else:  # a bare number would be SI (watts): a power system's figures are MVA and MW, so say it
            raise InputError(f"{flag} {text}: give the unit, e.g. '{text} {unit}'")
        if not value > 0 or value != value or value == float("inf"):
            raise InputError(f"{flag} {text}: expected a positive power in {unit} (e.g. '50 {unit}')")
        out[key] = value
    return out


def _q(v, si: str, unit: str = "", decimals: int = 3, suffix: str = "") -> str:
    return fmt_quantity(v, si, unit or si, decimals, suffix=suffix, none="-")


def _load_text(op) -> str:
    if op.load is None:
        return "none"
    force = fmt_quantity(op.load_force, "N", "kN", 2)
    return f"curve ({force})" if isinstance(op.load, str) else force


def _summary(cfg, a, flow_control=None) -> str:
    f, op = a.figures, a.op
    circuit = {True: ", flow-control valves in", False: ", flow-control valves out", None: ""}[flow_control]
    lines = [
        f"plant {cfg.name}: linear model at {_q(op.position, 'm', 'mm', 1)}, load {_load_text(op)}, valve slope "
        f"'{a.info['gain']}'{circuit}",
        f"  trim pressures p_A {_q(op.pressure_a, 'Pa', 'bar', 3, ' abs')}, p_B {_q(op.pressure_b, 'Pa', 'bar', 3, ' abs')} "
        "(p_A + p_B = p_s + p_atm)",
        f"  states {', '.join(a.plant.state_labels)} ({a.info['unobservable_or_uncontrollable_states']} mode(s) not seen from u_d to x)",
        f"  pneumatic natural frequency {_q(f['natural_frequency_hz'], 'Hz', 'Hz', 2)} (analytic "
        f"{_q(f['natural_frequency_analytic_hz'], 'Hz', 'Hz', 2)}), damping {_q(f['pneumatic_damping_ratio'], '', '', 3)}",
        f"  plant velocity gain {_q(f['plant_velocity_gain'], 'm/s', 'mm/s', 2, ' per V')}, loop gain K_P*K_q "
        f"{_q(f['loop_gain'], '1/s', '1/s', 2)}",
        f"  time constant {_q(f['time_constant'], 's', 'ms', 1)} (step metric, sampled loop); dominant pole "
        f"{_q(f['dominant_time_constant'], 's', 'ms', 1)}; first-order estimate (1 + K_q K_D)/(K_q K_P) "
        f"{_q(f['first_order_time_constant'], 's', 'ms', 1)}",
        f"  -3 dB bandwidth {_q(f['bandwidth_hz'], 'Hz', 'Hz', 2)}; least closed-loop damping {_q(f['damping_ratio'], '', '', 3)}; "
        f"stable: {'yes' if f['stable'] else 'NO'}",
        f"  gain margin {_q(f['gain_margin_db'], 'dB', 'dB', 1)} at {_q(f['phase_crossover_hz'], 'Hz', 'Hz', 1)}, "
        f"phase margin {_q(f['phase_margin_deg'], 'deg', 'deg', 1)} at {_q(f['gain_crossover_hz'], 'Hz', 'Hz', 1)} (sampled loop; "
        f"continuous {_q(f.get('gain_margin_db_continuous'), 'dB', 'dB', 1)}, {_q(f.get('phase_margin_deg_continuous'), 'deg', 'deg', 1)})",
        "  closed-loop poles: " + ", ".join(f"{p[0]:.2f}{p[1]:+.2f}j" for p in a.data["poles"]["closed_loop"]),
    ]
    tau = f["time_constant"]
    if tau is not None:
        lines.append(f"  IEC 61362 window 0.10-0.25 s: {'inside' if 0.10 <= tau <= 0.25 else 'OUTSIDE'}")
    return "\n".join(lines)


def run(args) -> int:
    """Run the analysis, print a summary, write JSON / plots."""
    from compliance.cli.common import plant_from_args
    from compliance.files.jsonable import jsonable
    from compliance.linear.analysis import analyse

    governor = bool(args.governor or args.governor_json)
    if args.stroke_load is not None and not governor:
        raise InputError(f"--stroke-load {args.stroke_load}: the load of the governor's large moves; it needs --governor "
                         "(or --governor-json), without which no large move is run")
    study = _study(args, governor)
    sl = None
    if governor:  # parsed before any work: a bad --stroke-load is exit 2 with nothing run
        from compliance.units.amounts import parse_load

        sl = "default" if args.stroke_load is None else parse_load(args.stroke_load, f"--stroke-load {args.stroke_load!r}",
                                                                   require_unit=False)
    check_args_outputs(args, (args.governor_json, "--governor-json", (".json",)), (args.plot, "--plot", _PLOT_SUFFIXES))
    cfg = plant_from_args(args)
    x, load, flow_control = _point(cfg, args, governor)
    a = analyse(cfg, x, load, flow_control=flow_control, gain=args.gain)
    summary = _summary(cfg, a, flow_control)
    print(summary.splitlines()[0] if args.quiet else summary)
    out = {"schema": "govcheck-linear/1", "plant": cfg.name, "path": cfg.path, "digest": cfg.digest, "analysis": a.to_dict()}
    omap = None
    if args.map:
        from compliance.linear.maps import map_table, operating_map

        omap = operating_map(cfg, flow_control=args.flow_control, gain=args.gain)
        print("\ntime constant [ms] over stroke x load (* outside 100-250 ms):")
        print(map_table(omap))
        print("\ngain margin [dB]:")
        print(map_table(omap, "gain_margin_db", 1.0, 1))
        print("\nphase margin [deg]:")
        print(map_table(omap, "phase_margin_deg", 1.0, 0))
        for n in omap.notes:
            print(f"  note: {n}")
        out["map"] = omap.to_dict()
    if args.crosscheck:
        from compliance.linear.maps import crosscheck, crosscheck_table

        rows = crosscheck(cfg, flow_control=args.flow_control)
        print("\ncross-check, linear vs nonlinear time constant (metric: dead time to 63.2 % of the commanded step):")
        print(crosscheck_table(rows))
        out["crosscheck"] = jsonable(rows)
    if governor:
        from compliance.linear.governor_model import governor_parameters

        reuse = a if args.gain == "mean" else None  # Tg_linear is the mean-slope figure of the same point
        gov = governor_parameters(cfg, position=x, load=load, stroke_load=sl, flow_control=flow_control, linear=reuse)
        gov.study = study
        print(f"\nequivalent gate-servo parameters ({gov.basis()['circuit']}; pu on the machine base, gate = stroke):")
        print(gov.table())
        out["governor"] = gov.to_dict()
        if args.governor_json:
            from compliance.files.atomic import write_json_atomic

            write_json_atomic(args.governor_json, gov.to_dict())
    if args.json:
        from compliance.files.atomic import write_json_atomic
        from compliance.files.reproducible import is_reproducible, make_reproducible

        write_json_atomic(args.json, make_reproducible(out) if is_reproducible(args.reproducible) else out)
        print(f"\nwrote {args.json}")
    if args.plot:
        _plot(a, args.plot, omap)
        print(f"wrote {args.plot}")
    return 0


def _plot(a, path, omap=None) -> None:
    """The report's figures of this analysis on one page (Bode, poles, predicted step; with --map the time-constant map)."""
    from compliance.files.atomic import write_bytes_atomic
    from compliance.report.figures_linear import analysis_page
    from compliance.results.linear import LinearAnalysisRecord, OperatingMapRecord

    analysis = LinearAnalysisRecord.from_dict(a.to_dict(), "linear analysis")
    grid = OperatingMapRecord.from_dict(omap.to_dict(), "operating map") if omap is not None else None
    page = analysis_page(analysis, fmt_quantity(a.op.position, "m", "mm", 1), grid, fmt=path.rsplit(".", 1)[-1].lower())
    write_bytes_atomic(path, page)
