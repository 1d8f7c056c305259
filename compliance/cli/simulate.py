"""``govcheck simulate``: one nonlinear simulation of a plant, written to CSV/Parquet/COMTRADE with its sidecar."""

from __future__ import annotations

import io
import json
import os
from pathlib import Path

from compliance.cli.common import (add_parser, add_plant_argument, plant_from_args, plant_source,
                                   quantity)
from compliance.errors import InputError
from compliance.files.atomic import file_bytes
from compliance.model.force_limit import check_load_force
from compliance.simulation.profiles import Profile, parse_sine, steps

MAX_DURATION = 3600.0  # [s] one simulation; longer is a typo (1e9 s would need TiB of memory)
MAX_SAMPLES = 4_000_000  # output rows (~0.5 GB of columns)
PLOT_SUFFIXES = (".png", ".svg", ".pdf")
OUTPUT_SUFFIXES = (".csv", ".csv.gz", ".parquet", ".cfg", ".cff")
SIDECAR_MARK = "# govcheck simulate sidecar"


def register(sub):
    """Add the ``simulate`` sub-command."""
    p = add_parser(
        sub, "simulate",
        help="simulate a plant with a reference profile and write the traces (+ sidecar)",
        description=(
            "Simulate a plant configuration in closed loop (PID with dead-zone compensation) and write "
            "the canonical recording columns (time, position, reference, valve_command, pressure_a, "
            "pressure_b, supply_pressure) plus internal states, and the NAME.toml sidecar with the plant and "
            "the test conditions, so 'govcheck validate' and 'govcheck diagnose' replay the file as it is. "
            "Quantities accept units: '136 mm', '11.4 kN'. Nothing is written when an input is refused."
        ),
        examples=[
            "govcheck simulate models/plant-a.toml --x0 '136 mm' --load '11.4 kN' --steps '2%@1s,-2%@4s' --duration 7 -o run.csv",
            "govcheck simulate plant-a --x0 80mm --sine 8mm,0.05Hz --duration 40 -o sine.parquet --plot sine.png",
            "govcheck simulate plant-a --command '3V@0.5s,0V@2s' --duration 3 -o open.csv",
            "govcheck simulate plant-a --x0 136mm --steps '-5%@1s' --duration 3 -o run.cfg",
        ],
    )
    add_plant_argument(p)
    p.add_argument("--x0", default=None, help="initial position (default: mid-stroke), e.g. '136 mm'")
    p.add_argument("--load", default="0 N", help="constant closing load (> 0 closes), e.g. '11.4 kN', or 'curve' for the configured load curve")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--steps", help="step sequence of increments, e.g. '2%%@1s,-2%%@4s' or '5mm@1s'")
    g.add_argument("--sine", help="sinusoid AMPLITUDE,FREQUENCY[,START] about x0, e.g. '8mm,0.05Hz'")
    g.add_argument("--command", dest="open_loop_command", help="open-loop valve command steps 'VOLTS@TIME,...' (plant only, no controller), e.g. '3V@0.5s,0V@2s'")
    p.add_argument("--duration", default="10 s", help=f"simulated time (default 10 s, at most {MAX_DURATION:g} s)")
    p.add_argument("--flow-control", choices=("on", "off"), help="install/remove the 2V2/2V3 flow-control valves (default: as configured)")
    p.add_argument("--noise", action="store_true", help="add seeded sensor noise (20 um position, 300 Pa pressures, 16-bit)")
    p.add_argument("--seed", type=int, default=None, help="with --noise: noise seed, a whole number >= 0 (default 0)")
    p.add_argument("-o", "--output", required=True, metavar="FILE.csv",
                   help="output file: .csv, .csv.gz, .parquet, or COMTRADE (IEEE C37.111-2013, BINARY32): .cfg (with "
                        "FILE.dat beside it) or the single file .cff; the sidecar FILE.toml goes beside it")
    p.add_argument("--plot", metavar="FILE.png", help="also write a plot of position, command and pressures (.png, .svg or .pdf)")
    return p


