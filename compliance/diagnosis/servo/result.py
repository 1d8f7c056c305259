"""The result of one diagnosis of a servo recording (``servo.diagnose.diagnose`` builds it once: frozen)."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

from compliance.model.config import PlantConfig
from compliance.diagnosis.servo.report_data import diagnosis_to_dict
from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict


@dataclass(frozen=True)
class Diagnosis:
    """Result of ``diagnose`` (``to_dict`` gives the documented JSON); every field is known when it is built."""

    verdict: DiagnosisVerdict
    reason: str
    winner: str | None
    runner_up: str | None
    fits: dict
    scores: dict
    fit_before: dict
    fit_after: dict
    objective_before: dict
    objective_after: dict
    windows: list
    floors: dict
    cfg: PlantConfig
    fitted_cfg: PlantConfig | None
    recording: str
    seconds: float
    simulations: int
    jobs: int
    notes: list = field(default_factory=list)
    traces: dict = field(default_factory=dict)
    agreement: dict = field(default_factory=dict)  # candidate -> share of its chi-square gain inside the windows
    located_regimes: list = field(default_factory=list)
    ambiguous: list = field(default_factory=list)  # explanations the recording cannot tell apart (winner first)
    signals_left: dict = field(default_factory=dict)  # signal -> normalised RMS above select.RESIDUAL_LIMIT after the winner
    search: list = field(default_factory=list)  # rounds of the multi-effect search (servo/effect_sets.py)
    contributions: dict = field(default_factory=dict)  # effect -> its own contribution in the winning set
    suggested_test: dict | None = None  # discriminate.design_test for an ambiguous recording
    empirical: dict | None = None  # empirical.empirical_term when the library leaves residual
    split: dict | None = None  # split.split_scan: does the recording pin a lag's split or only its total
    friction_form: dict | None = None  # friction_form.friction_form_check: another friction law as the base

    def ranked(self) -> list[str]:
        """Candidate names by BIC, best first (nominal included)."""
        return sorted(self.scores, key=lambda k: self.scores[k].bic)

    @cached_property
    def explanation(self) -> str:
        """The finding in words (``servo.explanation.explain``), written from the fields above when first read."""
        from compliance.diagnosis.servo.explanation import explain

        return explain(self)

    def to_dict(self, saved_model: str | None = None) -> dict:
        """The JSON document of docs/diagnosis-schema.md (``saved_model``: where ``save_fitted`` wrote the fitted plant)."""
        return diagnosis_to_dict(self, saved_model)


__all__ = ["Diagnosis"]
