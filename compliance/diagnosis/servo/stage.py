"""What every stage of one servo diagnosis shares: the recording's replay, floors and located windows
(``prepare_recording``), the fits so far and the workers that run them (``Stage``).

Stages 1-2 of ``servo.diagnose``: the nominal replay (re-synchronised segments, matched noise), the
residual model with its noise floors, the located windows of the nominal residual and their regimes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from compliance.errors import did_you_mean
from compliance.model.config import PlantConfig, plant_to_toml
from compliance.effects import EFFECTS
from compliance.errors import InputError
from compliance.diagnosis.servo.fit import FitResult, chi2_parts
from compliance.diagnosis.servo.parallel_fits import fit_context, run_fits
from compliance.processes import PerProcess
from compliance.validation.replay import ReplaySetup, prepare_replay, run_replay
from compliance.diagnosis.evidence.residuals import build_residual_model, signal_fit, with_fail_level
from compliance.diagnosis.evidence.locate_misfit import locate_mismatch
from compliance.plants import kind_of


@dataclass
class Stage:
    """What every stage of one diagnosis shares (built once by ``prepare_recording``)."""

    setup: ReplaySetup
    rc: PlantConfig
    nominal_sim: dict
    model: object
    events: list
    event_mask: np.ndarray
    nominal_rms: dict
    nvec: np.ndarray
    payload: tuple
    jobs: int
    fits: dict = field(default_factory=dict)
    vecs: dict = field(default_factory=dict)
    sims: int = 2
    rebased: bool = False  # the friction law's other form is the base (servo/friction_form.py)
    client: object = None  # the run's Dask client (--scheduler); None: the local pool of ``jobs`` processes
    context: PerProcess | None = None  # the workers' fit context (``parallel_fits``), one for every stage

    def run_fits(self, tasks, follow=None, wanted=None) -> list:
        """``parallel_fits.run_fits`` of ``tasks`` (and of the follow-ups ``follow`` adds) on this diagnosis' workers.

        The fit context is built once, here, before the local pool forks: each stage's workers inherit it
        instead of building it from the plant's TOML again (a Dask worker builds its own from the recipe).
        """
        if self.context is None:
            self.context = fit_context(self.payload)
        if self.client is None:
            self.context.get()
        return run_fits(tasks, self.jobs, self.context, client=self.client, follow=follow, wanted=wanted)


def check_effects(cfg: PlantConfig, effects) -> list[str]:
    """Stage 0: the effects to try (``None``: every declared effect the plant does not already have); a name
    that is not declared, or a plant kind whose recordings the replay cannot run (``PlantKind.diagnosis_support``),
    is an ``InputError``."""
    kind_of(cfg).check_diagnosable(cfg)
    names = [e for e in EFFECTS if e not in cfg.effects] if effects is None else list(effects)
    for e in names:
        if e not in EFFECTS:
            raise InputError(f"--effects: '{e}' is not a declared effect{did_you_mean(e, EFFECTS)} (known: {', '.join(EFFECTS)})")
    return names


def prepare_recording(cfg: PlantConfig, frame, meta: dict, stride: int, jobs: int, sims: int = 0, client=None) -> Stage:
    """Stages 1-2: the nominal replay, floors, located windows (``sims``: replays already run for this diagnosis;
    ``client``: the run's Dask client, None for the local pool)."""
    setup = prepare_replay(cfg, frame, meta)
    rc = setup.config(cfg)
    nominal_sim = run_replay(rc, setup)
    model = build_residual_model(rc, setup, stride=stride, nominal=nominal_sim)
    model = with_fail_level(model, model.vector(nominal_sim))
    events, event_mask, _ = locate_mismatch(rc, setup, model.signals, nominal_sim)
    nominal_rms = {s: v["rms_normalised"] for s, v in signal_fit(model, nominal_sim).items()}
    nvec = model.vector(nominal_sim)
    st = Stage(setup, rc, nominal_sim, model, events, event_mask, nominal_rms, nvec, (plant_to_toml(rc), setup, model), jobs,
               client=client)
    st.sims += sims
    chi2, parts = chi2_parts(model, nvec)
    st.fits["nominal"] = FitResult("nominal", (), [], [], chi2, parts, model.size, 0, 0.0, "nominal model")
    return st


__all__ = ["Stage", "check_effects", "prepare_recording"]
