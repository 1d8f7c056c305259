"""Read test-bench recordings into the canonical DataFrame (SI units, absolute pressures).

``read_recording(path, column_map=None, required=...) -> (DataFrame, metadata)`` reads

- the canonical CSV of ``/work/shared/recording-format.md`` (also ``.csv.gz``), with its
  optional ``NAME.toml`` sidecar (``X.csv.gz`` -> ``X.toml``);
- any delimited text a column map describes (other names, units, gauge pressures, no header,
  settling rows to drop);
- MATLAB / dSPACE ``.mat`` exports (``scipy.io.loadmat``; plain variables, struct fields,
  dSPACE ``Y(i).Name`` / ``Y(i).Data`` records);
- COMTRADE (IEEE C37.111) ``.cfg`` / ``.dat`` pairs (the ``comtrade`` package);
- Parquet (pandas / pyarrow).

Everything that is not a clean recording raises one ``InputError`` naming the file, the
line / sample / column and what was expected (docs/recordings.md has the catalogue).
Nothing is filled, interpolated or guessed.
"""

from __future__ import annotations

import gzip
import io
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from .column_map import CANONICAL_UNITS, ColumnMap, ColumnSpec, _suggest, is_pressure, load_column_map
from .errors import InputError
from .units import convert_array, parse_quantity, registry

DEFAULT_REQUIRED = ("time", "position", "valve_command")  # recording-format.md, "required: yes"
_CANONICAL_ORDER = ("time", "position", "reference", "valve_command", "pressure_a", "pressure_b", "supply_pressure")
_TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")
_NUMBER_WITH_UNIT = re.compile(r"^\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*[^\d\s.,:;/\-+]")
_PRESSURE_WORD = re.compile(r"\s+\(?(abs|absolute|a|gauge|g)\)?\s*$", re.IGNORECASE)
_TEXT_KEYS = ("description", "plant", "name", "notes", "source", "licence", "license")


@dataclass
class _Source:
    """A format reader's output: named raw float arrays plus how to name a row."""

    names: list[str]
    get: Callable[[ColumnSpec], tuple[np.ndarray, str | None]]  # -> (raw values, unit from file)
    row: Callable[[int], str]  # 0-based sample index -> "line 57" / "sample 12"
    time: np.ndarray | None = None  # formats that carry their own time axis (COMTRADE) [s]
    extra: dict | None = None


