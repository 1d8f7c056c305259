"""Write a recording frame as COMTRADE (IEEE C37.111-2013, or -1999): ``.cfg`` + ``.dat``, or one ``.cff``.

The bytes are made in memory; the caller writes them with the one atomic writer. Choices
(ours, within the standard):

- one analog channel per numeric column, named as the column, unit ``uu`` in SI
  (``recordings.column_map.CANONICAL_UNITS``; pressures absolute, in Pa);
- integer data types are scaled per channel so the channel's range fills the integers
  (``a`` = half the range / the largest integer, ``b`` = the mid-range): the a-factor is the
  file's resolution, a few 1e-10 of the range for BINARY32;
- a uniform time axis starting at 0 is declared by its sample rate (``nrates = 1``), any other
  by the time stamps (``nrates = 0``, microseconds, ``timemult`` raised when 32 bits of
  microseconds, 71 min, are not enough);
- no power line is involved: the line frequency is written as 0; the time quality code is
  ``F`` (no clock: a simulation has no date), the start time the epoch unless given;
- values are primary (``P``) unless a channel is given a ratio, then its values are written on
  the secondary side (``S``) as a transducer behind a CT/PT ratio would log them.
"""

from __future__ import annotations

import datetime as _dt
import math

import numpy as np
import pandas as pd

from compliance.errors import InputError
from compliance.recordings.column_map import CANONICAL_UNITS

__all__ = ["FILE_TYPES", "comtrade_bytes"]

# raw integer range per data type, and the value that marks a missing sample (C37.111-1999/2013)
_INT_RANGE = {"ASCII": 99998, "BINARY": 32767, "BINARY32": 2147483647}
_MISSING = {"ASCII": 99999, "BINARY": -32768, "BINARY32": -2147483648}
_DTYPE = {"BINARY": "<i2", "BINARY32": "<i4", "FLOAT32": "<f4"}
FILE_TYPES = {"1999": ("ASCII", "BINARY"), "2013": ("ASCII", "BINARY", "BINARY32", "FLOAT32")}
_MAX_STAMP = 4294967294  # 0xFFFFFFFF marks a missing time stamp
_TIME_BASE = 1e-6  # [s] time stamps in microseconds (six decimals in the .cfg time stamps)


def _scaling(values: np.ndarray, file_type: str) -> tuple[float, float]:
    """a, b with a*raw + b = value over the channel's range (a = 1, b = 0 for FLOAT32)."""
    if file_type == "FLOAT32":
        return 1.0, 0.0
    finite = values[np.isfinite(values)]
    lo, hi = (float(np.min(finite)), float(np.max(finite))) if finite.size else (0.0, 0.0)
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    top = _INT_RANGE[file_type]
    if not half > 0:
        return (abs(mid) or 1.0) / top, mid  # a constant channel: any step, raw 0
    return half / top, mid


def _time_plan(time: np.ndarray) -> tuple[list[str], np.ndarray, float]:
    """The sample-rate lines of the .cfg, the time stamps and timemult."""
    if time.size and float(time[0]) < 0:
        raise InputError(f"COMTRADE time stamps cannot be negative (the first sample is at {time[0]:g} s)")
    n = time.size
    dt = np.diff(time)
    step = float(np.median(dt)) if n > 1 else 0.0
    uniform = n > 1 and step > 0 and float(np.max(np.abs(dt - step))) <= 1e-9 * step and abs(float(time[0])) <= 1e-9 * step
    mult = max(1.0, float(math.ceil(float(time[-1]) / (_TIME_BASE * _MAX_STAMP)))) if n else 1.0
    stamps = np.rint(time / (_TIME_BASE * mult)).astype(np.uint32)
    rates = ["1", f"{1.0 / step!r},{n}"] if uniform else ["0", f"0,{n}"]
    return rates, stamps, mult


def _field(text: str) -> str:
    """A free-text .cfg field: no comma (the separator) and no line break."""
    return " ".join(str(text).replace(",", " ").split())


def _raw(values: np.ndarray, a: float, b: float, file_type: str) -> np.ndarray:
    """The stored samples of one channel: a*raw + b = value, NaN as the standard's missing value."""
    if file_type == "FLOAT32":
        return values
    top = _INT_RANGE[file_type]
    raw = np.clip(np.rint((values - b) / a), -top, top)
    raw[~np.isfinite(values)] = _MISSING[file_type]
    return raw


def _stamp(t: _dt.datetime) -> str:
    return t.strftime("%d/%m/%Y,%H:%M:%S.%f")


def _channels(frame: pd.DataFrame, ratios: dict) -> list[tuple[str, np.ndarray, str, float]]:
    """(name, values as written, unit, primary/secondary ratio or 0 for primary values)."""
    out = []
    for name in frame.columns:
        if name == "time" or frame[name].dtype.kind not in "fiub":
            continue
        if "," in str(name) or not str(name).strip():
            raise InputError(f"column {name!r}: a COMTRADE channel id must be non-empty and hold no comma")
        values = frame[name].to_numpy(dtype=np.float64)
        ratio = ratios.get(name)
        k = float(ratio[0]) / float(ratio[1]) if ratio else 0.0
        out.append((name, values / k if k else values, CANONICAL_UNITS.get(name, ""), k))
    return out


