"""Delimited text recordings: the canonical CSV (also ``.csv.gz``) and any table a column map describes.

Comment and blank lines are skipped, a header line names the columns (or the map says
``header = false`` and columns are taken by index), every cell must be a number (or, in a time
column, a date and time). Errors name the file's own line numbers.

Files as spreadsheets and loggers export them are read as they are: a UTF-8 byte-order mark
(Excel's "CSV UTF-8") is dropped; the delimiter is taken from the header line (tab, ';' or ',';
``.tsv`` is tab) unless a column map names it; a ';' or tab file whose cells read ``1,25`` uses
the decimal comma (European locales).
"""

from __future__ import annotations

import gzip
import io
import re
from pathlib import Path

import pandas as pd

from compliance.recordings.column_map import ColumnMap, ColumnSpec
from compliance.errors import InputError
from compliance.recordings.columns import RecordingSource, column_position, numeric_column

__all__ = ["TEXT_SUFFIXES", "read_text_table"]

TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _split(line: str, delim: str | None) -> list[str]:
    return line.split() if delim is None else line.split(delim)


_DECIMAL_COMMA = re.compile(r"^\s*[-+]?\d+,\d+([eE][-+]?\d+)?\s*$")


def sniff_delimiter(first: str, path: Path, given: str | None) -> str | None:
    """The delimiter a map gave, else the one the first (header) line uses: tab, ';' or ','."""
    if given != "auto":
        return given
    if path.name.lower().removesuffix(".gz").endswith(".tsv") or "\t" in first:
        return "\t"
    return ";" if first.count(";") > first.count(",") else ","


def sniff_decimal(lines: list[str], delim: str | None, given: str) -> str:
    """``","`` when a ';' / tab / whitespace file writes its numbers as ``1,25`` (a European logger), else ``"."``."""
    if given != "auto":
        return given
    if delim == ",":
        return "."
    cells = [c for line in lines[:20] for c in _split(line, delim)]
    return "," if any(_DECIMAL_COMMA.match(c) for c in cells) else "."


def _no_data(path, text: str, skip: int, comment: str) -> None:
    """Why no data line is left: the column map's ``skip_rows`` took them (named), or the file has none."""
    total = len(text.splitlines())
    if skip and skip >= total:
        raise InputError(f"{path}: the column map's skip_rows = {skip} skips every line (the file has {total}); "
                         "skip only the lines above the header")
    if skip and any(line.strip() and not line.strip().startswith(comment) for line in text.splitlines()[:skip]):
        raise InputError(f"{path}: no data after the column map's skip_rows = {skip} (the file has {total} lines, the "
                         f"rest blank or '{comment}' comments); skip only the lines above the header")
    raise InputError(f"{path}: no data (only blank or '{comment}' comment lines)")


def read_text_table(path: Path, cmap: ColumnMap | None) -> RecordingSource:
    """Read a delimited text recording (see the module docstring) into raw float columns.

    Raises
    ------
    InputError
        Not UTF-8 text, no data, no header (or a bad one), a row with the wrong number of
        fields, a cell that is not a number.
    """
    try:
        if path.name.lower().endswith(".gz"):
            with gzip.open(path, "rt", encoding="utf-8-sig") as fh:
                text = fh.read()
        else:
            text = path.read_text(encoding="utf-8-sig")  # a BOM (Excel's "CSV UTF-8") is not a column name
    except (UnicodeDecodeError, OSError, EOFError) as exc:
        what = "gzip-compressed UTF-8 text (the file is cut short or not gzip)" if path.name.lower().endswith(".gz") else "UTF-8 text"
        raise InputError(f"{path}: cannot read as {what} ({exc.__class__.__name__}: {exc})") from None
    comment = cmap.comment if cmap else "#"
    skip = cmap.skip_rows if cmap else 0
    header = cmap.header if cmap else True
    numbers, lines, comments = [], [], []
    for no, line in enumerate(text.splitlines()[skip:], start=skip + 1):
        stripped = line.strip()
        if stripped and not stripped.startswith(comment):
            numbers.append(no)
            lines.append(line)
        elif stripped and not lines:
            comments.append(stripped[len(comment):].strip())  # the logger's own header lines (instruments.py)
    if not lines:
        _no_data(path, text, skip, comment)
    delim = sniff_delimiter(lines[0], path, cmap.delimiter if cmap else "auto")
    decimal = sniff_decimal(lines[1:] if header else lines, delim, cmap.decimal if cmap else "auto")
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
            decimal=decimal,
            skipinitialspace=True,
            engine="c",
        )
    except pd.errors.ParserError as exc:
        m = re.search(r"line (\d+), saw (\d+)", str(exc))
        where = f"line {numbers[int(m.group(1)) - 1]}" if m else "a data line"
        raise InputError(f"{path}: {where}: wrong number of fields ({' '.join(str(exc).split())})") from None
    width = len(names) if names is not None else table.shape[1]
    if table.shape[1] != width:
        counts = [len(_split(line, delim)) for line in lines]
        bad = next((i for i, c in enumerate(counts) if c != width), 0)
        raise InputError(f"{path}: line {numbers[bad]}: {counts[bad]} fields, the header has {width}")
    columns = []
    for j in range(table.shape[1]):
        col = table.iloc[:, j]
        label = f"column '{names[j]}'" if names else f"column {j} (0-based)"
        columns.append(numeric_column(col, lambda i, label=label: f"{path}: line {numbers[i]}, {label}"))
    keys = names if names is not None else [str(j) for j in range(len(columns))]
    too_few = f"the file has {len(columns)} columns"

    def get(spec: ColumnSpec):
        return columns[column_position(spec, keys, str(path), "column", too_few, "header has")], None

    return RecordingSource(keys, get, lambda i: f"line {numbers[i]}", extra={"comment_lines": comments} if comments else None)