def read_recording(path, column_map=None, *, required=DEFAULT_REQUIRED):
    """Read a recording into canonical columns in SI units.

    Parameters
    ----------
    path : str or pathlib.Path
        ``.csv``, ``.csv.gz``, ``.txt``, ``.mat``, ``.cfg`` / ``.dat`` (COMTRADE) or ``.parquet``.
    column_map : str, pathlib.Path, dict, ColumnMap or None
        How the file's columns map to canonical names (see ``compliance.column_map``). None
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
        ``column_map``, ``columns`` (canonical -> source description), ``dropped_rows``.

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
    reader = {"csv": _read_text_table, "mat": _read_mat, "comtrade": _read_comtrade, "parquet": _read_parquet}[fmt]
    src = reader(path, cmap)
    specs = _specs(path, src, cmap)
    frame, described = _build_frame(path, src, specs, cmap)
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
    meta = {}
    if cmap is not None and cmap.metadata:
        meta.update(si_metadata(cmap.metadata, f"{cmap.source}: metadata"))
    meta.update(_sidecar(path))
    if src.extra:
        meta.update(src.extra)
    fmt_name = "csv.gz" if fmt == "csv" and path.name.lower().endswith(".gz") else fmt
    meta.update(
        source_path=str(path),
        format=fmt_name,
        column_map=cmap.source if cmap is not None else None,
        columns=described,
        dropped_rows=drop,
    )
    return frame, meta


# ----------------------------------------------------------------------------- formats
def _detect_format(path: Path, cmap: ColumnMap | None) -> str:
    if cmap is not None and cmap.format:
        return cmap.format
    name = path.name.lower()
    if name.endswith(".gz"):
        name = name[:-3]
    suffix = Path(name).suffix
    if suffix == ".cfg" or (suffix == ".dat" and _partner(path, ".cfg") is not None):
        return "comtrade"
    if suffix in _TEXT_SUFFIXES:
        return "csv"
    if suffix == ".mat":
        return "mat"
    if suffix in (".parquet", ".pq"):
        return "parquet"
    raise InputError(
        f"{path}: unknown recording format '{suffix}'; expected .csv, .csv.gz, .txt, .mat, "
        f".cfg/.dat (COMTRADE) or .parquet (or set format = ... in the column map)"
    )


def _partner(path: Path, suffix: str) -> Path | None:
    for s in (suffix, suffix.upper()):
        p = path.with_suffix(s)
        if p.is_file():
            return p
    return None


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _split(line: str, delim: str | None) -> list[str]:
    return line.split() if delim is None else line.split(delim)


def _read_text_table(path: Path, cmap: ColumnMap | None) -> _Source:
    try:
        if path.name.lower().endswith(".gz"):
            with gzip.open(path, "rt", encoding="utf-8") as fh:
                text = fh.read()
        else:
            text = path.read_text(encoding="utf-8")
    except (UnicodeDecodeError, OSError, EOFError) as exc:
        raise InputError(f"{path}: cannot read as UTF-8 text ({exc.__class__.__name__}: {exc})") from None
    comment = cmap.comment if cmap else "#"
    skip = cmap.skip_rows if cmap else 0
    delim = cmap.delimiter if cmap else ","
    header = cmap.header if cmap else True
    numbers, lines = [], []
    for no, line in enumerate(text.splitlines()[skip:], start=skip + 1):
        stripped = line.strip()
        if stripped and not stripped.startswith(comment):
            numbers.append(no)
            lines.append(line)
    if not lines:
        raise InputError(f"{path}: no data (only blank or '{comment}' comment lines)")
    names = None
    if header:
        names = [h.strip().strip("\"'") for h in _split(lines[0], delim)]
        if all(_is_number(h) for h in names):
            raise InputError(
                f"{path}: line {numbers[0]}: no header line (the first line is all numbers); the canonical "
                f"CSV starts with column names (time,position,...), or give a column map with header = false"
            )
        for j, h in enumerate(names):
            if not h:
                raise InputError(f"{path}: line {numbers[0]}: header column {j + 1} has no name")
            if h in names[:j]:
                raise InputError(f"{path}: line {numbers[0]}: column name '{h}' appears twice in the header")
        numbers, lines = numbers[1:], lines[1:]
        if not lines:
            raise InputError(f"{path}: a header but no data rows")
    try:
        table = pd.read_csv(
            io.StringIO("\n".join(lines)),
            header=None,
            sep=r"\s+" if delim is None else delim,
            skipinitialspace=True,
            engine="c",
        )
    except pd.errors.ParserError as exc:
        m = re.search(r"line (\d+), saw (\d+)", str(exc))
        where = f"line {numbers[int(m.group(1)) - 1]}" if m else "a data line"
        raise InputError(f"{path}: {where}: wrong number of fields ({exc})") from None
    width = len(names) if names is not None else table.shape[1]
    if table.shape[1] != width:
        counts = [len(_split(line, delim)) for line in lines]
        bad = next((i for i, c in enumerate(counts) if c != width), 0)
        raise InputError(f"{path}: line {numbers[bad]}: {counts[bad]} fields, the header has {width}")
    columns = []
    for j in range(table.shape[1]):
        col = table.iloc[:, j]
        label = f"column '{names[j]}'" if names else f"column {j} (0-based)"
        values = pd.to_numeric(col, errors="coerce") if col.dtype.kind not in "fiu" else col
        bad = values.isna() & col.notna()
        if col.dtype.kind == "b" or bad.any():
            i = int(np.argmax(bad.to_numpy())) if bad.any() else 0
            raise InputError(f"{path}: line {numbers[i]}, {label}: {str(col.iloc[i])!r} is not a number")
        columns.append(values.to_numpy(dtype=float))
    keys = names if names is not None else [str(j) for j in range(len(columns))]

    def get(spec: ColumnSpec):
        c = spec.column
        if isinstance(c, int):
            if c >= len(columns):
                raise InputError(f"{path}: column index {c} (for '{spec.name}') but the file has {len(columns)} columns")
            return columns[c], None
        if c not in keys:
            raise InputError(
                f"{path}: no column '{c}' (for '{spec.name}'){_suggest(c, keys)}; header has: {', '.join(keys)}"
            )
        return columns[keys.index(c)], None

    return _Source(keys, get, lambda i: f"line {numbers[i]}")


def _read_mat(path: Path, cmap: ColumnMap | None) -> _Source:
    import scipy.io

    try:
        raw = scipy.io.loadmat(str(path), simplify_cells=True)
    except NotImplementedError:
        raise InputError(f"{path}: MATLAB v7.3 (HDF5) files are not supported; save with -v7 (save(..., '-v7'))") from None
    except Exception as exc:  # scipy raises ValueError/TypeError/... on a non-MAT file
        raise InputError(f"{path}: not a readable MATLAB .mat file ({exc.__class__.__name__}: {exc})") from None
    variables = {k: v for k, v in raw.items() if not k.startswith("__")}
    names = _mat_default_names(variables)

    def find(column: str):
        obj = variables
        for part in column.split("."):
            if isinstance(obj, dict) and part in obj:
                obj = obj[part]
            else:
                hit = _dspace_signal(variables, column)
                if hit is None:
                    avail = _mat_paths(variables)
                    raise InputError(
                        f"{path}: no variable, struct field or dSPACE signal '{column}'{_suggest(column, avail)}; "
                        f"found: {', '.join(avail[:20])}"
                    )
                return hit
        return obj

    def get(spec: ColumnSpec):
        if isinstance(spec.column, int):
            raise InputError(f"{path}: '{spec.name}': MATLAB columns are named by variable (e.g. column = \"x_mm\")")
        obj = find(spec.column)
        arr = np.asarray(obj)
        if arr.dtype.kind not in "fiub":
            raise InputError(f"{path}: variable '{spec.column}' (for '{spec.name}') is not numeric ({arr.dtype})")
        arr = arr.astype(float)
        if arr.ndim == 2 and spec.index is not None:
            if arr.shape[0] < arr.shape[1]:
                arr = arr.T  # samples along the longer axis
            if spec.index >= arr.shape[1]:
                raise InputError(f"{path}: '{spec.column}' has {arr.shape[1]} columns, index {spec.index} asked")
            arr = arr[:, spec.index]
        elif arr.ndim == 2 and 1 in arr.shape:
            arr = arr.ravel()
        if arr.ndim != 1:
            raise InputError(
                f"{path}: variable '{spec.column}' (for '{spec.name}') has shape {arr.shape}; "
                f"give index = N in the column map to take one column"
            )
        return arr, None

    return _Source(names, get, lambda i: f"sample {i + 1}")


def _mat_default_names(variables: dict) -> list[str]:
    """Canonical names found as top-level variables, else as fields of the only struct."""
    top = [k for k in variables if k in CANONICAL_UNITS and np.asarray(variables[k]).dtype.kind in "fiu"]
    if top:
        return top
    structs = [k for k, v in variables.items() if isinstance(v, dict)]
    if len(structs) == 1:
        s = variables[structs[0]]
        return [f"{structs[0]}.{k}" for k in s if k in CANONICAL_UNITS]
    return []


def _mat_paths(obj, prefix="") -> list[str]:
    out = []
    if isinstance(obj, dict):
        for k, v in obj.items():
            p = f"{prefix}.{k}" if prefix else k
            out.extend(_mat_paths(v, p) if isinstance(v, dict) else [p])
    return out


def _dspace_signal(obj, column: str):
    """dSPACE ControlDesk export: ``rec.Y(i).Name`` matches ``column`` (or ends in ``/column``)."""
    if isinstance(obj, dict):
        for v in obj.values():
            hit = _dspace_signal(v, column)
            if hit is not None:
                return hit
    elif isinstance(obj, (list, np.ndarray)) and len(obj) and all(isinstance(e, dict) for e in obj):
        for e in obj:
            name = str(e.get("Name", ""))
            if "Data" in e and (name == column or name.rstrip('"').endswith(("/" + column, '"' + column))):
                return e["Data"]
    return None


def _read_comtrade(path: Path, cmap: ColumnMap | None) -> _Source:
    import comtrade

    cfg = path if path.suffix.lower() == ".cfg" else _partner(path, ".cfg")
    dat = _partner(path, ".dat") if cfg is not None else None
    if cfg is None or dat is None:
        raise InputError(f"{path}: a COMTRADE recording needs both NAME.cfg and NAME.dat beside each other")
    rec = comtrade.Comtrade(ignore_warnings=True)
    try:
        rec.load(str(cfg), str(dat))
        time = np.asarray(rec.time, dtype=float)
        channels = [np.asarray(a, dtype=float) for a in rec.analog]
    except Exception as exc:  # the comtrade package raises bare Exceptions on bad files
        raise InputError(f"{cfg}: not a readable COMTRADE pair ({exc.__class__.__name__}: {exc})") from None
    ids = [str(n).strip() for n in rec.analog_channel_ids]
    units = [str(ch.uu).strip() or None for ch in rec.cfg.analog_channels]

    def get(spec: ColumnSpec):
        c = spec.column
        if isinstance(c, int):
            if c >= len(ids):
                raise InputError(f"{cfg}: analog channel index {c} (for '{spec.name}') but there are {len(ids)}")
            return channels[c], units[c]
        if c not in ids:
            raise InputError(f"{cfg}: no analog channel '{c}' (for '{spec.name}'){_suggest(c, ids)}; channels: {', '.join(ids)}")
        return channels[ids.index(c)], units[ids.index(c)]

    extra = {"station_name": str(rec.station_name).strip(), "recording_device": str(rec.rec_dev_id).strip()}
    if rec.start_timestamp is not None:
        extra["start_timestamp"] = rec.start_timestamp.isoformat()
    return _Source(ids, get, lambda i: f"sample {i + 1}", time=time, extra=extra)


def _read_parquet(path: Path, cmap: ColumnMap | None) -> _Source:
    try:
        table = pd.read_parquet(path)
    except Exception as exc:  # pyarrow raises ArrowInvalid etc.
        raise InputError(f"{path}: not a readable Parquet file ({exc.__class__.__name__}: {exc})") from None
    names = [str(c) for c in table.columns]

    def get(spec: ColumnSpec):
        c = spec.column
        if isinstance(c, int):
            if c >= len(names):
                raise InputError(f"{path}: column index {c} (for '{spec.name}') but the table has {len(names)} columns")
            c = names[c]
        if c not in names:
            raise InputError(f"{path}: no column '{c}' (for '{spec.name}'){_suggest(c, names)}; columns: {', '.join(names)}")
        col = table.iloc[:, names.index(c)]
        values = pd.to_numeric(col, errors="coerce") if col.dtype.kind not in "fiu" else col
        bad = values.isna() & col.notna()
        if col.dtype.kind == "b" or bad.any():
            i = int(np.argmax(bad.to_numpy())) if bad.any() else 0
            raise InputError(f"{path}: row {i + 1}, column '{c}': {str(col.iloc[i])!r} is not a number")
        return values.to_numpy(dtype=float), None

    return _Source(names, get, lambda i: f"row {i + 1}")


# ----------------------------------------------------------------------------- mapping
def _specs(path: Path, src: _Source, cmap: ColumnMap | None) -> list[ColumnSpec]:
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


def _build_frame(path: Path, src: _Source, specs: list[ColumnSpec], cmap: ColumnMap | None):
    data, described = {}, {}
    if src.time is not None:
        data["time"] = src.time
        described["time"] = "file time axis [s]"
    for spec in specs:
        raw, file_unit = src.get(spec)
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
        if spec.name in data:
            raise InputError(f"{path}: two columns map to '{spec.name}'")
        data[spec.name] = np.asarray(values, dtype=float)
        kind = f" {spec.kind}" if spec.kind else ""
        described[spec.name] = f"{spec.column} [{unit or spec.si_unit or '-'}{kind}]"
    lengths = {k: len(v) for k, v in data.items()}
    if len(set(lengths.values())) > 1:
        raise InputError(f"{path}: columns have different lengths: {lengths}")
    order = [c for c in _CANONICAL_ORDER if c in data] + [c for c in data if c not in _CANONICAL_ORDER]
    return pd.DataFrame({c: data[c] for c in order}), described


# ----------------------------------------------------------------------------- validation
def _check_required(path: Path, frame: pd.DataFrame, required, src: _Source, cmap: ColumnMap | None) -> None:
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


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate(([idx[0]], idx[breaks + 1]))
    ends = np.concatenate((idx[breaks], [idx[-1]]))
    return list(zip(starts.tolist(), ends.tolist()))


def _check_finite(path: Path, frame: pd.DataFrame, row) -> None:
    problems = []
    for name in frame.columns:
        runs = _runs(~np.isfinite(frame[name].to_numpy()))
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
            f"{path}: {row(i)}: time not strictly increasing (t = {time[i]!r} s after {time[i - 1]!r} s at {row(i - 1)})"
        )


# ----------------------------------------------------------------------------- metadata
def sidecar_path(path) -> Path:
    """The sidecar of a recording: ``X.csv`` / ``X.csv.gz`` / ``X.mat`` / ``X.cfg`` -> ``X.toml``."""
    path = Path(path)
    name = path.name[:-3] if path.name.lower().endswith(".gz") else path.name
    return path.with_name(Path(name).stem + ".toml")


def _sidecar(path: Path) -> dict:
    side = sidecar_path(path)
    if not side.is_file():
        return {}
    try:
        data = tomllib.loads(side.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{side}: sidecar is not valid TOML ({exc})") from None
    return si_metadata(data, str(side))


def si_metadata(data, where: str):
    """Convert quantity strings in a metadata tree to SI floats.

    ``"8 bar abs"`` -> 800000.0, ``"25.7 mm"`` -> 0.0257, ``"20 degC"`` -> 293.15; numbers are
    taken as SI already (recording-format.md); other strings are kept. A pressure string
    without ``abs`` / ``gauge`` is an ``InputError``.
    """
    if isinstance(data, dict):
        return {k: (v if k in _TEXT_KEYS else si_metadata(v, f"{where}: {k}")) for k, v in data.items()}
    if isinstance(data, list):
        return [si_metadata(v, f"{where}[{i}]") for i, v in enumerate(data)]
    if isinstance(data, bool) or not isinstance(data, str) or not _NUMBER_WITH_UNIT.match(data):
        return data
    ureg = registry()
    whole = _quantity(ureg, data)
    stripped = _PRESSURE_WORD.sub("", data)
    bare = _quantity(ureg, stripped) if stripped != data else None
    pressure = ureg.Pa.dimensionality
    if any(q is not None and q.dimensionality == pressure for q in (whole, bare)):
        return parse_quantity(data, "Pa", where, pressure=True)
    if whole is None:
        return data
    try:
        return float(whole.to_base_units().magnitude)
    except Exception:  # e.g. an offset unit pint cannot bring to base: keep the text
        return data


def _quantity(ureg, text: str):
    try:
        q = ureg.Quantity(text)
        q.dimensionality  # noqa: B018 - plain numbers have it too
    except Exception:  # pint raises many types; all mean "not a quantity"
        return None
    return q
