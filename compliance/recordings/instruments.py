"""The logger and its sensors as a recording declares them: ``[logger]`` and ``[channels.NAME]``.

A field recording is shaped by its instruments as well as by the plant: the logger's own rate and
anti-alias filter (a first-order filter at f_c delays slow signals by 1/(2 pi f_c)), a channel group
logged late on a second acquisition module, a transducer's resolution and calibration. The sidecar
(or a column map's ``[metadata]``) declares them here, in one schema, so the replay can put the same
filter, delays and calibration on the simulated channels and the noise floors can respect the
resolution (docs/recording-format.md, "Logger and channels").

Every key is validated at the edge (pydantic for the shape, pint for the units): numbers are SI,
strings carry units (``"80 Hz"``, ``"3 ms"``, ``"50 um"``). The result is the metadata convention
every reader shares: ``metadata["logger"] = {"rate": Hz, "anti_alias_cutoff": Hz, ...}`` and
``metadata["channels"][canonical_name] = {"resolution": SI, "delay": s, "gain": relative,
"offset": SI, ...}`` (SI floats).

A logger's own comment lines may say the same (``# portable DAQ, 500 Hz, first-order anti-alias
filter 200 Hz on every analog input``); only the exact phrases of ``COMMENT_PATTERNS`` count, and
only when the sidecar declares no ``[logger]``.

The declarations are then held to the data they describe (``check_declarations``, run by the
reader on every recording): a declared logger rate must be the rate of the time stamps, a
transducer's declared range must hold what it recorded, and a channel's declared delay must leave
some of the recording to compare. A declaration that contradicts its data is refused (one message
naming the file, the key and both figures): the replay would otherwise put a wrong filter, delay or
calibration on the model and report the result as a finding about the plant. Each check is its own
function (``check_logger_rate``, ``check_channel_ranges``, ``check_channel_delays``).
"""

from __future__ import annotations

import re

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

from compliance.errors import InputError, did_you_mean
from compliance.units import ATMOSPHERE_PA, parse_quantity

__all__ = ["CHANNEL_KEYS", "LOGGER_KEYS", "MEASURED_CHANNELS", "RANGE_MARGIN", "RATE_TOLERANCE", "check_channel_delays",
           "check_channel_ranges", "check_declarations", "check_logger_rate", "instrument_facts", "logger_from_comments"]

# channels whose instruments may be declared, and the SI unit of their values
MEASURED_CHANNELS = {"position": "m", "reference": "m", "valve_command": "V", "pressure_a": "Pa", "pressure_b": "Pa",
                     "supply_pressure": "Pa", "force": "N"}
Quantity = float | int | str


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _Logger(_Strict):
    rate: Quantity | None = None  # Hz: the logger's own sample rate (the time stamps say it too)
    anti_alias_cutoff: Quantity | None = None  # Hz: first-order anti-alias filter on every measured channel
    anti_alias_order: int = 1  # only first-order filters are modelled
    description: str | None = None


class _Channel(_Strict):
    delay: Quantity | None = None  # s: logged this much later than the controller's clock
    resolution: Quantity | None = None  # channel unit: quantisation step of the transducer / converter
    gain: Quantity | None = None  # relative: recorded = gain * true (on gauge pressure for pressures)
    offset: Quantity | None = None  # channel unit: added after the gain
    anti_alias_cutoff: Quantity | None = None  # Hz: this channel's own filter (overrides the logger's)
    range: list[Quantity] | None = None  # channel unit: [low, high] the transducer covers
    description: str | None = None


LOGGER_KEYS = tuple(_Logger.model_fields)
CHANNEL_KEYS = tuple(_Channel.model_fields)
_LOGGER_UNITS = {"rate": "Hz", "anti_alias_cutoff": "Hz"}
_CHANNEL_UNITS = {"delay": "s", "gain": "", "anti_alias_cutoff": "Hz"}  # resolution, offset, range: the channel's


def _message(exc: ValidationError, where: str, known) -> str:
    err = exc.errors()[0]
    path = ".".join(str(p) for p in err["loc"])
    if err["type"] == "extra_forbidden":
        key = str(err["loc"][-1])
        return f"{where}.{path}: unknown key{did_you_mean(key, known)} (known: {', '.join(known)})"
    return f"{where}.{path}: {err['msg']}"


def _validated(model: type[_Strict], table, where: str, title: str) -> _Strict:
    if not isinstance(table, dict):
        raise InputError(f"{where}: expected a table [{title}]")
    try:
        return model(**table)
    except ValidationError as exc:
        raise InputError(_message(exc, where, tuple(model.model_fields))) from None


