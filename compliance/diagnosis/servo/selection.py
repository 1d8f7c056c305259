"""Which explanation the data support: information criteria on normalised residuals, and the verdict.

Each candidate j (the nominal model, the base recalibration, each effect) has a chi-square
chi2_j of its normalised residuals (N of them) and k_j fitted parameters. Residuals of an
imperfect model are not white noise, so the chi-squares are first divided by the
over-dispersion c = max(1, min_j chi2_j / (N - k_j)) (quasi-likelihood, Burnham & Anderson
2002 sec. 6.2) and then

    BIC_j = chi2_j / c + k_j ln N          (Schwarz 1978, Gaussian errors of known scale)
    AIC_j = chi2_j / c + 2 k_j              (Akaike 1974)

The lowest BIC wins. A candidate must also *matter*: lower the chi-square of the simpler
explanation by at least ``MIN_GAIN`` of that explanation's excess over the noise floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# nominal normalised RMS at or below which a signal agrees "within the noise floor", judged on the re-synchronised
# replay with the time-resolved floors (the fits' objective, as RESIDUAL_LIMIT is). Not on the constant floor: a
# stick-slip servo's replay error comes in noise-decided bursts at breakaways, so one recording's RMS over the test
# against the bootstrap's mean level varies 0.6-2.3 x between noise draws of the same model (20 null recordings
# of plant A: 6 above 1.5 on the constant floor, 1.01-1.35 on the time-resolved one but for one with a single
# 0.2 mm burst; generated effect cases 3.2 and up)
NOISE_TOLERANCE = 1.5
SIGNIFICANCE = 10.0  # BIC difference counted as strong evidence (Kass & Raftery 1995)
MIN_GAIN = 0.25  # share of the simpler model's excess chi-square a more complex one must remove
EXPLAINED_ENOUGH = 0.5  # share of the nominal excess the winner must remove, else "unexplained"
# an explanation is complete only when it brings every signal's re-synchronised residual to within this
# multiple of its noise floor (normalised RMS; chi2/N per signal <= 4): the null bootstrap's floors are what
# a correct model leaves, so a complete explanation sits near 1 and model-form differences of an
# independent bench add a little; above it the verdict is "partially_explained" naming the signals left
RESIDUAL_LIMIT = 2.0
AMBIGUOUS_BIC = SIGNIFICANCE  # explanations within this BIC of the winner are not told apart by the recording
# ... nor are two that both bring every signal within RESIDUAL_LIMIT with chi-squares within this ratio: the
# BIC counts every residual as independent, while a replay's misfit comes in correlated bursts (the
# Newey-West factor of servo/fit.py is 5-30), so a BIC gap between two explanations that both sit at the
# noise floor measures model-form detail of the bench, not physics
AMBIGUOUS_RATIO = 1.5


@dataclass(frozen=True)
class Score:
    """Information criteria of one candidate."""

    name: str
    chi2: float
    k: int
    aic: float
    bic: float
    delta_bic: float = 0.0
    explained: float = 0.0  # share of the nominal excess chi-square (chi2 - N) removed, at most 1


def score_all(fits: dict, n: int) -> dict[str, Score]:
    """Scores of every fitted candidate (``fits``: name -> FitResult with chi2 and k)."""
    finite = [f for f in fits.values() if math.isfinite(f.chi2)]
    c = max(1.0, min(f.chi2 / max(n - f.k, 1) for f in finite)) if finite else 1.0
    nom = fits.get("nominal")
    excess_nom = max(nom.chi2 - n, 0.0) if nom is not None else 0.0
    raw = {}
    for name, f in fits.items():
        q = f.chi2 / c
        raw[name] = (f.chi2, f.k, q + 2 * f.k, q + f.k * math.log(n))
    best = min((v[3] for v in raw.values()), default=0.0)
    out = {}
    for name, (chi2, k, aic, bic) in raw.items():
        explained = (nom.chi2 - chi2) / excess_nom if excess_nom > 0 and math.isfinite(chi2) else 0.0
        explained = min(explained, 1.0)  # a fit below the floor estimate has explained all of the excess
        out[name] = Score(name, chi2, k, aic, bic, bic - best, explained)
    return out


def beats(scores, a: str, b: str, n: int) -> bool:
    """True when candidate ``a`` is a significant, material improvement on the simpler ``b``."""
    sa, sb = scores[a], scores[b]
    if sb.bic - sa.bic < SIGNIFICANCE:
        return False
    excess = max(sb.chi2 - n, 0.0)
    return excess > 0 and (sb.chi2 - sa.chi2) >= MIN_GAIN * excess



def verdict(scores: dict[str, Score], n: int, nominal_rms: dict, effect_names) -> tuple[str, str | None, str]:
    """Decide the verdict.

    Parameters
    ----------
    scores : dict
        name -> Score (must contain ``nominal``; ``base`` and effects when fitted).
    n : int
        Number of residuals.
    nominal_rms : dict
        Signal -> normalised RMS of the nominal's re-synchronised replay with the time-resolved
        floors (the objective of the fits; see ``NOISE_TOLERANCE``).
    effect_names : iterable of str
        Candidates that are missing physics (effects and effect + recalibration combinations).

    Returns
    -------
    (verdict, winner, reason)
        ``no_mismatch`` | ``parameters_only`` | ``missing_physics`` | ``unexplained``; the
        winning candidate (None for no_mismatch); a one-line reason.
    """
    effect_names = [e for e in effect_names if e in scores]
    within = max(nominal_rms.values(), default=0.0) <= NOISE_TOLERANCE
    ref = "nominal"
    if "base" in scores and beats(scores, "base", "nominal", n):
        ref = "base"
    best_eff = min(effect_names, key=lambda e: scores[e].bic, default=None)
    winner = ref
    if best_eff is not None and beats(scores, best_eff, ref, n):
        winner = best_eff
    elif best_eff is not None and ref == "base" and scores[best_eff].bic < scores["base"].bic and beats(scores, best_eff, "nominal", n):
        winner = best_eff  # the effect explains what the recalibration does, more cheaply
    if within:
        return "no_mismatch", None, (
            f"the nominal model already fits to within the noise floor (largest normalised RMS "
            f"{max(nominal_rms.values()):.2f} <= {NOISE_TOLERANCE})")
    if winner == "nominal":
        return "unexplained", None, "the nominal model misses the recording and no candidate improves it significantly"
    if scores[winner].explained < EXPLAINED_ENOUGH:
        return "unexplained", winner, (
            f"the best candidate ({winner}) removes only {100*scores[winner].explained:.0f} % of the excess residual")
    if winner == "base":
        return "parameters_only", "base", "recalibrating base parameters explains the recording; no physics is missing"
    return "missing_physics", winner, f"{winner} explains {100*scores[winner].explained:.0f} % of the excess residual"


def signals_left(objective: dict | None) -> dict[str, float]:
    """Signal -> normalised RMS of the signals an explanation leaves above ``RESIDUAL_LIMIT``."""
    return {s: v for s, v in (objective or {}).items() if v > RESIDUAL_LIMIT}


def honest(verdict_name: str, winner: str | None, reason: str, objective_after: dict | None) -> tuple[str, str]:
    """Downgrade a complete-sounding verdict the residual does not support.

    ``missing_physics`` and ``parameters_only`` stand only when every signal's residual after the
    winner is within ``RESIDUAL_LIMIT`` times its noise floor; otherwise the verdict is
    ``partially_explained`` and the reason names the signals left and how far above their floors.
    """
    if verdict_name not in ("missing_physics", "parameters_only"):
        return verdict_name, reason
    left = signals_left(objective_after)
    if not left:
        return verdict_name, reason
    words = ", ".join(f"{s} {v:.1f} x its floor" for s, v in sorted(left.items(), key=lambda kv: -kv[1]))
    return "partially_explained", (f"{reason}, but leaves {words} (complete only within {RESIDUAL_LIMIT:g} x the "
                                   f"floor on every signal)")


def same_physics(a: str, b: str) -> bool:
    """True when two candidate names hold the same effects (``x`` and ``x+base`` are one explanation)."""
    ea = {e for e in a.split("+") if e != "base"}
    eb = {e for e in b.split("+") if e != "base"}
    return ea == eb


def nested(a: str, b: str) -> bool:
    """True when one candidate's effects contain the other's (a set and its subset are not rivals:
    the multi-effect search and parsimony decide between them; ``base``, the recalibration, counts
    as one more term)."""
    ea, eb = set(a.split("+")), set(b.split("+"))
    return ea <= eb or eb <= ea


def ambiguity_set(scores: dict[str, Score], winner: str | None, objectives: dict | None = None) -> list[str]:
    """Candidates (other physics than the winner) the recording cannot tell from it.

    A candidate with other, not nested, physics is indistinguishable when it explains as much of the excess as the verdict asks
    of a winner (``EXPLAINED_ENOUGH``) and either its BIC is within ``AMBIGUOUS_BIC`` of the
    winner's, or both it and the winner are complete (``objectives``: candidate -> signal ->
    normalised RMS, every signal within ``RESIDUAL_LIMIT``) with chi-squares within
    ``AMBIGUOUS_RATIO``. The winner comes first; the others by BIC.
    """
    if winner is None or winner not in scores:
        return []
    w = scores[winner]
    objectives = objectives or {}

    def complete(k):
        return k in objectives and not signals_left(objectives[k])

    def rival(k, s):
        if k in ("nominal", winner) or nested(k, winner) or s.explained < EXPLAINED_ENOUGH:
            return False
        if s.bic - w.bic < AMBIGUOUS_BIC:
            return True
        return complete(k) and complete(winner) and s.chi2 < AMBIGUOUS_RATIO * w.chi2

    rivals = [k for k, s in scores.items() if rival(k, s)]
    # one entry per physics (keep the better of x and x+base)
    best: dict[frozenset, str] = {}
    for k in sorted(rivals, key=lambda k: scores[k].bic):
        key = frozenset(e for e in k.split("+") if e != "base")
        best.setdefault(key, k)
    return [winner] + list(best.values()) if best else []
