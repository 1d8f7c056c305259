"""The typed result of a check: frozen records the terminal, the files, the gate, the sweeps and the report read.

``CheckResult`` holds the plant and requirement set as judged, the summary, one
``RequirementVerdict`` per requirement with its ``VerdictRow``s (SI values, limits and margins;
``Status``/``Basis``/``Severity`` enums; ``RequestKey`` tuples) and the runs. Its JSON (schema
``govcheck-results/1``) is written by ``as_dict``/``to_json`` and read by ``from_json``, the edge. A site's
measured verdicts (``govcheck accept``, ``govcheck-site/1``) read into a ``SiteResult`` with the same verdicts;
the linear, validation and remedies sections a result carries read into records of their own
(``results.linear``, ``results.validation``, ``results.remedies``); the model's evidence and the
loop's stability margins are records of the result (``results.evidence``).
"""

from compliance.results.check_result import RESULTS_SCHEMA, CheckResult, Coverage
from compliance.results.entries import EntryCoverage, RequirementVerdict
from compliance.results.evidence import (ComparedFigure, ContradictedVerdict, EvidenceSource, ModelEvidence, StabilityPoint,
                                         StabilitySection)
from compliance.results.keys import RequestKey
from compliance.results.plant import EffectRecord, LoadCurve, ParameterRecord, PlantRecord
from compliance.results.requirement_set import (OperatingPointRecord, ProcedureRecord, RequirementSetRecord,
                                                RequirementSpec)
from compliance.results.rows import Band, RowTexts, SampleRecord, VerdictRow, WorstCase
from compliance.results.runs import Finding, Mark, RunRecord, Timing, Trace, Unjudged
from compliance.results.site_result import SITE_SCHEMA, SiteResult, typed_results
from compliance.results.summary import Counts, Qualifier, Summary

__all__ = ["RESULTS_SCHEMA", "SITE_SCHEMA", "Band", "CheckResult", "ComparedFigure", "ContradictedVerdict", "Counts",
           "Coverage", "EffectRecord", "EntryCoverage", "EvidenceSource", "Finding", "LoadCurve", "Mark",
           "ModelEvidence", "OperatingPointRecord", "ParameterRecord", "PlantRecord", "ProcedureRecord", "Qualifier",
           "RequestKey", "RequirementSetRecord", "RequirementSpec", "RequirementVerdict", "RowTexts", "RunRecord",
           "SampleRecord", "SiteResult", "StabilityPoint", "StabilitySection", "Summary", "Timing", "Trace",
           "Unjudged", "VerdictRow", "WorstCase", "typed_results"]
