"""The validation report of a servo diagnosis: the recording replayed before and after, with what the diagnosis added.

``govcheck diagnose --report`` renders the model-validation report of the recording with a
``diagnosis`` entry (docs/diagnosis-schema.md, ``render_validation_report``): the validation of
the nominal model, the validation of the fitted one (``after``), the explanation quoting the fits
of the table printed beside it, and the winning candidate's parameters grouped by effect.
"""

from __future__ import annotations

__all__ = ["validation_with_diagnosis"]


def _added(winner: dict) -> list[dict]:
    """The winner's fitted parameters grouped by effect (base parameters as one group), with each effect's meaning."""
    from compliance.effects import EFFECTS

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
    diag : diagnosis.engine.Diagnosis
        The diagnosis (its fitted configuration is validated too, when there is one).
    data : dict
        ``diag.to_dict()`` (explanation, verdict, ranked effects, winner).
    """
    from compliance.diagnosis.explain import explain_with_table
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
