"""Sweep files (TOML, schema ``govcheck-sweep/1``): validated at the edge with pydantic + pint.

A sweep file names the base configuration, the requirement file, the adjustable parameters
(a range or a list of values, units everywhere), the uncertain parameters with their
distributions (tolerance yield), and the search. :func:`load_sweep` returns a frozen
:class:`SweepSpec` with SI floats; any problem is ONE :class:`InputError` naming the file and
field (exit 2) before any simulation. The format is documented in docs/scaling.md.
"""

from __future__ import annotations

import math
from compliance.model.toml_file import read_toml
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, Union

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from compliance.errors import InputError, did_you_mean
from compliance.sweep.candidates.parameter_paths import ParamPath, describe
from compliance.units import parse_quantity

__all__ = ["Adjustable", "SweepSpec", "Uncertain", "load_sweep", "SCHEMA"]

SCHEMA = "govcheck-sweep/1"
Value = Union[str, float, int]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", populate_by_name=True)


class _AdjustIn(_Strict):
    range: list[Value] | None = None
    values: list[Value] | None = None
    steps: int = Field(3, ge=2, le=50)


class _UncertainIn(_Strict):
    distribution: Literal["normal", "uniform", "list"]
    std: Value | None = None
    half_width: Value | None = None
    values: list[Value] | None = None


class _SearchIn(_Strict):
    method: Literal["grid", "latin_hypercube", "optimise"]
    samples: int = Field(64, ge=1, le=1_000_000)
    seed: int = 0
    iterations: int = Field(4, ge=1, le=50)


class _YieldIn(_Strict):
    units: int = Field(200, ge=2, le=1_000_000)
    seed: int = 0
    confidence: float = Field(0.95, gt=0.5, lt=1.0)


class _SweepIn(_Strict):
    schema_: Literal["govcheck-sweep/1"] = Field(alias="schema")
    name: str
    title: str = ""
    base: str
    requirements: str
    linear: bool = False
    search: _SearchIn
    adjust: dict[str, _AdjustIn]
    uncertain: dict[str, _UncertainIn] = {}
    yield_: _YieldIn = Field(default_factory=_YieldIn, alias="yield")


@dataclass(frozen=True)
class Adjustable:
    """An adjustable parameter: SI ``low``/``high`` (range) or ``values`` (list); ``base`` filled later."""

    param: ParamPath
    low: float
    high: float
    values: tuple[float, ...] | None  # a list of allowed settings instead of a range
    steps: int

    @property
    def span(self) -> float:
        """The normalising width (high - low); changes are measured in fractions of it."""
        return self.high - self.low


