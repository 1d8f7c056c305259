"""Procedure kinds as data: what each kind does and the settings it takes, with units and defaults.

A requirement file's ``[procedures.NAME]`` names a kind and gives its settings; they are
validated here (:func:`parse_setting`). Plant B's tracking kinds (seed 001) are declared
here too; their runners are in :mod:`compliance.procedures.path_tracking`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from compliance.units.amounts import parse_amount
from compliance.errors import InputError

__all__ = ["CHOICES", "KINDS", "STROKE_STARTS", "ROBOT_TRACKING", "TRACKING", "Kind", "Setting", "parse_setting"]


@dataclass(frozen=True)
class Setting:
    """A procedure setting: type (``length``, ``time``, ``frequency``, ``speed``, ``voltage``,
    ``number``, ``count``, ``bool``, ``directions``, ``pattern``, or a word from ``CHOICES``), default text (None = required)."""

    type: str
    default: object
    meaning: str


@dataclass(frozen=True)
class Kind:
    """A procedure kind: what it does and the settings it takes."""

    name: str
    meaning: str
    settings: dict


_SI = {"length": "m", "time": "s", "frequency": "Hz", "speed": "m/s", "voltage": "V"}
_CMD = Setting("voltage", "full", "valve command magnitude about the valve centre; 'full' = valve.command_limit")

# How a full stroke starts: as the hold at the end left the chambers, or at rest with the pressures
# balancing the load about their mean (the idealised start); simulation.scenario.stroke_start_pressures.
STROKE_STARTS = ("end_stop", "rest")
_START = Setting("start", "end_stop", "initial chamber pressures: 'end_stop' = as the hold at the end left them (the side "
                 "about to drive exhausted, the other at supply); 'rest' = at rest balancing the load about their mean")

# settings whose value is a word from a fixed list: type -> allowed words
CHOICES = {
    "start": STROKE_STARTS,
    # "governor": full set-point change through the closed loop, the set-point rate limiter acting (in service);
    # "manual": full valve command in open loop, the positioner in manual (the valve and throttles alone)
    "drive": ("governor", "manual"),
    # how the stroke times are timed (metrics.stroke.timed)
    "timing": ("full_rate", "end_to_end", "extrapolated"),
    # the device that sets each direction's time: "auto" = the set-point rate limiter when one is configured
    # (the throttles are then its backstop), else the flow-control valves
    "device": ("auto", "limiter", "throttle"),
}
_DRIVE = Setting("drive", "governor", "how the stroke is driven: 'governor' = full set-point change through the closed loop "
                 "(the set-point rate limiter acting: the stroke in service); 'manual' = full valve command in open loop "
                 "(the positioner in manual: what the valve and the flow-control valves alone allow)")

KINDS: dict[str, Kind] = {
    k.name: k
    for k in (
        Kind("steps", "set-point step sequence in closed loop from the operating point", {
            "size": Setting("length", None, "step size, e.g. '5 %stroke' or '8 mm'"),
            "pattern": Setting("pattern", ["up", "down"], "directions of the successive steps"),
            "lead": Setting("time", "1 s", "hold before the first step"),
            "dwell": Setting("time", "4 s", "time between steps"),
            "tau_from_rest": Setting("bool", True, "count the time constant only on the first step, which starts from rest "
                                     "at the operating point (the standards' test); later steps start from the previous "
                                     "step's settled state and are reported, not judged"),
        }),
        Kind("sine", "sinusoidal set-point x0 + A sin(2 pi f t) in closed loop (seed 000: 8 mm at 0.05 Hz)", {
            "amplitude": Setting("length", None, "amplitude A"),
            "frequency": Setting("frequency", None, "frequency f"),
            "cycles": Setting("number", 2, "number of periods simulated"),
            "skip_cycles": Setting("number", 0.5, "periods left out of the tracking errors (start transient)"),
        }),
        Kind("full_stroke", "full stroke from one end to the other, driven by the governor (in service) or in manual", {
            "directions": Setting("directions", ["opening", "closing"], "which strokes"),
            "drive": _DRIVE,
            "command": _CMD,
            "flow_control": Setting("bool", True, "flow-control valves 2V2/2V3 in the circuit"),
            "timeout": Setting("time", "30 s", "simulated time per stroke"),
            "start": _START,
        }),
        Kind("independent_adjustment", "change one direction's speed setting; the other direction's time must not change", {
            "adjust": Setting("directions", ["opening", "closing"], "which direction's setting to change, one at a time"),
            "factor": Setting("number", 0.5, "factor applied to the adjusted setting (limiter rate or throttle conductance)"),
            "device": Setting("device", "auto", "the speed setting adjusted: 'limiter' = the set-point rate limiter's rate of "
                              "that direction, 'throttle' = that direction's flow-control valve, 'auto' = the limiter when "
                              "the configuration has one, else the throttle"),
            "timing": Setting("timing", "full_rate", "how the stroke times are timed (as the opening_time option timing)"),
            "drive": _DRIVE,
            "command": _CMD,
            "timeout": Setting("time", "30 s", "simulated time per stroke"),
            "start": _START,
        }),
        Kind("hold", "reach the operating point's position from below, then hold it under its load in closed loop", {
            "duration": Setting("time", "10 s", "simulated time"),
            "settle": Setting("time", "3 s", "start of the measurement window"),
            "approach": Setting("length", "2 %stroke", "start this far below the position (0: start at rest on it); "
                                "larger than the accuracy asked, so the servo must move to hold"),
        }),
        Kind("dead_band", "slow triangular set-point in closed loop; width of the hysteresis loop", {
            "amplitude": Setting("length", "2 %stroke", "triangle amplitude about the operating point"),
            "rate": Setting("speed", "0.5 mm/s", "set-point speed (slow against the servo's time constant)"),
            "lead": Setting("time", "1 s", "hold before the triangle"),
        }),
    )
}


# plant B (seed 001): one axis under state feedback, and the 3-axis robot
_COMMON = {
    "without_compensation": Setting("bool", False, "switch the friction compensation off for this run (comparison)"),
    "pid": Setting("bool", False, "run the PID of the configuration instead of the state feedback (comparison)"),
}
_ROBOT = {
    "lead": Setting("time", "0.5 s", "hold at the start point before the motion"),
    "tail": Setting("time", "1 s", "hold at the end point after the motion (settling)"),
    **_COMMON,
}

TRACKING_KINDS: dict[str, Kind] = {
    k.name: k
    for k in (
        Kind("axis_tracking", "one plant-B axis follows x0 + A sin(2 pi f t) under the seed 001 controller", {
            "amplitude": Setting("length", None, "amplitude A"),
            "frequency": Setting("frequency", None, "frequency f"),
            "cycles": Setting("number", 2, "number of periods simulated"),
            "skip_cycles": Setting("number", 0.5, "periods left out of the errors (start transient)"),
            **_COMMON,
        }),
        Kind("circle_tracking", "3-axis robot draws a circle in the xy plane about the workspace centre (seed 001 fig. 8)", {
            "radius": Setting("length", None, "circle radius"),
            "frequency": Setting("frequency", None, "turns per second"),
            "cycles": Setting("number", 2, "number of turns"),
            **_ROBOT,
        }),
        Kind("helix_tracking", "3-axis robot follows a helix about z: a circle in xy rising one pitch per turn", {
            "radius": Setting("length", None, "helix radius"),
            "frequency": Setting("frequency", None, "turns per second"),
            "pitch": Setting("length", "20 mm", "rise per turn"),
            "cycles": Setting("number", 2, "number of turns"),
            **_ROBOT,
        }),
        Kind("stroke_tracking", "3-axis robot writes the shipped hand-drawn character (seed 001 fig. 8, pen on z)", {
            "scale": Setting("number", 1.0, "scale factor of the drawing about its centre"),
            "speed": Setting("speed", "50 mm/s", "path speed limit"),
            **_ROBOT,
        }),
    )
}
ROBOT_TRACKING = ("circle_tracking", "helix_tracking", "stroke_tracking")
TRACKING = tuple(TRACKING_KINDS)
KINDS.update(TRACKING_KINDS)


def parse_setting(setting: Setting, value, where: str):
    """Validate one setting value (Amounts for quantities, plain values otherwise).

    Parameters
    ----------
    setting : Setting
        The declaration (its ``type`` decides what is accepted).
    value : object
        As written in the TOML file.
    where : str
        File and key path for the error message.

    Raises
    ------
    InputError
        A negative quantity, a non-positive number, a non-boolean flag, an unknown direction.
    """
    t = setting.type
    if t in _SI:
        if t == "voltage" and value == "full":
            return "full"
        a = parse_amount(value, _SI[t], where)
        if a.value < 0:
            raise InputError(f"{where}: must not be negative")
        if t == "frequency" and a.value == 0:
            raise InputError(f"{where}: a frequency must be positive")
        if a.value == 0 and setting.default is None:  # the size of the test itself: zero leaves nothing to measure
            raise InputError(f"{where}: {value!r} is zero: a test of {setting.meaning.split(',')[0]} zero measures nothing; "
                             "give a positive amount")
        return a
    if t in ("number", "count"):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise InputError(f"{where}: expected a positive number, got {value!r}")
        return float(value)
    if t == "bool":
        if not isinstance(value, bool):
            raise InputError(f"{where}: expected true or false, got {value!r}")
        return value
    if t in CHOICES:
        if value not in CHOICES[t]:
            raise InputError(f"{where}: expected one of {', '.join(repr(v) for v in CHOICES[t])}, got {value!r}")
        return value
    allowed = ("opening", "closing") if t == "directions" else ("up", "down")
    if not isinstance(value, list) or not value or any(v not in allowed for v in value):
        raise InputError(f"{where}: expected a non-empty list of {' / '.join(repr(a) for a in allowed)}, got {value!r}")
    return list(value)
