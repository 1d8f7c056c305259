"""Requirement files: load TOML, follow ``extends``, validate with units, freeze.

A requirement file (``requirements/*.toml``, schema ``govcheck-requirements/1``) declares
operating points, test procedures and requirements, each a table keyed by its name or id.
A file may ``extends`` others (a reference name such as ``"iec61362"`` or a path relative
to the file); tables are merged key by key, the extending file winning. A limit may be
tightened freely; loosening it (or lowering the severity, or disabling a requirement) must
say ``allow_loosen = true`` and is reported. The format is described in docs/requirements.md.
"""

from __future__ import annotations

import difflib
import hashlib
import math
import os
import re
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError

from .errors import InputError
from .metrics import METRICS, STEP_OPTION_DEFAULTS
from .procedures import KINDS, parse_setting
from .units import parse_quantity
from .verdicts import COMPARATORS

SCHEMA = "govcheck-requirements/1"
SEVERITIES = ("mandatory", "advisory")
SOURCES = ("simulation", "linear")
OPEN_LIMIT = "purchaser"  # the limit is a data-sheet value the purchaser supplies

_STROKE_RE = re.compile(r"(%|percent)\s*(of\s+)?(the\s+)?stroke", re.IGNORECASE)
# SI unit of a metric -> unit of the factor that multiplies the stroke in a "%stroke" amount
_PER_STROKE_UNIT = {"m": "", "m/s": "1/s"}


def _suggest(word: str, choices) -> str:
    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1)
    return f"; did you mean '{close[0]}'?" if close else ""


# --------------------------------------------------------------------------- amounts
@dataclass(frozen=True)
class Amount:
    """A quantity as written, possibly relative to the stroke (``"1 %stroke"``).

    ``value`` is SI, or, when ``per_stroke``, the factor that multiplies the stroke [m]
    (``"1 %stroke"`` -> 0.01, ``"20 %stroke/s"`` -> 0.2 [1/s]).
    """

    value: float
    per_stroke: bool
    text: str

    def resolve(self, stroke: float) -> float:
        """SI value for a servomotor of stroke ``stroke`` [m]."""
        return self.value * stroke if self.per_stroke else self.value


def parse_amount(value: Any, si_unit: str, where: str, *, require_unit: bool = True) -> Amount:
    """Read ``"1.6 mm"``, ``"1 %stroke"``, ``"20 %stroke/s"`` or ``"0.25 s"`` into an Amount.

    Parameters
    ----------
    value : str
        Quantity with a unit (bare numbers are refused when ``require_unit``: a limit must say
        what it means).
    si_unit : str
        SI unit of the quantity (``""`` for a fraction such as ``"5 %"``).
    where : str
        File and key path for the error message.
    """
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise InputError(f"{where}: expected a quantity such as '1.6 mm', got {type(value).__name__}")
    if not isinstance(value, str):
        if require_unit and si_unit != "":
            raise InputError(f"{where}: {value!r} has no unit; write it with one, e.g. '{value} {si_unit}'")
        return Amount(parse_quantity(value, si_unit, where), False, str(value))
    if _STROKE_RE.search(value):
        if si_unit not in _PER_STROKE_UNIT:
            raise InputError(f"{where}: '%stroke' applies to positions and speeds, not to a quantity in '{si_unit or 'no unit'}'")
        text = _STROKE_RE.sub("percent", value)
        return Amount(parse_quantity(text, _PER_STROKE_UNIT[si_unit], where), True, value)
    if require_unit and si_unit != "" and re.fullmatch(r"\s*[-+0-9.eE]+\s*", value):
        raise InputError(f"{where}: {value!r} has no unit; expected one convertible to '{si_unit}'")
    return Amount(parse_quantity(value, si_unit, where), False, value)


# --------------------------------------------------------------------------- file schema
class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _OpModel(_Strict):
    title: str | None = None
    initial_position: str | None = None
    load: str | None = None
    flow_control: bool | None = None
    note: str | None = None


class _ProcModel(BaseModel):
    model_config = ConfigDict(extra="allow", frozen=True)  # settings depend on the kind; checked below
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
        return f"{path}: {keypath}: unknown key '{key}'{_suggest(key, _MODEL_FIELDS.get(parent, []))}"
    return f"{path}: {keypath}: {err['msg'].lower()} (got {err.get('input')!r})"


