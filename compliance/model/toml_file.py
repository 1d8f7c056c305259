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


# file kind -> how to recognise it from its parsed top level (for "this is a requirement file, not a plant")
FILE_KINDS = {
    "requirement file": lambda d: str(d.get("schema", "")).startswith("govcheck-requirements"),
    "sweep file": lambda d: str(d.get("schema", "")).startswith("govcheck-sweep"),
    "hardware catalogue": lambda d: str(d.get("schema", "")).startswith("govcheck-hardware"),
    "duty file": lambda d: str(d.get("schema", "")).startswith("govcheck-duty"),
    "plant configuration": lambda d: isinstance(d.get("cylinder"), dict) and isinstance(d.get("name"), str),
    "column map": lambda d: isinstance(d.get("columns"), dict),
    "recording sidecar": lambda d: isinstance(d.get("conditions"), dict) or (
        isinstance(d.get("plant"), str) and "cylinder" not in d and "schema" not in d),
    "validation settings file": lambda d: bool({"replay", "locate", "limits", "windows", "overlays"} & set(d))
    and not ({"cylinder", "schema", "columns", "conditions"} & set(d)),
}


def file_kind(data: Any) -> str | None:
    """What kind of govcheck file a parsed TOML mapping looks like (a key of ``FILE_KINDS``), or None."""
    if not isinstance(data, dict):
        return None
    return next((kind for kind, looks in FILE_KINDS.items() if looks(data)), None)


def toml_text(raw: bytes, path) -> dict[str, Any]:
    """Parse TOML bytes as exported by any editor: UTF-8 with or without a byte-order mark (Excel, Notepad).

    Raises
    ------
    InputError
        Bytes that are not UTF-8, or malformed TOML (naming the file).
    """
    try:
        text = raw.decode("utf-8-sig")  # a leading BOM is an encoding mark, not content
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: malformed TOML ({exc})") from None


def read_toml(path: Path, kind: str | None = None) -> tuple[dict[str, Any], str]:
    """Parse a TOML file (BOM tolerated); with ``kind``, refuse a file that is plainly another kind.

    Returns
    -------
    tuple
        (the parsed mapping, sha256 hex digest of the file's bytes).

    Raises
    ------
    InputError
        Unreadable file, bytes that are not UTF-8, malformed TOML, or a file of another kind
        (a requirement file given where a plant configuration is expected), naming the file.
    """
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    data = toml_text(raw, path)
    check_kind(data, path, kind)
    return data, hashlib.sha256(raw).hexdigest()


def check_kind(data: Any, path, kind: str | None) -> None:
    """Refuse a parsed file that is recognisably another kind than ``kind`` (a key of ``FILE_KINDS``)."""
    seen = file_kind(data)
    if kind is not None and seen is not None and seen != kind:
        raise InputError(f"{path}: this is a {seen}, not a {kind}; check the order and the names of the arguments")


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
