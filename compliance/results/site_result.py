"""A site's measured verdicts as the gate and JUnit read them: ``govcheck accept``'s results (``govcheck-site/1``).

Its ``requirements[]`` are check's verdicts (:class:`~compliance.results.RequirementVerdict` with basis
``measured``; the measured value's uncertainty and the model's prediction in each record's ``extra``),
so a site's verdicts and a check's compare and report alike. docs/acceptance.md gives every key.
"""

from __future__ import annotations

from dataclasses import dataclass

from compliance.errors import InputError
from compliance.results.check_result import RESULTS_SCHEMA, CheckResult
from compliance.results.entries import RequirementVerdict
from compliance.results.numbers import check_numbers
from compliance.results.plant import PlantRecord
from compliance.results.record import FrozenDict, Record, key, need, records
from compliance.results.requirement_set import RequirementSetRecord
from compliance.results.summary import Summary

__all__ = ["SITE_SCHEMA", "SiteResult", "typed_results"]

SITE_SCHEMA = "govcheck-site/1"


@dataclass(frozen=True, kw_only=True)
class SiteResult(Record):
    """A site's commissioning recordings judged by a requirement file (read back from its JSON)."""

    schema: str = SITE_SCHEMA
    created: str | None = None
    command_line: str | None = None
    versions: FrozenDict = key(factory=FrozenDict)
    site: FrozenDict = key(factory=FrozenDict)  # {name, path, digest, recordings: [...]}
    plant: PlantRecord = key(read=PlantRecord.from_dict)
    requirement_set: RequirementSetRecord = key(read=RequirementSetRecord.from_dict)
    summary: Summary = key(read=Summary.from_dict)
    requirements: tuple[RequirementVerdict, ...] = key(read=records(RequirementVerdict))
    diagnosis: FrozenDict | None = None
    timing: FrozenDict = key(factory=FrozenDict)
    reproducible: bool | None = key(omit_none=True, default=None)
    extra: FrozenDict = key(factory=FrozenDict)

    @property
    def verdicts(self) -> dict[str, RequirementVerdict]:
        """Requirement id -> its verdict."""
        return {e.id: e for e in self.requirements}

    @property
    def wall(self) -> float:
        """Wall time of the acceptance run [s] (0 when not recorded)."""
        return self.timing.get("wall") or 0.0


def typed_results(data, where: str = "results"):
    """A results JSON object as its record: a check's (:class:`CheckResult`) or a site's (:class:`SiteResult`).

    Raises
    ------
    InputError
        Not a govcheck results object of a supported schema, or a missing / mistyped key (named with its path).
    """
    need(data, where)
    schema = data.get("schema")
    if schema == SITE_SCHEMA:
        check_numbers(data, where)
        return SiteResult.from_dict(data, where)
    if schema is None:
        raise InputError(f"{where}: key 'schema' is missing; expected a govcheck results file ('{RESULTS_SCHEMA}' or "
                         f"'{SITE_SCHEMA}')")
    if schema != RESULTS_SCHEMA:
        raise InputError(f"{where}: key 'schema' is '{schema}'; this govcheck reads '{RESULTS_SCHEMA}' or "
                         f"'{SITE_SCHEMA}' (re-run 'govcheck check' to regenerate the results)")
    return CheckResult.from_dict(data, where)
