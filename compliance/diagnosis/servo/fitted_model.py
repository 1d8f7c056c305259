"""The fitted plant a diagnosis hands back: the winner's values on the nominal plant, with provenance."""

from __future__ import annotations

from datetime import datetime, timezone
from pathlib import Path

from compliance.errors import InputError
from compliance.model.config import PlantConfig, save_plant
from compliance.diagnosis.servo.candidates import expand_base
from compliance.diagnosis.servo.fit import FitResult


def fitted_plant(cfg: PlantConfig, fit: FitResult, meta: dict) -> PlantConfig:
    """The plant (not the test's controller overrides) with the winner's values, with provenance."""
    params = expand_base(cfg, fit.params, fit.values)
    effects: dict[str, dict] = {}
    for fp, v in zip(fit.params, fit.values):
        if fp.kind == "effect":
            effects.setdefault(fp.effect, {})[fp.name] = v
    prov = dict(cfg.provenance)
    prov.update({
        "fitted_by": "govcheck diagnose",
        "parent": str(cfg.path or cfg.name),
        "parent_digest": cfg.digest or "(in-memory configuration)",
        "recording": str(meta.get("source_path", "<recording>")),
        "date": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "explanation": fit.name,
    })
    return cfg.replace(params=params or None, effects=effects or None, provenance=prov,
                       sources={k: "derived" for k in params}, name=f"{cfg.name}-fitted")


def save_fitted(diag, path) -> Path:
    """Write the fitted configuration (never overwrites; ``save_plant`` refuses)."""
    if diag.fitted_cfg is None:
        raise InputError(f"{path}: nothing to save: the verdict is '{diag.verdict}' (no fitted model)")
    out = save_plant(diag.fitted_cfg, path)
    diag.saved_model = str(out)
    return out


__all__ = ["fitted_plant", "save_fitted"]
