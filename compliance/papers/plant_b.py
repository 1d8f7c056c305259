"""Seed 001's two claims, by simulation: numbers and figures for docs/plant-b.md.

    .venv/bin/python -m compliance.papers.plant_b docs/figures/plant-b

(1) Flow laws: on the flow trend of a charging record, Sanville (eq. 5) and Bobrow (eq. 6)
    misfit where the power law (eq. 7) fits (``flow_trend``).
(2) Friction compensation: the state feedback with the observers and the compensation tracks
    with less error and less stick-slip than the same loop without it (and than a PID).
Prints the tables quoted in docs/plant-b.md; every number is recomputed, nothing is typed in.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from compliance.model.config import load_plant
from compliance.characterise.flow_trend import flow_claim, sensitivity
from compliance.metrics.path_tracking import axis_metrics
from compliance.tracking.paths import time_parameterise
from compliance.simulation.state_feedback_loop import AxisReference, simulate_axis
from compliance.procedures.path_tracking import run_procedure

MM = 1e3
MAGNIFY = 50.0  # error magnification of the state-feedback xy plots
_CASES = (("PID", {"pid": True}), ("state feedback", {"without_compensation": True}), ("state feedback + compensation", {}))
_COLORS = {"PID": "#CC79A7", "state feedback": "#E69F00", "state feedback + compensation": "#0072B2"}


def flow_figures(cfg, out: Path) -> list[str]:
    """Figure and table of claim (1)."""
    import matplotlib.pyplot as plt

    ps, pa = cfg.p("air.supply_pressure"), cfg.p("air.atmospheric_pressure")
    c = flow_claim(ps, pa)
    laws = (("sanville", "Sanville, eq. (5)"), ("bobrow", "Bobrow, eq. (6)"), ("power-0.25", "power law, eq. (7), lambda = 0.25"),
            ("iso6358", "ISO 6358, b fitted"))
    fig, axes = plt.subplots(1, 4, figsize=(12, 3.2), sharey=True)
    p = np.linspace(c.pressure.min(), c.pressure.max(), 300)
    for ax, (law, title) in zip(axes, laws):
        ax.plot(c.pressure / ps, c.trend * 1e3, ".", ms=2, color="#999999", label="flow trend (record)")
        ax.plot(c.pressure / ps, c.true_flow * 1e3, color="#222222", lw=0.8, label="detailed valve (truth)")
        ax.plot(p / ps, c.predict(law, p) * 1e3, color="#D55E00", lw=1.4, label="fitted law")
        ax.set_title(f"{title}\nRMS {c.relative_rms[law]*100:.1f} % of peak", fontsize=9)
        ax.set_xlabel("p / p_s")
    axes[0].set_ylabel("mass flow [g/s]")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(out / "flow-laws.png", dpi=110)
    plt.close(fig)
    lines = ["| law | parameters (SI) | RMS / peak flow |", "|---|---|---|"]
    for law, title in laws:
        f = c.fits[law]
        par = ", ".join(f"{k} = {v:.4g}" for k, v in f.params.items())
        lines.append(f"| {title} | {par} | {c.relative_rms[law]*100:.1f} % |")
    truth = np.sqrt(np.mean((c.trend - c.true_flow) ** 2)) / np.max(c.trend)
    lines.append(f"\nflow trend vs the detailed valve's true flow: RMS {truth*100:.2f} % of peak")
    lines += ["", "| b | laminar share | Sanville | Bobrow | power law | ISO 6358 |", "|---|---|---|---|---|---|"]
    for row in sensitivity(ps, pa):
        lines.append(f"| {row['b']:.1f} | {row['laminar_share']*100:.0f} % | {row['sanville']*100:.1f} % | "
                     f"{row['bobrow']*100:.1f} % | {row['power-0.25']*100:.1f} % | {row['iso6358']*100:.1f} % |")
    return lines


def _run_all(cfg, kind, **settings):
    return {name: run_procedure(cfg, kind, **settings, **opts) for name, opts in _CASES}


def tracking_figures(cfg, out: Path) -> list[str]:
    """Figures and tables of claim (2)."""
    lines = ["| path | controller | path RMS [mm] | path max [mm] | axis RMS (worst) [mm] | stick-slip episodes | "
             "stuck / moving (worst axis) |", "|---|---|---|---|---|---|---|"]
    runs = {}
    for kind, label, settings in (("circle_tracking", "circle R 50 mm, 0.2 Hz", dict(radius=0.05, frequency=0.2)),
                                  ("helix_tracking", "helix R 50 mm, pitch 20 mm", dict(radius=0.05, frequency=0.2)),
                                  ("stroke_tracking", "character 江, 50 mm/s", {})):
        runs[kind] = _run_all(cfg, kind, **settings)
        for name, r in runs[kind].items():
            s = r["summary"]
            lines.append(f"| {label} | {name} | {s['path_rms_error']*MM:.3f} | {s['path_max_error']*MM:.3f} | "
                         f"{s['axis_rms_error']*MM:.3f} | {s['stick_slip_episodes']:.0f} | {s['stick_slip_fraction']*100:.1f} % |")
    for kind, fname in (("circle_tracking", "circle.png"), ("stroke_tracking", "character.png")):
        _path_figure(runs[kind], out / fname)
    _reversal_figure(runs["circle_tracking"], out / "reversal.png")
    lines += _slow_ramps(cfg, out / "slow-ramp.png")
    lines += _compensation_forms(cfg)
    return lines


def _path_figure(runs: dict, path: Path) -> None:
    """PID path, magnified state-feedback error about the reference, path deviation over time."""
    import matplotlib.pyplot as plt

    from compliance.report.figures_tracking import draw_path
    from compliance.results.runs import Trace

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), gridspec_kw={"width_ratios": [1, 1, 1.6]})
    for name, r in runs.items():
        tr = [t for t in r["traces"] if t.get("kind") == "path3d"][0]
        if name == "PID":
            draw_path(axes[0], axes[2], Trace.from_dict(tr), label="PID", color=_COLORS[name], errors=False)
            axes[0].set_title("PID (the error is visible at this scale)", fontsize=9)
        else:
            axes[2].plot(tr["time"], np.asarray(tr["path_deviation"]) * MM, color=_COLORS[name], lw=1.0, label=name)
            ref = np.column_stack([tr["reference_x"], tr["reference_y"]])
            pos = np.column_stack([tr["position_x"], tr["position_y"]])
            mag = (ref + MAGNIFY * (pos - ref)) * MM
            axes[1].plot(mag[:, 0], mag[:, 1], color=_COLORS[name], lw=0.9, label=name)
    axes[1].plot(np.asarray(tr["path_x"]) * MM, np.asarray(tr["path_y"]) * MM, color="#555555", lw=0.6, label="reference")
    axes[1].set_aspect("equal", adjustable="datalim")
    axes[1].set_title(f"state feedback, error x{MAGNIFY:g} about the reference", fontsize=9)
    axes[1].set_xlabel("x [mm]")
    axes[1].legend(fontsize=6, loc="lower left")
    axes[2].set_yscale("log")
    axes[2].set_ylim(1e-3, 20)
    axes[2].set_ylabel("path deviation [mm]")
    axes[2].set_title("distance of the tool point from the reference path", fontsize=9)
    axes[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _reversal_figure(circle_runs: dict, path: Path) -> None:
    """One reversal of the circle's x axis, with and without compensation."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2), sharex=True)
    for name in ("state feedback", "state feedback + compensation"):
        tr = [t for t in circle_runs[name]["traces"] if t["label"].endswith("axis x")][0]
        t = np.asarray(tr["time"])
        sl = (t > 2.9) & (t < 3.4)
        err = (np.asarray(tr["reference"]) - np.asarray(tr["position"])) * MM
        axes[0].plot(t[sl], err[sl], color=_COLORS[name], label=name)
        axes[1].plot(t[sl], np.asarray(tr["friction_force"])[sl], color=_COLORS[name], label=f"{name}: true")
        axes[1].plot(t[sl], np.asarray(tr["friction_estimate"])[sl], "--", color=_COLORS[name], label=f"{name}: observed (eq. 11)")
        pos = np.asarray(tr["position"])
        axes[2].plot(t[sl], np.gradient(pos, t)[sl] * MM, color=_COLORS[name], label=name)
    axes[2].plot(t[sl], np.asarray(tr["reference_velocity"])[sl] * MM, color="#555555", lw=0.8, label="reference")
    axes[0].set_ylabel("x error [mm]")
    axes[1].set_ylabel("friction [N]")
    axes[2].set_ylabel("x speed [mm/s]")
    for ax in axes:
        ax.set_xlabel("time [s]")
        ax.legend(fontsize=6)
    fig.suptitle("circle, x axis through its velocity reversal (reference speed crosses zero at t = 3.015 s)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _slow_ramps(cfg, path: Path) -> list[str]:
    """Slow ramps: single axis through the falling branch of eq. (8); table rows and the 5 mm/s figure."""
    import matplotlib.pyplot as plt

    ts = cfg.p("controller.sample_time")
    lines = ["", "| ramp speed | controller | axis RMS [mm] | axis max [mm] | episodes | stuck / moving |",
             "|---|---|---|---|---|---|"]
    fig, axes = plt.subplots(1, 2, figsize=(12, 3.0))
    for vr in (0.005, 0.02):
        traj = time_parameterise(np.array([[0, 0, 0], [3 * vr, 0, 0]]), speed_limit=vr, acceleration_limit=0.5,
                                 sample_time=ts).hold(0.5, 0.5)
        ref = AxisReference(0.1 + traj.position[:, 0], traj.velocity[:, 0], traj.acceleration[:, 0])
        for name, comp in (("state feedback", False), ("state feedback + compensation", True)):
            df = simulate_axis(cfg, ref, compensation=comp)
            m = axis_metrics(df, "x", 0.5, 3.5, moving_speed=0.5 * vr)
            lines.append(f"| {vr*MM:g} mm/s | {name} | {m.axis_rms['x']*MM:.3f} | {m.axis_max['x']*MM:.3f} | "
                         f"{m.stick_slip_count} | {m.stick_fraction('x')*100:.0f} % |")
            if vr == 0.005:
                t = df["time"].to_numpy()
                axes[0].plot(t, (df["reference"] - df["position"]) * MM, color=_COLORS[name], label=name)
                axes[1].plot(t, df["velocity"] * MM, color=_COLORS[name], lw=0.8, label=name)
        if vr == 0.005:
            axes[1].plot(t, df["reference_velocity"] * MM, color="#555555", lw=0.8, label="reference")
    axes[0].set_ylabel("error [mm]")
    axes[1].set_ylabel("speed [mm/s]")
    for ax in axes:
        ax.set_xlabel("time [s]")
        ax.set_xlim(0.4, 2.0)
        ax.legend(fontsize=7)
    fig.suptitle("one axis, ramp at 5 mm/s (inside the falling branch of eq. 8, v < v_d = 10 mm/s)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return lines


def _compensation_forms(cfg) -> list[str]:
    """The static-gain compensation (the other reading of G_f) beside the inverse, for comparison."""
    ts = cfg.p("controller.sample_time")
    t = np.arange(int(6.0 / ts) + 1) * ts
    w = 2 * np.pi * 0.2
    ref = AxisReference(0.15 + 0.05 * np.sin(w * t), 0.05 * w * np.cos(w * t), -0.05 * w * w * np.sin(w * t))
    lines = ["", "| compensation form (50 mm sine, 0.2 Hz, one axis) | axis RMS after 1 s [mm] |", "|---|---|"]
    for form in ("inverse", "static"):
        df = simulate_axis(cfg, ref, compensation=True, compensation_form=form)
        m = axis_metrics(df, "x", 1.0)
        lines.append(f"| {form} | {m.axis_rms['x']*MM:.3f} |")
    return lines


def rate_filter_table(cfg) -> list[str]:
    """Path RMS and valve-command jitter against the low-pass of dF^/dt (controller.RATE_FILTER_FACTOR)."""
    import math

    from compliance.model.state_feedback import C_RATE_ALPHA, controller_vector
    from compliance.metrics.path_tracking import robot_metrics
    from compliance.tracking.paths import circle, stroke_path
    from compliance.tracking.robot import RobotRun, cartesian_robot

    robot = cartesian_robot(cfg)
    ts = cfg.p("controller.sample_time")
    w_f = cfg.p("controller.friction_observer_bandwidth")
    trajs = {"character": stroke_path("jiang", sample_time=ts).hold(0.5, 1.0), "circle": circle(0.05, 0.2, cycles=2, sample_time=ts).hold(0.5, 1.0)}
    noise = {"position_quantum": 10e-6, "pressure_noise": 200.0}
    lines = ["| filter / observer bandwidth | character path RMS [mm] | circle path RMS, noisy sensors [mm] | "
             "x command jitter, noisy [V] |", "|---|---|---|---|"]
    for factor in ("off", 1.0, 3.0, 10.0, None):
        row = []
        for name, tr in trajs.items():
            for nz in ({}, noise) if name == "circle" else ({},):
                frames = {}
                for i, a in enumerate(robot.axes):
                    ref = AxisReference(a.centre + tr.position[:, i], tr.velocity[:, i], tr.acceleration[:, i])
                    d = controller_vector(a.cfg, compensation=factor != "off", x0=float(ref.position[0]), load=a.load)
                    if factor != "off":
                        d.vector[C_RATE_ALPHA] = 1.0 if factor is None else 1.0 - math.exp(-factor * w_f * ts)
                    frames[a.name] = simulate_axis(a.cfg, ref, load=a.load, design=d, **nz)
                m = robot_metrics(RobotRun(tr, frames, robot), 0.5, tr.time[-1] - 1.0)
                if name == "character" or nz:
                    row.append(f"{m.path_rms*MM:.3f}")
                if nz:
                    row.append(f"{np.std(np.diff(frames['x']['valve_command'].to_numpy())):.3f}")
        name = "no filter" if factor is None else ("compensation off" if factor == "off" else f"{factor:g} x")
        lines.append(f"| {name} | " + " | ".join(row) + " |")
    return lines


def main(argv=None) -> int:
    """Write the figures to the folder given (default docs/figures/plant-b) and print the tables."""
    import matplotlib

    matplotlib.use("Agg")
    argv = sys.argv[1:] if argv is None else argv
    out = Path(argv[0] if argv else "docs/figures/plant-b")
    out.mkdir(parents=True, exist_ok=True)
    cfg = load_plant("plant-b")
    for line in flow_figures(cfg, out) + [""] + tracking_figures(cfg, out) + [""] + rate_filter_table(cfg):
        print(line)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
