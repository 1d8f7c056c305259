"""MATLAB / dSPACE ``.mat`` recordings (``scipy.io.loadmat``, MAT v4 to v7).

Columns are named by variable: a plain variable (``x_mm``), a struct field
(``rec.position``) or a dSPACE ControlDesk signal (``rec.Y(i).Name`` / ``rec.Y(i).Data``).
Without a column map, canonical names are taken as top-level variables or as the fields
of the only struct.
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

    return RecordingSource(names, get, lambda i: f"sample {i + 1}")


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
