"""COMTRADE (IEEE C37.111-1999/2013) recordings read in double precision, on primary values.

The ``comtrade`` package parses the ``.cfg`` and decodes the data; govcheck asks it for
float64 time and values (its default, float32, resolves only 0.24 ms at t = 3600 s), checks the
data against the ``.cfg`` first (``comtrade_files``), and adds what the package leaves out:

- the primary/secondary flag and ratio of each analog channel (C37.111-1999/2013 fields
  ``primary``, ``secondary``, ``PS``): values marked ``S`` are multiplied by primary/secondary;
  a channel whose flag is neither ``P`` nor ``S`` with a ratio other than 1 is refused, since
  nobody can tell which side its values are on;
- the channel resolution: the a-factor ``a`` for integer data (BINARY, BINARY32, ASCII
  integers), ``a`` times the last decimal for ASCII numbers with decimals, ``a`` times the
  float32 spacing at the channel's largest raw value for FLOAT32 — on the primary side, in the
  channel's unit (converted to SI with the values, ``recordings.columns``);
- the channel's time skew, the trigger time and the edition, data type and form (pair / ``.cff``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from compliance.errors import InputError
from compliance.recordings.column_map import ColumnMap, ColumnSpec
from compliance.recordings.columns import RecordingSource, column_position
from compliance.recordings.comtrade_files import DataLayout, check_data, load_parts, partner_file

__all__ = ["partner_file", "primary_scale", "read_comtrade"]


def primary_scale(channel, revision: str, where: str) -> float:
    """Factor from a channel's ``a*x+b`` values to primary values (1, or primary/secondary for ``S``).

    Parameters
    ----------
    channel : comtrade.AnalogChannel
        With ``primary``, ``secondary`` (ratio terms) and ``pors`` (the P/S flag).
    revision : str
        The edition year of the ``.cfg`` (``"1991"`` has no ratio fields: values as recorded).
    where : str
        The channel, for messages.

    Raises
    ------
    InputError
        ``S`` with a ratio that is not two positive numbers; a flag that is neither ``P`` nor
        ``S`` with a ratio other than 1 (ambiguous).
    """
    if revision == "1991":
        return 1.0
    flag = str(channel.pors).strip().upper()
    p, s = float(channel.primary), float(channel.secondary)
    usable = math.isfinite(p) and math.isfinite(s) and p > 0 and s > 0
    if flag == "P":
        return 1.0
    if flag == "S":
        if not usable:
            raise InputError(f"{where}: P/S = S (values on the secondary side) but the ratio primary:secondary = "
                             f"{p:g}:{s:g} cannot scale them to primary; give both as positive numbers")
        return p / s
    if p == s:
        return 1.0  # whichever side the values are on, a 1:1 ratio gives the same primary value
    raise InputError(f"{where}: P/S flag {flag or '(empty)'!r} is neither P nor S, and the ratio primary:secondary = "
                     f"{p:g}:{s:g} is not 1, so whether the values are primary or secondary cannot be told; "
                     "set the flag to P or S")


def _ascii_decimals(data: bytes) -> list[int]:
    """Most digits after the decimal point in each field of the ASCII sample lines (0 for integer data)."""
    lines = data.splitlines()
    width = lines[0].count(b",") + 1 if lines else 0
    if b"." not in data:
        return [0] * width  # the usual case: integer samples, as the 1999 edition writes them
    most = [0] * width
    for line in lines:
        for k, f in enumerate(line.split(b",")):
            most[k] = max(most[k], len(f.strip().partition(b".")[2]))
    return most


def _raw_resolution(layout: DataLayout, channel, raw: np.ndarray, decimals: int) -> float:
    """Smallest step of a channel's ``a*x+b`` values the file can hold [channel unit]."""
    a = abs(float(channel.a))
    if layout.file_type == "FLOAT32":
        finite = np.abs(raw[np.isfinite(raw)])
        return a * float(np.spacing(np.float32(finite.max() if finite.size else 1.0)))
    return a * 10.0 ** -decimals