def _command_profile(spec: str, limit: float) -> Profile:
    times, values = [0.0], [0.0]
    for item in [s for s in spec.split(",") if s.strip()]:
        if "@" not in item:
            raise InputError(f"--command: item '{item}' must look like '3V@0.5s'")
        v, t = item.split("@", 1)
        volts = quantity(v.strip(), "V", "--command")
        tt = quantity(t.strip(), "s", "--command")
        if not abs(volts) <= limit:
            raise InputError(f"--command: '{item.strip()}' asks for {volts:g} V; the valve's command limit "
                             f"(valve.command_limit) is +/-{limit:g} V")
        if tt < times[-1]:
            raise InputError("--command: times must not go backwards")
        times += [tt, tt]
        values += [values[-1], volts]
    return Profile(times, values)


def _duration(cfg, text: str) -> float:
    duration = quantity(text, "s", "--duration")
    if not duration > 0:
        raise InputError(f"--duration {text!r}: must be a positive time")
    ts = cfg.p("controller.sample_time")
    if duration < 2 * ts:
        raise InputError(f"--duration {text!r}: shorter than two controller samples ({2 * ts * 1e3:g} ms); nothing would be simulated")
    if duration > MAX_DURATION:
        raise InputError(f"--duration {text!r}: longer than the {MAX_DURATION:g} s one simulation may cover; split the test")
    samples = duration / cfg.p("controller.sample_time")
    if samples > MAX_SAMPLES:
        raise InputError(f"--duration {text!r}: {samples:.3g} samples at the controller sample time "
                         f"{cfg.p('controller.sample_time')*1e3:g} ms; at most {MAX_SAMPLES:g}")
    return duration


def _check_within(profile: Profile | None, duration: float, option: str) -> None:
    if profile is None:
        return
    last = float(max(profile.times))
    if last > duration * (1 + 1e-12) + 1e-9:
        raise InputError(f"{option}: an event at t = {last:g} s is later than --duration {duration:g} s; "
                         "lengthen --duration or drop the event")


def _check_sine(cfg, x0: float, spec: str) -> None:
    """A sine set-point inside the stroke and resolved by the controller's clock (below Nyquist)."""
    from compliance.simulation.profiles import _SINE_RE
    from compliance.units import parse_quantity

    m = _SINE_RE.match(spec)
    if not m:
        return  # parse_sine names the syntax
    stroke, ts = cfg.p("cylinder.stroke"), cfg.p("controller.sample_time")
    amp = abs(parse_quantity(m.group(1), "m", "--sine"))
    if x0 - amp < -1e-12 or x0 + amp > stroke + 1e-12:
        raise InputError(f"--sine {spec}: the set-point swings {(x0-amp)*1e3:.1f}..{(x0+amp)*1e3:.1f} mm about "
                         f"--x0 {x0*1e3:.1f} mm, outside the stroke 0..{stroke*1e3:.0f} mm; lower the amplitude or move --x0")
    freq = parse_quantity(m.group(2), "Hz", "--sine")
    nyquist = 0.5 / ts
    if freq >= nyquist:
        raise InputError(f"--sine {spec}: {freq:g} Hz is at or above the Nyquist frequency {nyquist:g} Hz of the "
                         f"{ts*1e3:g} ms controller clock: the controller would see an alias, not the sine")


