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

NOISE_TOLERANCE = 1.5  # nominal normalised RMS at or below which a signal agrees "within the noise floor"
SIGNIFICANCE = 10.0  # BIC difference counted as strong evidence (Kass & Raftery 1995)
MIN_GAIN = 0.25  # share of the simpler model's excess chi-square a more complex one must remove
EXPLAINED_ENOUGH = 0.5  # share of the nominal excess the winner must remove, else "unexplained"


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


def _beats(scores, a: str, b: str, n: int) -> bool:
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
        Signal -> normalised RMS of the nominal replay.
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
    if "base" in scores and _beats(scores, "base", "nominal", n):
        ref = "base"
    best_eff = min(effect_names, key=lambda e: scores[e].bic, default=None)
    winner = ref
    if best_eff is not None and _beats(scores, best_eff, ref, n):
        winner = best_eff
    elif best_eff is not None and ref == "base" and scores[best_eff].bic < scores["base"].bic and _beats(scores, best_eff, "nominal", n):
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