def _si(value, unit: str, where: str, *, positive: bool = False, allow_zero: bool = True) -> float:
    v = parse_quantity(value, unit, where)  # pressures here are differences (resolution, offset): no abs/gauge
    if positive and not (v > 0 or (allow_zero and v == 0)):
        raise InputError(f"{where}: {value!r}; expected a {'non-negative' if allow_zero else 'positive'} quantity")
    return float(v)


def _logger(table, where: str) -> dict:
    facts = _validated(_Logger, table, where, "logger")
    if facts.anti_alias_order != 1:
        raise InputError(f"{where}.anti_alias_order: {facts.anti_alias_order}; only a first-order anti-alias filter is modelled (1)")
    out = {}
    for key, unit in _LOGGER_UNITS.items():
        value = getattr(facts, key)
        if value is not None:
            out[key] = _si(value, unit, f"{where}.{key}", positive=True, allow_zero=False)
    if facts.description:
        out["description"] = facts.description
    return out


def _channel(name: str, table, where: str) -> dict:
    if name not in MEASURED_CHANNELS:
        raise InputError(f"{where}: unknown channel '{name}'{did_you_mean(name, MEASURED_CHANNELS)} "
                         f"(known: {', '.join(MEASURED_CHANNELS)})")
    facts = _validated(_Channel, table, where, f"channels.{name}")
    unit = MEASURED_CHANNELS[name]
    out = {}
    if facts.delay is not None:
        out["delay"] = _si(facts.delay, "s", f"{where}.delay")
    if facts.resolution is not None:
        out["resolution"] = _si(facts.resolution, unit, f"{where}.resolution", positive=True)
    if facts.gain is not None:
        out["gain"] = _si(facts.gain, "", f"{where}.gain", positive=True, allow_zero=False)
    if facts.offset is not None:
        out["offset"] = _si(facts.offset, unit, f"{where}.offset")
    if facts.anti_alias_cutoff is not None:
        out["anti_alias_cutoff"] = _si(facts.anti_alias_cutoff, "Hz", f"{where}.anti_alias_cutoff", positive=True, allow_zero=False)
    if facts.range is not None:
        if len(facts.range) != 2:
            raise InputError(f"{where}.range: expected [low, high]")
        lo, hi = (_si(v, unit, f"{where}.range") for v in facts.range)
        if not hi > lo:
            raise InputError(f"{where}.range: [{lo:g}, {hi:g}]; expected low < high")
        out["range"] = [lo, hi]
    return out


def instrument_facts(data: dict, where: str) -> dict:
    """Validate and convert a metadata tree's ``logger`` and ``channels`` tables to SI floats.

    Parameters
    ----------
    data : dict
        Raw sidecar (or column-map ``[metadata]``) tree; other keys are returned untouched.
    where : str
        File name for messages.

    Returns
    -------
    dict
        ``data`` with ``logger`` (``rate``, ``anti_alias_cutoff`` [Hz]) and ``channels`` (canonical
        name -> ``delay`` [s], ``resolution`` / ``offset`` [channel SI unit], ``gain`` [-],
        ``anti_alias_cutoff`` [Hz], ``range``) in SI, when declared.

    Raises
    ------
    InputError
        An unknown key or channel, a value of the wrong dimension or sign.
    """
    out = dict(data)
    if "logger" in data:
        out["logger"] = _logger(data["logger"], f"{where}: logger")
    if "channels" in data:
        chans = data["channels"]
        if not isinstance(chans, dict):
            raise InputError(f"{where}: channels: expected tables [channels.NAME]")
        out["channels"] = {name: _channel(name, table, f"{where}: channels.{name}") for name, table in chans.items()}
    return out


# a logger's comment line that states its anti-alias filter, or states that there is none
COMMENT_PATTERNS = {
    "anti_alias_cutoff": re.compile(r"first[- ]order\s+anti[- ]alias(?:ing)?\s+filter\s+(?:at\s+)?(\d+(?:\.\d+)?)\s*Hz", re.I),
    "rate": re.compile(r"(?:DAQ|logger|trend log)\b[^#]*?\(?\b(\d+(?:\.\d+)?)\s*Hz\b", re.I),
}


def logger_from_comments(lines) -> dict:
    """Logger facts stated in a recording's comment lines in the phrases ``COMMENT_PATTERNS`` knows.

    Returns ``{"rate": Hz, "anti_alias_cutoff": Hz}`` for what was stated (``{}`` when nothing was),
    ``"source": "comment lines"`` when anything was.
    """
    out = {}
    for line in lines or ():
        for key, pattern in COMMENT_PATTERNS.items():
            m = pattern.search(line)
            if m and key not in out:
                out[key] = float(m.group(1))
    return out | {"source": "comment lines"} if out else {}


# ----------------------------------------------------------------------------- declarations held to the data
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
