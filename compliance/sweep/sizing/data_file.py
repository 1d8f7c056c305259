"""A data file of the design stage (catalogue, duty) read and validated at the edge: one message, exit 2."""

from __future__ import annotations

from pathlib import Path

from pydantic import ValidationError

from compliance.errors import InputError
from compliance.model.toml_file import read_toml

__all__ = ["read_validated"]


def read_validated(path: Path, model, schema: str, what: str):
    """Parse ``path`` with the pydantic ``model``; its ``schema_`` field must be ``schema``.

    Raises
    ------
    InputError
        Missing file, malformed TOML, a field the model refuses, or another schema (naming file and field).
    """
    if path.is_dir():
        raise InputError(f"{path}: is a folder; expected a {what} (TOML file)")
    if not path.is_file():
        raise InputError(f"{path}: {what} not found")
    data, _ = read_toml(path, what)  # a requirement file or a plant given here is named as such
    try:
        raw = model.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        raise InputError(f"{path}: {'.'.join(str(p) for p in err['loc'])}: {err['msg']}") from None
    if raw.schema_ != schema:
        raise InputError(f"{path}: schema: expected \"{schema}\", got {raw.schema_!r}")
    return raw
