"""Optional ``[identity]`` table of a plant configuration: who and what a signed report is about.

Site, unit, the equipment identification (valve, cylinders, positioner, ... with serial
numbers) and the document fields of a factory-acceptance-test report. None of it enters the
physics; the report prints it on page 1 and leaves a blank to fill in by hand for what is absent.

    [identity]
    site = "SHPP Example, 400 kW"
    unit = "Unit 1 wicket-gate servomotor"
    document_number = "QA-GOV-0001"
    revision = "A"
    author = "J. Engineer"
    witness = "for the owner: A. Witness"       # also supplier, test_date, revision_note
    [identity.equipment.valve]
    id = "5/3 proportional valve 1V1"
    serial = "SN 12345"
"""

from __future__ import annotations

from types import MappingProxyType

from compliance.errors import InputError

FIELDS = ("site", "unit", "owner", "supplier", "witness", "test_date", "document_number", "revision", "revision_note",
          "author")
EQUIPMENT_FIELDS = ("id", "serial", "make", "model", "note")


def _text(v, where: str) -> str:
    if isinstance(v, bool) or not isinstance(v, (str, int, float)):
        raise InputError(f"{where}: expected text, got {type(v).__name__}")
    return str(v).strip()


def parse_identity(raw, where: str) -> MappingProxyType:
    """Validate an ``[identity]`` table -> read-only ``{field: text, "equipment": {role: {field: text}}}``.

    Raises
    ------
    InputError
        Not a table, an unknown field (named), or a value that is not text.
    """
    if raw is None:
        return MappingProxyType({})
    kw = f"{where}: identity"
    if not isinstance(raw, dict):
        raise InputError(f"{kw}: expected a table ([identity])")
    out: dict = {}
    for k, v in raw.items():
        if k == "equipment":
            if not isinstance(v, dict):
                raise InputError(f"{kw}.equipment: expected [identity.equipment.ROLE] tables")
            eq = {}
            for role, item in v.items():
                if not isinstance(item, dict):
                    raise InputError(f"{kw}.equipment.{role}: expected a table with {', '.join(EQUIPMENT_FIELDS)}")
                bad = sorted(set(item) - set(EQUIPMENT_FIELDS))
                if bad:
                    raise InputError(f"{kw}.equipment.{role}: unknown field '{bad[0]}' (expected {', '.join(EQUIPMENT_FIELDS)})")
                eq[str(role)] = MappingProxyType({f: _text(x, f"{kw}.equipment.{role}.{f}") for f, x in item.items()})
            out["equipment"] = MappingProxyType(eq)
        elif k in FIELDS:
            out[k] = _text(v, f"{kw}.{k}")
        else:
            raise InputError(f"{kw}: unknown field '{k}' (expected {', '.join(FIELDS)} or [identity.equipment.ROLE])")
    return MappingProxyType(out)


def identity_dict(identity) -> dict:
    """Plain-JSON copy of a parsed identity (for the results file)."""
    return {k: ({r: dict(f) for r, f in v.items()} if k == "equipment" else v) for k, v in (identity or {}).items()}
