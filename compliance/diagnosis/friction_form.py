"""The friction law's form as a structural alternative of the base model.

Before hunting for missing physics, a practitioner tries the plant's other declared friction
laws that share the same steady-state map (the same static, Coulomb, Stribeck and viscous
parameters): LuGre bristles (Canudas de Wit 1995) and the variable-viscous law with a stick
phase (seed 000 eq. 7). Switching between them moves the position by up to a millimetre in
the stick-slip regime, several times what most effects move it, and no recalibration of base
parameters absorbs that. The nominal model is replayed once with each alternative form on the
same segments and residual model; an alternative is adopted as the base of the whole search
only when it is a strong, material improvement by the rule every candidate meets against the
nominal model (``select.beats``): BIC lower by at least ``SIGNIFICANCE`` (no extra parameter,
over-dispersion ``c`` applied) and at least ``MIN_GAIN`` of the nominal excess removed, both
scored with the declared plant's floors (a form's own null floors would flatter the form whose
replay wanders more). Otherwise nothing changes (one extra replay).
"""

from __future__ import annotations

from types import SimpleNamespace

from compliance.errors import InputError, SimulationError
from compliance.diagnosis.fit import chi2_parts
from compliance.diagnosis.replay_fit import run_replay
from compliance.diagnosis.select import MIN_GAIN, SIGNIFICANCE, beats, score_all

OPTION = "friction.model"
# forms with one steady-state map (same parameters); the piecewise Stribeck law (seed 001 eq. 8)
# has its own parameters, so it is not an alternative form of the same plant
SAME_MAP_FORMS = ("lugre", "variable_viscous")


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


def form_words(check: dict | None) -> str:
    """One sentence for the explanation when an alternative form was adopted (empty otherwise)."""
    if not check or not check.get("adopted"):
        return ""
    a, d = check["adopted"], check["declared"]
    return (f" The friction law fits better as {a} than {d}: replayed with it, the nominal model loses "
            f"{100*check['share_of_excess']:.0f} % of its excess residual (BIC lower by {check['delta_bic']:.0f}), "
            f"so {a} is the base of this diagnosis.")