def comtrade_bytes(frame: pd.DataFrame, *, station: str, device: str = "govcheck", revision: str = "2013",
                   file_type: str = "BINARY32", single_file: bool = False, start: _dt.datetime | None = None,
                   trigger_time: float = 0.0, ratios: dict | None = None, header: str = "") -> dict[str, bytes]:
    """The COMTRADE files of a frame with a ``time`` column [s] and SI value columns.

    Parameters
    ----------
    frame : pandas.DataFrame
        ``time`` [s] (>= 0, increasing) and numeric columns in SI (pressures absolute).
    station, device : str
        The .cfg's station name and recording device id.
    revision : {"2013", "1999"}
        The edition written.
    file_type : {"ASCII", "BINARY", "BINARY32", "FLOAT32"}
        The data type (1999: ASCII or BINARY).
    single_file : bool
        One ``.cff`` (2013 only) instead of ``.cfg`` + ``.dat``.
    start : datetime, optional
        Time stamp of the first data point (default 1970-01-01 00:00:00).
    trigger_time : float
        Trigger on the frame's time axis [s]; its stamp is ``start`` + (trigger_time - the first sample's time).
    ratios : dict, optional
        Column -> (primary, secondary): those columns are written as secondary values.
    header : str
        Free text for the HDR section of a ``.cff``.

    Returns
    -------
    dict
        Suffix (``".cfg"``, ``".dat"`` or ``".cff"``) -> bytes.
    """
    if file_type not in FILE_TYPES.get(revision, ()):
        raise InputError(f"COMTRADE {revision}: data type {file_type!r} is not one of {FILE_TYPES.get(revision, ())}")
    if single_file and revision != "2013":
        raise InputError("the single-file form .cff exists in COMTRADE 2013 only")
    time = frame["time"].to_numpy(dtype=np.float64)
    chans = _channels(frame, ratios or {})
    rates, stamps, mult = _time_plan(time)
    scales = [_scaling(v, file_type) for _, v, _, _ in chans]
    raws = [_raw(v, a, b, file_type) for (_, v, _, _), (a, b) in zip(chans, scales)]
    start = start or _dt.datetime(1970, 1, 1)
    lines = [f"{_field(station)},{_field(device)},{revision}", f"{len(chans)},{len(chans)}A,0D"]
    for i, ((name, _, unit, k), (a, b), raw) in enumerate(zip(chans, scales, raws), 1):
        kept = raw[np.isfinite(raw) & (raw != _MISSING.get(file_type))]
        lo, hi = (float(np.min(kept)), float(np.max(kept))) if kept.size else (0.0, 0.0)
        ratio = f"{k!r},1.0,S" if k else "1.0,1.0,P"
        lo_hi = f"{lo:.9g},{hi:.9g}" if file_type == "FLOAT32" else f"{int(lo)},{int(hi)}"
        lines.append(f"{i},{name},,,{unit},{a!r},{b!r},0,{lo_hi},{ratio}")
    # the first time stamp is the first sample's: the trigger's stamp is measured from it, not from t = 0
    trigger = start + _dt.timedelta(seconds=float(trigger_time) - float(time[0]))
    lines += ["0", *rates, _stamp(start), _stamp(trigger), file_type, f"{mult:g}"]
    if revision == "2013":
        lines += ["0,0", "F,0"]  # UTC, local = UTC; time quality F: no clock behind these times
    cfg = ("\r\n".join(lines) + "\r\n").encode("ascii")
    n = np.arange(1, time.size + 1, dtype=np.uint32)
    if file_type == "ASCII":
        cols = [n.astype(str), stamps.astype(str)] + [r.astype(np.int64).astype(str) for r in raws]
        dat = ("\r\n".join(",".join(row) for row in zip(*cols)) + "\r\n").encode("ascii")
    else:
        dtype = [("n", "<u4"), ("t", "<u4")] + [(f"c{i}", _DTYPE[file_type]) for i in range(len(chans))]
        rec = np.empty(time.size, dtype=dtype)
        rec["n"], rec["t"] = n, stamps
        for i, raw in enumerate(raws):
            rec[f"c{i}"] = raw
        dat = rec.tobytes()
    if not single_file:
        return {".cfg": cfg, ".dat": dat}
    # C37.111-2013 names the data section ASCII or BINARY only; which binary type is the .cfg's ft line
    kind = "ASCII" if file_type == "ASCII" else f"BINARY: {len(dat)}"
    hdr = (header.rstrip() + "\r\n") if header.strip() else ""
    head = b"--- file type: CFG ---\r\n" + cfg + b"--- file type: INF ---\r\n--- file type: HDR ---\r\n" + hdr.encode("utf-8")
    return {".cff": head + f"--- file type: DAT {kind} ---\r\n".encode("ascii") + dat}
