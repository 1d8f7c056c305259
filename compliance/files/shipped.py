"""A file given by path or by the name of one shipped with govcheck: one rule for every kind.

``plant-a``, ``shpp-400kw``, ``jiang``, ``zillen-friction`` and ``default`` name files in
``compliance/data/`` so that ``--plant plant-a`` or ``extends = "iec61362"`` works after
``pip install``. Every loader resolves its argument here, with one precedence:

1. written as a path (ends with the kind's suffix, or holds a path separator): that file;
2. otherwise a shipped name: the shipped file;
3. otherwise an existing file of that name (a suffix-less file in the working folder);
4. otherwise an error naming what was looked for, the closest shipped name and the list.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from compliance.errors import InputError, did_you_mean


@dataclass(frozen=True)
class ShippedKind:
    """A kind of file govcheck ships: its folder under ``compliance/data``, suffix and name."""

    folder: str
    suffix: str
    label: str  # what a message calls one ("plant configuration")
    shipped_label: str  # what a message calls a shipped one ("reference plant")


KINDS = {
    "plant": ShippedKind("plants", ".toml", "plant configuration", "reference plant"),
    "requirements": ShippedKind("requirements", ".toml", "requirement file", "reference requirement file"),
    "path": ShippedKind("paths", ".csv", "path file", "shipped path"),
    "column_map": ShippedKind("column_maps", ".toml", "column map", "shipped map"),
    "hardware": ShippedKind("hardware", ".toml", "hardware catalogue", "shipped catalogue"),
}


def shipped_names(kind: str) -> list[str]:
    """Names of the files of ``kind`` shipped in ``compliance/data/`` (without suffix), sorted."""
    k = KINDS[kind]
    folder = resources.files("compliance") / "data" / k.folder
    try:
        return sorted(p.name[: -len(k.suffix)] for p in folder.iterdir() if p.name.endswith(k.suffix))
    except (FileNotFoundError, NotADirectoryError):
        return []


def shipped_file(kind: str, name: str) -> Path:
    """The shipped file ``name`` of ``kind`` (it need not exist: check with ``is_file``)."""
    k = KINDS[kind]
    return Path(str(resources.files("compliance") / "data" / k.folder / f"{name}{k.suffix}"))


def looks_like_path(text: str, kind: str) -> bool:
    """True when ``text`` is written as a path: the kind's suffix, or a path separator."""
    return text.lower().endswith(KINDS[kind].suffix) or "/" in text or os.sep in text


def resolve_shipped(source: str | os.PathLike, kind: str, *, relative_to: Path | None = None, where: str = "") -> Path:
    """The file meant by ``source``: a path, or the name of a file shipped with govcheck.

    Parameters
    ----------
    source : str or path-like
        What the user wrote.
    kind : {"plant", "requirements", "path", "column_map", "hardware"}
        Which shipped folder names are looked up in.
    relative_to : pathlib.Path, optional
        Folder a relative path is taken from (a file that names another, e.g. ``extends``).
    where : str
        Prefix of the error message (file and key that named ``source``); default ``source``.

    Raises
    ------
    InputError
        A path that is not a file, or a name that is neither shipped nor a file.
    """
    k = KINDS[kind]
    s = str(source)
    if looks_like_path(s, kind):
        p = Path(s)
        if relative_to is not None and not p.is_absolute():
            p = relative_to / p
        if not p.is_file():
            raise InputError(f"{where or s}: {k.label} '{s}' not found")
        return p
    ref = shipped_file(kind, s)
    if ref.is_file():
        return ref
    p = Path(s) if relative_to is None else relative_to / s
    if p.is_file():
        return p
    names = shipped_names(kind)
    raise InputError(f"{where or s}: '{s}' is neither a file nor a {k.shipped_label}{did_you_mean(s, names)} "
                     f"({k.shipped_label}s: {', '.join(names) or 'none'})")
