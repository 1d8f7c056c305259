"""From a format reader's raw columns to the canonical recording frame (SI, absolute pressures).

Every format reader (``recording_csv``, ``recording_mat``, ``recording_comtrade``,
``recording_parquet``) returns a :class:`RecordingSource`: the names it found, a getter of one
raw column and how to name a row in messages. :func:`canonical_specs` and :func:`build_frame`
then map those columns to canonical names and convert their units, the same for every format.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

import numpy as np
import pandas as pd

from compliance.errors import did_you_mean
from compliance.recordings.column_map import CANONICAL_UNITS, ColumnMap, ColumnSpec, is_pressure
from compliance.errors import InputError
from compliance.units import convert_array

__all__ = ["CANONICAL_ORDER", "RecordingSource", "build_frame", "canonical_specs", "channel_facts", "column_position",
           "numeric_column"]

CANONICAL_ORDER = ("time", "position", "reference", "valve_command", "pressure_a", "pressure_b", "supply_pressure")


@dataclass
class RecordingSource:
    """A format reader's output: named raw float arrays plus how to name a row."""

    names: list[str]
    get: Callable[[ColumnSpec], tuple[np.ndarray, str | None]]  # -> (raw values, unit from file)
    row: Callable[[int], str]  # 0-based sample index -> "line 57" / "sample 12"
    time: np.ndarray | None = None  # formats that carry their own time axis (COMTRADE) [s]
    extra: dict | None = None
    # per-channel facts the file states (COMTRADE): {"resolution": in the file's unit, "skew": s}
    facts: Callable[[ColumnSpec], dict] | None = None


def column_position(spec: ColumnSpec, names: list[str], where: str, noun: str, too_few: str, listing: str) -> int:
    """Position in ``names`` of the column a spec asks for, by 0-based index or by name.

    Parameters
    ----------
    spec : ColumnSpec
        ``spec.column`` is an int (index) or a name.
    names : list of str
        Names of the columns the file holds, in order.
    where : str
        File for the error message.
    noun : str
        What a column is called in this format (``"column"``, ``"analog channel"``).
    too_few : str
        End of the message for an index past the last column (``"the file has 3 columns"``).
    listing : str
        Label of the list of names in the message for an unknown name (``"header has"``).

    Raises
    ------
    InputError
        Index out of range or unknown name (with the closest known name).
    """
    c = spec.column
    if isinstance(c, int):
        if c >= len(names):
            raise InputError(f"{where}: {noun} index {c} (for '{spec.name}') but {too_few}")
        return c
    if c not in names:
        raise InputError(f"{where}: no {noun} '{c}' (for '{spec.name}'){did_you_mean(c, names)}; {listing}: {', '.join(names)}")
    return names.index(c)


def numeric_column(col: pd.Series, where_row: Callable[[int], str]) -> np.ndarray:
    """A table column as floats; the first cell that is not a number is an error.

    Parameters
    ----------
    col : pandas.Series
        One column as read (numbers, or text that should hold numbers).
    where_row : callable
        0-based row -> ``"FILE: line 12, column 'x'"`` for the error message.

    Raises
    ------
    InputError
        A boolean column or a cell that is not a number (an empty cell is NaN, left to the
        finiteness check).
    """
    if col.dtype.kind == "M" or _looks_like_dates(col):
        return date_seconds(col, where_row)
    values = pd.to_numeric(col, errors="coerce") if col.dtype.kind not in "fiu" else col
    bad = values.isna() & col.notna()
    if col.dtype.kind == "b" or bad.any():
        i = int(np.argmax(bad.to_numpy())) if bad.any() else 0
        raise InputError(f"{where_row(i)}: {str(col.iloc[i])!r} is not a number")
    return values.to_numpy(dtype=float)


_DATE = re.compile(r"^\s*(\d{4}-\d{1,2}-\d{1,2}|\d{1,2}[./]\d{1,2}[./]\d{2,4})[ T]\d{1,2}:\d{2}")


def _looks_like_dates(col: pd.Series) -> bool:
    return col.dtype.kind == "O" and len(col) > 0 and bool(_DATE.match(str(col.iloc[0])))


