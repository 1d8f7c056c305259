"""``govcheck simulate``: one nonlinear simulation of a plant, written to CSV/Parquet (+ optional plot)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from compliance.errors import InputError
from compliance.simulation.profiles import Profile, parse_sine, steps
from compliance.simulation import Scenario, SensorNoise, simulate
from compliance.cli.common import add_plant_argument, plant_from_args, quantity


def register(sub):
    p = sub.add_parser(
        "simulate",
        help="simulate a plant with a reference profile and write the traces",
        description=(
            "Simulate a plant configuration in closed loop (PID with dead-zone compensation) and write "
            "the canonical recording columns (time, position, reference, valve_command, pressure_a, "
            "pressure_b, supply_pressure) plus internal states. Quantities accept units: '136 mm', '11.4 kN'."
        ),
        epilog=(
            "examples:\n"
            "  govcheck simulate models/plant-a.toml --x0 '136 mm' --load '11.4 kN' --steps '2%@1s,-2%@4s' --duration 7 -o run.csv\n"
            "  govcheck simulate --plant plant-a --x0 80mm --sine 8mm,0.05Hz --duration 40 -o sine.parquet --plot sine.png"
        ),
        formatter_class=__import__("argparse").RawDescriptionHelpFormatter,
    )
    add_plant_argument(p)
    p.add_argument("--x0", default=None, help="initial position (default: mid-stroke), e.g. '136 mm'")
    p.add_argument("--load", default="0 N", help="constant closing load (> 0 closes), e.g. '11.4 kN', or 'curve' for the configured load curve")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--steps", help="step sequence of increments, e.g. '2%%@1s,-2%%@4s' or '5mm@1s'")
    g.add_argument("--sine", help="sinusoid AMPLITUDE,FREQUENCY[,START] about x0, e.g. '8mm,0.05Hz'")
    g.add_argument("--command", dest="open_loop_command", help="open-loop valve command steps 'VOLTS@TIME,...' (plant only, no controller), e.g. '3V@0.5s,0V@2s'")
    p.add_argument("--duration", default="10 s", help="simulated time (default 10 s)")
    p.add_argument("--flow-control", choices=("on", "off"), help="install/remove the 2V2/2V3 flow-control valves (default: as configured)")
    p.add_argument("--noise", action="store_true", help="add seeded sensor noise (20 um position, 300 Pa pressures, 16-bit)")
    p.add_argument("--seed", type=int, default=0, help="noise seed (default 0)")
    p.add_argument("-o", "--output", required=True, help="output file: .csv or .parquet")
    p.add_argument("--plot", help="also write a PNG plot of position, command and pressures")
    return p


def _command_profile(spec: str) -> Profile:
    times = [0.0]
    values = [0.0]
    for item in [s for s in spec.split(",") if s.strip()]:
        if "@" not in item:
            raise InputError(f"--command: item '{item}' must look like '3V@0.5s'")
        v, t = item.split("@", 1)
        volts = quantity(v.strip(), "V", "--command")
        tt = quantity(t.strip(), "s", "--command")
        if tt < times[-1]:
            raise InputError("--command: times must not go backwards")
        times += [tt, tt]
        values += [values[-1], volts]
    return Profile(times, values)


def build_scenario(cfg, args) -> Scenario:
    stroke = cfg.p("cylinder.stroke")
    x0 = quantity(args.x0, "m", "--x0", 0.5 * stroke)
    if not 0.0 <= x0 <= stroke:
        raise InputError(f"--x0: {x0*1e3:.1f} mm is outside the stroke 0..{stroke*1e3:.0f} mm")
    duration = quantity(args.duration, "s", "--duration")
    if duration <= 0:
        raise InputError("--duration must be positive")
    load = "curve" if str(args.load).strip() == "curve" else quantity(args.load, "N", "--load")
    ref = cmd = None
    if args.steps:
        ref = steps(args.steps, x0, stroke)
    elif args.sine:
        ref = parse_sine(args.sine, x0, duration)
    elif args.open_loop_command:
        cmd = _command_profile(args.open_loop_command)
    fc = None if args.flow_control is None else args.flow_control == "on"
    noise = SensorNoise(20e-6, 10e-6, 300.0, 1e6 / 65536) if args.noise else None
    return Scenario(duration=duration, initial_position=x0, reference=ref, command=cmd, load=load,
                    flow_control=fc, noise=noise, seed=args.seed)


def write_frame(df, path: str) -> None:
    """Write CSV or Parquet atomically (temp file + rename)."""
    out = Path(path)
    suffix = out.suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise InputError(f"{path}: output must end in .csv or .parquet")
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=f".{out.name}.", suffix=".tmp")
    os.close(fd)
    try:
        if suffix == ".csv":
            df.to_csv(tmp, index=False, float_format="%.9g")
        else:
            df.to_parquet(tmp, index=False)
        os.replace(tmp, out)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def plot_run(df, path: str, title: str) -> None:
    """PNG with position/reference, valve command and chamber pressures."""
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
    out = Path(path)
    tmp = out.with_name(f".{out.name}.tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, out)


def run(args) -> int:
    cfg = plant_from_args(args)
    scenario = build_scenario(cfg, args)
    df = simulate(cfg, scenario)
    write_frame(df, args.output)
    if args.plot:
        plot_run(df, args.plot, f"{cfg.name}: simulated")
    err = (df.reference - df.position_true).abs().iloc[-1]
    print(f"simulated {scenario.duration:g} s of {cfg.name} -> {args.output} ({len(df)} samples); "
          f"final position {df.position_true.iloc[-1]*1e3:.2f} mm, final |error| {err*1e3:.3f} mm")
    return 0