def _parse(parts, data: bytes, layout: DataLayout):
    import comtrade

    rec = comtrade.Comtrade(ignore_warnings=True, use_numpy_arrays=True, use_double_precision=True)
    try:
        rec.read(parts.cfg_text, data.decode("ascii") if layout.file_type == "ASCII" else data)
    except Exception as exc:  # the comtrade package raises bare Exceptions on bad files
        raise InputError(f"{parts.cfg_where}: not a readable COMTRADE recording ({exc.__class__.__name__}: {exc})") from None
    return rec


def _layout(parts) -> DataLayout:
    import comtrade

    cfg = comtrade.Cfg(ignore_warnings=True)
    try:
        cfg.read(parts.cfg_text)
        return DataLayout(str(cfg.ft).strip().upper(), int(cfg.sample_rates[-1][1]), cfg.analog_count, cfg.status_count)
    except Exception as exc:  # the comtrade package raises bare Exceptions on bad files
        raise InputError(f"{parts.cfg_where}: not a readable COMTRADE configuration ({exc.__class__.__name__}: {exc})") from None


def read_comtrade(path: Path, cmap: ColumnMap | None) -> RecordingSource:
    """Read a COMTRADE recording (``.cfg`` / ``.dat`` pair or ``.cff``) into primary-side float64 channels.

    Returns
    -------
    RecordingSource
        Channels by id (or 0-based index), the file's time axis [s], per-channel facts
        (``resolution`` in the channel unit, ``skew`` [s]) and the recording facts
        (station, device, start and trigger time stamps, ``trigger_time`` [s] = trigger stamp minus
        first-sample stamp, i.e. measured from the first sample, as ``comtrade.Comtrade.trigger_time``;
        on the file's time axis the trigger is at the first sample's time plus it; edition, data type, form).

    Raises
    ------
    InputError
        Half a pair, data the ``.cfg`` does not describe, an unreadable file, an ambiguous
        primary/secondary flag, an unknown channel.
    """
    parts = load_parts(path)
    layout = _layout(parts)
    data = check_data(parts, layout)
    rec = _parse(parts, data, layout)
    cfg = rec.cfg
    revision = str(cfg.rev_year).strip()
    time = np.asarray(rec.time, dtype=np.float64)
    ids = [str(n).strip() for n in rec.analog_channel_ids]
    raw = [np.asarray(v, dtype=np.float64) for v in rec.analog]
    scales = [primary_scale(ch, revision, f"{parts.cfg_where}: analog channel {ch.n} '{name}'")
              for ch, name in zip(cfg.analog_channels, ids)]
    units = [str(ch.uu).strip() or None for ch in cfg.analog_channels]
    decimals = _ascii_decimals(data)[2:] if layout.file_type == "ASCII" else [0] * len(ids)

    def position(spec: ColumnSpec) -> int:
        return column_position(spec, ids, parts.cfg_where, "analog channel", f"there are {len(ids)}", "channels")

    def get(spec: ColumnSpec):
        j = position(spec)
        return raw[j] * scales[j], units[j]

    def facts(spec: ColumnSpec) -> dict:
        j = position(spec)
        ch = cfg.analog_channels[j]
        values = (raw[j] - float(ch.b)) / float(ch.a) if float(ch.a) else raw[j]
        return {"resolution": _raw_resolution(layout, ch, values, decimals[j]) * scales[j], "skew": float(ch.skew) * 1e-6}

    return RecordingSource(ids, get, lambda i: f"sample {i + 1}", time=time, extra=_recording_facts(rec, parts, layout),
                           facts=facts)


def _recording_facts(rec, parts, layout: DataLayout) -> dict:
    cfg = rec.cfg
    extra = {"station_name": str(rec.station_name).strip(), "recording_device": str(rec.rec_dev_id).strip(),
             "comtrade": {"revision": str(cfg.rev_year).strip(), "file_type": layout.file_type, "form": parts.form,
                          "time_from": "time stamps" if cfg.timestamp_critical else "sample rate"}}
    # the comtrade package gives an empty time stamp as year 1; such a stamp is left out, not reported as a date
    start, trigger = (t if t is not None and t.year > 1 else None for t in (cfg.start_timestamp, cfg.trigger_timestamp))
    if start is not None:
        extra["start_timestamp"] = start.isoformat()
    if trigger is not None:
        extra["trigger_timestamp"] = trigger.isoformat()
        if start is not None:
            extra["trigger_time"] = (trigger - start).total_seconds()
    return extra