# --------------------------------------------------------------------------- frozen objects
@dataclass(frozen=True)
class OperatingPoint:
    """Initial position, load and circuit state a procedure runs at."""

    name: str
    title: str
    initial_position: Amount | None
    load: float | str | None  # closing force [N], "curve", "nominal" (load.nominal_force) or None
    load_text: str
    flow_control: bool | None  # None = as configured in the plant
    note: str = ""

    def as_dict(self) -> dict:
        """Plain-JSON form (as written and SI)."""
        return {
            "name": self.name,
            "title": self.title,
            "initial_position": None if self.initial_position is None else self.initial_position.text,
            "load": self.load,
            "load_text": self.load_text,
            "flow_control": self.flow_control,
            "note": self.note,
        }


@dataclass(frozen=True)
class Procedure:
    """A test procedure: a kind (``steps``, ``sine``, ...) and its settings (Amounts / values)."""

    name: str
    kind: str
    title: str
    settings: dict
    note: str = ""

    def as_dict(self) -> dict:
        """Plain-JSON form with the settings as written."""
        return {
            "name": self.name,
            "kind": self.kind,
            "title": self.title,
            "settings": {k: (v.text if isinstance(v, Amount) else v) for k, v in self.settings.items()},
            "note": self.note,
        }


@dataclass(frozen=True)
class LimitHistory:
    """One file's say on a requirement's limit (for the tighten/loosen check)."""

    file: str
    comparator: str
    limit: tuple[Amount, ...] | None  # None = open (purchaser)
    severity: str
    enabled: bool
    allow_loosen: bool


@dataclass(frozen=True)
class Requirement:
    """One requirement as evaluated."""

    id: str
    title: str
    standard: str
    clause: str
    metric: str
    comparator: str
    limit: tuple[Amount, ...] | None  # None = open: a purchaser's data-sheet value nobody set
    procedures: tuple[str, ...]
    operating_points: tuple[str, ...]
    severity: str
    source: str
    options: dict
    note: str
    enabled: bool
    defined_in: str
    history: tuple[LimitHistory, ...] = field(default=())

    @property
    def limit_text(self) -> str:
        """The limit as written (``"0.10 s .. 0.25 s"``, ``"<= 1.6 mm"``)."""
        if self.limit is None:
            return "open (purchaser's data sheet)"
        if self.comparator == "within":
            return f"{self.limit[0].text} .. {self.limit[1].text}"
        return f"{self.comparator} {self.limit[0].text}"

    def resolved_limit(self, stroke: float) -> tuple[float, ...]:
        """SI limit(s) for a servomotor of ``stroke`` [m]."""
        if self.limit is None:
            raise ValueError(f"requirement {self.id} has an open limit")
        return tuple(a.resolve(stroke) for a in self.limit)

    def as_dict(self) -> dict:
        """Plain-JSON form (as written, with the history of files that set the limit)."""
        info = METRICS[self.metric]
        return {
            "id": self.id,
            "title": self.title,
            "standard": self.standard,
            "clause": self.clause,
            "metric": self.metric,
            "metric_meaning": info.meaning,
            "unit": info.si_unit,
            "display_unit": info.display_unit,
            "comparator": self.comparator,
            "limit_text": self.limit_text,
            "limit": None if self.limit is None else [a.text for a in self.limit],
            "procedures": list(self.procedures),
            "operating_points": list(self.operating_points),
            "severity": self.severity,
            "source": self.source,
            "options": {k: (v.text if isinstance(v, Amount) else v) for k, v in self.options.items()},
            "note": self.note,
            "enabled": self.enabled,
            "defined_in": self.defined_in,
            "history": [
                {
                    "file": h.file,
                    "comparator": h.comparator,
                    "limit": None if h.limit is None else [a.text for a in h.limit],
                    "severity": h.severity,
                    "enabled": h.enabled,
                    "allow_loosen": h.allow_loosen,
                }
                for h in self.history
            ],
        }


