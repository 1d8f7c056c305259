"""MATLAB / dSPACE ``.mat`` recordings (``scipy.io.loadmat``, MAT v4 to v7).

Columns are named by variable: a plain variable (``x_mm``), a struct field
(``rec.position``) or a dSPACE ControlDesk signal (``rec.Y(i).Name`` / ``rec.Y(i).Data``).
Without a column map, canonical names are taken as top-level variables or as the fields
of the one struct that holds them; two such structs, or a canonical name holding text, are
refused by name (a column map picks one: ``time = { column = "run1.time", unit = "s" }``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from compliance.errors import did_you_mean
from compliance.recordings.column_map import CANONICAL_UNITS, ColumnMap, ColumnSpec
from compliance.errors import InputError
from compliance.recordings.columns import RecordingSource

__all__ = ["read_mat"]


def read_mat(path: Path, cmap: ColumnMap | None) -> RecordingSource:
    """Read a ``.mat`` export into raw float columns (see the module docstring).

    Raises
    ------
    InputError
        MATLAB v7.3 (HDF5), not a MAT file, an unknown or non-numeric variable, a 2-D
        variable without ``index``.
    """
    import scipy.io

    try:
        raw = scipy.io.loadmat(str(path), simplify_cells=True)
    except NotImplementedError:
        raise InputError(f"{path}: MATLAB v7.3 (HDF5) files are not supported; save with -v7 (save(..., '-v7'))") from None
    except Exception as exc:  # scipy raises ValueError/TypeError/... on a non-MAT file
        raise InputError(f"{path}: not a readable MATLAB .mat file ({exc.__class__.__name__}: {exc})") from None
    variables = {k: v for k, v in raw.items() if not k.startswith("__")}
    names = _mat_default_names(path, variables, strict=cmap is None)

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
                        f"{path}: no variable, struct field or dSPACE signal '{column}'{did_you_mean(column, avail)}; "
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
            raise InputError(f"{path}: variable '{spec.column}' (for '{spec.name}') {_not_numbers(obj)}")
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

    return RecordingSource(names, get, lambda i: f"sample {i + 1}")


def _mat_default_names(path: Path, variables: dict, strict: bool) -> list[str]:
    """Canonical names found as top-level variables, else as fields of the one struct holding them.

    With ``strict`` (no column map) a canonical name that holds no numbers, or two structs
    that both hold canonical fields, raise :class:`InputError` naming them.
    """
    top = [k for k in variables if k in CANONICAL_UNITS]
    structs = {k: [f for f in v if f in CANONICAL_UNITS] for k, v in variables.items() if isinstance(v, dict)}
    structs = {k: fields for k, fields in structs.items() if fields}
    if strict:
        _refuse_text(path, {k: variables[k] for k in top} if top else
                     {f"{s}.{f}": variables[s][f] for s, fields in structs.items() for f in fields})
    if top:
        return [k for k in top if _numeric(variables[k])]
    if len(structs) > 1 and strict:
        first = next(iter(structs))
        raise InputError(
            f"{path}: {len(structs)} structs hold recording fields ({', '.join(repr(k) for k in structs)}); "
            f"expected one recording per file: save one struct per file, or pick one with a column map "
            f"(--column-map), e.g. time = {{ column = \"{first}.time\", unit = \"s\" }}"
        )
    if len(structs) == 1:
        name, fields = next(iter(structs.items()))
        return [f"{name}.{f}" for f in fields]
    return []


def _numeric(value) -> bool:
    return np.asarray(value).dtype.kind in "fiu"


def _not_numbers(value) -> str:
    """Why a variable is no column: text (MATLAB char), a struct or cell, or another type."""
    arr = np.asarray(value)
    if arr.dtype.kind in "US":
        return f"is text ({str(arr.ravel()[0])[:30]!r}), not one number per sample"
    if isinstance(value, (dict, list)) or arr.dtype.kind == "O":
        return "is a struct or cell array, not one number per sample"
    return f"is not numeric ({arr.dtype}); expected one number per sample"


def _refuse_text(path: Path, candidates: dict) -> None:
    """A canonical variable that holds text or a struct (char variable in MATLAB) is named."""
    for name, value in candidates.items():
        if not _numeric(value) and np.asarray(value).dtype.kind != "b":
            raise InputError(
                f"{path}: variable '{name}' {_not_numbers(value)}; store the samples as a numeric "
                f"vector, or map another variable to it with a column map (--column-map)"
            )


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
