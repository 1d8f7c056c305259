"""The plant a check judged: its identity, every parameter (SI, with unit, meaning and source), its effects.

docs/results-schema.md, ``plant``.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.results.record import FrozenDict, Record, key, records, tuple_of

__all__ = ["EffectParameter", "EffectRecord", "LoadCurve", "ParameterRecord", "PlantRecord"]


@dataclass(frozen=True, kw_only=True)
class ParameterRecord(Record):
    """A base parameter of the plant: SI value, SI unit (pint syntax), meaning and where it came from."""

    key: str
    value: float | None = None
    unit: str = ""
    meaning: str = ""
    source: str = ""  # paper | assumed | derived | user | fitted


@dataclass(frozen=True, kw_only=True)
class EffectParameter(Record):
    """A parameter of an effect switched on (SI)."""

    name: str
    value: float | None = None
    unit: str = ""
    meaning: str = ""


@dataclass(frozen=True, kw_only=True)
class EffectRecord(Record):
    """An optional piece of physics switched on, with its parameters."""

    name: str
    meaning: str = ""
    params: tuple[EffectParameter, ...] = key(default=(), read=records(EffectParameter))


@dataclass(frozen=True, kw_only=True)
class LoadCurve(Record):
    """The closing force on the gate over the stroke: positions [m], forces [N] and where the curve came from."""

    position: tuple[float, ...] = key(read=tuple_of(float))
    force: tuple[float, ...] = key(read=tuple_of(float))
    source: str | None = None  # paper | assumed | derived | user (None in an older file: taken as assumed)

    @property
    def assumed(self) -> bool:
        """Whether the curve is an assumption (not from the paper, a derivation or the user)."""
        return self.source in (None, "assumed")


@dataclass(frozen=True, kw_only=True)
class PlantRecord(Record):
    """The plant configuration as judged (docs/results-schema.md, ``plant``)."""

    name: str
    description: str | None = None
    path: str | None = None
    digest: str
    parameters: tuple[ParameterRecord, ...] = key(read=records(ParameterRecord))
    options: FrozenDict = key(factory=FrozenDict)
    effects: tuple[EffectRecord, ...] = key(default=(), read=records(EffectRecord))
    load_curve: LoadCurve | None = key(default=None, read=LoadCurve.from_dict)
    provenance: FrozenDict = key(factory=FrozenDict)
    identity: FrozenDict = key(factory=FrozenDict)

    def value(self, name: str, default=None):
        """The SI value of base parameter ``name`` (``default`` when the plant has none)."""
        for p in self.parameters:
            if p.key == name:
                return p.value
        return default

    @property
    def values(self) -> dict:
        """Every base parameter's SI value by key."""
        return {p.key: p.value for p in self.parameters}

    @property
    def stroke(self) -> float | None:
        """The servomotor stroke [m]."""
        return self.value("cylinder.stroke")
