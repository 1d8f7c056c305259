"""The result of one diagnosis of a servo recording (``servo.diagnose.diagnose`` builds it)."""

from __future__ import annotations

from dataclasses import dataclass, field

from compliance.model.config import PlantConfig
from compliance.diagnosis.servo.report_data import diagnosis_to_dict


@dataclass
class Diagnosis:
    """Result of ``diagnose`` (``to_dict`` gives the documented JSON)."""

    verdict: str
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
    explanation: str
    cfg: PlantConfig
    fitted_cfg: PlantConfig | None
    recording: str
    seconds: float
    simulations: int
    jobs: int
    notes: list = field(default_factory=list)
    traces: dict = field(default_factory=dict)
    saved_model: str | None = None
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

    def to_dict(self) -> dict:
        """The JSON document of docs/diagnosis-schema.md."""

        return diagnosis_to_dict(self)


__all__ = ["Diagnosis"]