@dataclass(frozen=True)
class RequirementSet:
    """A requirement file with everything it extends, merged and validated."""

    name: str
    title: str
    path: str
    digest: str
    files: tuple[tuple[str, str], ...]  # (path, sha256) of every file read, base first
    operating_points: dict
    procedures: dict
    requirements: tuple[Requirement, ...]

    def as_dict(self) -> dict:
        """Plain-JSON form of the set as evaluated."""
        return {
            "name": self.name,
            "title": self.title,
            "path": self.path,
            "digest": self.digest,
            "files": [{"path": p, "digest": d} for p, d in self.files],
            "operating_points": {k: v.as_dict() for k, v in self.operating_points.items()},
            "procedures": {k: v.as_dict() for k, v in self.procedures.items()},
            "requirements": [r.as_dict() for r in self.requirements],
        }


# --------------------------------------------------------------------------- loading
def reference_requirement_files() -> list[str]:
    """Names of the requirement files shipped with the package (``iec61362``, ...)."""
    folder = resources.files("compliance") / "data" / "requirements"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def resolve_requirements_path(source: str | os.PathLike, relative_to: Path | None = None, where: str = "") -> Path:
    """Path of a requirement file given as a path or a reference name (``"iec61362"``)."""
    s = str(source)
    looks_like_path = s.endswith(".toml") or "/" in s or os.sep in s
    if looks_like_path:
        p = Path(s)
        if relative_to is not None and not p.is_absolute():
            p = relative_to / p
        if not p.is_file():
            raise InputError(f"{where or s}: requirement file '{s}' not found")
        return p
    ref = resources.files("compliance") / "data" / "requirements" / f"{s}.toml"
    if not ref.is_file():
        p = Path(s)
        if p.is_file():
            return p
        names = reference_requirement_files()
        raise InputError(
            f"{where or s}: '{s}' is neither a file nor a reference requirement file{_suggest(s, names)} "
            f"(known: {', '.join(names) or 'none'})"
        )
    return Path(str(ref))


def _read_file(path: Path) -> tuple[dict, str]:
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


def _load_chain(path: Path, seen: tuple[str, ...]) -> list[tuple[Path, str, dict]]:
    """Files in merge order (bases first), each (path, digest, raw dict) validated structurally."""
    key = str(path.resolve())
    if key in seen:
        raise InputError(f"{path}: extends itself through {' -> '.join(seen)}")
    data, digest = _read_file(path)
    if "schema" in data:
        data = dict(data)
        data["schema_"] = data.pop("schema")
    try:
        model = _FileModel.model_validate(data)
    except ValidationError as exc:
        raise InputError(_pydantic_message(exc, str(path))) from None
    if model.schema_ is not None and model.schema_ != SCHEMA:
        raise InputError(f"{path}: schema: '{model.schema_}' is not supported (expected '{SCHEMA}')")
    chain: list[tuple[Path, str, dict]] = []
    bases = model.extends if isinstance(model.extends, list) else ([model.extends] if model.extends else [])
    for base in bases:
        bpath = resolve_requirements_path(base, path.parent, f"{path}: extends")
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
    path = resolve_requirements_path(source)
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
    ops = {n: _build_op(n, e, origin) for n, e in merged["operating_points"].items()}
    procs = {n: _build_proc(n, e, origin) for n, e in merged["procedures"].items()}
    reqs = tuple(
        _build_req(rid, e, origin, first_file[("requirements", rid)], ops, procs, history[rid])
        for rid, e in merged["requirements"].items()
    )
    if not reqs:
        raise InputError(f"{path}: declares no requirements (a [requirements.ID] table)")
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


def _where(origin, section, name, key):
    f = origin.get((section, name, key), "?")
    return f"{f}: {section}.{name}.{key}"


def _build_op(name: str, e: dict, origin) -> OperatingPoint:
    pos = None
    if e.get("initial_position") is not None:
        pos = parse_amount(e["initial_position"], "m", _where(origin, "operating_points", name, "initial_position"))
    load_text = e.get("load", "none")
    if load_text is None or load_text.strip().lower() in ("none", "0", ""):
        load = None
        load_text = "none"
    elif load_text.strip().lower() in ("curve", "nominal"):
        load = load_text.strip().lower()
    else:
        load = parse_amount(load_text, "N", _where(origin, "operating_points", name, "load")).value
    return OperatingPoint(name, e.get("title") or name, pos, load, load_text, e.get("flow_control"), e.get("note") or "")


