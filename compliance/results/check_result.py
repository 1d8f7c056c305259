"""The result of ``compliance.check``: one frozen, typed object the terminal, the files, the gate and the report read.

A result is made once (``compliance.pipeline.chain``) or read back from its JSON
(:meth:`CheckResult.from_json`); :meth:`CheckResult.as_dict` gives the JSON object of schema
``govcheck-results/1`` with the keys in the order the records declare, so a file read and written
again is byte-identical. Steps that add to a result (bands, the linear analysis, remedies) return a
new result (:meth:`CheckResult.with_`). docs/results-schema.md.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from compliance.errors import InputError
from compliance.requirements.verdict import Overall, Status
from compliance.results.entries import RequirementVerdict
from compliance.results.evidence import ModelEvidence, StabilitySection
from compliance.results.numbers import check_numbers
from compliance.results.plant import PlantRecord
from compliance.results.record import FrozenDict, Record, freeze, key, need, records
from compliance.results.requirement_set import RequirementSetRecord
from compliance.results.runs import Finding, RunRecord, Timing, Unjudged
from compliance.results.summary import Summary

__all__ = ["RESULTS_SCHEMA", "CheckResult", "Coverage"]

RESULTS_SCHEMA = "govcheck-results/1"


@dataclass(frozen=True, kw_only=True)
class Coverage(Record):
    """Every (run, metric request) with a computed value that no row judged, with the reason; the rule by
    which a requirement's cases make it evaluated (``campaign.judge.EVALUATION_RULE``)."""

    unjudged: tuple[Unjudged, ...] = key(default=(), read=records(Unjudged))
    evaluation_rule: str | None = key(omit_none=True, default=None)


def _section(v, where):
    return freeze(need(v, where))


