"""Recording metadata: the ``NAME.toml`` sidecar beside a recording, with quantities in SI.

A sidecar (recording-format.md, "Sidecar metadata") says which plant a recording was taken
on and under which conditions; quantity strings in it (and in a column map's ``[metadata]``)
become SI floats, pressures absolute.
"""

from __future__ import annotations

import re
from compliance.model.toml_file import read_toml
from pathlib import Path

from compliance.recordings.sidecar_schema import check_sidecar, check_test_table
from compliance.recordings.instruments import instrument_facts
from compliance.units import parse_quantity, registry

__all__ = ["read_sidecar", "si_metadata", "sidecar_path"]

_NUMBER_WITH_UNIT = re.compile(r"^\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*[^\d\s.,:;/\-+]")
_PRESSURE_WORD = re.compile(r"\s+\(?(abs|absolute|a|gauge|g)\)?\s*$", re.IGNORECASE)
_TEXT_KEYS = ("description", "plant", "name", "notes", "source", "licence", "license")


def sidecar_path(path) -> Path:
    """The sidecar of a recording: ``X.csv`` / ``X.csv.gz`` / ``X.mat`` / ``X.cfg`` -> ``X.toml``.

    A recording reached through a symbolic link with no sidecar beside the link has the one
    beside its target (a shared data folder linked into a project).
    """
    path = Path(path)
    side = _beside(path)
    if not side.exists() and path.is_symlink():
        target = _beside(path.resolve())
        if target.is_file():
            return target
    return side


def _beside(path: Path) -> Path:
    name = path.name[:-3] if path.name.lower().endswith(".gz") else path.name
    return path.with_name(Path(name).stem + ".toml")


def read_sidecar(path) -> dict:
    """Metadata of the sidecar beside recording ``path`` (SI floats), or ``{}`` when there is none.

    Raises
    ------
    InputError
        The sidecar is not valid TOML, holds a pressure without ``abs`` / ``gauge``, a
        ``[logger]`` / ``[channels.NAME]`` table that ``instruments.instrument_facts`` rejects, or a
        ``[test]`` table that ``sidecar_schema.check_test_table`` rejects.
    """
    side = sidecar_path(path)
    if not side.is_file():
        return {}
    data, _ = read_toml(side, "recording sidecar")
    check_sidecar(data, str(side))
    if "test" in data:
        check_test_table(data["test"], str(side))
    return si_metadata(instrument_facts(data, str(side)), str(side))


def si_metadata(data, where: str):
    """Convert quantity strings in a metadata tree to SI floats.

    ``"8 bar abs"`` -> 800000.0, ``"25.7 mm"`` -> 0.0257, ``"20 degC"`` -> 293.15; numbers are
    taken as SI already (recording-format.md); other strings are kept. A pressure string
    without ``abs`` / ``gauge`` is an ``InputError``.
    """
    if isinstance(data, dict):
        return {k: (v if k in _TEXT_KEYS else si_metadata(v, f"{where}: {k}")) for k, v in data.items()}
    if isinstance(data, list):
        return [si_metadata(v, f"{where}[{i}]") for i, v in enumerate(data)]
    if isinstance(data, bool) or not isinstance(data, str) or not _NUMBER_WITH_UNIT.match(data):
        return data
    ureg = registry()
    whole = _quantity(ureg, data)
    stripped = _PRESSURE_WORD.sub("", data)
    bare = _quantity(ureg, stripped) if stripped != data else None
    pressure = ureg.Pa.dimensionality
    if any(q is not None and q.dimensionality == pressure for q in (whole, bare)):
        return parse_quantity(data, "Pa", where, pressure=True)
    if whole is None:
        return data
    try:
        return float(whole.to_base_units().magnitude)
    except Exception:  # e.g. an offset unit pint cannot bring to base: keep the text
        return data


def _quantity(ureg, text: str):
    try:
        q = ureg.Quantity(text)
        q.dimensionality  # noqa: B018 - plain numbers have it too
    except Exception:  # pint raises many types; all mean "not a quantity"
        return None
    return q
