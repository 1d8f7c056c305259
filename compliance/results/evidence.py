"""The evidence a check carries beside its verdicts: what the measurements say about the model
(``model_evidence``) and the linearised loop's stability margins (``stability``).

``compliance.model_evidence`` compares the model with the sources its plant file names (the plant
paper's measured figures, recordings of the servo); figures are in the unit each gives (``mm``,
``s``, ``m/s``, ``% stroke``). ``compliance.linear.stability`` gives the phase [deg] and gain [dB]
margins at every distinct operating point against govcheck's own criterion (positions in m).
These records read both sections once, so the terminal and the report read attributes.
docs/results-schema.md, ``model_evidence`` and ``stability``.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.requirements.verdict import Severity
from compliance.results.record import FrozenDict, Record, key, records, tuple_of

__all__ = ["ComparedFigure", "ContradictedVerdict", "EvidenceSource", "FigureTexts", "MarginCriterion", "ModelEvidence",
           "StabilityPoint", "StabilitySection"]

_texts = tuple_of(str)


@dataclass(frozen=True, kw_only=True)
class FigureTexts(Record):
    """A compared figure's modelled and measured values as a reader sees them (``0.860 mm``)."""

    modelled: str = "-"
    measured: str = "-"


@dataclass(frozen=True, kw_only=True)
class ComparedFigure(Record):
    """One measured figure of a paper beside the model's: whether they agree and what it is evidence for."""

    test: str = ""
    metric: str = ""
    unit: str = ""
    modelled: float | None = None
    measured: float | None = None
    measured_range: tuple | None = None
    scatter: FrozenDict | None = None  # {kind: relative | absolute, width}
    agreement: str | None = None  # agrees | contradicts | None (no measured figure)
    by_construction: bool = False  # a parameter was derived to give it: no evidence
    independent: bool = True  # False: the configuration was calibrated to it
    bears_on: tuple[str, ...] = key(default=(), read=_texts)
    note: str | None = None
    display: FigureTexts = key(factory=FigureTexts, read=FigureTexts.from_dict)
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def counts(self) -> bool:
        """Whether the figure is independent evidence about the model (compared, not derived, not fitted to)."""
        return self.agreement is not None and self.independent and not self.by_construction


@dataclass(frozen=True, kw_only=True)
class EvidenceSource(Record):
    """A source of measurements: a paper's measured figures (``kind = "paper"``) or a recording replayed."""

    kind: str  # paper | recording
    name: str | None = key(omit_none=True, default=None)
    title: str | None = key(omit_none=True, default=None)
    path: str | None = key(omit_none=True, default=None)
    digest: str | None = key(omit_none=True, default=None)
    note: str | None = key(omit_none=True, default=None)
    description: str | None = key(omit_none=True, default=None)
    command: str = ""
    independence: str | None = key(omit_none=True, default=None)
    independent: bool | None = key(omit_none=True, default=None)
    agreement: str | None = key(omit_none=True, default=None)  # a recording's: agrees | contradicts
    compared: int | None = key(omit_none=True, default=None)
    agree: int | None = key(omit_none=True, default=None)
    contradict: int | None = key(omit_none=True, default=None)
    by_construction: int | None = key(omit_none=True, default=None)
    figures: tuple[ComparedFigure, ...] = key(default=(), read=records(ComparedFigure))
    modes: FrozenDict = key(factory=FrozenDict)  # a recording's replays: {mode: {pass, windows, failed_windows, fits}}
    bears_on: tuple[str, ...] = key(default=(), read=_texts)
    warnings: tuple[str, ...] = key(default=(), read=_texts)
    notes: tuple[str, ...] = key(default=(), read=_texts)
    by_construction_note: str | None = key(omit_none=True, default=None)
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def label(self) -> str:
        """The paper's title or the recording's path."""
        return self.title or self.path or self.kind


@dataclass(frozen=True, kw_only=True)
class ContradictedVerdict(Record):
    """A judged requirement whose metric a contradicting measured figure is evidence for."""

    requirement: str
    title: str | None = None
    severity: str = Severity.MANDATORY
    status: str = ""
    metric: str = ""
    figures: tuple[str, ...] = key(default=(), read=_texts)
    recordings: tuple[str, ...] = key(default=(), read=_texts)
    example: str = ""  # the largest miss, short
    direction: tuple[str, ...] = key(default=(), read=_texts)  # above / below the measured figure
    consequence: str = ""  # whether the model errs towards the limit (pessimistic) or away (optimistic)
    text: str = ""
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def lean(self) -> str:
        """The consequence in one word: ``pessimistic``, ``optimistic`` or ``either way``."""
        return next((w for w in ("pessimistic", "optimistic") if w in self.consequence), "either way")


@dataclass(frozen=True, kw_only=True)
class ModelEvidence(Record):
    """Whether the model is validated by the measurements its plant file names, and which verdicts they contradict."""

    status: str = "not validated"  # validated | contradicted | not validated
    validated: bool = False
    compared: int = 0  # independent measured figures compared (a recording counts as one)
    contradict: int = 0
    summary: str = ""
    examples: tuple[str, ...] = key(default=(), read=_texts)
    sources: tuple[EvidenceSource, ...] = key(default=(), read=records(EvidenceSource))
    contradicted: tuple[ContradictedVerdict, ...] = key(default=(), read=records(ContradictedVerdict))
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def word(self) -> str:
        """The status as page 1 prints it (``CONTRADICTED``)."""
        return self.status.upper()


@dataclass(frozen=True, kw_only=True)
class MarginCriterion(Record):
    """The smallest phase [deg] and gain [dB] margins govcheck accepts, and why (its own choice)."""

    phase_margin_deg: float = 30.0
    gain_margin_db: float = 6.0
    basis: str = ""


@dataclass(frozen=True, kw_only=True)
class StabilityPoint(Record):
    """The loop's margins at one distinct (position, load) of the requirement set."""

    operating_points: tuple[str, ...] = key(default=(), read=tuple_of(str))
    position: float | None = None  # [m]
    load: float | str | None = None  # N, "curve" or None
    phase_margin_deg: float | None = None
    gain_margin_db: float | None = None
    stable: bool | None = None
    meets: bool | None = None  # None: not linearised
    reason: str | None = None


@dataclass(frozen=True, kw_only=True)
class StabilitySection(Record):
    """Margins at every distinct operating point, the points below the criterion and one sentence."""

    criterion: MarginCriterion = key(factory=MarginCriterion, read=MarginCriterion.from_dict)
    points: tuple[StabilityPoint, ...] = key(default=(), read=records(StabilityPoint))
    below: tuple[str, ...] = key(default=(), read=tuple_of(str))
    summary: str = ""
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def below_points(self) -> tuple[StabilityPoint, ...]:
        """The points whose margins miss the criterion (or whose loop is unstable)."""
        return tuple(p for p in self.points if p.meets is False)