def date_seconds(col: pd.Series, where_row: Callable[[int], str]) -> np.ndarray:
    """Date-and-time cells (``2024-03-05 14:22:01.125``, ``05.03.2024 14:22:01,125``) as Unix seconds.

    A time zone written in the cell is honoured; cells without one are read as UTC (the
    recording is made relative to its first sample, so only the start shown in the metadata
    depends on it). Dotted dates are day first (European).
    """
    if col.dtype.kind == "M":
        stamps = pd.to_datetime(col, utc=True)
    else:
        text = col.astype(str).str.strip()
        dayfirst = bool(re.match(r"^\d{1,2}\.", text.iloc[0]))
        text = text.str.replace(r"(:\d{2}),(\d)", r"\1.\2", regex=True)  # decimal comma in the seconds
        stamps = pd.to_datetime(text, errors="coerce", utc=True, format="mixed", dayfirst=dayfirst)
    bad = stamps.isna() & col.notna()
    if bad.any():
        i = int(np.argmax(bad.to_numpy()))
        raise InputError(f"{where_row(i)}: {str(col.iloc[i])!r} is not a date and time like the first cell's")
    return stamps.to_numpy(dtype="datetime64[ns]").astype("int64") * 1e-9  # float64: 0.24 us steps near 2024


def canonical_specs(path, src: RecordingSource, cmap: ColumnMap | None) -> list[ColumnSpec]:
    """The column map's specs, or, without one, the file's canonical names taken as SI."""
    if cmap is not None:
        if src.time is not None and cmap.spec("time") is not None:
            raise InputError(f"{cmap.source}: COMTRADE carries its own time axis; remove 'time' from [columns]")
        return list(cmap.columns)
    specs = []
    for name in src.names:
        canon = name.rsplit(".", 1)[-1]  # MATLAB struct fields come as "rec.position"
        kind = "abs" if is_pressure(canon) else None  # canonical pressures are absolute
        si = CANONICAL_UNITS.get(canon, "Pa" if kind else "")
        specs.append(ColumnSpec(canon, name, None, kind, si_unit=si))
    return specs


def _to_si(path, src: RecordingSource, spec: ColumnSpec, cmap: ColumnMap | None, raw: np.ndarray, file_unit):
    """One raw column in SI (the map's gain and offset, then its unit or the file's); and the unit used."""
    values = spec.gain * raw + spec.offset if (spec.gain != 1.0 or spec.offset != 0.0) else raw
    unit = spec.unit or file_unit
    where = f"{path}: column '{spec.column}' -> '{spec.name}'"
    if cmap is None and src.time is None:
        unit = None  # canonical files are SI by definition
    if unit is not None or spec.kind == "gauge":
        if not spec.si_unit:
            values = convert_array(values, unit or "dimensionless", "dimensionless", where)
        else:
            values = convert_array(values, unit or spec.si_unit, spec.si_unit, where, pressure_kind=spec.kind)
    return np.asarray(values, dtype=float), unit


def build_frame(path, src: RecordingSource, specs: list[ColumnSpec], cmap: ColumnMap | None):
    """Canonical DataFrame (SI) and a description of where each column came from.

    Returns
    -------
    (pandas.DataFrame, dict)
        Columns in canonical order, then any other mapped column; canonical name ->
        ``"source column [unit kind]"``.
    """
    data, described = {}, {}
    if src.time is not None:
        data["time"] = src.time
        described["time"] = "file time axis [s]"
    for spec in specs:
        raw, file_unit = src.get(spec)
        values, unit = _to_si(path, src, spec, cmap, raw, file_unit)
        if spec.name in data:
            raise InputError(f"{path}: two columns map to '{spec.name}'")
        data[spec.name] = values
        kind = f" {spec.kind}" if spec.kind else ""
        described[spec.name] = f"{spec.column} [{unit or spec.si_unit or '-'}{kind}]"
    lengths = {k: len(v) for k, v in data.items()}
    if len(set(lengths.values())) > 1:
        raise InputError(f"{path}: columns have different lengths: {lengths}")
    order = [c for c in CANONICAL_ORDER if c in data] + [c for c in data if c not in CANONICAL_ORDER]
    return pd.DataFrame({c: data[c] for c in order}), described


def channel_facts(path, src: RecordingSource, specs: list[ColumnSpec], cmap: ColumnMap | None) -> dict:
    """Canonical name -> the facts the file states about that channel, resolution in SI.

    The resolution is a step, so it goes through the same conversion as the values as the
    difference of two converted values (offsets such as gauge -> absolute cancel).
    """
    if src.facts is None:
        return {}
    out = {}
    for spec in specs:
        facts = dict(src.facts(spec))
        _, file_unit = src.get(spec)
        step, _ = _to_si(path, src, spec, cmap, np.array([0.0, float(facts["resolution"])]), file_unit)
        facts["resolution"] = abs(float(step[1] - step[0]))
        out[spec.name] = facts
    return out
