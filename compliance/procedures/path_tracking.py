"""Runners of plant B's tracking procedures (one axis, the 3-axis robot), in the harness's vocabulary.

The kinds are declared in :mod:`compliance.procedures.kinds` (``TRACKING``) and the metrics in
:mod:`compliance.metrics.catalogue`; the registry runs every tracking kind through
:func:`harness_runner`. :func:`run_procedure` is the plain library entry point underneath.
"""

from __future__ import annotations

import math
import time as _time

import numpy as np

from compliance.model.config import PlantConfig
from compliance.errors import InputError
from compliance.procedures.kinds import KINDS, TRACKING, Kind, parse_setting
from compliance.procedures.outcomes import MAX_TRACE_POINTS, TRACE_COLUMNS, Sample, downsample
from compliance.metrics.path_tracking import axis_metrics, path_deviation, robot_metrics
from compliance.plants import kind_of
from compliance.tracking.paths import AXES, circle, helix, stroke_path
from compliance.tracking.robot import cartesian_robot, run_robot
from compliance.simulation.state_feedback_loop import AxisReference, simulate_axis

_EXTRA_OPTIONS = ("initial_position", "load", "position_noise", "position_quantum", "pressure_noise", "seed")


def _value(v, stroke):
    """SI value of a setting given as an Amount (requirement file) or a plain number."""
    if hasattr(v, "resolve"):
        return float(v.resolve(stroke))
    return v


def _settings(cfg: PlantConfig, kind: Kind, options: dict) -> dict:
    stroke = cfg.p("cylinder.stroke")
    out = {}
    for k, v in options.items():
        if k in _EXTRA_OPTIONS:
            continue
        if k not in kind.settings:
            raise InputError(f"procedure '{kind.name}': unknown setting '{k}' (settings: {', '.join(kind.settings)})")
        if isinstance(v, str) or isinstance(v, list):
            v = parse_setting(kind.settings[k], v, f"procedure '{kind.name}'.{k}")
        out[k] = _value(v, stroke)
    for k, s in kind.settings.items():
        if k not in out:
            if s.default is None:
                raise InputError(f"procedure '{kind.name}': missing setting '{k}' ({s.meaning})")
            out[k] = _value(parse_setting(s, s.default, f"default of {kind.name}.{k}"), stroke)
    for k, s in kind.settings.items():
        v = out[k]
        if s.type == "bool":
            if not isinstance(v, bool):
                raise InputError(f"procedure '{kind.name}'.{k}: expected true or false, got {v!r}")
        elif isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
            raise InputError(f"procedure '{kind.name}'.{k}: expected a non-negative number in SI units, got {v!r}")
    return out


def run_procedure(cfg: PlantConfig, procedure_name: str, **options) -> dict:
    """Run one tracking procedure and measure its metrics.

    Parameters
    ----------
    cfg : PlantConfig
        A plant-B configuration (one axis; the robot is built from it).
    procedure_name : str
        A kind of ``KINDS``: ``axis_tracking``, ``circle_tracking``, ``helix_tracking``,
        ``stroke_tracking``.
    **options
        The kind's settings (SI floats and bools, strings with units such as ``"50 mm"``, or
        requirement-file Amounts), plus ``initial_position`` [m] (the axis start for
        ``axis_tracking``, the workspace centre on every axis for the robot; default
        mid-stroke), ``load`` [N] (``axis_tracking`` only), ``position_noise``,
        ``position_quantum`` [m], ``pressure_noise`` [Pa] and ``seed``.

    Returns
    -------
    dict
        ``metrics``: metric -> list of {value (SI), label, detail}; ``summary``: metric -> worst
        value; ``traces``: downsampled plot traces (one canonical trace per axis, plus a
        ``path3d`` trace with reference, measured and dense reference path, per-axis errors
        and path deviation); ``notes``; ``controller``: the design of each axis; ``window``.

    Raises
    ------
    InputError
        Unknown procedure or setting, path outside the stroke, bad controller settings.
    """
    t0 = _time.perf_counter()
    if procedure_name not in TRACKING:
        raise InputError(f"tracking procedure '{procedure_name}' is not known (known: {', '.join(TRACKING)})")
    kind = KINDS[procedure_name]
    s = _settings(cfg, kind, options)
    stroke = cfg.p("cylinder.stroke")
    x0 = options.get("initial_position")
    x0 = 0.5 * stroke if x0 is None else float(_value(x0, stroke))
    noise = {k: float(options.get(k, 0.0) or 0.0) for k in ("position_noise", "position_quantum", "pressure_noise")}
    seed = int(options.get("seed", 0) or 0)
    mode, comp, ctrl_text = kind_of(cfg).axis_controller(cfg, s)  # the plant kind's controller on the tracking loop
    if procedure_name == "axis_tracking":
        res = _run_axis(cfg, s, x0, options.get("load"), mode, comp, noise, seed)
    else:
        if options.get("load") not in (None, 0.0):
            raise InputError(f"procedure '{procedure_name}': the robot carries no external load (gravity on z is built in)")
        res = _run_robot(cfg, procedure_name, s, x0, mode, comp, noise, seed)
    res["notes"].insert(0, f"controller: {ctrl_text}")
    res["procedure"] = procedure_name
    res["wall_time"] = _time.perf_counter() - t0
    return res


