"""TOML at the edge: read a file into a mapping with its digest; check the keys of one table.

Every input file (plant configurations, requirement files, validation settings) is read and its
tables checked the same way, so a bad file always gets the same kind of message: the file, the
key path and what was expected.
"""

from __future__ import annotations

import hashlib
import tomllib
from pathlib import Path
from typing import Any, Iterable

from compliance.errors import InputError


def read_toml(path: Path) -> tuple[dict[str, Any], str]:
    """Parse a TOML file.

    Returns
    -------
    tuple
        (the parsed mapping, sha256 hex digest of the file's bytes).

    Raises
    ------
    InputError
        Unreadable file, bytes that are not UTF-8, or malformed TOML (naming the file).
    """
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: malformed TOML ({exc})") from None
    return data, hashlib.sha256(raw).hexdigest()


def check_table(table: Any, where: str, allowed: Iterable[str], *, word: str = "key", expected: str) -> dict:
    """Check that ``table`` is a TOML table whose keys are all in ``allowed``.

    Parameters
    ----------
    table : object
        The parsed value.
    where : str
        Its location (``"file: key.path"``), the start of every message.
    allowed : iterable of str
        Admissible keys, listed in the message for an unknown one.
    word : str
        What the file format calls a key ("key" or "field").
    expected : str
        What a non-table should have been ("a table with position and force").

    Returns
    -------
    dict
        ``table`` itself.
    """
    if not isinstance(table, dict):
        raise InputError(f"{where}: expected {expected}")
    allowed = list(allowed)
    unknown = set(table) - set(allowed)
    if unknown:
        raise InputError(f"{where}: unknown {word} '{sorted(unknown)[0]}' (expected {', '.join(allowed)})")
    return table
