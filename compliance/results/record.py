"""How a typed result record meets its JSON: one declaration per field, read and written in that order.

Every record of a check's result is a frozen dataclass whose fields are declared with :func:`key`:
the JSON key (the field name unless given), whether the key is left out when the value is None
(an optional key such as a row's ``band``), and how a JSON value becomes the field's value (a
nested record, a tuple of records, an enum). :func:`as_dict` writes the keys in field order, so the
declaration *is* the schema's key order and a file read and written again is byte-identical;
:func:`from_dict` reads a JSON object, names a missing required key by its path (``InputError``)
and keeps keys a newer govcheck added (``extra``, written back last).

Sections kept as written (a linear analysis, a remedies search) are :class:`FrozenDict` trees:
read-only dicts and tuples, written back unchanged.
"""

from __future__ import annotations

import dataclasses
import enum
from typing import Any, Callable

from compliance.errors import InputError
from compliance.results.keys import RequestKey

__all__ = ["FrozenDict", "Record", "as_dict", "derived", "enum_of", "freeze", "from_dict", "key", "need", "optional",
           "records", "tuple_of"]

_NO = dataclasses.MISSING


class FrozenDict(dict):
    """A dict that cannot change after it is made (JSON writers and pickling see a plain dict)."""

    def _refuse(self, *a, **k):
        raise TypeError("a result section is read-only; build a new result instead")

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = __ior__ = _refuse

    def __reduce__(self):
        return FrozenDict, (dict(self),)

    def __copy__(self):
        return self

    def __deepcopy__(self, memo):
        return self


def freeze(obj):
    """Read-only copy of a JSON tree: dicts become :class:`FrozenDict`, lists tuples (records stay as they are)."""
    if isinstance(obj, FrozenDict):
        return obj
    if isinstance(obj, dict):
        return FrozenDict({k: freeze(v) for k, v in obj.items()})
    if isinstance(obj, (list, tuple)):
        if _SCALARS.issuperset(map(type, obj)):  # a signal of a trace: thousands of numbers, copied at C speed
            return tuple(obj)
        return tuple(freeze(v) for v in obj)
    return obj


_SCALARS = frozenset({float, int, str, bool, type(None)})


def key(name: str | None = None, *, omit_none: bool = False, read: Callable | None = None,
        write: Callable | None = None, default=_NO, factory=_NO) -> Any:
    """Declare a record field: its JSON key, whether None leaves the key out, how its JSON value is read
    (``read(value, where)``) and written (``write(value)``).

    A field without ``default``/``factory`` is required in a file (``from_dict`` names it when missing).
    """
    meta = {"json": name, "omit_none": omit_none, "read": read, "write": write}
    if factory is not _NO:
        return dataclasses.field(default_factory=factory, metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


class Record:
    """Mixin of a result record: ``as_dict()`` and ``from_dict()`` by the field declarations."""

    def as_dict(self) -> dict:
        """Plain-JSON form, keys in declaration order (the results schema)."""
        return as_dict(self)

    @classmethod
    def from_dict(cls, data, where: str = "results"):
        """The record of a JSON object (``where`` names it in an error)."""
        return from_dict(cls, data, where)


def derived(default=None) -> Any:
    """A field computed from the others or from the plant (an SI position), never read from or written to JSON."""
    return dataclasses.field(default=default, metadata={"derived": True}, compare=False)


def _plain(v):
    if isinstance(v, RequestKey):
        return str(v)
    if isinstance(v, Record):
        return v.as_dict()
    if isinstance(v, enum.Enum):
        return v.value if not isinstance(v, str) else v
    if isinstance(v, tuple) and v and isinstance(v[0], Record):
        return [x.as_dict() for x in v]
    return v


def as_dict(rec) -> dict:
    """A record as a JSON object (see the module docstring)."""
    out = {}
    for f in dataclasses.fields(rec):
        if f.name == "extra" or f.metadata.get("derived"):
            continue
        v = getattr(rec, f.name)
        if v is None and f.metadata.get("omit_none"):
            continue
        write = f.metadata.get("write")
        out[f.metadata.get("json") or f.name] = write(v) if write is not None and v is not None else _plain(v)
    extra = getattr(rec, "extra", None)
    if extra:
        out.update(extra)
    return out


def need(data, where: str) -> dict:
    """``data`` when it is a JSON object, else an ``InputError`` naming ``where``."""
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected a JSON object, got {type(data).__name__} (a govcheck results file, "
                         "schema 'govcheck-results/1')")
    return data


def from_dict(cls, data, where: str = "results"):
    """Build record ``cls`` from a JSON object; unknown keys go to its ``extra`` (when it has one)."""
    data = need(data, where)
    kw, known = {}, set()
    for f in dataclasses.fields(cls):
        if f.name == "extra" or f.metadata.get("derived"):
            continue
        k = f.metadata.get("json") or f.name
        known.add(k)
        if k not in data:
            if f.default is _NO and f.default_factory is _NO:
                raise InputError(f"{where}: key '{k}' is missing from the results file (expected a govcheck results "
                                 "file, schema 'govcheck-results/1')")
            continue
        v = data[k]
        read = f.metadata.get("read")
        # a field written by its own function reads its own null too (a qualifier of none is null)
        reads = read is not None and (v is not None or f.metadata.get("write") is not None)
        kw[f.name] = read(v, f"{where}.{k}") if reads else freeze(v)
    if any(f.name == "extra" for f in dataclasses.fields(cls)):
        kw["extra"] = freeze({k: v for k, v in data.items() if k not in known})
    return cls(**kw)


def enum_of(cls) -> Callable:
    """Reader of an enum value (``Status``, ``Basis``...): an unknown spelling is named with the known ones."""
    def read(v, where):
        try:
            return cls(v)
        except ValueError:
            raise InputError(f"{where}: {v!r} is not one of {', '.join(repr(m.value) for m in cls)}") from None
    return read


def optional(cls) -> Callable:
    """Reader of an optional section of ``cls``: an empty object (or null) is no section."""
    return lambda v, where: cls.from_dict(v, where) if v else None


def records(cls) -> Callable:
    """Reader of a JSON list of ``cls`` objects -> tuple of records."""
    def read(v, where):
        if not isinstance(v, (list, tuple)):
            raise InputError(f"{where}: expected a list, got {type(v).__name__}")
        return tuple(cls.from_dict(x, f"{where}[{i}]") for i, x in enumerate(v))
    return read


def tuple_of(conv: Callable) -> Callable:
    """Reader of a JSON list converting each item with ``conv`` -> tuple."""
    def read(v, where):
        if not isinstance(v, (list, tuple)):
            raise InputError(f"{where}: expected a list, got {type(v).__name__}")
        return tuple(conv(x) for x in v)
    return read
