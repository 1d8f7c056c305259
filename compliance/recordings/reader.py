"""Read test-bench recordings into the canonical DataFrame (SI units, absolute pressures).

``read_recording(path, column_map=None, required=...) -> (DataFrame, metadata)`` reads

- the canonical CSV of docs/recording-format.md (also ``.csv.gz``), with its
  optional ``NAME.toml`` sidecar (``X.csv.gz`` -> ``X.toml``);
- any delimited text a column map describes (other names, units, gauge pressures, no header,
  settling rows to drop);
- MATLAB / dSPACE ``.mat`` exports (``scipy.io.loadmat``; plain variables, struct fields,
  dSPACE ``Y(i).Name`` / ``Y(i).Data`` records);
- COMTRADE (IEEE C37.111-1999/2013) ``.cfg`` / ``.dat`` pairs and ``.cff`` single files;
- Parquet (pandas / pyarrow).

Everything that is not a clean recording raises one ``InputError`` naming the file, the
line / sample / column and what was expected (docs/recordings.md has the catalogue).
Nothing is filled, interpolated or guessed.

This module picks the format, runs its reader and checks the result; the readers are
``recording_csv``, ``recording_mat``, ``recording_comtrade`` and ``recording_parquet``,
the mapping to canonical SI columns is ``recording_columns`` and the sidecar is
``recording_metadata``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from compliance.recordings.column_map import ColumnMap, load_column_map
from compliance.errors import InputError
from compliance.recordings.columns import RecordingSource, build_frame, canonical_specs, channel_facts
from compliance.recordings.comtrade import partner_file, read_comtrade
from compliance.recordings.delimited import TEXT_SUFFIXES, read_text_table
from compliance.recordings.mat import read_mat
from compliance.recordings.instruments import check_declarations, instrument_facts, logger_from_comments
from compliance.recordings.metadata import read_sidecar, si_metadata, sidecar_path
from compliance.recordings.parquet import read_parquet
from compliance.recordings.plausibility import check_ranges, check_time_base, relative_time
from compliance.metrics.trace_windows import true_runs

__all__ = ["DEFAULT_REQUIRED", "read_recording", "si_metadata", "sidecar_path"]

DEFAULT_REQUIRED = ("time", "position", "valve_command")  # recording-format.md, "required: yes"
_READERS = {"csv": read_text_table, "mat": read_mat, "comtrade": read_comtrade, "parquet": read_parquet}


def read_recording(path, column_map=None, *, required=DEFAULT_REQUIRED):
    """Read a recording into canonical columns in SI units.

    Parameters
    ----------
    path : str or pathlib.Path
        ``.csv``, ``.csv.gz``, ``.txt``, ``.mat``, ``.cfg`` / ``.dat`` or ``.cff`` (COMTRADE) or ``.parquet``.
    column_map : str, pathlib.Path, dict, ColumnMap or None
        How the file's columns map to canonical names (see ``compliance.recordings.column_map``). None
        means the file already uses canonical names and SI units (absolute pressures).
    required : iterable of str
        Canonical columns the caller needs; ``time`` is always required.

    Returns
    -------
    (pandas.DataFrame, dict)
        Columns ``time`` [s], ``position`` [m], ``reference`` [m], ``valve_command`` [V],
        ``pressure_a`` / ``pressure_b`` / ``supply_pressure`` [Pa abs], and any other mapped
        column in SI (``force`` [N]...). Metadata: the sidecar (and the map's ``[metadata]``)
        with quantities converted to SI floats, plus ``source_path``, ``format``,
        ``column_map``, ``columns`` (canonical -> source description), ``dropped_rows``; for
        COMTRADE also ``trigger_time`` [s], ``comtrade`` (edition, data type, form) and
        ``channels[name]`` = ``{"resolution": SI step, "skew": s}``.

    Raises
    ------
    InputError
        Missing file or header, non-numeric cell, time not strictly increasing, NaN values,
        unknown unit, a required column missing.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: recording not found (or not a file)")
    cmap = load_column_map(column_map) if column_map is not None else None
    fmt = _detect_format(path, cmap)
    src = _READERS[fmt](path, cmap)
    specs = canonical_specs(path, src, cmap)
    frame, described = build_frame(path, src, specs, cmap)
    required = tuple(dict.fromkeys(("time",) + tuple(required)))
    _check_required(path, frame, required, src, cmap)
    drop = cmap.drop_first if cmap else 0
    if drop:
        if drop >= len(frame):
            raise InputError(f"{path}: drop_first = {drop} leaves no rows ({len(frame)} in the file)")
        frame = frame.iloc[drop:].reset_index(drop=True)
    row = (lambda i, _r=src.row, _d=drop: _r(i + _d))
    _check_finite(path, frame, row)
    _check_time(path, frame["time"].to_numpy(), row)
    frame["time"], time_start = relative_time(path, frame["time"].to_numpy())
    check_ranges(path, frame, row)  # every sample, not only the first
    meta = {"time_start": time_start} if time_start else {}
    if cmap is not None and cmap.metadata:
        meta.update(si_metadata(instrument_facts(cmap.metadata, f"{cmap.source}: metadata"), f"{cmap.source}: metadata"))
    meta.update(read_sidecar(path))
    meta = _with_source_facts(meta, dict(src.extra or {}))
    _merge_channel_facts(meta, channel_facts(path, src, specs, cmap))
    time_spec = cmap.spec("time") if cmap is not None else None
    check_time_base(path, frame["time"].to_numpy(), meta,
                    unit_given=src.time is not None or (time_spec is not None and bool(time_spec.unit)))
    check_declarations(frame, meta, _declared_in(path, cmap))
    fmt_name = "csv.gz" if fmt == "csv" and path.name.lower().endswith(".gz") else fmt
    meta.update(
        source_path=str(path),
        format=fmt_name,
        column_map=cmap.source if cmap is not None else None,
        columns=described,
        dropped_rows=drop,
    )
    return frame, meta


def _declared_in(path: Path, cmap: ColumnMap | None) -> str:
    """Where the recording's ``[logger]`` / ``[channels]`` came from: its sidecar, else the column map."""
    side = sidecar_path(path)
    if side.is_file() or cmap is None:
        return str(side)
    return f"{cmap.source}: metadata"


def _merge_channel_facts(meta: dict, facts: dict) -> None:
    """The file's per-channel facts into ``meta["channels"]`` beside the sidecar's ``[channels.NAME]``.

    A resolution stated by both is the coarser one: the recording resolves neither finer than
    its file's quantum nor finer than the sensor the sidecar describes.
    """
    if not facts:
        return
    channels = meta.setdefault("channels", {})
    for name, given in facts.items():
        entry = channels.setdefault(name, {})
        if not isinstance(entry, dict):
            continue
        for key, value in given.items():
            old = entry.get(key)
            numeric = isinstance(old, (int, float)) and not isinstance(old, bool)
            entry[key] = max(float(old), value) if key == "resolution" and numeric else (old if old is not None else value)


def _with_source_facts(meta: dict, extra: dict) -> dict:
    """Metadata with what the file itself says: a format's own channel facts (a COMTRADE channel's
    resolution) under the declared ones, and logger facts from recognised comment lines only when
    neither the sidecar nor the column map declares a ``[logger]``."""
    comments = extra.pop("comment_lines", None)
    channels = extra.pop("channels", None)
    meta.update(extra)
    if channels:
        declared = meta.get("channels") or {}
        meta["channels"] = {name: {**channels.get(name, {}), **declared.get(name, {})} for name in {**channels, **declared}}
    if "logger" not in meta:
        stated = logger_from_comments(comments)
        if stated:
            meta["logger"] = stated
    return meta


def _detect_format(path: Path, cmap: ColumnMap | None) -> str:
    if cmap is not None and cmap.format:
        return cmap.format
    name = path.name.lower()
    if name.endswith(".gz"):
        name = name[:-3]
    suffix = Path(name).suffix
    if suffix in (".cfg", ".cff") or (suffix == ".dat" and partner_file(path, ".cfg") is not None):
        return "comtrade"
    if suffix in TEXT_SUFFIXES:
        return "csv"
    if suffix == ".mat":
        return "mat"
    if suffix in (".parquet", ".pq"):
        return "parquet"
    raise InputError(
        f"{path}: unknown recording format '{suffix}'; expected .csv, .csv.gz, .txt, .mat, "
        f".cfg/.dat or .cff (COMTRADE) or .parquet (or set format = ... in the column map)"
    )


# ----------------------------------------------------------------------------- validation
def _check_required(path: Path, frame: pd.DataFrame, required, src: RecordingSource, cmap: ColumnMap | None) -> None:
    missing = [c for c in required if c not in frame.columns]
    if missing:
        hint = (
            "add it to the column map" if cmap is not None
            else "give a column map (--column-map) that maps your logger's names and units"
        )
        raise InputError(
            f"{path}: missing column(s) {', '.join(repr(m) for m in missing)} needed here; "
            f"the file has: {', '.join(src.names) or 'none'}; {hint}"
        )


def _check_finite(path: Path, frame: pd.DataFrame, row) -> None:
    problems = []
    for name in frame.columns:
        # inclusive [first, last] sample of each gap
        runs = [(a, stop - 1) for a, stop in true_runs(~np.isfinite(frame[name].to_numpy()))]
        if runs:
            shown = ", ".join(row(a) if a == b else f"{row(a)} to {row(b)} ({b - a + 1} values)" for a, b in runs[:3])
            more = f" and {len(runs) - 3} more" if len(runs) > 3 else ""
            problems.append(f"column '{name}' has NaN/empty/infinite values at {shown}{more}")
    if problems:
        raise InputError(
            f"{path}: " + "; ".join(problems) + ". govcheck does not fill gaps: cut or repair the recording"
        )


def _check_time(path: Path, time: np.ndarray, row) -> None:
    if time.size < 2:
        raise InputError(f"{path}: needs at least 2 samples, has {time.size}")
    bad = np.flatnonzero(np.diff(time) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(
            f"{path}: {row(i)}: time not strictly increasing (t = {float(time[i]):.9g} s after {float(time[i - 1]):.9g} s at {row(i - 1)})"
        )
