"""What every stage of one servo diagnosis shares: the recording's replay, floors and located windows
(``prepare_recording``), the fits so far and the workers that run them (``Stage``, ``record``), and the
first fits with their speculative second starts (``first_fits``).

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
from compliance.diagnosis.servo.fit import COMPETE, FitResult, chi2_parts, competing
from compliance.diagnosis.servo.parallel_fits import SecondStart, fit_context, run_fits
from compliance.processes import AFTER, AHEAD, PerProcess
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


def record(st: Stage, tasks: list, results: list) -> None:
    """The fits' results (``Stage.run_fits``' (result, residual vector) of each task) into the diagnosis."""
    for task, (res, v) in zip(tasks, results):
        st.sims += res.sims - (task.first.sims if isinstance(task, SecondStart) else 0)  # a second start counts its first fit's too
        st.fits[res.name] = res
        st.vecs[res.name] = v


def first_fits(st: Stage, tasks: list) -> None:
    """The first fits ``tasks``, then a second local fit where it can still matter: a candidate with a second start
    (``FitResult.second_from``) within COMPETE of the best first fit (``fit.competing``).

    The second starts run speculatively on the same workers as the first fits, each once its candidate's first fit
    is known and only while it still competes with the best first fit so far (the best only improves: one that
    stops competing never competes again). One whose first fit is near the floors (chi-square within COMPETE of the
    residual count: it would take a rival halving an already small misfit) starts before the first fits not
    started yet, the others once every first fit has started (our choice of priority: it changes the wall time,
    never a result). Which second starts are used depends on the final first fits only, never on finishing order,
    and only theirs count in the replays.
    """
    firsts: list[FitResult] = []

    def follow(i: int, out) -> list:
        if i >= len(tasks):
            return []
        firsts.append(out[0])
        return [SecondStart(out[0])] if out[0].second_from else []  # the executor asks ``wanted`` before it starts

    def wanted(task: SecondStart) -> int:
        if not any(f is task.first for f in competing(firsts)):
            return 0
        return AHEAD if task.first.chi2 <= COMPETE * st.model.size else AFTER

    out = st.run_fits(tasks, follow, wanted)
    record(st, tasks, out[:len(tasks)])
    speculative = {r.name: (r, v) for (r, v) in (o for o in out[len(tasks):] if o is not None)}
    seconds = [SecondStart(f) for f in competing([f for k, f in st.fits.items() if k != "nominal"]) if f.second_from]
    missing = [t for t in seconds if t.first.name not in speculative]
    speculative.update({r.name: (r, v) for r, v in st.run_fits(missing)} if missing else {})
    record(st, seconds, [speculative[t.first.name] for t in seconds])


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


__all__ = ["Stage", "check_effects", "first_fits", "prepare_recording", "record"]
