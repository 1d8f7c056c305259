"""From an operating point to simulated runs: the steps every procedure runner shares.

Where a run starts (the operating point's position inside the stroke), what load it holds,
the full-command voltages, the one call into the simulator, and the samples every
closed-loop run adds (peak speeds, valve saturation). No physics here: the plant is
``compliance.simulation``'s.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

from compliance import metrics as M
from compliance.errors import InputError
from compliance.simulation.scenario import scenario_load, stroke_start_pressures
from compliance.procedures.outcomes import Sample, downsample

__all__ = [
    "DRIVES",
    "LIMITER_KEYS",
    "add_drive_samples",
    "at_operating_point",
    "closed_loop_trace",
    "full_command",
    "full_command_stroke",
    "simulate_run",
    "start_position",
    "stroke",
    "swing",
]


# how a full stroke is driven: "governor" = a full set-point change through the closed loop, the governor's
# set-point rate limiter acting (the stroke the gate makes in service); "manual" = full valve command in open
# loop, the positioner in manual (what the valve and the flow-control valves alone allow: the backstop)
DRIVES = ("governor", "manual")
# the parameters of the governor's set-point rate limiter (docs/physics.md, controller section)
LIMITER_KEYS = ("controller.setpoint_opening_rate", "controller.setpoint_closing_rate", "controller.end_zone_rate",
                "controller.end_zone_width", "controller.setpoint_lead_limit")


def at_operating_point(cfg, op):
    """The configuration as operating point ``op`` runs it.

    A point with ``setpoint_limiter = false`` injects the set-point downstream of the governor's rate
    limiter (the limiter does not act: the time-constant test); every other point runs ``cfg`` as given.
    """
    if op.setpoint_limiter is False and cfg.setpoint_rate_limited:
        return cfg.replace(params={k: 0.0 for k in LIMITER_KEYS}, sources={k: cfg.sources.get(k, "user") for k in LIMITER_KEYS})
    return cfg


def stroke(cfg) -> float:
    """Servomotor stroke of the plant [m]."""
    return cfg.p("cylinder.stroke")


def start_position(cfg, op, procedure) -> float:
    """The operating point's initial position for ``procedure`` [m], inside the stroke.

    Raises
    ------
    InputError
        The operating point has no initial position, or it lies outside the stroke.
    """
    if op.initial_position is None:
        raise InputError(f"operating point '{op.name}' has no initial_position, needed by procedure '{procedure.name}'")
    x0 = op.initial_position.resolve(stroke(cfg))
    if not 0.0 <= x0 <= stroke(cfg):
        raise InputError(f"operating point '{op.name}': initial position {x0*1e3:.1f} mm is outside the stroke")
    return x0


def full_command(cfg, setting) -> tuple[float, float]:
    """(opening, closing) full command voltages about the valve centre [V].

    ``setting`` is ``"full"`` (the valve's command limit) or an Amount in volts.
    """
    centre = cfg.p("valve.centre_voltage")
    mag = cfg.p("valve.command_limit") - abs(centre) if setting == "full" else setting.value
    return centre + mag, centre - mag


def simulate_run(cfg, duration, x0, *, reference=None, command=None, load=None, flow_control=None, pressures=None):
    """Simulate one scenario (``compliance.simulation``, looked up at call time) -> DataFrame.

    ``pressures``: initial chamber pressures (p_A, p_B) [Pa]; None = at rest balancing the load.
    """
    from compliance.simulation import Scenario
    from compliance.plants import simulate

    return simulate(cfg, Scenario(duration, x0, reference=reference, command=command, load=load, flow_control=flow_control,
                                  initial_pressures=pressures))


def full_command_stroke(cfg, op, direction, command, duration, flow_control, start="end_stop", drive="governor"):
    """One full stroke from the end a ``direction`` starts at, driven as ``drive`` says.

    ``drive = "governor"``: the set-point steps to the other end at t = 0 and the closed loop moves the
    gate, through the governor's set-point rate limiter when one is configured (the stroke in service).
    ``drive = "manual"``: full valve command in open loop (the positioner in manual: what the valve and
    the flow-control valves alone allow).

    Parameters
    ----------
    cfg : PlantConfig
    op : requirements.OperatingPoint
        Its load is held.
    direction : {"opening", "closing"}
        Opening starts closed (x = 0), closing starts fully open (x = stroke).
    command : "full" or Amount
        Valve command magnitude about the centre of a manual stroke [V].
    duration : float
        Simulated time [s].
    flow_control : bool or None
        Flow-control valves in the circuit (None = as configured).
    start : {"end_stop", "rest"}
        Initial chamber pressures (:func:`stroke_start_pressures`).
    drive : {"governor", "manual"}

    Returns
    -------
    pandas.DataFrame
    """
    from compliance.simulation.profiles import Profile

    u_open, u_close = full_command(cfg, command)
    x0, u = (0.0, u_open) if direction == "opening" else (stroke(cfg), u_close)
    load = scenario_load(cfg, op)
    key = (_plant_key(cfg), load, direction, u, duration, flow_control, start, drive)
    if key in _STROKES:  # the steps procedures at one operating point ask for the same strokes
        _STROKES.move_to_end(key)
        return _STROKES[key]
    pressures = stroke_start_pressures(cfg, direction, start)
    if drive == "governor":
        df = simulate_run(cfg, duration, x0, reference=Profile.constant(stroke(cfg) - x0), load=load,
                          flow_control=flow_control, pressures=pressures)
    else:
        df = simulate_run(cfg, duration, x0, command=Profile.constant(u), load=load, flow_control=flow_control,
                          pressures=pressures)
    _STROKES[key] = df
    if len(_STROKES) > _STROKES_KEPT:
        _STROKES.popitem(last=False)
    return df


# full-command strokes already simulated in this process (the callers only read them): every steps procedure
# at an operating point checks the same full-command speeds, and a perturbed plant repeats them per step size
_STROKES: OrderedDict = OrderedDict()
_STROKES_KEPT = 24


def _plant_key(cfg) -> tuple:
    """Everything of a configuration a simulation reads, hashable (a configuration is frozen but holds mappings)."""
    curve = None if cfg.load_curve is None else (cfg.load_curve[0].tobytes(), cfg.load_curve[1].tobytes())
    return (tuple(cfg.params.items()), tuple(cfg.options.items()), curve,
            tuple((k, tuple(v.items())) for k, v in cfg.effects.items()))


def swing(cfg, proc, op) -> tuple[float, float]:
    """Centre and amplitude of a set-point swinging about the operating point [m], inside the stroke.

    The amplitude is the procedure's ``amplitude`` setting (possibly per cent of stroke).

    Raises
    ------
    InputError
        The operating point has no position inside the stroke, or ``x0 +/- amplitude``
        leaves it (naming the procedure and the operating point).
    """
    stroke_length = stroke(cfg)
    x0 = start_position(cfg, op, proc)
    amplitude = proc.settings["amplitude"].resolve(stroke_length)
    if x0 - amplitude < 0 or x0 + amplitude > stroke_length:
        raise InputError(
            f"procedure '{proc.name}' at '{op.name}': {x0*1e3:.1f} +/- {amplitude*1e3:.1f} mm leaves the stroke"
        )
    return x0, amplitude


def closed_loop_trace(cfg, proc, op, out, duration, x0, reference):
    """Simulate ``reference`` in closed loop at the operating point, keep its plot trace.

    Parameters
    ----------
    cfg : PlantConfig
    proc, op : requirements.Procedure, requirements.OperatingPoint
    out : RunOutcome
        Receives the downsampled trace, labelled ``procedure@operating_point``.
    duration : float
        Simulated time [s].
    x0 : float
        Initial position [m].
    reference : profiles.Profile
        Position set-point [m].

    Returns
    -------
    tuple
        (label, time [s], position [m], reference [m], valve command [V]) arrays.
    """
    df = simulate_run(cfg, duration, x0, reference=reference, load=scenario_load(cfg, op), flow_control=op.flow_control)
    label = f"{proc.name}@{op.name}"
    out.traces.append(downsample(df, label))
    tt, x, r, u = M.frame_columns(df, "time", "position", "reference", "valve_command")
    return label, tt, x, r, u


def add_drive_samples(cfg, out, tt, x, u, label, t_from=-np.inf, t_to=np.inf):
    """Add the peak speeds [m/s] and the valve-saturation fraction [-] of a window to ``out``."""
    v, vo, vc = M.speed_extremes(tt, x, t_from, t_to)
    for key, val in (("max_speed", v), ("max_opening_speed", vo), ("max_closing_speed", vc)):
        out.add(key, Sample(val, label))
    thr = cfg.p("valve.saturation_voltage")
    centre = cfg.p("valve.centre_voltage")
    out.add("saturation_fraction", Sample(M.saturation_fraction(tt, u - centre, thr, t_from, t_to), label,
                                          detail={"threshold_V": thr}))