def build_scenario(cfg, args):
    """The :class:`~compliance.simulation.Scenario` the arguments describe (every guard before any work)."""
    from compliance.simulation import Scenario, SensorNoise
    from compliance.units.amounts import parse_load, parse_position

    stroke = cfg.p("cylinder.stroke")
    x0 = 0.5 * stroke if args.x0 is None else parse_position(args.x0, stroke, f"--x0 {args.x0!r}", require_unit=False)
    if not 0.0 <= x0 <= stroke:
        raise InputError(f"--x0: {x0*1e3:.1f} mm is outside the stroke 0..{stroke*1e3:.0f} mm")
    duration = _duration(cfg, args.duration)
    load = parse_load(args.load, f"--load {args.load!r}", require_unit=False)
    check_load_force(cfg, load, "--load")
    ref = cmd = None
    if args.steps:
        ref = steps(args.steps, x0, stroke)
        _check_within(ref, duration, "--steps")
    elif args.sine:
        _check_sine(cfg, x0, args.sine)  # before the profile is built: a 1 MHz sine would never finish sampling
        ref = parse_sine(args.sine, x0, duration)
        _check_within(ref, duration, "--sine (its START)")  # a sine starting after the end would be dropped
    elif args.open_loop_command:
        cmd = _command_profile(args.open_loop_command, cfg.p("valve.command_limit"))
        _check_within(cmd, duration, "--command")
    if args.seed is not None and not args.noise:
        raise InputError(f"--seed {args.seed}: seeds the sensor noise, and no --noise is asked for; add --noise or drop --seed")
    seed = 0 if args.seed is None else args.seed
    if seed < 0:
        raise InputError(f"--seed {seed}: expected a whole number >= 0")
    fc = None if args.flow_control is None else args.flow_control == "on"
    noise = SensorNoise(20e-6, 10e-6, 300.0, 1e6 / 65536) if args.noise else None
    return Scenario(duration=duration, initial_position=x0, reference=ref, command=cmd, load=load,
                    flow_control=fc, noise=noise, seed=seed)


def _check_output(path: str) -> None:
    from compliance.files.outputs import check_output

    check_output(path, "-o/--output", OUTPUT_SUFFIXES)
    if path.lower().endswith(".cfg"):
        dat = Path(path).with_suffix(".dat")
        check_output(dat, "-o/--output (its COMTRADE .dat)")
        if dat.exists() and not _written_by_simulate(path):
            raise InputError(f"-o {path}: its COMTRADE data file {dat} exists and was not written by govcheck simulate "
                             "(no govcheck sidecar beside it); choose another output name (nothing is overwritten)")


def _written_by_simulate(output: str) -> bool:
    """The files of ``output`` are an earlier govcheck simulate run: its sidecar carries the mark."""
    from compliance.recordings.metadata import sidecar_path

    side = sidecar_path(output)
    if not side.is_file():
        return False
    return side.read_text(encoding="utf-8", errors="replace").split("\n", 1)[0].strip() == SIDECAR_MARK


def sidecar_text(cfg, scenario, plant: str) -> str:
    """The NAME.toml sidecar (docs/recording-format.md) of a simulated run: plant, conditions, controller."""
    load = scenario.load
    load_line = 'load_force = "curve"' if load == "curve" else f"load_force = {float(load or 0.0)!r}"
    mode = "open loop (valve command given)" if scenario.command is not None else "closed loop (PID)"
    return "\n".join([
        SIDECAR_MARK,
        f"plant = {json.dumps(plant)}",
        f'description = "govcheck simulate: {mode}, {scenario.duration:g} s"',
        "",
        "[conditions]",
        load_line,
        f"initial_position = {float(scenario.initial_position)!r}",
        f"supply_pressure = {float(cfg.p('air.supply_pressure'))!r}",
        "",
        "[controller]",
        f"kp = {float(cfg.p('controller.kp'))!r}",
        f"ki = {float(cfg.p('controller.ki'))!r}",
        f"kd = {float(cfg.p('controller.kd'))!r}",
        f"sample_time = {float(cfg.p('controller.sample_time'))!r}",
        "",
    ])


def _sidecar_target(output: str) -> Path:
    from compliance.files.outputs import check_output
    from compliance.recordings.metadata import sidecar_path

    side = sidecar_path(output)
    check_output(side, "sidecar")
    if side.exists():
        head = side.read_text(encoding="utf-8", errors="replace").split("\n", 1)[0]
        if head.strip() != SIDECAR_MARK:
            raise InputError(f"-o {output}: its sidecar {side} exists and was not written by govcheck simulate; "
                             "choose another output name (nothing is overwritten)")
    return side


def _plant_reference(source: str, side: Path) -> str:
    """How the sidecar names the plant: a reference name as is, a file relative to the sidecar's folder."""
    from compliance.files.shipped import looks_like_path, shipped_names

    if not looks_like_path(source, "plant") and source in shipped_names("plant"):
        return source
    return os.path.relpath(Path(source).resolve(), side.resolve().parent)


