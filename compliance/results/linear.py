"""The linear analysis of a check as the report reads it (schema ``govcheck-linear/1``, ``govcheck linear --json``).

The section is written as the linear step made it (``CheckResult.linear``); these records read it
once, with every optional key's default declared here, so the report and ``govcheck linear --plot``
read attributes (SI: m, N, s, Hz, dB, deg). docs/linear.md gives the keys.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.results.record import FrozenDict, Record, key, optional, records, tuple_of

__all__ = ["Bode", "CrossCheckRow", "GovernorBasis", "GovernorRecord", "LinearAnalysisRecord", "LinearFigures",
           "LinearPoint", "LinearSection", "OperatingMapRecord", "Poles", "PredictedStep"]


@dataclass(frozen=True, kw_only=True)
class LinearPoint(Record):
    """Where the plant was trimmed: position [m], load (N, "curve" or None) and the constant force there [N]."""

    position: float | None = None
    load: float | str | None = None
    load_force: float | None = None
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def load_key(self):
        """The load as a comparison key: its kind for a curve or none, else the force to 0.1 N."""
        return self.load if isinstance(self.load, str) or self.load is None else round(self.load, 1)


@dataclass(frozen=True, kw_only=True)
class LinearFigures(Record):
    """The closed loop's headline figures at one point."""

    time_constant: float | None = None  # [s]
    gain_margin_db: float | None = None
    phase_margin_deg: float | None = None
    bandwidth_hz: float | None = None
    damping_ratio: float | None = None
    natural_frequency_hz: float | None = None
    gain_crossover_hz: float | None = None
    stable: bool | None = None
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class Bode(Record):
    """Loop and closed-loop frequency responses (frequency [Hz], magnitude [dB], phase [deg])."""

    frequency_hz: tuple = ()
    loop_magnitude_db: tuple = ()
    loop_phase_deg: tuple = ()
    loop_discrete_magnitude_db: tuple = ()
    loop_discrete_phase_deg: tuple = ()
    closed_loop_magnitude_db: tuple = ()
    closed_loop_phase_deg: tuple = ()
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def loop_magnitude(self) -> tuple:
        """The sampled loop's magnitude where given, else the continuous loop's [dB]."""
        return self.loop_discrete_magnitude_db or self.loop_magnitude_db

    @property
    def loop_phase(self) -> tuple:
        """The sampled loop's phase where given, else the continuous loop's [deg]."""
        return self.loop_discrete_phase_deg or self.loop_phase_deg


@dataclass(frozen=True, kw_only=True)
class Poles(Record):
    """Poles and zeros as (real [1/s], imaginary [rad/s]) pairs."""

    closed_loop: tuple = ()
    closed_loop_zeros: tuple = ()
    plant_minimal: tuple = ()
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class PredictedStep(Record):
    """The linear loop's answer to a step of ``size`` [m]: time [s] and position [m], sampled and continuous."""

    size: float = 0.0
    time: tuple = ()
    position: tuple = ()
    time_continuous: tuple = ()
    position_continuous: tuple = ()
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class LinearAnalysisRecord(Record):
    """The linearised plant and closed loop at one operating point."""

    label: str | None = None
    operating_point: LinearPoint = key(factory=LinearPoint, read=LinearPoint.from_dict)
    figures: LinearFigures = key(factory=LinearFigures, read=LinearFigures.from_dict)
    bode: Bode = key(factory=Bode, read=Bode.from_dict)
    poles: Poles = key(factory=Poles, read=Poles.from_dict)
    step: PredictedStep | None = key(default=None, read=optional(PredictedStep))
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def point_key(self) -> tuple:
        """(position to 1 um, load key): analyses at one key stand for one point."""
        x = self.operating_point.position
        return (round(x, 6) if isinstance(x, (int, float)) else None, self.operating_point.load_key)


