"""``govcheck characterise``: valve flow law and friction map from bench recordings.

    govcheck characterise valve RECORDING --volume "1 L" [--supply-pressure "8 bar abs"] ...
    govcheck characterise friction RECORDING... [--area "518.8 mm^2" | --bore "25.7 mm"] ...
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from compliance.cli.common import add_outputs, check_args_outputs, wrap_description
from compliance.errors import InputError
from compliance.units import parse_quantity


def register(subparsers):
    """Add the ``characterise`` command and its ``valve`` / ``friction`` targets."""
    p = subparsers.add_parser(
        "characterise",
        help="fit the valve flow law or the seal friction map to bench recordings",
        description=wrap_description("Characterise the bench: valve flow law from charging/discharging a known volume "
        "(ISO 6358, Sanville, Bobrow, power laws ranked by AIC), or the friction-velocity map from "
        "constant-speed runs (Coulomb, static, Stribeck velocity, viscous; optional pressure-dependent Coulomb)."),
        epilog="examples:\n"
               "  govcheck characterise valve charge.csv --volume '1 L' --supply-pressure '8 bar abs' --json valve.json\n"
               "  govcheck characterise friction O-ring257_*bar.csv --column-map zillen-friction --bore '25.7 mm' --plot f.png",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="target", metavar="TARGET", required=True)

    v = sub.add_parser(
        "valve", help="flow law from a fixed-volume charging/discharging recording",
        description=wrap_description("Fit the valve's mass-flow law to a recording of the pressure in a known fixed volume being "
                    "charged from the supply (or discharged to atmosphere) through the valve: the mass flow is "
                    "V/(gamma R T) dp/dt (adiabatic filling of a rigid volume, seed 001 eq. 3; isentropic expansion "
                    "when discharging). Laws are ranked by AIC; a law whose fitted conductance or area "
                    "is not positive is physically impossible and never ranked best. --volume is required."),
        epilog="examples:\n"
               "  govcheck characterise valve charge.csv --volume '1 L' --supply-pressure '8 bar abs'\n"
               "  govcheck characterise valve bench.txt --column-map bench.toml --volume '0.5 L' --mode discharge --json v.json --plot v.svg",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    v.add_argument("recording", help="recording with time and the volume's pressure")
    v.add_argument("--volume", required=True, help='the fixed volume incl. pipe, e.g. "1 L"')
    v.add_argument("--column-map", help="column map TOML (or a shipped map name) for a non-canonical file")
    v.add_argument("--supply-pressure", help='if the recording has no supply_pressure column, e.g. "8 bar abs"')
    v.add_argument("--exhaust-pressure", default="1.01325 bar abs", help="for discharging (default 1 atm)")
    v.add_argument("--temperature", default="20 degC", help="supply temperature (default 20 degC)")
    v.add_argument("--pressure-column", default="pressure_a", help="canonical column with the volume's pressure")
    v.add_argument("--mode", choices=("auto", "charge", "discharge"), default="auto")
    v.add_argument("--window", type=int, help="Savitzky-Golay window [samples, odd] (default 4%% of the transient)")
    v.add_argument("--laws", help="comma-separated subset of iso6358,sanville,bobrow,power,power-0.25")
    add_outputs(v, "json")
    v.add_argument("--plot", metavar="FILE.png", help="write a figure here (.png, .svg or .pdf)")

    f = sub.add_parser(
        "friction", help="friction-velocity map from constant-speed runs (one seal, any pressures)",
        description=wrap_description("Fit the friction-velocity map of one seal to constant-speed runs: friction = F - p_gauge A "
                    "(drive force minus pressure force), binned by velocity; Coulomb, static, Stribeck velocity and "
                    "viscous terms per direction, optionally a pressure-dependent Coulomb term across runs."),
        epilog="examples:\n"
               "  govcheck characterise friction O-ring257_*bar.csv --column-map zillen-friction --bore '25.7 mm'\n"
               "  govcheck characterise friction run1.csv run2.csv --area '518.8 mm^2' --symmetric --json f.json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    f.add_argument("recordings", nargs="+", help="recordings with time, position, force, pressure_a")
    f.add_argument("--column-map", help="column map TOML or shipped name, e.g. zillen-friction")
    f.add_argument("--area", help='piston area, e.g. "518.8 mm^2" (else --bore, else the metadata)')
    f.add_argument("--bore", help='piston diameter, e.g. "25.7 mm"')
    f.add_argument("--symmetric", action="store_true", help="one set of parameters for both directions")
    f.add_argument("--min-speed", default="1 mm/s", help="speeds below are not map points (default 1 mm/s)")
    f.add_argument("--window", default="0.2 s", help="velocity derivative window (default 0.2 s)")
    add_outputs(f, "json")
    f.add_argument("--plot", metavar="FILE.png", help="write a figure here (.png, .svg or .pdf)")
    return p


_PLOT_SUFFIXES = (".png", ".svg", ".pdf")


def run(args) -> int:
    """Run ``govcheck characterise TARGET``; returns the exit code (0)."""
    check_args_outputs(args, (args.plot, "--plot", _PLOT_SUFFIXES))
    if args.target == "valve":
        return _run_valve(args)
    return _run_friction(args)


def _run_valve(args) -> int:
    from compliance.characterise.charging import characterise_valve
    from compliance.characterise.flow_law import LAWS
    from compliance.recordings.reader import read_recording

    volume = parse_quantity(args.volume, "m^3", "--volume")
    temperature = parse_quantity(args.temperature, "K", "--temperature")
    exhaust = parse_quantity(args.exhaust_pressure, "Pa", "--exhaust-pressure", pressure=True)
    laws = tuple(LAWS)
    if args.laws is not None:
        laws = tuple(x.strip() for x in args.laws.split(",") if x.strip())
        if not laws:
            raise InputError(f"--laws {args.laws!r}: no flow law named; give a comma-separated subset of "
                             f"{', '.join(LAWS)} (or leave --laws out for all of them)")
        for law in laws:
            if law not in LAWS:
                raise InputError(f"--laws: '{law}' not known; known: {', '.join(LAWS)}")
    frame, meta = read_recording(args.recording, args.column_map, required=("time", args.pressure_column))
    supply = None
    if args.supply_pressure:
        supply = parse_quantity(args.supply_pressure, "Pa", "--supply-pressure", pressure=True)
    elif isinstance(meta.get("conditions", {}).get("supply_pressure"), float):
        supply = meta["conditions"]["supply_pressure"]
    if args.window is not None and (args.window < 5 or args.window % 2 == 0):
        raise InputError(f"--window: must be an odd number of samples >= 5, got {args.window}")
    if not volume > 0:
        raise InputError(f"--volume {args.volume!r}: expected a positive volume such as '1 L'")
    try:
        result = characterise_valve(
            frame, volume, supply_pressure=supply, exhaust_pressure=exhaust, temperature=temperature,
            pressure_column=args.pressure_column, mode=args.mode, window=args.window, laws=laws, source=args.recording,
        )
    except InputError as exc:
        if args.recording in str(exc):
            raise
        raise InputError(f"{args.recording}: {exc}") from None
    print(_valve_table(result))
    if args.json:
        data = result.to_dict()
        for row, fit in zip(data["ranking"], result.fits):
            row["implausible"] = fit.implausible  # never ranked best (compliance.characterise.flow_law)
        _write_json(args.json, data)
    if args.plot:
        from compliance.characterise.plots import plot_valve

        plot_valve(result, args.plot)
    return 0


def _fmt(value, se=None) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    text = f"{value:.4g}"
    if se is not None and math.isfinite(se):
        text += f" ± {se:.2g}"
    return text


def _valve_table(r) -> str:
    lines = [
        f"valve characterisation: {r.source} ({r.mode}, V = {r.volume * 1e3:.4g} L, T = {r.temperature:.2f} K)",
        f"derivative: {r.derivative}; {r.time.size} samples used (t = {r.time[0]:.3g}-{r.time[-1]:.3g} s); "
        f"pressure noise {r.pressure_noise:.3g} Pa",
        f"{'rank':<5}{'law':<12}{'AIC':>10}{'RMS [g/s]':>12}  parameters (± 1 standard error, SI)",
    ]
    for i, fit in enumerate(r.fits, 1):
        params = ", ".join(f"{k} = {_fmt(v, fit.stderr.get(k))} {fit.units.get(k, '').strip('-')}".rstrip() for k, v in fit.params.items())
        lines.append(f"{i:<5}{fit.law:<12}{fit.aic:>10.1f}{fit.rms * 1e3:>12.4g}  {params}"
                     + (f"  NOT PHYSICAL: {fit.implausible}" if fit.implausible else ""))
    best = r.best
    if best.law == "iso6358":
        c = best.params["conductance"]
        lines.append(f"best: ISO 6358, C = {c * 1e8:.4g} dm^3/(s*bar), b = {best.params['critical_ratio']:.3f}")
    else:
        lines.append(f"best: {best.law} ({best.equation})")
    lines.append("AIC counts one observation per derivative window (smoothed residuals are correlated).")
    return "\n".join(lines)


def _run_friction(args) -> int:
    from compliance.characterise.friction_map import characterise_friction, piston_area, prepare_run
    from compliance.recordings.reader import read_recording

    window = parse_quantity(args.window, "s", "--window")
    v_min = parse_quantity(args.min_speed, "m/s", "--min-speed")
    if window <= 0 or v_min <= 0:
        raise InputError("--window and --min-speed must be > 0")
    runs, area = [], None
    if args.area:
        area = parse_quantity(args.area, "m^2", "--area")
    elif args.bore:
        area = piston_area(parse_quantity(args.bore, "m", "--bore"))
    for path in args.recordings:
        frame, meta = read_recording(path, args.column_map, required=("time", "position", "pressure_a", "force"))
        a = area
        if a is None:
            if isinstance(meta.get("piston_area"), float):
                a = meta["piston_area"]
            elif isinstance(meta.get("bore"), float):
                a = piston_area(meta["bore"])
            else:
                raise InputError(
                    f"{path}: the piston area is not known; give --area or --bore (or piston_area / bore in the "
                    f"sidecar or the column map's [metadata])"
                )
        if not a > 0:
            raise InputError(f"{path}: piston area must be > 0 m^2, got {a}")
        runs.append(prepare_run(Path(path).name, frame, a, window_s=window))
    result = characterise_friction(runs, asymmetric=not args.symmetric, v_min=v_min)
    print(_friction_table(result))
    if args.json:
        _write_json(args.json, result.to_dict())
    if args.plot:
        from compliance.characterise.plots import plot_friction

        plot_friction(result, args.plot)
    return 0


def _friction_table(r) -> str:
    fits = list(r.fits.values())
    names = []
    for fit in fits:
        names += [k for k in fit.params if k not in names]
    hidden = set.intersection(*(set(f.fixed) for f in fits))
    for k in list(hidden):
        if k.startswith("stribeck_drop"):
            hidden |= {k.replace("stribeck_drop", "stribeck_velocity"), k.replace("stribeck_drop", "static")}
    names = [k for k in names if k not in hidden]
    width = 26
    lines = [
        f"friction map: {len(r.runs)} run(s), piston area {r.area:.5g} m^2; friction = F - p_gauge*A (Zillen eq. 3)",
        f"{'parameter':<24}{'unit':<8}" + "".join(f"{f.model:>{width}}" for f in fits),
    ]
    for k in names:
        unit = next((f.units.get(k) for f in fits if f.units.get(k)), "")
        cells = [_fmt(f.params.get(k), f.stderr.get(k)) if k in f.params else "" for f in fits]
        lines.append(f"{k:<24}{unit:<8}" + "".join(f"{c:>{width}}" for c in cells))
    lines.append(f"{'rms residual (bins)':<24}{'N':<8}" + "".join(f"{f.rms_bins:>{width}.4g}" for f in fits))
    lines.append(f"{'rms residual (samples)':<24}{'N':<8}" + "".join(f"{f.rms_samples:>{width}.4g}" for f in fits))
    lines.append(f"{'bins / samples':<24}{'':<8}" + "".join(f"{f'{f.n_bins} / {f.n_samples}':>{width}}" for f in fits))
    fixed = {k: v for f in fits for k, v in f.fixed.items()}
    for k, why in fixed.items():
        lines.append(f"not fitted: {k} = 0 ({why})")
    lines.append("per run (pressure-independent map of each run alone):")
    first = r.per_run[0][2]
    cols = ["coulomb_pos", "coulomb_neg"] if first.asymmetric else ["coulomb"]
    lines.append(f"  {'run':<28}{'p [bar g]':>10}" + "".join(f"{c + ' [N]':>20}" for c in cols) + f"{'rms [N]':>10}")
    for name, p, fit in r.per_run:
        cells = "".join(f"{_fmt(fit.params[c], fit.stderr.get(c)):>20}" for c in cols)
        lines.append(f"  {name:<28}{p / 1e5:>10.3f}{cells}{fit.rms_samples:>10.3g}")
    return "\n".join(lines)


def _write_json(path: str, data: dict) -> None:
    from compliance.files.atomic import write_json_atomic

    write_json_atomic(path, data)