@dataclass(frozen=True)
class Uncertain:
    """An uncertain parameter: a distribution around the candidate's value."""

    param: ParamPath
    distribution: str  # normal | uniform | list
    spread: float  # std (normal) or half width (uniform); relative when ``relative``
    relative: bool
    values: tuple[float, ...] | None


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep file (all SI)."""

    path: str
    name: str
    title: str
    base: str
    requirements: str
    linear: bool
    method: str
    samples: int
    seed: int
    iterations: int
    adjust: tuple[Adjustable, ...]
    uncertain: tuple[Uncertain, ...]
    yield_units: int
    yield_seed: int
    confidence: float

    @property
    def paths(self) -> dict:
        """Every parameter path the sweep moves -> :class:`ParamPath`."""
        out = {a.param.path: a.param for a in self.adjust}
        out.update({u.param.path: u.param for u in self.uncertain})
        return out


def _keys_at(model, loc) -> list[str]:
    """The keys a table at ``loc`` of the sweep file may hold (by their TOML spelling)."""
    for part in loc:
        fields = {(f.alias or n): f for n, f in model.model_fields.items()}
        if part not in fields:
            continue  # a free key of a dict table (a parameter path) or a union tag
        ann = fields[part].annotation
        args = [a for a in getattr(ann, "__args__", ()) if isinstance(a, type) and issubclass(a, BaseModel)]
        model = ann if isinstance(ann, type) and issubclass(ann, BaseModel) else (args[0] if args else model)
    return [(f.alias or n) for n, f in model.model_fields.items()]


def _where_of(path: Path, loc) -> str:
    parts = [f'"{p}"' if isinstance(p, str) and "." in p else str(p) for p in loc if p not in ("str", "float", "int")]
    return f"{path}: {'.'.join(parts)}"


def _si(text, pp: ParamPath, where: str) -> float:
    v = parse_quantity(text, pp.unit, where, pressure=pp.pressure)
    if not (pp.low <= v <= pp.high):
        raise InputError(f"{where}: {v:g} {pp.unit} is outside the admissible {pp.low:g} .. {pp.high:g} {pp.unit} ({pp.meaning})")
    return v


def _adjustable(path: str, a: _AdjustIn, where: str) -> Adjustable:
    pp = describe(path, where)
    if (a.range is None) == (a.values is None):
        raise InputError(f"{where}: give either range = [low, high] or values = [...]")
    if a.values is not None:
        vals = tuple(_si(v, pp, f"{where}.values[{i}]") for i, v in enumerate(a.values))
        if not vals:
            raise InputError(f"{where}.values: empty list; give at least one value")
        return Adjustable(pp, min(vals), max(vals), tuple(sorted(set(vals))), a.steps)
    if len(a.range) != 2:
        raise InputError(f"{where}.range: expected [low, high], got {len(a.range)} values")
    lo, hi = (_si(v, pp, f"{where}.range[{i}]") for i, v in enumerate(a.range))
    if not hi > lo:
        raise InputError(f"{where}.range: empty range ({a.range[0]} .. {a.range[1]}); low must be below high")
    return Adjustable(pp, lo, hi, None, a.steps)


def _spread(text, pp: ParamPath, where: str) -> tuple[float, bool]:
    relative = isinstance(text, str) and text.strip().endswith("%")
    v = parse_quantity(text, "" if relative else pp.unit, where)  # a difference: no abs/gauge
    if v < 0 or not math.isfinite(v):
        raise InputError(f"{where}: negative tolerance {text!r}; a spread must be >= 0")
    return v, relative


def _uncertain(path: str, u: _UncertainIn, where: str) -> Uncertain:
    pp = describe(path, where)
    if u.distribution == "list":
        if not u.values:
            raise InputError(f"{where}.values: distribution 'list' needs a non-empty list of values")
        return Uncertain(pp, "list", 0.0, False, tuple(_si(v, pp, f"{where}.values[{i}]") for i, v in enumerate(u.values)))
    key = "std" if u.distribution == "normal" else "half_width"
    text = getattr(u, key)
    if text is None:
        raise InputError(f"{where}: distribution '{u.distribution}' needs {key} (e.g. \"10 %\" or a quantity in {pp.unit})")
    spread, relative = _spread(text, pp, f"{where}.{key}")
    return Uncertain(pp, u.distribution, spread, relative, None)


def _resolve_file(text: str, folder: Path) -> str:
    """A path relative to the sweep file when it exists there, else as written (reference name)."""
    p = Path(text)
    cand = p if p.is_absolute() else folder / p
    return str(cand) if cand.exists() else text


def load_sweep(source) -> SweepSpec:
    """Read and validate a sweep file.

    Raises
    ------
    InputError
        Unreadable TOML, unknown field or parameter path, wrong unit, empty range, negative
        tolerance: one message naming the file and the field.
    """
    path = Path(source)
    if not path.is_file():
        raise InputError(f"{path}: sweep file not found")
    data, _ = read_toml(path, "sweep file")
    try:
        raw = _SweepIn.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors()  # a misspelt key also leaves its right spelling missing: name the misspelling
        err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
        if err["type"] == "extra_forbidden":
            key = str(err["loc"][-1])
            raise InputError(f"{_where_of(path, err['loc'])}: unknown key '{key}'"
                             f"{did_you_mean(key, _keys_at(_SweepIn, err['loc'][:-1]))}") from None
        raise InputError(f"{_where_of(path, err['loc'])}: {err['msg']}") from None
    if not raw.adjust:
        raise InputError(f"{path}: adjust: no adjustable parameter; name at least one")
    adjust = tuple(_adjustable(k, v, f'{path}: adjust."{k}"') for k, v in raw.adjust.items())
    uncertain = tuple(_uncertain(k, v, f'{path}: uncertain."{k}"') for k, v in raw.uncertain.items())
    folder = path.parent
    return SweepSpec(
        path=str(path), name=raw.name, title=raw.title or raw.name,
        base=_resolve_file(raw.base, folder), requirements=_resolve_file(raw.requirements, folder),
        linear=raw.linear, method=raw.search.method, samples=raw.search.samples, seed=raw.search.seed,
        iterations=raw.search.iterations, adjust=adjust, uncertain=uncertain,
        yield_units=raw.yield_.units, yield_seed=raw.yield_.seed, confidence=raw.yield_.confidence,
    )