@dataclass(frozen=True, kw_only=True)
class OperatingMapRecord(Record):
    """Linear figures over stroke x load: ``values[name][i][j]`` at load i, position j (None: no trim)."""

    positions: tuple[float, ...] = ()
    loads: tuple = ()
    values: FrozenDict = key(factory=FrozenDict)
    window: tuple | None = None  # the time constant's requirement window [s]
    notes: tuple[str, ...] = key(default=(), read=tuple_of(str))
    extra: FrozenDict = key(factory=FrozenDict)

    def minimum(self, name: str):
        """(smallest value of quantity ``name``, its position [m], its load) or None."""
        grid = self.values.get(name)
        if not grid:
            return None
        loads = self.loads or (None,) * len(grid)
        cells = [(v, self.positions[j], loads[i]) for i, row in enumerate(grid) for j, v in enumerate(row)
                 if isinstance(v, (int, float))]
        return min(cells, key=lambda c: c[0]) if cells else None


@dataclass(frozen=True, kw_only=True)
class CrossCheckRow(Record):
    """A small step simulated with the nonlinear model beside the linear time constant at a critical point."""

    position: float | None = None
    load: float | str | None = None
    load_force: float | None = None
    step: float | None = None  # fraction of the stroke
    tau_linear: float | None = None
    tau_nonlinear: float | None = None
    ratio: float | None = None
    steady_error: float | None = None
    why: str | None = None
    skipped: str | None = None
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class GovernorBasis(Record):
    """Where the HYGOV figures come from: the Tg steps (at ``Tg_point``, their fractions of the stroke and
    nonlinear time constants [s]) and the strokes behind UO and UC, or the export's own sentences."""

    sentences: tuple[str, ...] = key(default=(), read=tuple_of(str))
    Tg_point: LinearPoint = key(factory=LinearPoint, read=LinearPoint.from_dict)
    Tg_steps: tuple[float, ...] = ()
    Tg_nonlinear_samples: tuple = ()
    stroke_runs: FrozenDict = key(factory=FrozenDict)  # {opening: {stroke_time, ...}, closing: {...}, load}
    extra: FrozenDict = key(factory=FrozenDict)

    def stroke_time(self, direction: str):
        """The closed-loop stroke time [s] of ``direction`` (opening / closing), None when not run."""
        return (self.stroke_runs.get(direction) or {}).get("stroke_time")


@dataclass(frozen=True, kw_only=True)
class GovernorRecord(Record):
    """The equivalent HYGOV gate-servo parameters and where they come from."""

    model: str = "HYGOV"
    parameters: FrozenDict = key(factory=FrozenDict)
    rate_limits: FrozenDict = key(factory=FrozenDict)
    units: FrozenDict = key(factory=FrozenDict)
    Tg_linear: float | None = None
    basis: GovernorBasis = key(factory=GovernorBasis, read=GovernorBasis.from_dict)
    extra: FrozenDict = key(factory=FrozenDict)


@dataclass(frozen=True, kw_only=True)
class LinearSection(Record):
    """A linear analysis document: one analysis (``govcheck linear``) or one per operating point (a check)."""

    schema: str = "govcheck-linear/1"
    analyses: tuple[LinearAnalysisRecord, ...] = key(default=(), read=records(LinearAnalysisRecord))
    analysis: LinearAnalysisRecord | None = key(default=None, read=optional(LinearAnalysisRecord))
    map: OperatingMapRecord | None = key(default=None, read=optional(OperatingMapRecord))
    crosscheck: tuple[CrossCheckRow, ...] = key(default=(), read=records(CrossCheckRow))
    governor: GovernorRecord | None = key(default=None, read=optional(GovernorRecord))
    notes: tuple[str, ...] = key(default=(), read=tuple_of(str))
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def all_analyses(self) -> tuple[LinearAnalysisRecord, ...]:
        """Every analysis of the document."""
        return self.analyses or ((self.analysis,) if self.analysis is not None else ())