def _build_proc(name: str, e: dict, origin) -> Procedure:
    where = _where(origin, "procedures", name, "kind")
    kind = e.get("kind")
    if kind is None:
        raise InputError(f"{where}: missing 'kind' (one of {', '.join(KINDS)})")
    if kind not in KINDS:
        raise InputError(f"{where}: '{kind}' is not a procedure kind{_suggest(kind, KINDS)} (known: {', '.join(KINDS)})")
    spec = KINDS[kind]
    settings = {}
    for k, v in e.items():
        if k in ("kind", "title", "note"):
            continue
        if k not in spec.settings:
            raise InputError(
                f"{_where(origin, 'procedures', name, k)}: unknown setting for a '{kind}' procedure"
                f"{_suggest(k, spec.settings)} (settings: {', '.join(spec.settings)})"
            )
        settings[k] = parse_setting(spec.settings[k], v, _where(origin, "procedures", name, k))
    for k, s in spec.settings.items():
        if k not in settings:
            if s.default is None:
                raise InputError(f"{origin.get(('procedures', name, 'kind'), '?')}: procedures.{name}: missing setting '{k}' ({s.meaning})")
            settings[k] = parse_setting(s, s.default, f"default of {kind}.{k}")
    return Procedure(name, kind, e.get("title") or name, settings, e.get("note") or "")


def _parse_limit(e: dict, where: str, metric: str, comparator: str):
    lim = e.get("limit")
    if lim is None:
        raise InputError(f"{where}: missing 'limit' (a quantity with a unit, a [low, high] pair for 'within', or '{OPEN_LIMIT}')")
    if isinstance(lim, str) and lim.strip().lower() == OPEN_LIMIT:
        return None
    unit = METRICS[metric].si_unit
    if comparator == "within":
        if not isinstance(lim, list) or len(lim) != 2:
            raise InputError(f"{where}: 'within' needs limit = [low, high], e.g. ['0.10 s', '0.25 s']")
        a = (parse_amount(lim[0], unit, where), parse_amount(lim[1], unit, where))
        if a[0].per_stroke == a[1].per_stroke and a[0].value > a[1].value:
            raise InputError(f"{where}: low limit {a[0].text} is above high limit {a[1].text}")
        return a
    if isinstance(lim, list):
        raise InputError(f"{where}: comparator '{comparator}' takes one limit, got a list")
    return (parse_amount(lim, unit, where),)


def _build_req(rid, e, origin, defined_in, ops, procs, hist) -> Requirement:
    sec = "requirements"

    def need(key, choices=None):
        v = e.get(key)
        if v is None:
            raise InputError(f"{defined_in}: {sec}.{rid}: missing '{key}'" + (f" (one of {', '.join(choices)})" if choices else ""))
        if choices is not None and v not in choices:
            raise InputError(f"{_where(origin, sec, rid, key)}: '{v}' is not one of {', '.join(choices)}{_suggest(v, choices)}")
        return v

    title = need("title")
    metric = need("metric", list(METRICS))
    comparator = need("comparator", list(COMPARATORS))
    severity = e.get("severity", "mandatory")
    if severity not in SEVERITIES:
        raise InputError(f"{_where(origin, sec, rid, 'severity')}: '{severity}' is not one of {', '.join(SEVERITIES)}")
    source = e.get("source", "simulation")
    if source not in SOURCES:
        raise InputError(f"{_where(origin, sec, rid, 'source')}: '{source}' is not one of {', '.join(SOURCES)}")
    limit = _parse_limit(e, _where(origin, sec, rid, "limit"), metric, comparator)
    op_names = tuple(e.get("operating_points") or ())
    if not op_names:
        raise InputError(f"{defined_in}: {sec}.{rid}: missing 'operating_points' (a list of names from [operating_points])")
    for n in op_names:
        if n not in ops:
            raise InputError(f"{_where(origin, sec, rid, 'operating_points')}: operating point '{n}' is not declared{_suggest(n, ops)}")
    proc_names = tuple(e.get("procedures") or ())
    info = METRICS[metric]
    if source == "simulation":
        if not proc_names:
            raise InputError(f"{defined_in}: {sec}.{rid}: missing 'procedures' (a list of names from [procedures])")
        for n in proc_names:
            if n not in procs:
                raise InputError(f"{_where(origin, sec, rid, 'procedures')}: procedure '{n}' is not declared{_suggest(n, procs)}")
            if procs[n].kind not in info.kinds:
                raise InputError(
                    f"{_where(origin, sec, rid, 'procedures')}: metric '{metric}' cannot be measured by procedure "
                    f"'{n}' of kind '{procs[n].kind}' (it needs one of: {', '.join(info.kinds)})"
                )
            if procs[n].kind != "full_stroke" and procs[n].kind != "independent_adjustment":
                for o in op_names:
                    if ops[o].initial_position is None:
                        raise InputError(
                            f"{_where(origin, sec, rid, 'operating_points')}: operating point '{o}' has no "
                            f"initial_position, which procedure '{n}' ({procs[n].kind}) needs"
                        )
    options = {}
    for k, v in (e.get("options") or {}).items():
        if k not in info.options:
            raise InputError(
                f"{_where(origin, sec, rid, 'options')}.{k}: metric '{metric}' takes no option '{k}'"
                + (f"{_suggest(k, info.options)} (options: {', '.join(info.options)})" if info.options else "")
            )
        options[k] = parse_amount(v, STEP_OPTION_DEFAULTS[k][0], f"{_where(origin, sec, rid, 'options')}.{k}")
    history = []
    for fpath, snap in hist:
        try:
            lim = _parse_limit(snap, f"{fpath}: {sec}.{rid}.limit", metric, snap.get("comparator", comparator))
        except InputError:
            lim = None if str(snap.get("limit", "")).lower() == OPEN_LIMIT else limit
        history.append(
            LimitHistory(
                fpath,
                snap.get("comparator", comparator),
                lim,
                snap.get("severity", "mandatory"),
                bool(snap.get("enabled", True)),
                bool(snap.get("allow_loosen", False)),
            )
        )
    return Requirement(
        id=rid,
        title=title,
        standard=e.get("standard", ""),
        clause=need("clause"),
        metric=metric,
        comparator=comparator,
        limit=limit,
        procedures=proc_names,
        operating_points=op_names,
        severity=severity,
        source=source,
        options=options,
        note=e.get("note", ""),
        enabled=bool(e.get("enabled", True)),
        defined_in=defined_in,
        history=tuple(history),
    )


