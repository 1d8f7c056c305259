"""Column maps: how a logger's columns, units and layout become the canonical recording.

A column map is a TOML file (or the equivalent dict) such as::

    description = "Zillen friction bench, whitespace separated, no header"
    delimiter = "whitespace"        # "auto" (default: sniffed), ",", ";", "tab", "whitespace"
    decimal = "."                   # "auto" (default: "," when cells read 1,25 in a ; or tab file), ".", ","
    header = false                  # then columns are 0-based indexes
    skip_rows = 0                   # raw lines skipped before the header / data
    drop_first = 15                 # data rows dropped after reading (settling samples)
    time_unit = "ms"                # shortcut for columns.time.unit

    [columns]
    time = { column = 0 }
    position = { column = 4, unit = "mm" }
    pressure_a = { column = 5, unit = "bar", kind = "gauge" }
    force = { column = 6, unit = "N" }

    [metadata]                      # bench facts shared by every file of this logger
    bore = "25.7 mm"

Each ``[columns]`` entry maps a canonical name to ``column`` (a header name, a MATLAB
variable or dotted struct path, a COMTRADE channel name, or a 0-based index), ``unit``
(any unit pint knows), ``kind = "abs" | "gauge"`` (required for pressures), and optionally
``gain`` / ``offset`` (raw -> unit: ``value = gain * raw + offset``), ``index`` (column of a
2-D MATLAB matrix) and ``si_unit`` (for a name govcheck does not know).

Reference maps shipped with govcheck live in ``compliance/data/column_maps/`` and are
selected by name (``"zillen-friction"``).
"""

from __future__ import annotations

from compliance.model.toml_file import read_toml
from dataclasses import dataclass, field
from types import MappingProxyType

from compliance.errors import did_you_mean
from compliance.errors import InputError
from compliance.files.shipped import resolve_shipped

# canonical column -> SI unit ("Pa" columns are absolute pressures); recording-format.md
CANONICAL_UNITS = MappingProxyType(
    {
        "time": "s",
        "position": "m",
        "reference": "m",
        "valve_command": "V",
        "pressure_a": "Pa",
        "pressure_b": "Pa",
        "supply_pressure": "Pa",
        "exhaust_pressure": "Pa",
        "force": "N",
        "load_force": "N",
        "friction_force": "N",
        "velocity": "m/s",
        "position_true": "m",
        "temperature": "K",
        "temperature_a": "K",
        "temperature_b": "K",
        "supply_temperature": "K",
        "flow_a": "kg/s",
        "flow_b": "kg/s",
        "opening": "",
        "command_demand": "V",
    }
)

_DELIMITERS = {"auto": "auto", ",": ",", ";": ";", "tab": "\t", "\t": "\t", "whitespace": None, " ": None}
_DECIMALS = ("auto", ".", ",")
_TOP_KEYS = (
    "description",
    "format",
    "delimiter",
    "decimal",
    "header",
    "skip_rows",
    "drop_first",
    "time_unit",
    "comment",
    "columns",
    "metadata",
)
_ENTRY_KEYS = ("column", "unit", "kind", "gain", "offset", "index", "si_unit")
_FORMATS = ("csv", "mat", "comtrade", "parquet")


def is_pressure(name: str) -> bool:
    """True if canonical column ``name`` is a pressure (stored in Pa absolute)."""
    return CANONICAL_UNITS.get(name) == "Pa" or name.startswith("pressure") or name.endswith("_pressure")


@dataclass(frozen=True)
class ColumnSpec:
    """Where one canonical column comes from and how to convert it to SI."""

    name: str
    column: str | int
    unit: str | None = None
    kind: str | None = None
    gain: float = 1.0
    offset: float = 0.0
    index: int | None = None
    si_unit: str = ""


@dataclass(frozen=True)
class ColumnMap:
    """A validated column map (see the module docstring for the file layout)."""

    source: str
    columns: tuple[ColumnSpec, ...]
    delimiter: str | None = "auto"  # "auto": sniffed from the header line (recordings/delimited.py)
    decimal: str = "auto"
    header: bool = True
    skip_rows: int = 0
    drop_first: int = 0
    comment: str = "#"
    format: str | None = None
    description: str = ""
    metadata: dict = field(default_factory=dict)

    def spec(self, name: str) -> ColumnSpec | None:
        """The entry for canonical column ``name``, or None."""
        for s in self.columns:
            if s.name == name:
                return s
        return None




def load_column_map(source) -> ColumnMap:
    """Load and validate a column map.

    Parameters
    ----------
    source : str or pathlib.Path or dict or ColumnMap
        A TOML file, the name of a shipped map (``"zillen-friction"``), a dict with the
        same layout, or an already loaded map.

    Returns
    -------
    ColumnMap

    Raises
    ------
    InputError
        Unknown keys, a pressure without ``kind``, a column that is neither a name nor an
        index, an unreadable file.
    """
    if isinstance(source, ColumnMap):
        return source
    if isinstance(source, dict):
        return _from_dict(source, "column map (dict)")
    path = resolve_shipped(source, "column_map", where="column map")
    data, _ = read_toml(path, "column map")
    return _from_dict(data, str(path))


def _int_option(data, key, where, default):
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InputError(f"{where}: '{key}' must be a whole number >= 0, got {value!r}")
    return value


