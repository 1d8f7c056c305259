"""The friction law's form as a structural alternative of the base model.

Before hunting for missing physics, a practitioner tries the plant's other declared friction
laws that share the same steady-state map (the same static, Coulomb, Stribeck and viscous
parameters): LuGre bristles (Canudas de Wit 1995) and the variable-viscous law with a stick
phase (seed 000 eq. 7). Switching between them moves the position by up to a millimetre in
the stick-slip regime, several times what most effects move it, and no recalibration of base
parameters absorbs that. The nominal model is replayed once with each alternative form on the
same segments and residual model; an alternative is adopted as the base of the whole search
only when it is a strong, material improvement by the rule every candidate meets against the
nominal model (``servo.selection.beats``): BIC lower by at least ``SIGNIFICANCE`` (no extra parameter,
over-dispersion ``c`` applied) and at least ``MIN_GAIN`` of the nominal excess removed, both
scored with the declared plant's floors (a form's own null floors would flatter the form whose
replay wanders more). Otherwise nothing changes (one extra replay).

A dominant effect can hide the form: a valve lag of 30-50 rad/s makes most of the nominal misfit, so
the other form alone removes little of it, and under the declared form the lag's own fit fails (the
stick band decides where the piston stalls) while a sensor lag stands in for it. So when the declared
form keeps the base and the search's verdict is incomplete (``verdicts.verdict.INCOMPLETE``), the form is tried
again with the effects on (``form_after_effects``): each single-effect fit is replayed with the other
form (one replay each, ``friction_form_check`` with the fit as the nominal), the ``FORM_REFITS`` that
it improves most are refitted under the other form (the declared plant's floors), and the best refit
is adopted by the same rule (``servo.selection.beats``) against the declared form's best candidate (lowest
BIC). A complete verdict pays nothing.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

from compliance.model.config import plant_to_toml
from compliance.model.parameters import apply
from compliance.effects import EFFECTS
from compliance.errors import InputError, SimulationError
from compliance.diagnosis.servo.candidates import effect_candidate
from compliance.diagnosis.servo.fit import chi2_parts
from compliance.validation.replay import run_replay
from compliance.diagnosis.servo.selection import beats, score_all
from compliance.diagnosis.servo.parallel_fits import FitEffect, run_fits

OPTION = "friction.model"
# forms with one steady-state map (same parameters); the piecewise Stribeck law (seed 001 eq. 8)
# has its own parameters, so it is not an alternative form of the same plant
SAME_MAP_FORMS = ("lugre", "variable_viscous")
FORM_REFITS = 4  # single effects refitted under the other form (those its replay improves most)


def friction_form_check(rc, setup, model, nominal_fit) -> dict | None:
    """Replay the nominal with each alternative friction form; say which one, if any, to adopt.

    Parameters
    ----------
    rc : PlantConfig
        The replay configuration of the declared plant.
    setup : ReplaySetup
        Segments of the recording.
    model : ResidualModel
        The residual model of the declared plant (floors, signals).
    nominal_fit : FitResult
        The declared plant's nominal fit (chi2 over ``model.size`` residuals).

    Returns
    -------
    dict or None
        ``{"option", "declared", "tried": {form: chi2}, "chi2_declared", "adopted" (form or None),
        "share_of_excess", "delta_bic", "replays"}``; None when the declared form has no alternative.
    """
    declared = rc.options[OPTION]
    if declared not in SAME_MAP_FORMS:
        return None
    n = model.size
    fits = {"nominal": nominal_fit}
    tried = {}
    for form in SAME_MAP_FORMS:
        if form == declared:
            continue
        try:
            chi2, _ = chi2_parts(model, model.vector(run_replay(rc.replace(options={OPTION: form}), setup)))
        except (SimulationError, InputError):
            continue
        tried[form] = float(chi2)
        fits[form] = SimpleNamespace(chi2=chi2, k=0)
    out = {"option": OPTION, "declared": declared, "tried": tried, "chi2_declared": float(nominal_fit.chi2),
           "adopted": None, "share_of_excess": 0.0, "delta_bic": 0.0, "replays": len(SAME_MAP_FORMS) - 1}
    if not tried:
        return out
    scores = score_all(fits, n)
    best = min(tried, key=tried.get)
    gain_bic = scores["nominal"].bic - scores[best].bic
    out["share_of_excess"], out["delta_bic"] = float(scores[best].explained), float(gain_bic)
    if beats(scores, best, "nominal", n):  # the rule every candidate meets against the nominal model
        out["adopted"] = best
    return out


def form_after_effects(check: dict, rc, setup, model, fits: dict, jobs: int, client=None) -> dict:
    """The other friction form tried again with the single effects on, after an incomplete verdict.

    Parameters
    ----------
    check : dict
        ``friction_form_check`` of the nominal (the declared form kept the base).
    rc, setup, model
        Replay configuration, segments and residual model of the declared plant.
    fits : dict
        Every candidate the declared form's search fitted (name -> FitResult).
    jobs : int
        Worker processes for the refits.
    client : distributed.Client, optional
        The run's Dask client (``processes.dask_session``); None: the local pool.

    Returns
    -------
    dict
        ``check`` with ``adopted`` set when the best refit beats the declared form's best candidate
        (``servo.selection.beats``), ``replays`` counting the retry, and ``after``: ``{"reference", "chi2_reference",
        "screened": {effect: chi2 replayed with the other form}, "refitted": {effect: chi2}, "best",
        "share_of_excess", "delta_bic"}``.
    """
    other = next(iter(check["tried"]), None)  # the other form, when its nominal replay ran
    out = {**check, "after": None}
    if other is None:
        return out
    screened, replays = {}, 0
    for name, f in fits.items():
        if name in EFFECTS and math.isfinite(f.chi2):
            tried = friction_form_check(apply(rc, f.params, f.values), setup, model, f)["tried"]
            replays += 1
            if other in tried and tried[other] < f.chi2:  # the other form helps with this effect on
                screened[name] = tried[other]
    order = sorted(screened, key=screened.get)[:FORM_REFITS]
    payload = (plant_to_toml(rc.replace(options={OPTION: other})), setup, model)
    tasks = [FitEffect(effect_candidate(e)) for e in order]
    refits = {f"{r.name}@{other}": r for r, _ in run_fits(tasks, jobs, payload, client=client)} if tasks else {}
    replays += sum(r.sims + 1 for r in refits.values())
    out["replays"] = check["replays"] + replays
    scores = score_all({**fits, **refits}, model.size)
    ref = min(fits, key=lambda k: scores[k].bic)
    after = {"reference": ref, "chi2_reference": float(fits[ref].chi2), "screened": screened,
             "refitted": {k.split("@")[0]: float(r.chi2) for k, r in refits.items()}, "best": None,
             "share_of_excess": 0.0, "delta_bic": 0.0}
    if refits:
        best = min(refits, key=lambda k: scores[k].bic)
        excess = max(fits[ref].chi2 - model.size, 1e-12)
        after.update(best=best.split("@")[0], share_of_excess=float((fits[ref].chi2 - refits[best].chi2) / excess),
                     delta_bic=float(scores[ref].bic - scores[best].bic))
        if beats(scores, best, ref, model.size):  # the rule every candidate meets against a simpler one
            out["adopted"] = other
    out["after"] = after
    return out


def form_words(check: dict | None) -> str:
    """One sentence for the explanation when an alternative form was adopted (empty otherwise)."""
    if not check or not check.get("adopted"):
        return ""
    a, d = check["adopted"], check["declared"]
    if check.get("after"):  # adopted after the effects were fitted
        af = check["after"]
        return (f" The friction law fits better as {a} than {d}: with {af['best']} refitted under it, the model loses "
                f"{100*af['share_of_excess']:.0f} % of the excess residual {d}'s best explanation ({af['reference']}) "
                f"leaves (BIC lower by {af['delta_bic']:.0f}), so {a} is the base of this diagnosis.")
    return (f" The friction law fits better as {a} than {d}: replayed with it, the nominal model loses "
            f"{100*check['share_of_excess']:.0f} % of its excess residual (BIC lower by {check['delta_bic']:.0f}), "
            f"so {a} is the base of this diagnosis.")
