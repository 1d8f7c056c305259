"""What a sidecar declares about its instruments, checked against the recording it describes.

``[logger]`` and ``[channels.NAME]`` (``compliance.recordings.instruments``) are validated for
shape and units where they are read; here they meet the data: a declared logger rate must be the
rate of the time stamps, a transducer's declared range must hold what it recorded, and a
channel's declared delay must leave some of the recording to compare. A declaration that
contradicts its data is refused (one message naming the file, the key and both figures), because
the replay would otherwise put a wrong filter, delay or calibration on the model and report the
result as a finding about the plant.

Each check is its own function (``check_logger_rate``, ``check_channel_ranges``,
``check_channel_delays``); ``check_declarations`` runs them all.
"""

from __future__ import annotations

import numpy as np

from compliance.errors import InputError
from compliance.units import ATMOSPHERE_PA

__all__ = ["RANGE_MARGIN", "RATE_TOLERANCE", "check_channel_delays", "check_channel_ranges", "check_declarations",
           "check_logger_rate"]

RATE_TOLERANCE = 0.02  # a declared rate and the time stamps' median rate agree to 2 % (clock drift is ppm; our margin)
RANGE_MARGIN = 0.05  # transducers read a little past their nominal span; 5 % of the span either side (our margin)
_PRESSURES = ("pressure_a", "pressure_b", "supply_pressure")
_SHOW = {"position": (1e3, "mm"), "reference": (1e3, "mm"), "valve_command": (1.0, "V"), "force": (1e-3, "kN"),
         **{p: (1e-5, "bar") for p in _PRESSURES}}


def check_logger_rate(frame, meta: dict, where: str) -> None:
    """``[logger] rate`` is the rate of the time stamps (median interval) to ``RATE_TOLERANCE``.

    A rate read from a comment line (``instruments.logger_from_comments``) is what the logger can do, not a
    declaration of this file (a trend log may be decimated), and is not held to the time stamps.
    """
    logger = meta.get("logger") or {}
    rate = logger.get("rate")
    if logger.get("source") == "comment lines":
        return
    if not isinstance(rate, (int, float)) or isinstance(rate, bool) or len(frame) < 2:
        return
    dt = float(np.median(np.diff(frame["time"].to_numpy())))
    if not dt > 0:
        return
    seen = 1.0 / dt
    if abs(seen / rate - 1.0) > RATE_TOLERANCE:
        raise InputError(f"{where}: logger.rate = {rate:g} Hz, and the time stamps are {seen:.4g} Hz apart (median interval "
                         f"{dt * 1e3:.4g} ms); the declared rate sets the replay's sampling, so correct the declaration "
                         "(or the time column's unit)")


def _span_text(name: str, lo: float, hi: float) -> str:
    k, unit = _SHOW.get(name, (1.0, "SI"))
    return f"{lo * k:.4g} .. {hi * k:.4g} {unit}"


def check_channel_ranges(frame, meta: dict, where: str) -> None:
    """Every recorded value of a channel lies in its declared ``range`` (``RANGE_MARGIN`` of the span either side).

    A pressure range may be written gauge or absolute (the data are absolute): it holds when the
    data fit either reading.
    """
    for name, facts in (meta.get("channels") or {}).items():
        rng = facts.get("range") if isinstance(facts, dict) else None
        if not rng or name not in frame.columns:
            continue
        lo, hi = float(rng[0]), float(rng[1])
        pad = RANGE_MARGIN * (hi - lo)
        data = frame[name].to_numpy()
        low, high = float(np.min(data)), float(np.max(data))
        shifts = (0.0, ATMOSPHERE_PA) if name in _PRESSURES else (0.0,)
        if any(low >= lo + s - pad and high <= hi + s + pad for s in shifts):
            continue
        k, unit = _SHOW.get(name, (1.0, "SI"))
        worst = high if high > hi + pad else low
        reading = " (gauge or absolute)" if name in _PRESSURES else ""
        raise InputError(f"{where}: channels.{name}.range = {_span_text(name, lo, hi)}{reading}, and the recording's "
                         f"'{name}' reaches {worst * k:.4g} {unit} (recorded {_span_text(name, low, high)}); a transducer "
                         "cannot record beyond its range: correct the declared range (or the column's unit)")


def check_channel_delays(frame, meta: dict, where: str) -> None:
    """A channel's declared ``delay`` is shorter than the recording (else nothing of it could be compared)."""
    t = frame["time"].to_numpy()
    duration = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    for name, facts in (meta.get("channels") or {}).items():
        delay = facts.get("delay") if isinstance(facts, dict) else None
        if not isinstance(delay, (int, float)) or isinstance(delay, bool):
            continue
        if delay >= duration:
            raise InputError(f"{where}: channels.{name}.delay = {delay:g} s is as long as the whole recording "
                             f"({duration:.4g} s): no sample of '{name}' would be left to compare; a logging delay is a "
                             "few samples (check the unit: \"5 ms\", not \"5 s\")")


def check_declarations(frame, meta: dict, where: str) -> None:
    """Run every declaration check (logger rate, channel ranges, channel delays) on one recording.

    Parameters
    ----------
    frame : pandas.DataFrame
        The recording in canonical SI columns (absolute pressures).
    meta : dict
        Its metadata with ``logger`` and ``channels`` in SI (``instruments.instrument_facts``).
    where : str
        The file that declared them, for the message.

    Raises
    ------
    InputError
        A declaration its data contradict.
    """
    check_logger_rate(frame, meta, where)
    check_channel_ranges(frame, meta, where)
    check_channel_delays(frame, meta, where)
