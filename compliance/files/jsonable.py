"""The one JSON cleaner: numpy scalars/arrays to Python, non-finite floats to null, keys to text.

Every JSON writer of govcheck goes through :func:`json_text` (or :func:`jsonable` first), so
a NaN never reaches a file as the non-standard ``NaN`` token and numpy types never make
``json.dumps`` fail after the work is done.
"""

from __future__ import annotations

import dataclasses
import gzip
import json
import math
import zlib
from pathlib import Path, PurePath

import numpy as np

from compliance.errors import InputError

__all__ = ["json_number", "json_text", "jsonable", "read_json"]


def jsonable(obj):
    """Plain-Python copy of ``obj`` fit for strict JSON.

    numpy scalars and arrays become ``int`` / ``float`` / ``bool`` / lists, non-finite floats
    become ``None``, tuples become lists, mapping keys become text, paths become text and
    dataclasses become dicts. Other objects are returned unchanged (``json.dumps`` then names
    what it cannot write).
    """
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        return f if math.isfinite(f) else None
    if isinstance(obj, PurePath):
        return str(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return jsonable(dataclasses.asdict(obj))
    return obj


def json_number(value) -> float | None:
    """One number for JSON: a finite float, or None (for None, NaN and infinities)."""
    if value is None:
        return None
    f = float(value)
    return f if math.isfinite(f) else None


def json_text(data, *, indent: int | None = 1, compact: bool = False) -> str:
    """Strict JSON text of ``data`` (cleaned by :func:`jsonable`), ending in a newline.

    Parameters
    ----------
    data : object
        A results tree.
    indent : int or None
        Indentation for people; ignored when ``compact``.
    compact : bool
        No spaces at all (results files whose traces make up most of the bytes).
    """
    clean = jsonable(data)
    if compact:
        return json.dumps(clean, separators=(",", ":"), allow_nan=False) + "\n"
    return json.dumps(clean, indent=indent, allow_nan=False) + "\n"


def read_json(path, what: str) -> dict:
    """Read a JSON object from ``path``; InputError naming the file otherwise."""
    p = Path(path)
    try:
        raw = p.read_bytes()
        if p.suffix == ".gz":  # a results file stored compressed (a sweep's best candidate, with its traces)
            raw = gzip.decompress(raw)
        data = json.loads(raw.decode("utf-8"))
    except FileNotFoundError:
        raise InputError(f"{p}: {what} file not found") from None
    except IsADirectoryError:
        raise InputError(f"{p}: is a folder; expected a {what} JSON file") from None
    except (UnicodeDecodeError, json.JSONDecodeError, gzip.BadGzipFile, EOFError, zlib.error) as exc:
        raise InputError(f"{p}: not a JSON {what} file ({exc})") from None
    if not isinstance(data, dict):
        raise InputError(f"{p}: expected a JSON object ({what}), got {type(data).__name__}")
    return data