@dataclass(frozen=True, kw_only=True)
class CheckResult(Record):
    """A plant judged against a requirement set (docs/results-schema.md).

    Attributes
    ----------
    plant, requirement_set : PlantRecord, RequirementSetRecord
        What was judged (operating points with SI positions and loads).
    summary : Summary
        The overall verdict (``summary.status``), counts and qualifiers.
    requirements : tuple of RequirementVerdict
        One verdict per requirement, in file order, each with its rows (SI values and limits).
    runs : tuple of RunRecord
        Every simulation run with its values, traces and marks.
    model_evidence : ModelEvidence or None
        The model's agreement with the measurements its plant file names, and the verdicts they contradict.
    stability : StabilitySection or None
        The linearised loop's margins at every operating point against govcheck's criterion.
    linear, remedies, uncertainty, ... : FrozenDict or None
        Sections kept as their steps wrote them.
    """

    schema: str = key(default=RESULTS_SCHEMA)
    created: str | None = key(default=None)
    command_line: str | None = key(default=None)
    versions: FrozenDict = key(factory=FrozenDict)
    plant: PlantRecord = key(read=PlantRecord.from_dict)
    requirement_set: RequirementSetRecord = key(read=RequirementSetRecord.from_dict)
    summary: Summary = key(read=Summary.from_dict)
    coverage: Coverage = key(factory=Coverage, read=Coverage.from_dict)
    findings: tuple[Finding, ...] = key(default=(), read=records(Finding))
    model_evidence: ModelEvidence | None = key(omit_none=True, default=None, read=ModelEvidence.from_dict)
    stability: StabilitySection | None = key(omit_none=True, default=None, read=StabilitySection.from_dict)
    uncertainty: FrozenDict | None = key(default=None, read=_section)
    requirements: tuple[RequirementVerdict, ...] = key(read=records(RequirementVerdict))
    runs: tuple[RunRecord, ...] = key(default=(), read=records(RunRecord))
    timing: Timing | None = key(omit_none=True, default=None, read=Timing.from_dict)
    linear: FrozenDict | None = key(omit_none=True, default=None, read=_section)
    sweep: FrozenDict | None = key(omit_none=True, default=None, read=_section)
    sizing: FrozenDict | None = key(omit_none=True, default=None, read=_section)
    remedies: FrozenDict | None = key(omit_none=True, default=None, read=_section)
    tolerance_yield: FrozenDict | None = key(omit_none=True, default=None, read=_section)
    validation: FrozenDict | None = key(omit_none=True, default=None, read=_section)
    reproducible: bool | None = key(omit_none=True, default=None)
    extra: FrozenDict = key(factory=FrozenDict)

    # ------------------------------------------------------------------ reading
    @classmethod
    def from_dict(cls, data, where: str = "results") -> "CheckResult":
        """The result of a results JSON object; the operating points get their SI positions and loads.

        Raises
        ------
        InputError
            Not a results object of schema ``govcheck-results/1``, or a missing / mistyped key (named with its path).
        """
        need(data, where)
        if "schema" not in data:
            raise InputError(f"{where}: key 'schema' is missing (expected a govcheck results file, schema "
                             f"'{RESULTS_SCHEMA}')")
        if data["schema"] != RESULTS_SCHEMA:
            raise InputError(f"{where}: key 'schema' is '{data['schema']}'; this govcheck reads '{RESULTS_SCHEMA}' "
                             "(re-run 'govcheck check' to regenerate the results)")
        check_numbers(data, where)
        return super().from_dict(data, where).resolved()

    @classmethod
    def of(cls, results: dict) -> "CheckResult":
        """The typed form of a results dict this process just made (``campaign.run.assemble``): no file checks."""
        return super().from_dict(results, "results").resolved()

    @classmethod
    def from_json(cls, path) -> "CheckResult":
        """Read a results file written by ``govcheck check --json`` (or ``to_json``)."""
        from compliance.files.jsonable import read_json

        return cls.from_dict(read_json(Path(path), "results"), str(path))

    def resolved(self) -> "CheckResult":
        """This result with every operating point's position and load in SI (from the plant's stroke)."""
        return replace(self, requirement_set=self.requirement_set.resolved(self.plant.stroke,
                                                                           self.plant.value("load.nominal_force")))

    # ------------------------------------------------------------------ writing
    def json_text(self) -> str:
        """The results JSON (compact: the traces make up most of it; tools, not people, read it)."""
        from compliance.files.jsonable import json_text

        return json_text(self.as_dict(), compact=True)

    def to_json(self, path) -> None:
        """Write the results JSON atomically; gzip-compressed when ``path`` ends in ``.gz``."""
        from compliance.files.atomic import write_text_atomic

        write_text_atomic(path, self.json_text())

    def made_reproducible(self, command_line: str | None = None) -> "CheckResult":
        """This result as ``--reproducible`` writes it: fixed ``created``, no timings, ``command_line`` replaced."""
        from compliance.files.reproducible import make_reproducible

        return CheckResult.of(make_reproducible(self.as_dict(), command_line))

    # ------------------------------------------------------------------ steps
    def with_(self, **changes) -> "CheckResult":
        """A new result with some sections replaced (a step's output; JSON sections are frozen)."""
        sections = {"uncertainty", "linear", "sweep", "sizing", "remedies", "tolerance_yield", "validation", "versions"}
        return replace(self, **{k: freeze(v) if k in sections and v is not None else v for k, v in changes.items()})

    # ------------------------------------------------------------------ questions
    @property
    def status(self) -> Overall:
        """The overall verdict."""
        return self.summary.status

    @property
    def passed(self) -> bool:
        """Whether every mandatory requirement passes with evidence."""
        return self.summary.status == Overall.PASS

    @property
    def linear_section(self):
        """The linear analysis as records (:class:`~compliance.results.linear.LinearSection`), or None when not run."""
        from compliance.results.linear import LinearSection

        return LinearSection.from_dict(self.linear, "results.linear") if self.linear else None

    @property
    def wall(self) -> float:
        """Wall time of the check [s] (0 in a reproducible result)."""
        return self.timing.wall if self.timing is not None else 0.0

    @property
    def verdicts(self) -> dict[str, RequirementVerdict]:
        """Requirement id -> its verdict."""
        return {e.id: e for e in self.requirements}

    def run(self, run_id: str) -> RunRecord | None:
        """The run ``procedure@operating_point`` (None when it was not simulated)."""
        return next((r for r in self.runs if r.id == run_id), None)

    def failed(self) -> tuple[RequirementVerdict, ...]:
        """The requirements that fail."""
        return tuple(e for e in self.requirements if e.status == Status.FAIL)
