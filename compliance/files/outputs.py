"""Output paths checked before any work starts: folder exists, target writable, suffix right.

A command calls :func:`check_outputs` with every output it was asked for before it loads,
simulates or fits anything, so a run that would fail at the end fails at once and writes
nothing. Folders are never created: a misspelt folder is an error, the same for every command.
"""

from __future__ import annotations

import os
from pathlib import Path

from compliance.errors import InputError

__all__ = ["check_output", "check_outputs"]


def check_output(path, flag: str, suffixes: tuple[str, ...] | None = None) -> None:
    """Refuse an output path that cannot be written as asked.

    Parameters
    ----------
    path : str or pathlib.Path
        Where the file is to go.
    flag : str
        The option that named it (``--json``), for the message.
    suffixes : tuple of str, optional
        Accepted endings (lower case, with the dot), e.g. ``(".png", ".svg", ".pdf")``.

    Raises
    ------
    InputError
        A missing folder, a path that is a folder, a read-only file or folder, a wrong suffix.
    """
    p = Path(path)
    if not str(path).strip():
        raise InputError(f"{flag}: empty path; expected a file name")
    folder = p.parent if str(p.parent) else Path(".")
    if p.is_dir():
        example = Path(path) / ("results" + (suffixes[0] if suffixes else ".json"))
        raise InputError(f"{flag} {path}: is a folder; expected a file name (e.g. {example})")
    if suffixes:
        name = p.name.lower()
        if not any(name.endswith(s) for s in suffixes):
            raise InputError(f"{flag} {path}: expected a file ending in {', '.join(suffixes)}")
    if not folder.is_dir():
        raise InputError(f"{flag} {path}: folder '{folder}' does not exist (govcheck does not create folders)")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{flag} {path}: folder '{folder}' is not writable")
    if p.exists() and (not os.access(p, os.W_OK) or not p.stat().st_mode & 0o222):  # mode bits too: root may write anything
        raise InputError(f"{flag} {path}: the file exists and is read-only; govcheck does not replace it")


def check_outputs(*outputs, inputs: dict | None = None) -> None:
    """Check several ``(path, flag[, suffixes])`` outputs; ``None`` paths are skipped.

    Two options naming the same file are an error too (one would overwrite the other), and so
    is an output that is one of the run's ``inputs`` (``{path: what it is}``): a run never
    writes over what it reads (``reproduce plant.toml --calibrate plant.toml``).
    """
    seen: dict[Path, str] = {Path(p).resolve(): what for p, what in (inputs or {}).items()}
    own = set(seen)
    for item in outputs:
        path, flag = item[0], item[1]
        if path is None:
            continue
        check_output(path, flag, item[2] if len(item) > 2 else None)
        key = Path(path).resolve()
        if key in own:
            raise InputError(f"{flag} {path}: is an input of this run ({seen[key]}); govcheck never writes over its "
                             "inputs: give the output another name")
        if key in seen:
            raise InputError(f"{flag} {path}: the same file as {seen[key]}; give each output its own file")
        seen[key] = flag