def _from_dict(data: dict, where: str) -> ColumnMap:
    for key in data:
        if key not in _TOP_KEYS:
            raise InputError(f"{where}: unknown key '{key}'{did_you_mean(key, _TOP_KEYS)} (known: {', '.join(_TOP_KEYS)})")
    delim_text = data.get("delimiter", "auto")
    if delim_text not in _DELIMITERS:
        raise InputError(
            f"{where}: delimiter {delim_text!r} not known; use one of 'auto', ',', ';', 'tab', 'whitespace'"
        )
    decimal = data.get("decimal", "auto")
    if decimal not in _DECIMALS:
        raise InputError(f"{where}: decimal {decimal!r} not known; use one of 'auto', '.', ','")
    header = data.get("header", True)
    if not isinstance(header, bool):
        raise InputError(f"{where}: 'header' must be true or false, got {header!r}")
    fmt = data.get("format")
    if fmt is not None and fmt not in _FORMATS:
        raise InputError(f"{where}: format {fmt!r} not known{did_you_mean(fmt, _FORMATS)} (known: {', '.join(_FORMATS)})")
    comment = data.get("comment", "#")
    if not isinstance(comment, str) or len(comment) != 1:
        raise InputError(f"{where}: 'comment' must be one character, got {comment!r}")
    metadata = data.get("metadata", {})
    if not isinstance(metadata, dict):
        raise InputError(f"{where}: [metadata] must be a table")
    from compliance.recordings.sidecar_schema import check_sidecar

    check_sidecar(metadata, where, keys="metadata")  # the same keys as a sidecar: they end in the same metadata
    cols = data.get("columns")
    if not isinstance(cols, dict) or not cols:
        raise InputError(f"{where}: needs a [columns] table mapping canonical names to {{column = ..., unit = ...}}")
    time_unit = data.get("time_unit")
    specs = []
    for name, entry in cols.items():
        specs.append(_spec(name, entry, f"{where}: columns.{name}", header, time_unit))
    return ColumnMap(
        source=where,
        columns=tuple(specs),
        delimiter=_DELIMITERS[delim_text],
        decimal=decimal,
        header=header,
        skip_rows=_int_option(data, "skip_rows", where, 0),
        drop_first=_int_option(data, "drop_first", where, 0),
        comment=comment,
        format=fmt,
        description=str(data.get("description", "")),
        metadata=dict(metadata),
    )


def _spec(name: str, entry, where: str, header: bool, time_unit) -> ColumnSpec:
    if isinstance(entry, (str, int)) and not isinstance(entry, bool):
        entry = {"column": entry}
    if not isinstance(entry, dict):
        raise InputError(f"{where}: expected a table such as {{column = \"x_mm\", unit = \"mm\"}}")
    for key in entry:
        if key not in _ENTRY_KEYS:
            raise InputError(f"{where}: unknown key '{key}'{did_you_mean(key, _ENTRY_KEYS)} (known: {', '.join(_ENTRY_KEYS)})")
    if "column" not in entry:
        raise InputError(f"{where}: missing 'column' (a column name or a 0-based index)")
    column = entry["column"]
    if isinstance(column, bool) or not isinstance(column, (str, int)) or (isinstance(column, int) and column < 0):
        raise InputError(f"{where}: 'column' must be a name or a 0-based index, got {column!r}")
    if not header and isinstance(column, str):
        raise InputError(f"{where}: the map says header = false, so 'column' must be a 0-based index, got {column!r}")
    si_unit = entry.get("si_unit", CANONICAL_UNITS.get(name))
    if si_unit is None:
        if is_pressure(name):
            si_unit = "Pa"
        else:
            raise InputError(
                f"{where}: '{name}' is not a canonical column{did_you_mean(name, CANONICAL_UNITS)}; "
                f"known: {', '.join(CANONICAL_UNITS)} (or give si_unit = \"...\" for your own column)"
            )
    unit = entry.get("unit")
    if unit is None and name == "time" and time_unit is not None:
        unit = time_unit
    if unit is not None and not isinstance(unit, str):
        raise InputError(f"{where}: 'unit' must be a string such as \"mm\", got {unit!r}")
    kind = entry.get("kind")
    if is_pressure(name):
        if kind not in ("abs", "gauge"):
            raise InputError(f"{where}: pressure column needs kind = \"abs\" or \"gauge\", got {kind!r}")
    elif kind is not None:
        raise InputError(f"{where}: 'kind' applies to pressures only; '{name}' is not a pressure")
    numbers = {}
    for key, default in (("gain", 1.0), ("offset", 0.0)):
        value = entry.get(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"{where}: '{key}' must be a number, got {value!r}")
        numbers[key] = float(value)
    if numbers["gain"] == 0.0 or numbers["gain"] != numbers["gain"]:
        raise InputError(f"{where}: gain = {entry.get('gain')!r} would turn every sample into the offset; "
                         "expected the non-zero factor from the logger's raw value to the unit (value = gain * raw + offset)")
    index = entry.get("index")
    if index is not None and (isinstance(index, bool) or not isinstance(index, int) or index < 0):
        raise InputError(f"{where}: 'index' must be a 0-based column index of a matrix, got {index!r}")
    return ColumnSpec(name, column, unit, kind, numbers["gain"], numbers["offset"], index, si_unit)
