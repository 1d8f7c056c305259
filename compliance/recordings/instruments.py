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
"""

from __future__ import annotations

import re

from pydantic import BaseModel, ConfigDict, ValidationError

from compliance.errors import InputError, did_you_mean
from compliance.units import parse_quantity

__all__ = ["CHANNEL_KEYS", "LOGGER_KEYS", "MEASURED_CHANNELS", "instrument_facts", "logger_from_comments"]

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