def _axis_trace(df, label):
    return downsample(df, label, columns=TRACE_COLUMNS + ("reference_velocity", "friction_force", "friction_estimate"))


def _pack(m, labels_extra=""):
    metrics = {
        "axis_rms_error": [{"value": v, "label": f"axis {a}{labels_extra}", "detail": {}} for a, v in m.axis_rms.items()],
        "axis_max_error": [{"value": v, "label": f"axis {a}{labels_extra}", "detail": {}} for a, v in m.axis_max.items()],
        "stick_slip_episodes": [{
            "value": float(m.stick_slip_count), "label": f"all axes{labels_extra}",
            "detail": {"per_axis": {a: sum(1 for e in m.episodes if e.axis == a) for a in m.axis_rms},
                       "episodes": [[e.axis, e.t_start, e.t_end] for e in m.episodes]},
        }],
    }
    fr = [{"value": m.stick_fraction(a), "label": f"axis {a}{labels_extra}", "detail": {}}
          for a in m.axis_rms if m.stick_fraction(a) is not None]
    if fr:
        metrics["stick_slip_fraction"] = fr
    if m.path_rms is not None:
        metrics["path_rms_error"] = [{"value": m.path_rms, "label": f"3-D path{labels_extra}", "detail": {}}]
        metrics["path_max_error"] = [{"value": m.path_max, "label": f"3-D path{labels_extra}", "detail": {}}]
    summary = {k: max(x["value"] for x in v) for k, v in metrics.items()}
    return metrics, summary


def _run_axis(cfg, s, x0, load, mode, comp, noise, seed):
    if isinstance(load, str):
        raise InputError("procedure 'axis_tracking': a load curve is not supported; give a constant load [N]")
    amp, f = s["amplitude"], s["frequency"]
    stroke = cfg.p("cylinder.stroke")
    if not (amp > 0 and f > 0):
        raise InputError("procedure 'axis_tracking': amplitude and frequency must be > 0")
    if x0 - amp < 0 or x0 + amp > stroke:
        raise InputError(f"procedure 'axis_tracking': {x0*1e3:.1f} +/- {amp*1e3:.1f} mm leaves the stroke 0..{stroke*1e3:.0f} mm")
    ts = cfg.p("controller.sample_time")
    duration = s["cycles"] / f
    t = np.arange(int(round(duration / ts)) + 1) * ts
    w = 2.0 * math.pi * f
    ref = AxisReference(x0 + amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t))
    df = simulate_axis(cfg, ref, mode=mode, compensation=comp, load=load, seed=seed, **noise)
    t_from = s["skip_cycles"] / f
    m = axis_metrics(df, "x", t_from)
    metrics, summary = _pack(m)
    label = f"axis sine {amp*1e3:g} mm at {f:g} Hz"
    return {"metrics": metrics, "summary": summary, "traces": [_axis_trace(df, label)],
            "notes": [f"errors after {t_from:.2f} s (skip {s['skip_cycles']:g} periods)"],
            "controller": {"x": df.attrs["controller"]}, "window": list(m.window)}


def _trajectory(kind, s, ts):
    if kind == "circle_tracking":
        return circle(s["radius"], s["frequency"], cycles=s["cycles"], sample_time=ts)
    if kind == "helix_tracking":
        return helix(s["radius"], s["frequency"], s["pitch"], cycles=s["cycles"], sample_time=ts)
    return stroke_path("jiang", scale=s["scale"], speed_limit=s["speed"], sample_time=ts)


