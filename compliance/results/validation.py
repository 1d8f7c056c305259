"""A model validation (and a diagnosis) as the report reads it: schema ``govcheck.validation/1``.

``govcheck validate`` and ``govcheck diagnose`` write the document; a check's result may carry
one (``CheckResult.validation``). These records read it once, with every optional key's default
declared here (SI; errors per unit of each signal's base where the name says ``_pu``).
docs/validation.md gives the keys.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.results.record import FrozenDict, Record, key, optional, records, tuple_of

__all__ = ["DiagnosisRecord", "FittedEffect", "FittedParameter", "LocatedWindow", "Overlay", "RankedEffect",
           "ReplayMode", "SignalFit", "ValidationRecord", "WindowMetric"]


def _map_of(cls):
    """Reader of ``{name: object}`` -> ``FrozenDict`` of records."""
    return lambda v, where: FrozenDict({k: cls.from_dict(x, f"{where}.{k}") for k, x in v.items()})


@dataclass(frozen=True, kw_only=True)
class Overlay(Record):
    """A signal recorded and replayed: time [s] and values [its SI unit]."""

    time: tuple = ()
    recorded: tuple = ()
    simulated: tuple = ()
    unit: str = ""
    role: str | None = None
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class SignalFit(Record):
    """How well a replay fits one signal: fit [%], normalised RMS, RMS and largest error [SI]."""

    fit_percent: float | None = None
    nrmse: float | None = None
    rms_error: float | None = None
    max_abs_error: float | None = None
    unit: str = ""
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class WindowMetric(Record):
    """Errors of one signal in one window of the test [per unit], against the window kind's limits."""

    window: str | None = None
    kind: str | None = None
    start: float | None = None
    signal: str | None = None
    max_error: float | None = None
    mean_absolute_error: float | None = None
    limits: FrozenDict = key(factory=FrozenDict)
    passed: bool | None = key("pass", default=None)
    failed: tuple[str, ...] = key(default=(), read=tuple_of(str))
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class LocatedWindow(Record):
    """Where the replay misses one signal [s], how strongly, and the regimes that dominate there."""

    signal: str | None = None
    start: float | None = None
    end: float | None = None
    peak_ratio: float | None = None
    dominant: tuple[str, ...] = key(default=(), read=tuple_of(str))
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class ReplayMode(Record):
    """One replay of the recording (closed loop, or the recorded valve command into the plant)."""

    overlays: FrozenDict = key(factory=FrozenDict, read=_map_of(Overlay))
    fits: FrozenDict = key(factory=FrozenDict, read=_map_of(SignalFit))
    window_metrics: tuple[WindowMetric, ...] = key(default=(), read=records(WindowMetric))
    located_windows: tuple[LocatedWindow, ...] = key(default=(), read=records(LocatedWindow))
    passed: bool | None = key("pass", default=None)
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class FittedParameter(Record):
    """A parameter fitted by a diagnosis: SI value, unit, standard error and meaning."""

    name: str = ""
    value: float | None = None
    unit: str = ""
    stderr: float | None = None
    meaning: str = ""
    bounds: tuple = ()
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class FittedEffect(Record):
    """A piece of physics a diagnosis added, with its fitted parameters."""

    name: str = ""
    meaning: str = ""
    params: tuple[FittedParameter, ...] = key(default=(), read=records(FittedParameter))
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class RankedEffect(Record):
    """A candidate explanation as the diagnosis ranked it (BIC difference to the best, fitted parameters)."""

    name: str = ""
    delta_bic: float | None = None
    parameters: tuple[FittedParameter, ...] = key(default=(), read=records(FittedParameter))
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class ValidationRecord(Record):
    """A recording replayed with the model: the replays, what they miss, and a diagnosis when one was run."""

    schema: str = "govcheck.validation/1"
    created: str | None = None
    tool: FrozenDict = key(factory=FrozenDict)  # {name, version} of the govcheck that wrote it
    recording: FrozenDict = key(factory=FrozenDict)
    plant: FrozenDict = key(factory=FrozenDict)
    conditions: FrozenDict = key(factory=FrozenDict)
    settings: FrozenDict = key(factory=FrozenDict)
    windows: tuple = ()
    modes: FrozenDict = key(factory=FrozenDict, read=_map_of(ReplayMode))
    summary: FrozenDict = key(factory=FrozenDict)
    warnings: tuple[str, ...] = key(default=(), read=tuple_of(str))
    diagnosis: "DiagnosisRecord | None" = key(default=None, read=lambda v, where: optional(DiagnosisRecord)(v, where))
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def passed(self) -> bool | None:
        """The validation's overall pass (None when not decided)."""
        return self.summary.get("pass")


@dataclass(frozen=True, kw_only=True)
class DiagnosisRecord(Record):
    """What a diagnosis concluded: the verdict, the ranked explanations, the physics added, the replay after."""

    verdict: str | None = None
    winner: str | None = None
    effects_ranked: tuple[RankedEffect, ...] = key(default=(), read=records(RankedEffect))
    added: tuple[FittedEffect, ...] = key(default=(), read=records(FittedEffect))
    effects: tuple[FittedEffect, ...] = key(default=(), read=records(FittedEffect))
    explanation: str | None = None
    after: ValidationRecord | None = key(default=None, read=optional(ValidationRecord))
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def physics_added(self) -> tuple[FittedEffect, ...]:
        """The effects added with their fitted parameters."""
        return self.added or self.effects

    @property
    def ranked_winner(self) -> RankedEffect | None:
        """The winning explanation among the ranked ones (the first when none is named)."""
        named = next((e for e in self.effects_ranked if e.name == self.winner), None)
        return named or (self.effects_ranked[0] if self.effects_ranked else None)
