"""The structure of a requirement file (schema ``govcheck-requirements/1``), checked with pydantic.

Only the shape is checked here: known keys with the right types, the schema version, a
message naming the file and key path (with the closest known key) for anything else. What
the values mean (units, metric names, references between tables) is checked when the merged
entries are built (``compliance.requirements.entries``).
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, ValidationError

from compliance.errors import did_you_mean
from compliance.errors import InputError

__all__ = ["OPEN_LIMIT", "SCHEMA", "validate_file"]

SCHEMA = "govcheck-requirements/1"
OPEN_LIMIT = "purchaser"  # the limit is a data-sheet value the purchaser supplies


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _OpModel(_Strict):
    title: str | None = None
    initial_position: str | None = None
    load: str | None = None
    flow_control: bool | None = None
    setpoint_limiter: bool | None = None
    note: str | None = None


class _ProcModel(BaseModel):
    model_config = ConfigDict(extra="allow", frozen=True)  # settings depend on the kind: requirement_entries checks them
    kind: str | None = None
    title: str | None = None
    note: str | None = None


class _ReqModel(_Strict):
    title: str | None = None
    standard: str | None = None
    clause: str | None = None
    metric: str | None = None
    comparator: str | None = None
    limit: str | list[str] | None = None
    procedures: list[str] | None = None
    operating_points: list[str] | None = None
    severity: str | None = None
    source: str | None = None
    options: dict[str, str] | None = None
    note: str | None = None
    enabled: bool | None = None
    allow_loosen: bool | None = None
    reading: str | None = None
    alternative: str | None = None
    own_choice: str | None = None
    not_applicable: dict[str, str] | None = None


class _FileModel(_Strict):
    schema_: str | None = None
    name: str | None = None
    title: str | None = None
    standard: str | None = None
    description: str | None = None
    extends: str | list[str] | None = None
    operating_points: dict[str, _OpModel] = {}
    procedures: dict[str, _ProcModel] = {}
    requirements: dict[str, _ReqModel] = {}


_MODEL_FIELDS = {
    (): [*(_FileModel.model_fields.keys() - {"schema_"}), "schema"],
    ("operating_points",): list(_OpModel.model_fields),
    ("procedures",): list(_ProcModel.model_fields),
    ("requirements",): list(_ReqModel.model_fields),
}


_UNION_TAGS = {"str", "list[str]", "dict[str,str]", "bool", "float", "int"}


def _pydantic_message(exc: ValidationError, path: str) -> str:
    err = exc.errors()[0]
    loc = [str(x) for x in err["loc"] if str(x) not in _UNION_TAGS]
    keypath = ".".join("schema" if x == "schema_" else x for x in loc) or "<top>"
    if len(loc) >= 3 and loc[0] == "requirements" and loc[2] == "limit":
        return (f"{path}: {'.'.join(loc[:3])}: expected a string with a unit such as '1.6 mm', "
                f"a [low, high] pair of them, or '{OPEN_LIMIT}' (got {err.get('input')!r})")
    if err["type"] == "extra_forbidden":
        key = loc[-1]
        parent = tuple(loc[:1]) if len(loc) > 2 else ()
        return f"{path}: {keypath}: unknown key '{key}'{did_you_mean(key, _MODEL_FIELDS.get(parent, []))}"
    return f"{path}: {keypath}: {err['msg'].lower()} (got {err.get('input')!r})"



def validate_file(data: dict, path) -> _FileModel:
    """Check the structure of one requirement file's TOML tables.

    Parameters
    ----------
    data : dict
        The file as ``tomllib`` read it (``schema`` may be present).
    path : str or pathlib.Path
        The file, for messages.

    Raises
    ------
    InputError
        An unknown key (with the closest known one), a value of the wrong type, or a schema
        version this release does not read.
    """
    if "schema" in data:
        data = dict(data)
        data["schema_"] = data.pop("schema")
    try:
        model = _FileModel.model_validate(data)
    except ValidationError as exc:
        raise InputError(_pydantic_message(exc, str(path))) from None
    if model.schema_ is not None and model.schema_ != SCHEMA:
        raise InputError(f"{path}: schema: '{model.schema_}' is not supported (expected '{SCHEMA}')")
    return model