def _run_robot(cfg, kind, s, centre, mode, comp, noise, seed):
    ts = cfg.p("controller.sample_time")
    traj = _trajectory(kind, s, ts)
    full = traj.hold(s["lead"], s["tail"])
    robot = cartesian_robot(cfg, centre=centre)
    run = run_robot(robot, full, mode=mode, compensation=comp, seed=seed, **noise)
    t_from, t_to = s["lead"], s["lead"] + traj.duration + ts / 2
    m = robot_metrics(run, t_from, t_to)
    metrics, summary = _pack(m)
    traces = [_axis_trace(run.frames[a], f"{traj.name}: axis {a}") for a in AXES]
    traces.append(_path_trace(run, traj.name))
    notes = [f"{traj.name}; motion {traj.duration:.2f} s from {t_from:.2f} s, metrics over the motion",
             "robot masses " + ", ".join(f"{a} {v['moving_mass']:.1f} kg" for a, v in robot.as_dict().items())
             + f"; gravity {robot.axis('z').load or 0:.1f} N on z"]
    return {"metrics": metrics, "summary": summary, "traces": traces, "notes": notes,
            "controller": {a: run.frames[a].attrs["controller"] for a in AXES}, "robot": robot.as_dict(),
            "window": list(m.window)}


def _path_trace(run, name, max_points=MAX_TRACE_POINTS) -> dict:
    """Downsampled 3-D overlay: reference, measured, dense reference path, per-axis errors, deviation."""
    t = run.time
    ref = run.stacked("reference")
    pos = run.stacked("position")
    dev = path_deviation(pos, run.trajectory.path)
    n = t.size
    idx = np.unique(np.linspace(0, n - 1, min(n, max_points)).round().astype(int))
    path = run.trajectory.path
    pidx = np.unique(np.linspace(0, path.shape[0] - 1, min(path.shape[0], max_points)).round().astype(int))
    out = {"label": f"{name}: 3-D path", "kind": "path3d", "points": int(idx.size), "samples": int(n),
           "time": [float(v) for v in t[idx]], "path_deviation": [float(v) for v in dev[idx]]}
    for i, a in enumerate(AXES):
        out[f"reference_{a}"] = [float(v) for v in ref[idx, i]]
        out[f"position_{a}"] = [float(v) for v in pos[idx, i]]
        out[f"error_{a}"] = [float(v) for v in (ref[idx, i] - pos[idx, i])]
        out[f"path_{a}"] = [float(v) for v in path[pidx, i]]
    return out


# ---------------------------------------------------------------------------------------------- harness
def harness_runner(cfg, proc, op, requests, out) -> None:
    """Runner with the signature of ``procedures._RUNNERS`` (``procedures.run`` calls it).

    Parameters
    ----------
    cfg : PlantConfig
    proc : requirements.Procedure
        Its ``kind`` is one of ``KINDS`` and its settings are validated Amounts / values.
    op : requirements.OperatingPoint
        ``initial_position``: the axis start / the robot's workspace centre; ``load``: a
        constant load for ``axis_tracking``.
    requests : list
        (metric, options) requested by the requirements (every metric is measured anyway).
    out : procedures.RunOutcome
        Filled with one Sample per metric value, the traces and notes.
    """
    opts = dict(proc.settings)
    if op.initial_position is not None:
        opts["initial_position"] = op.initial_position.resolve(cfg.p("cylinder.stroke"))
    if op.load is not None:
        if proc.kind != "axis_tracking":
            raise InputError(f"procedure '{proc.name}' at '{op.name}': the robot takes no external load (operating point load = {op.load_text})")
        opts["load"] = op.load
    res = run_procedure(cfg, proc.kind, **opts)
    for metric, samples in res["metrics"].items():
        for smp in samples:
            out.add(metric, Sample(smp["value"], smp["label"], detail=smp["detail"]))
    label = f"{proc.name}@{op.name}"
    for tr in res["traces"]:
        tr = dict(tr)
        tr["label"] = f"{label} {tr['label']}"
        out.traces.append(tr)
    out.marks.append({"trace": label, "type": "tracking_window", "value": res["window"]})
    out.notes.extend(res["notes"])


RUNNERS = {k: harness_runner for k in TRACKING}
