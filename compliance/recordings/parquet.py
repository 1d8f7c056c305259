"""Parquet recordings (pandas / pyarrow): one column per signal, named or taken by 0-based index."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from compliance.recordings.column_map import ColumnMap, ColumnSpec
from compliance.errors import InputError
from compliance.recordings.columns import RecordingSource, column_position, numeric_column

__all__ = ["read_parquet"]


def read_parquet(path: Path, cmap: ColumnMap | None) -> RecordingSource:
    """Read a Parquet table into raw float columns.

    Raises
    ------
    InputError
        Not a readable Parquet file, an unknown column, a cell that is not a number.
    """
    try:
        table = pd.read_parquet(path)
    except Exception as exc:  # pyarrow raises ArrowInvalid etc.
        raise InputError(f"{path}: not a readable Parquet file ({exc.__class__.__name__}: {exc})") from None
    names = [str(c) for c in table.columns]

    def get(spec: ColumnSpec):
        name = names[column_position(spec, names, str(path), "column", f"the table has {len(names)} columns", "columns")]
        col = table.iloc[:, names.index(name)]
        return numeric_column(col, lambda i: f"{path}: row {i + 1}, column '{name}'"), None

    return RecordingSource(names, get, lambda i: f"row {i + 1}")
