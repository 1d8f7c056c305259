"""The frozen objects a requirement file becomes: operating points, procedures, requirements, the set.

Everything here is immutable and already validated (``compliance.requirements.loading`` builds it);
limits stay as written (:class:`~compliance.units.amounts.Amount`, possibly per cent of stroke) and are
resolved to SI only against a plant's stroke. ``as_dict`` gives the plain-JSON form the
results carry (docs/results-schema.md, ``requirement_set``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from compliance.files.display import display_path
from compliance.units.amounts import Amount
from compliance.metrics.catalogue import METRICS

__all__ = ["LimitHistory", "OperatingPoint", "Procedure", "Requirement", "RequirementSet", "format_limit"]


def format_limit(comparator: str, limit: tuple[Amount, ...] | None, open_text: str) -> str:
    """A limit as written: ``"0.10 s .. 0.25 s"`` (within), ``"<= 1.6 mm"``, or ``open_text`` when open."""
    if limit is None:
        return open_text
    if comparator == "within":
        return f"{limit[0].text} .. {limit[1].text}"
    return f"{comparator} {limit[0].text}"


def _as_written(value):
    """An Amount as its text, any other setting or option as it is."""
    return value.text if isinstance(value, Amount) else value


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
    # the governor's set-point rate limiter: None = as configured; False = not acting (the set-point is
    # injected downstream of the limiter, as for the time-constant test)
    setpoint_limiter: bool | None = None

    def as_dict(self) -> dict:
        """Plain-JSON form (as written and SI)."""
        return {
            "name": self.name,
            "title": self.title,
            "initial_position": None if self.initial_position is None else self.initial_position.text,
            "load": self.load,
            "load_text": self.load_text,
            "flow_control": self.flow_control,
            "setpoint_limiter": self.setpoint_limiter,
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
            "settings": {k: _as_written(v) for k, v in self.settings.items()},
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
    reading: str = ""  # how the clause is read (an assumption), docs/requirements.md "Readings"
    alternative: str = ""  # the other reading a purchaser may mean
    own_choice: str = ""  # what in this entry is govcheck's (or the file's) choice, not the standard's
    not_applicable: dict = field(default_factory=dict)  # operating point -> why the limit does not apply there

    @property
    def limit_text(self) -> str:
        """The limit as written (``"0.10 s .. 0.25 s"``, ``"<= 1.6 mm"``)."""
        return format_limit(self.comparator, self.limit, "open (purchaser's data sheet)")

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
            "options": {k: _as_written(v) for k, v in self.options.items()},
            "note": self.note,
            "enabled": self.enabled,
            "defined_in": self.defined_in,
            "reading": self.reading,
            "alternative": self.alternative,
            "own_choice": self.own_choice,
            "not_applicable": dict(self.not_applicable),
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
            "path": display_path(self.path),
            "digest": self.digest,
            "files": [{"path": display_path(p), "digest": d} for p, d in self.files],
            "operating_points": {k: v.as_dict() for k, v in self.operating_points.items()},
            "procedures": {k: v.as_dict() for k, v in self.procedures.items()},
            "requirements": [r.as_dict() for r in self.requirements],
        }
