"""Requirement files: load TOML, follow ``extends``, validate with units, freeze.

A requirement file (``requirements/*.toml``, schema ``govcheck-requirements/1``) declares
operating points, test procedures and requirements, each a table keyed by its name or id.
A file may ``extends`` others (a reference name such as ``"iec61362"`` or a path relative
to the file); tables are merged key by key, the extending file winning. A limit may be
tightened freely; loosening it (or lowering the severity, or disabling a requirement) must
say ``allow_loosen = true`` and is reported. The format is described in docs/requirements.md.

This module finds, reads and merges the files; the rest lives beside it:
``schema`` (file structure), ``entries`` (each entry's meaning), ``requirement_set`` (the
frozen objects), ``compliance.units.amounts`` (``"1 %stroke"``) and ``tightening``
(:func:`check_tightening`). The TOML itself is read by ``compliance.model.toml_file``.
"""

from __future__ import annotations

import os
from pathlib import Path

from pydantic import BaseModel

from compliance.units.amounts import Amount, parse_amount
from compliance.errors import InputError
from compliance.model.toml_file import read_toml
from compliance.files.shipped import resolve_shipped
from compliance.requirements.tightening import check_tightening
from compliance.requirements.limit_sign import check_limit_signs
from compliance.requirements.entries import SEVERITIES, SOURCES, build_operating_point, build_procedure, build_requirement
from compliance.requirements.schema import OPEN_LIMIT, SCHEMA, validate_file
from compliance.requirements.requirement_set import LimitHistory, OperatingPoint, Procedure, Requirement, RequirementSet

__all__ = [
    "OPEN_LIMIT",
    "SCHEMA",
    "SEVERITIES",
    "SOURCES",
    "Amount",
    "LimitHistory",
    "OperatingPoint",
    "Procedure",
    "Requirement",
    "RequirementSet",
    "check_tightening",
    "load_requirements",
    "parse_amount",
]


def _load_chain(path: Path, seen: tuple[str, ...]) -> list[tuple[Path, str, dict]]:
    """Files in merge order (bases first), each (path, digest, raw dict) validated structurally."""
    key = str(path.resolve())
    if key in seen:
        raise InputError(f"{path}: extends itself through {' -> '.join(seen)}")
    data, digest = read_toml(path, "requirement file")
    model = validate_file(data, path)
    chain: list[tuple[Path, str, dict]] = []
    bases = model.extends if isinstance(model.extends, list) else ([model.extends] if model.extends else [])
    for base in bases:
        bpath = resolve_shipped(base, "requirements", relative_to=path.parent, where=f"{path}: extends")
        for item in _load_chain(bpath, seen + (key,)):
            if all(str(item[0].resolve()) != str(c[0].resolve()) for c in chain):
                chain.append(item)
    chain.append((path, digest, model.model_dump(exclude_unset=True)))
    return chain


def load_requirements(source: str | os.PathLike) -> RequirementSet:
    """Load a requirement file (path or reference name) with everything it extends.

    Raises
    ------
    InputError
        One message naming the file and key path of the first problem.
    """
    path = resolve_shipped(source, "requirements")
    chain = _load_chain(path, ())
    merged: dict[str, dict[str, dict]] = {"operating_points": {}, "procedures": {}, "requirements": {}}
    origin: dict[tuple[str, str, str], str] = {}
    first_file: dict[tuple[str, str], str] = {}
    history: dict[str, list[tuple[str, dict]]] = {}
    top = chain[-1][2]
    for fpath, _, data in chain:
        fstd = data.get("standard", "")
        for section in merged:
            for name, entry in (data.get(section) or {}).items():
                if isinstance(entry, BaseModel):
                    entry = entry.model_dump(exclude_unset=True)
                slot = merged[section].setdefault(name, {})
                first_file.setdefault((section, name), str(fpath))
                if section == "requirements" and "standard" not in slot and "standard" not in entry and fstd:
                    slot["standard"] = fstd
                for k, v in entry.items():
                    slot[k] = v
                    origin[(section, name, k)] = str(fpath)
                if section == "requirements":
                    history.setdefault(name, []).append((str(fpath), dict(slot)))
    ops = {n: build_operating_point(n, e, origin) for n, e in merged["operating_points"].items()}
    procs = {n: build_procedure(n, e, origin) for n, e in merged["procedures"].items()}
    reqs = tuple(
        build_requirement(rid, e, origin, first_file[("requirements", rid)], ops, procs, history[rid])
        for rid, e in merged["requirements"].items()
    )
    if not reqs:
        raise InputError(f"{path}: declares no requirements (a [requirements.ID] table)")
    check_limit_signs(reqs, origin)
    return RequirementSet(
        name=top.get("name") or path.stem,
        title=top.get("title") or top.get("name") or path.stem,
        path=str(path),
        digest=chain[-1][1],
        files=tuple((str(p), d) for p, d, _ in chain),
        operating_points=ops,
        procedures=procs,
        requirements=reqs,
    )