def _trigger_time(df) -> float:
    """First change of the set-point (or, open loop, of the valve command) [s]; 0 when nothing changes."""
    col = df["reference"] if df["reference"].nunique() > 1 else df["valve_command"]
    moved = (col != col.iloc[0]).to_numpy()
    return float(df["time"].iloc[int(moved.argmax())]) if moved.any() else 0.0


def output_files(df, path: str, station: str, description: str) -> list[tuple[Path, bytes]]:
    """(file, bytes) of a run, made in memory: one CSV / Parquet / .cff file, or a COMTRADE .dat then its .cfg."""
    name = path.lower()
    if name.endswith((".cfg", ".cff")):
        from compliance.recordings.comtrade_write import comtrade_bytes

        files = comtrade_bytes(df, station=station, single_file=name.endswith(".cff"), trigger_time=_trigger_time(df),
                               header=description)
        # the .dat first: a reader that finds the new .cfg finds its data
        return [(Path(path).with_suffix(suffix), files[suffix]) for suffix in (".dat", ".cfg", ".cff") if suffix in files]
    return [(Path(path), frame_bytes(df, path))]


def frame_bytes(df, path: str) -> bytes:
    """The CSV (.csv / .csv.gz) or Parquet bytes of a run, made in memory."""
    name = path.lower()
    buf = io.BytesIO()
    if name.endswith(".parquet"):
        df.to_parquet(buf, index=False)
        return buf.getvalue()
    return file_bytes(name, df.to_csv(index=False, float_format="%.9g", lineterminator="\n"))


def plot_bytes(df, path: str, title: str) -> bytes:
    """Plot with position/reference, valve command and chamber pressures, in the format of ``path``'s suffix."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(9, 7), sharex=True)
    t = df.time
    ax[0].plot(t, df.reference * 1e3, "k--", lw=1, label="reference")
    ax[0].plot(t, df.position * 1e3, lw=1.2, label="position")
    ax[0].set_ylabel("position [mm]")
    ax[0].legend(loc="best")
    ax[1].plot(t, df.valve_command, lw=1)
    ax[1].set_ylabel("valve command [V]")
    ax[2].plot(t, df.pressure_a / 1e5, lw=1, label="p_A")
    ax[2].plot(t, df.pressure_b / 1e5, lw=1, label="p_B")
    ax[2].set_ylabel("pressure [bar abs]")
    ax[2].set_xlabel("time [s]")
    ax[2].legend(loc="best")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    buf = io.BytesIO()
    fmt = Path(path).suffix.lower().lstrip(".")
    meta = {"Date": None} if fmt == "svg" else ({"CreationDate": None} if fmt == "pdf" else {})
    fig.savefig(buf, format=fmt, dpi=110, metadata=meta)
    plt.close(fig)
    return buf.getvalue()


def run(args) -> int:
    """Check every input and output, simulate, then write the run, its sidecar and the plot."""
    from compliance.files.atomic import write_bytes_atomic, write_text_atomic
    from compliance.files.outputs import check_outputs
    from compliance.plants import simulate

    _check_output(args.output)
    check_outputs((args.output, "-o/--output"), (args.plot, "--plot", PLOT_SUFFIXES))
    side = _sidecar_target(args.output)
    source = plant_source(args)
    cfg = plant_from_args(args)
    scenario = build_scenario(cfg, args)
    df = simulate(cfg, scenario)
    files = output_files(df, args.output, cfg.name, f"govcheck simulate of {cfg.name}, {scenario.duration:g} s")
    plot = plot_bytes(df, args.plot, f"{cfg.name}: simulated") if args.plot else None
    for target, data in files:
        write_bytes_atomic(target, data)
    write_text_atomic(side, sidecar_text(cfg, scenario, _plant_reference(source, side)))
    if plot is not None:
        write_bytes_atomic(args.plot, plot)
    err = (df.reference - df.position_true).abs().iloc[-1]
    written = " + ".join(str(t) for t, _ in files)
    print(f"simulated {scenario.duration:g} s of {cfg.name} -> {written} + {side} ({len(df)} samples); "
          f"final position {df.position_true.iloc[-1]*1e3:.2f} mm, final |error| {err*1e3:.3f} mm")
    return 0
