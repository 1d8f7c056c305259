"""The result of one diagnosis of a servo recording (``Diagnosis``, built once by ``servo.diagnose.diagnose``:
frozen) and its JSON document (docs/diagnosis-schema.md): plain numbers, SI units named.

Also the validation report's ``diagnosis`` entry (``govcheck diagnose --report``,
:func:`validation_with_diagnosis`): the recording validated before and after, the explanation
quoting the fits of the table printed beside it, the winner's parameters grouped by effect.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property


from compliance.effects import EFFECTS
from compliance.diagnosis.servo.instrument_candidates import finding_words
from compliance.diagnosis.verdicts.candidate_set import is_instrument
from compliance.files.jsonable import json_number, jsonable
from compliance.model.config import PlantConfig
from compliance.model.parameters import BASE_BY_KEY
from compliance.diagnosis.servo.candidates import FRICTION_LEVEL
from compliance.diagnosis.evidence.residuals import UNITS
from compliance.diagnosis.servo.selection import RESIDUAL_LIMIT
from compliance.diagnosis.verdicts.candidate_set import CandidateSet
from compliance.diagnosis.verdicts.verdict import DiagnosisVerdict

SCHEMA = "govcheck-diagnosis/1"  # docs/diagnosis-schema.md




def _param_rows(cfg, fit) -> list[dict]:
    rows = []
    for fp, v, e in zip(fit.params, fit.values, fit.stderr):
        if fp.kind == "instrument":  # a finding about the logger or a transducer, not the plant
            rows.append({"name": fp.key, "kind": "instrument", "value": json_number(v), "stderr": json_number(e), "unit": fp.unit,
                         "meaning": "check your instrumentation: " + finding_words(fit), "nominal": json_number(fp.nominal)})
        elif fp.kind == "effect":
            rows.append({"name": fp.key, "kind": "effect", "value": json_number(v), "stderr": json_number(e), "unit": fp.unit,
                         "meaning": EFFECTS[fp.effect].param(fp.name).meaning, "default": json_number(fp.nominal)})
        elif fp.key == FRICTION_LEVEL:
            for key in ("friction.static_force", "friction.coulomb_force"):
                a = cfg.p(key)
                rows.append({"name": key, "kind": "base", "value": json_number(a * v), "stderr": json_number(a * e), "unit": "N",
                             "meaning": BASE_BY_KEY[key].meaning, "nominal": json_number(a)})
        else:
            rows.append({"name": fp.key, "kind": "base", "value": json_number(v), "stderr": json_number(e), "unit": fp.unit,
                         "meaning": BASE_BY_KEY[fp.key].meaning, "nominal": json_number(fp.nominal)})
    return rows


def _lumped_rows(fit, name: str) -> list[dict]:
    """The declared lumped combinations (e.g. a total lag) of the effects in a fit, with errors."""
    rows = []
    for e in CandidateSet.parse(name).terms:
        got = fit.lumped(e) if e in EFFECTS else None
        if got is not None:
            decl = EFFECTS[e].lumped
            rows.append({"name": f"{e}.{decl.name}", "value": json_number(got[0]), "stderr": json_number(got[1]), "unit": decl.unit,
                         "meaning": decl.meaning})
    return rows


def _fit_table(fit: dict | None) -> dict | None:
    if fit is None:
        return None
    return {s: {"rms": json_number(v["rms"]), "unit": UNITS[s], "rms_normalised": json_number(v["rms_normalised"]),
                "nrmse": json_number(v["nrmse"]), "fit_percent": json_number(v["fit_percent"])} for s, v in fit.items()}


def _ambiguity(d) -> dict | None:
    """The explanations the recording cannot tell apart and the test that would (docs/diagnosis-schema.md)."""
    if not d.ambiguous:
        return None
    return {"explanations": list(d.ambiguous),
            "delta_bic": {k: json_number(d.scores[k].bic - d.scores[d.ambiguous[0]].bic) for k in d.ambiguous},
            "suggested_test": jsonable(d.suggested_test)}


def diagnosis_to_dict(d, saved_model: str | None = None) -> dict:
    """Serialise a ``servo.diagnose.Diagnosis`` (see docs/diagnosis-schema.md)."""
    ranked = d.ranked()
    agreement = d.agreement
    effects = []
    for rank, name in enumerate(ranked, start=1):
        f = d.fits[name]
        s = d.scores[name]
        kind = "nominal" if name == "nominal" else "base" if name == "base" else "instrument" if is_instrument(name) else "effect"
        effects.append({
            "rank": rank,
            "name": name,
            "kind": kind,
            "effects": CandidateSet.parse(name).effects,
            "parameters": _param_rows(d.cfg, f),
            "lumped": _lumped_rows(f, name),
            "k": f.k,
            "chi2": json_number(s.chi2),
            "chi2_per_residual": json_number(s.chi2 / f.n) if f.n else None,
            "aic": json_number(s.aic),
            "bic": json_number(s.bic),
            "delta_bic": json_number(s.delta_bic),
            "score": json_number(-s.delta_bic),
            "explained_fraction": json_number(s.explained),
            "window_agreement": json_number(agreement.get(name)) if name != "nominal" else None,
            "simulations": f.sims,
            "seconds": json_number(f.seconds),
        })
    return {
        "schema": SCHEMA,
        "kind": "servo_replay",
        "recording": d.recording,
        "plant": {"name": d.cfg.name, "path": d.cfg.path, "digest": d.cfg.digest},
        "verdict": d.verdict,
        "reason": d.reason,
        "winner": d.winner,
        "runner_up": d.runner_up,
        "explanation": d.explanation,
        "effects": effects,
        "fit_before": _fit_table(d.fit_before),
        "fit_after": _fit_table(d.fit_after),
        "objective_before": {s: json_number(v) for s, v in d.objective_before.items()},
        "objective_after": {s: json_number(v) for s, v in d.objective_after.items()} if d.objective_after else None,
        "noise_floor": {s: {"value": json_number(v), "unit": UNITS[s]} for s, v in d.floors.items()},
        "windows": [
            {k: (json_number(v) if isinstance(v, float) else ({s: json_number(x) for s, x in v.items()} if isinstance(v, dict) else v))
             for k, v in w.items()}
            for w in d.windows
        ],
        "located_regimes": list(d.located_regimes),
        "ambiguity": _ambiguity(d),
        "signals_left": {s: json_number(v) for s, v in d.signals_left.items()},
        "residual_limit": RESIDUAL_LIMIT,
        "contributions": {e: {k: json_number(v) for k, v in c.items()} for e, c in d.contributions.items()},
        "effect_search": jsonable(d.search),
        "empirical": jsonable(d.empirical),
        "split": jsonable(getattr(d, "split", None)),
        "friction_form": jsonable(getattr(d, "friction_form", None)),
        "saved_model": saved_model,
        "notes": list(d.notes),
        "timing": {"seconds": json_number(d.seconds), "simulations": d.simulations, "jobs": d.jobs},
    }


# --------------------------------------------------------------------------- the validation report's entry
def _added(winner: dict) -> list[dict]:
    """The winner's fitted parameters grouped by effect (base parameters as one group), with each effect's meaning."""
    groups: dict[str, list] = {}
    for p in winner["parameters"]:
        group = p["name"].split(".")[0] if p["kind"] == "effect" else "base parameters (recalibrated)"
        groups.setdefault(group, []).append({"name": p["name"].split(".", 1)[1] if p["kind"] == "effect" else p["name"],
                                             "value": p["value"], "unit": p["unit"]})
    return [{"name": g, "meaning": EFFECTS[g].meaning if g in EFFECTS else "", "params": params} for g, params in groups.items()]


def validation_with_diagnosis(cfg, frame, meta: dict, diag, data: dict) -> dict:
    """The validation result of ``frame`` against ``cfg`` with the ``diagnosis`` entry of ``diag``.

    Parameters
    ----------
    cfg : PlantConfig
        The plant the recording was diagnosed against.
    frame, meta
        The recording (``recordings.reader.read_recording``).
    diag : Diagnosis
        The diagnosis (its fitted configuration is validated too, when there is one).
    data : dict
        ``diag.to_dict()`` (explanation, verdict, ranked effects, winner).
    """
    from compliance.diagnosis.servo.explanation import explain_with_table
    from compliance.validation.validate import ValidationSettings, validate

    settings = ValidationSettings(modes=("closed_loop",) if "reference" in frame.columns else ("plant_only",))
    result = validate(cfg, frame, meta, settings)
    entry = {"explanation": data["explanation"], "verdict": data["verdict"], "added": [], "effects_ranked": data["effects"]}
    if diag.fitted_cfg is not None:
        entry["after"] = validate(diag.fitted_cfg, frame, meta, settings)
        mode = settings.modes[0]  # the explanation quotes the fits of the table printed beside it
        entry["explanation"] = explain_with_table(diag, result["modes"][mode]["fits"], entry["after"]["modes"][mode]["fits"])
        entry["added"] = _added(next(e for e in data["effects"] if e["name"] == data["winner"]))
    result["diagnosis"] = entry
    return result


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
