"""``govcheck validate``: replay a recording with a plant model, print fits and located misfit windows."""

from __future__ import annotations


from compliance.cli.common import (add_recording_inputs, add_parser, add_outputs, add_quiet, add_reproducible, check_args_outputs, check_sidecar_conditions,
                                   parse_param_overrides, sidecar_plant, split_config)
from compliance.errors import InputError
from compliance.files.atomic import write_json_atomic

# the replay modes of compliance.validation.replay.MODES; the library is imported in run() only, so that
# building the dispatcher's parser for other commands does not pay for scipy.signal
MODES = ("closed_loop", "plant_only")

_SHORT = {"position": "position", "valve_command": "command", "pressure_a": "p_A", "pressure_b": "p_B", "supply_pressure": "p_s"}
_SCALE = {"position": (1e3, "mm"), "valve_command": (1.0, "V"), "pressure_a": (1e-3, "kPa"), "pressure_b": (1e-3, "kPa"), "supply_pressure": (1e-3, "kPa")}


def register(sub):
    p = add_parser(
        sub, "validate",
        help="replay a recording with a plant model: fit per signal, located misfit windows, windowed error limits",
        description=(
            "Simulate a recorded test with the model - closed loop (the model's controller follows the recorded "
            "reference) and/or plant only (the recorded valve command drives the plant) - and compare: fit per "
            "signal, the time windows where the residual stands above the recording's own noise floor (with the "
            "operating regimes they fall in), and IEC 61400-27-2-style windowed errors (max, mean, mean absolute, "
            "per unit) against limits. Exit 0 when every window is within its limits, 1 when one is not, 2 on bad input."
        ),
        examples=[
            "govcheck validate models/plant-a.toml run.csv.gz",
            "govcheck validate run.csv.gz      # the plant named by the sidecar run.toml",
            "govcheck validate plant-a log.txt --column-map bench.toml --mode plant_only --json val.json",
            "govcheck validate plant-a run.csv --setting limits.position.steady.max_error=0.005 --report val.html",
            "govcheck validate plant-a run.csv --param friction.bristle_stiffness=1e6",
        ],
        usage="govcheck validate [options] [CONFIG] RECORDING",
    )
    add_recording_inputs(p, "the recording (canonical CSV/CSV.GZ with NAME.toml sidecar, or any format a column map reads)")
    p.add_argument("--mode", default="both", help="closed_loop, plant_only or both (default both)")
    p.add_argument("--noise", default=None, help="closed-loop position-noise replay: auto (default), recorded, none")
    p.add_argument("--settings", help="validation settings TOML (limits, locate parameters, windows); see docs/validation.md")
    p.add_argument("--setting", action="append", default=[], metavar="KEY=VALUE",
                   help="override one setting, e.g. limits.position.steady.max_error=0.02 or locate.k_on=4 (repeatable)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="override one plant parameter in SI, e.g. friction.bristle_stiffness=1e6 (repeatable)")
    add_outputs(p, "json", "report", "pdf", help={"json": "write the results (docs/validation-schema.md) to FILE.json",
                                                  "pdf": "also write the report as PDF to FILE.pdf (with --report)"})
    add_quiet(p, "print only the result line")
    add_reproducible(p)
    p.add_argument("--max-windows", type=int, default=30, help="located windows printed per mode (default 30; all are in --json)")
    return p


def _render(result: dict, html: str, pdf: str | None) -> None:
    from compliance.report.render import render_validation_report

    render_validation_report(result, html, pdf_path=pdf)


def _fmt(v, spec: str = ".2f", none: str = "-") -> str:
    return none if v is None else format(v, spec)


def format_summary(result: dict, max_windows: int = 30) -> str:
    """Plain-text tables of a validation result: conditions, fits, located windows, windowed errors."""
    lines = []
    rec, plant, cond = result["recording"], result["plant"], result["conditions"] or {}
    lines.append(f"recording {rec['path']}: {rec['samples']} samples, {rec['duration']:.3f} s, "
                 f"step {rec['sample_time_median']*1e3:.3g} ms{'' if rec['uniform'] else ' (non-uniform)'}")
    lines.append(f"model {plant['name']} ({plant['path'] or 'in memory'})" + ("; overrides: " + ", ".join(f"{k}={v:g}" for k, v in plant["overrides"].items()) if plant["overrides"] else ""))
    if cond:
        ip = cond.get("initial_pressures")
        lines.append(
            f"conditions: x0 {cond['initial_position']*1e3:.2f} mm, load {cond['load_force'] if cond['load_force'] is not None else 0:g} N, "
            f"supply {cond['supply_pressure']/1e5:.3f} bar abs, "
            + (f"p_A/p_B(0) {ip[0]/1e5:.3f}/{ip[1]/1e5:.3f} bar abs" if ip else "pressures at rest (not recorded)")
            + f"; Kp {cond['controller']['kp']:g}, Ki {cond['controller']['ki']:g}, Kd {cond['controller']['kd']:g}, Ts {cond['controller']['sample_time']*1e3:g} ms"
        )
    floors = result["noise_floors"]
    if floors:
        lines.append("noise floors (from the recording): " + ", ".join(
            f"{_SHORT[s]} {f['value']*_SCALE[s][0]:.3g} {_SCALE[s][1]}" for s, f in floors.items()))
    for w in result["warnings"]:
        lines.append(f"warning: {w}")
    for mode, m in result["modes"].items():
        lines.append("")
        lines.append(f"== {mode.replace('_', '-')} replay" + (" (recorded position noise fed to the model's sensor)" if m["noise_replay"] else ""))
        lines.append(f"  {'signal':10s} {'fit %':>8s} {'NRMSE':>7s} {'RMS err':>10s} {'max |err|':>10s} {'unit':>5s}")
        for s, f in m["fits"].items():
            sc, u = _SCALE[s]
            lines.append(f"  {_SHORT[s]:10s} {_fmt(f['fit_percent']):>8s} {_fmt(f['nrmse'], '.4f'):>7s} "
                         f"{_fmt(None if f['rms_error'] is None else f['rms_error']*sc, '.4g'):>10s} "
                         f"{_fmt(None if f['max_abs_error'] is None else f['max_abs_error']*sc, '.4g'):>10s} {u:>5s}")
        wins = m["located_windows"]
        lines.append(f"  located windows: {len(wins)} (residual above {result['settings']['locate']['k_on']:g} x noise floor)")
        if wins:
            lines.append(f"  {'signal':9s} {'start s':>8s} {'end s':>8s} {'dur s':>6s} {'peak':>10s} {'x floor':>8s}  regimes at onset (first 0.2 s) | over the window")
            for w in wins[:max_windows]:
                sc, u = _SCALE[w["signal"]]
                lines.append(f"  {_SHORT[w['signal']]:9s} {w['start']:8.3f} {w['end']:8.3f} {w['duration']:6.3f} "
                             f"{w['peak_abs']*sc:7.3g} {u:<3s}{w['peak_ratio']:7.1f}  {', '.join(w['onset']) or '-'} | {', '.join(w['dominant']) or '-'}")
            if len(wins) > max_windows:
                lines.append(f"  ... {len(wins) - max_windows} more in the JSON results")
        rows = m["window_metrics"]
        sigs = m["compared_signals"]
        lines.append(f"  windowed errors [pu] (MXE / MAE; * = outside its limit): {'PASS' if m['pass'] else 'FAIL'}")
        head = f"  {'window':32s} {'kind':9s}" + "".join(f" {_SHORT[s]:>15s}" for s in sigs)
        lines.append(head)
        by = {}
        for r in rows:
            by.setdefault((r["window"], r["start"]), {})[r["signal"]] = r
        for (name, _), per in by.items():
            any_row = next(iter(per.values()))
            cells = []
            for s in sigs:
                r = per.get(s)
                if r is None or r["max_error"] is None:
                    cells.append(f" {'-':>15s}")
                    continue
                mark = "*" if not r["pass"] else " "
                cells.append(f" {r['max_error']:7.4f}/{r['mean_absolute_error']:6.4f}{mark}")
            lines.append(f"  {name[:32]:32s} {any_row['kind']:9s}" + "".join(cells))
    lines.append("")
    lines.append("result: " + ("PASS (every window within its limits)" if result["summary"]["pass"] else "FAIL (windows outside their limits: " + ", ".join(f"{k} {v}" for k, v in result["summary"]["failed_rows"].items()) + ")"))
    return "\n".join(lines)


def run(args) -> int:
    """Check every input and output, replay the recording, print and write the result."""
    from compliance.model.config import load_plant
    from compliance.recordings.reader import read_recording
    from compliance.validation.validate import apply_overrides, read_settings_table, settings_from_dict, validate

    plant_arg, recordings = split_config(args, args.inputs)
    if len(recordings) > 1:
        raise InputError(f"{recordings[1]}: one recording at a time (arguments: [CONFIG] RECORDING)")
    recording = recordings[0]
    mode = args.mode.strip().replace("-", "_")
    if mode not in MODES + ("both",):
        raise InputError(f"--mode '{args.mode}' is not one of closed_loop, plant_only, both")
    modes = MODES if mode == "both" else (mode,)
    if args.max_windows < 0:
        raise InputError(f"--max-windows {args.max_windows}: expected a number of windows >= 0")
    if args.noise is not None and modes == ("plant_only",):
        raise InputError(f"--noise {args.noise}: the position noise of the closed-loop replay, and --mode plant_only "
                         "runs none; drop --noise or use --mode both")
    if args.pdf and not args.report:
        raise InputError("--pdf needs --report FILE.html")
    check_args_outputs(args)  # fail before the work, nothing written
    params = parse_param_overrides(args.param)
    table = read_settings_table(args.settings) if args.settings else {}
    settings_where = args.settings or "--setting"
    table = apply_overrides(table, list(args.setting))
    table.setdefault("replay", {})
    table["replay"] = dict(table["replay"], modes=list(modes))
    if args.noise is not None:
        table["replay"]["noise"] = args.noise
    settings = settings_from_dict(table, settings_where)
    required = ("time", "position") + (("reference",) if modes == ("closed_loop",) else ()) + (("valve_command",) if modes == ("plant_only",) else ())
    df, meta = read_recording(recording, args.column_map, required=required)
    plant_src = plant_arg or sidecar_plant(meta, recording)
    if not plant_src:
        raise InputError(f"{recording}: no plant given (CONFIG) and the sidecar names none")
    cfg = load_plant(plant_src)
    if params:
        cfg = cfg.replace(params=params)
    check_sidecar_conditions(cfg, df, meta, recording)
    result = validate(cfg, df, meta, settings)
    summary = format_summary(result, args.max_windows)
    print(summary.rstrip().splitlines()[-1] if args.quiet else summary)
    written = _finish(result, args)
    if args.json:
        write_json_atomic(args.json, written)
        print(f"results: {args.json}")
    if args.report:
        _render(written, args.report, args.pdf)
        print(f"report: {args.report}" + (f", {args.pdf}" if args.pdf else ""))
    return 0 if result["summary"]["pass"] else 1


def _finish(result: dict, args) -> dict:
    from compliance.files.reproducible import is_reproducible, make_reproducible

    return make_reproducible(result) if is_reproducible(args.reproducible) else result