# --------------------------------------------------------------------------- tighten / loosen
def _interval(comparator: str, limits: tuple[float, ...]) -> tuple[float, float]:
    if comparator in ("<=", "<"):
        return (-math.inf, limits[0])
    if comparator in (">=", ">"):
        return (limits[0], math.inf)
    return (limits[0], limits[1])


def check_tightening(req: Requirement, stroke: float) -> list[str]:
    """Check that every override tightened the requirement; return notes on allowed loosening.

    Each file's limit must accept a subset of what the file before it accepted, severity may
    not drop from mandatory to advisory and a requirement may not be disabled, unless that
    file says ``allow_loosen = true``.

    Raises
    ------
    InputError
        When a file loosens a requirement without ``allow_loosen = true``.
    """
    notes = []
    for prev, cur in zip(req.history, req.history[1:]):
        problems = []
        if prev.limit is not None and cur.limit is None:
            problems.append("re-opens a limit that was set")
        elif prev.limit is not None and cur.limit is not None:
            a = _interval(prev.comparator, tuple(x.resolve(stroke) for x in prev.limit))
            b = _interval(cur.comparator, tuple(x.resolve(stroke) for x in cur.limit))
            tol = 1e-9 * max(1.0, *(abs(v) for v in (*a, *b) if math.isfinite(v)))
            if b[0] < a[0] - tol or b[1] > a[1] + tol:
                problems.append(f"widens the limit from {_fmt_lim(prev)} to {_fmt_lim(cur)}")
        if prev.severity == "mandatory" and cur.severity == "advisory":
            problems.append("lowers the severity from mandatory to advisory")
        if prev.enabled and not cur.enabled:
            problems.append("disables it")
        if problems:
            msg = f"{cur.file}: requirements.{req.id}: {'; '.join(problems)} (set by {prev.file})"
            if not cur.allow_loosen:
                raise InputError(msg + "; a file may only tighten an inherited requirement unless it says allow_loosen = true")
            notes.append("LOOSENED: " + msg)
    return notes


def _fmt_lim(h: LimitHistory) -> str:
    if h.limit is None:
        return "open"
    if h.comparator == "within":
        return f"{h.limit[0].text} .. {h.limit[1].text}"
    return f"{h.comparator} {h.limit[0].text}"
